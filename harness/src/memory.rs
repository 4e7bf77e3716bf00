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
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field) && l[field.len()..].starts_with(':'))?;
    line[field.len() + 1..].split_whitespace().next()?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

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
