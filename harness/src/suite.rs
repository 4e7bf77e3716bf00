//! A run of many cases: load and validate every input first, then run, then write reports, so bad
//! input stops the run before anything is written.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};

use crate::case::{run_case, CaseResult, Reference};
use crate::config::MethodParams;
use crate::error::HarnessError;
use crate::metrics::RestGeometry;
use crate::scenario::{load_specs, DataSource, LoadedScenario};
use crate::verdict::VerdictRules;

/// The method every other is compared with (`rms_to_arap_over_diag`, `max_to_arap_over_diag`).
pub const REFERENCE_METHOD: &str = "arap";

/// Environment variable naming the survey data directory (same as `--survey-dir`).
pub const SURVEY_DIR_ENV: &str = "DEFORM_SURVEY_DIR";

/// Everything a run needs to know.
#[derive(Clone, Debug)]
pub struct SuiteOptions {
    pub configs_dir: PathBuf,
    pub reports_dir: PathBuf,
    pub survey_dir: Option<PathBuf>,
    /// Restrict to these scenarios (empty: all).
    pub scenarios: Vec<String>,
    /// Restrict to these methods (empty: each scenario's list).
    pub methods: Vec<String>,
    pub progress: bool,
}

/// Results of a run, with the scenarios they were computed on.
pub struct SuiteRun {
    pub results: Vec<CaseResult>,
    pub scenarios: Vec<LoadedScenario>,
    pub data_source: String,
}

impl SuiteOptions {
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

/// The configuration of a run: method parameters and verdict rules.
pub struct RunConfig {
    pub params: MethodParams,
    pub rules: VerdictRules,
}

/// Load and validate the configuration (`methods.toml`, `verdicts.toml`) and every selected scenario.
pub fn prepare(options: &SuiteOptions) -> Result<(RunConfig, Vec<LoadedScenario>, DataSource), HarnessError> {
    let params = MethodParams::load(&options.configs_dir.join("methods.toml"))?;
    let rules = VerdictRules::load(&options.configs_dir.join("verdicts.toml"))?;
    for m in &options.methods {
        methods::registry::find(m)?;
    }
    let mut specs = load_specs(&options.configs_dir.join("scenarios"))?;
    if !options.scenarios.is_empty() {
        for name in &options.scenarios {
            if !specs.iter().any(|s| &s.name == name) {
                let known: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
                return Err(HarnessError::Scenario {
                    scenario: name.clone(),
                    message: format!("no such scenario; known: {}", known.join(", ")),
                });
            }
        }
        specs.retain(|s| options.scenarios.contains(&s.name));
    }
    let source = options.data_source()?;
    let scenarios = specs.iter().map(|s| s.load(&source)).collect::<Result<Vec<_>, _>>()?;
    Ok((RunConfig { params, rules }, scenarios, source))
}

/// Run every selected method on every scenario. [`REFERENCE_METHOD`] runs first in each scenario so
/// the others can be compared with it; results are reported in registry order.
pub fn run(options: &SuiteOptions) -> Result<SuiteRun, HarnessError> {
    let (config, scenarios, source) = prepare(options)?;
    let plan: Vec<(usize, Vec<&'static str>)> = scenarios
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let names = s
                .spec
                .method_names()
                .into_iter()
                .filter(|m| options.methods.is_empty() || options.methods.iter().any(|x| x == m))
                .collect();
            (i, names)
        })
        .collect();
    let total: usize = plan.iter().map(|(_, m)| m.len()).sum();
    let bar = if options.progress { ProgressBar::new(total as u64) } else { ProgressBar::hidden() };
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .expect("static template")
            .progress_chars("=> "),
    );
    let mut results = Vec::with_capacity(total);
    for (i, names) in plan {
        let scenario = &scenarios[i];
        let rest = RestGeometry::new(&scenario.mesh, &scenario.topology);
        let mut order = names.clone();
        order.sort_by_key(|m| *m != REFERENCE_METHOD);
        let mut cases: Vec<CaseResult> = Vec::with_capacity(order.len());
        for method in order {
            bar.set_message(format!("{} / {method}", scenario.spec.name));
            let reference = if method == REFERENCE_METHOD {
                Reference::Itself
            } else {
                cases
                    .iter()
                    .find(|c| c.method == REFERENCE_METHOD)
                    .and_then(|c| c.positions.as_deref())
                    .map_or(Reference::Missing, Reference::Of)
            };
            let case =
                run_case(scenario, &rest, method, &config.params.get(method), &config.rules, reference);
            cases.push(case);
            bar.inc(1);
        }
        cases.sort_by_key(|c| names.iter().position(|m| *m == c.method));
        results.extend(cases);
    }
    bar.finish_and_clear();
    let n_survey = scenarios.iter().filter(|s| s.mesh_source == "survey").count();
    let data_source = match (&source, n_survey) {
        (DataSource::Survey(dir), n) if n == scenarios.len() => format!("survey data from {}", dir.display()),
        (_, 0) => "procedural look-alikes of the survey shapes".to_string(),
        (DataSource::Survey(dir), n) => format!(
            "survey data from {} for {n} scenario(s), procedural look-alikes for the other {}",
            dir.display(),
            scenarios.len() - n
        ),
        (DataSource::Procedural, _) => unreachable!("survey meshes are only loaded from a survey directory"),
    };
    Ok(SuiteRun { results, scenarios, data_source })
}

/// The workspace root (configs/ and reports/ live there), from the harness crate's location.
pub fn workspace_root() -> PathBuf {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    root.canonicalize().unwrap_or_else(|_| root.to_path_buf())
}
