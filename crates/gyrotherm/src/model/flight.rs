//! Turning a model file into the flight crate's models: here, beside the model, so that
//! both the load-time plausibility check and `compensate` use it without an import cycle.

use super::*;

use crate::flight_size::HiddenSize;
use gyrotherm_core::compensator::ModelError as FlightModelError;
use gyrotherm_core::compensator::{Compensator, TargetModel, LSTM_INPUTS};
use gyrotherm_core::features::MAX_FEATURES;
use gyrotherm_core::static_model::{StaticBaseline, StaticLstm, StaticTarget};

/// [`sized_compensator`], boxed in a frame of its own (see [`crate::flight_size`]).
#[inline(never)]
pub(crate) fn boxed_compensator<const H: usize>(
    model: &ModelFile,
) -> Result<Box<Compensator<H>>, CompensateError> {
    sized_compensator::<H>(model).map(Box::new)
}

/// The flight compensator of a model file (bias 0 °/s and K = 1 where a target is absent) at
/// `H` hidden units (an LSTM of the model larger than `H` is refused).
pub(crate) fn sized_compensator<const H: usize>(
    model: &ModelFile,
) -> Result<Compensator<H>, CompensateError> {
    let spec = model.feature_spec().map_err(CompensateError::Model)?;
    let in_target = |target| {
        move |e| CompensateError::InTarget {
            target,
            source: Box::new(e),
        }
    };
    let bias = target_model(model.bias.as_ref(), 0.0).map_err(in_target(Target::Bias))?;
    let scale = target_model(model.scale.as_ref(), 1.0).map_err(in_target(Target::Scale))?;
    let limits = model
        .features
        .temp_sensor
        .to_core()
        .map_err(CompensateError::Model)?;
    Compensator::with_limits(spec, bias, scale, limits).map_err(CompensateError::Flight)
}

/// Widen an LSTM to the flight input count and `H` hidden units: input columns beyond
/// `input_size` get weight 0, and so do hidden units beyond `hidden_size` (their state stays
/// 0 and they add nothing to the output; see [`crate::flight_size`]).
pub(crate) fn padded_core_lstm<const H: usize>(
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

/// The flight model of one target (`None`: the constant `absent`) at `H` hidden units: the
/// compensator's own conversion of its flight form ([`static_target`]), so that what runs on
/// the ground is what an export carries.
pub(crate) fn target_model<const H: usize>(
    sub: Option<&SubModel>,
    absent: f64,
) -> Result<TargetModel<H>, CompensateError> {
    static_target(sub, absent)?
        .to_target()
        .map_err(CompensateError::Flight)
}

/// The flight form of one target (`None`: the constant `absent`) at `H` hidden units, as plain
/// data: its baseline's terms, and its LSTM widened to `H` units and the flight input count
/// ([`padded_core_lstm`]) with its normalisation. Both the compensator ([`target_model`]) and
/// the exports are made from it.
pub(crate) fn static_target<const H: usize>(
    sub: Option<&SubModel>,
    absent: f64,
) -> Result<StaticTarget<H>, CompensateError> {
    let Some(sub) = sub else {
        return Ok(StaticTarget::constant(absent));
    };
    let baseline = sub
        .baseline_core()
        .transpose()
        .map_err(CompensateError::Baseline)?
        .map(|b| static_baseline(&b));
    let lstm = match sub.lstm() {
        Some((params, input_norm, target_norm)) => {
            let w = padded_core_lstm::<H>(params)?;
            let n = input_norm.mean.len();
            if n > MAX_FEATURES {
                return Err(CompensateError::LstmInputs { inputs: n });
            }
            let mut mean = [0.0; MAX_FEATURES];
            let mut std = [1.0; MAX_FEATURES];
            mean[..n].copy_from_slice(&input_norm.mean);
            std[..n].copy_from_slice(&input_norm.std);
            Some(StaticLstm {
                w_ih: *w.w_ih(),
                w_hh: *w.w_hh(),
                b_ih: *w.b_ih(),
                b_hh: *w.b_hh(),
                w_out: *w.w_out(),
                b_out: w.b_out(),
                n_inputs: n as u8,
                input_mean: mean,
                input_std: std,
                target_mean: target_norm.mean[0],
                target_std: target_norm.std[0],
            })
        }
        None => None,
    };
    Ok(StaticTarget {
        offset: 0.0,
        baseline,
        lstm,
        lstm_reads_base: sub.reads_base(),
    })
}

/// A core baseline as plain data.
pub(crate) fn static_baseline(b: &gyrotherm_core::baseline::BaselineModel) -> StaticBaseline {
    let mut s = StaticBaseline {
        n_features: b.n_features() as u8,
        n_terms: b.n_terms() as u8,
        powers: [[0; MAX_FEATURES]; gyrotherm_core::baseline::MAX_TERMS],
        coefficients: [0.0; gyrotherm_core::baseline::MAX_TERMS],
    };
    for j in 0..b.n_terms() {
        if let Some((p, c)) = b.term(j) {
            s.powers[j][..p.len()].copy_from_slice(p);
            s.coefficients[j] = c;
        }
    }
    s
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
