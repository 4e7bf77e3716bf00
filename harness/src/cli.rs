//! The command line of the harness (`all`, `run`, `check`, `baseline`, `list`): the CLI edge, where
//! errors become `anyhow` messages and exit codes. In the library so the end-to-end tests drive
//! exactly what the binary runs.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::case::CaseResult;
use crate::metrics::METRICS;
use crate::regression::{BaselineKind, GateOutcome};
use crate::report::{html, plots, render};
use crate::scenario::load_specs;
use crate::shard::Shard;
use crate::suite::{self, SuiteOptions, SURVEY_DIR_ENV};
use crate::{peers, regression, report};
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
    /// Run every method on every scenario, write reports/ and end with the regression check.
    All {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        peers: Peers,
        #[command(flatten)]
        gate: Gate,
        /// Skip the regression check.
        #[arg(long)]
        no_check: bool,
        /// Run part K of N (a job array's task; see the README): a deterministic share of the
        /// scenarios, balanced by their estimated cost. Writes a partial report (results.json and
        /// the result meshes) for `merge`; no plots, figures or regression check.
        #[arg(long, value_name = "K/N")]
        shard: Option<Shard>,
    },
    /// Combine the partial reports of `all --shard K/N` (one directory each, K = 1..N) into the
    /// report one run would have written, ending with the regression check.
    Merge {
        /// The partial report directories.
        #[arg(required = true)]
        partials: Vec<PathBuf>,
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        gate: Gate,
    },
    /// Run chosen methods on one scenario and print the results (writes reports/ like `all`).
    Run {
        /// Method name (repeatable; see `list`).
        #[arg(long = "method", required = true)]
        methods: Vec<String>,
        /// Scenario name (see `list`), or the path of a scenario file.
        #[arg(long)]
        scenario: String,
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        peers: Peers,
    },
    /// Compare reports/results.json with the baseline; exit non-zero naming every regression.
    Check {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        gate: Gate,
    },
    /// Rewrite the baseline from reports/results.json (on purpose: after a change that is meant to
    /// alter results).
    Baseline {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        gate: Gate,
    },
    /// List the registered methods and the scenarios.
    List(Common),
}

#[derive(Args, Clone)]
struct Peers {
    /// Check every result of up to 100K faces for self-intersections with open3d (slow on large
    /// meshes: ~25 s per result on the bumpy plane) and report it in the `self_intersecting` column.
    #[arg(long)]
    self_intersections: bool,
    /// The cross-check Python with open3d (`scripts/python-env` prints it).
    #[arg(long, env = peers::PYTHON_ENV)]
    python: Option<PathBuf>,
}

impl Peers {
    /// The Python to run the peer checks with, if they were asked for.
    fn python(&self) -> anyhow::Result<Option<PathBuf>> {
        if !self.self_intersections {
            return Ok(None);
        }
        match &self.python {
            Some(p) if p.is_file() => Ok(Some(p.clone())),
            Some(p) => anyhow::bail!("--python {}: no such file", p.display()),
            None => anyhow::bail!(
                "--self-intersections needs the cross-check Python with open3d: give --python or set {} \
                 (scripts/python-env sets it up and prints its path)",
                peers::PYTHON_ENV
            ),
        }
    }
}

#[derive(Args, Clone)]
struct Gate {
    /// The regression baseline [default: reports/baselines/survey.json in the workspace for a run on
    /// the survey data, reports/baselines/procedural.json for one on the procedural look-alikes].
    #[arg(long)]
    baseline: Option<PathBuf>,
}

impl Gate {
    /// The baseline `results` are compared with.
    fn path(&self, results: &[CaseResult]) -> PathBuf {
        self.baseline
            .clone()
            .unwrap_or_else(|| BaselineKind::of(results).default_path(&suite::workspace_root()))
    }
}

#[derive(Args, Clone)]
struct Common {
    /// Directory with the survey's .off/.sel/.def files [env: DEFORM_SURVEY_DIR]. Without it the
    /// procedural look-alikes are used, and every report says so.
    #[arg(long, env = SURVEY_DIR_ENV)]
    survey_dir: Option<PathBuf>,
    /// Configuration directory (methods.toml, verdicts.toml, scenarios/).
    #[arg(long)]
    configs: Option<PathBuf>,
    /// Scenario directory [default: scenarios/ in the configuration directory]; e.g.
    /// configs/real-meshes for the real-mesh suite.
    #[arg(long)]
    scenarios: Option<PathBuf>,
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
            scenarios_dir: self.scenarios.clone(),
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
/// Exit code of a run or check that found quality regressions against the baseline.
pub const EXIT_REGRESSION: u8 = 3;

/// Parse `args` (program name first) and run. `Err` means bad input or I/O failure: the caller prints
/// it and exits with [`EXIT_ERROR`]; argument errors exit inside clap as usual.
pub fn run<I, T>(args: I) -> anyhow::Result<ExitCode>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = Cli::parse_from(args);
    match cli.command {
        Command::All { common, peers, gate, no_check, shard } => {
            let options = common.options(Vec::new(), Vec::new());
            if let Some(shard) = shard {
                return run_shard(&options, shard);
            }
            let gate = if no_check { Err("--no-check".to_string()) } else { standard_suite(&options, gate) };
            let run = suite::run(&options).context("preparing the run")?;
            publish(&options, run, peers.python()?, gate)
        }
        Command::Merge { partials, common, gate } => {
            let options = common.options(Vec::new(), Vec::new());
            let run = suite::merge(&options, &partials).context("merging partial reports")?;
            let gate = standard_suite(&options, gate);
            publish(&options, run, None, gate)
        }
        Command::Run { methods, scenario, common, peers } => {
            let options = common.options(vec![scenario], methods);
            let run = suite::run(&options).context("preparing the run")?;
            publish(&options, run, peers.python()?, Err("`run` covers one scenario".to_string()))
        }
        Command::Check { common, gate } => {
            let dir = common.options(Vec::new(), Vec::new()).reports_dir;
            let results = report::read_results(&dir.join("results.json"))?.cases;
            let path = gate.path(&results);
            if !path.is_file() {
                anyhow::bail!("{}: no such baseline", path.display());
            }
            match regression::gate(&path, &results)? {
                GateOutcome::Checked { baseline, findings } => Ok(print_findings(&findings, &baseline)),
                GateOutcome::NotChecked(reason) => anyhow::bail!("{reason}"),
            }
        }
        Command::Baseline { common, gate } => {
            let dir = common.options(Vec::new(), Vec::new()).reports_dir;
            let results = report::read_results(&dir.join("results.json"))?.cases;
            let baseline = regression::baseline_from(&results);
            let path = gate.path(&results);
            regression::write_baseline(&path, &baseline)?;
            println!(
                "baseline: {} cases from {} written to {}",
                baseline.cases.len(),
                dir.display(),
                path.display()
            );
            Ok(ExitCode::SUCCESS)
        }
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

/// Print the gate's findings; the exit code is [`EXIT_REGRESSION`] if any is a regression.
fn print_findings(findings: &[regression::Finding], baseline: &std::path::Path) -> ExitCode {
    let regressions = findings.iter().filter(|f| f.is_regression()).count();
    for f in findings {
        if f.is_regression() {
            eprintln!("regression: {f}");
        } else {
            println!("{f}");
        }
    }
    if regressions > 0 {
        eprintln!("error: {regressions} quality regression(s) against {}", baseline.display());
        ExitCode::from(EXIT_REGRESSION)
    } else {
        println!("check: no quality regression against {}", baseline.display());
        ExitCode::SUCCESS
    }
}

/// The gate of a run with `options`: the committed baselines cover the default configuration
/// (`configs/` and its scenarios); any other run is compared only with a baseline named on purpose.
fn standard_suite(options: &SuiteOptions, gate: Gate) -> Result<Gate, String> {
    let default_configs = suite::workspace_root().join("configs");
    let same = |a: &std::path::Path, b: &std::path::Path| {
        a.canonicalize().ok().zip(b.canonicalize().ok()).is_some_and(|(a, b)| a == b)
    };
    if gate.baseline.is_some() {
        Ok(gate)
    } else if !same(&options.configs_dir, &default_configs) || options.scenarios_dir.is_some() {
        Err(format!(
            "the committed baselines cover the scenarios of {} (name one with --baseline)",
            default_configs.display()
        ))
    } else {
        Ok(gate)
    }
}

/// Run part `shard` of the suite and write its partial report.
fn run_shard(options: &SuiteOptions, shard: Shard) -> anyhow::Result<ExitCode> {
    let run = suite::run_shard(options, shard).context("preparing the run")?;
    for note in &run.notes {
        eprintln!("note: {note}");
    }
    let dir = &options.reports_dir;
    report::write_partial(dir, &run.results, &run.scenarios, &run.data_source, shard)
        .context("writing the partial report")?;
    print_table(&run.results);
    println!(
        "shard {shard}: {} scenario(s), {} case(s); partial report in {} (combine the N parts with `harness merge`)",
        run.scenarios.len(),
        run.results.len(),
        dir.display()
    );
    if run.results.iter().any(|r| r.status.is_failed()) {
        eprintln!("error: some case(s) failed (see the status column)");
        return Ok(ExitCode::from(EXIT_CASE_FAILED));
    }
    Ok(ExitCode::SUCCESS)
}

/// Check the results of `run` with open3d when `peer_python` is given, write every report, and
/// compare with the baseline `gate` names (or say why not); print the table and pick the exit code.
fn publish(
    options: &SuiteOptions,
    mut run: suite::SuiteRun,
    peer_python: Option<PathBuf>,
    gate: Result<Gate, String>,
) -> anyhow::Result<ExitCode> {
    for note in &run.notes {
        eprintln!("note: {note}");
    }
    if let Some(python) = peer_python {
        let answers = peers::self_intersections(&python, &run.results, &run.scenarios)
            .context("self-intersection check (open3d)")?;
        for (r, answer) in run.results.iter_mut().zip(answers) {
            r.self_intersecting = answer;
        }
    }
    let dir = &options.reports_dir;
    report::write_reports(dir, &run.results, &run.scenarios, &run.data_source).context("writing reports")?;
    let mut images = plots::write_plots(dir, &run.results).context("writing plots")?;
    images.extend(render::write_figures(dir, &run.results, &run.scenarios).context("writing figures")?);

    let outcome = match gate {
        Ok(gate) => regression::gate(&gate.path(&run.results), &run.results)?,
        Err(reason) => GateOutcome::NotChecked(reason),
    };
    let table1 = report::render_table1(&run.results);
    html::write_index(
        dir,
        &html::render_index(&run.results, &run.data_source, &images, &table1, &outcome, &run.notes),
    )
    .context("writing index.html")?;

    println!("data: {}", run.data_source);
    print_table(&run.results);
    println!("reports: {} (open index.html)", options.reports_dir.display());
    let gate_code = match &outcome {
        GateOutcome::Checked { baseline, findings } => print_findings(findings, baseline),
        GateOutcome::NotChecked(reason) => {
            println!("regression check skipped: {reason}");
            ExitCode::SUCCESS
        }
    };
    let suspect = run.results.iter().filter(|r| r.status.is_suspect()).count();
    if suspect > 0 {
        println!("{suspect} case(s) suspect (see the status column and the reasons there)");
    }
    let failed = run.results.iter().filter(|r| r.status.is_failed()).count();
    if failed > 0 {
        eprintln!("error: {failed} case(s) failed (see the status column)");
        return Ok(ExitCode::from(EXIT_CASE_FAILED));
    }
    Ok(gate_code)
}

/// The results table on stdout: one row per case, the timings, every metric of the table, the status.
fn print_table(results: &[CaseResult]) {
    let width = |label: &str| label.chars().count().max(9);
    let mut header = format!(
        "{:<14} {:<16} {:>7} {:>9} {:>8} {:>9} {:>6}",
        "scenario", "method", "#V", "precomp s", "bind s", "iter ms", "iters"
    );
    for spec in &METRICS {
        header.push_str(&format!(" {:>w$}", spec.label, w = width(spec.label)));
    }
    println!("{header}  status");
    for r in results {
        let mut line = format!(
            "{:<14} {:<16} {:>7} {:>9.4} {:>8.4} {:>9.3} {:>6}",
            r.scenario, r.method, r.vertices, r.precompute_s, r.bind_s, r.median_iteration_ms, r.iterations
        );
        for spec in &METRICS {
            line.push_str(&format!(
                " {:>w$}",
                spec.format.apply(r.quality.get(spec.metric)),
                w = width(spec.label)
            ));
        }
        println!("{line}  {}", r.status);
    }
}
