//! `contact-sweep` — thin entry point: parse flags, validate them into domain types, run.

use std::process::ExitCode;

use clap::Parser;
use contact_sweep::cli::{self, Cli};

fn main() -> ExitCode {
    let args = Cli::parse();
    match cli::main(args) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(cli::exit_code(&e))
        }
    }
}
