//! `[BINDS=N] hirm_bind_timing MESH.off MESH.sel`: HIRM's handle update time `t_h` for the survey
//! handle set (fixed and handle regions), bound N times (default 5) in one process.
use methods::{DeformationMethod, HandleRegion, HandleSet};
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let mesh = meshes::io::read_mesh(&args[1])?;
    let sel = meshes::io::read_selection(&args[2], mesh.n_vertices())?;
    let fixed = meshes::edit::vertices_with_status(&sel, meshes::VertexStatus::Fixed);
    let handle = meshes::edit::vertices_with_status(&sel, meshes::VertexStatus::Handle);
    let handles = HandleSet::new(
        vec![
            HandleRegion { name: "fixed".into(), vertices: fixed },
            HandleRegion { name: "handle".into(), vertices: handle },
        ],
        mesh.n_vertices(),
    )?;
    let mut hirm = methods::hirm::Hirm::new(Default::default())?;
    hirm.precompute(&mesh)?;
    for _ in 0..std::env::var("BINDS").map_or(5, |b| b.parse().unwrap()) {
        let t = std::time::Instant::now();
        hirm.bind_handles(&handles)?;
        let th = hirm
            .phase_timings()
            .into_iter()
            .find(|(k, _)| *k == methods::keys::phase::T_H_HANDLE_UPDATE)
            .unwrap()
            .1;
        println!("bind {:.3} ms, t_h {:.3} ms", t.elapsed().as_secs_f64() * 1e3, th * 1e3);
    }
    Ok(())
}
