//! The plain use of the library: read a test log, fit a compensation model, save it, load it
//! back, compensate a log with it.
//!
//! ```text
//! cargo run -p gyrotherm --release --example fit_and_compensate -- [LOG.csv] [MODEL.json]
//! ```
//!
//! With no log given, a static thermal-chamber run is simulated (profile `seed-shock`) and
//! written to a temporary folder first, so the example runs anywhere. The model is the
//! published comparison's linear fit (bias = c0 + c1·T + c2·dT): fast, and the shape of every
//! other method's use (`FitConfig::new(Method::Residual)` and the other recipe methods).

use std::error::Error;
use std::path::PathBuf;

use gyrotherm::metrics::bias_stability_dph;
use gyrotherm::{
    compensate_log, fit_model, read_log, simulate, write_log, FitConfig, Method, ModelFile,
    NamedLog, ReadOptions, SimConfig,
};

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args_os().skip(1).map(PathBuf::from);
    let log_path = args.next();
    let work = std::env::temp_dir().join(format!("gyrotherm-example-{}", std::process::id()));
    std::fs::create_dir_all(&work)?;
    let model_path = args.next().unwrap_or_else(|| work.join("model.json"));

    // 1. A log: the one given, or a simulated static chamber run.
    let log_path = match log_path {
        Some(p) => p,
        None => {
            let p = work.join("seed-shock.csv");
            let mut cfg = SimConfig::builtin("seed-shock")?;
            cfg.seed = 7;
            write_log(&p, &simulate(&cfg)?)?;
            println!("simulated a static chamber run: {}", p.display());
            p
        }
    };
    let (log, report) = read_log(&log_path, &ReadOptions::default())?;
    println!(
        "read {} samples ({} filled) from {}",
        log.len(),
        report.filled_samples,
        log_path.display()
    );

    // 2. Fit. Static logs train the bias model, rate-table logs the scale-factor model.
    let name = log_path.display().to_string();
    let logs = [NamedLog {
        name: &name,
        log: &log,
    }];
    let fitted = fit_model(&logs, &FitConfig::new(Method::Linear), &|_, _, _| {})?;

    // 3. Save and load the model file (written atomically; loading checks every field).
    fitted.model.save(&model_path)?;
    let model = ModelFile::load(&model_path)?;
    println!("model saved and loaded: {}", model_path.display());

    // 4. Compensate with the flight compensator, sample by sample.
    let out = compensate_log(&model, &log)?;
    let tau_s = 100.0;
    let period = log.sample_period_s();
    let raw = bias_stability_dph(&log.gyro_dps, period, tau_s)?.bias_stability_dph;
    let comp = bias_stability_dph(&out.gyro_comp_dps, period, tau_s)?.bias_stability_dph;
    println!("bias stability (τ = {tau_s} s): raw {raw:.4} °/h, compensated {comp:.4} °/h");
    Ok(())
}
