//! The edit files of the Botsch–Sorkine deformation survey: the per-vertex selection (`.sel`) and the
//! handle transform (`.def`).
//!
//! `.sel`: `#` comment lines, then one integer per vertex in vertex order, `0` fixed, `1` free (the
//! deformable region), `2` handle:
//! ```text
//! # per vertex status: 0=fixed, 1=deformable-region, 2=handle
//! 2
//! 1
//! 0
//! ```
//! `.def`: `#` comment lines, then the 4x4 affine transform applied to handle vertices, row major,
//! acting on column vectors `(x, y, z, 1)`:
//! ```text
//! # 4x4 handle transformation matrix
//! 1 0 0 -32.3
//! 0 1 0 0
//! 0 0 1 56.7
//! 0 0 0 1
//! ```
//! In both, comments may also trail data on a line, and blank lines are ignored.

use std::path::Path;

use super::{atomic_write, data_lines, read_text, syntax, RoundTrip};
use crate::edit::{AffineTransform, VertexStatus};
use crate::error::{MeshError, Result};

/// Read the selection `path` of a mesh with `n_vertices` vertices: `#V` statuses in vertex order.
///
/// Several codes on one line are accepted and counted in order. Errors (all wrapped in
/// [`MeshError::InFile`]): [`MeshError::Syntax`] with the line for a token that is not an integer or a
/// code outside `{0, 1, 2}`; [`MeshError::LengthMismatch`] when the file holds other than `n_vertices`
/// codes.
pub fn read_selection(path: impl AsRef<Path>, n_vertices: usize) -> Result<Vec<VertexStatus>> {
    let path = path.as_ref();
    read_text(path).and_then(|text| parse_selection(&text, n_vertices)).map_err(|e| e.in_file(path))
}

fn parse_selection(text: &str, n_vertices: usize) -> Result<Vec<VertexStatus>> {
    let mut selection = Vec::with_capacity(n_vertices.min(text.len() / 2 + 1));
    for (line, content) in data_lines(text) {
        for token in content.split_ascii_whitespace() {
            let v = selection.len();
            let code: i64 = token.parse().map_err(|_| {
                syntax(
                    line,
                    format!("vertex {v}: status '{token}' is not an integer (0 fixed, 1 free, 2 handle)"),
                )
            })?;
            let status = VertexStatus::from_code(code).ok_or_else(|| {
                syntax(
                    line,
                    format!("vertex {v}: status {code} is not one of 0 (fixed), 1 (free), 2 (handle)"),
                )
            })?;
            selection.push(status);
        }
    }
    if selection.len() != n_vertices {
        return Err(MeshError::LengthMismatch {
            what: "selection",
            got: selection.len(),
            expected: n_vertices,
        });
    }
    Ok(selection)
}

/// Write the `#V` statuses `selection` to `path` in the survey's `.sel` layout (two comment lines, then
/// one code per line). Atomic, see [`atomic_write`]; errors name the file.
pub fn write_selection(path: impl AsRef<Path>, selection: &[VertexStatus]) -> Result<()> {
    atomic_write(path, |w| {
        writeln!(w, "# per vertex status: 0=fixed, 1=deformable-region, 2=handle")?;
        writeln!(w, "# {} vertices", selection.len())?;
        for s in selection {
            writeln!(w, "{}", s.code())?;
        }
        Ok(())
    })
}

/// Read the 4x4 handle transform `path` (row major) into an [`AffineTransform`].
///
/// Errors (all wrapped in [`MeshError::InFile`]): [`MeshError::Syntax`] with the line for a malformed
/// number, a row with other than 4 numbers, a fifth row, or a file that ends before the fourth row (the
/// line is then the file's last line); [`MeshError::Invalid`] from [`AffineTransform::from_rows`] for a
/// non-finite entry or a last row other than `0 0 0 1`.
pub fn read_transform(path: impl AsRef<Path>) -> Result<AffineTransform> {
    let path = path.as_ref();
    read_text(path).and_then(|text| parse_transform(&text)).map_err(|e| e.in_file(path))
}

fn parse_transform(text: &str) -> Result<AffineTransform> {
    let mut rows = [[0.0f64; 4]; 4];
    let mut n_rows = 0;
    for (line, content) in data_lines(text) {
        let Some(row) = rows.get_mut(n_rows) else {
            return Err(syntax(line, "unexpected fifth row; a transform has exactly 4 rows of 4 numbers"));
        };
        let tokens: Vec<&str> = content.split_ascii_whitespace().collect();
        if tokens.len() != 4 {
            return Err(syntax(
                line,
                format!("row {}: expected 4 numbers, found {}", n_rows + 1, tokens.len()),
            ));
        }
        for (slot, token) in row.iter_mut().zip(&tokens) {
            *slot = token
                .parse()
                .map_err(|_| syntax(line, format!("row {}: '{token}' is not a number", n_rows + 1)))?;
        }
        n_rows += 1;
    }
    if n_rows < 4 {
        return Err(syntax(
            text.lines().count(),
            format!("the file ends after {n_rows} rows; a transform has exactly 4 rows of 4 numbers"),
        ));
    }
    AffineTransform::from_rows(rows)
}

/// Write `transform` to `path` in the survey's `.def` layout (a comment line, then 4 rows of 4
/// numbers with round-trip precision). Atomic, see [`atomic_write`]; errors name the file.
pub fn write_transform(path: impl AsRef<Path>, transform: &AffineTransform) -> Result<()> {
    atomic_write(path, |w| {
        writeln!(w, "# 4x4 handle transformation matrix")?;
        for row in transform.rows() {
            writeln!(
                w,
                "{} {} {} {}",
                RoundTrip(row[0]),
                RoundTrip(row[1]),
                RoundTrip(row[2]),
                RoundTrip(row[3])
            )?;
        }
        Ok(())
    })
}
