//! Turning a model file into the flight crate's models: here, beside the model, so that
//! both the load-time plausibility check and `compensate` use it without an import cycle.

use super::*;

use gyrotherm_core::compensator::ModelError as FlightModelError;
use gyrotherm_core::compensator::{NormalisedLstm, TargetModel, HIDDEN, LSTM_INPUTS};

/// Widen an LSTM to the flight input count: input columns beyond `input_size` get weight 0.
pub fn padded_core_lstm(
    params: &LstmParams,
) -> Result<gyrotherm_core::lstm::LstmWeights<LSTM_INPUTS, HIDDEN>, CompensateError> {
    let i = params.input_size;
    if i > LSTM_INPUTS {
        return Err(CompensateError::LstmInputs { inputs: i });
    }
    let mut wide = params.clone();
    wide.input_size = LSTM_INPUTS;
    wide.w_ih = params
        .w_ih
        .chunks(i.max(1))
        .flat_map(|row| {
            let mut r = row.to_vec();
            r.resize(LSTM_INPUTS, 0.0);
            r
        })
        .collect();
    wide.to_core::<LSTM_INPUTS, HIDDEN>()
        .map_err(CompensateError::Params)
}

fn core_lstm(
    params: &LstmParams,
    input_norm: &ZScore,
    target_norm: &ZScore,
) -> Result<NormalisedLstm, CompensateError> {
    let w = padded_core_lstm(params)?;
    NormalisedLstm::new(
        &w,
        &input_norm.mean,
        &input_norm.std,
        target_norm.mean[0],
        target_norm.std[0],
    )
    .map_err(CompensateError::Flight)
}

/// The flight model of one target (`None`: the constant `absent`).
pub fn target_model(sub: Option<&SubModel>, absent: f64) -> Result<TargetModel, CompensateError> {
    let Some(sub) = sub else {
        return Ok(TargetModel::constant(absent));
    };
    let baseline = sub
        .baseline_core()
        .transpose()
        .map_err(CompensateError::Baseline)?;
    let lstm = match sub.lstm() {
        Some((params, input_norm, target_norm)) => {
            Some(core_lstm(params, input_norm, target_norm)?)
        }
        None => None,
    };
    let lstm_reads_base = sub.reads_base();
    Ok(TargetModel {
        offset: 0.0,
        baseline,
        lstm,
        lstm_reads_base,
    })
}

/// Why a model could not be turned into the flight compensator, or a log not compensated: the
/// target, sample, line or value at fault.
#[derive(Debug)]
#[non_exhaustive]
pub enum CompensateError {
    /// The model file's feature definition.
    Model(ModelFileError),
    /// The LSTM reads more inputs than flight code takes.
    LstmInputs { inputs: usize },
    /// The LSTM parameters cannot be exported.
    Params(ParamsError),
    /// The least-squares part cannot be evaluated in flight.
    Baseline(BaselineError),
    /// The flight crate refused the model.
    Flight(FlightModelError),
    /// In the bias or scale-factor model.
    InTarget {
        target: Target,
        source: Box<CompensateError>,
    },
}

impl std::fmt::Display for CompensateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CompensateError::Model(e) => e.fmt(f),
            CompensateError::LstmInputs { inputs } => write!(
                f,
                "the LSTM reads {inputs} inputs; flight code takes at most {LSTM_INPUTS}"
            ),
            CompensateError::Params(e) => e.fmt(f),
            CompensateError::Baseline(e) => e.fmt(f),
            CompensateError::Flight(e) => e.fmt(f),
            CompensateError::InTarget { target, .. } => f.write_str(target.as_str()),
        }
    }
}

impl std::error::Error for CompensateError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent wrappers: the inner error's message is this error's own.
            CompensateError::Model(e) => e.source(),
            CompensateError::Params(e) => e.source(),
            CompensateError::Baseline(e) => e.source(),
            CompensateError::InTarget { source, .. } => Some(source.as_ref()),
            // Transparent: the flight crate's message is this error's own.
            CompensateError::Flight(e) => e.source(),
            CompensateError::LstmInputs { .. } => None,
        }
    }
}
