//! The labelled verdict set (issue 62): results whose truth is known, built from the meshes and
//! handle layouts of scenario files, judged by the verdict rules, and counted per rule
//! ([`tally`]). Data in `configs/labelled/*.toml`, one `[[entry]]` per case:
//!
//! ```toml
//! [[entry]]
//! name = "bar: local shrink by 25%"
//! scenario = "../scenarios/bar.toml"    # mesh and handle regions (its own edit is not used)
//! source = "procedural"                 # or "survey" (needs the survey dir; skipped without it);
//!                                       # a scenario with a mesh file uses the file
//! vertices = 3000                       # procedural size (default: the scenario's)
//! edit = { kind = "twist", degrees = 90 }               # the sound edit: the handles' targets
//! defect = { kind = "resize", factor = 0.75 }           # what corrupts its result (none: good)
//! label = "bad"                         # or "good"
//! kinds = ["shrinks"]                   # bad: the reason kinds that must fire (REASON_KINDS)
//! also = ["swells"]                     # kinds that may fire as well (true of the shape too)
//! noise = 1e-9                          # jitter of the result, in rest diagonals (default 0)
//! ```
//!
//! A scenario with a mesh collection (`[manifest]`, `meshes`) gives one case per mesh. An entry
//! whose data is absent (no survey dir, an unset `${VAR}` or a missing file) is skipped and
//! counted as skipped. `[[real]]` entries ([`real`]) are results of the suite's own methods.

pub mod edits;
pub mod real;
pub mod tally;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use measures::{Judgement, Reference, RestGeometry, VerdictRules, REASON_KINDS};
use methods::{HandleSet, HandleTargets};
use serde::Deserialize;

use crate::error::HarnessError;
use crate::scenario::{load_spec, DataSource, LoadedScenario, PathContext, ScenarioSpec};
pub use edits::{Defect, Edit, Shape};
pub use real::RealSpec;
pub use tally::Tally;

/// The label of an entry.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Label {
    /// A sound result: a verdict should pass it.
    Good,
    /// A broken result: a verdict must flag it (with its `kinds`, for the per-rule recall).
    Bad,
    /// A defect smaller than the rules are made to see (a patch 10% smaller or larger: sound results
    /// differ from arap's by as much, configs/verdicts.toml): counted apart, in neither precision
    /// nor recall nor the good cases' false alarms.
    Tolerated,
}

/// Where a built-in scenario's mesh comes from.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq, PartialOrd, Ord)]
#[serde(rename_all = "snake_case")]
pub enum Source {
    #[default]
    Procedural,
    Survey,
}

/// One labelled case as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EntrySpec {
    pub name: String,
    /// A scenario file, relative to this file: its mesh and its first step's handle regions.
    pub scenario: String,
    #[serde(default)]
    pub source: Source,
    #[serde(default)]
    pub vertices: Option<usize>,
    pub edit: Edit,
    #[serde(default)]
    pub defect: Option<Defect>,
    pub label: Label,
    #[serde(default)]
    pub kinds: Vec<String>,
    #[serde(default)]
    pub also: Vec<String>,
    #[serde(default)]
    pub noise: f64,
}

/// A file of `configs/labelled/`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelledFile {
    #[serde(default)]
    pub entry: Vec<EntrySpec>,
    #[serde(default)]
    pub real: Vec<RealSpec>,
}

/// The entries of every file of a directory, each with its file.
#[derive(Clone, Debug, Default)]
pub struct LabelledSet {
    pub entries: Vec<(PathBuf, EntrySpec)>,
    pub real: Vec<(PathBuf, RealSpec)>,
}

/// A case judged: its name, truth and judgement.
#[derive(Clone, Debug)]
pub struct Judged {
    pub name: String,
    pub label: Label,
    pub kinds: Vec<String>,
    pub also: Vec<String>,
    pub judgement: Judgement,
}

/// An entry (or a mesh of it) that was not run, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    pub name: String,
    pub reason: String,
}

/// Where the optional data lives.
#[derive(Clone, Debug, Default)]
pub struct DataDirs {
    pub survey: Option<PathBuf>,
}

/// Fails naming `path`, the entry and the key.
fn entry_error(path: &Path, index: usize, name: &str, message: String) -> HarnessError {
    HarnessError::Config { path: path.to_path_buf(), message: format!("entry[{index}] `{name}`: {message}") }
}

/// The label's kinds checked: known reason kinds; some for `bad`, none for `good`.
pub(crate) fn check_label(label: Label, kinds: &[String], also: &[String]) -> Result<(), String> {
    for (key, list) in [("kinds", kinds), ("also", also)] {
        if let Some(k) = list.iter().find(|k| !REASON_KINDS.contains(&k.as_str())) {
            return Err(format!(
                "{key} = [.. \"{k}\" ..]: not a reason kind (one of {})",
                REASON_KINDS.join(", ")
            ));
        }
    }
    match (label, kinds.is_empty()) {
        (Label::Bad, true) => Err("label = \"bad\" needs `kinds`: the reason kinds that must fire".into()),
        (Label::Good | Label::Tolerated, false) => {
            Err("label = \"good\" or \"tolerated\" takes no `kinds`".into())
        }
        _ => Ok(()),
    }
}

impl LabelledSet {
    /// Read every `*.toml` of `dir` (sorted), checking each entry.
    pub fn load(dir: &Path) -> Result<Self, HarnessError> {
        let io = |error| HarnessError::Io { path: dir.to_path_buf(), error };
        let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(io)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        paths.sort();
        let mut set = LabelledSet::default();
        for path in paths {
            let text = std::fs::read_to_string(&path)
                .map_err(|error| HarnessError::Io { path: path.clone(), error })?;
            let file: LabelledFile = toml::from_str(&text)
                .map_err(|e| HarnessError::Config { path: path.clone(), message: e.to_string() })?;
            for (i, e) in file.entry.iter().enumerate() {
                let fail = |m: String| entry_error(&path, i, &e.name, m);
                check_label(e.label, &e.kinds, &e.also).map_err(fail)?;
                e.edit.check().map_err(|m| fail(format!("edit: {m}")))?;
                if let Some(d) = &e.defect {
                    d.check().map_err(|m| fail(format!("defect: {m}")))?;
                }
                if !(e.noise.is_finite() && e.noise >= 0.0) {
                    return Err(fail(format!("noise = {}: must be a finite number >= 0", e.noise)));
                }
                if set.entries.iter().any(|(_, o)| o.name == e.name) {
                    return Err(fail("the name is already used".into()));
                }
            }
            for (i, r) in file.real.iter().enumerate() {
                r.check().map_err(|m| entry_error(&path, i, &r.name, m))?;
            }
            set.entries.extend(file.entry.into_iter().map(|e| (path.clone(), e)));
            set.real.extend(file.real.into_iter().map(|r| (path.clone(), r)));
        }
        Ok(set)
    }
}

/// The key a loaded scenario is cached under: the scenario file, the source and the size.
type ScenarioKey = (PathBuf, Source, Option<usize>);

/// A scenario's meshes, each with its rest geometry (loaded once for every entry on it).
pub(crate) type Meshes = Vec<(LoadedScenario, RestGeometry)>;

/// The scenario file `written` (relative to `file`) loaded from `source` at `vertices`, or why
/// its data is absent (`Ok(Err(reason))`).
pub(crate) fn load_scenario(
    file: &Path,
    written: &str,
    source: Source,
    vertices: Option<usize>,
    dirs: &DataDirs,
) -> Result<Result<Meshes, String>, HarnessError> {
    let path = file.parent().map(|d| d.join(written)).unwrap_or_else(|| PathBuf::from(written));
    let mut spec: ScenarioSpec = load_spec(&path)?;
    if let Some(reason) = data_missing(&spec) {
        return Ok(Err(reason));
    }
    let data = match source {
        Source::Survey => match (&dirs.survey, &spec.survey) {
            (Some(dir), Some(_)) if dir.is_dir() => {
                spec.procedural = None;
                DataSource::Survey(dir.clone())
            }
            (_, None) => {
                return Err(HarnessError::Config {
                    path,
                    message: "source = \"survey\": the scenario has no `survey`".into(),
                })
            }
            _ => return Ok(Err("needs the survey data (--survey-dir or DEFORM_SURVEY_DIR)".into())),
        },
        Source::Procedural => {
            if let (Some(p), Some(n)) = (spec.procedural.as_mut(), vertices) {
                p.vertices = Some(n);
            }
            DataSource::Procedural
        }
    };
    let loaded = spec.load(&data)?;
    Ok(Ok(loaded
        .scenarios
        .into_iter()
        .map(|s| {
            let rest = RestGeometry::new(&s.mesh, &s.topology);
            (s, rest)
        })
        .collect()))
}

/// Why a scenario's mesh file or manifest is absent, if it is (an unset `${VAR}` or no file).
fn data_missing(spec: &ScenarioSpec) -> Option<String> {
    let base = spec.path.parent().map(Path::to_path_buf).unwrap_or_default();
    let paths = PathContext { base, stem: None, read: Default::default() };
    let (key, written) = match (&spec.mesh, &spec.manifest) {
        (Some(mesh), _) => ("mesh", mesh.as_str()),
        (None, Some(manifest)) => ("manifest.file", manifest.file.as_str()),
        _ => return None,
    };
    paths.resolve_existing(key, written).err()
}

/// Judge every entry of `set` by `rules`: the judged cases and the skipped ones.
pub fn judge_all(
    set: &LabelledSet,
    rules: &VerdictRules,
    dirs: &DataDirs,
) -> Result<(Vec<Judged>, Vec<Skipped>), HarnessError> {
    let mut cache: BTreeMap<ScenarioKey, Result<Meshes, String>> = BTreeMap::new();
    let (mut judged, mut skipped) = (Vec::new(), Vec::new());
    for (i, (file, e)) in set.entries.iter().enumerate() {
        let key = (file.join(&e.scenario), e.source, e.vertices);
        if !cache.contains_key(&key) {
            let loaded = load_scenario(file, &e.scenario, e.source, e.vertices, dirs)?;
            cache.insert(key.clone(), loaded);
        }
        let meshes = match &cache[&key] {
            Ok(meshes) => meshes,
            Err(reason) => {
                skipped.push(Skipped { name: e.name.clone(), reason: reason.clone() });
                continue;
            }
        };
        let several = meshes.len() > 1;
        for (scenario, rest) in meshes {
            let name = if several { format!("{} [{}]", e.name, scenario.spec.name) } else { e.name.clone() };
            let judgement =
                judge_entry(e, scenario, rest, rules).map_err(|m| entry_error(file, i, &e.name, m))?;
            judged.push(Judged {
                name,
                label: e.label,
                kinds: e.kinds.clone(),
                also: e.also.clone(),
                judgement,
            });
        }
    }
    Ok((judged, skipped))
}

/// Build the entry's result on `scenario` (its first step's handles) and judge it.
fn judge_entry(
    e: &EntrySpec,
    scenario: &LoadedScenario,
    rest: &RestGeometry,
    rules: &VerdictRules,
) -> Result<Judgement, String> {
    let handles: &HandleSet = &scenario.steps[0].handles;
    if let Some(Defect::Miss { region: Some(name), .. }) = &e.defect {
        if !handles.regions().iter().any(|r| &r.name == name) {
            let names: Vec<&str> = handles.regions().iter().map(|r| r.name.as_str()).collect();
            return Err(format!(
                "defect.region = \"{name}\": no such region (there are {})",
                names.join(", ")
            ));
        }
    }
    let shape = Shape::new(&scenario.mesh, handles);
    let map = e.edit.map(&shape);
    let good: Vec<[f64; 3]> = scenario.mesh.positions().iter().map(|p| map(*p)).collect();
    let targets = HandleTargets::new(handles, handles.constrained().map(|v| good[v as usize]).collect())
        .map_err(|e| e.to_string())?;
    let mut result = match &e.defect {
        Some(defect) => defect.apply(&shape, &map, &good),
        None => good,
    };
    if e.noise > 0.0 {
        jitter(&mut result, e.noise * shape.diagonal);
    }
    let steps = [(handles, &targets)];
    Ok(measures::judge_on(
        rules,
        rest,
        &scenario.mesh,
        &scenario.topology,
        &result,
        &steps,
        Reference::Missing,
    ))
}

/// Add a deterministic pseudo-random offset of up to `amplitude` per coordinate to `positions`.
fn jitter(positions: &mut [[f64; 3]], amplitude: f64) {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    for p in positions.iter_mut() {
        for x in p.iter_mut() {
            // xorshift64*
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            let r = (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64;
            *x += amplitude * (2.0 * r - 1.0);
        }
    }
}
