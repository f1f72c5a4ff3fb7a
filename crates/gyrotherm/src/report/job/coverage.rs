//! Figures 9 and 10: the coverage map of the model the report is about (a unit axis's own fit
//! where one is given, else the column of [`compensated_result`], else the first model with a
//! map) with the main held-out log's path over it, and that model's σ beside the residual of
//! the first static held-out log.

use super::{compensated_result, fmt_num, sig, to_dph, Builder, CoverageModel, FIGURE_WINDOW_S};
use crate::compare::{Comparison, TestResult};
use crate::coverage_track::{covered_cells, track};
use crate::fit::NamedLog;
use crate::model::ModelFile;
use crate::report::coverage_figures::{
    coverage_map_figure, sigma_figure, CellRect, CoverageMapData, SigmaData,
};
use crate::report::ReportError;

/// Index of figure 9 in [`super::FIGURE_STEMS`]; figure 10 follows it.
const MAP_INDEX: usize = 8;

/// The model with a coverage map the report is about, and its column label.
fn mapped_model<'a>(r: &TestResult, cmp: &'a Comparison) -> Option<(&'a ModelFile, &'a str)> {
    let with_map = |key: &str| {
        cmp.fits
            .iter()
            .zip(&cmp.columns)
            .find(|(f, c)| c.key == key && f.model.coverage.is_some())
    };
    compensated_result(r)
        .and_then(|m| with_map(m.key))
        .or_else(|| {
            cmp.fits
                .iter()
                .zip(&cmp.columns)
                .find(|(f, _)| f.model.coverage.is_some())
        })
        .map(|(f, c)| (&f.model, c.label))
}

/// `static_pair` comes with its index among the held-out logs (for `shipped`'s output).
pub(super) fn coverage_figures(
    b: &mut Builder,
    main_pair: Option<(&NamedLog, &TestResult)>,
    static_pair: Option<((&NamedLog, &TestResult), usize)>,
    cmp: &Comparison,
    shipped: Option<&CoverageModel>,
) -> Result<(), ReportError> {
    const NO_MAP: &str = "no model in this comparison carries a coverage map (only models with \
                          a least-squares bias get one)";
    let model_of = |r: &TestResult| match shipped {
        Some(s) => Some((s.model, s.label)),
        None => mapped_model(r, cmp),
    };
    match main_pair {
        None => b.note(MAP_INDEX + 1, "no held-out log given"),
        Some((l, r)) => match model_of(r) {
            None => b.note(MAP_INDEX + 1, NO_MAP),
            Some((model, label)) => map_figure(b, l, model, label)?,
        },
    }
    match static_pair {
        None => b.note(MAP_INDEX + 2, "no static held-out log given"),
        Some(((l, r), i)) => match model_of(r) {
            None => b.note(MAP_INDEX + 2, NO_MAP),
            Some((model, label)) => {
                let given = shipped.and_then(|s| s.compensated_dps.get(i));
                sigma_fig(b, l, model, label, given.map(Vec::as_slice))?
            }
        },
    }
    Ok(())
}

fn track_of(
    l: &NamedLog,
    model: &ModelFile,
) -> Result<Option<crate::coverage_track::CoverageTrack>, ReportError> {
    track(model, l.log).map_err(|e| ReportError::Data {
        what: format!("coverage of {}: {e}", l.name),
    })
}

fn map_figure(
    b: &mut Builder,
    l: &NamedLog,
    model: &ModelFile,
    label: &str,
) -> Result<(), ReportError> {
    let (Some(def), Some(t)) = (model.coverage.as_ref(), track_of(l, model)?) else {
        b.note(MAP_INDEX + 1, "the coverage map does not apply");
        return Ok(());
    };
    let cells: Vec<CellRect> = covered_cells(def)
        .iter()
        .map(|c| CellRect {
            temp_c: c.temp_c,
            rate_c_per_min: (60.0 * c.rate_c_per_s.0, 60.0 * c.rate_c_per_s.1),
        })
        .collect();
    let rate: Vec<f64> = t.rate_c_per_s.iter().map(|r| 60.0 * r).collect();
    let files = coverage_map_figure(
        &b.path(MAP_INDEX),
        &CoverageMapData {
            cells: &cells,
            temp_c: &t.temp_c,
            rate_c_per_min: &rate,
            coverage: &t.coverage(),
            run: l.name,
        },
    )?;
    let shares = t.shares().unwrap_or([0.0; 3]);
    b.add(
        &files,
        format!(
            "Coverage map of the {label} model: the (T, dT) cells its static training steps \
             covered ({} of {} cells of {} °C × {} °C/min), and the path of {} over them \
             (the compensator's temperature and rate features): {} % of its samples inside, \
             {} % at the edge (within one cell), {} % outside.",
            cells.len(),
            def.n_temp * def.n_rate,
            sig(def.temp_cell_c),
            sig(60.0 * def.rate_cell_c_per_s),
            l.name,
            pct(shares[0]),
            pct(shares[1]),
            pct(shares[2]),
        ),
    );
    Ok(())
}

/// `compensated`: the model's output on `l` where the caller has it (a unit axis's own fit,
/// which runs on several sensors); else `model` compensates `l`.
fn sigma_fig(
    b: &mut Builder,
    l: &NamedLog,
    model: &ModelFile,
    label: &str,
    compensated: Option<&[f64]>,
) -> Result<(), ReportError> {
    let Some(t) = track_of(l, model)? else {
        b.note(MAP_INDEX + 2, "the coverage map does not apply");
        return Ok(());
    };
    // A static log's true rate is taken as 0 (the simulator's; a real log still holds the
    // Earth rate's component, which shows as an offset).
    let residual = match compensated {
        Some(c) => to_dph(c),
        None => {
            let comp =
                crate::compensate::compensate_log(model, l.log).map_err(|e| ReportError::Data {
                    what: format!("compensating {}: {e}", l.name),
                })?;
            to_dph(&comp.gyro_comp_dps)
        }
    };
    let files = sigma_figure(
        &b.path(MAP_INDEX + 1),
        &SigmaData {
            time_s: &l.log.time_s,
            residual_dph: &residual,
            sigma_dph: &t.sigma_dph(),
            coverage: &t.coverage(),
            window_s: FIGURE_WINDOW_S,
        },
    )?;
    b.add(
        &files,
        format!(
            "Residual bias of {} after the {label} model (compensated output, true rate 0: \
             {} s means) and the band ±1σ of compensate's σ (averaged over the same windows); \
             below, σ per sample, coloured by coverage. Inside the training region about 68 % \
             of the means should lie in the band (docs/experiments/coverage.md).",
            l.name,
            fmt_num(FIGURE_WINDOW_S)
        ),
    );
    Ok(())
}

fn pct(v: f64) -> String {
    format!("{:.1}", 100.0 * v)
}
