//! The command line of the harness (`all`, `run`, `list`): the CLI edge, where errors become `anyhow`
//! messages and exit codes. In the library so the end-to-end tests drive exactly what the binary runs.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::scenario::load_specs;
use crate::suite::{self, SuiteOptions, SURVEY_DIR_ENV};
use anyhow::Context;
use clap::{Args, Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "harness",
    version,
    about = "deformbench: handle-based mesh deformation methods side by side"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run every method on every scenario and write reports/.
    All(Common),
    /// Run chosen methods on one scenario and print the results (writes reports/ like `all`).
    Run {
        /// Method name (repeatable; see `list`).
        #[arg(long = "method", required = true)]
        methods: Vec<String>,
        /// Scenario name (see `list`).
        #[arg(long)]
        scenario: String,
        #[command(flatten)]
        common: Common,
    },
    /// List the registered methods and the scenarios.
    List(Common),
}

#[derive(Args, Clone)]
struct Common {
    /// Directory with the survey's .off/.sel/.def files [env: DEFORM_SURVEY_DIR]. Without it the
    /// procedural look-alikes are used, and every report says so.
    #[arg(long, env = SURVEY_DIR_ENV)]
    survey_dir: Option<PathBuf>,
    /// Configuration directory (methods.toml, scenarios/).
    #[arg(long)]
    configs: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    reports: Option<PathBuf>,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

impl Common {
    fn options(&self, scenarios: Vec<String>, methods: Vec<String>) -> SuiteOptions {
        let root = suite::workspace_root();
        SuiteOptions {
            configs_dir: self.configs.clone().unwrap_or_else(|| root.join("configs")),
            reports_dir: self.reports.clone().unwrap_or_else(|| root.join("reports")),
            survey_dir: self.survey_dir.clone(),
            scenarios,
            methods,
            progress: !self.quiet,
        }
    }
}

/// Exit code of a run in which some case failed (reports are still written).
pub const EXIT_CASE_FAILED: u8 = 1;
/// Exit code of bad input or I/O errors (nothing written).
pub const EXIT_ERROR: u8 = 2;

/// Parse `args` (program name first) and run. `Err` means bad input or I/O failure: the caller prints
/// it and exits with [`EXIT_ERROR`]; argument errors exit inside clap as usual.
pub fn run<I, T>(args: I) -> anyhow::Result<ExitCode>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = Cli::parse_from(args);
    match cli.command {
        Command::All(common) => execute(&common.options(Vec::new(), Vec::new())),
        Command::Run { methods, scenario, common } => execute(&common.options(vec![scenario], methods)),
        Command::List(common) => {
            let options = common.options(Vec::new(), Vec::new());
            println!("methods:");
            for m in methods::registry::METHODS {
                println!("  {:<14} {}", m.name, m.summary);
            }
            println!("scenarios ({}):", options.configs_dir.join("scenarios").display());
            for s in load_specs(&options.configs_dir.join("scenarios"))? {
                println!("  {:<14} {}", s.name, s.description);
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn execute(options: &SuiteOptions) -> anyhow::Result<ExitCode> {
    let run = suite::run(options).context("preparing the run")?;
    crate::report::write_reports(&options.reports_dir, &run.results, &run.scenarios, &run.data_source)
        .context("writing reports")?;
    println!("data: {}", run.data_source);
    println!(
        "{:<12} {:<12} {:>7} {:>10} {:>9} {:>10} {:>6} {:>9} {:>9} {:>10} {:>10}  status",
        "scenario",
        "method",
        "#V",
        "precomp s",
        "bind s",
        "iter ms",
        "iters",
        "E_th deg",
        "E_ph deg",
        "resid/diag",
        "arap/diag"
    );
    let mut failed = 0;
    for r in &run.results {
        println!(
            "{:<12} {:<12} {:>7} {:>10.4} {:>9.4} {:>10.3} {:>6} {:>9.4} {:>9.4} {:>10.2e} {:>10}  {}",
            r.scenario,
            r.method,
            r.vertices,
            r.precompute_s,
            r.bind_s,
            r.median_iteration_ms,
            r.iterations,
            r.e_theta_deg,
            r.e_phi_deg,
            r.handle_residual_over_diag,
            r.rms_to_arap_over_diag.map(|v| format!("{v:.2e}")).unwrap_or_else(|| "-".into()),
            r.status
        );
        if r.status != "ok" {
            failed += 1;
        }
    }
    println!("reports: {}", options.reports_dir.display());
    if failed > 0 {
        eprintln!("error: {failed} case(s) failed (see the status column)");
        return Ok(ExitCode::from(EXIT_CASE_FAILED));
    }
    Ok(ExitCode::SUCCESS)
}
