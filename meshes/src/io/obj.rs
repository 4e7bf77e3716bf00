//! Wavefront OBJ (`.obj`), geometry only.
//!
//! Reads the `v` (position) and `f` (face) statements and ignores everything else (`vt`, `vn`, groups,
//! objects, materials, smoothing groups, lines, points, free-form geometry). Face corners may be written
//! `v`, `v/vt`, `v//vn` or `v/vt/vn`; only the position index is used, so texture and normal seams do
//! not split vertices, nor do `o`/`g` groups. Indices are 1-based; negative indices count back from the
//! last vertex defined so far, as the format specifies. Faces of more than 3 corners are
//! fan-triangulated from their first corner (see [`super::polygon`]: correct for convex polygons and
//! those star-shaped from corner 0).
//!
//! This is a hand-written parser rather than `tobj` because the benchmark needs the file's vertices
//! exactly as written, and per-vertex files (`.sel`, libigl `.dmat` selections) index them in file
//! order. With `LoadOptions { triangulate: true, single_index: false, .. }`, tobj 4 emits one model
//! per `o` object and per `g` group, each with its own positions numbered in order of first use by
//! that model's faces: vertices are reordered, vertices shared across groups are duplicated (the
//! groups come apart) and vertices no face uses are dropped; without its `use_f64` feature it also
//! rounds positions to `f32`. `tests/obj_tobj.rs` shows the reordering on a five-vertex file.

use std::io::Write;
use std::path::Path;

use super::polygon::Polygons;
use super::{atomic_write, data_lines, read_text, syntax, RoundTrip};
use crate::error::{MeshError, Result};
use crate::mesh::TriMesh;

/// Read the OBJ file `path` into a mesh of `#V x 3` positions (every `v`, in file order, including
/// vertices no face uses) and `#T x 3` triangles (every `f` in file order, made 0-based, a face of
/// `k > 3` corners giving `k - 2` consecutive fan triangles).
///
/// Errors (all wrapped in [`MeshError::InFile`]; faces are numbered 0-based in file order, not by
/// triangle): [`MeshError::Syntax`] with the line for a malformed number, too few coordinates, a
/// rational vertex (`w != 1`), an index of 0 or a relative index before the first vertex;
/// [`MeshError::IndexOutOfRange`] naming the face for an index past the last vertex;
/// [`MeshError::Untriangulable`] naming the face for fewer than 3 corners or a repeated corner that
/// puts one vertex twice into a fan triangle; and [`MeshError::NonFiniteCoordinate`] naming the
/// vertex.
pub fn read_obj(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    read_text(path).and_then(|text| parse_obj(&text)).map_err(|e| e.in_file(path))
}

/// Parse OBJ `text` (the content of a file, see [`read_obj`]) into a mesh. Errors are not wrapped with
/// a file name.
pub fn parse_obj(text: &str) -> Result<TriMesh> {
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces = Polygons::new();
    for (line, content) in data_lines(text) {
        let mut tokens = content.split_ascii_whitespace();
        match tokens.next() {
            Some("v") => {
                let v = positions.len();
                let values: Vec<&str> = tokens.collect();
                let mut p = [0.0f64; 3];
                for (axis, slot) in p.iter_mut().enumerate() {
                    let token = values.get(axis).ok_or_else(|| {
                        syntax(line, format!("vertex {v}: expected 3 coordinates, found {}", values.len()))
                    })?;
                    *slot = parse_number(token, v, line)?;
                }
                // Exactly four values is `x y z w`; six or seven are `x y z r g b [a]` (colors, ignored).
                if let [_, _, _, w] = values[..] {
                    let w = parse_number(w, v, line)?;
                    if w != 1.0 {
                        return Err(syntax(
                            line,
                            format!("vertex {v}: rational vertices (w = {w}) are not supported"),
                        ));
                    }
                }
                positions.push(p);
            }
            Some("f") => {
                let f = faces.len();
                let n = positions.len();
                let corners = tokens.map(|t| parse_corner(t, f, n, line)).collect::<Result<Vec<u32>>>()?;
                faces.push(corners);
            }
            _ => {}
        }
    }
    // Range checks wait until every `v` is read: a face may name a vertex defined after it.
    let triangles = faces.triangulate(positions.len())?;
    TriMesh::new(positions, triangles)
}

/// Write `mesh` (`#V x 3` positions, `#F x 3` triangles) to `path` as OBJ `v` and `f` lines (1-based),
/// every coordinate with round-trip precision. Atomic, see [`atomic_write`]; errors name the file.
pub fn write_obj(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    atomic_write(path, |w| write_obj_to(w, mesh))
}

fn write_obj_to(w: &mut dyn Write, mesh: &TriMesh) -> Result<()> {
    writeln!(w, "# {} vertices, {} triangles", mesh.n_vertices(), mesh.n_faces())?;
    for p in mesh.positions() {
        writeln!(w, "v {} {} {}", RoundTrip(p[0]), RoundTrip(p[1]), RoundTrip(p[2]))?;
    }
    for t in mesh.triangles() {
        writeln!(w, "f {} {} {}", u64::from(t[0]) + 1, u64::from(t[1]) + 1, u64::from(t[2]) + 1)?;
    }
    Ok(())
}

fn parse_number(token: &str, vertex: usize, line: usize) -> Result<f64> {
    // Non-finite values ("nan", "inf") parse here and are rejected by TriMesh::new, naming the vertex.
    token.parse().map_err(|_| syntax(line, format!("vertex {vertex}: coordinate '{token}' is not a number")))
}

/// The 0-based position index of a face corner `v[/vt[/vn]]`, resolving negative (relative) indices
/// against the `n_defined` vertices read so far.
fn parse_corner(token: &str, face: usize, n_defined: usize, line: usize) -> Result<u32> {
    let v = token.split('/').next().unwrap_or(token);
    let i: i64 = v
        .parse()
        .map_err(|_| syntax(line, format!("face {face}: vertex index '{token}' is not an integer")))?;
    let zero_based = match i {
        0 => {
            return Err(syntax(
                line,
                format!("face {face}: vertex index 0 is invalid (OBJ indices start at 1)"),
            ))
        }
        i if i > 0 => i - 1,
        i => {
            let resolved = i64::try_from(n_defined).unwrap_or(i64::MAX).saturating_add(i);
            if resolved < 0 {
                return Err(syntax(
                    line,
                    format!("face {face}: relative vertex index {i} points before the first vertex ({n_defined} defined so far)"),
                ));
            }
            resolved
        }
    };
    u32::try_from(zero_based).map_err(|_| MeshError::IndexOutOfRange {
        face,
        index: zero_based as u64,
        n_vertices: n_defined,
    })
}
