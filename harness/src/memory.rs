//! Peak resident memory of a case, from Linux's own counters: the process's resident set before the
//! case (`VmRSS`) and its high-water mark after (`VmHWM`), which writing `5` to
//! `/proc/self/clear_refs` resets to the current resident set. The difference is what the method
//! added at its peak: its factorizations, eigenvectors and reduced model, not the meshes the harness
//! already holds. Only meaningful when one case runs at a time (`--jobs 1`: the counter is the
//! process's) and for methods that run in the process (an external method's memory is its own
//! process's). It is a lower bound: pages the allocator kept from earlier cases and reuses are
//! already resident, so a small case often reads 0; the large blocks of a large mesh (factors,
//! eigenvector bases) are mapped afresh and do count. A counting global allocator would be exact,
//! at a cost on every allocation. Anything unreadable gives `None`, never an error.
//!
//! Before a run loads a mesh it estimates the memory a scenario will need ([`estimate`]): the mesh
//! as it will be (after `refine`) times what the harness holds per vertex, plus what its methods
//! add at their peak ([`methods::registry::MethodEntry::bytes_per_vertex`]), and refuses one that
//! needs more than the machine has available ([`available_bytes`], `MemAvailable`) unless
//! `--force` is given: a scenario with `refine = 12` once allocated ~21 GB and was killed by the
//! kernel (issue 60).

use std::path::PathBuf;

/// What the harness itself holds per vertex of a scenario's mesh, bytes: the mesh (positions and
/// about two triangles per vertex, 48 bytes), its topology, the rest geometry of the measures, the
/// refinement's last two levels, every case's result and the report's copies. An estimate from
/// those structures, not a measurement; the methods' figures dominate it.
pub const HARNESS_BYTES_PER_VERTEX: u64 = 1_000;

/// `MemAvailable` of `/proc/meminfo`, bytes: what can be allocated without swapping; `None` where
/// it is not known (then nothing is refused).
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    kib_field(&meminfo, "MemAvailable").map(|k| k * 1024)
}

/// The vertex and face counts of a mesh of `vertices` and `faces` after `levels` levels of
/// subdivision: each maps `#V, #E, #F` to `#V + #E, 2#E + 3#F, 4#F`
/// ([`meshes::subdivision`]), with `#E = 3#F / 2` (a closed mesh; an open one has a few more).
/// In `f64`, so no level count overflows.
pub fn refined_size(vertices: f64, faces: f64, levels: u32) -> (f64, f64) {
    let (mut v, mut e, mut f) = (vertices, 1.5 * faces, faces);
    for _ in 0..levels {
        (v, e, f) = (v + e, 2.0 * e + 3.0 * f, 4.0 * f);
    }
    (v, f)
}

/// A scenario's estimated peak memory.
#[derive(Clone, Debug, PartialEq)]
pub struct MemoryEstimate {
    /// The mesh as the methods will see it.
    pub vertices: f64,
    pub faces: f64,
    /// What the harness holds for it ([`HARNESS_BYTES_PER_VERTEX`]).
    pub mesh_bytes: f64,
    /// The methods counted at once (the largest; with `--jobs J` the J largest) with their bytes
    /// per vertex and bytes.
    pub methods: Vec<(String, u64, f64)>,
    /// The sum: the estimate.
    pub total: f64,
}

/// The peak memory of a scenario whose mesh has `vertices`, run with `methods` (name and bytes per
/// vertex; cases run one at a time, so the largest counts, or the `jobs` largest).
pub fn estimate(vertices: f64, faces: f64, methods: &[(String, u64)], jobs: usize) -> MemoryEstimate {
    let mesh_bytes = vertices * HARNESS_BYTES_PER_VERTEX as f64;
    let mut largest: Vec<&(String, u64)> = methods.iter().collect();
    largest.sort_by(|a, b| b.1.cmp(&a.1));
    let methods: Vec<(String, u64, f64)> = largest
        .into_iter()
        .take(jobs.max(1))
        .map(|(name, per_vertex)| (name.clone(), *per_vertex, vertices * *per_vertex as f64))
        .collect();
    let total = mesh_bytes + methods.iter().map(|m| m.2).sum::<f64>();
    MemoryEstimate { vertices, faces, mesh_bytes, methods, total }
}

/// A scenario refused before its mesh was loaded: its estimate exceeds the available memory.
#[derive(Debug, thiserror::Error)]
#[error(
    "{}: `{key}`: {mesh}: needs an estimated {} ({}), more than the {} of memory available (MemAvailable in \
     /proc/meminfo); nothing was loaded or run. Lower it, or give --force to run anyway",
    file.display(),
    gib(estimate.total),
    breakdown(estimate),
    gib(*available as f64)
)]
pub struct MemoryRefusal {
    /// The scenario file.
    pub file: PathBuf,
    /// The key that asks for the size (`refine = 12`, `procedural.vertices = 5000000`, the mesh file).
    pub key: String,
    /// The mesh it asks for, in words (`cube.off, 8 vertices refined 12 times: 134.2M vertices`).
    pub mesh: String,
    pub estimate: MemoryEstimate,
    /// `MemAvailable`, bytes.
    pub available: u64,
}

impl MemoryRefusal {
    /// The refusal of `estimate` when it exceeds `available` (none when `available` is unknown).
    pub fn check(
        estimate: MemoryEstimate,
        available: Option<u64>,
        file: PathBuf,
        key: String,
        mesh: String,
    ) -> Result<(), MemoryRefusal> {
        match available {
            Some(available) if estimate.total > available as f64 => {
                Err(MemoryRefusal { file, key, mesh, estimate, available })
            }
            _ => Ok(()),
        }
    }
}

/// `bytes` in GiB, one decimal (two below 1 GiB).
fn gib(bytes: f64) -> String {
    let g = bytes / (1u64 << 30) as f64;
    if g < 1.0 {
        format!("{g:.2} GiB")
    } else {
        format!("{g:.1} GiB")
    }
}

/// A count with a unit suffix: `134.2M`, `5.3K`, `812`.
pub fn count(n: f64) -> String {
    match n {
        n if n >= 1e9 => format!("{:.1}G", n / 1e9),
        n if n >= 1e6 => format!("{:.1}M", n / 1e6),
        n if n >= 1e4 => format!("{:.1}K", n / 1e3),
        n => format!("{n:.0}"),
    }
}

/// What the estimate is made of, in words.
fn breakdown(e: &MemoryEstimate) -> String {
    let mut parts = vec![format!(
        "the mesh of {} vertices and {} faces at {HARNESS_BYTES_PER_VERTEX} bytes per vertex: {}",
        count(e.vertices),
        count(e.faces),
        gib(e.mesh_bytes)
    )];
    parts.extend(e.methods.iter().map(|(name, per_vertex, bytes)| {
        format!("`{name}` at {per_vertex} bytes per vertex: {}", gib(*bytes))
    }));
    parts.join("; ")
}

/// A `kB` field of a `/proc` status-like text.
fn kib_field(text: &str, field: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with(field) && l[field.len()..].starts_with(':'))?;
    line[field.len() + 1..].split_whitespace().next()?.parse().ok()
}

/// The resident set now, bytes, with the high-water mark reset to it; `None` where Linux's
/// counters are not there.
pub fn start_peak() -> Option<u64> {
    std::fs::write("/proc/self/clear_refs", "5").ok()?;
    status_kib("VmRSS").map(|k| k * 1024)
}

/// The largest resident set since [`start_peak`] above `start`, MiB.
pub fn peak_since(start: Option<u64>) -> Option<f64> {
    let start = start?;
    let peak = status_kib("VmHWM")? * 1024;
    Some(peak.saturating_sub(start) as f64 / (1024.0 * 1024.0))
}

/// A `kB` field of /proc/self/status.
fn status_kib(field: &str) -> Option<u64> {
    kib_field(&std::fs::read_to_string("/proc/self/status").ok()?, field)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refinement_quadruples_faces_and_adds_an_edge_vertex() {
        // A closed cube of 8 vertices, 18 edges, 12 triangles: one level gives 26 vertices and 48
        // faces (meshes::subdivision), then 98 and 192.
        assert_eq!(refined_size(8.0, 12.0, 0), (8.0, 12.0));
        assert_eq!(refined_size(8.0, 12.0, 1), (26.0, 48.0));
        assert_eq!(refined_size(8.0, 12.0, 2), (98.0, 192.0));
        let (v, f) = refined_size(8.0, 12.0, 12);
        assert_eq!(f, 12.0 * 4f64.powi(12));
        // #V - #E + #F = 2 holds: #V = 2 + #F / 2.
        assert_eq!(v, 2.0 + f / 2.0);
    }

    #[test]
    fn the_estimate_is_the_mesh_plus_the_largest_method_and_refuses_above_the_available() {
        let methods = vec![
            ("arap".to_string(), 3_200),
            ("laplacian".to_string(), 7_600),
            ("isolines".to_string(), 2_000),
        ];
        let (v, f) = refined_size(8.0, 12.0, 12);
        let e = estimate(v, f, &methods, 1);
        assert_eq!(e.methods.len(), 1);
        assert_eq!(e.methods[0].0, "laplacian");
        assert_eq!(e.total, v * (HARNESS_BYTES_PER_VERTEX + 7_600) as f64);
        assert!(e.total > 20.0 * (1u64 << 30) as f64, "refine = 12 of a cube: {} bytes", e.total);
        let two = estimate(v, f, &methods, 2);
        assert_eq!(two.total, v * (HARNESS_BYTES_PER_VERTEX + 7_600 + 3_200) as f64);
        let refusal = MemoryRefusal::check(
            e.clone(),
            Some(16 << 30),
            "s.toml".into(),
            "refine = 12".into(),
            "cube.off refined 12 times".into(),
        )
        .unwrap_err()
        .to_string();
        let expected =
            format!("s.toml: `refine = 12`: cube.off refined 12 times: needs an estimated {}", gib(e.total));
        assert!(refusal.starts_with(&expected), "{refusal}");
        assert_eq!(gib(e.total), "806.3 GiB");
        assert!(refusal.contains("more than the 16.0 GiB of memory available"), "{refusal}");
        assert!(
            refusal.contains("`laplacian` at 7600 bytes per vertex") && refusal.contains("--force"),
            "{refusal}"
        );
        assert!(
            MemoryRefusal::check(e.clone(), None, "s.toml".into(), String::new(), String::new()).is_ok(),
            "unknown: not refused"
        );
        let small = estimate(1000.0, 2000.0, &methods, 1);
        assert!(MemoryRefusal::check(small, Some(16 << 30), "s.toml".into(), String::new(), String::new())
            .is_ok());
    }

    #[test]
    fn mem_available_is_read_on_linux() {
        if std::path::Path::new("/proc/meminfo").exists() {
            let bytes = available_bytes().expect("MemAvailable");
            assert!(bytes > 1 << 20, "{bytes}");
        }
        assert_eq!(kib_field("MemTotal:  100 kB\nMemAvailable:   2048 kB\n", "MemAvailable"), Some(2048));
    }

    #[test]
    fn a_large_allocation_shows_in_the_peak_and_a_reset_forgets_it() {
        let Some(start) = start_peak() else { return };
        let block = vec![1u8; 256 << 20];
        // Touch every page so it is resident.
        let sum: u64 = block.iter().step_by(4096).map(|&b| u64::from(b)).sum();
        assert_eq!(sum, (256 << 20) / 4096);
        drop(block);
        let peak = peak_since(Some(start)).unwrap();
        assert!((250.0..400.0).contains(&peak), "{peak} MiB");
        let again = start_peak();
        let peak = peak_since(again).unwrap();
        assert!(peak < 64.0, "after the reset: {peak} MiB");
    }
}
