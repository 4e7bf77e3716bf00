//! Opt-in repair of a triangle mesh that [`crate::Topology`] or
//! [`TriMesh::check_nondegenerate`] refuses, so that real meshes with the usual defects can be run
//! rather than only refused (a scenario's `repair = true`). In order:
//!
//! 1. faces of zero area (at most `1e-12 x diagonal^2`, the threshold of `check_nondegenerate`)
//!    are dropped;
//! 2. repeated faces (the same three vertices in any order) are dropped, the first kept;
//! 3. on an edge with more than two faces, the faces after the first two (in file order) are
//!    dropped. Decision: dropping, not splitting the edge by duplicating its vertices, because
//!    results are written in the input file's vertex order and a split vertex has no single place
//!    there; the report says how many faces went;
//! 4. orientation is made consistent per connected piece (faces joined by manifold edges), by
//!    flipping the faces that disagree with the piece's majority; a piece that cannot be oriented
//!    (a Moebius band) is left as it is and counted.
//!
//! Vertices are never moved, merged or renumbered (unreferenced ones are dropped later by the loader
//! as for any mesh file). Face numbers in the report are the input's.

use std::collections::HashMap;

use crate::error::Result;
use crate::mesh::TriMesh;

/// What [`repair`] changed, with the input's face numbers.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RepairLog {
    pub zero_area_faces: Vec<u32>,
    pub repeated_faces: Vec<u32>,
    pub nonmanifold_faces: Vec<u32>,
    pub flipped_faces: Vec<u32>,
    /// Pieces whose faces cannot be oriented consistently (left as they were).
    pub nonorientable_pieces: usize,
}

impl RepairLog {
    /// Whether the mesh came out as it went in.
    pub fn is_empty(&self) -> bool {
        *self == RepairLog::default()
    }

    /// One line for people: `4 zero-area faces dropped (e.g. face 4752); 12 faces flipped (...)`,
    /// or `nothing to repair`.
    pub fn summary(&self) -> String {
        let parts: Vec<String> = [
            (&self.zero_area_faces, "zero-area faces dropped"),
            (&self.repeated_faces, "repeated faces dropped"),
            (&self.nonmanifold_faces, "faces beyond the first two on a non-manifold edge dropped"),
            (&self.flipped_faces, "faces flipped to the orientation of their neighbours"),
        ]
        .iter()
        .filter(|(faces, _)| !faces.is_empty())
        .map(|(faces, what)| format!("{} {what} (e.g. face {})", faces.len(), faces[0]))
        .chain((self.nonorientable_pieces > 0).then(|| {
            format!(
                "{} piece(s) cannot be oriented consistently and were left as they were",
                self.nonorientable_pieces
            )
        }))
        .collect();
        if parts.is_empty() {
            "nothing to repair".to_string()
        } else {
            parts.join("; ")
        }
    }
}

/// `mesh` with the repairs of the module doc, and what they changed. Errors: every face dropped.
pub fn repair(mesh: &TriMesh) -> Result<(TriMesh, RepairLog)> {
    let mut log = RepairLog::default();
    let d = mesh.bbox_diagonal();
    let threshold = 1e-12 * d * d;
    let positions = mesh.positions();
    // Input face numbers of the faces kept so far.
    let mut kept: Vec<u32> = Vec::with_capacity(mesh.n_faces());
    let mut seen: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.n_faces());
    for (f, t) in mesh.triangles().iter().enumerate() {
        if !(crate::primitives::triangle_area(positions, t) > threshold) {
            log.zero_area_faces.push(f as u32);
            continue;
        }
        let mut key = *t;
        key.sort_unstable();
        if seen.insert(key, f as u32).is_some() {
            log.repeated_faces.push(f as u32);
            continue;
        }
        kept.push(f as u32);
    }
    let triangles = mesh.triangles();
    let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(3 * kept.len() / 2);
    for &f in &kept {
        let t = triangles[f as usize];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edge_faces.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut dropped = vec![false; mesh.n_faces()];
    let mut extra: Vec<u32> =
        edge_faces.values().filter(|fs| fs.len() > 2).flat_map(|fs| fs[2..].to_vec()).collect();
    extra.sort_unstable();
    extra.dedup();
    for &f in &extra {
        dropped[f as usize] = true;
    }
    log.nonmanifold_faces = extra;
    kept.retain(|&f| !dropped[f as usize]);
    for fs in edge_faces.values_mut() {
        fs.retain(|&f| !dropped[f as usize]);
    }

    let mut out: Vec<[u32; 3]> = kept.iter().map(|&f| triangles[f as usize]).collect();
    let slot: HashMap<u32, usize> = kept.iter().enumerate().map(|(i, &f)| (f, i)).collect();
    // Orientation: BFS over pieces; flip[i] says whether face i must turn to agree with the seed.
    let forward = |t: &[u32; 3], a: u32, b: u32| (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b);
    let mut flip: Vec<Option<bool>> = vec![None; out.len()];
    for seed in 0..out.len() {
        if flip[seed].is_some() {
            continue;
        }
        flip[seed] = Some(false);
        let mut piece = vec![seed];
        let mut queue = vec![seed];
        let mut orientable = true;
        while let Some(i) = queue.pop() {
            let t = out[i];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let Some(faces) = edge_faces.get(&(a.min(b), a.max(b))) else { continue };
                if faces.len() != 2 {
                    continue;
                }
                for &g in faces {
                    let j = slot[&g];
                    if j == i {
                        continue;
                    }
                    // Consistent neighbours walk the shared edge in opposite directions.
                    let same_direction = forward(&out[j], a, b);
                    let wanted = flip[i].expect("set before queued") ^ same_direction;
                    match flip[j] {
                        None => {
                            flip[j] = Some(wanted);
                            piece.push(j);
                            queue.push(j);
                        }
                        Some(have) if have != wanted => orientable = false,
                        Some(_) => {}
                    }
                }
            }
        }
        if !orientable {
            log.nonorientable_pieces += 1;
            piece.iter().for_each(|&i| flip[i] = Some(false));
            continue;
        }
        // Keep the majority's orientation: flip the fewer faces.
        let flipped = piece.iter().filter(|&&i| flip[i] == Some(true)).count();
        if 2 * flipped > piece.len() {
            piece.iter().for_each(|&i| flip[i] = flip[i].map(|f| !f));
        }
    }
    for (i, t) in out.iter_mut().enumerate() {
        if flip[i] == Some(true) {
            t.swap(1, 2);
            log.flipped_faces.push(kept[i]);
        }
    }
    log.flipped_faces.sort_unstable();
    Ok((TriMesh::new(mesh.positions().to_vec(), out)?, log))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Topology;

    /// A 3 x 3 grid of squares (16 vertices, 18 triangles), consistently oriented.
    fn grid() -> TriMesh {
        let mut p = Vec::new();
        for j in 0..4 {
            for i in 0..4 {
                p.push([i as f64, j as f64, 0.0]);
            }
        }
        let mut t = Vec::new();
        for j in 0..3u32 {
            for i in 0..3u32 {
                let v = 4 * j + i;
                t.push([v, v + 1, v + 5]);
                t.push([v, v + 5, v + 4]);
            }
        }
        TriMesh::new(p, t).unwrap()
    }

    #[test]
    fn a_sound_mesh_is_left_as_it_is() {
        let mesh = grid();
        let (out, log) = repair(&mesh).unwrap();
        assert!(log.is_empty(), "{log:?}");
        assert_eq!(out.triangles(), mesh.triangles());
        assert_eq!(log.summary(), "nothing to repair");
    }

    #[test]
    fn every_defect_is_repaired_and_reported_with_the_input_face_numbers() {
        let mesh = grid();
        let mut t = mesh.triangles().to_vec();
        let mut p = mesh.positions().to_vec();
        // Faces 0 and 7 flipped (the majority keeps its orientation), face 18 repeats face 3 turned,
        // face 19 has zero area, faces 20 and 21 are two fins on the edge 5-6 (the first two faces
        // there are the grid's).
        t[0].swap(1, 2);
        t[7].swap(1, 2);
        t.push([t[3][1], t[3][2], t[3][0]]);
        p.push([0.5, 0.0, 0.0]);
        t.push([0, 1, 16]);
        p.push([1.5, 1.0, 1.0]);
        p.push([1.5, 1.0, -1.0]);
        t.push([5, 6, 17]);
        t.push([6, 5, 18]);
        let broken = TriMesh::new(p, t).unwrap();
        assert!(Topology::new(&broken).is_err() && broken.check_nondegenerate().is_err());
        let (out, log) = repair(&broken).unwrap();
        assert_eq!(log.zero_area_faces, [19]);
        assert_eq!(log.repeated_faces, [18]);
        assert_eq!(log.nonmanifold_faces, [20, 21]);
        assert_eq!(log.flipped_faces, [0, 7]);
        assert_eq!(log.nonorientable_pieces, 0);
        assert_eq!(out.triangles(), grid().triangles(), "the grid as it was");
        assert_eq!(out.positions(), broken.positions(), "vertices are never moved or renumbered");
        let summary = log.summary();
        assert!(
            summary.contains("1 zero-area faces dropped (e.g. face 19)")
                && summary.contains("2 faces flipped"),
            "{summary}"
        );
    }

    #[test]
    fn a_moebius_band_is_counted_and_left_as_it_is() {
        // Five quads around a loop joined with a half twist: no consistent orientation exists.
        let n = 5u32;
        let mut p = Vec::new();
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let w = std::f64::consts::PI * i as f64 / n as f64;
            let (c, s) = (a.cos(), a.sin());
            p.push([c * (2.0 + w.cos()), s * (2.0 + w.cos()), w.sin()]);
            p.push([c * (2.0 - w.cos()), s * (2.0 - w.cos()), -w.sin()]);
        }
        let mut t = Vec::new();
        for i in 0..n {
            let (a0, b0) = (2 * i, 2 * i + 1);
            let (a1, b1) = if i + 1 < n { (2 * i + 2, 2 * i + 3) } else { (1, 0) };
            t.push([a0, b0, a1]);
            t.push([b0, b1, a1]);
        }
        let band = TriMesh::new(p, t).unwrap();
        let (out, log) = repair(&band).unwrap();
        assert_eq!(log.nonorientable_pieces, 1);
        assert!(log.flipped_faces.is_empty());
        assert_eq!(out.triangles(), band.triangles());
    }
}
