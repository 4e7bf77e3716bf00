//! How a handle region moves: the transform of a `[[regions]]` entry (rotate, scale, translate, or a
//! survey `.def` matrix), resolved on the rest mesh into a [`Motion`].
//!
//! ```toml
//! rotate = { axis = [0, 0, 1], degrees = 30, about = "centroid" }   # or about = [0.5, 0.5, 0] (bbox coordinates)
//! scale = 1.2                                                      # about the same pivot
//! translate = [0.0, 0.0, 0.1]                                      # x rest bbox diagonal ...
//! translate_units = "diagonal"                                     # ... or "mesh" (absolute)
//! # def = "handle.def"                                             # a 4x4 matrix instead of the above
//! ```
//!
//! Order: scale about the pivot, then rotate about it, then translate (the usual scale-rotate-translate
//! of modelling tools); the pivot is the centroid of the region's rest vertices unless `about` names
//! a point.

use meshes::{AffineTransform, TriMesh};
use serde::Deserialize;

use super::selection::{centroid, PathContext};

/// How a region's targets follow from the current shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// Stay where it is.
    Hold,
    /// The affine transform applied to the current positions.
    Transform(AffineTransform),
    /// Move by this offset.
    Translate([f64; 3]),
}

/// A rotation as written.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotateSpec {
    /// Axis direction (need not be unit; not zero).
    pub axis: [f64; 3],
    pub degrees: f64,
    #[serde(default)]
    pub about: Pivot,
}

/// The point a region rotates and scales about.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum Pivot {
    /// `"centroid"`: the centroid of the region's rest vertices.
    Named(PivotName),
    /// A point in the rest mesh's bounding-box coordinates.
    Point([f64; 3]),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PivotName {
    Centroid,
}

impl Default for Pivot {
    fn default() -> Self {
        Pivot::Named(PivotName::Centroid)
    }
}

/// Units of `translate`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Multiples of the rest bounding-box diagonal (the same edit on meshes of any size).
    #[default]
    Diagonal,
    /// Mesh units.
    Mesh,
}

/// The transform fields of a region as written (all optional; none: the region is held).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TransformSpec {
    pub rotate: Option<RotateSpec>,
    pub scale: Option<f64>,
    pub translate: Option<[f64; 3]>,
    pub translate_units: Units,
    pub def: Option<String>,
}

impl TransformSpec {
    /// Whether any transform is given.
    pub fn is_empty(&self) -> bool {
        self.rotate.is_none() && self.scale.is_none() && self.translate.is_none() && self.def.is_none()
    }

    /// The motion of the region with rest `vertices` of `mesh`. Errors say which field is wrong.
    pub fn resolve(&self, mesh: &TriMesh, vertices: &[u32], paths: &PathContext) -> Result<Motion, String> {
        if let Some(def) = &self.def {
            if self.rotate.is_some() || self.scale.is_some() || self.translate.is_some() {
                return Err(
                    "`def` is a whole transform: give it alone, without rotate, scale or translate".into()
                );
            }
            let path = paths.resolve_existing("def", def)?;
            let t = meshes::io::read_transform(&path).map_err(|e| e.to_string())?;
            return Ok(Motion::Transform(t));
        }
        if self.is_empty() {
            return Ok(Motion::Hold);
        }
        let (lo, hi) = mesh.bbox();
        let diagonal = mesh.bbox_diagonal();
        let pivot = match self.rotate.as_ref().map(|r| &r.about).unwrap_or(&Pivot::default()) {
            Pivot::Named(PivotName::Centroid) => centroid(mesh, vertices),
            Pivot::Point(c) => {
                if c.iter().any(|x| !x.is_finite()) {
                    return Err(format!("rotate.about {c:?} must be finite"));
                }
                std::array::from_fn(|k| lo[k] + c[k] * (hi[k] - lo[k]))
            }
        };
        let mut t = AffineTransform::IDENTITY;
        if let Some(s) = self.scale {
            if !(s.is_finite() && s > 0.0) {
                return Err(format!("scale {s} must be a positive finite number"));
            }
            t = scaling_about(s, pivot);
        }
        if let Some(r) = &self.rotate {
            let axis_length = meshes::vector::norm(r.axis);
            if !(axis_length.is_finite() && axis_length > 0.0 && r.degrees.is_finite()) {
                return Err(format!("rotate: axis {:?} must be finite and non-zero, degrees finite", r.axis));
            }
            t = AffineTransform::rotation_about(r.axis, r.degrees.to_radians(), pivot).compose(&t);
        }
        if let Some(d) = self.translate {
            if d.iter().any(|x| !x.is_finite()) {
                return Err(format!("translate {d:?} must be finite"));
            }
            let d = match self.translate_units {
                Units::Diagonal => d.map(|c| c * diagonal),
                Units::Mesh => d,
            };
            t = AffineTransform::translation(d).compose(&t);
        }
        Ok(Motion::Transform(t))
    }
}

/// Uniform scaling by `s` about `center`.
fn scaling_about(s: f64, center: [f64; 3]) -> AffineTransform {
    let mut rows = [[0.0; 4]; 4];
    for i in 0..3 {
        rows[i][i] = s;
        rows[i][3] = (1.0 - s) * center[i];
    }
    rows[3][3] = 1.0;
    AffineTransform::from_rows(rows).expect("finite and affine by construction")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> TriMesh {
        TriMesh::new(
            vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap()
    }

    fn paths() -> PathContext {
        PathContext { base: ".".into(), stem: None, read: Default::default() }
    }

    fn apply(m: &Motion, p: [f64; 3]) -> [f64; 3] {
        match m {
            Motion::Transform(t) => t.apply(p),
            Motion::Translate(d) => [p[0] + d[0], p[1] + d[1], p[2] + d[2]],
            Motion::Hold => p,
        }
    }

    #[test]
    fn scale_then_rotate_about_the_centroid_then_translate() {
        let mesh = square();
        let spec = TransformSpec {
            rotate: Some(RotateSpec { axis: [0.0, 0.0, 2.0], degrees: 90.0, about: Pivot::default() }),
            scale: Some(2.0),
            translate: Some([0.0, 0.0, 1.0]),
            translate_units: Units::Diagonal,
            def: None,
        };
        // Region: vertices 1 and 2, centroid (2, 1, 0).
        let m = spec.resolve(&mesh, &[1, 2], &paths()).unwrap();
        // (2, 2): scaled about (2, 1) -> (2, 3); rotated 90 degrees about z there -> (0, 1); lifted by
        // one diagonal (2 sqrt 2).
        let q = apply(&m, [2.0, 2.0, 0.0]);
        let expected = [0.0, 1.0, 8f64.sqrt()];
        assert!((0..3).all(|k| (q[k] - expected[k]).abs() < 1e-12), "{q:?}");
        // The pivot itself only translates.
        let c = apply(&m, [2.0, 1.0, 0.0]);
        assert!((c[2] - 8f64.sqrt()).abs() < 1e-12 && (c[0] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn mesh_units_pivot_points_and_bad_fields() {
        let mesh = square();
        let spec = TransformSpec {
            translate: Some([1.0, 0.0, 0.0]),
            translate_units: Units::Mesh,
            ..Default::default()
        };
        assert_eq!(apply(&spec.resolve(&mesh, &[0], &paths()).unwrap(), [0.0; 3]), [1.0, 0.0, 0.0]);
        let about_corner = TransformSpec {
            rotate: Some(RotateSpec {
                axis: [0.0, 0.0, 1.0],
                degrees: 180.0,
                about: Pivot::Point([0.0, 0.0, 0.0]),
            }),
            ..Default::default()
        };
        let q = apply(&about_corner.resolve(&mesh, &[2], &paths()).unwrap(), [2.0, 2.0, 0.0]);
        assert!((q[0] + 2.0).abs() < 1e-12 && (q[1] + 2.0).abs() < 1e-12, "{q:?}");
        assert_eq!(TransformSpec::default().resolve(&mesh, &[0], &paths()).unwrap(), Motion::Hold);
        let zero_axis = TransformSpec {
            rotate: Some(RotateSpec { axis: [0.0; 3], degrees: 10.0, about: Pivot::default() }),
            ..Default::default()
        };
        assert!(zero_axis.resolve(&mesh, &[0], &paths()).unwrap_err().contains("axis"));
        let negative = TransformSpec { scale: Some(-1.0), ..Default::default() };
        assert!(negative.resolve(&mesh, &[0], &paths()).unwrap_err().contains("scale"));
        let both = TransformSpec { def: Some("x.def".into()), scale: Some(2.0), ..Default::default() };
        assert!(both.resolve(&mesh, &[0], &paths()).unwrap_err().contains("alone"));
    }
}
