//! Where a solve that does not converge is still moving: run one method on one scenario file for a
//! number of iterations and list the vertices whose last step was largest, with where they are
//! (bounding-box coordinates), how far they are from rest, and the shape of their one-ring.
//!
//! ```sh
//! DEFORM_REAL_MESHES_DIR=../shared/real-meshes cargo run --release -p harness --example unsettled_vertices -- \
//!     configs/real-meshes/armadillo.toml laplacian 2000 [anderson|none]
//! ```
//!
//! Issue 24 used it to find that `laplacian` on the armadillo keeps swinging the free left arm
//! (~34K vertices still moving, the hand 0.28 diagonals from rest), not a few bad triangles.

use std::ops::ControlFlow;
use std::path::Path;

use anyhow::{bail, Context, Result};
use harness::scenario::{load_spec, DataSource};
use meshes::vector::{norm, sub};
use methods::{IterationObserver, IterationReport};

/// Keeps the shapes of the last two iterations and prints the step every 100.
struct LastTwo {
    cap: usize,
    previous: Option<Vec<[f64; 3]>>,
    last: Option<Vec<[f64; 3]>>,
}

impl IterationObserver for LastTwo {
    fn on_iteration(
        &mut self,
        r: &IterationReport,
        shape: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> ControlFlow<()> {
        if let (true, Some(shape)) = (r.iteration + 2 >= self.cap, shape) {
            self.previous = self.last.take();
            self.last = Some(shape());
        }
        if r.iteration % 100 == 0 {
            eprintln!("iteration {:>6}  step {:.3e}", r.iteration, r.step);
        }
        ControlFlow::Continue(())
    }
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        bail!("usage: unsettled_vertices SCENARIO.toml METHOD ITERATIONS [anderson|none]");
    }
    let spec = load_spec(Path::new(&args[1]))?;
    let method = args[2].as_str();
    let cap: usize = args[3].parse().context("ITERATIONS is a whole number")?;
    let scenario = spec.load(&DataSource::Procedural)?.scenarios.remove(0);
    let configs = harness::paths::project_root()?.join("configs/methods.toml");
    let config: toml::Table = std::fs::read_to_string(&configs)?.parse()?;
    let mut params = config.get(method).and_then(toml::Value::as_table).cloned().unwrap_or_default();
    params.insert("max_iterations".into(), (cap as i64).into());
    if let Some(acceleration) = args.get(4) {
        params.insert("acceleration".into(), acceleration.clone().into());
    }
    let mut m = methods::registry::create(method, &params)?;
    m.precompute(&scenario.mesh)?;
    let step = &scenario.steps[0];
    let targets = step.targets(&m.positions())?;
    m.bind_handles(&step.handles)?;
    let mut observer = LastTwo { cap, previous: None, last: None };
    let summary = m.solve(&targets, &mut observer)?;
    println!("{summary:?}");
    let (Some(before), Some(after)) = (observer.previous, observer.last) else {
        bail!("fewer than two iterations: nothing to compare");
    };
    let (rest, diagonal) = (scenario.mesh.positions(), scenario.mesh.bbox_diagonal());
    let (lo, hi) = scenario.mesh.bbox();
    let mut steps: Vec<(f64, usize)> =
        before.iter().zip(&after).enumerate().map(|(i, (p, q))| (norm(sub(*p, *q)) / diagonal, i)).collect();
    steps.sort_by(|a, b| b.0.total_cmp(&a.0));
    for &(s, v) in steps.iter().take(15) {
        let at: Vec<String> =
            (0..3).map(|k| format!("{:.2}", (rest[v][k] - lo[k]) / (hi[k] - lo[k]))).collect();
        let ring = scenario.topology.one_ring(v);
        let shortest =
            ring.iter().map(|&j| norm(sub(rest[j as usize], rest[v]))).fold(f64::INFINITY, f64::min);
        println!(
            "vertex {v:>6}  step {s:.2e}  at ({})  valence {}  shortest edge {:.1e}  from rest {:.3}",
            at.join(", "),
            ring.len(),
            shortest / diagonal,
            norm(sub(after[v], rest[v])) / diagonal,
        );
    }
    let moving = steps.iter().filter(|(s, _)| *s > 1e-5).count();
    println!("{moving} of {} vertices stepped more than 1e-5 diagonals", rest.len());
    Ok(())
}
