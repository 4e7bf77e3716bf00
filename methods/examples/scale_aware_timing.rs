//! `scale_aware_timing MESH.off`: the parts of one outer iteration of `scale_aware` on the rest
//! shape — step one (20 local/global normal iterations) and step two (assembly, numeric
//! refactorization of the 3#V x 3#V system, back-substitution) — repeated 10 times.
use faer::Mat;
use methods::scale_aware::{
    NormalPyramids, RecoveryTimings, ScaleAwareEquations, ScaleInvariantMeasures, VertexRecovery,
};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let mesh = meshes::io::read_mesh(&args[1])?;
    let topology = meshes::Topology::new(&mesh)?;
    let (p, t) = (mesh.positions(), mesh.triangles());
    let n = mesh.n_vertices();
    let measures = ScaleInvariantMeasures::new(p, t, &topology);
    let pyramids = NormalPyramids::new(p, t, &measures.normals, Default::default());
    let mut normals = measures.normals.clone();
    let equations = ScaleAwareEquations::new(n, t, measures);
    // The first 10 vertices constrained: enough to make the system definite.
    let diagonal: Vec<f64> = (0..3 * n).map(|i| if i < 30 { 100.0 } else { 0.0 }).collect();
    let s = Instant::now();
    let mut recovery = VertexRecovery::new(&equations)?;
    println!("symbolic analysis {:.1} ms", s.elapsed().as_secs_f64() * 1e3);
    let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (mut rotations, mut frames) = (vec![id; n], vec![id; n]);
    let mut rhs = Mat::<f64>::zeros(3 * n, 1);
    for _ in 0..10 {
        let s = Instant::now();
        pyramids.update_normals(&mut normals, &mut rotations, &mut frames, 20, 0.0);
        let step_one = s.elapsed().as_secs_f64() * 1e3;
        let mut timings = RecoveryTimings::default();
        recovery.solve(&equations, &normals, &diagonal, &mut rhs, &mut timings)?;
        println!(
            "step one (20 it) {step_one:.2} ms, assemble {:.2} ms, factorize {:.2} ms, solve {:.2} ms",
            timings.assembly_s * 1e3,
            timings.refactorization_s * 1e3,
            timings.back_substitution_s * 1e3
        );
    }
    Ok(())
}
