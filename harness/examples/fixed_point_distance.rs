//! How far a method's answer is from its own fixed point: run one method on the first step of a
//! scenario with its configured parameters (plus `key=value` overrides), then again from the same
//! start with a tight tolerance, and print iterations, solve seconds and the RMS / max distance
//! between the two answers over the rest diagonal.
//!
//! ```sh
//! DEFORM_SURVEY_DIR=../shared/deformation-survey cargo run --release -p harness \
//!     --example fixed_point_distance -- configs/scenarios/bar.toml arap [key=value ...] \
//!     [--reference key=value ...]
//! ```
//!
//! Values parse as TOML (`tolerance=1e-8`, `acceleration="none"`). Issue 51 measured the default
//! `arap` stop against its 1e-12 fixed point with it.

use std::ops::ControlFlow;
use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use harness::scenario::{load_spec, DataSource};
use meshes::vector::{dot, sub};
use methods::{IterationObserver, IterationReport, NoObserver, SolveSummary};

/// TRACE=file with a cached reference: per iteration, the step and the true max distance to the
/// reference over the diagonal (to study stopping rules offline).
struct Trace {
    reference: Vec<[f64; 3]>,
    diagonal: f64,
    lines: String,
}

impl IterationObserver for Trace {
    fn on_iteration(
        &mut self,
        r: &IterationReport,
        shape: Option<&dyn Fn() -> Vec<[f64; 3]>>,
    ) -> ControlFlow<()> {
        let x = shape.map(|s| s()).unwrap_or_default();
        let max =
            x.iter().zip(&self.reference).map(|(a, b)| dot(sub(*a, *b), sub(*a, *b))).fold(0.0, f64::max);
        self.lines += &format!("{} {:e} {:e}\n", r.iteration, r.step, max.sqrt() / self.diagonal);
        ControlFlow::Continue(())
    }
}

fn parse_override(table: &mut toml::Table, text: &str) -> Result<()> {
    let (key, value) = text.split_once('=').with_context(|| format!("`{text}` is not key=value"))?;
    let value: toml::Table =
        format!("v = {value}").parse().with_context(|| format!("`{value}` is not a TOML value"))?;
    table.insert(key.to_string(), value["v"].clone());
    Ok(())
}

fn read_positions(path: &Path) -> Result<Vec<[f64; 3]>> {
    let text = std::fs::read_to_string(path)?;
    text.lines()
        .map(|l| {
            let v: Vec<f64> = l.split(' ').map(str::parse).collect::<Result<_, _>>()?;
            Ok([v[0], v[1], v[2]])
        })
        .collect()
}

fn solve(
    method: &str,
    params: &toml::Table,
    scenario: &harness::scenario::LoadedScenario,
) -> Result<(Vec<[f64; 3]>, SolveSummary, f64)> {
    let mut m = methods::registry::create(method, params)?;
    m.precompute(&scenario.mesh)?;
    let step = &scenario.steps[0];
    let targets = step.targets(&m.positions())?;
    m.bind_handles(&step.handles)?;
    let start = Instant::now();
    let summary = m.solve(&targets, &mut NoObserver)?;
    Ok((m.positions(), summary, start.elapsed().as_secs_f64()))
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        bail!("usage: fixed_point_distance SCENARIO.toml METHOD [key=value ...] [--reference key=value ...]");
    }
    let spec = load_spec(Path::new(&args[1]))?;
    let source = match std::env::var_os("DEFORM_SURVEY_DIR") {
        Some(dir) if spec.survey.is_some() => DataSource::Survey(dir.into()),
        _ => DataSource::Procedural,
    };
    let scenario = spec.load(&source)?.scenarios.remove(0);
    let method = args[2].as_str();
    let configs = harness::paths::project_root()?.join("configs/methods.toml");
    let config: toml::Table = std::fs::read_to_string(&configs)?.parse()?;
    let base = config.get(method).and_then(toml::Value::as_table).cloned().unwrap_or_default();
    let (mut params, mut reference) = (base.clone(), base);
    reference.insert("tolerance".into(), 1e-12.into());
    reference.insert("max_iterations".into(), 200_000.into());
    let mut into_reference = false;
    for arg in &args[3..] {
        if arg == "--reference" {
            into_reference = true;
        } else if into_reference {
            parse_override(&mut reference, arg)?;
        } else {
            parse_override(&mut params, arg)?;
        }
    }
    if let (Some(trace), Some(cache)) = (std::env::var_os("TRACE"), std::env::var_os("FIXED_POINT_CACHE")) {
        let reference = read_positions(Path::new(&cache))?;
        let mut observer = Trace { reference, diagonal: scenario.mesh.bbox_diagonal(), lines: String::new() };
        let mut m = methods::registry::create(method, &params)?;
        m.precompute(&scenario.mesh)?;
        let step = &scenario.steps[0];
        let targets = step.targets(&m.positions())?;
        m.bind_handles(&step.handles)?;
        m.solve(&targets, &mut observer)?;
        std::fs::write(trace, observer.lines)?;
        return Ok(());
    }
    let (answer, summary, seconds) = solve(method, &params, &scenario)?;
    println!("run:       {} it, {seconds:.3} s, {summary:?}", summary.iterations);
    // FIXED_POINT_CACHE=file: the reference's positions are read from it when it exists, else
    // computed and written there (the 1e-12 reference of the bar takes minutes).
    let cache = std::env::var_os("FIXED_POINT_CACHE").map(std::path::PathBuf::from);
    let fixed: Vec<[f64; 3]> = match &cache {
        Some(path) if path.exists() => {
            println!("reference: read from {}", path.display());
            read_positions(path)?
        }
        _ => {
            let (fixed, rsummary, rseconds) = solve(method, &reference, &scenario)?;
            println!("reference: {} it, {rseconds:.3} s, {rsummary:?}", rsummary.iterations);
            if let Some(path) = &cache {
                let text: String =
                    fixed.iter().map(|p| format!("{:e} {:e} {:e}\n", p[0], p[1], p[2])).collect();
                std::fs::write(path, text)?;
            }
            fixed
        }
    };
    let diagonal = scenario.mesh.bbox_diagonal();
    let squared: Vec<f64> = answer.iter().zip(&fixed).map(|(a, b)| dot(sub(*a, *b), sub(*a, *b))).collect();
    let rms = (squared.iter().sum::<f64>() / squared.len() as f64).sqrt() / diagonal;
    let max = squared.iter().cloned().fold(0.0, f64::max).sqrt() / diagonal;
    println!("distance to the reference over the diagonal: rms {rms:.3e}, max {max:.3e}");
    Ok(())
}
