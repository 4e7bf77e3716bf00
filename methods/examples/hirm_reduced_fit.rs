//! `[MIN_FIELDS=n] [ISOLINES=n] hirm_reduced_fit REST TARGET`: how near HIRM's reduced space
//! (`X = W R`, eq 4-8, built on the rest mesh REST) comes to a target shape TARGET (same vertices,
//! e.g. the `isolines` result of the same edit): RMS and largest vertex distance of the best
//! least-squares fit, in bounding-box diagonals. Issue 16's diagnosis of where HIRM cannot follow.
use methods::DeformationMethod;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        return Err("usage: hirm_reduced_fit REST TARGET".into());
    }
    let rest = meshes::io::read_mesh(&args[1])?;
    let target = meshes::io::read_mesh(&args[2])?;
    if target.n_vertices() != rest.n_vertices() {
        return Err(format!(
            "{} has {} vertices, {} has {}",
            args[2],
            target.n_vertices(),
            args[1],
            rest.n_vertices()
        )
        .into());
    }
    let env = |k: &str, d: usize| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    let defaults = methods::hirm::HirmParams::default();
    let params = methods::hirm::HirmParams {
        min_fields: env("MIN_FIELDS", defaults.min_fields),
        isolines: env("ISOLINES", defaults.isolines),
        max_fields: env("MIN_FIELDS", defaults.min_fields).max(defaults.max_fields),
        ..defaults
    };
    let mut hirm = methods::hirm::Hirm::new(params)?;
    hirm.precompute(&rest)?;
    let independent = hirm.handle_independent()?.ok_or("no handle-independent model after precompute")?;
    let model = &independent.model;
    let diagonal = rest.bbox_diagonal();
    for (name, shape) in [("rest", &rest), ("target", &target)] {
        let fit =
            model.least_squares_fit(shape.positions()).ok_or("the fit's normal equations are singular")?;
        let fitted = model.positions(fit.as_ref());
        let d: Vec<f64> = fitted
            .iter()
            .zip(shape.positions())
            .map(|(p, q)| meshes::vector::norm(meshes::vector::sub(*p, *q)) / diagonal)
            .collect();
        let rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt();
        let (worst, max) = d.iter().enumerate().fold((0, 0.0), |a, (i, &x)| if x > a.1 { (i, x) } else { a });
        println!(
            "{name}: {} isolines, best fit RMS {rms:.2e}, max {max:.2e} (vertex {worst}) of the diagonal",
            model.n_isolines()
        );
    }
    Ok(())
}
