//! Vertex-id lists: a set of vertices written as their 0-based indices.
//!
//! ```text
//! # handle vertices
//! 12 13 14
//! 15        # comments, full-line or trailing, and blank lines anywhere
//! ```
//! Any mix of spaces, tabs and newlines separates the ids. The order (and any repetition) is kept as
//! written: it is the caller's to decide whether a set or a sequence is meant, and to check the ids
//! against a mesh.

use std::path::Path;

use super::{data_lines, read_text, syntax};
use crate::error::Result;

/// Read the vertex-id list `path`: every id in file order (`#ids`, not checked against any mesh).
///
/// Errors (all wrapped in [`crate::MeshError::InFile`]): [`crate::MeshError::Syntax`] with the 1-based
/// line for a token that is not a non-negative integer below `2^32`, or invalid UTF-8.
pub fn read_index_list(path: impl AsRef<Path>) -> Result<Vec<u32>> {
    let path = path.as_ref();
    read_text(path).and_then(|text| parse_index_list(&text)).map_err(|e| e.in_file(path))
}

fn parse_index_list(text: &str) -> Result<Vec<u32>> {
    let mut ids = Vec::new();
    for (line, content) in data_lines(text) {
        for token in content.split_ascii_whitespace() {
            let id = token.parse::<u32>().map_err(|_| {
                syntax(
                    line,
                    format!("entry {}: '{token}' is not a vertex id (a non-negative integer)", ids.len()),
                )
            })?;
            ids.push(id);
        }
    }
    Ok(ids)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::MeshError;

    #[test]
    fn ids_in_order_with_comments_and_blank_lines() {
        assert_eq!(parse_index_list("# c\n3 1\t2\n\n 1 # again\n0\n").unwrap(), vec![3, 1, 2, 1, 0]);
        assert!(parse_index_list("# nothing\n").unwrap().is_empty());
    }

    #[test]
    fn bad_tokens_name_the_line() {
        for (text, line) in [("1\n2\n-3\n", 3), ("1 2.0\n", 1), ("# x\n\n4294967296\n", 3), ("1,2\n", 1)] {
            let e = parse_index_list(text).unwrap_err();
            assert!(matches!(e, MeshError::Syntax { line: l, .. } if l == line), "{text:?}: {e:?}");
        }
    }
}
