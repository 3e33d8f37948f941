//! The `inertia` command. Thin glue over the `inertia` library.

use inertia::sim::scenario::{Common, Scenario};
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        None | Some("reproduce") => reproduce(),
        Some("--help" | "-h") => {
            println!("usage: inertia reproduce");
            ExitCode::SUCCESS
        }
        Some(other) => {
            eprintln!("inertia: unknown subcommand `{other}` (try --help)");
            ExitCode::from(2)
        }
    }
}

fn reproduce() -> ExitCode {
    for sc in [Scenario::slew(), Scenario::spin()] {
        match sc.simulate(&Common::paper()) {
            Ok(out) => {
                let max_rho = out
                    .samples
                    .iter()
                    .map(|s| s.rho_nms.norm())
                    .fold(0.0, f64::max);
                let max_w = out
                    .samples
                    .iter()
                    .map(|s| s.omega_rad_s.norm())
                    .fold(0.0, f64::max);
                println!(
                    "{}: {} samples, max |rho| = {max_rho:.3} N m s, max |w| = {max_w:.3} rad/s",
                    sc.name(),
                    out.samples.len()
                );
            }
            Err(e) => {
                eprintln!("inertia: {e}");
                return ExitCode::from(1);
            }
        }
    }
    ExitCode::SUCCESS
}
