//! Polygon faces of the OBJ and PLY readers and their fan triangulation.
//!
//! A face with corners `c_0, c_1, ..., c_{k-1}` (`k >= 3`) becomes the `k - 2` triangles
//! `(c_0, c_i, c_{i+1})` for `i = 1..k-1`, in that order, keeping the face's orientation. This is
//! correct for convex polygons and for polygons star-shaped from corner 0 (every corner visible from
//! `c_0`); other concave polygons get overlapping or flipped triangles. No geometry is consulted:
//! the triangles depend only on the corner order, so a file always gives the same mesh.

use crate::error::{MeshError, Result};

/// Faces read from a file, each a list of 0-based vertex indices, kept flat (`corners` and `#F + 1`
/// `offsets`) so a large mesh costs no allocation per face.
#[derive(Debug)]
pub(crate) struct Polygons {
    corners: Vec<u32>,
    offsets: Vec<usize>,
}

impl Polygons {
    pub(crate) fn new() -> Self {
        Self { corners: Vec::new(), offsets: vec![0] }
    }

    /// Number of faces pushed so far; the 0-based number of the next face.
    pub(crate) fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Append one face.
    pub(crate) fn push(&mut self, corners: impl IntoIterator<Item = u32>) {
        self.corners.extend(corners);
        self.offsets.push(self.corners.len());
    }

    /// `#T x 3` triangles, the fans of every face in file order (see the module docs).
    ///
    /// Checks each face in face terms before triangulating, so errors name the file's face number
    /// (0-based), not a triangle's: [`MeshError::IndexOutOfRange`] for a corner `>= n_vertices`,
    /// [`MeshError::Untriangulable`] for fewer than 3 corners or a fan triangle with a repeated vertex.
    pub(crate) fn triangulate(&self, n_vertices: usize) -> Result<Vec<[u32; 3]>> {
        let mut triangles = Vec::with_capacity(self.corners.len().saturating_sub(2 * self.len()));
        for (face, w) in self.offsets.windows(2).enumerate() {
            let corners = &self.corners[w[0]..w[1]];
            if let Some(&index) = corners.iter().find(|&&i| i as usize >= n_vertices) {
                return Err(MeshError::IndexOutOfRange { face, index: u64::from(index), n_vertices });
            }
            push_fan(&mut triangles, face, corners)?;
        }
        Ok(triangles)
    }
}

/// Append the fan triangles of one face with in-range `corners` to `triangles`.
fn push_fan(triangles: &mut Vec<[u32; 3]>, face: usize, corners: &[u32]) -> Result<()> {
    let k = corners.len();
    if k < 3 {
        return Err(MeshError::Untriangulable { face, corners: k, reason: "at least 3 are needed".into() });
    }
    let c0 = corners[0];
    for (i, pair) in corners[1..].windows(2).enumerate() {
        let t = [c0, pair[0], pair[1]];
        let repeated = if t[0] == t[1] || t[0] == t[2] {
            Some(t[0])
        } else if t[1] == t[2] {
            Some(t[1])
        } else {
            None
        };
        if let Some(vertex) = repeated {
            return Err(MeshError::Untriangulable {
                face,
                corners: k,
                reason: format!("fan triangle {i} (corners 0, {}, {}) repeats vertex {vertex}", i + 1, i + 2),
            });
        }
        triangles.push(t);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fan(faces: &[&[u32]], n: usize) -> Result<Vec<[u32; 3]>> {
        let mut p = Polygons::new();
        for f in faces {
            p.push(f.iter().copied());
        }
        p.triangulate(n)
    }

    #[test]
    fn fans_from_corner_zero_in_order() {
        assert_eq!(fan(&[&[0, 1, 2]], 3).unwrap(), vec![[0, 1, 2]]);
        assert_eq!(
            fan(&[&[4, 0, 1, 2, 3], &[1, 2, 3]], 5).unwrap(),
            vec![[4, 0, 1], [4, 1, 2], [4, 2, 3], [1, 2, 3]]
        );
    }

    #[test]
    fn rejects_small_faces_repeats_and_out_of_range_naming_the_face() {
        let e = fan(&[&[0, 1, 2], &[0, 1]], 3).unwrap_err();
        assert!(matches!(e, MeshError::Untriangulable { face: 1, corners: 2, .. }), "{e:?}");
        assert!(e.to_string().contains("face 1") && e.to_string().contains("2 corners"), "{e}");
        let e = fan(&[&[]], 3).unwrap_err();
        assert!(matches!(e, MeshError::Untriangulable { face: 0, corners: 0, .. }), "{e:?}");
        let e = fan(&[&[0, 1, 2, 0]], 3).unwrap_err();
        assert!(e.to_string().contains("face 0") && e.to_string().contains("repeats vertex 0"), "{e}");
        let e = fan(&[&[0, 1, 2, 2, 3]], 4).unwrap_err();
        assert!(e.to_string().contains("repeats vertex 2"), "{e}");
        let e = fan(&[&[0, 1, 2], &[0, 2, 7, 1]], 3).unwrap_err();
        assert!(matches!(e, MeshError::IndexOutOfRange { face: 1, index: 7, n_vertices: 3 }), "{e:?}");
    }
}
