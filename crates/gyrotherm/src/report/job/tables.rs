//! The report's tables: the comparison table and the model metadata.

use super::fmt_num;
use crate::compare::{Candidate, Column, CompareConfig, Comparison};
use crate::features::feature_names;
use crate::fit::NamedLog;
use crate::model::ModelFile;
use crate::report::html::Table;

/// The comparison table of `gyrotherm compare` ([`Comparison::table`]) as the report's HTML
/// table: one row per figure, the held-out log named on its first row, a noise-floor column.
pub fn comparison_table(cmp: &Comparison, cfg: &CompareConfig) -> Table {
    let t = cmp.table(cfg);
    let mut headers = vec!["held-out log".to_owned(), "figure".to_owned()];
    headers.extend(t.columns.iter().cloned());
    headers.push("noise floor".to_owned());
    let mut rows = Vec::new();
    for block in &t.blocks {
        for (k, r) in block.rows.iter().enumerate() {
            let mut row = vec![
                if k == 0 { block.title() } else { String::new() },
                r.figure.label(),
            ];
            row.extend(r.cells.iter().cloned());
            row.push(r.floor.clone().unwrap_or_default());
            rows.push(row);
        }
    }
    Table { headers, rows }
}

/// Key-value facts of the models: method, recipe and epochs, seed, training ranges, data
/// digest, inputs.
pub fn metadata(
    train: &[NamedLog],
    cmp: &Comparison,
    cfg: &CompareConfig,
) -> Vec<(String, String)> {
    let mut md = vec![
        (
            "training logs".to_owned(),
            train.iter().map(|l| l.name).collect::<Vec<_>>().join(", "),
        ),
        (
            "bias-stability smoothing τ".to_owned(),
            format!("{} s", fmt_num(cfg.tau_s)),
        ),
        (
            "bias target window".to_owned(),
            format!("{} s", fmt_num(cfg.fit.bias_window_s)),
        ),
        (
            "settle time per table segment".to_owned(),
            format!("{} s", fmt_num(cfg.settle_s)),
        ),
    ];
    for ((f, col), cand) in cmp.fits.iter().zip(&cmp.columns).zip(&cfg.candidates) {
        model_metadata(&mut md, &f.model, col, cand, cfg);
        for (name, t) in [
            ("bias network", &f.bias_training),
            ("scale-factor network", &f.scale_training),
        ] {
            if let Some(t) = t {
                md.push((
                    format!("{} {name}", col.key),
                    format!("{} epochs, final loss {:.4e}", t.epochs, t.final_loss),
                ));
            }
        }
    }
    md
}

fn model_metadata(
    md: &mut Vec<(String, String)>,
    m: &ModelFile,
    col: &Column,
    cand: &Candidate,
    cfg: &CompareConfig,
) {
    let p = col.key;
    let ti = &m.training;
    let targets = match (m.bias.is_some(), m.scale.is_some()) {
        (true, true) => "bias and scale factor",
        (true, false) => "bias only (no static training log)",
        (false, true) => "scale factor only (no rate-table training log)",
        (false, false) => "none",
    };
    md.push((
        format!("{p} model"),
        format!("{} ({} method) — {targets}", col.label, m.method.as_str()),
    ));
    if m.method.is_recipe() {
        let recipe = cand.fit_config(&cfg.fit).recipe;
        md.push((
            format!("{p} recipe"),
            format!("{}, at most {} epochs", recipe.kind.as_str(), recipe.epochs),
        ));
    }
    if let Ok(spec) = m.feature_spec() {
        md.push((format!("{p} inputs"), feature_names(&spec).0.join(", ")));
    }
    md.push((
        format!("{p} training range"),
        format!(
            "temperature {:.2} to {:.2} °C, rate {:.3} to {:.3} °C/min",
            ti.temp_range_c.min,
            ti.temp_range_c.max,
            ti.rate_range_c_per_s.min * 60.0,
            ti.rate_range_c_per_s.max * 60.0
        ),
    ));
    if let Some(e) = ti.epochs {
        md.push((format!("{p} epochs"), e.to_string()));
    }
    if let Some(s) = ti.seed {
        md.push((format!("{p} seed"), s.to_string()));
    }
    md.push((
        format!("{p} data digest (SHA-256)"),
        ti.data_digest_sha256.clone(),
    ));
    md.push((format!("{p} training inputs"), ti.inputs.join(", ")));
    md.push((format!("{p} written by"), ti.created_by.clone()));
}
