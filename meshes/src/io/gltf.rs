//! glTF 2.0 (`.gltf` JSON and `.glb` binary): a reader through the `gltf` crate and a hand-written GLB
//! writer.
//!
//! Reading flattens the default scene (or the first scene when none is marked default) into one mesh:
//! every node that references a mesh contributes each of that mesh's `TRIANGLES` primitives, with its
//! `POSITION`s transformed by the node's world transform (positions are `f32` in glTF and widened to
//! `f64`). Without any scene, every mesh is read untransformed. Primitives do not share vertices with
//! each other (glTF has no such concept), so a mesh split into several primitives (typically one per
//! material) has duplicated vertices along the splits. Point and line primitives carry no surface and
//! are skipped; strips and fans are rejected rather than converted, like polygons in OFF.
//! Sparse accessors are not supported. Textures and images are never loaded.

use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use ::gltf::Semantic;
use serde_json::json;

use super::atomic_write;
use crate::error::{MeshError, Result};
use crate::geometry::vertex_normals;
use crate::mesh::TriMesh;

/// Column-major 4x4 matrix, the layout glTF uses (`m[column][row]`).
type Mat4 = [[f64; 4]; 4];

const IDENTITY: Mat4 =
    [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];

/// Read the glTF (`.gltf`, with embedded `data:` or external buffers resolved next to the file) or GLB
/// file `path` into one mesh of `#V x 3` positions and `#F x 3` triangles (see the module docs for how
/// scenes, nodes and primitives are flattened). A node whose world transform mirrors (negative
/// determinant) has its triangles' corner order reversed, as the glTF specification requires, so
/// faces stay counter-clockwise seen from outside.
///
/// Errors (all wrapped in [`MeshError::InFile`]): [`MeshError::Io`] when the file or an external
/// buffer cannot be read; [`MeshError::Format`] naming the mesh and primitive for invalid glTF, a
/// missing or mistyped `POSITION`, an index count not a multiple of 3, an index beyond its
/// primitive's vertices, a strip or fan primitive, or a node hierarchy that is not a tree; and the
/// validation errors of [`TriMesh::new`] (e.g. [`MeshError::Empty`] when no triangle is found).
pub fn read_gltf(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    read_gltf_inner(path).map_err(|e| e.in_file(path))
}

fn read_gltf_inner(path: &Path) -> Result<TriMesh> {
    let bytes = std::fs::read(path)?;
    let ::gltf::Gltf { document, blob } = ::gltf::Gltf::from_slice(&bytes).map_err(gltf_error)?;
    let base = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // import_buffers, not import: images are irrelevant here and a missing texture must not fail the read.
    let buffers = ::gltf::import_buffers(&document, Some(base), blob).map_err(gltf_error)?;
    let buffer_data = |b: ::gltf::Buffer<'_>| buffers.get(b.index()).map(|d| d.0.as_slice());

    let mut out = Flattened { positions: Vec::new(), triangles: Vec::new() };
    match document.default_scene().or_else(|| document.scenes().next()) {
        Some(scene) => {
            let mut visited = vec![false; document.nodes().count()];
            // Explicit stack: a deep (or malicious) hierarchy must not overflow the call stack. Pushed in
            // reverse so vertices come out in depth-first pre-order, scene roots and children in file order.
            let mut stack: Vec<(::gltf::Node<'_>, Mat4)> = scene.nodes().map(|n| (n, IDENTITY)).collect();
            stack.reverse();
            while let Some((node, parent)) = stack.pop() {
                let seen = visited.get_mut(node.index()).ok_or_else(|| {
                    MeshError::Format(format!("glTF: node {} does not exist", node.index()))
                })?;
                if std::mem::replace(seen, true) {
                    return Err(MeshError::Format(format!(
                        "glTF: node {} is reached twice; the node hierarchy is not a tree",
                        node.index()
                    )));
                }
                let world = mul(&parent, &to_f64(node.transform().matrix()));
                if let Some(mesh) = node.mesh() {
                    for primitive in mesh.primitives() {
                        out.append(&primitive, mesh.index(), &world, &buffer_data)?;
                    }
                }
                let first_child = stack.len();
                stack.extend(node.children().map(|c| (c, world)));
                stack[first_child..].reverse();
            }
        }
        None => {
            for mesh in document.meshes() {
                for primitive in mesh.primitives() {
                    out.append(&primitive, mesh.index(), &IDENTITY, &buffer_data)?;
                }
            }
        }
    }
    TriMesh::new(out.positions, out.triangles)
}

struct Flattened {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
}

impl Flattened {
    fn append<'a, 's, F>(
        &mut self,
        primitive: &'a ::gltf::Primitive<'a>,
        mesh: usize,
        world: &Mat4,
        buffer_data: &F,
    ) -> Result<()>
    where
        F: Clone + Fn(::gltf::Buffer<'a>) -> Option<&'s [u8]>,
    {
        let p = primitive.index();
        let context =
            |message: String| MeshError::Format(format!("glTF mesh {mesh}, primitive {p}: {message}"));
        match primitive.mode() {
            Mode::Triangles => {}
            Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => return Ok(()),
            mode @ (Mode::TriangleStrip | Mode::TriangleFan) => {
                return Err(context(format!("mode {mode:?} is not supported, only TRIANGLES")));
            }
        }
        let position_accessor =
            primitive.get(&Semantic::Positions).ok_or_else(|| context("no POSITION attribute".into()))?;
        if position_accessor.data_type() != DataType::F32
            || position_accessor.dimensions() != Dimensions::Vec3
        {
            return Err(context(format!(
                "POSITION is {:?} {:?}, expected float VEC3",
                position_accessor.data_type(),
                position_accessor.dimensions()
            )));
        }
        check_accessor_bounds(&position_accessor).map_err(|m| context(format!("POSITION: {m}")))?;
        if let Some(indices) = primitive.indices() {
            if indices.dimensions() != Dimensions::Scalar
                || !matches!(indices.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
            {
                return Err(context(format!(
                    "indices are {:?} {:?}, expected unsigned integer SCALAR",
                    indices.data_type(),
                    indices.dimensions()
                )));
            }
            check_accessor_bounds(&indices).map_err(|m| context(format!("indices: {m}")))?;
        }

        let reader = primitive.reader(buffer_data.clone());
        let read_positions =
            reader.read_positions().ok_or_else(|| context("POSITION data lies outside its buffer".into()))?;
        let base = self.positions.len();
        self.positions.extend(read_positions.map(|q| transform_point(world, q.map(f64::from))));
        let n = self.positions.len() - base;
        let indices: Vec<u32> = match primitive.indices() {
            Some(_) => reader
                .read_indices()
                .ok_or_else(|| context("index data lies outside its buffer".into()))?
                .into_u32()
                .collect(),
            None => (0..u32::try_from(n).map_err(|_| context("too many vertices".into()))?).collect(),
        };
        if !indices.chunks_exact(3).remainder().is_empty() {
            return Err(context(format!("{} indices is not a multiple of 3", indices.len())));
        }
        let mirrored = det3(world) < 0.0;
        for (k, corners) in indices.chunks_exact(3).enumerate() {
            let mut t = [0u32; 3];
            for (slot, &i) in t.iter_mut().zip(corners) {
                // Checked per primitive: after offsetting, a bad index would silently reach another primitive.
                if i as usize >= n {
                    return Err(context(format!("triangle {k}: index {i} is out of range ({n} vertices)")));
                }
                *slot = u32::try_from(base + i as usize).map_err(|_| context("too many vertices".into()))?;
            }
            if mirrored {
                t.swap(1, 2);
            }
            self.triangles.push(t);
        }
        Ok(())
    }
}

/// The `gltf` crate's readers assume a non-empty accessor within its buffer view (otherwise they
/// underflow or read garbage); check that here so bad files fail with a message instead.
fn check_accessor_bounds(accessor: &::gltf::Accessor<'_>) -> Result<(), String> {
    if accessor.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    let view = accessor.view().ok_or("the accessor has no buffer view")?;
    if accessor.count() == 0 {
        return Err("the accessor is empty (count 0)".into());
    }
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!("byte stride {stride} is smaller than the element size {size}"));
    }
    let end = (accessor.count() - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(accessor.offset()))
        .and_then(|x| x.checked_add(size));
    match end {
        Some(end) if end <= view.length() => Ok(()),
        _ => Err(format!(
            "{} elements at offset {} do not fit in buffer view {} ({} bytes)",
            accessor.count(),
            accessor.offset(),
            view.index(),
            view.length()
        )),
    }
}

fn gltf_error(e: ::gltf::Error) -> MeshError {
    MeshError::Format(format!("glTF: {e}"))
}

fn to_f64(m: [[f32; 4]; 4]) -> Mat4 {
    m.map(|c| c.map(f64::from))
}

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    std::array::from_fn(|c| std::array::from_fn(|r| (0..4).map(|k| a[k][r] * b[c][k]).sum()))
}

fn transform_point(m: &Mat4, p: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r])
}

/// Determinant of the linear (upper-left 3x3) part.
fn det3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2]) - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

/// Write `mesh` to `path` as a binary glTF 2.0 file, see [`encode_glb`]. Atomic, see
/// [`atomic_write`]; errors name the file.
pub fn write_glb(path: impl AsRef<Path>, mesh: &TriMesh, colors: Option<&[[f32; 3]]>) -> Result<()> {
    let path = path.as_ref();
    let bytes = encode_glb(mesh, colors).map_err(|e| e.in_file(path))?;
    atomic_write(path, |w| Ok(w.write_all(&bytes)?))
}

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A; // "JSON"
const CHUNK_BIN: u32 = 0x004E_4942; // "BIN\0"
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Encode `mesh` as a binary glTF 2.0 (GLB) file: one scene, one node, one mesh, one `TRIANGLES`
/// primitive with
/// - `POSITION`: `#V` float32 VEC3, with the `min`/`max` the specification requires;
/// - `NORMAL`: `#V` float32 VEC3, unit area-weighted vertex normals
///   ([`crate::geometry::vertex_normals`]); a vertex without one (isolated, or only on zero-area faces)
///   gets `+z`, since glTF requires unit normals;
/// - `COLOR_0`: `#V` float32 VEC3 linear RGB in `[0, 1]`, when `colors` is given;
/// - indices: `#F x 3` SCALAR, uint16 when every index fits (at most 65,535 vertices: half the
///   bytes, for the survey-sized meshes a report writes by the dozen), else uint32.
///
/// Errors: [`MeshError::LengthMismatch`] when `colors` does not have `#V` entries;
/// [`MeshError::Invalid`] for a color outside `[0, 1]` (or NaN), a coordinate beyond the `f32` range,
/// or a file beyond the 4 GiB GLB limit.
pub fn encode_glb(mesh: &TriMesh, colors: Option<&[[f32; 3]]>) -> Result<Vec<u8>> {
    let nv = mesh.n_vertices();
    let nf = mesh.n_faces();
    if let Some(c) = colors {
        if c.len() != nv {
            return Err(MeshError::LengthMismatch { what: "color array", got: c.len(), expected: nv });
        }
        if let Some((v, rgb)) =
            c.iter().enumerate().find(|(_, rgb)| !rgb.iter().all(|x| (0.0..=1.0).contains(x)))
        {
            return Err(MeshError::Invalid(format!("vertex {v}: color {rgb:?} is outside [0, 1]")));
        }
    }

    let mut bin: Vec<u8> = Vec::with_capacity(12 * nv * if colors.is_some() { 3 } else { 2 } + 12 * nf);
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for (v, p) in mesh.positions().iter().enumerate() {
        for (k, &x) in p.iter().enumerate() {
            let x = x as f32;
            if !x.is_finite() {
                return Err(MeshError::Invalid(format!(
                    "vertex {v}: coordinate {k} ({}) does not fit in a 32-bit float",
                    p[k]
                )));
            }
            // min/max from the stored f32 values, or they could disagree with the data by one ulp.
            lo[k] = lo[k].min(x);
            hi[k] = hi[k].max(x);
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    let normals_offset = bin.len();
    for n in vertex_normals(mesh.positions(), mesh.triangles()) {
        let n = if n == [0.0; 3] { [0.0, 0.0, 1.0] } else { n };
        for x in n {
            bin.extend_from_slice(&(x as f32).to_le_bytes());
        }
    }
    let colors_offset = bin.len();
    for rgb in colors.unwrap_or(&[]) {
        for x in rgb {
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    let indices_offset = bin.len();
    let short = nv <= u16::MAX as usize;
    for t in mesh.triangles() {
        for &i in t {
            if short {
                bin.extend_from_slice(&(i as u16).to_le_bytes());
            } else {
                bin.extend_from_slice(&i.to_le_bytes());
            }
        }
    }
    let (index_type, index_bytes) = if short { (UNSIGNED_SHORT, 6 * nf) } else { (UNSIGNED_INT, 12 * nf) };
    let vec3_bytes = 12 * nv;

    let mut attributes = json!({ "POSITION": 0, "NORMAL": 1 });
    let mut views = vec![
        json!({ "buffer": 0, "byteOffset": 0, "byteLength": vec3_bytes, "target": ARRAY_BUFFER }),
        json!({ "buffer": 0, "byteOffset": normals_offset, "byteLength": vec3_bytes, "target": ARRAY_BUFFER }),
        json!({ "buffer": 0, "byteOffset": indices_offset, "byteLength": index_bytes, "target": ELEMENT_ARRAY_BUFFER }),
    ];
    let mut accessors = vec![
        json!({ "bufferView": 0, "componentType": FLOAT, "count": nv, "type": "VEC3", "min": lo, "max": hi }),
        json!({ "bufferView": 1, "componentType": FLOAT, "count": nv, "type": "VEC3" }),
        json!({ "bufferView": 2, "componentType": index_type, "count": 3 * nf, "type": "SCALAR" }),
    ];
    if colors.is_some() {
        attributes["COLOR_0"] = json!(3);
        views.push(json!({ "buffer": 0, "byteOffset": colors_offset, "byteLength": vec3_bytes, "target": ARRAY_BUFFER }));
        accessors.push(json!({ "bufferView": 3, "componentType": FLOAT, "count": nv, "type": "VEC3" }));
    }
    let root = json!({
        "asset": { "version": "2.0", "generator": "deformbench meshes" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{ "attributes": attributes, "indices": 2, "mode": 4 }] }],
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": views,
        "accessors": accessors,
    });
    let mut json_chunk =
        serde_json::to_vec(&root).map_err(|e| MeshError::Format(format!("glTF JSON: {e}")))?;
    // Chunks must be 4-byte aligned: JSON pads with spaces, BIN with zeros.
    json_chunk.resize(json_chunk.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json_chunk.len() + 8 + bin.len();
    let too_large =
        || MeshError::Invalid(format!("the mesh needs {total} bytes, beyond the 4 GiB GLB limit"));
    let total32 = u32::try_from(total).map_err(|_| too_large())?;
    let json_len = u32::try_from(json_chunk.len()).map_err(|_| too_large())?;
    let bin_len = u32::try_from(bin.len()).map_err(|_| too_large())?;

    let mut out = Vec::with_capacity(total);
    for word in [GLB_MAGIC, 2, total32, json_len, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json_chunk);
    for word in [bin_len, CHUNK_BIN] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&bin);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrix_product_is_column_major() {
        let t = {
            let mut m = IDENTITY;
            m[3] = [1.0, 2.0, 3.0, 1.0];
            m
        };
        let s = {
            let mut m = IDENTITY;
            m[0][0] = 2.0;
            m
        };
        // translate after scaling: x -> 2x + 1
        assert_eq!(transform_point(&mul(&t, &s), [1.0, 1.0, 1.0]), [3.0, 3.0, 4.0]);
        assert_eq!(transform_point(&mul(&s, &t), [1.0, 1.0, 1.0]), [4.0, 3.0, 4.0]);
        assert_eq!(det3(&s), 2.0);
    }
}
