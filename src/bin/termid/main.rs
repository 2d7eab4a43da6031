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
    // a closed pipe (`termid … | head`) ends the process quietly, as it does other Unix
    // tools, instead of a panic in the next `println!`
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal before any thread starts
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = args::Cli::parse();
    let command = move || match cli.command {
        args::Command::Identify(cmd) => identify::run(*cmd),
        args::Command::Simulate(cmd) => simulate::run(cmd),
        args::Command::Reproduce(cmd) => reproduce::run(cmd),
        args::Command::Compare(cmd) => compare::run(cmd),
        args::Command::Diagnose(cmd) => diagnose::run(cmd),
        args::Command::Validate(cmd) => validate::run(cmd),
    };
    // The command runs on a worker of the thread pool: the library's parallel passes over
    // the rows then start at once, where from outside the pool every pass would wait for a
    // sleeping worker to wake (≈ 20 µs, a fifth of a 2 505-row fit). Workers get the main
    // thread's 8 MiB stack.
    let result = match rayon::ThreadPoolBuilder::new().stack_size(8 << 20).build() {
        Ok(pool) => pool.install(command),
        Err(_) => command(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            ExitCode::from(2)
        }
    }
}
