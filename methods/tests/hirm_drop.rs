//! `hirm` leaves no thread behind: dropping it waits for the background precompute that its last
//! solve started (section 4.5), so a benchmark's next case is never timed beside it. A test binary
//! of its own, so no other test's threads come and go while the threads are counted.

mod fixtures;

use std::collections::BTreeSet;

use methods::hirm::{Hirm, HirmParams};
use methods::{DeformationMethod, NoObserver};

/// Thread ids of this process (Linux: the entries of `/proc/self/task`); `None` elsewhere.
fn threads() -> Option<BTreeSet<u64>> {
    let ids = std::fs::read_dir("/proc/self/task").ok()?;
    Some(ids.filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok()).collect())
}

/// Precompute, bind and solve the bar's twist, which starts a background precompute.
fn solved(bar: &fixtures::Bar) -> Hirm {
    let mut hirm = Hirm::new(HirmParams::default()).unwrap();
    hirm.precompute(&bar.mesh).unwrap();
    let handles = bar.handles();
    hirm.bind_handles(&handles).unwrap();
    hirm.solve(&bar.handle_moved_by(&handles, &bar.edit), &mut NoObserver).unwrap();
    hirm
}

#[test]
fn dropping_waits_for_the_background_precompute() {
    let Some(_) = threads() else { return };
    let bar = fixtures::bar(6000);
    // A first run starts whatever pools the solve uses, so they are in the count.
    drop(solved(&bar));
    // By thread id, not by count: a thread of the runtime that ends meanwhile must not hide the
    // worker (counting did, in about half the runs).
    let before = threads().unwrap();
    let hirm = solved(&bar);
    let started: BTreeSet<u64> = threads().unwrap().difference(&before).copied().collect();
    drop(hirm);
    assert!(!started.is_empty(), "the solve started no background worker");
    // A joined thread can stay listed for a moment: join returns when the kernel clears its tid,
    // before the task is reaped. Allow 50 ms for that, far below the worker's own ~220 ms of work
    // on this bar, so a worker left running is still caught.
    let mut outlived: Vec<u64> = Vec::new();
    for _ in 0..10 {
        outlived = started.intersection(&threads().unwrap()).copied().collect();
        if outlived.is_empty() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(outlived.is_empty(), "threads {outlived:?} started by the solve outlived the method");
}
