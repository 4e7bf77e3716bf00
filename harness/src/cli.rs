//! The command line of the harness (`all`, `run`, `merge`, `check`, `baseline`, `compare`, `list`,
//! `history`): the CLI edge, where errors become `anyhow` messages and exit codes. In the library so the end-to-end tests drive
//! exactly what the binary runs.

use std::path::PathBuf;
use std::process::ExitCode;

use crate::comparison::ComparedRun;
use crate::config::PeerSetup;
use crate::metrics::METRICS;
use crate::paths::SURVEY_DIR_ENV;
use crate::pipeline::{self, GateRequest, Outcome, PublishOptions};
use crate::record::CaseResult;
use crate::regression::{self, GateOutcome};
use crate::report::{MeshFormat, MeshOutput};
use crate::scenario::load_specs;
use crate::shard::Shard;
use crate::staged_dir::StagedDir;
use crate::suite::{self, SuiteOptions};
use anyhow::Context;
use clap::{Args, Parser, Subcommand};

mod history;

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
        meshes: Meshes,
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
        #[command(flatten)]
        force: Force,
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
        meshes: Meshes,
        #[command(flatten)]
        gate: Gate,
        /// The parts ran with --sweeps: report the sweep points in the order one run would.
        #[arg(long)]
        sweeps: bool,
    },
    /// Run chosen methods on chosen scenarios and print the results (writes reports/ like `all`).
    Run {
        /// Method name (repeatable; see `list`). Without it each scenario runs the methods its
        /// `methods = [...]` lists; a scenario that lists none is then an error naming it (give
        /// --method, or run every method with `all --scenarios DIR`).
        #[arg(long = "method")]
        methods: Vec<String>,
        /// Scenario name (see `list`), or the path of a scenario file (repeatable).
        #[arg(long = "scenario", required = true)]
        scenarios: Vec<String>,
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        peers: Peers,
        #[command(flatten)]
        meshes: Meshes,
        #[command(flatten)]
        force: Force,
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
    /// Compare run B with run A (report directories or results.json files): per case and method the
    /// ratio of the timing medians, judged against their spread (`--repeat`), and every quality
    /// change against the gate's tolerances; printed and written as compare.md and compare.html.
    Compare {
        /// The earlier run, or the reference.
        a: PathBuf,
        /// The run judged against A.
        b: PathBuf,
        /// Where compare.md and compare.html go [default: ./reports/comparison].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Exit non-zero when some case is slower (exit 4) or worse in quality (exit 3).
        #[arg(long, value_enum, value_delimiter = ',')]
        fail_on: Vec<FailOn>,
        /// The smallest change of a median, as a fraction, that is called slower or faster even when
        /// the min–max ranges do not overlap.
        #[arg(long, default_value_t = crate::comparison::DEFAULT_MIN_CHANGE)]
        min_change: f64,
    },
    /// Judge the labelled verdict set (known-good and known-bad results, README "Labelled verdict
    /// set") by verdicts.toml and print the precision/recall table per rule kind; exit 1 when a bad
    /// case misses one of its expected kinds or more than 2% of the good cases are flagged.
    VerdictCheck {
        /// The set's directory [default: labelled/ in the configuration directory].
        #[arg(long)]
        labelled: Option<PathBuf>,
        /// Also run the `[[real]]` cases: the suite's methods on their scenarios (minutes).
        #[arg(long)]
        real: bool,
        #[command(flatten)]
        common: Common,
    },
    /// List the registered methods and the scenarios.
    List(Common),
    /// The configuration built into this binary (used where there is no ./configs).
    Configs {
        #[command(subcommand)]
        command: ConfigsCommand,
    },
    /// Results across commits: record runs into the history store, run commits, show the
    /// timelines with their steps, bisect a step (README, "Results across commits").
    History {
        #[command(subcommand)]
        command: history::HistoryCommand,
    },
    /// Run the whole method protocol once on a tiny built-in mesh (hello, precompute, two binds
    /// and solves, quit) and say what is wrong in plain words, with the times (docs/protocol.md);
    /// exit 0 when the method speaks the protocol. With --methods FILE for your own method.
    CheckMethod {
        /// The method's name (see `list`).
        name: String,
        #[command(flatten)]
        common: Common,
        /// The Python for `${DEFORMBENCH_PYTHON}` [env: DEFORMBENCH_PYTHON].
        #[arg(long)]
        python: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum ConfigsCommand {
    /// Write the built-in project files into DIR (created if missing): configs/, the committed
    /// baselines (reports/baselines/), the Python scripts (python/, external/). Run `harness` from
    /// DIR afterwards to use them as edited. Overwrites nothing: a file already there is an error.
    Export {
        /// The directory to write into.
        dir: PathBuf,
    },
}

/// What makes `compare` exit non-zero.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum FailOn {
    /// Some case's total time is slower beyond its spread.
    Slower,
    /// Some case is worse in quality, failed or turned suspect or unfinished.
    Worse,
}

#[derive(Args, Clone)]
struct Peers {
    /// Add the peer libraries' methods of configs/peers.toml (libigl's ARAP and biharmonic
    /// deformation, open3d's ARAP) to every scenario that does not restrict its methods. They run
    /// in the cross-check Python (--python); without it the run says that peers were not run.
    #[arg(long)]
    peers: bool,
    /// Check every result of up to 100K faces for self-intersections with open3d (slow on large
    /// meshes: ~25 s per result on the bumpy plane) and report it in the `self_intersecting` column.
    #[arg(long)]
    self_intersections: bool,
    /// Add the parameter sweeps of configs/sweeps.toml (each value of a swept parameter one more
    /// variant, `isolines[isolines=10]`) on the scenarios it names, and draw each test's
    /// quality–time plots and budget table (README "Sweeps").
    #[arg(long)]
    sweeps: bool,
    /// The cross-check Python with libigl and open3d (`scripts/python-env` prints it) [env:
    /// DEFORMBENCH_PYTHON; empty counts as unset].
    #[arg(long)]
    python: Option<PathBuf>,
}

impl Peers {
    /// The peer methods' file and Python when `--peers` was given and the Python is there; `Err`
    /// says why peers are not run.
    fn peer_methods(&self, configs_dir: &std::path::Path) -> Option<Result<PeerSetup, String>> {
        if !self.peers {
            return None;
        }
        Some(match &self.python_path() {
            Some(p) if p.is_file() => Ok(PeerSetup { file: configs_dir.join("peers.toml"), python: p.clone() }),
            Some(p) => Err(format!("peers not run: the Python {} does not exist", p.display())),
            None => Err(format!(
                "peers not run: they need the cross-check Python with libigl and open3d; give --python or set {} \
                 (scripts/python-env sets it up and prints its path)",
                crate::paths::PYTHON_ENV
            )),
        })
    }

    /// `--python`, else `DEFORMBENCH_PYTHON` when set and not empty.
    fn python_path(&self) -> Option<PathBuf> {
        self.python.clone().or_else(|| path_from_env(crate::paths::PYTHON_ENV))
    }

    /// The Python to run the peer checks with, if they were asked for.
    fn python(&self) -> anyhow::Result<Option<PathBuf>> {
        if !self.self_intersections {
            return Ok(None);
        }
        match &self.python_path() {
            Some(p) if p.is_file() => Ok(Some(p.clone())),
            Some(p) => anyhow::bail!("--python {}: no such file", p.display()),
            None => anyhow::bail!(
                "--self-intersections needs the cross-check Python with open3d: give --python or set {} \
                 (scripts/python-env sets it up and prints its path)",
                crate::paths::PYTHON_ENV
            ),
        }
    }
}

#[derive(Args, Clone)]
struct Force {
    /// Run scenarios whose estimated memory (the mesh after `refine`, or `vertices`, times what its
    /// methods need per vertex) exceeds the memory available (MemAvailable); without it they are
    /// refused, exit code 2, before their mesh is loaded.
    #[arg(long)]
    force: bool,
}

#[derive(Args, Clone)]
struct Gate {
    /// The regression baseline [default: the committed reports/baselines/survey.json beside the
    /// configuration (./ or built in) for a run on the survey data, procedural.json for one on the
    /// procedural look-alikes].
    #[arg(long)]
    baseline: Option<PathBuf>,
}

#[derive(Args, Clone)]
struct Common {
    /// Directory with the survey's .off/.sel/.def files [env: DEFORM_SURVEY_DIR]. Without it the
    /// procedural look-alikes are used, and every report says so.
    #[arg(long)]
    survey_dir: Option<PathBuf>,
    /// Configuration directory (methods.toml, verdicts.toml, scenarios/) [default: ./configs when it
    /// holds methods.toml, else the configuration built into this binary; `configs export DIR`
    /// writes that out].
    #[arg(long)]
    configs: Option<PathBuf>,
    /// A method file of your own, in the methods.toml format (paths relative to it), added on top
    /// of the configuration's methods; repeatable [env: DEFORMBENCH_METHODS=a.toml:b.toml].
    #[arg(long = "methods", value_name = "FILE")]
    method_files: Vec<PathBuf>,
    /// Scenario directory [default: scenarios/ in the configuration directory]; e.g.
    /// configs/real-meshes for the real-mesh suite.
    #[arg(long)]
    scenarios: Option<PathBuf>,
    /// Output directory [default: ./reports].
    #[arg(long)]
    reports: Option<PathBuf>,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
    /// Worker threads of every method: our methods' thread pool, and OMP_NUM_THREADS,
    /// OPENBLAS_NUM_THREADS, MKL_NUM_THREADS and IGL_NUM_THREADS of external programs
    /// [default: the logical cores shared among the --jobs, at least 1]. `--threads 1` is like for
    /// like with single-threaded peers.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    threads: Option<u32>,
    /// Cases run at a time, each with its own --threads workers (for machines with many cores;
    /// J x threads should not exceed the logical cores). Concurrent cases disturb each other's
    /// timings: see the README, "Timings".
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    jobs: u32,
    /// Run the suite in N rounds: the first measures every case, each later one times every case
    /// again with a fresh method instance (a fresh process for an external method). Timing columns
    /// give the median with min and max; the measures come from the first round, and a later result
    /// that is not bitwise the first makes the case `suspect: non-deterministic`.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    repeat: u32,
}

#[derive(Args, Clone)]
struct Meshes {
    /// Format of the result meshes in reports/meshes/.
    #[arg(long, value_enum, default_value_t = MeshFormat::Glb)]
    mesh_format: MeshFormat,
    /// Also write the result meshes of scenarios that say `result_meshes = false` (the resolution
    /// sweeps).
    #[arg(long)]
    every_mesh: bool,
}

impl Meshes {
    fn output(&self) -> MeshOutput {
        MeshOutput { format: self.mesh_format, every_scenario: self.every_mesh }
    }
}

impl Common {
    fn options(
        &self,
        scenarios: Vec<String>,
        methods: Vec<String>,
        command_line: &[String],
    ) -> anyhow::Result<SuiteOptions> {
        let configs_dir = match &self.configs {
            Some(dir) => dir.clone(),
            None => {
                let project = crate::paths::project_files()?;
                if let crate::paths::ProjectFiles::BuiltIn(_) = project {
                    eprintln!("note: {}", project.describe());
                }
                project.root().join("configs")
            }
        };
        Ok(SuiteOptions {
            configs_dir,
            scenarios_dir: self.scenarios.clone(),
            reports_dir: self.reports.clone().unwrap_or_else(crate::paths::default_reports_dir),
            survey_dir: self.survey_dir.clone().or_else(|| path_from_env(SURVEY_DIR_ENV)),
            scenarios,
            methods,
            peers: None,
            sweeps: None,
            method_files: if self.method_files.is_empty() {
                std::env::var_os(METHODS_ENV)
                    .map(|v| std::env::split_paths(&v).filter(|p| !p.as_os_str().is_empty()).collect())
                    .unwrap_or_default()
            } else {
                self.method_files.clone()
            },
            python: path_from_env(crate::paths::PYTHON_ENV),
            threads: self
                .threads
                .map_or_else(|| crate::threads::default_threads(self.jobs as usize), |t| t as usize),
            jobs: self.jobs as usize,
            command_line: command_line.to_vec(),
            repetitions: self.repeat as usize,
            progress: !self.quiet,
            force: false,
            provided: Vec::new(),
        })
    }
}

/// Exit code of a run in which some case failed (reports are still written).
pub const EXIT_CASE_FAILED: u8 = 1;
/// Exit code of bad input or I/O errors (nothing written).
pub const EXIT_ERROR: u8 = 2;
/// Exit code of a run or check that found quality regressions against the baseline (and of
/// `compare --fail-on worse` that found a worse case).
pub const EXIT_REGRESSION: u8 = 3;
/// Exit code of `compare --fail-on slower` that found a slower case.
pub const EXIT_SLOWER: u8 = 4;

/// Parse `args` (program name first) and run. `Err` means bad input or I/O failure: the caller prints
/// it and exits with [`EXIT_ERROR`]; argument errors exit inside clap as usual.
/// Method files added by default when `--methods` is not given, separated by `:`.
pub const METHODS_ENV: &str = "DEFORMBENCH_METHODS";

/// The path in environment variable `name`, unless it is unset or empty (`VAR=` in a shell means
/// "no value", not "the current directory"). Read here rather than by clap, which refuses an empty
/// value as a missing one.
fn path_from_env(name: &str) -> Option<PathBuf> {
    std::env::var_os(name).filter(|v| !v.is_empty()).map(PathBuf::from)
}

pub fn run<I, T>(args: I) -> anyhow::Result<ExitCode>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let args: Vec<std::ffi::OsString> = args.into_iter().map(Into::into).collect();
    let command_line: Vec<String> = args.iter().map(|a| a.to_string_lossy().into_owned()).collect();
    let cli = Cli::parse_from(args);
    match cli.command {
        Command::All { common, peers, meshes, gate, no_check, shard, force } => {
            all(common, peers, meshes, gate, no_check, shard, force, &command_line)
        }
        Command::Merge { partials, common, meshes, gate, sweeps } => {
            let mut options = common.options(Vec::new(), Vec::new(), &command_line)?;
            options.sweeps = sweeps.then(|| options.configs_dir.join("sweeps.toml"));
            let (staging, staged_options) = staged(&options)?;
            let run = suite::merge(&staged_options, &partials).context("merging partial reports")?;
            let gate = GateRequest::for_suite(&options, gate.baseline);
            let publish = PublishOptions { peer_python: None, meshes: meshes.output() };
            publish_and_print(&staged_options, staging, run, &publish, gate)
        }
        Command::Run { methods, scenarios, common, peers, meshes, force } => {
            run_chosen(methods, scenarios, common, peers, meshes, force, &command_line)
        }
        Command::Check { common, gate } => {
            let dir = common.options(Vec::new(), Vec::new(), &command_line)?.reports_dir;
            match pipeline::check(&dir, gate.baseline.as_deref())? {
                GateOutcome::Checked { baseline, findings } => Ok(print_findings(&findings, &baseline)),
                GateOutcome::NotChecked(reason) => anyhow::bail!("{reason}"),
            }
        }
        Command::Baseline { common, gate } => {
            let dir = common.options(Vec::new(), Vec::new(), &command_line)?.reports_dir;
            let (path, cases) = pipeline::write_baseline(&dir, gate.baseline.as_deref())?;
            println!("baseline: {cases} cases from {} written to {}", dir.display(), path.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare { a, b, out, fail_on, min_change } => compare(&a, &b, out, &fail_on, min_change),
        Command::CheckMethod { name, common, python } => check_method(&name, common, python, &command_line),
        Command::History { command } => history::run(command),
        Command::Configs { command: ConfigsCommand::Export { dir } } => {
            let written = crate::paths::export_built_in(&dir)?;
            println!(
                "{} files written to {} (configs/, reports/baselines/, python/, external/); run harness from there \
                 to use them",
                written.len(),
                dir.display()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::VerdictCheck { labelled, real, common } => {
            verdict_check(labelled, real, common, &command_line)
        }
        Command::List(common) => list(common, &command_line),
    }
}

/// `verdict-check`: the labelled set judged, its table printed.
fn verdict_check(
    labelled: Option<PathBuf>,
    real: bool,
    common: Common,
    command_line: &[String],
) -> anyhow::Result<ExitCode> {
    use crate::labelled::{judge_all, real::judge_real, tally, DataDirs, LabelledSet, Tally};
    let options = common.options(Vec::new(), Vec::new(), command_line)?;
    let dir = labelled.unwrap_or_else(|| options.configs_dir.join("labelled"));
    let rules = measures::VerdictRules::load(&options.configs_dir.join("verdicts.toml"))?;
    let set = LabelledSet::load(&dir)?;
    let dirs = DataDirs { survey: options.survey_dir.clone() };
    let (mut judged, mut skipped) = judge_all(&set, &rules, &dirs)?;
    if real {
        let catalog = crate::config::MethodCatalog::load(&options.configs_dir.join("methods.toml"))?;
        let (j, s) = judge_real(&set.real, &catalog, &rules, &dirs)?;
        judged.extend(j);
        skipped.extend(s);
    }
    for s in &skipped {
        println!("skipped: {}: {}", s.name, s.reason);
    }
    print!("{}", tally::case_lines(&judged));
    let tally = Tally::of(&judged, &skipped);
    println!("\n{}", tally.table());
    for (name, missed) in &tally.bad_missed {
        println!("flagged, but not as expected: {name}: missed {}", missed.join(", "));
    }
    let good_ok = tally.good_flagged_share() <= 0.02;
    if !good_ok {
        println!("good cases flagged: {}", tally.good_flagged.join("; "));
    }
    for name in &tally.bad_unflagged {
        println!("bad case not flagged: {name}");
    }
    Ok(if tally.bad_unflagged.is_empty() && good_ok { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// `all`: every method on every scenario, published and gated (or one shard of it).
#[allow(clippy::too_many_arguments)]
fn all(
    common: Common,
    peers: Peers,
    meshes: Meshes,
    gate: Gate,
    no_check: bool,
    shard: Option<Shard>,
    force: Force,
    command_line: &[String],
) -> anyhow::Result<ExitCode> {
    let mut options = common.options(Vec::new(), Vec::new(), command_line)?;
    options.force = force.force;
    options.python = peers.python_path();
    let skipped_peers = options.add_peers(peers.peer_methods(&options.configs_dir));
    options.sweeps = peers.sweeps.then(|| options.configs_dir.join("sweeps.toml"));
    let (staging, staged_options) = staged(&options)?;
    if let Some(shard) = shard {
        return run_shard(&staged_options, staging, shard);
    }
    let gate = if no_check {
        GateRequest::Skip("--no-check".to_string())
    } else {
        GateRequest::for_suite(&options, gate.baseline)
    };
    let publish = PublishOptions { peer_python: peers.python()?, meshes: meshes.output() };
    let mut run = suite::run(&staged_options).context("preparing the run")?;
    run.notes.extend(skipped_peers);
    publish_and_print(&staged_options, staging, run, &publish, gate)
}

/// `run`: the chosen scenarios and methods, published without the gate.
fn run_chosen(
    methods: Vec<String>,
    scenarios: Vec<String>,
    common: Common,
    peers: Peers,
    meshes: Meshes,
    force: Force,
    command_line: &[String],
) -> anyhow::Result<ExitCode> {
    let mut options = common.options(scenarios, methods, command_line)?;
    options.force = force.force;
    if options.methods.is_empty() {
        suite::require_listed_methods(&options)?;
    }
    options.python = peers.python_path();
    let skipped_peers = options.add_peers(peers.peer_methods(&options.configs_dir));
    options.sweeps = peers.sweeps.then(|| options.configs_dir.join("sweeps.toml"));
    let publish = PublishOptions { peer_python: peers.python()?, meshes: meshes.output() };
    let (staging, staged_options) = staged(&options)?;
    let mut run = suite::run(&staged_options).context("preparing the run")?;
    run.notes.extend(skipped_peers);
    publish_and_print(
        &staged_options,
        staging,
        run,
        &publish,
        GateRequest::Skip("`run` covers chosen scenarios and methods".to_string()),
    )
}

/// `compare A B`: two runs side by side, written to `out`; the exit code `fail_on` asks for.
fn compare(
    a: &std::path::Path,
    b: &std::path::Path,
    out: Option<PathBuf>,
    fail_on: &[FailOn],
    min_change: f64,
) -> anyhow::Result<ExitCode> {
    anyhow::ensure!(
        (0.0..1.0).contains(&min_change),
        "--min-change {min_change}: a fraction in [0, 1), e.g. 0.05 for 5%"
    );
    let (a, b) = (ComparedRun::read(a)?, ComparedRun::read(b)?);
    let comparison = crate::comparison::compare(&a, &b, min_change);
    let out = out.unwrap_or_else(|| crate::paths::current_dir_join("reports/comparison"));
    crate::report::write_comparison(&out, &comparison)
        .with_context(|| format!("writing the comparison to {}", out.display()))?;
    // The warnings head the printed markdown.
    println!("{}", crate::report::run_comparison::render_markdown(&comparison));
    println!("comparison: {} (compare.md, compare.html)", out.display());
    let tally = comparison.tally();
    if fail_on.contains(&FailOn::Worse) && tally.worse > 0 {
        eprintln!("error: {} case(s) worse in quality", tally.worse);
        return Ok(ExitCode::from(EXIT_REGRESSION));
    }
    if fail_on.contains(&FailOn::Slower) && tally.slower > 0 {
        eprintln!("error: {} case(s) slower", tally.slower);
        return Ok(ExitCode::from(EXIT_SLOWER));
    }
    Ok(ExitCode::SUCCESS)
}

/// `check-method NAME`: the protocol check of one method ([`crate::method_check`]).
fn check_method(
    name: &str,
    common: Common,
    python: Option<PathBuf>,
    command_line: &[String],
) -> anyhow::Result<ExitCode> {
    let mut options = common.options(Vec::new(), Vec::new(), command_line)?;
    if python.is_some() {
        options.python = python;
    }
    let catalog = suite::load_catalog(&options)?;
    let method = catalog.find(name).map_err(|m| anyhow::anyhow!("{m}"))?;
    println!(
        "checking `{name}` ({}) on a {}-vertex bar:",
        method.summary,
        crate::method_check::CHECK_VERTICES
    );
    let result = crate::method_check::check(method);
    for line in &result.lines {
        println!("  {line}");
    }
    if result.passed {
        println!("`{name}` speaks the protocol");
        Ok(ExitCode::SUCCESS)
    } else {
        println!("`{name}` does not speak the protocol yet: see the FAIL line above and docs/protocol.md");
        Ok(ExitCode::from(EXIT_CASE_FAILED))
    }
}

/// `list`: the configuration's methods and scenarios, in aligned columns.
fn list(common: Common, command_line: &[String]) -> anyhow::Result<ExitCode> {
    let options = common.options(Vec::new(), Vec::new(), command_line)?;
    println!("methods ({}):", options.configs_dir.join("methods.toml").display());
    let catalog = suite::load_catalog(&options)?;
    let methods: Vec<Vec<String>> = catalog
        .methods()
        .iter()
        .map(|m| {
            let what = match &m.unavailable {
                None => m.summary.clone(),
                Some(why) => format!("UNAVAILABLE: {why} ({})", m.file.display()),
            };
            vec![m.name.clone(), m.origin.label().to_string(), what]
        })
        .collect();
    columns(&methods).iter().for_each(|line| println!("{line}"));
    println!("scenarios ({}):", options.configs_dir.join("scenarios").display());
    let scenarios: Vec<Vec<String>> = load_specs(&options.configs_dir.join("scenarios"))?
        .into_iter()
        .map(|s| vec![s.name, s.description])
        .collect();
    columns(&scenarios).iter().for_each(|line| println!("{line}"));
    Ok(ExitCode::SUCCESS)
}

/// `rows` as lines of aligned columns: indented by two, each column but the last as wide as its
/// widest cell, two spaces between columns.
fn columns(rows: &[Vec<String>]) -> Vec<String> {
    let count = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> = (0..count)
        .map(|c| rows.iter().filter_map(|r| r.get(c)).map(|cell| cell.chars().count()).max().unwrap_or(0))
        .collect();
    rows.iter()
        .map(|row| {
            let mut line = String::from(" ");
            for (cell, width) in row.iter().zip(&widths) {
                line.push_str(&format!(" {cell:<width$} "));
            }
            line.trim_end().to_string()
        })
        .collect()
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

/// `options` with its report directory replaced by a staging directory beside it ([`StagedDir`]):
/// the run writes its logs and reports there, and [`StagedDir::publish`] swaps the whole directory
/// in at the end, so a run killed or failed at any moment leaves the old report or the new one.
fn staged(options: &SuiteOptions) -> anyhow::Result<(StagedDir, SuiteOptions)> {
    let staging = StagedDir::begin(&options.reports_dir)?;
    let mut staged = options.clone();
    staged.reports_dir = staging.path().to_path_buf();
    Ok((staging, staged))
}

/// Run part `shard` of the suite and write its partial report (`options` writing into `staging`).
fn run_shard(options: &SuiteOptions, staging: StagedDir, shard: Shard) -> anyhow::Result<ExitCode> {
    let run = suite::run_shard(options, shard).context("preparing the run")?;
    for note in &run.notes {
        eprintln!("note: {note}");
    }
    let failed = pipeline::publish_partial(options, &run, shard).context("writing the partial report")?;
    let target = staging.target().to_path_buf();
    staging.publish().context("publishing the partial report")?;
    print_table(&run.results);
    println!(
        "shard {shard}: {} scenario(s), {} case(s); partial report in {} (combine the N parts with `harness merge`)",
        run.scenarios.len(),
        run.results.len(),
        target.display()
    );
    for line in run.input_summary() {
        println!("{line}");
    }
    if failed > 0 {
        eprintln!("error: {failed} case(s) failed: {} (see the status column)", failed_cases(&run.results));
        return Ok(ExitCode::from(EXIT_CASE_FAILED));
    }
    Ok(ExitCode::SUCCESS)
}

/// Publish `run` ([`pipeline::publish`] into `staging`, which `options` write into, then swapped
/// in), print its notes, table, phase times and gate findings, and pick the exit code:
/// [`EXIT_CASE_FAILED`] over [`EXIT_REGRESSION`] over success.
fn publish_and_print(
    options: &SuiteOptions,
    staging: StagedDir,
    mut run: suite::SuiteRun,
    publish: &PublishOptions,
    gate: GateRequest,
) -> anyhow::Result<ExitCode> {
    for note in &run.notes {
        eprintln!("note: {note}");
    }
    // The reports' own parallel work (the figures) keeps to the run's threads too.
    let pool = crate::threads::pool(options.threads)?;
    let outcome =
        pool.install(|| pipeline::publish(options, &mut run, publish, gate)).context("publishing the run")?;
    let target = staging.target().to_path_buf();
    staging.publish().context("publishing the report directory")?;
    println!("data: {}", run.data_source);
    println!("{}", run.provenance.summary());
    print_table(&run.results);
    if !outcome.arap_against_libigl.is_empty() {
        println!("\n{}", outcome.arap_against_libigl);
    }
    print_phases(&outcome);
    println!("reports: {} (open index.html)", target.display());
    let gate_code = match &outcome.gate {
        GateOutcome::Checked { baseline, findings } => print_findings(findings, baseline),
        GateOutcome::NotChecked(reason) => {
            println!("regression check skipped: {reason}");
            ExitCode::SUCCESS
        }
    };
    if outcome.suspect > 0 {
        println!("{} case(s) suspect (see the status column and the reasons there)", outcome.suspect);
    }
    if outcome.unfinished > 0 {
        println!(
            "{} case(s) unfinished: stopped at their iteration cap, judged on an iterate (see the status column)",
            outcome.unfinished
        );
    }
    for line in run.input_summary() {
        println!("{line}");
    }
    if outcome.failed > 0 {
        eprintln!(
            "error: {} case(s) failed: {} (see the status column)",
            outcome.failed,
            failed_cases(&run.results)
        );
        return Ok(ExitCode::from(EXIT_CASE_FAILED));
    }
    Ok(gate_code)
}

/// `scenario / method` of every failed case, comma-separated.
fn failed_cases(results: &[CaseResult]) -> String {
    let names: Vec<String> = results
        .iter()
        .filter(|r| r.status.is_failed())
        .map(|r| format!("{} / {}", r.scenario, r.method))
        .collect();
    names.join(", ")
}

/// Where the run's wall time went, one line per phase.
fn print_phases(outcome: &Outcome) {
    let total: f64 = outcome.phases.iter().map(|(_, s)| s).sum();
    println!("time by phase (wall seconds):");
    for (phase, seconds) in &outcome.phases {
        println!("  {:<38} {seconds:>8.2}", phase.label());
    }
    println!("  {:<38} {total:>8.2}", "sum (loading the inputs is not timed)");
}

/// The results table on stdout ([`results_table`]).
fn print_table(results: &[CaseResult]) {
    print!("{}", results_table(results));
}

/// The results table: one row per case, the timings, every metric of the table, the status. A time
/// that is not a number (an external method without a trace has no iteration time; a failed case
/// none at all) is `–`, as a missing measure is.
fn results_table(results: &[CaseResult]) -> String {
    let width = |label: &str| label.chars().count().max(9);
    let time = |v: f64, width: usize, decimals: usize| {
        if v.is_finite() {
            format!("{v:>width$.decimals$}")
        } else {
            format!("{:>width$}", "–")
        }
    };
    let mut header = format!(
        "{:<14} {:<16} {:>7} {:>9} {:>8} {:>9} {:>6}",
        "scenario", "method", "#V", "precomp s", "bind s", "iter ms", "iters"
    );
    for spec in &METRICS {
        header.push_str(&format!(" {:>w$}", spec.label, w = width(spec.label)));
    }
    let mut table = format!("{header}  status\n");
    for r in results {
        let mut line = format!(
            "{:<14} {:<16} {:>7} {} {} {} {:>6}",
            r.scenario,
            r.method,
            r.vertices,
            time(r.precompute_s, 9, 4),
            time(r.bind_s, 8, 4),
            time(r.median_iteration_ms, 9, 3),
            r.iterations
        );
        for spec in &METRICS {
            line.push_str(&format!(
                " {:>w$}",
                spec.format.apply(r.quality.get(spec.metric)),
                w = width(spec.label)
            ));
        }
        table.push_str(&format!("{line}  {}\n", r.status));
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_results_table_prints_a_dash_where_a_time_is_not_a_number() {
        // An external method without a trace: no iteration time; a failed case: no times at all.
        let mut external = CaseResult::empty("bar", "harmonic", "procedural look-alike", 500, 996);
        (external.precompute_s, external.bind_s, external.iterations) = (0.25, 0.01, 1);
        let mut failed = CaseResult::empty("bar", "broken", "procedural look-alike", 500, 996);
        failed.status = crate::verdict::Status::Failed("crashed".into());
        let table = results_table(&[external, failed]);
        assert!(!table.to_lowercase().contains("nan") && !table.contains("inf"), "{table}");
        let rows: Vec<&str> = table.lines().collect();
        let header = rows[0];
        let column = header.find("iter ms").unwrap() + "iter ms".len();
        for row in &rows[1..] {
            let cell: String = row.chars().take(column).collect::<String>();
            assert!(cell.ends_with('–'), "the iter ms cell of {row:?} is a dash");
        }
        assert!(rows[1].contains("0.2500") && rows[1].contains("0.0100"), "{}", rows[1]);
    }
}
