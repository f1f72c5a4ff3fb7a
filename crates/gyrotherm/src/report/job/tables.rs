//! The report's tables: the comparison table, the model table (one column per model) and
//! the settings the models share.

use super::fmt_num;
use crate::compare::{CompareConfig, Comparison};
use crate::features::{FeatureKind, FeatureSpec};
use crate::fit::{FitOutcome, NamedLog, TrainSummary};
use crate::model::{Method, ModelFile, SubModel};
use crate::report::html::Table;

/// A results table (a comparison's, or a unit axis's with its unit-fit column) as the
/// report's HTML table: held-out log, figure, the output columns, the noise floor.
pub(crate) fn results_table(t: &crate::compare::ComparisonTable) -> Table {
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

/// Settings shared by every model of the comparison, key then value: the training logs and
/// the comparison's windows, then the provenance fields (data digest, training inputs,
/// writer) when every model carries the same value; [`model_table`] shows them otherwise.
pub(crate) fn shared_settings(
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
    for field in PROVENANCE {
        if let Some(v) = shared_value(cmp, field) {
            md.push((format!("{} (all models)", field.label()), v));
        }
    }
    md
}

/// The models side by side: a header row naming each model, then one row per field.
/// A cell whose field does not apply to that model (epochs of a least-squares fit, the
/// recipe of a method without one) holds "—"; a field that applies to no model has no row.
pub(crate) fn model_table(cmp: &Comparison, cfg: &CompareConfig) -> Table {
    let n = cmp.fits.len().min(cmp.columns.len());
    let mut headers = vec!["field".to_owned()];
    headers.extend(cmp.columns[..n].iter().map(|c| c.label.to_owned()));
    let mut rows = Vec::new();
    for field in FIELDS {
        if PROVENANCE.contains(&field) && shared_value(cmp, field).is_some() {
            continue;
        }
        let cells: Vec<Option<String>> = (0..n)
            .map(|i| {
                let recipe = cfg
                    .candidates
                    .get(i)
                    .map(|c| c.fit_config(&cfg.fit).recipe.kind.as_str());
                field.value(&cmp.fits[i], recipe)
            })
            .collect();
        if cells.iter().all(Option::is_none) {
            continue;
        }
        let mut row = vec![field.label().to_owned()];
        row.extend(
            cells
                .into_iter()
                .map(|c| c.unwrap_or_else(|| NOT_APPLICABLE.to_owned())),
        );
        rows.push(row);
    }
    Table { headers, rows }
}

/// The cell of a field that does not apply to a model.
pub(crate) const NOT_APPLICABLE: &str = "—";

/// The rows of [`model_table`], in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Field {
    Method,
    Recipe,
    BiasModel,
    ScaleModel,
    Inputs,
    TempRange,
    RateRange,
    Seed,
    BiasNetwork,
    ScaleNetwork,
    DataDigest,
    TrainingInputs,
    WrittenBy,
}

const FIELDS: [Field; 13] = [
    Field::Method,
    Field::Recipe,
    Field::BiasModel,
    Field::ScaleModel,
    Field::Inputs,
    Field::TempRange,
    Field::RateRange,
    Field::Seed,
    Field::BiasNetwork,
    Field::ScaleNetwork,
    Field::DataDigest,
    Field::TrainingInputs,
    Field::WrittenBy,
];

/// Fields that are usually the same for every model (the same training data, the same
/// program): said once, beside the shared settings, when they are.
const PROVENANCE: [Field; 3] = [Field::DataDigest, Field::TrainingInputs, Field::WrittenBy];

impl Field {
    fn label(self) -> &'static str {
        match self {
            Field::Method => "method",
            Field::Recipe => "recipe",
            Field::BiasModel => "bias model",
            Field::ScaleModel => "scale-factor model",
            Field::Inputs => "inputs",
            Field::TempRange => "training temperature (°C)",
            Field::RateRange => "training temperature rate (°C/min)",
            Field::Seed => "seed",
            Field::BiasNetwork => "bias LSTM training",
            Field::ScaleNetwork => "scale-factor LSTM training",
            Field::DataDigest => "data digest (SHA-256)",
            Field::TrainingInputs => "training inputs",
            Field::WrittenBy => "written by",
        }
    }

    /// The cell of this field for one model (`recipe`: the recipe its column trained);
    /// None where the field does not apply.
    fn value(self, f: &FitOutcome, recipe: Option<&str>) -> Option<String> {
        let m = &f.model;
        let ti = &m.training;
        match self {
            Field::Method => Some(m.method.as_str().to_owned()),
            Field::Recipe => recipe
                .filter(|_| m.method == Method::Lstm)
                .map(str::to_owned),
            Field::BiasModel => Some(sub_model(&m.bias, "no static training log")),
            Field::ScaleModel => Some(sub_model(&m.scale, "no rate-table training log")),
            Field::Inputs => m.feature_spec().ok().map(|s| input_names(&s).join(", ")),
            Field::TempRange => Some(format!(
                "{:.2} to {:.2}",
                ti.temp_range_c.min, ti.temp_range_c.max
            )),
            Field::RateRange => Some(format!(
                "{:.3} to {:.3}",
                ti.rate_range_c_per_s.min * 60.0,
                ti.rate_range_c_per_s.max * 60.0
            )),
            // A seed only matters to a model with a network it initialised.
            Field::Seed => holds_lstm(m)
                .then_some(ti.seed)
                .flatten()
                .map(|s| s.to_string()),
            Field::BiasNetwork => network(&m.bias, &f.bias_training),
            Field::ScaleNetwork => network(&m.scale, &f.scale_training),
            Field::DataDigest => Some(ti.data_digest_sha256.clone()),
            Field::TrainingInputs => Some(ti.inputs.join(", ")),
            Field::WrittenBy => Some(ti.created_by.clone()),
        }
    }
}

/// The value every model has for `field`, if they all have the same one.
fn shared_value(cmp: &Comparison, field: Field) -> Option<String> {
    let mut values = cmp.fits.iter().map(|f| field.value(f, None));
    let first = values.next()??;
    values
        .all(|v| v.as_deref() == Some(first.as_str()))
        .then_some(first)
}

/// What a sub-model is made of, or why there is none.
fn sub_model(s: &Option<SubModel>, missing: &str) -> String {
    match s {
        Some(s) => s.kind().to_owned(),
        None => format!("none ({missing})"),
    }
}

/// Whether the model holds an LSTM in either sub-model.
fn holds_lstm(m: &ModelFile) -> bool {
    [&m.bias, &m.scale]
        .iter()
        .any(|s| s.as_ref().is_some_and(|s| s.lstm().is_some()))
}

/// Epochs and final loss of the LSTM of one sub-model: only where the model kept an LSTM
/// there and its training ran (a recipe whose least-squares base won keeps none, and its
/// summary would read "0 epochs").
fn network(s: &Option<SubModel>, t: &Option<TrainSummary>) -> Option<String> {
    s.as_ref().and_then(SubModel::lstm)?;
    let t = t.as_ref().filter(|t| t.epochs > 0)?;
    Some(format!(
        "{} epochs, final loss {:.3e} (normalised MSE)",
        t.epochs, t.final_loss
    ))
}

/// The model inputs as a reader says them: `T`, `dT/dt`, `T mean 20 s`, `T lag 266 s`,
/// `T − lag 266 s` (a lag is a first-order low-pass of T with that time constant, rounded
/// to whole seconds in the text; the model file keeps the exact value). The spaces inside
/// a name are no-break spaces, so a table cell wraps only between names.
pub fn input_names(spec: &FeatureSpec) -> Vec<String> {
    (0..spec.n_features())
        .map(|i| {
            let name = match spec.kind(i) {
                Some(FeatureKind::Temperature) => "T".to_owned(),
                Some(FeatureKind::Rate) => "dT/dt".to_owned(),
                Some(FeatureKind::MovingAverage) => {
                    format!("T mean {} s", whole_seconds(spec.smoothing_window_s))
                }
                Some(FeatureKind::Lag(j)) => format!("T lag {} s", lag_s(spec, j)),
                Some(FeatureKind::LagDiff(j)) => format!("T − lag {} s", lag_s(spec, j)),
                None => format!("x{i}"),
            };
            name.replace(' ', "\u{a0}")
        })
        .collect()
}

fn lag_s(spec: &FeatureSpec, j: u8) -> String {
    spec.lag_tau_s
        .get(usize::from(j))
        .map_or_else(|| "?".to_owned(), |&t| whole_seconds(t))
}

/// `v` rounded to whole seconds, as text.
fn whole_seconds(v: f64) -> String {
    if v.is_finite() {
        format!("{:.0}", v.round())
    } else {
        v.to_string()
    }
}
