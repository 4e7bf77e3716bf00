//! Scenarios: a mesh (survey file or procedural look-alike), its handle set and targets, the methods
//! to run. One TOML file per scenario in `configs/scenarios/`.
//!
//! ```toml
//! name = "bar"
//! description = "135 degree twist of the bar about its axis"
//! survey = "bar"                      # <survey dir>/bar.off, bar.sel, bar.def
//! procedural = { shape = "bar" }      # used when no survey directory is given
//! # procedural = { shape = "bar", vertices = 50000 }
//! # methods = ["laplacian", "arap"]   # default: every registered method
//! ```

use std::path::{Path, PathBuf};

use meshes::shapes::{self, ShapeKind};
use meshes::{AffineTransform, Topology, TriMesh, VertexStatus};
use methods::{HandleRegion, HandleSet, HandleTargets};
use serde::Deserialize;

use crate::error::HarnessError;

/// A scenario file as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSpec {
    /// Unique name, used in reports and on the command line.
    pub name: String,
    /// One line for people.
    #[serde(default)]
    pub description: String,
    /// Stem of the survey files (`.off`, `.sel`, `.def`) in the survey directory.
    #[serde(default)]
    pub survey: Option<String>,
    /// Procedural look-alike, used when no survey directory is given or `survey` is absent.
    #[serde(default)]
    pub procedural: Option<ProceduralSpec>,
    /// Methods to run (default: all registered).
    #[serde(default)]
    pub methods: Option<Vec<String>>,
    /// The file it was read from.
    #[serde(skip)]
    pub path: PathBuf,
}

/// A procedural mesh request.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProceduralSpec {
    /// `bar`, `cylinder`, `cactus` or `plane`.
    pub shape: String,
    /// Approximate vertex count (default: the survey original's).
    #[serde(default)]
    pub vertices: Option<usize>,
}

/// Where meshes come from for this run.
#[derive(Clone, Debug)]
pub enum DataSource {
    /// The original survey files in this directory.
    Survey(PathBuf),
    /// Procedural look-alikes.
    Procedural,
}

/// A scenario ready to run: validated mesh, handles and targets.
pub struct LoadedScenario {
    pub spec: ScenarioSpec,
    /// `survey` or `procedural look-alike`, printed in every report row.
    pub mesh_source: String,
    pub mesh: TriMesh,
    pub topology: Topology,
    pub handles: HandleSet,
    pub targets: HandleTargets,
}

/// Read every `*.toml` in `dir`, sorted by file name; names must be unique.
pub fn load_specs(dir: &Path) -> Result<Vec<ScenarioSpec>, HarnessError> {
    let entries =
        std::fs::read_dir(dir).map_err(|error| HarnessError::Io { path: dir.to_path_buf(), error })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    let mut specs: Vec<ScenarioSpec> = Vec::with_capacity(paths.len());
    for path in paths {
        let spec = load_spec(&path)?;
        if let Some(other) = specs.iter().find(|s| s.name == spec.name) {
            return Err(HarnessError::Config {
                path,
                message: format!("scenario name `{}` is already used by {}", spec.name, other.path.display()),
            });
        }
        specs.push(spec);
    }
    if specs.is_empty() {
        return Err(HarnessError::Config {
            path: dir.to_path_buf(),
            message: "no scenario files (*.toml)".into(),
        });
    }
    Ok(specs)
}

/// Read and check one scenario file.
pub fn load_spec(path: &Path) -> Result<ScenarioSpec, HarnessError> {
    let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
    let text = std::fs::read_to_string(path)
        .map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
    let mut spec: ScenarioSpec = toml::from_str(&text).map_err(|e| config(e.to_string()))?;
    spec.path = path.to_path_buf();
    if spec.survey.is_none() && spec.procedural.is_none() {
        return Err(config("a scenario needs `survey` or `procedural` (or both)".into()));
    }
    if let Some(p) = &spec.procedural {
        p.shape.parse::<ShapeKind>().map_err(|e| config(format!("procedural.shape: {e}")))?;
    }
    for m in spec.methods.iter().flatten() {
        methods::registry::find(m).map_err(|e| config(e.to_string()))?;
    }
    Ok(spec)
}

impl ScenarioSpec {
    /// Methods to run on this scenario, in registry order.
    pub fn method_names(&self) -> Vec<&'static str> {
        let all = methods::registry::method_names();
        match &self.methods {
            Some(list) => all.into_iter().filter(|m| list.iter().any(|l| l == m)).collect(),
            None => all,
        }
    }

    /// Load the mesh and edit from `source` and validate them.
    pub fn load(&self, source: &DataSource) -> Result<LoadedScenario, HarnessError> {
        let fail = |message: String| HarnessError::Scenario { scenario: self.name.clone(), message };
        let (mesh, topology, selection, transform, mesh_source) = match (
            source,
            &self.survey,
            &self.procedural,
        ) {
            (DataSource::Survey(dir), Some(stem), _) => {
                let mesh_path = dir.join(format!("{stem}.off"));
                let mesh = meshes::io::read_mesh(&mesh_path)?;
                mesh.check_nondegenerate().map_err(|e| e.in_file(&mesh_path))?;
                let topology = Topology::new(&mesh).map_err(|e| e.in_file(&mesh_path))?;
                let selection =
                    meshes::io::read_selection(dir.join(format!("{stem}.sel")), mesh.n_vertices())?;
                let transform = meshes::io::read_transform(dir.join(format!("{stem}.def")))?;
                (mesh, topology, selection, transform, "survey".to_string())
            }
            (_, _, Some(p)) => {
                let kind: ShapeKind = p.shape.parse().map_err(|e| fail(format!("{e}")))?;
                let target = p.vertices.unwrap_or_else(|| shapes::default_vertex_count(kind));
                let shape = shapes::generate(kind, target)?;
                shape.mesh.check_nondegenerate()?;
                let topology = Topology::new(&shape.mesh)?;
                (shape.mesh, topology, shape.selection, shape.transform, "procedural look-alike".to_string())
            }
            (DataSource::Procedural, Some(_), None) => return Err(fail(
                "needs the survey data (--survey-dir or DEFORM_SURVEY_DIR) and has no `procedural` fallback"
                    .into(),
            )),
            (_, None, None) => return Err(fail("has neither `survey` nor `procedural`".into())),
        };
        let (handles, targets) =
            survey_edit(&mesh, &selection, &transform).map_err(|e| fail(e.to_string()))?;
        Ok(LoadedScenario { spec: self.clone(), mesh_source, mesh, topology, handles, targets })
    }
}

/// The survey edit as a handle set: region `fixed` (status 0, target = rest position, omitted when
/// empty) and region `handle` (status 2, target = `T (x, y, z, 1)`).
pub fn survey_edit(
    mesh: &TriMesh,
    selection: &[VertexStatus],
    transform: &AffineTransform,
) -> Result<(HandleSet, HandleTargets), methods::MethodError> {
    let fixed = meshes::edit::vertices_with_status(selection, VertexStatus::Fixed);
    let handle = meshes::edit::vertices_with_status(selection, VertexStatus::Handle);
    if handle.is_empty() {
        return Err(methods::MethodError::Handles("the selection has no handle vertices (code 2)".into()));
    }
    let p = mesh.positions();
    let mut targets: Vec<[f64; 3]> = fixed.iter().map(|&v| p[v as usize]).collect();
    targets.extend(handle.iter().map(|&v| transform.apply(p[v as usize])));
    let mut regions = Vec::new();
    if !fixed.is_empty() {
        regions.push(HandleRegion { name: "fixed".into(), vertices: fixed });
    }
    regions.push(HandleRegion { name: "handle".into(), vertices: handle });
    let handles = HandleSet::new(regions, mesh.n_vertices())?;
    let targets = HandleTargets::new(&handles, targets)?;
    Ok((handles, targets))
}
