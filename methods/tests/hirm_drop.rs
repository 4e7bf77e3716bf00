//! `hirm` leaves no thread behind: dropping it waits for the background precompute that its last
//! solve started (section 4.5), so a benchmark's next case is never timed beside it. A test binary
//! of its own, so no other test's threads come and go while the threads are counted.

mod fixtures;

use methods::hirm::{Hirm, HirmParams};
use methods::{DeformationMethod, NoObserver};

/// Threads of this process (Linux: the entries of `/proc/self/task`); `None` elsewhere.
fn threads() -> Option<usize> {
    Some(std::fs::read_dir("/proc/self/task").ok()?.count())
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
    let before = threads().unwrap();
    let hirm = solved(&bar);
    let during = threads().unwrap();
    drop(hirm);
    let after = threads().unwrap();
    assert!(during > before, "the solve started no background worker ({before} -> {during} threads)");
    assert_eq!(after, before, "a thread outlived the method ({before} before, {after} after the drop)");
}
