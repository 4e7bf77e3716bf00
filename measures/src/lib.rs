//! Quality measures of a handle-based deformation result against its rest mesh, and the verdict
//! rules that judge them: what deformbench measures, without the benchmark around it. It depends
//! on `meshes` and `methods` (without its `external` feature) and on no command line, plotting,
//! database or process library, so a Python package or a user's program can use it alone.
//!
//! [`evaluate`] is the entry point: plain arrays in (rest and result positions, faces, handle
//! regions and their targets), every measure out; [`judge`] takes the same arrays and the verdict
//! rules and gives the measures with the reasons a result is suspect. The harness measures and
//! judges every case through [`judge_on`] (over [`evaluate_on`]), the same with the rest side
//! computed once per scenario.
//!
//! The modules, by concept:
//!
//! - [`metric`]: the metric table ([`METRICS`]): each measure's key, unit, formula, which way is
//!   better, regression tolerance, print format and function;
//! - [`quality`]: [`Quality`], the values of one result, and its results.json form;
//! - [`rest`], [`evaluation`], [`local`]: what the measures compare with (once per rest mesh), what
//!   they read of one result, and what each of its faces and one-rings did;
//! - [`distortion`], [`turn`], [`size`], [`distance`]: the measures themselves (angles, areas,
//!   lengths, volume, folds; turns of the surface and the turn the handles ask; the size they ask,
//!   face stretches, e_iso and the resized shares; distances);
//! - [`statistics`]: RMS and percentiles;
//! - [`verdict`], [`status`], [`step_trend`]: the rules that make a case `suspect`, the status they
//!   give, and why an iteration did not finish;
//! - [`error`]: what can go wrong ([`MeasuresError`]).
//!
//! Decision (issue 61): the print format of a measure ([`Format`], a column of [`METRICS`]) stays
//! here although it is presentation: it is one field of the table row that defines a measure, so a
//! new measure stays one row in one crate, and it needs nothing but `std`. Everything else about
//! presenting measures (tables, plots, pages) is the harness's.

pub mod distance;
pub mod distortion;
pub mod error;
pub mod evaluation;
pub mod local;
pub mod metric;
pub mod quality;
pub mod rest;
pub mod size;
pub mod statistics;
pub mod status;
pub mod step_trend;
pub mod turn;
pub mod verdict;

use meshes::{Topology, TriMesh};
use methods::{HandleRegion, HandleSet, HandleTargets};

pub use error::MeasuresError;
pub use evaluation::Evaluation;
pub use metric::{Better, Format, Metric, MetricSpec, Tolerance, METRICS};
pub use quality::Quality;
pub use rest::RestGeometry;
pub use status::{Status, Unfinished, STATUS_KINDS};
pub use step_trend::StepTrend;
pub use verdict::{reason_kind, Motion, Reference, VerdictRules, REASON_KINDS};

/// Every measure of a deformation result against its rest mesh.
///
/// # Inputs
///
/// - `rest`: `#V x 3` rest positions.
/// - `faces`: `#F x 3` triangles, indices into `rest`, counter-clockwise seen from outside (an
///   edge may have one or two faces).
/// - `result`: `#V x 3` positions of the deformed mesh, on the same faces.
/// - `fixed`: `#f` vertices held at their rest positions (may be empty): a handle region whose
///   targets are its rest positions, the first region.
/// - `handles`: `#H` handle regions, each a list of distinct vertices moved as a unit; no vertex
///   in two regions nor in `fixed`. At least one region or `fixed` vertex.
/// - `targets`: `#H` lists, the `#h_i x 3` target positions of the vertices of `handles[i]`, in
///   its order: where the edit asked them to go.
/// - `reference`: `#V x 3` result of the reference method (`arap`) on the same edit, if there is
///   one: the `*_to_arap` measures compare with it (`None` leaves them out).
///
/// # Outputs
///
/// The [`Quality`]: one value per [`Metric`] ([`Quality::get`]; `None` where a measure does not
/// apply: the volume of an open mesh, the `*_to_arap` measures without a reference,
/// `arap_energy` where its Laplacian cannot be built).
///
/// # Errors
///
/// [`MeasuresError`] for arrays that do not fit together: faces that make no mesh, a result,
/// reference or target list of the wrong size, handle regions that overlap or leave the mesh.
pub fn evaluate<H: AsRef<[usize]>, T: AsRef<[[f64; 3]]>>(
    rest: &[[f64; 3]],
    faces: &[[usize; 3]],
    result: &[[f64; 3]],
    fixed: &[usize],
    handles: &[H],
    targets: &[T],
    reference: Option<&[[f64; 3]]>,
) -> Result<Quality, MeasuresError> {
    let edit = Arrays::check(rest, faces, result, fixed, handles, targets, reference)?;
    let geometry = RestGeometry::new(&edit.mesh, &edit.topology);
    Ok(evaluate_on(&geometry, &edit.mesh, &edit.topology, result, (&edit.handles, &edit.targets), reference))
}

/// The arrays of [`evaluate`] and [`judge`], checked and made into a mesh and an edit.
struct Arrays {
    mesh: TriMesh,
    topology: Topology,
    handles: HandleSet,
    targets: HandleTargets,
}

impl Arrays {
    /// Check that the arrays fit together (see [`evaluate`]'s errors) and build the mesh, its edges
    /// and the edit (`fixed` first, as the region `fixed`).
    fn check<H: AsRef<[usize]>, T: AsRef<[[f64; 3]]>>(
        rest: &[[f64; 3]],
        faces: &[[usize; 3]],
        result: &[[f64; 3]],
        fixed: &[usize],
        handles: &[H],
        targets: &[T],
        reference: Option<&[[f64; 3]]>,
    ) -> Result<Arrays, MeasuresError> {
        let triangles = faces
            .iter()
            .enumerate()
            .map(|(f, t)| {
                let whose = || format!("face {f}");
                Ok([index(t[0], whose)?, index(t[1], whose)?, index(t[2], whose)?])
            })
            .collect::<Result<Vec<[u32; 3]>, MeasuresError>>()?;
        let mesh = TriMesh::new(rest.to_vec(), triangles)?;
        let topology = Topology::new(&mesh)?;
        check_size("result", result.len(), rest.len())?;
        if let Some(reference) = reference {
            check_size("reference", reference.len(), rest.len())?;
        }
        let (handles, targets) = edit(rest, fixed, handles, targets)?;
        Ok(Arrays { mesh, topology, handles, targets })
    }
}

/// [`evaluate`] for a caller that measures many results on one rest mesh (the harness: every
/// method on a scenario), with the rest side computed once and the handles already checked.
///
/// # Inputs
///
/// - `rest`: [`RestGeometry::new`] of `mesh` and `topology` (it holds the reference's ARAP
///   operator, the costly part).
/// - `mesh`, `topology`: the rest mesh (`#V` vertices, `#F` faces) and its edges.
/// - `result`: `#V x 3` positions of the deformed mesh.
/// - `handles`, `targets`: the handle regions of the edit (validated for `#V` vertices) and the
///   `#b x 3` targets of their vertices, in [`HandleSet::constrained`] order.
/// - `reference`: `#V x 3` result of the reference method on the same edit, if there is one.
///
/// # Outputs
///
/// The [`Quality`] of `result`, as [`evaluate`]'s. Panics if `result` or `reference` is not
/// `#V x 3`.
pub fn evaluate_on(
    rest: &RestGeometry,
    mesh: &TriMesh,
    topology: &Topology,
    result: &[[f64; 3]],
    (handles, targets): (&HandleSet, &HandleTargets),
    reference: Option<&[[f64; 3]]>,
) -> Quality {
    Quality::evaluate(&Evaluation::new(rest, mesh, topology, result, (handles, targets), reference))
}

/// A result judged: its measures, what the verdict read beside them, and the reasons it is
/// suspect (empty: `ok`).
#[derive(Clone, Debug, PartialEq)]
pub struct Judgement {
    pub quality: Quality,
    pub motion: Motion,
    pub reasons: Vec<String>,
}

/// Measure `result` and judge it by `rules`: [`evaluate`]'s inputs, with `reference` (if any)
/// taken as a finished reference result on the same edit (`Some(result)` itself: the reference
/// judged).
///
/// # Errors
///
/// As [`evaluate`].
#[allow(clippy::too_many_arguments)]
pub fn judge<H: AsRef<[usize]>, T: AsRef<[[f64; 3]]>>(
    rules: &VerdictRules,
    rest: &[[f64; 3]],
    faces: &[[usize; 3]],
    result: &[[f64; 3]],
    fixed: &[usize],
    handles: &[H],
    targets: &[T],
    reference: Option<&[[f64; 3]]>,
) -> Result<Judgement, MeasuresError> {
    let edit = Arrays::check(rest, faces, result, fixed, handles, targets, reference)?;
    let geometry = RestGeometry::new(&edit.mesh, &edit.topology);
    let reference = match reference {
        Some(r) if r == result => Reference::Itself,
        Some(positions) => Reference::Of { positions, finished: true },
        None => Reference::Missing,
    };
    let steps = [(&edit.handles, &edit.targets)];
    Ok(judge_on(rules, &geometry, &edit.mesh, &edit.topology, result, &steps, reference))
}

/// [`judge`] for a caller that judges many results on one rest mesh (the harness), as
/// [`evaluate_on`]: `steps` are the edit's steps (handle set and targets; the last is measured,
/// all of them bound how far a handle moved), `reference` the result judged beside.
pub fn judge_on(
    rules: &VerdictRules,
    rest: &RestGeometry,
    mesh: &TriMesh,
    topology: &Topology,
    result: &[[f64; 3]],
    steps: &[(&HandleSet, &HandleTargets)],
    reference: Reference<'_>,
) -> Judgement {
    let last = *steps.last().expect("an edit has at least one step");
    let positions = match reference {
        // The reference's distances and turn to itself are 0.
        Reference::Itself => Some(result),
        Reference::Of { positions, .. } => Some(positions),
        Reference::Missing => None,
    };
    let quality = evaluate_on(rest, mesh, topology, result, last, positions);
    let motion = Motion::of(rest, mesh, result, steps, reference);
    let reasons = rules.reasons(&quality, motion);
    Judgement { quality, motion, reasons }
}

/// `fixed` and the `handles` as a handle set on `rest.len()` vertices (`fixed` first, as the
/// region `fixed`; the others `handle 1`, `handle 2`, ...) and their targets (`fixed` at rest).
fn edit<H: AsRef<[usize]>, T: AsRef<[[f64; 3]]>>(
    rest: &[[f64; 3]],
    fixed: &[usize],
    handles: &[H],
    targets: &[T],
) -> Result<(HandleSet, HandleTargets), MeasuresError> {
    check_size("targets (lists, one per handle)", targets.len(), handles.len())?;
    let mut regions = Vec::with_capacity(handles.len() + 1);
    let mut positions = Vec::new();
    for (h, (region, aims)) in handles.iter().zip(targets).enumerate() {
        let (region, aims) = (region.as_ref(), aims.as_ref());
        let name = format!("handle {}", h + 1);
        check_size(&format!("targets of `{name}`"), aims.len(), region.len())?;
        let vertices = region.iter().map(|&v| index(v, || name.clone())).collect::<Result<_, _>>()?;
        regions.push(HandleRegion { name, vertices });
        positions.extend_from_slice(aims);
    }
    if !fixed.is_empty() {
        let vertices = fixed.iter().map(|&v| index(v, || "fixed".into())).collect::<Result<_, _>>()?;
        regions.insert(0, HandleRegion { name: "fixed".into(), vertices });
    }
    let handles = HandleSet::new(regions, rest.len())?;
    let held = fixed.iter().map(|&v| rest[v]);
    let targets = HandleTargets::new(&handles, held.chain(positions).collect())?;
    Ok((handles, targets))
}

/// `i` as a `u32` vertex index (`whose` it is names it in the error).
fn index(i: usize, whose: impl FnOnce() -> String) -> Result<u32, MeasuresError> {
    u32::try_from(i).map_err(|_| MeasuresError::Size(format!("{}: vertex {i} is beyond 32 bits", whose())))
}

/// Fails unless the array `what` has `expected` rows.
fn check_size(what: &str, rows: usize, expected: usize) -> Result<(), MeasuresError> {
    if rows == expected {
        Ok(())
    } else {
        Err(MeasuresError::Size(format!("{what}: {rows} rows, expected {expected}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rest::tests::shape;
    use meshes::shapes::ShapeKind;
    use meshes::AffineTransform;

    /// Every metric of the shape `kind` moved by `f`, through [`evaluate`] (handles: 30 vertices
    /// spread over the mesh, not on one line, at their moved positions; reference: the moved shape
    /// itself).
    fn quality_after(kind: ShapeKind, f: impl Fn([f64; 3]) -> [f64; 3]) -> Quality {
        let (mesh, _, _) = shape(kind);
        let moved: Vec<[f64; 3]> = mesh.positions().iter().map(|&p| f(p)).collect();
        let faces: Vec<[usize; 3]> = mesh.triangles().iter().map(|t| t.map(|v| v as usize)).collect();
        let region: Vec<usize> = (0..mesh.n_vertices()).step_by(mesh.n_vertices() / 30 + 1).collect();
        let aims: Vec<[f64; 3]> = region.iter().map(|&v| moved[v]).collect();
        evaluate(mesh.positions(), &faces, &moved, &[], &[region], &[aims], Some(&moved)).unwrap()
    }

    #[test]
    fn every_measure_is_zero_for_a_rigid_motion() {
        let rigid = AffineTransform::rotation_about([1.0, -2.0, 0.5], 2.3, [0.3, 0.1, 7.0])
            .compose(&AffineTransform::translation([10.0, -4.0, 3.0]));
        for kind in [ShapeKind::Bar, ShapeKind::Cylinder, ShapeKind::Cactus, ShapeKind::BumpyPlane] {
            let q = quality_after(kind, |x| rigid.apply(x));
            for m in Metric::ALL {
                let v = q.get(m);
                if m == Metric::VolumeChange && v.is_none() {
                    continue;
                }
                let v = v.unwrap_or_else(|| panic!("{kind:?} {m}: no value"));
                assert!(v.abs() < 1e-9, "{kind:?} rigid: {m} = {v}");
            }
        }
    }

    #[test]
    fn uniform_scaling_gives_the_closed_forms() {
        for s in [0.5, 1.7, 3.0] {
            for kind in [ShapeKind::Bar, ShapeKind::Cylinder, ShapeKind::Cactus] {
                let q = quality_after(kind, |x| [s * x[0] + 1.0, s * x[1] - 2.0, s * x[2]]);
                let close = |m: Metric, expected: f64| {
                    let v = q.value(m);
                    assert!((v - expected).abs() < 1e-9, "{kind:?} s = {s}: {m} = {v}, expected {expected}");
                };
                close(Metric::ETheta, 0.0);
                close(Metric::EPhi, 0.0);
                close(Metric::Folds, 0.0);
                close(Metric::EArea, (2.0 * s.ln()).abs());
                close(Metric::ELength, s.ln().abs());
                close(Metric::AreaChange, s * s - 1.0);
                // Only closed look-alikes have a volume.
                let (_, topology, _) = shape(kind);
                if topology.is_closed() {
                    close(Metric::VolumeChange, s.powi(3) - 1.0);
                } else {
                    assert_eq!(q.get(Metric::VolumeChange), None, "{kind:?} is open");
                }
            }
        }
    }

    #[test]
    fn a_closed_look_alike_has_a_volume() {
        let closed = [ShapeKind::Bar, ShapeKind::Cylinder, ShapeKind::Cactus]
            .into_iter()
            .filter(|k| shape(*k).1.is_closed())
            .count();
        assert!(closed > 0, "the closed-form volume test needs a closed shape");
    }

    #[test]
    fn non_uniform_scaling_and_bending_are_measured() {
        let q = quality_after(ShapeKind::Bar, |x| [2.0 * x[0], x[1], x[2]]);
        let (t, p) = (q.value(Metric::ETheta), q.value(Metric::EPhi));
        assert!(t > 1.0 && p < 1e-9, "stretching a box changes corner angles, not its flat faces: {t}, {p}");
        assert!(q.value(Metric::EArea) > 0.1 && q.value(Metric::ELength) > 0.1);
        // Bending the plane about the y axis changes dihedral angles, and near-isometrically keeps
        // corners, areas and lengths.
        let q = quality_after(ShapeKind::BumpyPlane, |x| {
            let r = 200.0;
            let a = x[0] / r;
            [(r + x[2]) * a.sin(), x[1], (r + x[2]) * a.cos()]
        });
        let (t, p) = (q.value(Metric::ETheta), q.value(Metric::EPhi));
        assert!(p > 0.05 && t < p * 10.0, "bend: E_theta {t}, E_phi {p}");
        assert!(q.value(Metric::EArea) < 0.05 && q.value(Metric::Folds) == 0.0);
    }

    /// The arrays entry gives the bits of the harness's path ([`evaluate_on`] on a validated handle
    /// set, `fixed` as its first region), and names the arrays that do not fit.
    #[test]
    fn the_arrays_entry_is_the_harness_path_and_checks_its_inputs() {
        let (mesh, topology, rest) = shape(ShapeKind::Cylinder);
        let p = mesh.positions();
        let moved: Vec<[f64; 3]> = p.iter().map(|x| [x[0] + 0.1 * x[2] * x[2], x[1], 1.1 * x[2]]).collect();
        let faces: Vec<[usize; 3]> = mesh.triangles().iter().map(|t| t.map(|v| v as usize)).collect();
        let (lo, hi) = mesh.bbox();
        let below = |h: f64| (0..p.len()).filter(move |&v| p[v][2] < lo[2] + h * (hi[2] - lo[2]));
        let fixed: Vec<usize> = below(0.1).collect();
        let top: Vec<usize> = (0..p.len()).filter(|&v| p[v][2] > lo[2] + 0.9 * (hi[2] - lo[2])).collect();
        let aims: Vec<[f64; 3]> = top.iter().map(|&v| moved[v]).collect();
        let ours = evaluate(p, &faces, &moved, &fixed, &[&top[..]], &[&aims[..]], Some(p)).unwrap();
        let region = |name: &str, vertices: &[usize]| HandleRegion {
            name: name.into(),
            vertices: vertices.iter().map(|&v| v as u32).collect(),
        };
        let handles = HandleSet::new(vec![region("base", &fixed), region("top", &top)], p.len()).unwrap();
        let targets =
            HandleTargets::new(&handles, fixed.iter().map(|&v| p[v]).chain(aims.clone()).collect()).unwrap();
        let theirs = evaluate_on(&rest, &mesh, &topology, &moved, (&handles, &targets), Some(p));
        for m in Metric::ALL {
            assert_eq!(ours.get(m).map(f64::to_bits), theirs.get(m).map(f64::to_bits), "{m}");
        }
        let error = |r: Result<Quality, MeasuresError>| r.unwrap_err().to_string();
        let short = &moved[1..];
        assert!(error(evaluate(p, &faces, short, &fixed, &[&top[..]], &[&aims[..]], None))
            .starts_with("result: "));
        let e = error(evaluate(p, &faces, &moved, &fixed, &[&top[..]], &[&aims[1..]], None));
        assert!(e.starts_with("targets of `handle 1`: "), "{e}");
        let e = error(evaluate(p, &faces, &moved, &top, &[&top[..]], &[&aims[..]], None));
        assert!(e.contains("is in both handle `fixed` and handle `handle 1`"), "{e}");
        let e = error(evaluate(p, &[[0, 1, p.len()]], &moved, &fixed, &[&top[..]], &[&aims[..]], None));
        assert!(e.starts_with("face 0: vertex index ") && e.contains("out of range"), "{e}");
    }
}
