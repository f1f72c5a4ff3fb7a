//! The text the commands print for a comparison and for an evaluation (one gyro, and each
//! axis of an inertial unit).

use std::io::Write;

/// The figures of one column as text (the single-axis output, and each axis's block of a
/// unit log).
pub fn print_evaluation(
    w: &mut dyn Write,
    e: &gyrotherm::metrics::Evaluation,
) -> std::io::Result<()> {
    writeln!(
        w,
        "{} ({} samples, τ0 = {} s)",
        e.column, e.samples, e.sample_period_s
    )?;
    writeln!(w, "bias                 {:>14} °/h", num(e.bias_dph, 6))?;
    writeln!(
        w,
        "bias stability       {:>14} °/h (1σ of {} means of {} s{})",
        num(e.bias_stability_dph, 6),
        e.means,
        e.tau_s,
        if e.stop_segments_only {
            ", stop segments only"
        } else {
            ""
        }
    )?;
    if let Some(r) = &e.scale {
        let opt = |v: Option<f64>| v.map_or("-".to_string(), |x| num(x, 3));
        writeln!(w, "scale factor         {:>14}", num(r.scale_factor, 9))?;
        writeln!(
            w,
            "nonlinearity         {:>14} ppm",
            num(r.nonlinearity_ppm, 3)
        )?;
        writeln!(w, "asymmetry            {:>14} ppm", opt(r.asymmetry_ppm))?;
        writeln!(
            w,
            "SF thermal error     {:>14} ppm (max |K(t) − K_ref|, K_ref = {}, {} rate segments)",
            num(r.sf_thermal_error_ppm, 3),
            num(r.reference_scale, 9),
            r.scale_over_time.len()
        )?;
    }
    Ok(())
}

/// Fixed-point with `prec` decimals for ordinary magnitudes, scientific beyond (a figure of
/// 1e28 °/h is not printed as 29 digits).
fn num(x: f64, prec: usize) -> String {
    if x != 0.0 && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:.prec$e}")
    } else {
        format!("{x:.prec$}")
    }
}
