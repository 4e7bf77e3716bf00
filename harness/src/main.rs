//! `harness`: run the deformation methods on the Botsch–Sorkine tests and write reports/.

use std::process::ExitCode;

fn main() -> ExitCode {
    match harness::cli::run(std::env::args_os()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(harness::cli::EXIT_ERROR)
        }
    }
}
