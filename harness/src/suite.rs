//! A run of many cases: load and validate every input first, then run, then write reports, so bad
//! input stops the run before anything is written.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use indicatif::{ProgressBar, ProgressStyle};

use crate::case::{run_case, CaseSettings, Reference};
use crate::config::{ConfiguredMethod, Implementation, MethodCatalog, PeerSetup};
use crate::error::HarnessError;
use crate::metrics::RestGeometry;
use crate::provenance::Provenance;
use crate::record::{CaseResult, REFERENCE_METHOD};
use crate::scenario::{
    load_spec, load_specs, DataSource, LoadedScenario, ScenarioSpec, SizeCheck, SizeRequest, SkippedInput,
    FILE_SOURCE,
};
use crate::shard::{assign, estimated_cost, Shard};
use crate::verdict::VerdictRules;

/// Everything a run needs to know.
#[derive(Clone, Debug)]
pub struct SuiteOptions {
    pub configs_dir: PathBuf,
    /// The scenario files (default: `configs_dir/scenarios`).
    pub scenarios_dir: Option<PathBuf>,
    pub reports_dir: PathBuf,
    pub survey_dir: Option<PathBuf>,
    /// Restrict to these scenarios (empty: all): names, or paths of scenario files.
    pub scenarios: Vec<String>,
    /// Restrict to these methods (empty: each scenario's list).
    pub methods: Vec<String>,
    /// Add the peer methods of this file (`configs/peers.toml`, `--peers`) to every scenario that
    /// does not restrict its methods.
    pub peers: Option<PeerSetup>,
    /// Add the parameter sweeps of this file (`configs/sweeps.toml`, `--sweeps`).
    pub sweeps: Option<PathBuf>,
    /// Method files of the user's, added on top of `methods.toml` (`--methods`,
    /// `DEFORMBENCH_METHODS`).
    pub method_files: Vec<PathBuf>,
    /// `${DEFORMBENCH_PYTHON}` in every method file's commands (`--python`, else the environment).
    pub python: Option<PathBuf>,
    /// Worker threads of every method ([`crate::threads`]).
    pub threads: usize,
    /// Cases run at a time, each in its own pool of `threads` workers (`--jobs`).
    pub jobs: usize,
    /// Repetitions of each case's timed phases (`--repeat`).
    pub repetitions: usize,
    /// The command that asked for the run, for its record.
    pub command_line: Vec<String>,
    pub progress: bool,
    /// Run scenarios whose estimated memory exceeds the available memory (`--force`); otherwise
    /// they are refused before their mesh is loaded ([`crate::memory`]).
    pub force: bool,
    /// Methods given in-process by the program that runs the suite (the Python module's
    /// `deformbench.run`), added to the catalog; none from the command line.
    pub provided: Vec<crate::config::ProvidedMethod>,
}

/// Results of a run, with the scenarios they were computed on.
pub struct SuiteRun {
    pub results: Vec<CaseResult>,
    pub scenarios: Vec<LoadedScenario>,
    /// The meshes of collections that no case ran on, with the reason.
    pub skipped: Vec<SkippedInput>,
    pub data_source: String,
    /// What loading the scenarios noticed (dropped or duplicate vertices), each naming its scenario.
    pub notes: Vec<String>,
    /// Where and how the run was made.
    pub provenance: Provenance,
}

impl SuiteRun {
    /// The closing summary's lines on the inputs: every mesh of a collection that was skipped (its
    /// file and reason) and every mesh `repair = true` changed (its file and what changed); empty
    /// when there are none.
    pub fn input_summary(&self) -> Vec<String> {
        let mut lines = Vec::new();
        if !self.skipped.is_empty() {
            lines.push(format!(
                "{} mesh(es) of collections skipped, no case ran on them (index.html, \"Meshes skipped or repaired\"):",
                self.skipped.len()
            ));
            lines.extend(
                self.skipped
                    .iter()
                    .map(|s| format!("  skipped {}: {}: {}", s.scenario, s.file.display(), s.reason)),
            );
        }
        let repaired: Vec<(&str, &crate::scenario::Repaired)> = self
            .scenarios
            .iter()
            .filter_map(|s| Some((s.spec.name.as_str(), s.repaired.as_ref()?)))
            .collect();
        if !repaired.is_empty() {
            lines.push(format!(
                "{} mesh(es) repaired by `repair = true` before any case ran:",
                repaired.len()
            ));
            lines.extend(
                repaired
                    .iter()
                    .map(|(name, r)| format!("  repaired {name}: {}: {}", r.file.display(), r.changes)),
            );
        }
        lines
    }

    /// With a note per method of `catalog` that could not run here and why (once per run).
    fn with_unavailable(mut self, catalog: &MethodCatalog) -> SuiteRun {
        self.notes.extend(catalog.methods().iter().filter_map(|m| {
            m.unavailable
                .as_ref()
                .map(|why| format!("method `{m}` ({}) skipped: {why}", m.file.display(), m = m.name))
        }));
        self
    }

    /// The run of `results` on `scenarios`, its notes gathered ([`notes_of`]).
    fn new(
        options: &SuiteOptions,
        results: Vec<CaseResult>,
        scenarios: Vec<LoadedScenario>,
        skipped: Vec<SkippedInput>,
        data_source: String,
        provenance: Provenance,
    ) -> SuiteRun {
        let notes = notes_of(options, &scenarios, &skipped);
        SuiteRun { results, scenarios, skipped, data_source, notes, provenance }
    }
}

impl SuiteOptions {
    /// Take the peers' file when `peers` has one (`--peers` with its Python found); returns the note
    /// that says why peers were asked for but not run.
    pub fn add_peers(&mut self, peers: Option<Result<PeerSetup, String>>) -> Option<String> {
        match peers? {
            Ok(setup) => {
                self.peers = Some(setup);
                None
            }
            Err(reason) => {
                eprintln!("note: {reason}");
                Some(reason)
            }
        }
    }

    /// The data source: `survey_dir` if given (it must exist), else procedural look-alikes.
    pub fn data_source(&self) -> Result<DataSource, HarnessError> {
        match &self.survey_dir {
            Some(dir) if dir.is_dir() => Ok(DataSource::Survey(dir.clone())),
            Some(dir) => Err(HarnessError::Config {
                path: dir.clone(),
                message: "survey directory does not exist".into(),
            }),
            None => Ok(DataSource::Procedural),
        }
    }
}

/// The configuration of a run: its methods with their parameters, and the verdict rules.
pub struct RunConfig {
    pub catalog: MethodCatalog,
    pub rules: VerdictRules,
}

/// A run ready to start: its configuration, the scenarios that loaded, the meshes of collections
/// skipped, and where the survey meshes come from.
pub struct Prepared {
    pub config: RunConfig,
    pub scenarios: Vec<LoadedScenario>,
    pub skipped: Vec<SkippedInput>,
    pub source: DataSource,
}

/// Load and validate the configuration (`methods.toml`, the peers when asked for, `verdicts.toml`)
/// and every selected scenario.
pub fn prepare(options: &SuiteOptions) -> Result<Prepared, HarnessError> {
    prepare_within(options, false)
}

/// [`prepare`], with each scenario's estimated memory checked against the available memory before
/// its mesh is made or read, when `check_memory` and not `options.force` ([`memory_check`]).
fn prepare_within(options: &SuiteOptions, check_memory: bool) -> Result<Prepared, HarnessError> {
    let catalog = load_catalog(options)?;
    let rules = VerdictRules::load(&options.configs_dir.join("verdicts.toml"))?;
    for m in &options.methods {
        if let Some(why) = catalog.get(m).and_then(|c| c.unavailable.as_ref().map(|w| (c, w))) {
            return Err(HarnessError::Config {
                path: why.0.file.clone(),
                message: format!("[{m}]: cannot run here: {}", why.1),
            });
        }
        // The name came from the command line: the error says so, not methods.toml.
        if let Some(message) = unknown_method(options, &catalog, m) {
            return Err(HarnessError::Report(format!("--method {m}: {message}")));
        }
    }
    if let Some(sweeps) = &options.sweeps {
        check_sweep_scenarios(options, &catalog, sweeps)?;
    }
    let specs = select_specs(options)?;
    for spec in &specs {
        let named = spec
            .methods
            .iter()
            .flatten()
            .map(|m| ("methods", m))
            .chain(spec.left_out.keys().map(|m| ("left_out", m)));
        for (key, m) in named {
            if let Some(message) = unknown_method(options, &catalog, m) {
                let key = if key == "left_out" {
                    format!("left_out.{m}")
                } else {
                    format!("methods = [.. \"{m}\" ..]")
                };
                return Err(HarnessError::Config {
                    path: spec.path.clone(),
                    message: format!("{key}: {message}"),
                });
            }
        }
    }
    let source = options.data_source()?;
    let mut scenarios = Vec::with_capacity(specs.len());
    let mut skipped = Vec::new();
    let no_check = |_: &SizeRequest| Ok(());
    let by_memory = |request: &SizeRequest| memory_check(options, &catalog, request);
    let check: SizeCheck = if check_memory && !options.force { &by_memory } else { &no_check };
    for spec in &specs {
        let loaded = spec.load_checked(&source, check)?;
        scenarios.extend(loaded.scenarios);
        skipped.extend(loaded.skipped);
    }
    Ok(Prepared { config: RunConfig { catalog, rules }, scenarios, skipped, source })
}

/// Why `name` is no method of `catalog` (with the nearest name, and whether it is a peer that
/// needs `--peers`), or `None` when it is one.
fn unknown_method(options: &SuiteOptions, catalog: &MethodCatalog, name: &str) -> Option<String> {
    let message = catalog.find(name).err()?;
    let is_peer =
        crate::config::peer_names(&options.configs_dir.join("peers.toml")).iter().any(|p| p == name);
    let hint = if is_peer && options.peers.is_none() { " (a peer: add --peers)" } else { "" };
    Some(format!("{message}{hint}"))
}

/// Every scenario a sweep file's `scenarios` names exists, in the run's scenario directory or the
/// configuration's `scenarios/`: a misspelt name would otherwise sweep nothing, silently.
fn check_sweep_scenarios(
    options: &SuiteOptions,
    catalog: &MethodCatalog,
    sweeps: &Path,
) -> Result<(), HarnessError> {
    let mut known: Vec<String> = Vec::new();
    let standard = options.configs_dir.join("scenarios");
    for dir in options.scenarios_dir.iter().chain([&standard]) {
        if dir.is_dir() {
            known.extend(load_specs(dir)?.into_iter().map(|s| s.name));
        }
    }
    for method in catalog.methods() {
        for name in method.runs_on.iter().flatten() {
            if !known.contains(name) {
                return Err(HarnessError::Config {
                    path: sweeps.to_path_buf(),
                    message: format!(
                        "`scenarios` names `{name}` (for `{}`), which is no scenario; known: {}",
                        method.name,
                        known.join(", ")
                    ),
                });
            }
        }
    }
    Ok(())
}

/// The methods of a run: `methods.toml` of the configuration directory, and the peers if asked for.
pub fn load_catalog(options: &SuiteOptions) -> Result<MethodCatalog, HarnessError> {
    let python = options.python.as_ref().map(|p| p.to_string_lossy().into_owned());
    let given: Vec<(&str, &str)> = python.iter().map(|p| (crate::paths::PYTHON_ENV, p.as_str())).collect();
    let mut catalog = MethodCatalog::load_with(&options.configs_dir.join("methods.toml"), &given)?;
    for file in &options.method_files {
        catalog.add_method_file(file, &given)?;
    }
    if let Some(peers) = &options.peers {
        catalog.add_peers(peers)?;
    }
    if let Some(sweeps) = &options.sweeps {
        catalog.add_sweeps(sweeps)?;
    }
    for provided in &options.provided {
        catalog.add_provided(provided)?;
    }
    Ok(catalog)
}

/// `run` without `--method` runs each scenario's own `methods = [...]`: an error naming every
/// selected scenario that lists none (rather than running every method on it, which is `all`'s
/// job), and saying what to give instead.
pub fn require_listed_methods(options: &SuiteOptions) -> Result<(), HarnessError> {
    let specs = select_specs(options)?;
    let without: Vec<String> = specs
        .iter()
        .filter(|s| s.methods.is_none())
        .map(|s| format!("`{}` ({})", s.name, s.path.display()))
        .collect();
    if without.is_empty() {
        return Ok(());
    }
    Err(HarnessError::Report(format!(
        "no --method given, and scenario {} lists no `methods = [...]`: give --method NAME (repeatable; \
         `harness list` shows the names), add `methods` to the scenario file, or run every method with \
         `harness all --scenarios DIR`",
        without.join(", ")
    )))
}

/// The scenario files of the run: every one in the scenarios directory, or the ones named (by name, or
/// by the path of a `.toml` file anywhere).
fn select_specs(options: &SuiteOptions) -> Result<Vec<ScenarioSpec>, HarnessError> {
    let dir = options.scenarios_dir.clone().unwrap_or_else(|| options.configs_dir.join("scenarios"));
    let is_path = |s: &str| s.ends_with(".toml") || s.contains(std::path::MAIN_SEPARATOR);
    let named: Vec<&String> = options.scenarios.iter().filter(|s| !is_path(s)).collect();
    let mut specs =
        if options.scenarios.is_empty() || !named.is_empty() { load_specs(&dir)? } else { Vec::new() };
    if !options.scenarios.is_empty() {
        for name in &named {
            if !specs.iter().any(|s| &&s.name == name) {
                let known: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
                return Err(HarnessError::Scenario {
                    scenario: name.to_string(),
                    file: None,
                    message: format!(
                        "--scenario {name}: no such scenario in {}{}; known: {} (or give the path of a \
                         scenario file)",
                        dir.display(),
                        crate::error::did_you_mean(name, known.iter().copied()),
                        known.join(", ")
                    ),
                });
            }
        }
        specs.retain(|s| named.contains(&&s.name));
        for path in options.scenarios.iter().filter(|s| is_path(s)) {
            let spec = load_spec(Path::new(path))?;
            if specs.iter().any(|s| s.name == spec.name) {
                return Err(HarnessError::Config {
                    path: path.into(),
                    message: format!("scenario name `{}` is given twice", spec.name),
                });
            }
            specs.push(spec);
        }
    }
    Ok(specs)
}

/// The methods of each scenario the run covers, in catalog order: those its `methods` list names,
/// else every method of the catalog that runs there (peers included when the run added them, sweep
/// points on their sweep file's scenarios); `options.methods` applied.
fn plan(options: &SuiteOptions, catalog: &MethodCatalog, scenarios: &[LoadedScenario]) -> Vec<Vec<MethodId>> {
    scenarios
        .iter()
        .map(|s| planned_methods(options, catalog, &s.spec, &s.spec.name).map(|(id, _)| id).collect())
        .collect()
}

/// A method of the run's catalog: its index in [`MethodCatalog::methods`]. A plan holds these, so
/// that nothing is looked up by name after planning.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct MethodId(usize);

impl MethodId {
    /// Its method in `catalog` (the catalog it was planned from).
    fn of(self, catalog: &MethodCatalog) -> &ConfiguredMethod {
        &catalog.methods()[self.0]
    }
}

/// The methods [`plan`] gives the scenario `name` of `spec` (a collection's member has its own name).
fn planned_methods<'a>(
    options: &'a SuiteOptions,
    catalog: &'a MethodCatalog,
    spec: &'a ScenarioSpec,
    name: &'a str,
) -> impl Iterator<Item = (MethodId, &'a ConfiguredMethod)> + 'a {
    (catalog.methods().iter().enumerate())
        .filter(move |(_, m)| match &spec.methods {
            Some(list) => list.contains(&m.name),
            None => m.runs_on.as_ref().is_none_or(|on| on.iter().any(|s| s == name)),
        })
        .filter(move |(_, m)| !spec.left_out.contains_key(&m.name) && m.unavailable.is_none())
        .filter(move |(_, m)| options.methods.is_empty() || options.methods.iter().any(|x| *x == m.name))
        .map(|(i, m)| (MethodId(i), m))
}

/// Refuse the mesh size `request` when the scenario's estimated memory ([`crate::memory::estimate`]:
/// the mesh and its planned built-in methods; an external method's memory is its own process's
/// and unknown here) exceeds the memory available now. `MemAvailable` is read at each request, so
/// the meshes already loaded count against it.
fn memory_check(
    options: &SuiteOptions,
    catalog: &MethodCatalog,
    request: &SizeRequest,
) -> Result<(), HarnessError> {
    let methods: Vec<(String, u64)> = planned_methods(options, catalog, request.spec, request.scenario)
        .filter_map(|(_, m)| match &m.implementation {
            Implementation::BuiltIn(entry) => Some((m.name.clone(), entry.bytes_per_vertex)),
            Implementation::External(_) | Implementation::Provided(_) => None,
        })
        .collect();
    let estimate = crate::memory::estimate(request.vertices, request.faces, &methods, options.jobs);
    crate::memory::MemoryRefusal::check(
        estimate,
        crate::memory::available_bytes(),
        request.spec.path.clone(),
        request.key.clone(),
        request.mesh.clone(),
    )
    .map_err(|refusal| HarnessError::Memory(Box::new(refusal)))
}

/// Run every selected method on every scenario. [`REFERENCE_METHOD`] runs first in each scenario so
/// the others can be compared with it; results are reported in registry order.
pub fn run(options: &SuiteOptions) -> Result<SuiteRun, HarnessError> {
    let mut provenance = record_of(options);
    let Prepared { config, scenarios, skipped, source } = prepare_within(options, true)?;
    provenance.inputs = crate::provenance::hash_inputs(inputs_of(options, &scenarios));
    let plan = plan(options, &config.catalog, &scenarios);
    let results = run_plan(options, &config, &scenarios, &plan)?;
    provenance.external = crate::provenance::external_records(&results);
    let data_source = describe_data(&source, &scenarios);
    Ok(SuiteRun::new(options, results, scenarios, skipped, data_source, provenance)
        .with_unavailable(&config.catalog))
}

/// Run the scenarios of part `shard` of the suite ([`crate::shard::assign`] on their estimated cost).
pub fn run_shard(options: &SuiteOptions, shard: Shard) -> Result<SuiteRun, HarnessError> {
    let mut provenance = record_of(options);
    let Prepared { config, scenarios, skipped, source } = prepare_within(options, true)?;
    provenance.inputs = crate::provenance::hash_inputs(inputs_of(options, &scenarios));
    let data_source = describe_data(&source, &scenarios);
    let plan = plan(options, &config.catalog, &scenarios);
    let costs: Vec<f64> = scenarios
        .iter()
        .zip(&plan)
        .map(|(s, ids)| {
            estimated_cost(s, &ids.iter().map(|id| id.of(&config.catalog).name.as_str()).collect::<Vec<_>>())
        })
        .collect();
    let shard_of = assign(&costs, shard.count);
    let (mine, plan): (Vec<(LoadedScenario, bool)>, Vec<Vec<MethodId>>) = scenarios
        .into_iter()
        .zip(plan)
        .zip(&shard_of)
        .map(|((s, p), &k)| ((s, k + 1 == shard.index), p))
        .filter(|((_, keep), _)| *keep)
        .unzip();
    let scenarios: Vec<LoadedScenario> = mine.into_iter().map(|(s, _)| s).collect();
    let results = run_plan(options, &config, &scenarios, &plan)?;
    provenance.external = crate::provenance::external_records(&results);
    Ok(SuiteRun::new(options, results, scenarios, skipped, data_source, provenance)
        .with_unavailable(&config.catalog))
}

/// The record of a run started now with `options`.
fn record_of(options: &SuiteOptions) -> Provenance {
    Provenance::record(options.command_line.clone(), options.threads, options.jobs, options.repetitions)
}

/// Every file the run read: the configuration, each scenario file and what it named.
fn inputs_of(options: &SuiteOptions, scenarios: &[LoadedScenario]) -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> =
        ["methods.toml", "verdicts.toml"].iter().map(|f| options.configs_dir.join(f)).collect();
    paths.extend(options.peers.as_ref().map(|p| p.file.clone()));
    for s in scenarios {
        paths.push(s.spec.path.clone());
        paths.extend(s.spec.files_read.paths());
    }
    paths
}

/// The notes of every scenario, each named, every mesh of a collection skipped with its reason,
/// and what concurrent cases do to the timings.
fn notes_of(options: &SuiteOptions, scenarios: &[LoadedScenario], skipped: &[SkippedInput]) -> Vec<String> {
    let mut notes: Vec<String> = scenarios
        .iter()
        .flat_map(|s| s.notes.iter().map(move |n| format!("scenario `{}`: {n}", s.spec.name)))
        .collect();
    notes.extend(scenarios.iter().flat_map(|s| {
        s.spec
            .left_out
            .iter()
            .map(move |(method, why)| format!("left out `{method}` on `{}`: {why}", s.spec.name))
    }));
    notes.extend(
        skipped
            .iter()
            .map(|s| format!("skipped `{}`: no case ran on {}: {}", s.scenario, s.file.display(), s.reason)),
    );
    if options.jobs > 1 {
        notes.push(format!(
            "cases ran {} at a time (--jobs), each on {} thread(s): they share the memory bandwidth and caches, \
             so their timings are not those of a case run alone (README, \"Timings\")",
            options.jobs, options.threads
        ));
    }
    notes
}

/// Run `plan[i]` (methods of the catalog) on `scenarios[i]` for every `i`, `options.jobs` cases at a time,
/// each job in its own pool of `options.threads` workers. Every scenario's [`REFERENCE_METHOD`] case
/// is queued before the others, which wait for it (or run it) when they need its shape; results come
/// back in plan order whatever the order they ran in, so a run's report does not depend on `jobs`.
///
/// With `--repeat N` the suite runs in N rounds: the first measures every case, each later one
/// times every case again ([`crate::case::repetition`]). Repeating a case N times back to back
/// misses the machine's slow drift: two such runs of one commit on this machine called 34 of 70 cases
/// slower or faster, with ranges that did not overlap. Rounds spread each case's repetitions over
/// the run, as asv's `rounds` do, so the spread takes the drift in.
fn run_plan(
    options: &SuiteOptions,
    config: &RunConfig,
    scenarios: &[LoadedScenario],
    plan: &[Vec<MethodId>],
) -> Result<Vec<CaseResult>, HarnessError> {
    let pools: Vec<rayon::ThreadPool> =
        (0..options.jobs.max(1)).map(|_| crate::threads::pool(options.threads)).collect::<Result<_, _>>()?;
    let is_reference = |id: &MethodId| id.of(&config.catalog).name == REFERENCE_METHOD;
    let queue: Vec<(usize, MethodId)> = {
        let planned = || plan.iter().enumerate().flat_map(|(s, ids)| ids.iter().map(move |id| (s, *id)));
        let (references, others): (Vec<_>, Vec<_>) = planned().partition(|(_, id)| is_reference(id));
        references.into_iter().chain(others).collect()
    };
    let rounds = options.repetitions.max(1);
    let bar = if options.progress {
        ProgressBar::new((queue.len() * rounds) as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .expect("static template")
            .progress_chars("=> "),
    );
    let mut shared = SharedCases {
        options,
        config,
        scenarios,
        rests: scenarios.iter().map(|_| OnceLock::new()).collect(),
        references: scenarios.iter().map(|_| OnceLock::new()).collect(),
        solves: methods::scale_aware::SolveMemo::default(),
        reference_of: plan.iter().map(|ids| ids.iter().copied().find(is_reference)).collect(),
        bar: &bar,
    };
    let first = in_jobs(&pools, queue.len(), |i| {
        let (s, method) = queue[i];
        let case = shared.run(s, method).map(|case| (s, method, case));
        bar.inc(1);
        case
    });
    let mut cases: Vec<(usize, MethodId, CaseResult)> = first.into_iter().flatten().collect();
    let references = std::mem::take(&mut shared.references).into_iter().zip(&shared.reference_of).enumerate();
    cases.extend(references.filter_map(|(s, (r, id))| Some((s, (*id)?, r.into_inner()?))));
    cases.sort_by_key(|(s, id, _)| (*s, plan[*s].iter().position(|m| m == id)));
    if rounds > 1 {
        let mut later: Vec<Vec<_>> = cases.iter().map(|_| Vec::with_capacity(rounds - 1)).collect();
        for round in 2..=rounds {
            bar.set_message(format!("round {round} of {rounds}"));
            let timed = in_jobs(&pools, cases.len(), |i| {
                let (s, id, case) = &cases[i];
                let method = id.of(&config.catalog);
                let again = (!case.status.is_failed())
                    .then(|| crate::case::repetition(&scenarios[*s], method, shared.settings()));
                bar.inc(1);
                again
            });
            for (i, again) in timed.into_iter().enumerate() {
                later[i].extend(again);
            }
        }
        cases = (cases.into_iter().zip(later))
            .map(|((s, id, first), later)| {
                let diagonal = shared.rests[s].get().map_or(f64::NAN, |r| r.diagonal);
                (s, id, crate::case::with_repetitions(first, diagonal, later))
            })
            .collect();
    }
    bar.finish_and_clear();
    Ok(cases.into_iter().map(|(_, _, case)| case).collect())
}

/// `work(i)` for every `i < count`, `pools.len()` items at a time: one job thread per pool takes
/// the next item and runs it inside its pool. The results in item order.
fn in_jobs<T: Send>(pools: &[rayon::ThreadPool], count: usize, work: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let next = AtomicUsize::new(0);
    let mut done: Vec<(usize, T)> = std::thread::scope(|scope| {
        let jobs: Vec<_> = pools
            .iter()
            .enumerate()
            .map(|(j, pool)| {
                let (work, next) = (&work, &next);
                std::thread::Builder::new()
                    .name(format!("{}-{j}", crate::threads::JOB_NAME))
                    .spawn_scoped(scope, move || {
                        pool.install(|| {
                            let mut mine = Vec::new();
                            loop {
                                let i = next.fetch_add(1, Ordering::Relaxed);
                                if i >= count {
                                    break mine;
                                }
                                mine.push((i, work(i)));
                            }
                        })
                    })
                    .expect("spawning a job thread")
            })
            .collect();
        jobs.into_iter().flat_map(|j| j.join().expect("a job thread panicked")).collect()
    });
    done.sort_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, t)| t).collect()
}

/// What the jobs of [`run_plan`] share: each scenario's rest geometry and reference case, computed
/// by whichever job needs them first (the others wait).
struct SharedCases<'a> {
    options: &'a SuiteOptions,
    config: &'a RunConfig,
    scenarios: &'a [LoadedScenario],
    rests: Vec<OnceLock<RestGeometry>>,
    references: Vec<OnceLock<CaseResult>>,
    /// The run's memo of solves ([`CaseSettings::solves`]).
    solves: methods::scale_aware::SolveMemo,
    /// The reference method of scenario `s`'s plan, if it runs it.
    reference_of: Vec<Option<MethodId>>,
    bar: &'a ProgressBar,
}

impl SharedCases<'_> {
    /// Run `method` on scenario `s`; `None` for the reference, which stays in `references`.
    fn run(&self, s: usize, method: MethodId) -> Option<CaseResult> {
        let Some(reference) = self.reference_of[s] else {
            return Some(self.run_case(s, method, Reference::Missing));
        };
        let r = self.references[s].get_or_init(|| self.run_case(s, reference, Reference::Itself));
        if method == reference {
            return None;
        }
        let finished = r.status.is_ok() || r.status.is_suspect();
        let reference = r
            .positions
            .as_deref()
            .map_or(Reference::Missing, |positions| Reference::Of { positions, finished });
        Some(self.run_case(s, method, reference))
    }

    /// How this run's cases are run.
    fn settings(&self) -> CaseSettings<'_> {
        CaseSettings {
            threads: self.options.threads,
            measure_memory: self.options.jobs == 1,
            solves: &self.solves,
        }
    }

    fn run_case(&self, s: usize, method: MethodId, reference: Reference<'_>) -> CaseResult {
        let scenario = &self.scenarios[s];
        let method = method.of(&self.config.catalog);
        self.bar.set_message(format!("{} / {}", scenario.spec.name, method.name));
        let rest = self.rests[s].get_or_init(|| RestGeometry::new(&scenario.mesh, &scenario.topology));
        let stderr_log = method.is_external().then(|| {
            self.options.reports_dir.join("logs").join(format!(
                "{}.stderr.txt",
                crate::stored_report::case_file_stem(&scenario.spec.name, &method.name)
            ))
        });
        run_case(scenario, rest, method, stderr_log, self.settings(), &self.config.rules, reference)
    }
}

/// The run that the partial reports in `dirs` (of `all --shard K/N` with these `options`, K = 1..N)
/// make up together: their cases in the order one run reports them, each result's shape read back
/// from its mesh file. Errors: a missing or repeated part, parts of different runs (data source or
/// N), a case of a scenario the options do not load, a mesh that does not fit its scenario.
pub fn merge(options: &SuiteOptions, dirs: &[PathBuf]) -> Result<SuiteRun, HarnessError> {
    let mut provenance = record_of(options);
    let Prepared { config, scenarios, skipped, source } = prepare(options)?;
    provenance.inputs = crate::provenance::hash_inputs(inputs_of(options, &scenarios));
    let data_source = describe_data(&source, &scenarios);
    let mut records: Vec<(usize, Provenance)> = Vec::new();
    let mut parts: Vec<(Shard, PathBuf, Vec<CaseResult>)> = Vec::with_capacity(dirs.len());
    for dir in dirs {
        let path = dir.join("results.json");
        let crate::stored_report::StoredReport {
            cases,
            data_source: their_source,
            shard,
            provenance: record,
            ..
        } = crate::stored_report::read_results(&path)?;
        let config = |message: String| HarnessError::Config { path: path.clone(), message };
        let shard = shard.ok_or_else(|| config("not a partial report (written without --shard)".into()))?;
        if their_source != data_source {
            return Err(config(format!("ran on {their_source}, but this merge loads {data_source}")));
        }
        if let Some((other, other_dir, _)) = parts.iter().find(|(s, _, _)| s.index == shard.index) {
            return Err(config(format!("part {other} is also in {}", other_dir.display())));
        }
        if let Some((other, _, _)) = parts.iter().find(|(s, _, _)| s.count != shard.count) {
            return Err(config(format!("is part {shard}, but another part is {other}")));
        }
        if let Some(record) = record {
            records.push((shard.index, record));
        }
        parts.push((shard, dir.clone(), cases));
    }
    let count = parts[0].0.count;
    let missing: Vec<String> = (1..=count)
        .filter(|k| !parts.iter().any(|(s, _, _)| s.index == *k))
        .map(|k| format!("{k}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(HarnessError::Config {
            path: dirs[0].clone(),
            message: format!("the merge lacks part(s) {}", missing.join(", ")),
        });
    }
    records.sort_by_key(|(index, _)| *index);
    provenance.parts = records.into_iter().map(|(_, record)| record).collect();
    let plan = plan(options, &config.catalog, &scenarios);
    let mut results: Vec<(usize, usize, CaseResult)> = Vec::new();
    for (_, dir, cases) in parts {
        for mut case in cases {
            let fail = |message: String| HarnessError::Config { path: dir.join("results.json"), message };
            let Some(i) = scenarios.iter().position(|s| s.spec.name == case.scenario) else {
                return Err(fail(format!(
                    "scenario `{}` is not among the scenarios this merge loads",
                    case.scenario
                )));
            };
            let order = (plan[i].iter())
                .position(|id| id.of(&config.catalog).name == case.method)
                .unwrap_or(usize::MAX);
            if !case.status.is_failed() {
                let mesh_path = dir.join("meshes").join(format!(
                    "{}.off",
                    crate::stored_report::case_file_stem(&case.scenario, &case.method)
                ));
                let mesh = meshes::io::read_mesh(&mesh_path)?;
                case.positions = Some(
                    scenarios[i]
                        .from_input_order(mesh.positions())
                        .map_err(|m| HarnessError::Config { path: mesh_path.clone(), message: m })?,
                );
            }
            results.push((i, order, case));
        }
    }
    results.sort_by_key(|(i, order, _)| (*i, *order));
    let results: Vec<CaseResult> = results.into_iter().map(|(_, _, c)| c).collect();
    Ok(SuiteRun::new(options, results, scenarios, skipped, data_source, provenance)
        .with_unavailable(&config.catalog))
}

/// One line on where the meshes of `scenarios` came from.
fn describe_data(source: &DataSource, scenarios: &[LoadedScenario]) -> String {
    let count = |what: &str| scenarios.iter().filter(|s| s.mesh_source == what).count();
    let (survey, procedural, files) = (count("survey"), count("procedural look-alike"), count(FILE_SOURCE));
    let survey_part = match source {
        DataSource::Survey(dir) => format!("survey data from {}", dir.display()),
        DataSource::Procedural => "survey data".to_string(),
    };
    let n = scenarios.len();
    match (survey, procedural, files) {
        (s, 0, 0) if s == n => survey_part,
        (0, p, 0) if p == n => "procedural look-alikes of the survey shapes".to_string(),
        (0, 0, f) if f == n => "mesh files named by the scenarios".to_string(),
        _ => {
            let mut parts = Vec::new();
            if survey > 0 {
                parts.push(format!("{survey_part} for {survey} scenario(s)"));
            }
            if procedural > 0 {
                parts.push(format!("procedural look-alikes for {procedural}"));
            }
            if files > 0 {
                parts.push(format!("mesh files for {files}"));
            }
            parts.join(", ")
        }
    }
}
