//! Time `spectral::smallest_eigenpairs` on a mesh: `eigen_timing MESH K [MASS]` (MESH a file or
//! `procedural:SHAPE:VERTICES`), MASS `barycentric`
//! (default, Rong et al. eq 6) or `voronoi`. Prints one JSON line; `scripts/bench-eigs-vs-scipy` runs
//! it next to scipy's eigsh.

use std::time::Instant;

use methods::linalg::spectral::{smallest_eigenpairs, EigenOptions};
use methods::operators::{cotan_laplacian, lumped_mass, MassKind};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, mesh_path, k, rest @ ..] = args.as_slice() else {
        return Err("usage: eigen_timing MESH K [barycentric|voronoi]".into());
    };
    let kind = match rest.first().map(String::as_str) {
        None | Some("barycentric") => MassKind::Barycentric,
        Some("voronoi") => MassKind::Voronoi,
        Some(other) => return Err(format!("unknown mass kind {other}").into()),
    };
    // `procedural:SHAPE:VERTICES` generates a look-alike instead of reading a file.
    let mesh = match mesh_path.strip_prefix("procedural:").and_then(|s| s.split_once(':')) {
        Some((shape, vertices)) => meshes::shapes::generate(shape.parse()?, vertices.parse()?)?.mesh,
        None => meshes::io::read_mesh(mesh_path)?,
    };
    let k: usize = k.parse()?;
    let mut stiffness = cotan_laplacian(mesh.positions(), mesh.triangles());
    stiffness.val_mut().iter_mut().for_each(|v| *v = -*v);
    let mass = lumped_mass(mesh.positions(), mesh.triangles(), kind);
    let mut options = EigenOptions::new(k);
    if let Ok(b) = std::env::var("EIG_BLOCK") {
        options.block_size = b.parse()?;
    }
    if let Ok(s) = std::env::var("EIG_BASIS") {
        options.basis_size = Some(s.parse()?);
    }
    // `EIG_REPEAT=N`: solve N times in this process and report the fastest (page faults and thread
    // start-up of the first call excluded, as in a benchmark loop).
    let repeat: usize = std::env::var("EIG_REPEAT").map_or(Ok(1), |r| r.parse())?;
    // Start the thread pool before timing, as Python starts OpenBLAS's threads at import, before
    // scipy's eigsh is timed.
    rayon::broadcast(|_| ());
    let mut seconds = f64::INFINITY;
    let mut pairs = None;
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        pairs = Some(smallest_eigenpairs(stiffness.as_ref(), &mass, &options)?);
        seconds = seconds.min(start.elapsed().as_secs_f64());
    }
    let pairs = pairs.expect("at least one run");
    println!(
        "{{\"mesh\": \"{mesh_path}\", \"vertices\": {}, \"k\": {k}, \"seconds\": {seconds:.4}, \"restarts\": {}, \"operator_applications\": {}, \"lambda_1\": {:.6e}, \"lambda_k\": {:.6e}, \"constant_mode\": {}}}",
        mesh.n_vertices(),
        pairs.restarts,
        pairs.operator_applications,
        pairs.values.get(1).copied().unwrap_or(f64::NAN),
        pairs.values[k - 1],
        pairs.constant_mode.map_or("null".to_string(), |i| i.to_string())
    );
    Ok(())
}
