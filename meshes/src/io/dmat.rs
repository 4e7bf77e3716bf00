//! libigl's dense matrix text format (`.dmat`), as its tutorials use for per-vertex selections
//! (one region id per vertex, [`read_dmat_column`]) and for lists of vertex indices
//! ([`read_dmat_integers`]).
//!
//! ```text
//! 1 4        # first line: #columns #rows
//! -1         # then #columns x #rows values, column by column (column-major), whitespace separated
//! 0
//! 2
//! -1
//! ```
//! Values may share lines or spread over any number of lines; blank lines are ignored (and, as
//! everywhere in this crate's text readers, `#` comments, which libigl never writes). libigl's binary
//! variant (a `0 0` header followed by raw doubles) is not supported.

use std::path::Path;

use super::{data_lines, read_text, syntax};
use crate::error::{MeshError, Result};

/// A dense `#rows x #cols` matrix of `f64`, stored column-major like the file (and Eigen).
#[derive(Clone, Debug, PartialEq)]
pub struct DenseMatrix {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

impl DenseMatrix {
    /// Number of rows (for a per-vertex column, `#V`).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Entry `(row, col)`; panics when out of range, like slice indexing.
    pub fn get(&self, row: usize, col: usize) -> f64 {
        assert!(row < self.rows && col < self.cols, "({row}, {col}) is outside {}x{}", self.rows, self.cols);
        self.data[col * self.rows + row]
    }

    /// Column `col` (`#rows` values).
    pub fn column(&self, col: usize) -> &[f64] {
        &self.data[col * self.rows..(col + 1) * self.rows]
    }

    /// All `#rows x #cols` values, column-major.
    pub fn data(&self) -> &[f64] {
        &self.data
    }
}

/// Read the `.dmat` file `path` into a `#rows x #cols` matrix (any numbers Rust's `f64` parser
/// accepts, including `nan` and `inf`).
///
/// Errors (all wrapped in [`MeshError::InFile`]): [`MeshError::Truncated`] for an empty file or fewer
/// values than the header announces; [`MeshError::Syntax`] with the line for a bad header, a value
/// that is not a number or a value beyond the announced count; [`MeshError::Format`] for libigl's
/// binary variant.
pub fn read_dmat(path: impl AsRef<Path>) -> Result<DenseMatrix> {
    let path = path.as_ref();
    read_dmat_text(path)
        .and_then(|text| {
            let (rows, cols, data) = parse_values(&text, |token| token.parse::<f64>().ok(), "a number")?;
            Ok(DenseMatrix { rows, cols, data })
        })
        .map_err(|e| e.in_file(path))
}

/// Read the single-column `.dmat` file `path` of a mesh with `n_vertices` vertices: `#V` integers in
/// vertex order, `-1` for a free vertex and `0, 1, 2, ...` for the region (handle) a vertex belongs
/// to, as libigl's ARAP tutorial selections are written.
///
/// Errors (all wrapped in [`MeshError::InFile`]): those of [`read_dmat`]; [`MeshError::Syntax`] with
/// the line and vertex for a value that is not an integer or is below `-1`; [`MeshError::Invalid`]
/// when the header announces other than one column; [`MeshError::LengthMismatch`] when it holds other
/// than `n_vertices` rows.
pub fn read_dmat_column(path: impl AsRef<Path>, n_vertices: usize) -> Result<Vec<i64>> {
    let path = path.as_ref();
    read_dmat_text(path).and_then(|text| parse_column(&text, n_vertices)).map_err(|e| e.in_file(path))
}

fn parse_column(text: &str, n_vertices: usize) -> Result<Vec<i64>> {
    let (rows, cols, values) =
        parse_values(text, |token| token.parse::<i64>().ok().filter(|&v| v >= -1), "an integer >= -1")?;
    if cols != 1 {
        return Err(MeshError::Invalid(format!(
            "expected one column (a per-vertex value), the header announces {cols} columns of {rows} rows"
        )));
    }
    if rows != n_vertices {
        return Err(MeshError::LengthMismatch { what: ".dmat column", got: rows, expected: n_vertices });
    }
    Ok(values)
}

/// Read the `.dmat` file `path` of one column (or one row) of integers, of any length: a per-vertex
/// column of region ids whose length the caller checks against its mesh, or a list of vertex
/// indices (as libigl writes an index vector, e.g. the constrained vertices `b`).
///
/// Errors (all wrapped in [`MeshError::InFile`]): those of [`read_dmat`]; [`MeshError::Syntax`] with
/// the line for a value that is not an integer; [`MeshError::Invalid`] for a matrix of more than one
/// column and more than one row.
pub fn read_dmat_integers(path: impl AsRef<Path>) -> Result<Vec<i64>> {
    let path = path.as_ref();
    read_dmat_text(path).and_then(|text| parse_integers(&text)).map_err(|e| e.in_file(path))
}

fn parse_integers(text: &str) -> Result<Vec<i64>> {
    let (rows, cols, values) = parse_values(text, |token| token.parse::<i64>().ok(), "an integer")?;
    if cols != 1 && rows != 1 {
        return Err(MeshError::Invalid(format!(
            "expected one column or one row of integers, the header announces {cols} columns of {rows} rows"
        )));
    }
    Ok(values)
}

/// The file's text; a binary `.dmat` is named as such rather than reported as invalid UTF-8.
fn read_dmat_text(path: &Path) -> Result<String> {
    read_text(path).map_err(|e| match e {
        MeshError::Syntax { .. } if std::fs::read(path).is_ok_and(|b| b.starts_with(b"0 0")) => {
            MeshError::Format(
                "binary .dmat (header '0 0' followed by raw doubles) is not supported; write it as text"
                    .into(),
            )
        }
        e => e,
    })
}

/// `(rows, cols, values)` of a `.dmat` text, each value converted by `parse` (which returns `None`
/// for a token it rejects; `expected` says what it wants, for the error message).
fn parse_values<T>(
    text: &str,
    parse: impl Fn(&str) -> Option<T>,
    expected: &str,
) -> Result<(usize, usize, Vec<T>)> {
    let mut lines = data_lines(text);
    let (header_line, header) = lines
        .next()
        .ok_or_else(|| MeshError::Truncated { expected: "the .dmat header '#columns #rows'".into() })?;
    let counts: Vec<&str> = header.split_ascii_whitespace().collect();
    let bad_header = || {
        syntax(
            header_line,
            format!(
                "expected the .dmat header '#columns #rows' (two non-negative integers), found '{}'",
                header.trim()
            ),
        )
    };
    let [cols, rows] = counts[..] else { return Err(bad_header()) };
    let (Ok(cols), Ok(rows)) = (cols.parse::<usize>(), rows.parse::<usize>()) else {
        return Err(bad_header());
    };
    let n = cols.checked_mul(rows).ok_or_else(|| {
        syntax(header_line, format!("{cols} columns x {rows} rows is more values than memory can hold"))
    })?;
    // Cap the reservation by what the text can hold: a lying header must not trigger a huge allocation.
    let mut values = Vec::with_capacity(n.min(text.len() / 2 + 1));
    for (line, content) in lines {
        for token in content.split_ascii_whitespace() {
            let k = values.len();
            if k == n {
                return Err(syntax(
                    line,
                    format!("unexpected value '{token}': the header announces {cols} x {rows} = {n} values"),
                ));
            }
            // Column-major: value k is row k % rows of column k / rows.
            let value = parse(token).ok_or_else(|| {
                syntax(
                    line,
                    format!("value {k} (row {}, column {}): '{token}' is not {expected}", k % rows, k / rows),
                )
            })?;
            values.push(value);
        }
    }
    if values.len() < n {
        return Err(MeshError::Truncated {
            expected: format!("{cols} x {rows} = {n} values announced in the header, found {}", values.len()),
        });
    }
    Ok((rows, cols, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_column_major() {
        let (rows, cols, data) =
            parse_values("2 3\n1 2 3\n4\n\n5 6\n", |t| t.parse::<f64>().ok(), "").unwrap();
        let m = DenseMatrix { rows, cols, data };
        assert_eq!((m.rows(), m.cols()), (3, 2));
        assert_eq!(m.column(1), &[4.0, 5.0, 6.0]);
        assert_eq!(m.get(2, 0), 3.0);
        assert_eq!(m.get(0, 1), 4.0);
    }

    #[test]
    fn column_errors_name_line_vertex_and_counts() {
        let e = parse_column("1 3\n-1\n0\n-2\n", 3).unwrap_err();
        assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");
        assert!(e.to_string().contains("row 2") && e.to_string().contains("'-2'"), "{e}");
        let e = parse_column("1 3\n-1\n0\n1.5\n", 3).unwrap_err();
        assert!(matches!(e, MeshError::Syntax { line: 4, .. }), "{e:?}");
        let e = parse_column("2 2\n0 0 0 0\n", 4).unwrap_err();
        assert!(matches!(e, MeshError::Invalid(_)) && e.to_string().contains("2 columns"), "{e:?}");
        let e = parse_column("1 3\n0 0 0\n", 4).unwrap_err();
        assert!(matches!(e, MeshError::LengthMismatch { got: 3, expected: 4, .. }), "{e:?}");
        assert_eq!(parse_column("1 3\n-1 0\n7\n", 3).unwrap(), vec![-1, 0, 7]);
    }

    #[test]
    fn integers_are_one_column_or_one_row_of_any_length() {
        assert_eq!(parse_integers("1 3\n12\n-1\n7\n").unwrap(), vec![12, -1, 7]);
        assert_eq!(parse_integers("2 1\n4 5\n").unwrap(), vec![4, 5]);
        let e = parse_integers("2 2\n0 1 2 3\n").unwrap_err();
        assert!(matches!(e, MeshError::Invalid(_)) && e.to_string().contains("2 columns of 2 rows"), "{e}");
        let e = parse_integers("1 2\n3\n4.5\n").unwrap_err();
        assert!(matches!(e, MeshError::Syntax { line: 3, .. }), "{e:?}");
    }
}
