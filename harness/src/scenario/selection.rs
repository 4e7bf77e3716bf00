//! Regions of a scenario as data: which vertices a region holds, chosen from a file (a survey `.sel`,
//! a libigl `.dmat` of region ids, a list of vertex ids) or by a shape in the rest mesh's bounding-box
//! coordinates (box, sphere, slab), so one rule applies to every mesh of a collection.
//!
//! ```toml
//! [[regions]]
//! name = "feet"
//! role = "fixed"                                   # fixed | handle | free
//! select = { slab = { axis = "z", from = 0.0, to = 0.05 } }   # the lowest 5% along z
//!
//! [[regions]]
//! name = "hand"
//! role = "handle"
//! select = { dmat = { file = "{stem}-selection.dmat", id = 1 } }
//! rotate = { axis = [0, 0, 1], degrees = 30 }       # about the region's centroid
//! translate = [0.0, 0.0, 0.1]                        # x rest bbox diagonal
//! ```
//!
//! File paths are relative to the scenario file, absolute, or start with `${VARIABLE}` (expanded from
//! the environment); `{stem}` stands for the mesh file's stem (for collections).

use std::path::{Path, PathBuf};

use meshes::vector::{norm, sub};
use meshes::TriMesh;
use serde::Deserialize;

/// What a region does in the edit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// Held at its rest position.
    Fixed,
    /// Moved by the region's transform.
    Handle,
    /// Explicitly free: its vertices are taken out of every fixed or handle region.
    Free,
}

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        self as usize
    }
}

/// How a region's vertices are chosen. Shapes are in the rest mesh's bounding-box coordinates
/// (`[0, 1]^3` spans the box), lengths in rest bbox diagonals.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Selection {
    /// The vertices with `status` (0 fixed, 1 free, 2 handle) in a survey `.sel` file.
    Sel { file: String, status: u8 },
    /// A libigl `.dmat` of one integer column, read as its `form` says: `region_ids` (the default)
    /// holds one region id per vertex of the mesh file (-1 free) and the region is the vertices of
    /// id `id`; `indices` lists the region's vertex indices (as libigl writes an index vector such
    /// as `b`) and takes no `id`.
    Dmat {
        file: String,
        #[serde(default)]
        id: Option<i64>,
        #[serde(default)]
        form: DmatForm,
    },
    /// These vertex ids (of the input file's vertex order).
    Vertices(Vec<u32>),
    /// The vertex ids listed in a text file (whitespace separated, `#` comments).
    VertexFile(String),
    /// The vertices inside the box `min..max` (bbox coordinates, inclusive).
    Box { min: [f64; 3], max: [f64; 3] },
    /// The vertices within `radius` (x diagonal) of `center` (bbox coordinates).
    Sphere { center: [f64; 3], radius: f64 },
    /// The vertices whose `axis` bbox coordinate lies in `from..=to` (`from = 0, to = 0.05`: the lowest
    /// 5% of the box along the axis).
    Slab { axis: Axis, from: f64, to: f64 },
}

/// What the integers of a `.dmat` selection are.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DmatForm {
    /// One region id per vertex of the mesh file, `-1` for none (libigl's ARAP tutorial selections).
    #[default]
    RegionIds,
    /// Vertex indices (libigl's index vectors).
    Indices,
}

/// Where the files a scenario names are looked up.
#[derive(Clone, Debug)]
pub struct PathContext {
    /// The scenario file's directory.
    pub base: PathBuf,
    /// The mesh file's stem, for `{stem}` (collections).
    pub stem: Option<String>,
    /// Every path resolved, for the run's record of its inputs.
    pub read: FilesRead,
}

/// The files a scenario named, shared by its clones (the run provenance hashes them).
#[derive(Clone, Debug, Default)]
pub struct FilesRead(std::sync::Arc<std::sync::Mutex<Vec<PathBuf>>>);

impl FilesRead {
    pub fn push(&self, path: PathBuf) {
        if let Ok(mut paths) = self.0.lock() {
            if !paths.contains(&path) {
                paths.push(path);
            }
        }
    }

    /// The paths so far, in the order they were first named.
    pub fn paths(&self) -> Vec<PathBuf> {
        self.0.lock().map(|p| p.clone()).unwrap_or_default()
    }
}

impl PathContext {
    /// `path` as written in the scenario, resolved: `${VAR}` expanded from the environment, `{stem}`
    /// substituted, relative paths taken from the scenario file's directory.
    pub fn resolve(&self, path: &str) -> Result<PathBuf, String> {
        let mut text = path.to_string();
        if let Some(stem) = &self.stem {
            text = text.replace("{stem}", stem);
        } else if text.contains("{stem}") {
            return Err(format!("`{path}`: {{stem}} needs a mesh file (`mesh` or `meshes`)"));
        }
        let text = crate::variables::expand(&text, "the directory it names")?;
        let p = PathBuf::from(text);
        let resolved = if p.is_absolute() { p } else { self.base.join(p) };
        self.read.push(resolved.clone());
        Ok(resolved)
    }

    /// `written`, the value of the scenario's key `key`, resolved as [`PathContext::resolve`] does,
    /// when something is there. Otherwise the error names the key, the value as written and the
    /// absolute path it resolved to (and, for a relative value, the directory it was taken from).
    pub fn resolve_existing(&self, key: &str, written: &str) -> Result<PathBuf, String> {
        let path = self.resolve(written).map_err(|e| format!("{key} = \"{written}\": {e}"))?;
        if path.exists() {
            return Ok(path);
        }
        let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let relative = !Path::new(written).is_absolute() && !written.starts_with("${");
        let from = if relative {
            format!(
                " (a relative path is taken from the scenario file's directory, {})",
                absolute(&self.base).display()
            )
        } else {
            String::new()
        };
        Err(format!("{key} = \"{written}\": {} does not exist{from}", absolute(&path).display()))
    }
}

/// The per-vertex files a region may read, one entry per vertex of the input file.
pub trait SelectionFiles {
    /// Survey status codes of `file`.
    fn sel(&self, file: &Path) -> Result<Vec<u8>, String>;
    /// The integers of the one-column `.dmat` `file`, as many as it holds (the caller checks them
    /// against the mesh).
    fn dmat(&self, file: &Path) -> Result<Vec<i64>, String>;
    /// Vertex ids listed in `file`.
    fn index_list(&self, file: &Path) -> Result<Vec<u32>, String>;
}

/// How the vertices of the input file map to the mesh the methods run on (unreferenced input
/// vertices are dropped on load).
#[derive(Clone, Debug, PartialEq)]
pub struct InputIndex {
    /// Per input vertex, its index in the mesh, `None` if it was dropped.
    pub kept_of_input: Vec<Option<u32>>,
}

impl InputIndex {
    /// Every input vertex kept, in order.
    pub fn identity(n: usize) -> Self {
        Self { kept_of_input: (0..n as u32).map(Some).collect() }
    }

    pub fn n_input(&self) -> usize {
        self.kept_of_input.len()
    }
}

impl Selection {
    /// The mesh vertices (ascending, no repeats) this selection picks on the mesh with `#V x 3`
    /// `positions`; file-based selections index the input file's vertices and are mapped by `input`
    /// (a dropped vertex is left out). Errors name the file or say why the selection is empty.
    pub fn vertices(
        &self,
        positions: &[[f64; 3]],
        input: &InputIndex,
        paths: &PathContext,
        files: &dyn SelectionFiles,
    ) -> Result<Vec<u32>, String> {
        let picked = self.pick(positions, input, paths, files)?;
        if matches!(self, Selection::Box { .. } | Selection::Sphere { .. } | Selection::Slab { .. }) {
            return Ok(picked);
        }
        let mut kept: Vec<u32> = picked.iter().filter_map(|&v| input.kept_of_input[v as usize]).collect();
        kept.sort_unstable();
        if kept.is_empty() {
            return Err(format!("selects only vertices that no face uses ({} of them)", picked.len()));
        }
        Ok(kept)
    }

    /// Shapes: mesh vertex ids (of the `#V x 3` mesh `positions`); files and lists: input vertex ids.
    fn pick(
        &self,
        positions: &[[f64; 3]],
        input: &InputIndex,
        paths: &PathContext,
        files: &dyn SelectionFiles,
    ) -> Result<Vec<u32>, String> {
        let source = FileSource { paths, files, n_input: input.n_input() };
        match self {
            Selection::Sel { file, status } => source.sel(file, *status),
            Selection::Dmat { file, id, form } => source.dmat(file, *id, *form),
            Selection::Vertices(list) => checked_ids(list.clone(), source.n_input, "select.vertices"),
            Selection::VertexFile(file) => source.vertex_file(file),
            Selection::Box { min, max } => BoxCoordinates::of(positions).inside_box(min, max),
            Selection::Sphere { center, radius } => {
                BoxCoordinates::of(positions).inside_sphere(center, *radius)
            }
            Selection::Slab { axis, from, to } => {
                BoxCoordinates::of(positions).inside_slab(*axis, *from, *to)
            }
        }
    }
}

/// Where a selection by file reads: the scenario's paths, the per-vertex files, and the number of
/// vertices of the mesh file (the input vertex ids the files give are below it).
struct FileSource<'a> {
    paths: &'a PathContext,
    files: &'a dyn SelectionFiles,
    n_input: usize,
}

impl FileSource<'_> {
    /// The input vertices of survey status `status` in the `.sel` file `file` (as written). `Err`:
    /// the file is missing or unreadable, or no vertex has that status.
    fn sel(&self, file: &str, status: u8) -> Result<Vec<u32>, String> {
        let path = self.paths.resolve_existing("select.sel.file", file)?;
        let codes = self.files.sel(&path)?;
        let picked = (0..self.n_input as u32).filter(|&v| codes[v as usize] == status).collect::<Vec<_>>();
        if picked.is_empty() {
            return Err(format!("{}: no vertex has status {status}", path.display()));
        }
        Ok(picked)
    }

    /// The input vertices the `.dmat` file `file` (as written) selects, read as `form` says: of
    /// region id `id`, or the indices it lists. `Err`: an `id` the form does not take or lacks, or
    /// what is wrong with the file.
    fn dmat(&self, file: &str, id: Option<i64>, form: DmatForm) -> Result<Vec<u32>, String> {
        let id = match (form, id) {
            (DmatForm::RegionIds, Some(id)) => id,
            (DmatForm::RegionIds, None) => {
                return Err(format!(
                    "select.dmat = {{ file = \"{file}\" }}: give `id = N` (the vertices whose region id is N in a \
                     per-vertex .dmat) or `form = \"indices\"` (the file lists vertex indices)"
                ))
            }
            (DmatForm::Indices, Some(_)) => {
                return Err(format!(
                    "select.dmat = {{ file = \"{file}\", form = \"indices\" }}: an index list takes no `id` \
                     (`id` picks a region of a per-vertex .dmat of region ids)"
                ))
            }
            (DmatForm::Indices, None) => {
                let path = self.paths.resolve_existing("select.dmat.file", file)?;
                return dmat_indices(&self.files.dmat(&path)?, self.n_input, &path);
            }
        };
        self.dmat_region(file, id)
    }

    /// The input vertices of region id `id` in the per-vertex `.dmat` file `file` (as written).
    /// `Err`: the file is missing or unreadable, does not hold one id per vertex, or no vertex has
    /// that id.
    fn dmat_region(&self, file: &str, id: i64) -> Result<Vec<u32>, String> {
        let path = self.paths.resolve_existing("select.dmat.file", file)?;
        let ids = self.files.dmat(&path)?;
        if ids.len() != self.n_input {
            return Err(wrong_length(&ids, self.n_input, &path, file));
        }
        let picked = (0..self.n_input as u32).filter(|&v| ids[v as usize] == id).collect::<Vec<_>>();
        if picked.is_empty() {
            let mut present: Vec<i64> = ids.clone();
            present.sort();
            present.dedup();
            return Err(format!(
                "{}: no vertex has region id {id} (ids present: {present:?})",
                path.display()
            ));
        }
        Ok(picked)
    }

    /// The input vertices listed in the text file `file` (as written), sorted and deduplicated.
    fn vertex_file(&self, file: &str) -> Result<Vec<u32>, String> {
        let path = self.paths.resolve_existing("select.vertex_file", file)?;
        checked_ids(self.files.index_list(&path)?, self.n_input, &path.display().to_string())
    }
}

/// A mesh's vertices and its bounding box, for the selections by shape: in box coordinates
/// `[0, 1]^3` spans the box, lengths are in diagonals.
struct BoxCoordinates<'a> {
    positions: &'a [[f64; 3]],
    lo: [f64; 3],
    hi: [f64; 3],
    diagonal: f64,
}

impl<'a> BoxCoordinates<'a> {
    /// The box coordinates of the `#V x 3` mesh `positions`.
    fn of(positions: &'a [[f64; 3]]) -> Self {
        let (lo, hi) = meshes::geometry::bbox(positions);
        Self { positions, lo, hi, diagonal: norm(sub(hi, lo)) }
    }

    /// The point `p` in box coordinates (0.5 along an axis the box is flat in).
    fn to_box(&self, p: [f64; 3]) -> [f64; 3] {
        let (lo, hi) = (self.lo, self.hi);
        std::array::from_fn(|k| if hi[k] > lo[k] { (p[k] - lo[k]) / (hi[k] - lo[k]) } else { 0.5 })
    }

    /// The point at box coordinates `c`.
    fn from_box(&self, c: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| self.lo[k] + c[k] * (self.hi[k] - self.lo[k]))
    }

    /// The mesh vertices at which `inside` holds, or the error `empty` says.
    fn within(
        &self,
        inside: impl Fn([f64; 3]) -> bool,
        empty: impl FnOnce() -> String,
    ) -> Result<Vec<u32>, String> {
        let picked: Vec<u32> =
            (0..self.positions.len() as u32).filter(|&v| inside(self.positions[v as usize])).collect();
        if picked.is_empty() {
            Err(empty())
        } else {
            Ok(picked)
        }
    }

    /// The mesh vertices in the box `min..max` (box coordinates, inclusive). `Err`: a bad box, or
    /// one that holds no vertex.
    fn inside_box(&self, min: &[f64; 3], max: &[f64; 3]) -> Result<Vec<u32>, String> {
        if !(finite(min) && finite(max)) || (0..3).any(|k| min[k] > max[k]) {
            return Err(format!("box: min {min:?} must be finite and <= max {max:?}"));
        }
        self.within(
            |p| (0..3).all(|k| (min[k]..=max[k]).contains(&self.to_box(p)[k])),
            || format!("box {min:?}..{max:?} (bbox coordinates, [0, 1] spans the mesh) holds no vertex"),
        )
    }

    /// The mesh vertices within `radius` diagonals of `center` (box coordinates). `Err`: a bad
    /// sphere, or one that holds no vertex.
    fn inside_sphere(&self, center: &[f64; 3], radius: f64) -> Result<Vec<u32>, String> {
        if !(finite(center) && radius.is_finite() && radius > 0.0) {
            return Err(format!("sphere: center {center:?} finite and radius {radius} > 0 needed"));
        }
        let c = self.from_box(*center);
        self.within(
            |p| norm(sub(p, c)) <= radius * self.diagonal,
            || {
                format!(
                    "sphere at {center:?} (bbox coordinates) with radius {radius} x diagonal holds no vertex"
                )
            },
        )
    }

    /// The mesh vertices whose `axis` box coordinate is in `from..=to`. `Err`: a bad slab, or one
    /// that holds no vertex.
    fn inside_slab(&self, axis: Axis, from: f64, to: f64) -> Result<Vec<u32>, String> {
        if !(from.is_finite() && to.is_finite() && from <= to) {
            return Err(format!("slab: from {from} must be finite and <= to {to}"));
        }
        self.within(
            |p| (from..=to).contains(&self.to_box(p)[axis.index()]),
            || {
                format!(
                    "slab {axis:?} {from}..{to} (bbox coordinates, [0, 1] spans the mesh) holds no vertex"
                )
            },
        )
    }
}

/// Whether every value of `v` is finite.
fn finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The vertices of the index-list `.dmat` `path` (`values`, of a mesh file of `n` vertices), sorted
/// and deduplicated. A negative value is an error that says the file looks like a per-vertex one.
fn dmat_indices(values: &[i64], n: usize, path: &Path) -> Result<Vec<u32>, String> {
    if let Some(k) = values.iter().position(|&v| v < 0) {
        let per_vertex = if values.len() == n {
            format!(
                "; it has one value per vertex ({n}): a per-vertex .dmat of region ids, selected with \
                 `id = N` instead of `form = \"indices\"`"
            )
        } else {
            String::new()
        };
        return Err(format!(
            "{} (select.dmat, form = \"indices\"): entry {k} is {}, not a vertex index{per_vertex}",
            path.display(),
            values[k]
        ));
    }
    let ids = values.iter().map(|&v| u32::try_from(v).unwrap_or(u32::MAX)).collect();
    checked_ids(ids, n, &format!("{} (select.dmat, form = \"indices\")", path.display()))
}

/// The error of a per-vertex `.dmat` (`file` as written, at `path`) whose `values` are not one per
/// vertex of the mesh file's `n`: when they could be vertex indices of that mesh, it says the file
/// looks like an index list and names the key that reads it as one.
fn wrong_length(values: &[i64], n: usize, path: &Path, file: &str) -> String {
    let head = format!(
        "{} (select.dmat with `id`): {} values, but a per-vertex .dmat holds one region id for each of the \
         mesh file's {n} vertices",
        path.display(),
        values.len()
    );
    let indices = values.len() < n && values.iter().all(|&v| (0..n as i64).contains(&v));
    if indices {
        format!(
            "{head}. Its values are all vertex indices of the mesh, so it looks like an index list (libigl's \
             other common .dmat): select its vertices with `select = {{ dmat = {{ file = \"{file}\", form = \"indices\" }} }}`"
        )
    } else {
        format!("{head} (nor are its values all vertex indices of the mesh, as an index list's, `form = \"indices\"`, would be)")
    }
}

/// `ids` sorted and deduplicated, each below `n`; `what` names the source in errors.
fn checked_ids(mut ids: Vec<u32>, n: usize, what: &str) -> Result<Vec<u32>, String> {
    if let Some(bad) = ids.iter().find(|&&v| v as usize >= n) {
        return Err(format!("{what}: vertex {bad} is out of range (the mesh has {n} vertices)"));
    }
    if ids.is_empty() {
        return Err(format!("{what}: lists no vertex"));
    }
    ids.sort_unstable();
    ids.dedup();
    Ok(ids)
}

/// The centroid of the vertices `ids` of `mesh`.
pub fn centroid(mesh: &TriMesh, ids: &[u32]) -> [f64; 3] {
    let p = mesh.positions();
    let n = ids.len().max(1) as f64;
    std::array::from_fn(|k| ids.iter().map(|&v| p[v as usize][k]).sum::<f64>() / n)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct NoFiles;
    impl SelectionFiles for NoFiles {
        fn sel(&self, _: &Path) -> Result<Vec<u8>, String> {
            Ok(vec![0, 2, 1, 2])
        }
        fn dmat(&self, file: &Path) -> Result<Vec<i64>, String> {
            Ok(if file.ends_with("x.dmat") { vec![-1, 0, 0, 1] } else { vec![3, 1, 3] })
        }
        fn index_list(&self, _: &Path) -> Result<Vec<u32>, String> {
            Ok(vec![3, 1, 3])
        }
    }

    /// Four vertices on the x axis at 0, 1, 2, 3 (bbox x coordinates 0, 1/3, 2/3, 1).
    fn line() -> Vec<[f64; 3]> {
        (0..4).map(|i| [i as f64, 0.0, 0.0]).collect()
    }

    /// `s` on [`line`], its files (read by [`NoFiles`]) present, empty, in a fresh directory.
    fn pick(s: &Selection, input: &InputIndex) -> Result<Vec<u32>, String> {
        let dir = tempfile::tempdir().unwrap();
        for file in ["x.sel", "x.dmat", "ids.txt", "b.dmat"] {
            std::fs::write(dir.path().join(file), "").unwrap();
        }
        let base = dir.path().to_path_buf();
        s.vertices(
            &line(),
            input,
            &PathContext { base, stem: Some("knight".into()), read: FilesRead::default() },
            &NoFiles,
        )
    }

    #[test]
    fn shapes_pick_by_bounding_box_coordinates() {
        let all = InputIndex::identity(4);
        let slab = Selection::Slab { axis: Axis::X, from: 0.0, to: 0.4 };
        assert_eq!(pick(&slab, &all).unwrap(), vec![0, 1]);
        let boxed = Selection::Box { min: [0.5, 0.0, 0.0], max: [1.0, 1.0, 1.0] };
        assert_eq!(pick(&boxed, &all).unwrap(), vec![2, 3]);
        // Radius 0.34 of the diagonal (3) around x = 3: vertices 2 and 3.
        let sphere = Selection::Sphere { center: [1.0, 0.5, 0.5], radius: 0.34 };
        assert_eq!(pick(&sphere, &all).unwrap(), vec![2, 3]);
        let outside = Selection::Box { min: [2.0, 0.0, 0.0], max: [3.0, 1.0, 1.0] };
        assert!(pick(&outside, &all).unwrap_err().contains("holds no vertex"));
        let inverted = Selection::Slab { axis: Axis::X, from: 0.5, to: 0.1 };
        assert!(pick(&inverted, &all).unwrap_err().contains("<= to"));
    }

    #[test]
    fn file_selections_index_the_input_and_map_through_dropped_vertices() {
        // Input vertex 1 was dropped; input 2 and 3 are mesh vertices 1 and 2 (mesh vertex 3 unused here).
        let input = InputIndex { kept_of_input: vec![Some(0), None, Some(1), Some(2)] };
        let handle = Selection::Sel { file: "x.sel".into(), status: 2 };
        assert_eq!(pick(&handle, &input).unwrap(), vec![2], "input 1 dropped, input 3 is mesh 2");
        let dmat =
            |file: &str, id: Option<i64>, form: DmatForm| Selection::Dmat { file: file.into(), id, form };
        let region = dmat("x.dmat", Some(0), DmatForm::RegionIds);
        assert_eq!(pick(&region, &input).unwrap(), vec![1]);
        let missing = dmat("x.dmat", Some(7), DmatForm::RegionIds);
        assert!(pick(&missing, &input).unwrap_err().contains("ids present: [-1, 0, 1]"));
        // An index list (3, 1, 3): input 1 was dropped, input 3 is mesh vertex 2.
        assert_eq!(pick(&dmat("b.dmat", None, DmatForm::Indices), &input).unwrap(), vec![2]);
        assert_eq!(pick(&Selection::VertexFile("ids.txt".into()), &input).unwrap(), vec![2]);
        let only_dropped = Selection::Vertices(vec![1]);
        assert!(pick(&only_dropped, &input).unwrap_err().contains("no face uses"));
    }

    #[test]
    fn a_dmat_read_the_wrong_way_says_which_form_it_looks_like() {
        let all = InputIndex::identity(4);
        let dmat =
            |file: &str, id: Option<i64>, form: DmatForm| Selection::Dmat { file: file.into(), id, form };
        // Three values on a four-vertex mesh, each a vertex index: an index list read as region ids.
        let e = pick(&dmat("b.dmat", Some(1), DmatForm::RegionIds), &all).unwrap_err();
        assert!(e.contains("b.dmat") && e.contains("3 values") && e.contains("4 vertices"), "{e}");
        assert!(e.contains("looks like an index list"), "{e}");
        assert!(e.contains("select = { dmat = { file = \"b.dmat\", form = \"indices\" } }"), "{e}");
        // One value per vertex with a -1: region ids read as an index list.
        let e = pick(&dmat("x.dmat", None, DmatForm::Indices), &all).unwrap_err();
        assert!(e.contains("entry 0 is -1") && e.contains("`id = N`"), "{e}");
        let e = pick(&dmat("x.dmat", None, DmatForm::RegionIds), &all).unwrap_err();
        assert!(e.contains("give `id = N`") && e.contains("form = \"indices\""), "{e}");
        let e = pick(&dmat("b.dmat", Some(1), DmatForm::Indices), &all).unwrap_err();
        assert!(e.contains("takes no `id`"), "{e}");
    }

    #[test]
    fn paths_resolve_against_the_scenario_with_variables_and_stems() {
        let ctx = PathContext {
            base: "/configs/real".into(),
            stem: Some("knight".into()),
            read: FilesRead::default(),
        };
        assert_eq!(
            ctx.resolve("{stem}-selection.dmat").unwrap(),
            PathBuf::from("/configs/real/knight-selection.dmat")
        );
        assert_eq!(ctx.resolve("/abs/x.off").unwrap(), PathBuf::from("/abs/x.off"));
        std::env::set_var("DEFORMBENCH_TEST_SELECTION_DIR", "/somewhere");
        assert_eq!(
            ctx.resolve("${DEFORMBENCH_TEST_SELECTION_DIR}/a.off").unwrap(),
            PathBuf::from("/somewhere/a.off")
        );
        let e = ctx.resolve("${DEFORMBENCH_TEST_UNSET_VARIABLE}/a.off").unwrap_err();
        assert!(e.contains("DEFORMBENCH_TEST_UNSET_VARIABLE"), "{e}");
        let no_stem = PathContext { base: ".".into(), stem: None, read: FilesRead::default() };
        assert!(no_stem.resolve("{stem}.sel").unwrap_err().contains("needs a mesh file"));
        let e = ctx.resolve_existing("select.dmat.file", "sel/{stem}.dmat").unwrap_err();
        assert_eq!(
            e,
            "select.dmat.file = \"sel/{stem}.dmat\": /configs/real/sel/knight.dmat does not exist \
             (a relative path is taken from the scenario file's directory, /configs/real)"
        );
    }
}
