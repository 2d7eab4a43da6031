//! The `termid` command: a thin layer over the library; `anyhow` lives only here.

mod args;
mod compare;
mod diagnose;
mod estimate;
mod figures;
mod identify;
mod identify_model;
mod moments;
mod monte_carlo;
mod new_ship;
mod outline;
mod progress;
mod reproduce;
mod runs;
mod scale;
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
    install_panic_report();
    let cli = args::Cli::parse();
    let command = move || match cli.command {
        args::Command::Identify(cmd) => identify::run(*cmd),
        args::Command::Simulate(cmd) => simulate::run(cmd),
        args::Command::Reproduce(cmd) => reproduce::run(cmd),
        args::Command::Compare(cmd) => compare::run(cmd),
        args::Command::Diagnose(cmd) => diagnose::run(cmd),
        args::Command::Validate(cmd) => validate::run(cmd),
        args::Command::Scale(cmd) => scale::run(cmd),
        args::Command::Moments(cmd) => moments::run(cmd),
        args::Command::Estimate(cmd) => estimate::run(cmd),
        args::Command::NewShip(cmd) => new_ship::run(cmd),
    };
    // The command runs on a worker of the thread pool: the library's parallel passes over
    // the rows then start at once, where from outside the pool every pass would wait for a
    // sleeping worker to wake (≈ 20 µs, a fifth of a 2 505-row fit). Workers get the main
    // thread's 8 MiB stack.
    let result =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            match rayon::ThreadPoolBuilder::new().stack_size(8 << 20).build() {
                Ok(pool) => pool.install(command),
                Err(_) => command(),
            }
        }));
    match result {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(err)) => {
            eprintln!("error: {err:#}");
            ExitCode::from(2)
        }
        // the hook has said what happened; unwinding removed any half-written output
        Err(_) => ExitCode::from(PANIC_EXIT),
    }
}

/// Exit code of a panic (a bug in termid, whatever the input).
const PANIC_EXIT: u8 = 3;

/// A panic is a bug: it is reported as an error with its place, and the process ends even if
/// some thread would wait for the panicking one (a watchdog exits after a few seconds should
/// unwinding not get back to `main`).
fn install_panic_report() {
    std::panic::set_hook(Box::new(|info| {
        // a dependency's panic that termid turns into a located error
        if termid::contain::active() {
            return;
        }
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(no message)".into());
        let place = info.location().map_or(String::new(), |l| format!(" at {}:{}", l.file(), l.line()));
        eprintln!(
            "error: internal error{place}: {message}\n(this is a bug in termid, not in your input: please report it with the command line)"
        );
        std::thread::spawn(|| {
            std::thread::sleep(std::time::Duration::from_secs(5));
            std::process::exit(i32::from(PANIC_EXIT));
        });
    }));
}
