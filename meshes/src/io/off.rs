//! Object File Format (`.off`), the format of the Botsch–Sorkine survey meshes.
//!
//! Accepted (Geomview OFF, triangles only):
//! ```text
//! OFF                 # header; the counts may follow on the same line: `OFF 4 2 0`
//! # comments, full-line or trailing, and blank lines anywhere
//! 4 2 0               # #vertices #faces [#edges]; #edges is ignored
//! 0 0 0               # one vertex per line: x y z, extra columns (colors, normals) ignored
//! 1 0 0
//! 0 1 0
//! 1 1 0
//! 3 0 1 2             # one face per line: corner count (must be 3), 0-based indices, extra columns ignored
//! 3 2 1 3
//! ```
//! The header keyword may carry the `ST`, `C`, `N` prefixes (`COFF`, `NOFF`, ...) since they only add
//! vertex columns, which are ignored. Faces with other than 3 corners are rejected, not triangulated:
//! a benchmark must run on exactly the triangles it was given.

use std::io::Write;
use std::path::Path;

use super::{atomic_write, data_lines, read_text, syntax, RoundTrip};
use crate::error::{MeshError, Result};
use crate::mesh::TriMesh;

/// Read the OFF file `path` into a mesh of `#V x 3` positions and `#F x 3` triangles, in file order.
///
/// Errors (all wrapped in [`MeshError::InFile`]): [`MeshError::Syntax`] with the line for a bad
/// header, a malformed number, too few fields, a negative index or content after the last face;
/// [`MeshError::Truncated`] when the file has fewer vertices or faces than its header announces;
/// [`MeshError::NotATriangle`] for a face with other than 3 corners; and the validation errors of
/// [`TriMesh::new`] (non-finite coordinate naming the vertex, out-of-range index naming the face).
pub fn read_off(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    read_text(path).and_then(|text| parse_off(&text)).map_err(|e| e.in_file(path))
}

/// Parse OFF `text` (the content of a file, see [`read_off`]) into a mesh. Errors are not wrapped
/// with a file name.
pub fn parse_off(text: &str) -> Result<TriMesh> {
    let mut lines = data_lines(text);
    let (header_line, header) =
        lines.next().ok_or_else(|| MeshError::Truncated { expected: "an OFF header".into() })?;
    let mut header_tokens = header.split_ascii_whitespace();
    let keyword = header_tokens.next().unwrap_or("");
    if !is_off_keyword(keyword) {
        return Err(syntax(header_line, format!("expected the header 'OFF', found '{keyword}'")));
    }
    let mut counts: Vec<&str> = header_tokens.collect();
    let mut counts_line = header_line;
    if counts.is_empty() {
        let (line, content) = lines.next().ok_or_else(|| MeshError::Truncated {
            expected: "the counts line '#vertices #faces #edges'".into(),
        })?;
        counts_line = line;
        counts = content.split_ascii_whitespace().collect();
    }
    let (n_vertices, n_faces) = match counts[..] {
        [v, f] | [v, f, _] => (parse_count(v, "vertex", counts_line)?, parse_count(f, "face", counts_line)?),
        _ => {
            return Err(syntax(
                counts_line,
                format!("expected the counts '#vertices #faces #edges', found {} numbers", counts.len()),
            ))
        }
    };
    // Cap the reservation by what the file can hold: a lying header must not trigger a huge allocation.
    let max_records = text.len() / 6 + 1;

    let mut positions = Vec::with_capacity(n_vertices.min(max_records));
    for v in 0..n_vertices {
        let (line, content) = lines.next().ok_or_else(|| MeshError::Truncated {
            expected: format!("{n_vertices} vertices announced in the header, found {v}"),
        })?;
        let mut tokens = content.split_ascii_whitespace();
        let mut p = [0.0f64; 3];
        for (axis, slot) in p.iter_mut().enumerate() {
            let token = tokens
                .next()
                .ok_or_else(|| syntax(line, format!("vertex {v}: expected 3 coordinates, found {axis}")))?;
            // Non-finite values ("nan", "inf") parse here and are rejected by TriMesh::new, naming the vertex.
            *slot = token
                .parse()
                .map_err(|_| syntax(line, format!("vertex {v}: coordinate '{token}' is not a number")))?;
        }
        positions.push(p);
    }

    let mut triangles = Vec::with_capacity(n_faces.min(max_records));
    for f in 0..n_faces {
        let (line, content) = lines.next().ok_or_else(|| MeshError::Truncated {
            expected: format!("{n_faces} faces announced in the header, found {f}"),
        })?;
        let mut tokens = content.split_ascii_whitespace();
        let corners_token = tokens.next().unwrap_or("");
        let corners: usize = corners_token.parse().map_err(|_| {
            syntax(line, format!("face {f}: corner count '{corners_token}' is not a non-negative integer"))
        })?;
        if corners != 3 {
            return Err(MeshError::NotATriangle { face: f, corners });
        }
        let mut t = [0u32; 3];
        for (k, slot) in t.iter_mut().enumerate() {
            let token = tokens
                .next()
                .ok_or_else(|| syntax(line, format!("face {f}: expected 3 vertex indices, found {k}")))?;
            *slot = parse_index(token, f, n_vertices, line)?;
        }
        triangles.push(t);
    }

    if let Some((line, _)) = lines.next() {
        return Err(syntax(
            line,
            format!("unexpected content after the {n_vertices} vertices and {n_faces} faces announced in the header"),
        ));
    }
    TriMesh::new(positions, triangles)
}

/// Write `mesh` (`#V x 3` positions, `#F x 3` triangles) to `path` as OFF, every coordinate with
/// round-trip precision. Atomic, see [`atomic_write`]; errors name the file.
pub fn write_off(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<()> {
    atomic_write(path, |w| write_off_to(w, mesh))
}

fn write_off_to(w: &mut dyn Write, mesh: &TriMesh) -> Result<()> {
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.n_vertices(), mesh.n_faces())?;
    for p in mesh.positions() {
        writeln!(w, "{} {} {}", RoundTrip(p[0]), RoundTrip(p[1]), RoundTrip(p[2]))?;
    }
    for t in mesh.triangles() {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
    }
    Ok(())
}

/// `[ST][C][N]OFF`: prefixes that only add per-vertex columns after `x y z`, which the reader ignores.
/// `4OFF` and `nOFF` change the dimension and are rejected.
pub(super) fn is_off_keyword(keyword: &str) -> bool {
    let Some(prefix) = keyword.strip_suffix("OFF") else {
        return false;
    };
    let prefix = prefix.strip_prefix("ST").unwrap_or(prefix);
    let prefix = prefix.strip_prefix('C').unwrap_or(prefix);
    let prefix = prefix.strip_prefix('N').unwrap_or(prefix);
    prefix.is_empty()
}

fn parse_count(token: &str, what: &str, line: usize) -> Result<usize> {
    token.parse().map_err(|_| syntax(line, format!("{what} count '{token}' is not a non-negative integer")))
}

/// A 0-based vertex index. Negative indices are a syntax error here because, once cast, they would
/// surface as a huge out-of-range index that hides the actual mistake.
fn parse_index(token: &str, face: usize, n_vertices: usize, line: usize) -> Result<u32> {
    match token.parse::<i64>() {
        Ok(i) if i < 0 => Err(syntax(line, format!("face {face}: negative vertex index {i}"))),
        Ok(i) => {
            u32::try_from(i).map_err(|_| MeshError::IndexOutOfRange { face, index: i as u64, n_vertices })
        }
        Err(_) => Err(syntax(line, format!("face {face}: vertex index '{token}' is not an integer"))),
    }
}
