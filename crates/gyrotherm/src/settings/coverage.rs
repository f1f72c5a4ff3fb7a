//! Coverage settings: how `train` maps the region of (temperature, temperature rate) its logs
//! covered and the cross-validated error there, and how fast the 1σ estimate grows outside it
//! (see [`crate::coverage`] and [`gyrotherm_core::coverage`]).
//!
//! [`SIGMA_SCALE`] was chosen on the design family of simulated units (unit seeds
//! 1000-1029) and measured once on the confirmation family (5000-5029); [`GROWTH_PER_CELL`]
//! on that design family and the wide family's design units (7100-7107), measured once on
//! wide units 7200-7207: `docs/experiments/coverage.md`.
//!
//! None of these is a user option, so none is listed in [`super::describe`](mod@super::describe): `train` always
//! maps with [`CoverageSettings::default`]. The σ scale and the growth were calibrated on
//! held-out runs *with this grid, these folds, this cell minimum and this shrinkage*; a user
//! changing any one of them would get a σ whose ±1σ share nobody has measured, and a map a
//! flight reader cannot compare with another model's. The struct keeps them together for
//! `crate::coverage::cross_validated` and its tests; the calibration harnesses vary scale
//! and growth on design units only, through [`crate::coverage::CoverageDef::rescaled`]
//! (`crates/gyrotherm-experiments/src/bin/coverage.rs` on single gyros; `imu_family --sigma`
//! on units, read by `bench/growth_share.py`). A change of any constant here needs that
//! record re-run (`bench/coverage.sh design`, then `confirm` once).

/// Temperature cells of the grid (the core's maximum).
pub(crate) const TEMP_CELLS: usize = gyrotherm_core::coverage::MAX_TEMP_CELLS;
/// Temperature-rate cells of the grid (the core's maximum).
pub(crate) const RATE_CELLS: usize = gyrotherm_core::coverage::MAX_RATE_CELLS;
/// Narrowest temperature cell, °C: twice the DS18B20's ±0.5 °C accuracy (He et al. 2024,
/// DOI 10.19452/j.issn1007-5453.2024.02.004, §3), so a log that barely moved covers a cell
/// or two, not sixteen slivers of noise.
pub(crate) const MIN_TEMP_CELL_C: f64 = 1.0;
/// Narrowest rate cell, °C/s: 0.06 °C/min, about the rate noise of a 0.0625 °C sensor step
/// over the 20 s rate window (0.0625 / 20 ≈ 0.003 °C/s) divided by thirty.
pub(crate) const MIN_RATE_CELL_C_PER_S: f64 = 1e-3;
/// Cross-validation folds: contiguous time blocks of each static log, as the `thermal`
/// method's own cross-validation uses (README, "The method").
pub const FOLDS: usize = 5;
/// Held-out steps a cell needs to count as covered: one 100 s bias window (He et al. 2024,
/// §3), so a cell's residual is at least one independent smoothed value.
pub(crate) const MIN_CELL_STEPS: u64 = 100;
/// Steps of pooled residual mixed into each cell's RMS (shrinkage towards the pooled RMS):
/// residuals of a 100 s smoothed target are correlated over about 100 steps, so a cell of a
/// few hundred steps holds only a few independent values.
pub(crate) const SHRINK_STEPS: f64 = 300.0;
/// σ = SIGMA_SCALE × the cell's shrunk cross-validated RMS (design family,
/// docs/experiments/coverage.md).
pub const SIGMA_SCALE: f64 = 0.9;
/// Growth of σ per cell of distance outside the training region: the smallest on the grid
/// whose ±1σ share outside coverage is at least 68.3 % on the design family's single gyros and
/// on the axes of units with physics past the design ranges (wide family seeds 7100-7107,
/// the LSTM's axes and all axes); 0.5, chosen on the single gyros alone, held there but left
/// the wide units' LSTM axes at 56 % (docs/experiments/coverage.md).
pub const GROWTH_PER_CELL: f64 = 1.5;

/// The coverage settings of one fit (defaults: the constants above).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoverageSettings {
    /// Temperature cells, 1..=16.
    pub temp_cells: usize,
    /// Rate cells, 1..=12.
    pub rate_cells: usize,
    /// Cross-validation folds, ≥ 2.
    pub folds: usize,
    /// Held-out steps a cell needs to count as covered.
    pub min_cell_steps: u64,
    /// Shrinkage of each cell's RMS towards the pooled one, steps.
    pub shrink_steps: f64,
    /// σ over the cell's shrunk RMS.
    pub sigma_scale: f64,
    /// Growth of σ per cell of distance outside the region.
    pub growth_per_cell: f64,
}

impl Default for CoverageSettings {
    fn default() -> Self {
        CoverageSettings {
            temp_cells: TEMP_CELLS,
            rate_cells: RATE_CELLS,
            folds: FOLDS,
            min_cell_steps: MIN_CELL_STEPS,
            shrink_steps: SHRINK_STEPS,
            sigma_scale: SIGMA_SCALE,
            growth_per_cell: GROWTH_PER_CELL,
        }
    }
}
