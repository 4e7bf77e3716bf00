//! `harness`: run the deformation methods on the Botsch–Sorkine tests and write reports/.

use std::process::ExitCode;

fn main() -> ExitCode {
    end_quietly_on_a_closed_pipe();
    match harness::cli::run(std::env::args_os()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(harness::cli::EXIT_ERROR)
        }
    }
}

/// `harness list | head` closes the pipe early: end as Unix tools do (SIGPIPE's default action)
/// instead of the panic Rust's `println!` makes of the write error (Rust ignores SIGPIPE).
fn end_quietly_on_a_closed_pipe() {
    #[cfg(target_os = "linux")]
    // SAFETY: restores a signal's default disposition at start-up, before any thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
