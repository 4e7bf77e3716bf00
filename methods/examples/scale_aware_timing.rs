//! `scale_aware_timing MESH.off`: the parts of one outer iteration of `scale_aware` on the rest
//! shape — step one (local/global normal iterations) and step two (assembly, numeric
//! refactorization of the 3#V x 3#V system, back-substitution) — repeated 10 times.
use faer::Mat;
use methods::scale_aware::{NormalPyramids, ScaleAwareEquations, ScaleInvariantMeasures};
use methods::sparse_cholesky::SparseCholesky;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let mesh = meshes::io::read_mesh(&args[1])?;
    let topology = meshes::Topology::new(&mesh)?;
    let (p, t) = (mesh.positions(), mesh.triangles());
    let n = mesh.n_vertices();
    let measures = ScaleInvariantMeasures::new(p, t, &topology);
    let pyramids = NormalPyramids::new(p, t, &measures.normals);
    let mut normals = measures.normals.clone();
    let equations = ScaleAwareEquations::new(n, t, measures);
    let mut matrix = equations.normal_matrix_pattern();
    let diagonal: Vec<f64> = (0..3 * n).map(|i| if i < 30 { 100.0 } else { 0.0 }).collect();
    let s = Instant::now();
    let mut cholesky = SparseCholesky::analyze(matrix.as_ref())?;
    println!("analyze {:.1} ms, nnz(A) {}", s.elapsed().as_secs_f64() * 1e3, matrix.val().len());
    let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (mut rotations, mut frames) = (vec![id; n], vec![id; n]);
    let mut rhs = Mat::<f64>::zeros(3 * n, 1);
    for _ in 0..10 {
        let s = Instant::now();
        pyramids.update_normals(&mut normals, &mut rotations, &mut frames, 20, 0.0);
        let t1 = s.elapsed().as_secs_f64() * 1e3;
        let s = Instant::now();
        equations.assemble_normal_matrix(&normals, &diagonal, matrix.val_mut());
        let t2 = s.elapsed().as_secs_f64() * 1e3;
        let s = Instant::now();
        cholesky.factorize(matrix.as_ref())?;
        let t3 = s.elapsed().as_secs_f64() * 1e3;
        let s = Instant::now();
        cholesky.solve_in_place(rhs.as_mut());
        let t4 = s.elapsed().as_secs_f64() * 1e3;
        println!(
            "step one (20 it) {t1:.2} ms, assemble {t2:.2} ms, factorize {t3:.2} ms, solve {t4:.2} ms, factor nnz {}",
            cholesky.factor_nnz()
        );
    }
    Ok(())
}
