//! `harness`: run the deformation methods on the Botsch–Sorkine tests and write reports/.

use std::process::ExitCode;

fn main() -> ExitCode {
    let code = match harness::cli::run(std::env::args_os()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(harness::cli::EXIT_ERROR)
        }
    };
    // The temporary copy of the built-in configuration, when this run needed one.
    harness::paths::remove_built_in_copy();
    code
}
