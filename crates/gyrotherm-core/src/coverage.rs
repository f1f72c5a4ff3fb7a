//! What the model knows: the region of (temperature, temperature rate) its training covered,
//! and a per-sample estimate of the error of the compensated output there.
//!
//! The training region is a fixed grid of at most [`MAX_TEMP_CELLS`] × [`MAX_RATE_CELLS`]
//! cells over the plane of the first two features (T, °C, and its rate dT, °C/s). A cell is
//! *covered* when training held enough steps in it; each covered cell carries σ, the 1σ
//! residual bias error (°/h) of the model there, as cross-validated on the training logs (the
//! ground library computes it: `gyrotherm::coverage`). Uncovered cells hold σ = 0.
//!
//! The verdict of a point (T, dT), with `d` its distance to the nearest covered cell measured
//! in cells (the larger of the T and the dT distance, 0 inside the cell):
//! - [`Coverage::Inside`]: `d = 0`, σ is the cell's;
//! - [`Coverage::Edge`]: `0 < d ≤ 1`, within one cell of the training region;
//! - [`Coverage::Outside`]: `d > 1`;
//!
//! and outside a covered cell σ = σ_nearest · (1 + g · d), g the map's growth per cell: a
//! model extrapolates worse the further it goes, and nothing it saw says how much worse, so
//! g is calibrated on held-out runs of a family of simulated units (see the ground library's
//! `settings::coverage`). Among cells at the same distance the largest σ is taken.
//!
//! Fixed size, no allocation, no panics: [`CoverageMap::verdict`] is a loop over the cells
//! (at most 192), run once per sample.

use core::fmt;

use crate::features::Features;

/// Most temperature cells of a coverage grid.
pub const MAX_TEMP_CELLS: usize = 16;
/// Most temperature-rate cells of a coverage grid.
pub const MAX_RATE_CELLS: usize = 12;

/// Where a sample lies against the training region.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coverage {
    /// In a covered cell.
    Inside,
    /// Within one cell of a covered cell.
    Edge,
    /// Further out: the model extrapolates.
    Outside,
}

impl Coverage {
    /// `inside`, `edge` or `outside`, as written in output files.
    pub const fn as_str(self) -> &'static str {
        match self {
            Coverage::Inside => "inside",
            Coverage::Edge => "edge",
            Coverage::Outside => "outside",
        }
    }

    /// The inverse of [`as_str`](Self::as_str).
    pub fn parse(s: &str) -> Option<Coverage> {
        [Coverage::Inside, Coverage::Edge, Coverage::Outside]
            .into_iter()
            .find(|c| c.as_str() == s)
    }
}

impl fmt::Display for Coverage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The verdict of one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// Against the training region.
    pub coverage: Coverage,
    /// 1σ estimate of the residual bias error of the compensated output, °/h.
    pub sigma_dph: f64,
    /// Distance to the nearest covered cell, in cells (0 inside).
    pub distance_cells: f64,
}

/// The grid's geometry: cell `(i, j)` spans temperatures
/// `temp_min_c + i·temp_cell_c ..= temp_min_c + (i+1)·temp_cell_c` and rates likewise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Lower edge of the first temperature cell, °C.
    pub temp_min_c: f64,
    /// Width of a temperature cell, °C.
    pub temp_cell_c: f64,
    /// Number of temperature cells (1..=[`MAX_TEMP_CELLS`]).
    pub n_temp: usize,
    /// Lower edge of the first rate cell, °C/s.
    pub rate_min_c_per_s: f64,
    /// Width of a rate cell, °C/s.
    pub rate_cell_c_per_s: f64,
    /// Number of rate cells (1..=[`MAX_RATE_CELLS`]).
    pub n_rate: usize,
}

/// A coverage map the core refuses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CoverageError {
    /// Edges not finite, or a cell width not finite and > 0.
    Geometry,
    /// A cell count of 0 or over the maximum.
    CellCount,
    /// The σ list does not hold `n_temp · n_rate` values.
    SigmaLength,
    /// A σ not finite or negative.
    Sigma,
    /// No covered cell (every σ is 0).
    Empty,
    /// The growth per cell is not finite and ≥ 0.
    Growth,
}

impl fmt::Display for CoverageError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CoverageError::Geometry => {
                "coverage grid: edges must be finite and cell widths finite and > 0"
            }
            CoverageError::CellCount => {
                "coverage grid: 1 to 16 temperature cells and 1 to 12 rate cells"
            }
            CoverageError::SigmaLength => "coverage grid: one σ per cell (n_temp · n_rate)",
            CoverageError::Sigma => "coverage grid: σ must be finite and >= 0 °/h",
            CoverageError::Empty => "coverage grid: no covered cell (every σ is 0)",
            CoverageError::Growth => "coverage grid: growth per cell must be finite and >= 0",
        })
    }
}

impl core::error::Error for CoverageError {}

/// The training region and its cross-validated error (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoverageMap {
    grid: Grid,
    /// σ per cell, °/h, `[temperature][rate]`; 0: not covered.
    sigma_dph: [[f64; MAX_RATE_CELLS]; MAX_TEMP_CELLS],
    growth_per_cell: f64,
}

impl CoverageMap {
    /// Checked constructor: `sigma_dph` holds one σ per cell, row-major by temperature
    /// (`sigma_dph[i · n_rate + j]` for temperature cell i, rate cell j), 0 where training did
    /// not cover the cell.
    pub fn new(
        grid: Grid,
        sigma_dph: &[f64],
        growth_per_cell: f64,
    ) -> Result<CoverageMap, CoverageError> {
        let finite = [
            grid.temp_min_c,
            grid.temp_cell_c,
            grid.rate_min_c_per_s,
            grid.rate_cell_c_per_s,
        ]
        .iter()
        .all(|v| v.is_finite());
        if !finite || grid.temp_cell_c <= 0.0 || grid.rate_cell_c_per_s <= 0.0 {
            return Err(CoverageError::Geometry);
        }
        if !(1..=MAX_TEMP_CELLS).contains(&grid.n_temp)
            || !(1..=MAX_RATE_CELLS).contains(&grid.n_rate)
        {
            return Err(CoverageError::CellCount);
        }
        if sigma_dph.len() != grid.n_temp * grid.n_rate {
            return Err(CoverageError::SigmaLength);
        }
        if !(growth_per_cell.is_finite() && growth_per_cell >= 0.0) {
            return Err(CoverageError::Growth);
        }
        let mut cells = [[0.0; MAX_RATE_CELLS]; MAX_TEMP_CELLS];
        let mut any = false;
        for (row, src) in cells.iter_mut().zip(sigma_dph.chunks(grid.n_rate)) {
            for (cell, &s) in row.iter_mut().zip(src) {
                if !(s.is_finite() && s >= 0.0) {
                    return Err(CoverageError::Sigma);
                }
                any |= s > 0.0;
                *cell = s;
            }
        }
        if !any {
            return Err(CoverageError::Empty);
        }
        Ok(CoverageMap {
            grid,
            sigma_dph: cells,
            growth_per_cell,
        })
    }

    /// The geometry.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The growth of σ per cell of distance outside the training region.
    pub fn growth_per_cell(&self) -> f64 {
        self.growth_per_cell
    }

    /// σ of cell `(i, j)`, °/h (0: not covered; None: no such cell).
    pub fn sigma_dph(&self, i: usize, j: usize) -> Option<f64> {
        if i >= self.grid.n_temp || j >= self.grid.n_rate {
            return None;
        }
        self.sigma_dph.get(i).and_then(|r| r.get(j)).copied()
    }

    /// The verdict of a temperature (°C) and temperature rate (°C/s). Not finite: outside,
    /// σ infinite.
    pub fn verdict(&self, temp_c: f64, rate_c_per_s: f64) -> Verdict {
        let g = &self.grid;
        let u = (temp_c - g.temp_min_c) / g.temp_cell_c;
        let v = (rate_c_per_s - g.rate_min_c_per_s) / g.rate_cell_c_per_s;
        if !(u.is_finite() && v.is_finite()) {
            return Verdict {
                coverage: Coverage::Outside,
                sigma_dph: f64::INFINITY,
                distance_cells: f64::INFINITY,
            };
        }
        // Distance from x to the unit interval [k, k + 1].
        let gap = |x: f64, k: usize| {
            let lo = k as f64;
            (lo - x).max(x - (lo + 1.0)).max(0.0)
        };
        let mut best_d = f64::INFINITY;
        let mut best_sigma = 0.0;
        for (i, row) in self.sigma_dph.iter().enumerate().take(g.n_temp) {
            let du = gap(u, i);
            for (j, &s) in row.iter().enumerate().take(g.n_rate) {
                if s <= 0.0 {
                    continue;
                }
                let d = du.max(gap(v, j));
                if d < best_d || (d == best_d && s > best_sigma) {
                    best_d = d;
                    best_sigma = s;
                }
            }
        }
        let coverage = if best_d <= 0.0 {
            Coverage::Inside
        } else if best_d <= 1.0 {
            Coverage::Edge
        } else {
            Coverage::Outside
        };
        Verdict {
            coverage,
            sigma_dph: best_sigma * (1.0 + self.growth_per_cell * best_d),
            distance_cells: best_d,
        }
    }

    /// The verdict of a compensator's latest features (T and dT, the first two; see
    /// [`Compensator::features`](crate::Compensator::features)); None before the first step
    /// or with fewer than two features.
    pub fn verdict_of(&self, features: Option<&Features>) -> Option<Verdict> {
        match features.map(|f| f.as_slice()) {
            Some([t, r, ..]) => Some(self.verdict(*t, *r)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two by two cells of 10 °C and 0.01 °C/s from (0 °C, 0 °C/s); only cell (0, 0) covered,
    /// with σ 0.02 °/h, growth 0.5 per cell: every expected value below follows from these
    /// numbers by the rule in the module doc.
    fn map() -> CoverageMap {
        let grid = Grid {
            temp_min_c: 0.0,
            temp_cell_c: 10.0,
            n_temp: 2,
            rate_min_c_per_s: 0.0,
            rate_cell_c_per_s: 0.01,
            n_rate: 2,
        };
        CoverageMap::new(grid, &[0.02, 0.0, 0.0, 0.0], 0.5).unwrap()
    }

    #[test]
    fn inside_edge_outside_and_sigma_growth() {
        let m = map();
        let v = m.verdict(5.0, 0.005);
        assert_eq!(v.coverage, Coverage::Inside);
        assert_eq!(v.sigma_dph, 0.02);
        // 5 °C beyond the covered cell's upper temperature edge: half a cell.
        let v = m.verdict(15.0, 0.005);
        assert_eq!(v.coverage, Coverage::Edge);
        assert!((v.distance_cells - 0.5).abs() < 1e-12, "{v:?}");
        assert!((v.sigma_dph - 0.02 * 1.25).abs() < 1e-15, "{v:?}");
        // Four cells out in rate (0.04 °C/s above the cell's edge at 0.01 °C/s), one in
        // temperature: the larger counts.
        let v = m.verdict(-10.0, 0.05);
        assert_eq!(v.coverage, Coverage::Outside);
        assert!((v.distance_cells - 4.0).abs() < 1e-9, "{v:?}");
        assert!((v.sigma_dph - 0.02 * 3.0).abs() < 1e-12, "{v:?}");
    }

    #[test]
    fn not_finite_is_outside_with_infinite_sigma() {
        let v = map().verdict(f64::NAN, 0.0);
        assert_eq!(v.coverage, Coverage::Outside);
        assert!(v.sigma_dph.is_infinite());
    }

    #[test]
    fn refuses_bad_maps() {
        let g = *map().grid();
        assert_eq!(
            CoverageMap::new(g, &[0.0; 4], 0.5),
            Err(CoverageError::Empty)
        );
        assert_eq!(
            CoverageMap::new(g, &[0.1; 3], 0.5),
            Err(CoverageError::SigmaLength)
        );
        assert_eq!(
            CoverageMap::new(g, &[0.1, f64::NAN, 0.0, 0.0], 0.5),
            Err(CoverageError::Sigma)
        );
        assert_eq!(
            CoverageMap::new(g, &[0.1; 4], -1.0),
            Err(CoverageError::Growth)
        );
        let wide = Grid {
            n_rate: MAX_RATE_CELLS + 1,
            ..g
        };
        assert_eq!(
            CoverageMap::new(wide, &[0.1; 2 * 13], 0.5),
            Err(CoverageError::CellCount)
        );
        let flat = Grid {
            temp_cell_c: 0.0,
            ..g
        };
        assert_eq!(
            CoverageMap::new(flat, &[0.1; 4], 0.5),
            Err(CoverageError::Geometry)
        );
    }

    #[test]
    fn coverage_names_round_trip() {
        for c in [Coverage::Inside, Coverage::Edge, Coverage::Outside] {
            assert_eq!(Coverage::parse(c.as_str()), Some(c));
        }
        assert_eq!(Coverage::parse("in"), None);
    }
}
