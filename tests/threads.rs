//! `--threads N` runs the methods (and the reports) on N worker threads: counted from
//! /proc/self/task while a run is under way, as the hirm drop test counts its worker. Its own test
//! binary, so no other test's threads come and go meanwhile.

use std::collections::BTreeSet;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// `(tid, name)` of every thread of this process.
fn live_threads() -> BTreeSet<(u64, String)> {
    std::fs::read_dir("/proc/self/task")
        .unwrap()
        .flatten()
        .filter_map(|e| {
            let tid = e.file_name().to_string_lossy().parse().ok()?;
            let name = std::fs::read_to_string(e.path().join("comm")).ok()?.trim().to_string();
            Some((tid, name))
        })
        .collect()
}

/// The threads that ran beside the test's own during `harness run --threads <threads>` (spectral_mhb
/// and arap on a small bar: faer's Krylov-Schur and arap's parallel local step).
fn threads_during_run(count: &str, jobs: &str) -> BTreeSet<(u64, String)> {
    let before = live_threads();
    let done = Arc::new(AtomicBool::new(false));
    let seen = {
        let done = Arc::clone(&done);
        std::thread::spawn(move || {
            let mut seen = BTreeSet::new();
            while !done.load(Ordering::Relaxed) {
                seen.extend(live_threads());
                std::thread::sleep(std::time::Duration::from_millis(2));
            }
            seen
        })
    };
    let dir = tempfile::tempdir().unwrap();
    let configs = dir.path().join("configs");
    std::fs::create_dir_all(configs.join("scenarios")).unwrap();
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for file in ["methods.toml", "verdicts.toml"] {
        std::fs::copy(root.join("configs").join(file), configs.join(file)).unwrap();
    }
    std::fs::write(
        configs.join("scenarios/bar.toml"),
        "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 3000 }\n",
    )
    .unwrap();
    let reports = dir.path().join("reports");
    let args = [
        "harness",
        "run",
        "--quiet",
        "--threads",
        count,
        "--jobs",
        jobs,
        "--method",
        "spectral_mhb",
        "--method",
        "arap",
        "--scenario",
        "bar",
        "--configs",
        configs.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ];
    let code = harness::cli::run(args).unwrap();
    done.store(true, Ordering::Relaxed);
    assert_eq!(code, std::process::ExitCode::SUCCESS);
    // The run records its threads (and the rest of its provenance) in results.json and on the page.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(reports.join("results.json")).unwrap()).unwrap();
    let record = &json["provenance"];
    assert_eq!(record["run"]["threads"].as_u64(), Some(count.parse().unwrap()));
    assert_eq!(record["run"]["jobs"].as_u64(), Some(jobs.parse().unwrap()));
    assert_eq!(record["run"]["command_line"][1], "run");
    assert!(record["machine"]["logical_cores"].as_u64().unwrap() >= 1);
    assert!(record["build"]["rustc"].as_str().unwrap().starts_with("rustc "));
    let inputs: Vec<String> = record["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .inspect(|i| assert_eq!(i["sha256"].as_str().unwrap().len(), 64))
        .map(|i| i["path"].as_str().unwrap().to_string())
        .collect();
    for file in ["methods.toml", "verdicts.toml", "scenarios/bar.toml"] {
        assert!(inputs.iter().any(|p| p.ends_with(file)), "{file} not in {inputs:?}");
    }
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    assert!(page.contains(&format!("{count} thread(s)")), "the page states the threads");
    let seen = seen.join().unwrap();
    // A new thread shows its parent's name until it names itself: keep each thread id once, named
    // as a worker if it ever was one.
    let before: BTreeSet<u64> = before.iter().map(|(tid, _)| *tid).collect();
    let mut by_tid = std::collections::BTreeMap::new();
    for (tid, name) in seen.into_iter().filter(|(tid, _)| !before.contains(tid)) {
        let entry = by_tid.entry(tid).or_insert_with(|| name.clone());
        if name.starts_with(&harness::threads::WORKER_NAME[..15])
            || name.starts_with(harness::threads::JOB_NAME)
        {
            *entry = name;
        }
    }
    by_tid.into_iter().collect()
}

#[test]
fn threads_n_runs_n_workers_and_nothing_else() {
    // Linux cuts thread names to 15 bytes.
    let worker = &harness::threads::WORKER_NAME[..15];
    for (n, jobs) in [(1usize, 1usize), (2, 1), (1, 2)] {
        let extra = threads_during_run(&n.to_string(), &jobs.to_string());
        let workers = extra.iter().filter(|(_, name)| name.starts_with(worker)).count();
        let job_threads =
            extra.iter().filter(|(_, name)| name.starts_with(harness::threads::JOB_NAME)).count();
        // Each job has a pool of n for its cases, and the reports have one pool of n.
        assert_eq!(workers, jobs * n + n, "--threads {n} --jobs {jobs}: {extra:?}");
        assert_eq!(job_threads, jobs, "--threads {n} --jobs {jobs}: {extra:?}");
        // The sampler is the only other thread (no global rayon pool, no stray worker).
        assert_eq!(extra.len(), workers + job_threads + 1, "--threads {n} --jobs {jobs}: {extra:?}");
    }
}
