//! `gyrotherm export`: write a model as flight code, C99 (`gyrotherm_model.h`,
//! `gyrotherm_model.c`) or a Rust module for gyrotherm-core (`gyrotherm_model.rs`), or as an
//! autopilot's gyro temperature-calibration parameters (ArduPilot `gyro_tcal.parm`, PX4
//! `gyro_tc.params`). See `gyrotherm::export`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context as _};
use gyrotherm::export::{ExportError, ExportTarget, Lang, EXPORT_TARGETS};
use gyrotherm::settings::autopilot::{self as ap, AutopilotSettings, GyroAxis, GYRO_AXES};
use gyrotherm::unit_model::Model;

use super::common::{choice, tell};

#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// Model file written by `gyrotherm train`.
    #[arg(long)]
    pub model: PathBuf,
    /// What to write.
    #[arg(long, required_unless_present = "lang", conflicts_with = "lang",
          value_parser = choice::<ExportTarget>(EXPORT_TARGETS.map(|t| (t.as_str(), t.help()))))]
    pub target: Option<ExportTarget>,
    /// Deprecated spelling of `--target c|rust`, kept for one release.
    #[arg(long, hide = true,
          value_parser = choice::<Lang>([Lang::C, Lang::Rust].map(|l| (l.as_str(), l.help()))))]
    pub lang: Option<Lang>,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// ardupilot, px4: the autopilot's IMU, from 0 (ArduPilot INS_TCAL<N+1>, PX4 TC_G<N>);
    /// default 0.
    #[arg(long, value_name = "N", value_parser = |s: &str| ap::parse_instance(s))]
    pub instance: Option<u8>,
    /// ardupilot, px4: the autopilot axis a single-gyro model fills; the other two get zero
    /// coefficients (a unit model's three axes are X, Y, Z in its column order); default x.
    #[arg(long, value_parser = choice::<GyroAxis>(GYRO_AXES.map(|a| (a.as_str(), ""))))]
    pub axis: Option<GyroAxis>,
    /// px4: the gyro's device id (DEVICE_ID of sensor_gyro, or CAL_GYRO<N>_ID), decimal or
    /// 0x hexadecimal; PX4 applies the parameters to the gyro with this id only.
    #[arg(long, value_name = "ID", value_parser = |s: &str| ap::parse_device_id(s))]
    pub device_id: Option<u32>,
}

impl ExportArgs {
    /// The library's autopilot settings (its defaults where a flag is absent).
    fn autopilot_settings(&self) -> AutopilotSettings {
        let d = AutopilotSettings::default();
        AutopilotSettings {
            instance: self.instance.unwrap_or(d.instance),
            axis: self.axis.unwrap_or(d.axis),
            device_id: self.device_id.or(d.device_id),
        }
    }
}

pub fn run(args: ExportArgs) -> anyhow::Result<ExitCode> {
    let target = match (args.target, args.lang) {
        (Some(t), _) => t,
        (None, Some(l)) => {
            eprintln!(
                "gyrotherm: warning: --lang is deprecated and will be removed: use --target {l}"
            );
            ExportTarget::from(l)
        }
        (None, None) => bail!("give --target"),
    };
    if target.lang().is_some() {
        for (given, flag) in [
            (args.instance.is_some(), "--instance"),
            (args.axis.is_some(), "--axis"),
            (args.device_id.is_some(), "--device-id"),
        ] {
            if given {
                bail!("{flag} is for --target ardupilot or px4, not {target}");
            }
        }
    }
    let model = Model::load(&args.model)?;
    if let Some(w) = model.load_warning(&args.model) {
        eprintln!("gyrotherm: warning: {w}");
    }
    let (told, written) = model.write_export(
        target,
        &args.autopilot_settings(),
        args.axis.is_some(),
        &args.out,
    );
    told.iter().for_each(tell);
    match written {
        Ok(()) => Ok(ExitCode::SUCCESS),
        // A file that cannot be written names itself; anything else is the model's fault.
        Err(e @ ExportError::Io { .. }) => Err(e.into()),
        Err(e) if target.lang().is_some() => Err(e.into()),
        Err(e) => Err(anyhow::Error::new(e))
            .with_context(|| format!("cannot use model {}", args.model.display())),
    }
}
