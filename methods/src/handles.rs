//! Handle sets and their targets. A handle is a region of vertices moved as a unit; the survey's fixed
//! region is a handle whose target is its rest position.

use crate::error::MethodError;

/// One handle: a named, non-empty set of distinct vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct HandleRegion {
    pub name: String,
    pub vertices: Vec<u32>,
}

/// A validated set of disjoint handle regions on a mesh of `n_vertices` vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct HandleSet {
    regions: Vec<HandleRegion>,
    n_vertices: usize,
    region_of: Vec<u32>,
}

/// `region_of` value of a vertex in no handle.
pub const FREE: u32 = u32::MAX;

impl HandleSet {
    /// Validate `regions` on a mesh with `n_vertices` vertices: at least one region, every region
    /// non-empty, indices in range, no vertex listed twice (within or across regions).
    pub fn new(regions: Vec<HandleRegion>, n_vertices: usize) -> Result<Self, MethodError> {
        if regions.is_empty() {
            return Err(MethodError::Handles("no handle regions".into()));
        }
        let mut region_of = vec![FREE; n_vertices];
        for (r, region) in regions.iter().enumerate() {
            if region.vertices.is_empty() {
                return Err(MethodError::Handles(format!("handle `{}` has no vertices", region.name)));
            }
            for &v in &region.vertices {
                let Some(slot) = region_of.get_mut(v as usize) else {
                    return Err(MethodError::Handles(format!(
                        "handle `{}`: vertex {v} is out of range (the mesh has {n_vertices} vertices)",
                        region.name
                    )));
                };
                if *slot != FREE {
                    let other = &regions[*slot as usize].name;
                    return Err(MethodError::Handles(if *slot as usize == r {
                        format!("handle `{}` lists vertex {v} twice", region.name)
                    } else {
                        format!("vertex {v} is in both handle `{other}` and handle `{}`", region.name)
                    }));
                }
                *slot = r as u32;
            }
        }
        Ok(Self { regions, n_vertices, region_of })
    }

    /// The regions, in order.
    pub fn regions(&self) -> &[HandleRegion] {
        &self.regions
    }

    /// Vertex count of the mesh this set was validated for.
    pub fn n_vertices(&self) -> usize {
        self.n_vertices
    }

    /// Fails unless this set was validated for a mesh of `n_vertices` vertices.
    pub fn check_mesh_size(&self, n_vertices: usize) -> Result<(), MethodError> {
        if self.n_vertices == n_vertices {
            return Ok(());
        }
        Err(MethodError::Handles(format!(
            "handle set is for {} vertices, the mesh has {n_vertices}",
            self.n_vertices
        )))
    }

    /// `#V` region index per vertex, [`FREE`] for unconstrained vertices.
    pub fn region_of(&self) -> &[u32] {
        &self.region_of
    }

    /// All constrained vertices, region by region: the order of [`HandleTargets`].
    pub fn constrained(&self) -> impl Iterator<Item = u32> + '_ {
        self.regions.iter().flat_map(|r| r.vertices.iter().copied())
    }

    /// Number of constrained vertices.
    pub fn n_constrained(&self) -> usize {
        self.regions.iter().map(|r| r.vertices.len()).sum()
    }
}

/// Target positions of the constrained vertices, in [`HandleSet::constrained`] order.
#[derive(Clone, Debug, PartialEq)]
pub struct HandleTargets {
    positions: Vec<[f64; 3]>,
    /// The constrained vertices of the handle set they were made for, in the same order: a method
    /// checks them against the set it has bound ([`HandleTargets::check_for`]).
    vertices: Vec<u32>,
}

impl HandleTargets {
    /// Check `positions` against `handles`: one finite target per constrained vertex.
    pub fn new(handles: &HandleSet, positions: Vec<[f64; 3]>) -> Result<Self, MethodError> {
        if positions.len() != handles.n_constrained() {
            return Err(MethodError::Targets(format!(
                "{} targets for {} constrained vertices",
                positions.len(),
                handles.n_constrained()
            )));
        }
        for (p, v) in positions.iter().zip(handles.constrained()) {
            if p.iter().any(|c| !c.is_finite()) {
                return Err(MethodError::Targets(format!("target of vertex {v} is not finite: {p:?}")));
            }
        }
        Ok(Self { positions, vertices: handles.constrained().collect() })
    }

    /// Targets in [`HandleSet::constrained`] order.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }

    /// Fails with [`MethodError::Targets`] unless these targets were made for the constrained
    /// vertices of `handles` (the set a method has bound), in its order: targets of another set
    /// would move the wrong vertices, or index past the constrained ones.
    pub fn check_for(&self, handles: &HandleSet) -> Result<(), MethodError> {
        if self.vertices.len() != handles.n_constrained() {
            return Err(MethodError::Targets(format!(
                "{} targets for the bound handle set's {} constrained vertices",
                self.vertices.len(),
                handles.n_constrained()
            )));
        }
        let mut pairs = self.vertices.iter().copied().zip(handles.constrained()).enumerate();
        match pairs.find(|(_, (made_for, bound))| made_for != bound) {
            None => Ok(()),
            Some((k, (made_for, bound))) => Err(MethodError::Targets(format!(
                "targets were made for another handle set: target {k} is for vertex {made_for}, the \
                 bound set's constrained vertex {k} is {bound}"
            ))),
        }
    }
}
