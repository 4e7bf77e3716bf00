//! [`Evaluation`]: everything the measures of one result read, gathered once.

use meshes::{Topology, TriMesh};
use methods::{HandleSet, HandleTargets};

use crate::distortion::ResultAngles;
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
        Self { rest, mesh, topology, result, handles, targets, reference, angles }
    }
}
