//! The `termid` command: a thin layer over the library; `anyhow` lives only here.

mod args;
mod compare;
mod diagnose;
mod identify;
mod monte_carlo;
mod progress;
mod reproduce;
mod runs;
mod simulate;
mod validate;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = args::Cli::parse();
    let result = match cli.command {
        args::Command::Identify(cmd) => identify::run(*cmd),
        args::Command::Simulate(cmd) => simulate::run(cmd),
        args::Command::Reproduce(cmd) => reproduce::run(cmd),
        args::Command::Compare(cmd) => compare::run(cmd),
        args::Command::Diagnose(cmd) => diagnose::run(cmd),
        args::Command::Validate(cmd) => validate::run(cmd),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(2)
        }
    }
}
