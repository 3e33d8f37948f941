//! The `inertia` command: thin glue over the `inertia` library.
//!
//! Exit codes:
//!
//! - 0: success;
//! - 2: bad input data or bad usage: one line on standard error, `FILE:LINE: …` naming
//!   the column when the data are at fault, or naming the option;
//! - 3: an I/O failure: an input that cannot be read, an output that cannot be written
//!   (named with its path);
//! - 1: an internal failure (a bug; nothing in a user's data or arguments leads there).
//!
//! With `estimate --json`, a failure also prints `{"error": {"kind", "sample", "line",
//! "message"}}` on standard output (`kind`: the library's `ErrorKind` name, as Python's
//! `DataError.kind` and C's `inertia_last_error_kind`).
//!
//! Every message is one line of at most [`error::MAX_MESSAGE_CHARS`] characters. Output
//! files appear only when a run succeeds ([`output`]).

mod args;
mod config;
mod error;
mod estimate;
mod history;
mod monte_carlo;
mod output;
mod plan;
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
        Command::Plan(a) => plan::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if let Command::Estimate(a) = &cli.command {
                if a.json {
                    println!("{}", e.json());
                }
            }
            eprintln!("inertia: {e}");
            ExitCode::from(e.code())
        }
    }
}
