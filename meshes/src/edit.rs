//! The edit of a Botsch–Sorkine test: per-vertex status (the survey's `.sel`) and the affine handle
//! transform (the survey's `.def`).

use crate::error::{MeshError, Result};

/// Role of a vertex in a survey edit (`.sel` values 0, 1, 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VertexStatus {
    /// `0`: stays at its rest position.
    Fixed,
    /// `1`: the deformable region.
    Free,
    /// `2`: moved by the handle transform.
    Handle,
}

impl VertexStatus {
    /// The survey's integer code.
    pub fn code(self) -> u8 {
        match self {
            VertexStatus::Fixed => 0,
            VertexStatus::Free => 1,
            VertexStatus::Handle => 2,
        }
    }

    /// Parse the survey's integer code.
    pub fn from_code(code: i64) -> Option<Self> {
        match code {
            0 => Some(VertexStatus::Fixed),
            1 => Some(VertexStatus::Free),
            2 => Some(VertexStatus::Handle),
            _ => None,
        }
    }
}

/// A 4x4 affine transform, row major, acting on column vectors `(x, y, z, 1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AffineTransform {
    rows: [[f64; 4]; 4],
}

impl AffineTransform {
    /// The identity transform.
    pub const IDENTITY: AffineTransform = AffineTransform {
        rows: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
    };

    /// Build from 4 rows; every entry must be finite and the last row `0 0 0 1` (to 1e-9).
    pub fn from_rows(rows: [[f64; 4]; 4]) -> Result<Self> {
        for (r, row) in rows.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                if !v.is_finite() {
                    return Err(MeshError::Invalid(format!(
                        "transform entry ({r}, {c}) is {v}, not a finite number"
                    )));
                }
            }
        }
        let last = rows[3];
        if (last[0].abs() + last[1].abs() + last[2].abs() + (last[3] - 1.0).abs()) > 1e-9 {
            return Err(MeshError::Invalid(format!(
                "transform is not affine: last row is {last:?}, expected [0, 0, 0, 1]"
            )));
        }
        Ok(Self { rows })
    }

    /// Rotation by `angle` radians about the unit `axis` through `center`.
    pub fn rotation_about(axis: [f64; 3], angle: f64, center: [f64; 3]) -> Self {
        let r = crate::vector::rotation_matrix(crate::vector::normalize_or_zero(axis), angle);
        let mut rows = [[0.0; 4]; 4];
        for i in 0..3 {
            rows[i][..3].copy_from_slice(&r[i]);
            rows[i][3] = center[i] - (r[i][0] * center[0] + r[i][1] * center[1] + r[i][2] * center[2]);
        }
        rows[3] = [0.0, 0.0, 0.0, 1.0];
        Self { rows }
    }

    /// Translation by `t`.
    pub fn translation(t: [f64; 3]) -> Self {
        let mut m = Self::IDENTITY;
        for i in 0..3 {
            m.rows[i][3] = t[i];
        }
        m
    }

    /// `self * other` (apply `other` first).
    pub fn compose(&self, other: &AffineTransform) -> Self {
        let mut rows = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                rows[i][j] = (0..4).map(|k| self.rows[i][k] * other.rows[k][j]).sum();
            }
        }
        Self { rows }
    }

    /// The 4 rows.
    pub fn rows(&self) -> &[[f64; 4]; 4] {
        &self.rows
    }

    /// `T * (p, 1)`.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| {
            self.rows[i][0] * p[0] + self.rows[i][1] * p[1] + self.rows[i][2] * p[2] + self.rows[i][3]
        })
    }
}

/// Vertex indices with the given status, ascending.
pub fn vertices_with_status(selection: &[VertexStatus], status: VertexStatus) -> Vec<u32> {
    selection.iter().enumerate().filter(|(_, s)| **s == status).map(|(i, _)| i as u32).collect()
}
