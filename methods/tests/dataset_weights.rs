//! Issue 62 part 3's measurement over the real-mesh dataset (`$DEFORM_DATASET_DIR`, its
//! MANIFEST.csv; skipped without it): per mesh, the negative off-diagonal weights of the plain
//! intrinsic Delaunay Laplacian (the old default) and of the tufted one (the new default), and the
//! sign of the ARAP energy (`methods::arap::ArapEnergy`, what the harness records as `arap_energy`)
//! of small random perturbations of the rest shape under both. Meshes are read as the harness reads
//! them (unreferenced vertices dropped) and not repaired: the five meshes with zero-area, repeated,
//! non-manifold or flipped faces are measured as they are.
//!
//! `DEFORM_DATASET_DIR=... cargo test --release -p methods --test dataset_weights -- --ignored --nocapture`

mod support;
use support::noise;

use faer::sparse::SparseColMat;
use methods::arap::ArapEnergy;
use methods::operators::{laplacian, LaplacianWeights};

/// Negative weights, one per edge (`i < j`): all of them, and those below `-1e-12 x` the larger
/// diagonal entry of the two vertices (the local scale: a mesh's largest entry, on a sliver, can be
/// 1e6 x a typical one, and flip-tolerance rounding is ~1e-16 x the local weights).
fn negatives(l: &SparseColMat<usize, f64>) -> (usize, usize) {
    let (s, v) = l.parts();
    let mut diagonal = vec![0.0f64; s.ncols()];
    for (j, d) in diagonal.iter_mut().enumerate() {
        for idx in s.col_range(j) {
            if s.row_idx()[idx] == j {
                *d = v[idx].abs();
            }
        }
    }
    let (mut all, mut large) = (0, 0);
    for j in 0..s.ncols() {
        for idx in s.col_range(j) {
            let i = s.row_idx()[idx];
            if i < j && v[idx] < 0.0 {
                all += 1;
                large += usize::from(v[idx] < -1e-12 * diagonal[i].max(diagonal[j]));
            }
        }
    }
    (all, large)
}

/// Per weight: `(negative weights, of them below -1e-12 x the local diagonal, negative energies of
/// PERTURBATIONS perturbations, least energy)` or the error.
type Row = Result<(usize, usize, usize, f64), String>;

const PERTURBATIONS: usize = 4;

fn measure(mesh: &meshes::TriMesh, weights: LaplacianWeights) -> Row {
    let l = laplacian(weights, mesh.positions(), mesh.triangles()).map_err(|e| e.to_string())?;
    let (all, large) = negatives(&l);
    let energy = ArapEnergy::new(mesh, weights).map_err(|e| e.to_string())?;
    let mut rng = noise(62);
    let scale = mesh.bbox_diagonal();
    let (mut negative, mut least) = (0, f64::INFINITY);
    for k in 0..PERTURBATIONS {
        let amplitude = [1e-3, 1e-2, 3e-2, 1e-1][k % 4];
        let x: Vec<[f64; 3]> = mesh
            .positions()
            .iter()
            .map(|p| std::array::from_fn(|a| p[a] + amplitude * scale * rng()))
            .collect();
        let e = energy.relative_energy(&x);
        negative += usize::from(e.is_nan() || e < 0.0);
        least = least.min(e);
    }
    Ok((all, large, negative, least))
}

fn show(row: &Row) -> String {
    match row {
        Ok((all, large, negative, least)) => {
            format!("{all:>6} {large:>6} {negative:>3}/{PERTURBATIONS} {least:>10.2e}")
        }
        Err(e) => format!("error: {}", e.chars().take(60).collect::<String>()),
    }
}

#[test]
#[ignore = "reads the whole dataset (DEFORM_DATASET_DIR); minutes"]
fn dataset_negative_weights_and_arap_energies() {
    let Some(dir) = std::env::var_os("DEFORM_DATASET_DIR").map(std::path::PathBuf::from) else {
        eprintln!("SKIPPED: DEFORM_DATASET_DIR is not set");
        return;
    };
    let manifest = std::fs::read_to_string(dir.join("MANIFEST.csv")).unwrap();
    let files: Vec<&str> = manifest.lines().skip(1).filter_map(|l| l.split(',').next()).collect();
    println!(
        "{:<22} {:>8} {:>6} | intrinsic_delaunay: neg <-1e-12 E<0 minE | tufted_delaunay: neg <-1e-12 E<0 minE",
        "mesh", "vertices", "bnd"
    );
    let mut totals = [[0usize; 4]; 2];
    for file in files {
        let input = meshes::io::read_mesh(dir.join(file)).unwrap();
        let (mesh, _) = meshes::clean::drop_unreferenced(&input);
        let boundary = meshes::Topology::new(&mesh)
            .map(|t| t.boundary_loops().iter().map(Vec::len).sum::<usize>().to_string())
            .unwrap_or_else(|_| "n/m".into());
        let rows = [LaplacianWeights::IntrinsicDelaunay, LaplacianWeights::TuftedDelaunay]
            .map(|w| measure(&mesh, w));
        for (total, row) in totals.iter_mut().zip(&rows) {
            match row {
                Ok((all, large, negative, _)) => {
                    total[0] += usize::from(*large > 0);
                    total[1] += all;
                    total[2] += usize::from(*negative > 0);
                }
                Err(_) => total[3] += 1,
            }
        }
        println!(
            "{file:<22} {:>8} {boundary:>6} | {} | {}",
            mesh.n_vertices(),
            show(&rows[0]),
            show(&rows[1])
        );
    }
    for (name, t) in ["intrinsic_delaunay", "tufted_delaunay"].iter().zip(&totals) {
        println!(
            "{name}: {} meshes with weights below -1e-12 x the local diagonal, {} negative weights (edges) in all, {} meshes with a negative ARAP energy, {} meshes refused",
            t[0], t[1], t[2], t[3]
        );
    }
    let tufted = &totals[1];
    assert_eq!(
        (tufted[1], tufted[2], tufted[3]),
        (0, 0, 0),
        "tufted: negative weights, energies or refusals"
    );
}
