//! `contact-sweep` — thin entry point: parse flags, validate them into domain types, run.

use std::process::ExitCode;

use clap::Parser;
use contact_sweep::cli::{self, Cli};

fn main() -> ExitCode {
    let args = Cli::parse();
    // `contact-sweep plan … | head`: a command that only prints ends quietly when its reader
    // goes away, as Unix tools do, instead of panicking on the broken pipe. `run` and `slurm`
    // keep Rust's default (a failed write is an error, not a kill), so a closed reader never
    // costs a batch of computed runs nor the summary written after them (`cli::say`).
    #[cfg(unix)]
    if !matches!(args.command, cli::Command::Run(_) | cli::Command::Slurm(_)) {
        // SAFETY: restoring the default disposition of SIGPIPE before any thread starts.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        }
    }
    match cli::main(args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(cli::exit_code(&e))
        }
    }
}
