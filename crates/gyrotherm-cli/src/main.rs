//! `gyrotherm`: thin command-line front end. Parses arguments, calls the library, prints.
//!
//! Exit codes: 0 success (and, with `--spec`, every limit met); 1 ran fine but a `--spec` limit
//! was missed (`evaluate`, `compare`, `report`, `lot add`); 2 error (the message names the
//! file, line and column, and what to do).

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;
mod signals;

/// Remove temperature-induced errors from fiber optic gyroscope (FOG) test logs.
#[derive(Debug, Parser)]
#[command(
    name = "gyrotherm",
    version,
    about,
    long_about = None,
    after_help = "Exit status: 0 success (with --spec: every limit met), 1 a --spec limit missed, 2 error (the message names the file, line and column).\nStart with `gyrotherm demo`; every command has --help."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Simulate, train, compare and print the results table on built-in defaults.
    Demo(cmd::demo::DemoArgs),
    /// Simulate a thermal-chamber test of a FOG and write the log as CSV.
    Simulate(cmd::simulate::SimulateArgs),
    /// Allan deviation (ADEV, OADEV, MDEV, HDEV) of a rate column, with noise terms.
    Allan(cmd::allan::AllanArgs),
    /// Bias, bias stability and (rate-table logs) scale-factor figures of a log.
    Evaluate(cmd::args::EvaluateArgs),
    /// Fit a compensation model (thermal-state, LSTM, linear or polynomial) to test logs.
    Train(cmd::args::TrainArgs),
    /// Apply a fitted model to a log (batch, or --stream on stdin/stdout).
    Compensate(cmd::args::CompensateArgs),
    /// Fit every method on training logs and judge them on a held-out log.
    Compare(cmd::args::CompareArgs),
    /// Write an HTML report with figures for a held-out comparison.
    Report(cmd::args::ReportArgs),
    /// What the training logs cover of a flight's (T, dT) envelope; a chamber profile that
    /// covers it.
    Plan(cmd::plan::PlanArgs),
    /// Check a model file, or re-seal one after a deliberate hand edit.
    Model(cmd::model::ModelArgs),
    /// Write a model as flight code: C99 or a Rust module for gyrotherm-core.
    Export(cmd::export::ExportArgs),
    /// Every setting of train, compensate, allan, evaluate and plan with its default and accepted
    /// values, as JSON (the library's own description; for tests and tools).
    #[command(hide = true)]
    Settings(cmd::settings::SettingsArgs),
    /// Record units judged against a spec in a lot database; list it; report its yield.
    Lot(cmd::lot::LotArgs),
}

fn main() -> ExitCode {
    // The matches are kept to tell a column option given from its default (`compensate`
    // takes a model's own columns unless told otherwise).
    let matches = <Cli as clap::CommandFactory>::command().get_matches();
    let cli = <Cli as clap::FromArgMatches>::from_arg_matches(&matches).unwrap_or_else(|e| {
        e.format(&mut <Cli as clap::CommandFactory>::command())
            .exit()
    });
    signals::remove_temp_files_on_termination();
    let result = match cli.command {
        Command::Demo(a) => cmd::demo::run(a),
        Command::Simulate(a) => cmd::simulate::run(a),
        Command::Allan(a) => cmd::allan::run(a),
        Command::Evaluate(a) => cmd::evaluate::run(a),
        Command::Train(a) => cmd::train::run(a),
        Command::Compensate(a) => cmd::compensate::run(
            a,
            cmd::common::given_columns(matches.subcommand_matches("compensate")),
        ),
        Command::Compare(a) => cmd::compare::run(a),
        Command::Report(a) => cmd::report::run(a),
        Command::Plan(a) => cmd::plan::run(a),
        Command::Model(a) => cmd::model::run(a),
        Command::Export(a) => cmd::export::run(a),
        Command::Settings(a) => cmd::settings::run(a),
        Command::Lot(a) => cmd::lot::run(
            a,
            cmd::common::given_columns(
                matches
                    .subcommand_matches("lot")
                    .and_then(|m| m.subcommand_matches("add")),
            ),
        ),
    };
    match result {
        Ok(code) => code,
        Err(err) => {
            if is_broken_pipe(&err) {
                return ExitCode::SUCCESS;
            }
            eprintln!("gyrotherm: {}", cmd::common::error_message(&err));
            ExitCode::from(2)
        }
    }
}

fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain().any(|e| {
        e.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            || e.downcast_ref::<gyrotherm::csvlog::LogError>()
                .is_some_and(|l| l.kind == gyrotherm::csvlog::LogErrorKind::OutputClosed)
    })
}
