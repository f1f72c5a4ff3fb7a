//! The checks of a unit model file: each axis's sensors and models, and the flight
//! compensator its further sensors build, as [`ImuModel::validate`](super::ImuModel::validate)
//! runs them.

use gyrotherm_core::features::LagOutputs;
use gyrotherm_core::multi::{AxisCompensator, MAX_SENSORS};

use super::{ImuAxis, ImuError, MAX_STREAM_AXES};
use crate::flight_size::{build_sized, FlightAxis, HiddenSize};
use crate::model::{hidden_size, sized_compensator, SubModel, Target};

/// One axis's checks in [`ImuModel::validate`]: its sensors among `temp_cols`, its model, and
/// the flight compensator its further sensors build.
pub(crate) fn axis_checks(temp_cols: &[String], a: &ImuAxis) -> Result<(), ImuError> {
    let distinct = a
        .temps
        .iter()
        .enumerate()
        .all(|(i, t)| !a.temps[..i].contains(t));
    if a.temps.is_empty()
        || a.temps.len() > MAX_SENSORS
        || !distinct
        || !a.temps.iter().all(|t| temp_cols.contains(t))
    {
        return Err(ImuError::Layout(format!(
            "axis {} must read 1 to {MAX_SENSORS} distinct temperature columns among \
             {}",
            a.gyro,
            temp_cols.join(", ")
        )));
    }
    if a.more.len() + 1 != a.temps.len() {
        return Err(ImuError::Layout(format!(
            "axis {}: `more` must hold one entry per further sensor ({} of them)",
            a.gyro,
            a.temps.len() - 1
        )));
    }
    a.model.validate().map_err(|source| ImuError::Axis {
        gyro: a.gyro.clone(),
        source: Box::new(source),
    })?;
    if let Some(f) = &a.fallback {
        if a.more.is_empty() {
            return Err(ImuError::Layout(format!(
                "axis {}: a `fallback` model is only for an axis that reads further sensors \
                 (remove it: this axis's model already reads its one sensor alone)",
                a.gyro
            )));
        }
        f.validate().map_err(|source| ImuError::Axis {
            gyro: a.gyro.clone(),
            source: Box::new(source),
        })?;
    }
    if !a.more.is_empty() {
        // The further sensors' parts must build a flight compensator, and with the first
        // sensor's model keep B and K plausible over the training range, as a single-axis
        // model must.
        let size = axes_hidden_size(std::slice::from_ref(a))?;
        let comp = build_sized!(FlightAxis, size, H => boxed_axis::<H>(temp_cols, a)?);
        let further: Vec<_> = comp
            .further()
            .into_iter()
            .map(|(_, s, b, k)| (s, b, k))
            .collect();
        a.model
            .check_outputs_with_further(comp.first().spec(), &further)
            .map_err(|source| ImuError::Axis {
                gyro: a.gyro.clone(),
                source: Box::new(source),
            })?;
    }
    Ok(())
}

/// Refuse more gyro axes than a unit model may have: the capacity of the flight unit that
/// compensates it ([`MAX_STREAM_AXES`]).
pub(crate) fn check_axis_count(n: usize) -> Result<(), ImuError> {
    if n > MAX_STREAM_AXES {
        return Err(ImuError::Layout(format!(
            "{n} gyro columns: a unit model has at most {MAX_STREAM_AXES} axes (what \
             `compensate` runs); split the unit into models of at most {MAX_STREAM_AXES} gyro \
             columns"
        )));
    }
    Ok(())
}

/// The first name listed twice in `names`, with both positions (1-based).
pub(crate) fn repeated(names: &[String]) -> Option<(&str, usize, usize)> {
    names.iter().enumerate().find_map(|(i, n)| {
        names[..i]
            .iter()
            .position(|m| m == n)
            .map(|j| (n.as_str(), j + 1, i + 1))
    })
}

/// `check` of each axis, on a thread per axis when there are several, in axis order.
pub(crate) fn each_axis<T: Send>(axes: &[ImuAxis], check: impl Fn(&ImuAxis) -> T + Sync) -> Vec<T> {
    if axes.len() < 2 {
        return axes.iter().map(check).collect();
    }
    crate::per_thread::on_threads(axes.len(), |k| check(&axes[k]))
}

/// The LSTM size a unit of `axes` runs at: the largest LSTM of any axis's model or fallback
/// (8 without one); see [`crate::flight_size`].
pub(crate) fn axes_hidden_size(axes: &[ImuAxis]) -> Result<HiddenSize, ImuError> {
    let mut size = HiddenSize::H8;
    for a in axes {
        for m in std::iter::once(&a.model).chain(a.fallback.as_ref()) {
            let s = hidden_size([m.bias.as_ref(), m.scale.as_ref()]).map_err(|source| {
                ImuError::Compensate {
                    gyro: a.gyro.clone(),
                    source: Box::new(source),
                }
            })?;
            size = size.max(s);
        }
    }
    Ok(size)
}

/// [`axis_compensator_in`], boxed in a frame of its own (see [`crate::flight_size`]).
#[inline(never)]
pub(crate) fn boxed_axis<const H: usize>(
    temp_cols: &[String],
    a: &ImuAxis,
) -> Result<Box<AxisCompensator<H>>, ImuError> {
    axis_compensator_in::<H>(temp_cols, a).map(Box::new)
}

/// [`ImuModel::axis_compensator`] with the model's temperature columns `temp_cols`, at `H`
/// hidden units.
fn axis_compensator_in<const H: usize>(
    temp_cols: &[String],
    a: &ImuAxis,
) -> Result<AxisCompensator<H>, ImuError> {
    let index = |t: &String| {
        temp_cols
            .iter()
            .position(|c| c == t)
            .ok_or_else(|| ImuError::Layout(format!("axis {} reads unknown sensor {t}", a.gyro)))
    };
    let layout = |what: String| ImuError::Layout(format!("axis {}: {what}", a.gyro));
    let first = sized_compensator::<H>(&a.model).map_err(|source| ImuError::Compensate {
        gyro: a.gyro.clone(),
        source: Box::new(source),
    })?;
    let spec0 = *first.spec();
    let mut axis = AxisCompensator::new(first, index(&a.temps[0])?);
    for (t, m) in a.temps.iter().skip(1).zip(&a.more) {
        let spec = spec0
            .with_lags(&m.lags_s, LagOutputs::DiffFromT)
            .map_err(|e| layout(format!("sensor {t}: {e}")))?;
        let part = |sub: &Option<SubModel>, what: Target| match sub {
            None => Ok(None),
            Some(
                sub @ SubModel::Baseline {
                    terms,
                    coefficients,
                },
            ) => {
                // A single-axis file's checks of a least-squares part: its terms, one
                // coefficient per term, each finite and plausible.
                sub.validate(spec.n_features())
                    .map_err(|source| ImuError::FurtherSensor {
                        gyro: a.gyro.clone(),
                        temp: t.clone(),
                        part: what,
                        source: Box::new(source),
                    })?;
                crate::baseline::to_core(terms, coefficients)
                    .map(Some)
                    .map_err(|e| layout(format!("sensor {t}, {}: {e}", what.as_str())))
            }
            Some(_) => Err(layout(format!(
                "sensor {t}, {}: a further sensor's part must be a baseline",
                what.as_str()
            ))),
        };
        axis = axis
            .with_sensor(
                index(t)?,
                spec,
                part(&m.bias, Target::Bias)?,
                part(&m.scale, Target::Scale)?,
            )
            .map_err(|e| layout(format!("sensor {t}: {e}")))?;
    }
    if let Some(f) = &a.fallback {
        let f = sized_compensator::<H>(f).map_err(|source| ImuError::Compensate {
            gyro: a.gyro.clone(),
            source: Box::new(source),
        })?;
        axis = axis.with_fallback(f);
    }
    Ok(axis)
}
