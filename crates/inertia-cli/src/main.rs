//! The `inertia` command: thin glue over the `inertia` library.
//!
//! Exit codes: 0 success, 2 bad usage or bad data, 1 internal failure.

mod args;
mod config;
mod error;
mod estimate;
mod history;
mod monte_carlo;
mod plot;
mod reproduce;
mod runner;
mod simulate;

use args::{Cli, Command};
use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Usage errors: clap prints them and exits with code 2.
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Simulate(a) => simulate::run(a),
        Command::Estimate(a) => estimate::run(a),
        Command::Reproduce(a) => reproduce::run(a),
        Command::MonteCarlo(a) => monte_carlo::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("inertia: {e}");
            ExitCode::from(e.code())
        }
    }
}
