//! Where a method's memory goes: `memory_breakdown METHOD MESH [METHODS.toml]` (MESH a file with its
//! `.sel` and `.def` beside it, or `procedural:SHAPE:VERTICES`; METHODS.toml default
//! `configs/methods.toml`, whose `[METHOD]` table gives the parameters) runs precompute, bind and one
//! solve of the shape's edit and prints, per phase, the heap in use at its start and the most in use
//! during it, in MiB.
//!
//! A counting global allocator gives the exact heap in use; a thread samples it every millisecond and
//! the method's own phase timings (`phase_timings`, in the order it reports them) split precompute
//! into its phases. A phase shorter than a few milliseconds may miss its peak; the run's peak is exact.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use methods::{HandleRegion, HandleSet, HandleTargets, NoObserver};

struct Counting;

static IN_USE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = IN_USE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        IN_USE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                let now =
                    IN_USE.fetch_add(new_size - layout.size(), Ordering::Relaxed) + new_size - layout.size();
                PEAK.fetch_max(now, Ordering::Relaxed);
            } else {
                IN_USE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const MIB: f64 = 1024.0 * 1024.0;

/// Samples of the heap in use, `(seconds since start, bytes)`, taken every millisecond.
struct Sampler {
    stop: Arc<AtomicBool>,
    thread: std::thread::JoinHandle<Vec<(f64, usize)>>,
}

impl Sampler {
    fn start(origin: Instant) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || {
            let mut samples = Vec::with_capacity(1 << 22);
            while !flag.load(Ordering::Relaxed) {
                samples.push((origin.elapsed().as_secs_f64(), IN_USE.load(Ordering::Relaxed)));
                std::thread::sleep(Duration::from_millis(1));
            }
            samples
        });
        Self { stop, thread }
    }

    fn finish(self) -> Vec<(f64, usize)> {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().expect("sampler")
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, method, mesh_arg, rest @ ..] = args.as_slice() else {
        return Err("usage: memory_breakdown METHOD MESH|procedural:SHAPE:VERTICES [METHODS.toml]".into());
    };
    let (mesh, selection, transform) =
        match mesh_arg.strip_prefix("procedural:").and_then(|s| s.split_once(':')) {
            Some((shape, vertices)) => {
                let s = meshes::shapes::generate(shape.parse()?, vertices.parse()?)?;
                (s.mesh, s.selection, s.transform)
            }
            None => {
                let mesh = meshes::io::read_mesh(mesh_arg)?;
                let base = std::path::Path::new(mesh_arg);
                let selection = meshes::io::read_selection(base.with_extension("sel"), mesh.n_vertices())?;
                (mesh, selection, meshes::io::read_transform(base.with_extension("def"))?)
            }
        };
    let config = rest.first().map_or("configs/methods.toml", String::as_str);
    let tables: toml::Table = std::fs::read_to_string(config)?.parse()?;
    let params = match tables.get(method.as_str()) {
        Some(toml::Value::Table(t)) => t.clone(),
        _ => toml::Table::new(),
    };

    let fixed = meshes::edit::vertices_with_status(&selection, meshes::VertexStatus::Fixed);
    let handle = meshes::edit::vertices_with_status(&selection, meshes::VertexStatus::Handle);
    let handles = HandleSet::new(
        vec![
            HandleRegion { name: "fixed".into(), vertices: fixed },
            HandleRegion { name: "handle".into(), vertices: handle.clone() },
        ],
        mesh.n_vertices(),
    )?;
    let targets: Vec<[f64; 3]> = handles
        .constrained()
        .map(|v| {
            let p = mesh.positions()[v as usize];
            if handle.contains(&v) {
                transform.apply(p)
            } else {
                p
            }
        })
        .collect();
    let targets = HandleTargets::new(&handles, targets)?;

    let mut instance = methods::registry::create(method, &params)?;
    let origin = Instant::now();
    let sampler = Sampler::start(origin);
    std::thread::sleep(Duration::from_millis(5));
    // The sampler's own buffer is counted from here on: the baseline.
    let before = IN_USE.load(Ordering::Relaxed);
    println!(
        "{method} on {mesh_arg}: {} vertices, {} triangles; in use before the method: {:.0} MiB",
        mesh.n_vertices(),
        mesh.triangles().len(),
        before as f64 / MIB
    );
    PEAK.store(before, Ordering::Relaxed);

    let start = origin.elapsed().as_secs_f64();
    let in_use_at_start = IN_USE.load(Ordering::Relaxed);
    instance.precompute(&mesh)?;
    let precompute_end = origin.elapsed().as_secs_f64();
    let precompute_phases: Vec<(String, f64)> =
        instance.phase_timings().into_iter().filter(|(_, s)| *s > 0.0).collect();
    let precompute_peak = PEAK.load(Ordering::Relaxed);
    let in_use_at_bind = IN_USE.load(Ordering::Relaxed);
    instance.bind_handles(&handles)?;
    let (bind_end, in_use_at_solve) = (origin.elapsed().as_secs_f64(), IN_USE.load(Ordering::Relaxed));
    let summary = instance.solve(&targets, &mut NoObserver)?;
    let end = origin.elapsed().as_secs_f64();
    let held = IN_USE.load(Ordering::Relaxed);
    let samples = sampler.finish();
    let peak = PEAK.load(Ordering::Relaxed);

    let most = |from: f64, to: f64| {
        samples.iter().filter(|(t, _)| (from..=to).contains(t)).map(|s| s.1).max().unwrap_or(0)
    };
    println!("{:<34} {:>9} {:>11} {:>9}", "phase", "seconds", "in use MiB", "most MiB");
    // Precompute's own phases, laid end to end from its start (the untimed glue between them is
    // small against a 1M mesh's phases).
    let mib = |bytes: usize| bytes.saturating_sub(before) as f64 / MIB;
    let mut t = start;
    for (name, seconds) in precompute_phases {
        if t + seconds > precompute_end + 1e-3 {
            break;
        }
        let at = samples.iter().find(|(s, _)| *s >= t).map_or(0, |s| s.1);
        println!(
            "{:<34} {:>9.2} {:>11.0} {:>9.0}",
            format!("precompute: {name}"),
            seconds,
            mib(at),
            mib(most(t, t + seconds))
        );
        t += seconds;
    }
    println!(
        "{:<34} {:>9.2} {:>11.0} {:>9.0}  (exact)",
        "precompute",
        precompute_end - start,
        mib(in_use_at_start),
        mib(precompute_peak)
    );
    println!(
        "{:<34} {:>9.2} {:>11.0} {:>9.0}",
        "bind",
        bind_end - precompute_end,
        mib(in_use_at_bind),
        mib(most(precompute_end, bind_end))
    );
    println!(
        "{:<34} {:>9.2} {:>11.0} {:>9.0}  ({} iterations)",
        "solve",
        end - bind_end,
        mib(in_use_at_solve),
        mib(most(bind_end, end)),
        summary.iterations
    );
    println!(
        "run's peak {:.0} MiB; the method holds {:.0} MiB after the solve (MiB above the {:.0} of the input and this tool)",
        mib(peak),
        mib(held),
        before as f64 / MIB
    );
    Ok(())
}
