//! [`Evaluation`]: everything the measures of one result read, gathered once.

use meshes::{Topology, TriMesh};
use methods::{HandleSet, HandleTargets};

use crate::distortion::ResultAngles;
use crate::local::{face_stretches, one_ring_turns};
use crate::rest::RestGeometry;

/// What a measure is computed from: one result on its scenario's rest mesh.
pub struct Evaluation<'a> {
    pub rest: &'a RestGeometry,
    pub mesh: &'a TriMesh,
    pub topology: &'a Topology,
    /// `#V x 3` result positions on the rest connectivity.
    pub result: &'a [[f64; 3]],
    /// The last edit step's handle set and targets.
    pub handles: &'a HandleSet,
    pub targets: &'a HandleTargets,
    /// `#V x 3` result of the reference method (`arap`) on the same scenario, if it has one.
    pub reference: Option<&'a [[f64; 3]]>,
    /// The result's corner and dihedral angles, computed once for every measure that needs them.
    pub angles: ResultAngles,
    /// `#F` stretches of the result's faces ([`face_stretches`]), once for `e_iso` and the shares.
    pub stretches: Vec<Option<[f64; 2]>>,
    /// The same of the reference's faces, where there is a reference other than this result.
    pub reference_stretches: Option<Vec<Option<[f64; 2]>>>,
    /// `#V` turns of the result's one-rings ([`one_ring_turns`], radians), once for both turn
    /// measures.
    pub turns: Vec<f64>,
}

impl<'a> Evaluation<'a> {
    /// The evaluation of the `#V x 3` `result` on `mesh` (with `rest` its rest geometry), whose last
    /// step held `handles` at `targets`, against the `reference` result if there is one.
    pub fn new(
        rest: &'a RestGeometry,
        mesh: &'a TriMesh,
        topology: &'a Topology,
        result: &'a [[f64; 3]],
        (handles, targets): (&'a HandleSet, &'a HandleTargets),
        reference: Option<&'a [[f64; 3]]>,
    ) -> Self {
        let angles = ResultAngles::new(mesh, topology, result);
        let (p, t) = (mesh.positions(), mesh.triangles());
        let stretches = face_stretches(p, result, t);
        // A reference that is this very result (the reference judged itself) is none to compare with.
        let reference_stretches = reference.filter(|r| *r != result).map(|r| face_stretches(p, r, t));
        let turns = one_ring_turns(p, result, topology);
        Self {
            rest,
            mesh,
            topology,
            result,
            handles,
            targets,
            reference,
            angles,
            stretches,
            reference_stretches,
            turns,
        }
    }
}
