//! Turning a model file into the flight crate's models: here, beside the model, so that
//! both the load-time plausibility check and `compensate` use it without an import cycle.

use super::*;

use crate::flight_size::HiddenSize;
use gyrotherm_core::compensator::ModelError as FlightModelError;
use gyrotherm_core::compensator::{NormalisedLstm, TargetModel, LSTM_INPUTS};

/// Widen an LSTM to the flight input count and `H` hidden units: input columns beyond
/// `input_size` get weight 0, and so do hidden units beyond `hidden_size` (their state stays
/// 0 and they add nothing to the output; see [`crate::flight_size`]).
pub fn padded_core_lstm<const H: usize>(
    params: &LstmParams,
) -> Result<gyrotherm_core::lstm::LstmWeights<LSTM_INPUTS, H>, CompensateError> {
    let i = params.input_size;
    if i > LSTM_INPUTS {
        return Err(CompensateError::LstmInputs { inputs: i });
    }
    let h = params.hidden_size;
    if HiddenSize::of_units(h).is_none() || h > H {
        return Err(CompensateError::HiddenSize { hidden: h });
    }
    params.validate().map_err(CompensateError::Params)?;
    let mut wide = LstmParams::zeros(LSTM_INPUTS, H);
    // Gate g's row j (PyTorch order: gates of h rows each) lands in row g·H + j.
    for g in 0..4 {
        for j in 0..h {
            let (src, dst) = (g * h + j, g * H + j);
            wide.w_ih[dst * LSTM_INPUTS..dst * LSTM_INPUTS + i]
                .copy_from_slice(&params.w_ih[src * i..(src + 1) * i]);
            wide.w_hh[dst * H..dst * H + h].copy_from_slice(&params.w_hh[src * h..(src + 1) * h]);
            wide.b_ih[dst] = params.b_ih[src];
            wide.b_hh[dst] = params.b_hh[src];
        }
    }
    wide.w_out[..h].copy_from_slice(&params.w_out);
    wide.b_out = params.b_out;
    wide.to_core::<LSTM_INPUTS, H>()
        .map_err(CompensateError::Params)
}

/// The flight size a model's LSTMs run at: the largest of them (8 without one). An LSTM of a
/// size flight code is not built for is refused, naming the size.
pub fn hidden_size<'a>(
    subs: impl IntoIterator<Item = Option<&'a SubModel>>,
) -> Result<HiddenSize, CompensateError> {
    let mut size = HiddenSize::H8;
    for (params, _, _) in subs.into_iter().flatten().filter_map(SubModel::lstm) {
        let h = params.hidden_size;
        let s = HiddenSize::of_units(h).ok_or(CompensateError::HiddenSize { hidden: h })?;
        size = size.max(s);
    }
    Ok(size)
}

fn core_lstm<const H: usize>(
    params: &LstmParams,
    input_norm: &ZScore,
    target_norm: &ZScore,
) -> Result<NormalisedLstm<H>, CompensateError> {
    let w = padded_core_lstm::<H>(params)?;
    NormalisedLstm::new(
        &w,
        &input_norm.mean,
        &input_norm.std,
        target_norm.mean[0],
        target_norm.std[0],
    )
    .map_err(CompensateError::Flight)
}

/// The flight model of one target (`None`: the constant `absent`) at `H` hidden units.
pub fn target_model<const H: usize>(
    sub: Option<&SubModel>,
    absent: f64,
) -> Result<TargetModel<H>, CompensateError> {
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
    /// The LSTM has a hidden size flight code is not built for.
    HiddenSize { hidden: usize },
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
            CompensateError::HiddenSize { hidden } => write!(
                f,
                "the LSTM has {hidden} hidden units; flight code runs {}",
                crate::settings::fit::hidden_sizes_text()
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
            CompensateError::LstmInputs { .. } | CompensateError::HiddenSize { .. } => None,
        }
    }
}
