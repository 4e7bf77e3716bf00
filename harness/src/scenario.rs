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
//!
//! Incremental editing: `[[steps]]` tables, each a new handle set bound to the result of the step
//! before (default: one step, the survey edit).
//!
//! ```toml
//! [[steps]]
//! edit = "survey"        # survey regions: `fixed` held, `handle` moved by the .def transform
//! [[steps]]
//! edit = "hold"          # every region of the step before, held where it is
//! [[steps.patches]]      # plus new handles
//! name = "middle"
//! center = [0.5, 0.5, 1.0]       # bbox coordinates of the rest mesh; the nearest vertex is the seed
//! radius = 0.03                  # vertices within radius x diagonal of the seed (rest positions)
//! translate = [0.0, 0.0, 0.05]   # target = current position + translate x diagonal
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
    /// Edit steps (default: the survey edit alone).
    #[serde(default)]
    pub steps: Vec<StepSpec>,
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

/// One edit step as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSpec {
    /// How the regions of the step before carry over.
    pub edit: StepEdit,
    /// New patch handles.
    #[serde(default)]
    pub patches: Vec<PatchSpec>,
}

/// How a step starts its handle set.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum StepEdit {
    /// The survey regions: `fixed` held, `handle` moved by the survey transform.
    Survey,
    /// Every region of the step before, held at its current position.
    Hold,
}

/// A patch handle: the vertices near a point of the rest mesh, translated.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatchSpec {
    pub name: String,
    /// A point in the rest bounding box, in `[0, 1]^3` box coordinates; the nearest vertex is the seed.
    pub center: [f64; 3],
    /// Radius around the seed, as a fraction of the bounding-box diagonal.
    pub radius: f64,
    /// Target offset, as a fraction of the bounding-box diagonal (default: held in place).
    #[serde(default)]
    pub translate: [f64; 3],
}

/// How a region's targets follow from the current shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// Stay where it is.
    Hold,
    /// The affine transform applied to the current positions.
    Transform(AffineTransform),
    /// Move by this offset.
    Translate([f64; 3]),
}

/// A resolved step: its handle set and how each region moves.
#[derive(Clone, Debug)]
pub struct LoadedStep {
    pub handles: HandleSet,
    /// One per region of `handles`, in order.
    pub motions: Vec<Motion>,
}

impl LoadedStep {
    /// Targets of the constrained vertices for the `#V x 3` shape `current` the step starts from.
    pub fn targets(&self, current: &[[f64; 3]]) -> Result<HandleTargets, methods::MethodError> {
        let mut out = Vec::with_capacity(self.handles.n_constrained());
        for (region, motion) in self.handles.regions().iter().zip(&self.motions) {
            out.extend(region.vertices.iter().map(|&v| {
                let p = current[v as usize];
                match motion {
                    Motion::Hold => p,
                    Motion::Transform(t) => t.apply(p),
                    Motion::Translate(d) => [p[0] + d[0], p[1] + d[1], p[2] + d[2]],
                }
            }));
        }
        HandleTargets::new(&self.handles, out)
    }
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
    /// The edit steps, at least one.
    pub steps: Vec<LoadedStep>,
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
        let steps = self.resolve_steps(&mesh, &selection, &transform).map_err(fail)?;
        Ok(LoadedScenario { spec: self.clone(), mesh_source, mesh, topology, steps })
    }

    /// The handle sets of the steps on the rest mesh (default: the survey edit alone).
    fn resolve_steps(
        &self,
        mesh: &TriMesh,
        selection: &[VertexStatus],
        transform: &AffineTransform,
    ) -> Result<Vec<LoadedStep>, String> {
        let default = [StepSpec { edit: StepEdit::Survey, patches: Vec::new() }];
        let specs = if self.steps.is_empty() { &default[..] } else { &self.steps[..] };
        let diagonal = mesh.bbox_diagonal();
        let (lo, hi) = mesh.bbox();
        let mut steps: Vec<LoadedStep> = Vec::with_capacity(specs.len());
        for (i, spec) in specs.iter().enumerate() {
            let at = |message: String| format!("step {}: {message}", i + 1);
            let (mut regions, mut motions) = match spec.edit {
                StepEdit::Survey => {
                    let (handles, motions) =
                        survey_regions(selection, transform).map_err(|e| at(e.to_string()))?;
                    (handles, motions)
                }
                StepEdit::Hold => {
                    let Some(previous) = steps.last() else {
                        return Err(at("`edit = \"hold\"` needs a step before it".into()));
                    };
                    (
                        previous.handles.regions().to_vec(),
                        vec![Motion::Hold; previous.handles.regions().len()],
                    )
                }
            };
            let mut taken = vec![false; mesh.n_vertices()];
            for r in &regions {
                r.vertices.iter().for_each(|&v| taken[v as usize] = true);
            }
            for patch in &spec.patches {
                let at = |message: String| at(format!("patch `{}`: {message}", patch.name));
                if !(patch.radius > 0.0 && patch.radius.is_finite())
                    || patch.center.iter().chain(&patch.translate).any(|c| !c.is_finite())
                {
                    return Err(at("radius must be positive and finite, center and translate finite".into()));
                }
                let point: [f64; 3] = std::array::from_fn(|c| lo[c] + patch.center[c] * (hi[c] - lo[c]));
                let p = mesh.positions();
                let distance = |v: usize| meshes::vector::norm(meshes::vector::sub(p[v], point));
                let seed = (0..p.len())
                    .min_by(|&a, &b| distance(a).total_cmp(&distance(b)))
                    .expect("non-empty mesh");
                let reach = patch.radius * diagonal;
                let vertices: Vec<u32> = (0..p.len())
                    .filter(|&v| {
                        !taken[v] && meshes::vector::norm(meshes::vector::sub(p[v], p[seed])) <= reach
                    })
                    .map(|v| v as u32)
                    .collect();
                if vertices.is_empty() {
                    return Err(at(format!(
                        "no free vertex within {} x diagonal of vertex {seed}",
                        patch.radius
                    )));
                }
                vertices.iter().for_each(|&v| taken[v as usize] = true);
                regions.push(HandleRegion { name: patch.name.clone(), vertices });
                motions.push(if patch.translate == [0.0; 3] {
                    Motion::Hold
                } else {
                    Motion::Translate(patch.translate.map(|c| c * diagonal))
                });
            }
            let handles = HandleSet::new(regions, mesh.n_vertices()).map_err(|e| at(e.to_string()))?;
            steps.push(LoadedStep { handles, motions });
        }
        Ok(steps)
    }
}

/// The survey regions: `fixed` (status 0, held; omitted when empty) and `handle` (status 2, moved by
/// `transform`).
fn survey_regions(
    selection: &[VertexStatus],
    transform: &AffineTransform,
) -> Result<(Vec<HandleRegion>, Vec<Motion>), methods::MethodError> {
    let fixed = meshes::edit::vertices_with_status(selection, VertexStatus::Fixed);
    let handle = meshes::edit::vertices_with_status(selection, VertexStatus::Handle);
    if handle.is_empty() {
        return Err(methods::MethodError::Handles("the selection has no handle vertices (code 2)".into()));
    }
    let mut regions = Vec::new();
    let mut motions = Vec::new();
    if !fixed.is_empty() {
        regions.push(HandleRegion { name: "fixed".into(), vertices: fixed });
        motions.push(Motion::Hold);
    }
    regions.push(HandleRegion { name: "handle".into(), vertices: handle });
    motions.push(Motion::Transform(transform.clone()));
    Ok((regions, motions))
}

/// The survey edit on the rest mesh as a handle set and its targets: region `fixed` (status 0,
/// target = rest position, omitted when empty) and region `handle` (status 2, target =
/// `T (x, y, z, 1)`).
pub fn survey_edit(
    mesh: &TriMesh,
    selection: &[VertexStatus],
    transform: &AffineTransform,
) -> Result<(HandleSet, HandleTargets), methods::MethodError> {
    let (regions, motions) = survey_regions(selection, transform)?;
    let step = LoadedStep { handles: HandleSet::new(regions, mesh.n_vertices())?, motions };
    let targets = step.targets(mesh.positions())?;
    Ok((step.handles, targets))
}
