//! Real cases of the labelled set: results of the suite's own methods on a scenario, labelled by
//! what a person sees in them (`[[real]]` in `configs/labelled/*.toml`):
//!
//! ```toml
//! [[real]]
//! name = "cylinder: laplacian shrinks"
//! scenario = "../scenarios/cylinder.toml"
//! source = "survey"          # default; "procedural" for the look-alike
//! method = "laplacian"       # a method of configs/methods.toml
//! label = "bad"
//! kinds = ["shrinks"]
//! ```
//!
//! Each is judged as the suite judges it: beside the scenario's `arap` result (`arap` itself beside
//! itself). Running the methods takes tens of seconds per scenario, so the test of these is
//! `#[ignore]`d and `harness verdict-check --real` runs them.

use std::collections::BTreeMap;
use std::path::PathBuf;

use measures::{Reference, VerdictRules};
use serde::Deserialize;

use super::{check_label, load_scenario, DataDirs, Judged, Label, Meshes, Skipped, Source};
use crate::case::{run_case, CaseSettings};
use crate::config::MethodCatalog;
use crate::error::HarnessError;

/// The method the real cases are judged beside, as the suite does.
pub const REFERENCE: &str = "arap";

/// A real case as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RealSpec {
    pub name: String,
    pub scenario: String,
    #[serde(default = "survey")]
    pub source: Source,
    pub method: String,
    pub label: Label,
    #[serde(default)]
    pub kinds: Vec<String>,
    #[serde(default)]
    pub also: Vec<String>,
}

fn survey() -> Source {
    Source::Survey
}

impl RealSpec {
    pub(crate) fn check(&self) -> Result<(), String> {
        check_label(self.label, &self.kinds, &self.also)
    }
}

/// The final positions of `method` on the first scenario of `meshes` (`None`: it failed).
fn run(
    meshes: &Meshes,
    catalog: &MethodCatalog,
    method: &str,
    rules: &VerdictRules,
) -> Result<Option<Vec<[f64; 3]>>, String> {
    let (scenario, rest) = &meshes[0];
    let configured = catalog.find(method)?;
    let solves = methods::scale_aware::SolveMemo::default();
    let settings = CaseSettings { threads: 1, measure_memory: false, solves: &solves };
    let result = run_case(scenario, rest, configured, None, settings, rules, Reference::Missing);
    Ok(result.positions)
}

/// A scenario's meshes and its reference result.
type Loaded = (Meshes, Vec<[f64; 3]>);

/// Run and judge every real case of `entries` with the methods of `catalog`.
pub fn judge_real(
    entries: &[(PathBuf, RealSpec)],
    catalog: &MethodCatalog,
    rules: &VerdictRules,
    dirs: &DataDirs,
) -> Result<(Vec<Judged>, Vec<Skipped>), HarnessError> {
    let mut cache: BTreeMap<(PathBuf, Source), Result<Loaded, String>> = BTreeMap::new();
    let (mut judged, mut skipped) = (Vec::new(), Vec::new());
    for (i, (file, e)) in entries.iter().enumerate() {
        let fail = |m: String| super::entry_error(file, i, &e.name, m);
        let key = (file.join(&e.scenario), e.source);
        if !cache.contains_key(&key) {
            let loaded = load_scenario(file, &e.scenario, e.source, None, dirs)?.and_then(|meshes| {
                let reference = run(&meshes, catalog, REFERENCE, rules)?
                    .ok_or_else(|| format!("the reference `{REFERENCE}` failed"))?;
                Ok((meshes, reference))
            });
            cache.insert(key.clone(), loaded);
        }
        let (meshes, reference) = match &cache[&key] {
            Ok(loaded) => loaded,
            Err(reason) => {
                skipped.push(Skipped { name: e.name.clone(), reason: reason.clone() });
                continue;
            }
        };
        let positions = if e.method == REFERENCE {
            reference.clone()
        } else {
            match run(meshes, catalog, &e.method, rules).map_err(fail)? {
                Some(p) => p,
                None => {
                    skipped.push(Skipped { name: e.name.clone(), reason: format!("`{}` failed", e.method) });
                    continue;
                }
            }
        };
        let (scenario, rest) = &meshes[0];
        if scenario.steps.len() != 1 {
            return Err(fail(format!(
                "scenario `{}` has {} edit steps; a real case takes one",
                scenario.spec.name,
                scenario.steps.len()
            )));
        }
        let step = &scenario.steps[0];
        let targets = step.targets(scenario.mesh.positions()).map_err(|m| fail(m.to_string()))?;
        let steps = [(&step.handles, &targets)];
        let against = if e.method == REFERENCE {
            Reference::Itself
        } else {
            Reference::Of { positions: reference, finished: true }
        };
        let judgement =
            measures::judge_on(rules, rest, &scenario.mesh, &scenario.topology, &positions, &steps, against);
        judged.push(Judged {
            name: e.name.clone(),
            label: e.label,
            kinds: e.kinds.clone(),
            also: e.also.clone(),
            judgement,
        });
    }
    Ok((judged, skipped))
}
