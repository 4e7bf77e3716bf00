//! Time `spectral::smallest_eigenpairs` on a mesh: `eigen_timing MESH K [MASS]` (MESH a file or
//! `procedural:SHAPE:VERTICES`), MASS `barycentric`
//! (default, Rong et al. eq 6) or `voronoi`. Prints one JSON line; `scripts/bench-eigs-vs-scipy` runs
//! it next to scipy's eigsh.

use std::time::Instant;

use methods::operators::{cotan_laplacian, lumped_mass, MassKind};
use methods::spectral::{smallest_eigenpairs, EigenOptions};

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
    let start = Instant::now();
    let mut options = EigenOptions::new(k);
    if let Ok(b) = std::env::var("EIG_BLOCK") {
        options.block_size = b.parse()?;
    }
    if let Ok(s) = std::env::var("EIG_BASIS") {
        options.basis_size = Some(s.parse()?);
    }
    let pairs = smallest_eigenpairs(stiffness.as_ref(), &mass, &options)?;
    let seconds = start.elapsed().as_secs_f64();
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
