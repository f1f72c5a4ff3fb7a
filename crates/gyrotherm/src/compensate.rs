//! Apply a fitted model to a log: the ground side of the flight [`Compensator`].
//!
//! Batch compensation runs the same `gyrotherm-core` compensator sample by sample that
//! `compensate --stream` and flight code run, so the numbers are identical by construction.

use gyrotherm_core::compensator::{Compensator, NormalisedLstm, TargetModel, HIDDEN, LSTM_INPUTS};

use crate::csvlog::TestLog;
use crate::model::{ModelFile, SubModel};
use crate::train::params::LstmParams;
use crate::train::zscore::ZScore;

/// Compensated series of one log, one value per sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Compensated {
    /// Predicted bias B, °/s.
    pub bias_dps: Vec<f64>,
    /// Predicted scale factor K, dimensionless.
    pub scale: Vec<f64>,
    /// G = (Ĝ - B) / K, °/s.
    pub gyro_comp_dps: Vec<f64>,
}

/// Widen an LSTM to the flight input count: input columns beyond `input_size` get weight 0.
fn padded_core_lstm(
    params: &LstmParams,
) -> Result<gyrotherm_core::lstm::LstmWeights<LSTM_INPUTS, HIDDEN>, String> {
    let i = params.input_size;
    if i > LSTM_INPUTS {
        return Err(format!(
            "the LSTM reads {i} inputs; flight code takes at most {LSTM_INPUTS}"
        ));
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
}

fn core_lstm(
    params: &LstmParams,
    input_norm: &ZScore,
    target_norm: &ZScore,
) -> Result<NormalisedLstm, String> {
    let w = padded_core_lstm(params)?;
    NormalisedLstm::new(
        &w,
        &input_norm.mean,
        &input_norm.std,
        target_norm.mean[0],
        target_norm.std[0],
    )
    .map_err(|e| e.to_string())
}

/// The flight model of one target (`None`: the constant `absent`).
pub fn target_model(sub: Option<&SubModel>, absent: f64) -> Result<TargetModel, String> {
    let Some(sub) = sub else {
        return Ok(TargetModel::constant(absent));
    };
    let baseline = sub.baseline_core().transpose()?;
    let lstm = match sub {
        SubModel::Lstm {
            params,
            input_norm,
            target_norm,
        }
        | SubModel::Residual {
            params,
            input_norm,
            target_norm,
            ..
        } => Some(core_lstm(params, input_norm, target_norm)?),
        SubModel::Baseline { .. } => None,
    };
    Ok(TargetModel {
        offset: 0.0,
        baseline,
        lstm,
    })
}

/// The flight compensator of a model file (bias 0 °/s and K = 1 where a target is absent).
pub fn compensator(model: &ModelFile) -> Result<Compensator, String> {
    let spec = model.feature_spec()?;
    let bias = target_model(model.bias.as_ref(), 0.0).map_err(|e| format!("bias: {e}"))?;
    let scale = target_model(model.scale.as_ref(), 1.0).map_err(|e| format!("scale: {e}"))?;
    Compensator::new(spec, bias, scale).map_err(|e| e.to_string())
}

/// Compensate a whole log with the flight compensator. The error names the sample.
pub fn compensate_log(model: &ModelFile, log: &TestLog) -> Result<Compensated, String> {
    let mut comp = compensator(model)?;
    let n = log.len();
    let mut out = Compensated {
        bias_dps: Vec::with_capacity(n),
        scale: Vec::with_capacity(n),
        gyro_comp_dps: Vec::with_capacity(n),
    };
    for i in 0..n {
        let c = comp
            .step(log.time_s[i], log.gyro_dps[i], log.temp_c[i])
            .map_err(|e| format!("sample {} (time {} s): {e}", i + 1, log.time_s[i]))?;
        out.bias_dps.push(c.bias_dps);
        out.scale.push(c.scale);
        out.gyro_comp_dps.push(c.rate_dps);
    }
    Ok(out)
}
