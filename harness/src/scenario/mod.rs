//! Scenarios: a mesh (survey file, procedural look-alike, or any mesh file by path, alone or as a
//! collection), its regions and their edits, the methods to run. One TOML file per scenario in
//! `configs/scenarios/` (or any file given by path).
//!
//! ```toml
//! name = "knight"
//! mesh = "${DEFORM_REAL_MESHES_DIR}/decimated-knight.off"   # OFF, OBJ, PLY, glTF/GLB; relative to this file
//! # meshes = "models/*.ply"                                 # a collection: one case per mesh x method
//! [[regions]]                                               # see `selection` and `motion`
//! name = "base"
//! role = "fixed"
//! select = { dmat = { file = "${DEFORM_REAL_MESHES_DIR}/decimated-knight-selection.dmat", id = 0 } }
//! [[regions]]
//! name = "head"
//! role = "handle"
//! select = { dmat = { file = "${DEFORM_REAL_MESHES_DIR}/decimated-knight-selection.dmat", id = 1 } }
//! rotate = { axis = [0, 0, 1], degrees = 30 }
//! ```
//!
//! On load a mesh file's unreferenced vertices are dropped (a note says how many; results are still
//! written in the input's vertex order), exact duplicate vertices are reported, and a connected
//! component that holds no constrained vertex is an error naming it (its system is singular).
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

pub mod frame;
pub mod manifest;
pub mod motion;
pub mod selection;

use std::path::{Path, PathBuf};

use meshes::shapes::{self, ShapeKind};
use meshes::{AffineTransform, Topology, TriMesh, VertexStatus};
use methods::{HandleRegion, HandleSet, HandleTargets};
use serde::{Deserialize, Serialize};

use crate::error::HarnessError;
pub use frame::{Frame, PrincipalFrame};
pub use manifest::{ManifestEntry, ManifestSpec};
pub use motion::{Motion, RotateSpec, TransformSpec, Units};
pub use selection::{FilesRead, InputIndex, PathContext, Role, Selection, SelectionFiles};

/// The `mesh_source` of a scenario whose mesh was read from a file named in the scenario.
pub const FILE_SOURCE: &str = "file";

/// A scenario file as written.
#[derive(Clone, Debug, Default, Deserialize)]
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
    /// A mesh file (relative to this file, absolute, or `${VAR}/...`).
    #[serde(default)]
    pub mesh: Option<String>,
    /// A glob of mesh files: one scenario `<name>-<stem>` per match, in sorted order.
    #[serde(default)]
    pub meshes: Option<String>,
    /// The rows of a manifest CSV that meet its conditions: one scenario `<name>-<stem>` per row
    /// ([`manifest`]).
    #[serde(default)]
    pub manifest: Option<ManifestSpec>,
    /// The axis the mesh stands on, drawn upwards in the figures (default `z`, the survey's).
    #[serde(default)]
    pub up: Option<selection::Axis>,
    /// The frame `[[regions]]` and patches are written in: `"bbox"` (default) or `"principal"`, the
    /// rest mesh's principal axes ([`frame`]).
    #[serde(default)]
    pub frame: Frame,
    /// Repair each mesh file before use ([`meshes::repair`]: zero-area and repeated faces and the
    /// extra faces of non-manifold edges dropped, orientation made consistent); what it changed is
    /// a note of the scenario and part of its cases' record. Default `false`: such meshes are
    /// refused (a collection skips them).
    #[serde(default)]
    pub repair: bool,
    /// Subdivide each mesh file this many times once it is loaded (and repaired), before anything
    /// else ([`meshes::subdivision`]: each level makes four faces of one), so a real shape runs at
    /// any size. Regions must then be in bounding-box coordinates (`box`, `sphere`, `slab`): vertex
    /// ids of the file would name only its old vertices. Default 0.
    #[serde(default)]
    pub refine: u32,
    /// How [`ScenarioSpec::refine`] places vertices: `"loop"` (default: a smooth surface, like a
    /// finer scan of the object) or `"midpoint"` (the file's exact shape, sampled finer).
    #[serde(default)]
    pub refine_scheme: RefineScheme,
    /// The regions of the first edit (default for `survey`/`procedural`: the survey selection).
    #[serde(default)]
    pub regions: Vec<RegionSpec>,
    /// Methods to run (default: all registered).
    #[serde(default)]
    pub methods: Option<Vec<String>>,
    /// Methods that would run here but are left out, each with the reason and the measured figure
    /// behind it (`left_out = { scale_aware = "..." }`): subtracted from `methods` (or the
    /// default), and each one a note of the run and a row of `size-series.md`, so a method that
    /// cannot run at a size is reported, not silently missing.
    #[serde(default)]
    pub left_out: std::collections::BTreeMap<String, String>,
    /// One shape at several sizes: the scenarios that share a `series` name are one line per
    /// method in `plots/size-series` and one table in `size-series.md` (time per phase, memory and
    /// fitted slopes against #V). E.g. `"igea"` for igea refined 0, 1 and 2 times.
    #[serde(default)]
    pub series: Option<String>,
    /// Whether reports write this scenario's result meshes and the 3D view's files (default: for
    /// meshes up to [`RESULT_MESHES_MAX_VERTICES`]; `--every-mesh` writes them anyway).
    #[serde(default)]
    pub result_meshes: Option<bool>,
    /// Edit steps (default: the first edit alone, the survey's or the `[[regions]]`).
    #[serde(default)]
    pub steps: Vec<StepSpec>,
    /// The file it was read from.
    #[serde(skip)]
    pub path: PathBuf,
    /// Every file the scenario named and loading read (meshes, selections, transforms).
    #[serde(skip)]
    pub files_read: FilesRead,
}

/// The subdivision scheme of `refine_scheme` ([`meshes::subdivision::Scheme`]).
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum RefineScheme {
    #[default]
    Loop,
    Midpoint,
}

impl RefineScheme {
    fn scheme(self) -> meshes::subdivision::Scheme {
        match self {
            RefineScheme::Loop => meshes::subdivision::Scheme::Loop,
            RefineScheme::Midpoint => meshes::subdivision::Scheme::Midpoint,
        }
    }
}

/// A region as written: its vertices and, for a handle, its transform (see [`motion`]). The
/// transform fields repeat [`TransformSpec`]'s because serde cannot flatten it and still reject
/// unknown keys.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionSpec {
    pub name: String,
    pub role: Role,
    pub select: Selection,
    #[serde(default)]
    pub rotate: Option<RotateSpec>,
    #[serde(default)]
    pub scale: Option<f64>,
    #[serde(default)]
    pub translate: Option<[f64; 3]>,
    #[serde(default)]
    pub translate_units: Units,
    #[serde(default)]
    pub def: Option<String>,
}

impl RegionSpec {
    fn transform(&self) -> TransformSpec {
        TransformSpec {
            rotate: self.rotate.clone(),
            scale: self.scale,
            translate: self.translate,
            translate_units: self.translate_units,
            def: self.def.clone(),
        }
    }
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
    /// The scenario's `[[regions]]`: fixed ones held, handles moved by their transforms.
    Regions,
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

/// A resolved step: its handle set and how each region moves.
#[derive(Clone, Debug)]
pub struct LoadedStep {
    pub handles: HandleSet,
    /// One per region of `handles`, in order.
    pub motions: Vec<Motion>,
    /// One per region of `handles`: `Fixed` or `Handle` (for the figures' colours).
    pub roles: Vec<Role>,
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

/// Above this many vertices a scenario's result meshes and 3D-view files are written only when it
/// says `result_meshes = true` or the run asks `--every-mesh`: a 1M-vertex case writes 48 MB of
/// `.glb` and 8 MB of view data (its test's rest mesh another 41 MB), and a page of such cases
/// stops being something to open.
pub const RESULT_MESHES_MAX_VERTICES: usize = 200_000;

/// A scenario ready to run: validated mesh, handles and targets.
pub struct LoadedScenario {
    pub spec: ScenarioSpec,
    /// `survey`, `procedural look-alike` or `file`, printed in every report row.
    pub mesh_source: String,
    pub mesh: TriMesh,
    pub topology: Topology,
    /// The edit steps, at least one.
    pub steps: Vec<LoadedStep>,
    /// The mesh file as read, when unreferenced vertices were dropped from it: results are written in
    /// its vertex order ([`LoadedScenario::in_input_order`]).
    pub input: Option<InputMesh>,
    /// What loading noticed (dropped or duplicate vertices), for the run's output and the page.
    pub notes: Vec<String>,
    /// The collection and mesh this scenario is one of (`meshes` or `[manifest]`).
    pub member: Option<Member>,
    /// What `repair = true` changed in its mesh file, when it changed something.
    pub repaired: Option<Repaired>,
}

/// A mesh file that `repair = true` changed, and what it changed ([`meshes::repair::RepairLog::summary`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Repaired {
    pub file: PathBuf,
    pub changes: String,
}

/// What [`ScenarioSpec::load`] made of a scenario file: the scenarios that load, and the meshes
/// of a collection it skipped.
pub struct Loaded {
    pub scenarios: Vec<LoadedScenario>,
    pub skipped: Vec<SkippedInput>,
}

/// A scenario of a collection: the collection's name (its scenario file's `name`, the edit family
/// of a dataset), the mesh file's stem, and the mesh's row of the manifest (empty for a glob).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Member {
    pub collection: String,
    pub mesh: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub attributes: Vec<(String, String)>,
    /// What `repair = true` changed in the mesh, if anything.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repaired: Option<String>,
}

impl Member {
    /// The manifest's value of `column`, if it has one.
    pub fn attribute(&self, column: &str) -> Option<&str> {
        self.attributes.iter().find(|(c, _)| c == column).map(|(_, v)| v.as_str())
    }
}

/// A mesh of a collection that no case ran on: the scenario it would have been, its file, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkippedInput {
    pub scenario: String,
    pub file: PathBuf,
    pub reason: String,
    pub member: Member,
}

/// The reason a collection's mesh is skipped, without the scenario name the record already has.
fn skip_reason(error: &HarnessError) -> String {
    match error {
        HarnessError::Scenario { message, .. } => message.clone(),
        other => other.to_string(),
    }
}

/// The size of mesh a scenario asks for, given to the run's memory check before the mesh is made,
/// read or refined ([`ScenarioSpec::load_checked`]).
pub struct SizeRequest<'a> {
    pub spec: &'a ScenarioSpec,
    /// The scenario's name (`<name>-<stem>` for a mesh of a collection).
    pub scenario: &'a str,
    /// The key of the scenario file that asks for the size: `refine = 12`,
    /// `procedural = { shape = "bar", vertices = 5000000 }`, `mesh = "big.ply"`.
    pub key: String,
    /// The mesh, in words: `cube.off (8 vertices, 12 faces) refined 12 times: 100.7M vertices`.
    pub mesh: String,
    /// The mesh the methods will see.
    pub vertices: f64,
    pub faces: f64,
}

/// The run's memory check: `Err` refuses the size ([`crate::memory`]).
pub type SizeCheck<'a> = &'a dyn Fn(&SizeRequest) -> Result<(), HarnessError>;

/// A mesh file as read, and which of its vertices the scenario's mesh kept.
#[derive(Clone, Debug)]
pub struct InputMesh {
    pub mesh: TriMesh,
    /// Mesh vertex `i` is input vertex `kept[i]`.
    pub kept: Vec<u32>,
}

impl LoadedScenario {
    /// Whether reports write this scenario's result meshes and 3D-view files by default: its
    /// `result_meshes`, else whether the mesh has at most [`RESULT_MESHES_MAX_VERTICES`].
    pub fn writes_result_meshes(&self) -> bool {
        self.spec.result_meshes.unwrap_or(self.mesh.n_vertices() <= RESULT_MESHES_MAX_VERTICES)
    }

    /// `#V x 3` positions on this scenario's mesh from positions in the input file's vertex order (the
    /// inverse of [`LoadedScenario::in_input_order`]).
    pub fn from_input_order(&self, positions: &[[f64; 3]]) -> Result<Vec<[f64; 3]>, String> {
        let expected = self.input.as_ref().map_or(self.mesh.n_vertices(), |i| i.mesh.n_vertices());
        if positions.len() != expected {
            return Err(format!("has {} vertices, the scenario's mesh {expected}", positions.len()));
        }
        Ok(match &self.input {
            None => positions.to_vec(),
            Some(input) => input.kept.iter().map(|&v| positions[v as usize]).collect(),
        })
    }

    /// The mesh with `#V x 3` `positions` (a result on this scenario's mesh), in the input file's
    /// vertex order: dropped vertices at their input position, faces as in the file.
    pub fn in_input_order(&self, positions: &[[f64; 3]]) -> Result<TriMesh, meshes::MeshError> {
        match &self.input {
            None => self.mesh.with_positions(positions.to_vec()),
            Some(input) => {
                let mut out = input.mesh.positions().to_vec();
                for (p, &v) in positions.iter().zip(&input.kept) {
                    out[v as usize] = *p;
                }
                input.mesh.with_positions(out)
            }
        }
    }
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
    // Keys sorted, as toml's map had them before the workspace enabled `preserve_order`: of several
    // faults in a file, serde names the first it meets.
    let table = crate::config::in_key_order(read_extended(path, 0)?);
    let mut spec: ScenarioSpec = table.try_into().map_err(|e: toml::de::Error| config(e.to_string()))?;
    spec.path = path.to_path_buf();
    let builtin = spec.survey.is_some() || spec.procedural.is_some();
    let files =
        spec.mesh.is_some() as usize + spec.meshes.is_some() as usize + spec.manifest.is_some() as usize;
    match (builtin, files) {
        (false, 0) => {
            return Err(config(
                "a scenario needs a mesh: `mesh`, `meshes`, `[manifest]`, `survey` or `procedural`".into(),
            ))
        }
        (true, 1..) => {
            return Err(config(
                "give either a mesh file (`mesh`, `meshes`, `[manifest]`) or `survey`/`procedural`, not both"
                    .into(),
            ))
        }
        (_, 2..) => {
            return Err(config(
                "give one of `mesh` (a file), `meshes` (a glob) and `[manifest]` (a filtered CSV)".into(),
            ))
        }
        _ => {}
    }
    if files > 0 && spec.regions.is_empty() {
        return Err(config("a mesh file needs its [[regions]] (at least one fixed or handle region)".into()));
    }
    if let Some(p) = &spec.procedural {
        p.shape.parse::<ShapeKind>().map_err(|e| config(format!("procedural.shape: {e}")))?;
    }
    if spec.refine > 0 {
        if builtin {
            return Err(config(
                "`refine` applies to mesh files (`mesh`, `meshes`, `[manifest]`); a procedural shape \
                 takes its size from `vertices`"
                    .into(),
            ));
        }
        let by_ids = spec.regions.iter().find(|r| {
            !matches!(r.select, Selection::Box { .. } | Selection::Sphere { .. } | Selection::Slab { .. })
        });
        if let Some(region) = by_ids {
            return Err(config(format!(
                "region `{}`: `refine` needs regions in bounding-box coordinates (box, sphere, slab); \
                 vertex ids of the file would name only its old vertices",
                region.name
            )));
        }
    }
    if let Some((method, _)) = spec.left_out.iter().find(|(_, why)| why.trim().is_empty()) {
        return Err(config(format!("left_out.{method}: give the reason it is left out (a measured figure)")));
    }
    if spec.series.as_deref().is_some_and(|s| s.trim().is_empty()) {
        return Err(config("`series` names the shape a size series is of; it cannot be empty".into()));
    }
    // The names in `methods` and `left_out` are checked against the run's methods (configs/methods.toml and any
    // peers) when the run is prepared.
    Ok(spec)
}

/// The keys that say where a scenario's mesh comes from: a file that `extends` another and gives
/// one of them replaces all of the other's.
const MESH_SOURCE_KEYS: [&str; 5] = ["mesh", "meshes", "manifest", "survey", "procedural"];

/// The TOML table of the scenario file `path`, with what it `extends` filled in: the keys of the
/// file it names (relative to `path`), each replaced by `path`'s own where it gives it. `depth`
/// counts the files that extended this one (a chain longer than 8 is taken for a cycle).
fn read_extended(path: &Path, depth: usize) -> Result<toml::Table, HarnessError> {
    let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
    let text = std::fs::read_to_string(path)
        .map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
    let mut table: toml::Table = toml::from_str(&text).map_err(|e| config(e.to_string()))?;
    let Some(extends) = table.remove("extends") else {
        return Ok(table);
    };
    let toml::Value::String(base) = extends else {
        return Err(config("`extends` is the path of another scenario file".into()));
    };
    if depth >= 8 {
        return Err(config(format!(
            "`extends = \"{base}\"`: more than 8 files extend each other (a cycle?)"
        )));
    }
    let base_path = path.parent().map(|d| d.join(&base)).unwrap_or_else(|| PathBuf::from(&base));
    let mut merged = read_extended(&base_path, depth + 1)?;
    if MESH_SOURCE_KEYS.iter().any(|k| table.contains_key(*k)) {
        MESH_SOURCE_KEYS.iter().for_each(|k| {
            merged.remove(*k);
        });
    }
    merged.extend(table);
    Ok(merged)
}

/// The first edit of a scenario: its regions, how each moves and its role.
struct InitialEdit {
    regions: Vec<HandleRegion>,
    motions: Vec<Motion>,
    roles: Vec<Role>,
}

/// A survey mesh or procedural look-alike: the mesh, its topology, its survey selection and
/// transform (the survey edit), and where it came from (`mesh_source`).
struct BuiltinMesh {
    mesh: TriMesh,
    topology: Topology,
    selection: Vec<VertexStatus>,
    transform: AffineTransform,
    mesh_source: String,
}

/// A mesh file as a scenario uses it (read, repaired, refined), the notes of what was done to it,
/// the collection's member it is (with what repair changed) and the record of a repair.
struct FileMesh {
    input: TriMesh,
    notes: Vec<String>,
    member: Option<Member>,
    repaired: Option<Repaired>,
}

/// The notes on the mesh file `path` once its unreferenced vertices are dropped (`mesh`, `map`):
/// how many were dropped, and how many of the others are exact duplicates.
fn cleaning_notes(path: &Path, mesh: &TriMesh, map: &meshes::clean::VertexMap) -> Vec<String> {
    let mut notes = Vec::new();
    let dropped = map.dropped();
    if !dropped.is_empty() {
        notes.push(format!(
            "{}: {} unreferenced vertices dropped (e.g. vertex {}); results are written in the file's vertex order",
            path.display(),
            dropped.len(),
            dropped[0]
        ));
    }
    let duplicates = meshes::clean::exact_duplicate_vertices(mesh.positions());
    if let Some((a, b)) = duplicates.first() {
        notes.push(format!(
            "{}: {} exact duplicate vertices (e.g. mesh vertices {a} and {b} at the same position); they are kept as distinct vertices",
            path.display(),
            duplicates.len()
        ));
    }
    notes
}

/// The per-vertex files of a mesh file with `n_input` vertices, read with the mesh crate's readers.
struct InputFiles {
    n_input: usize,
}

impl SelectionFiles for InputFiles {
    fn sel(&self, file: &Path) -> Result<Vec<u8>, String> {
        let codes = meshes::io::read_selection(file, self.n_input).map_err(|e| e.to_string())?;
        Ok(codes.into_iter().map(VertexStatus::code).collect())
    }

    fn dmat(&self, file: &Path) -> Result<Vec<i64>, String> {
        meshes::io::read_dmat_integers(file).map_err(|e| e.to_string())
    }

    fn index_list(&self, file: &Path) -> Result<Vec<u32>, String> {
        meshes::io::read_index_list(file).map_err(|e| e.to_string())
    }
}

impl ScenarioSpec {
    /// Where this scenario's relative paths start.
    fn paths(&self, stem: Option<String>) -> PathContext {
        let base = self.path.parent().map(Path::to_path_buf).unwrap_or_default();
        PathContext { base, stem, read: self.files_read.clone() }
    }

    /// Load the mesh(es) and edit and validate them: one scenario, or one per file of a collection
    /// (`meshes` or `[manifest]`), named `<name>-<file stem>`. A file of a collection that cannot
    /// be loaded or edited (refused at load, a region that selects nothing on it, a component with
    /// no constrained vertex) is skipped with its reason; the others load. Errors: a single mesh
    /// that cannot be loaded, a collection that matches no file or whose every file is skipped.
    pub fn load(&self, source: &DataSource) -> Result<Loaded, HarnessError> {
        self.load_checked(source, &|_| Ok(()))
    }

    /// [`ScenarioSpec::load`], each mesh's size given to `check` before the mesh is generated, read
    /// (when its header tells its size: OFF, PLY) and refined, so a size the machine cannot hold is
    /// refused before anything large is allocated.
    pub fn load_checked(&self, source: &DataSource, check: SizeCheck) -> Result<Loaded, HarnessError> {
        let fail = |message: String| HarnessError::Scenario {
            scenario: self.name.clone(),
            file: Some(self.path.clone()),
            message,
        };
        let members: Vec<(PathBuf, Vec<(String, String)>)> = if let Some(manifest) = &self.manifest {
            let entries = manifest.entries(&self.paths(None)).map_err(fail)?;
            entries.into_iter().map(|e| (e.path, e.columns)).collect()
        } else if let Some(pattern) = &self.meshes {
            let resolved = self.paths(None).resolve(pattern).map_err(|e| fail(format!("meshes: {e}")))?;
            let text = absolute(&resolved).to_string_lossy().into_owned();
            let mut paths: Vec<PathBuf> = glob::glob(&text)
                .map_err(|e| fail(format!("meshes = \"{pattern}\": not a glob pattern: {e}")))?
                .filter_map(Result::ok)
                .filter(|p| p.is_file())
                .collect();
            paths.sort();
            if paths.is_empty() {
                return Err(fail(format!("meshes = \"{pattern}\" ({text}) matches no file")));
            }
            paths.into_iter().map(|p| (p, Vec::new())).collect()
        } else if let Some(mesh) = &self.mesh {
            let path = self.paths(None).resolve_existing("mesh", mesh).map_err(fail)?;
            let stem = file_stem(&path);
            let scenario = self.load_file(&path, &self.name, Some(stem), None, check)?;
            return Ok(Loaded { scenarios: vec![scenario], skipped: Vec::new() });
        } else {
            return Ok(Loaded { scenarios: vec![self.load_builtin(source, check)?], skipped: Vec::new() });
        };
        let mut loaded = Loaded { scenarios: Vec::new(), skipped: Vec::new() };
        for (path, attributes) in members {
            self.files_read.push(path.clone());
            let stem = file_stem(&path);
            let name = format!("{}-{stem}", self.name);
            let member =
                Member { collection: self.name.clone(), mesh: stem.clone(), attributes, repaired: None };
            match self.load_file(&path, &name, Some(stem), Some(member.clone()), check) {
                Ok(scenario) => loaded.scenarios.push(scenario),
                Err(e) => loaded.skipped.push(SkippedInput {
                    scenario: name,
                    file: path,
                    reason: skip_reason(&e),
                    member,
                }),
            }
        }
        if loaded.scenarios.is_empty() {
            let first = &loaded.skipped[0];
            return Err(fail(format!(
                "every one of its {} meshes was skipped; the first, {}: {}",
                loaded.skipped.len(),
                first.file.display(),
                first.reason
            )));
        }
        Ok(loaded)
    }

    /// A survey mesh or procedural look-alike, with the survey edit or the scenario's regions.
    fn load_builtin(&self, source: &DataSource, check: SizeCheck) -> Result<LoadedScenario, HarnessError> {
        let fail = |message: String| self.scenario_error(message);
        let builtin = match (source, &self.survey, &self.procedural) {
            (DataSource::Survey(dir), Some(stem), _) => self.survey_mesh(dir, stem, check)?,
            (_, _, Some(p)) => self.procedural_mesh(p, check)?,
            (DataSource::Procedural, Some(_), None) => return Err(fail(
                "needs the survey data (--survey-dir or DEFORM_SURVEY_DIR) and has no `procedural` fallback"
                    .into(),
            )),
            (_, None, None) => return Err(fail("has neither `survey` nor `procedural`".into())),
        };
        let BuiltinMesh { mesh, topology, selection, transform, mesh_source } = builtin;
        let steps = self.builtin_steps(&mesh, &selection, &transform).map_err(fail)?;
        check_components(&mesh, &steps, None).map_err(fail)?;
        Ok(LoadedScenario {
            spec: self.clone(),
            mesh_source,
            mesh,
            topology,
            steps,
            input: None,
            notes: Vec::new(),
            member: None,
            repaired: None,
        })
    }

    /// The error `message` of this scenario, naming it and its file.
    fn scenario_error(&self, message: String) -> HarnessError {
        HarnessError::Scenario { scenario: self.name.clone(), file: Some(self.path.clone()), message }
    }

    /// The survey's mesh `stem` in `dir` (`<stem>.off`) with its selection (`.sel`) and transform
    /// (`.def`), its size given to `check` first when the header tells it.
    fn survey_mesh(&self, dir: &Path, stem: &str, check: SizeCheck) -> Result<BuiltinMesh, HarnessError> {
        let mesh_path = dir.join(format!("{stem}.off"));
        if let Some((v, f)) = meshes::io::header_counts(&mesh_path) {
            check(&SizeRequest {
                spec: self,
                scenario: &self.name,
                key: format!("survey = \"{stem}\""),
                mesh: format!("{} ({} vertices)", mesh_path.display(), crate::memory::count(v as f64)),
                vertices: v as f64,
                faces: f as f64,
            })?;
        }
        for extension in ["off", "sel", "def"] {
            self.files_read.push(dir.join(format!("{stem}.{extension}")));
        }
        let mesh = meshes::io::read_mesh(&mesh_path)?;
        mesh.check_nondegenerate().map_err(|e| e.in_file(&mesh_path))?;
        let topology = Topology::new(&mesh).map_err(|e| e.in_file(&mesh_path))?;
        let selection = meshes::io::read_selection(dir.join(format!("{stem}.sel")), mesh.n_vertices())?;
        let transform = meshes::io::read_transform(dir.join(format!("{stem}.def")))?;
        Ok(BuiltinMesh { mesh, topology, selection, transform, mesh_source: "survey".to_string() })
    }

    /// The procedural look-alike `p` asks for, with its survey-like selection and transform, its
    /// size given to `check` before it is generated.
    fn procedural_mesh(&self, p: &ProceduralSpec, check: SizeCheck) -> Result<BuiltinMesh, HarnessError> {
        let kind: ShapeKind = p.shape.parse().map_err(|e| self.scenario_error(format!("{e}")))?;
        let target = p.vertices.unwrap_or_else(|| shapes::default_vertex_count(kind));
        let vertices = p.vertices.map(|n| format!(", vertices = {n}")).unwrap_or_default();
        check(&SizeRequest {
            spec: self,
            scenario: &self.name,
            key: format!("procedural = {{ shape = \"{}\"{vertices} }}", p.shape),
            mesh: format!("the procedural {} of {} vertices", p.shape, crate::memory::count(target as f64)),
            // A closed triangle mesh has about two faces per vertex.
            vertices: target as f64,
            faces: 2.0 * target as f64,
        })?;
        let shape = shapes::generate(kind, target)?;
        shape.mesh.check_nondegenerate()?;
        let topology = Topology::new(&shape.mesh)?;
        Ok(BuiltinMesh {
            mesh: shape.mesh,
            topology,
            selection: shape.selection,
            transform: shape.transform,
            mesh_source: "procedural look-alike".to_string(),
        })
    }

    /// The steps on a survey or procedural `mesh`: the survey edit (its `selection` and
    /// `transform`) when the scenario has no `[[regions]]`, else its regions in its frame. `Err`:
    /// the message.
    fn builtin_steps(
        &self,
        mesh: &TriMesh,
        selection: &[VertexStatus],
        transform: &AffineTransform,
    ) -> Result<Vec<LoadedStep>, String> {
        if self.regions.is_empty() {
            if self.frame != Frame::Bbox {
                return Err(
                    "`frame` applies to [[regions]]; the survey edit is in the mesh's own coordinates".into(),
                );
            }
            let (regions, motions) = survey_regions(selection, transform).map_err(|e| e.to_string())?;
            let roles =
                regions.iter().map(|r| if r.name == "fixed" { Role::Fixed } else { Role::Handle }).collect();
            return self.resolve_steps(mesh, &InitialEdit { regions, motions, roles });
        }
        let input = InputIndex::identity(mesh.n_vertices());
        let files = InputFiles { n_input: mesh.n_vertices() };
        self.steps_in_frame(mesh, |m| {
            let initial = self.regions_edit(m, &input, &self.paths(None), &files)?;
            self.resolve_steps(m, &initial)
        })
    }

    /// The mesh file `path` as the scenario `name` (its `{stem}` for the region files).
    fn load_file(
        &self,
        path: &Path,
        name: &str,
        stem: Option<String>,
        member: Option<Member>,
        check: SizeCheck,
    ) -> Result<LoadedScenario, HarnessError> {
        let fail = |message: String| HarnessError::Scenario {
            scenario: name.to_string(),
            file: Some(self.path.clone()),
            message,
        };
        let FileMesh { input, mut notes, member, repaired } =
            self.read_mesh_file(path, name, member, check)?;
        let (mesh, map) = meshes::clean::drop_unreferenced(&input);
        notes.extend(cleaning_notes(path, &mesh, &map));
        mesh.check_nondegenerate().map_err(|e| e.in_file(path))?;
        let topology = Topology::new(&mesh).map_err(|e| e.in_file(path))?;
        let mut spec = self.clone();
        spec.name = name.to_string();
        let steps = spec.file_steps(&mesh, &input, &map, &self.paths(stem)).map_err(fail)?;
        let kept = map.kept().to_vec();
        check_components(&mesh, &steps, Some(&kept)).map_err(|e| fail(format!("{}: {e}", path.display())))?;
        let input = (!map.dropped().is_empty()).then(|| InputMesh { mesh: input, kept });
        Ok(LoadedScenario {
            spec,
            mesh_source: FILE_SOURCE.to_string(),
            mesh,
            topology,
            steps,
            input,
            notes,
            member,
            repaired,
        })
    }

    /// The mesh file `path` as the scenario `name` uses it: read, repaired and refined as the
    /// scenario says, its size given to `check` before it is read (when its header tells it) and
    /// before it is refined; with the notes of what was done to it, and `member` (a collection's
    /// mesh) with what repair changed.
    fn read_mesh_file(
        &self,
        path: &Path,
        name: &str,
        mut member: Option<Member>,
        check: SizeCheck,
    ) -> Result<FileMesh, HarnessError> {
        if let Some((v, f)) = meshes::io::header_counts(path) {
            check(&self.file_size_request(path, name, (v, f), " by its header"))?;
        }
        let mut notes = Vec::new();
        let (mut input, repaired) =
            self.repaired(meshes::io::read_mesh(path)?, path, &mut notes, &mut member)?;
        check(&self.file_size_request(path, name, (input.n_vertices(), input.n_faces()), ""))?;
        if self.refine > 0 {
            input = self.refined(input, path, &mut notes)?;
        }
        Ok(FileMesh { input, notes, member, repaired })
    }

    /// What the run's memory check is told of the mesh file `path` of `counts` (vertices, faces;
    /// `told` says where they come from) as the scenario `name`: refined when the scenario says so.
    fn file_size_request<'a>(
        &'a self,
        path: &Path,
        name: &'a str,
        (v, f): (usize, usize),
        told: &str,
    ) -> SizeRequest<'a> {
        let (vertices, faces) = crate::memory::refined_size(v as f64, f as f64, self.refine);
        let (key, mesh) = if self.refine > 0 {
            (
                format!("refine = {}", self.refine),
                format!(
                    "{} ({v} vertices, {f} faces{told}) refined {} times: {} vertices, {} faces",
                    path.display(),
                    self.refine,
                    crate::memory::count(vertices),
                    crate::memory::count(faces)
                ),
            )
        } else {
            let key = match (&self.mesh, &self.meshes) {
                (Some(m), _) => format!("mesh = \"{m}\""),
                (_, Some(g)) => format!("meshes = \"{g}\""),
                _ => "[manifest]".to_string(),
            };
            (key, format!("{} ({} vertices{told})", path.display(), crate::memory::count(vertices)))
        };
        SizeRequest { spec: self, scenario: name, key, mesh, vertices, faces }
    }

    /// `input` (read from `path`) repaired when the scenario says `repair = true`
    /// ([`meshes::repair`]); when that changed something, a note of it in `notes` and `member`, and
    /// the [`Repaired`] record.
    fn repaired(
        &self,
        input: TriMesh,
        path: &Path,
        notes: &mut Vec<String>,
        member: &mut Option<Member>,
    ) -> Result<(TriMesh, Option<Repaired>), HarnessError> {
        if !self.repair {
            return Ok((input, None));
        }
        // Results are then written with the repaired faces, in the file's vertex order.
        let (repaired, log) = meshes::repair::repair(&input).map_err(|e| e.in_file(path))?;
        if log.is_empty() {
            return Ok((repaired, None));
        }
        notes.push(format!("{}: repaired: {}", path.display(), log.summary()));
        if let Some(m) = member {
            m.repaired = Some(log.summary());
        }
        Ok((repaired, Some(Repaired { file: path.to_path_buf(), changes: log.summary() })))
    }

    /// The steps on `mesh`, the mesh file `input` without its unreferenced vertices (`map`): the
    /// scenario's regions in its frame, those chosen by file through `map`, files found from
    /// `paths`. `Err`: the message.
    fn file_steps(
        &self,
        mesh: &TriMesh,
        input: &TriMesh,
        map: &meshes::clean::VertexMap,
        paths: &PathContext,
    ) -> Result<Vec<LoadedStep>, String> {
        let mut kept_of_input = vec![None; input.n_vertices()];
        for (i, &v) in map.kept().iter().enumerate() {
            kept_of_input[v as usize] = Some(i as u32);
        }
        let index = InputIndex { kept_of_input };
        let files = InputFiles { n_input: input.n_vertices() };
        self.steps_in_frame(mesh, |m| {
            let initial = self.regions_edit(m, &index, paths, &files)?;
            self.resolve_steps(m, &initial)
        })
    }

    /// `input` (read from `path`) subdivided [`ScenarioSpec::refine`] times, with a note of the
    /// counts. Its vertices keep their indices and the new ones follow, so the refined mesh is the
    /// input from here on (results are written on it).
    fn refined(&self, input: TriMesh, path: &Path, notes: &mut Vec<String>) -> Result<TriMesh, HarnessError> {
        let refined = meshes::subdivision::refine(&input, self.refine, self.refine_scheme.scheme())
            .map_err(|e| e.in_file(path))?;
        notes.push(format!(
            "{}: refined by {} level(s) of {} subdivision: {} -> {} vertices, {} -> {} faces",
            path.display(),
            self.refine,
            match self.refine_scheme {
                RefineScheme::Loop => "Loop",
                RefineScheme::Midpoint => "midpoint",
            },
            input.n_vertices(),
            refined.n_vertices(),
            input.n_faces(),
            refined.n_faces()
        ));
        Ok(refined)
    }

    /// The steps `build` makes from `mesh` posed in the scenario's [`Frame`], their motions taken
    /// back to where `mesh` lies (vertex indices are the same in both).
    fn steps_in_frame(
        &self,
        mesh: &TriMesh,
        build: impl FnOnce(&TriMesh) -> Result<Vec<LoadedStep>, String>,
    ) -> Result<Vec<LoadedStep>, String> {
        match self.frame {
            Frame::Bbox => build(mesh),
            Frame::Principal => {
                let frame = PrincipalFrame::of(mesh);
                let mut steps = build(&frame.pose(mesh))?;
                for step in &mut steps {
                    step.motions = step.motions.iter().map(|m| frame.to_world(m)).collect();
                }
                Ok(steps)
            }
        }
    }

    /// The `[[regions]]` on `mesh`: vertices selected (file-based selections through `input`), free
    /// regions taken out of the others, motions resolved. Errors name the region.
    fn regions_edit(
        &self,
        mesh: &TriMesh,
        input: &InputIndex,
        paths: &PathContext,
        files: &dyn SelectionFiles,
    ) -> Result<InitialEdit, String> {
        let mut selected = Vec::with_capacity(self.regions.len());
        for r in &self.regions {
            let vertices = r
                .select
                .vertices(mesh.positions(), input, paths, files)
                .map_err(|e| format!("region `{}`: {e}", r.name))?;
            selected.push(vertices);
        }
        let mut free = vec![false; mesh.n_vertices()];
        for (r, vertices) in self.regions.iter().zip(&selected) {
            if r.role == Role::Free {
                if !r.transform().is_empty() {
                    return Err(format!("region `{}`: a free region has no transform", r.name));
                }
                vertices.iter().for_each(|&v| free[v as usize] = true);
            }
        }
        let mut edit = InitialEdit { regions: Vec::new(), motions: Vec::new(), roles: Vec::new() };
        for (r, vertices) in self.regions.iter().zip(selected) {
            if r.role == Role::Free {
                continue;
            }
            let vertices: Vec<u32> = vertices.into_iter().filter(|&v| !free[v as usize]).collect();
            if vertices.is_empty() {
                return Err(format!("region `{}`: every vertex it selects is in a free region", r.name));
            }
            let transform = r.transform();
            let motion = match r.role {
                Role::Fixed if !transform.is_empty() => {
                    return Err(format!(
                        "region `{}`: a fixed region is held; give a transform to a handle",
                        r.name
                    ))
                }
                Role::Fixed => Motion::Hold,
                _ => transform
                    .resolve(mesh, &vertices, paths)
                    .map_err(|e| format!("region `{}`: {e}", r.name))?,
            };
            edit.regions.push(HandleRegion { name: r.name.clone(), vertices });
            edit.motions.push(motion);
            edit.roles.push(r.role);
        }
        if edit.regions.is_empty() {
            return Err("[[regions]] has no fixed or handle region".into());
        }
        Ok(edit)
    }

    /// The handle sets of the steps on the rest mesh (default: the initial edit alone).
    fn resolve_steps(&self, mesh: &TriMesh, initial: &InitialEdit) -> Result<Vec<LoadedStep>, String> {
        let first = if self.regions.is_empty() { StepEdit::Survey } else { StepEdit::Regions };
        let default = [StepSpec { edit: first, patches: Vec::new() }];
        let specs = if self.steps.is_empty() { &default[..] } else { &self.steps[..] };
        let diagonal = mesh.bbox_diagonal();
        let (lo, hi) = mesh.bbox();
        let mut steps: Vec<LoadedStep> = Vec::with_capacity(specs.len());
        for (i, spec) in specs.iter().enumerate() {
            let at = |message: String| format!("step {}: {message}", i + 1);
            let (mut regions, mut motions, mut roles) = match spec.edit {
                StepEdit::Survey if !self.regions.is_empty() => {
                    return Err(at("this scenario has [[regions]]: its edit is `edit = \"regions\"`".into()))
                }
                StepEdit::Regions if self.regions.is_empty() => {
                    return Err(at("`edit = \"regions\"` needs [[regions]] in the scenario".into()))
                }
                StepEdit::Survey | StepEdit::Regions => {
                    (initial.regions.clone(), initial.motions.clone(), initial.roles.clone())
                }
                StepEdit::Hold => {
                    let Some(previous) = steps.last() else {
                        return Err(at("`edit = \"hold\"` needs a step before it".into()));
                    };
                    (
                        previous.handles.regions().to_vec(),
                        vec![Motion::Hold; previous.handles.regions().len()],
                        previous.roles.clone(),
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
                roles.push(Role::Handle);
                motions.push(if patch.translate == [0.0; 3] {
                    Motion::Hold
                } else {
                    Motion::Translate(patch.translate.map(|c| c * diagonal))
                });
            }
            let handles = HandleSet::new(regions, mesh.n_vertices()).map_err(|e| at(e.to_string()))?;
            steps.push(LoadedStep { handles, motions, roles });
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
    let roles = regions.iter().map(|r| if r.name == "fixed" { Role::Fixed } else { Role::Handle }).collect();
    let step = LoadedStep { handles: HandleSet::new(regions, mesh.n_vertices())?, motions, roles };
    let targets = step.targets(mesh.positions())?;
    Ok((step.handles, targets))
}

/// `path` made absolute (from the working directory) for a message, as it is if that fails.
fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// The file name of `path` without its extension, for scenario names and `{stem}`.
fn file_stem(path: &Path) -> String {
    path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

/// Every connected component of `mesh` must hold a constrained vertex in every step, or its linear
/// systems are singular (translations of the component are free). `kept` maps mesh vertices to the
/// input file's, for the message.
fn check_components(mesh: &TriMesh, steps: &[LoadedStep], kept: Option<&[u32]>) -> Result<(), String> {
    let (component, count) = meshes::clean::connected_components(mesh.n_vertices(), mesh.triangles());
    if count < 2 {
        return Ok(());
    }
    for (i, step) in steps.iter().enumerate() {
        let mut held = vec![false; count];
        for v in step.handles.constrained() {
            held[component[v as usize] as usize] = true;
        }
        if let Some(c) = held.iter().position(|h| !h) {
            let members: Vec<usize> =
                (0..mesh.n_vertices()).filter(|&v| component[v] as usize == c).collect();
            let first = members[0];
            let name = kept.map_or(first as u32, |k| k[first]);
            return Err(format!(
                "step {}: connected component {c} of {count} ({} vertices, the first is vertex {name}) has no \
                 fixed or handle vertex, so its system is singular; select some of its vertices or remove it",
                i + 1,
                members.len()
            ));
        }
    }
    Ok(())
}
