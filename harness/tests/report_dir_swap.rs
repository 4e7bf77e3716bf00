//! Issue 40: a report directory is one run, whatever happens. A run killed (SIGKILL) at random
//! moments, most of them in its publishing, leaves its report directory as the earlier run wrote it
//! or as a whole new run, never files of both; what the directory holds besides a run survives.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Every file under `dir` (relative path -> bytes).
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<PathBuf, Vec<u8>>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                out.insert(path.strip_prefix(root).unwrap().to_path_buf(), std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn write_all(dir: &Path, files: &BTreeMap<PathBuf, Vec<u8>>) {
    for (path, bytes) in files {
        std::fs::create_dir_all(dir.join(path).parent().unwrap()).unwrap();
        std::fs::write(dir.join(path), bytes).unwrap();
    }
}

/// `harness run` of `method` on the procedural cylinder into `reports`.
fn run(method: &str, reports: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_harness"));
    c.args(["run", "--scenario", "cylinder", "--method", method, "--quiet", "--reports"])
        .arg(reports)
        .env_remove("DEFORM_SURVEY_DIR")
        .env_remove("DEFORMBENCH_METHODS")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
    c
}

/// The run stamp of the page ("Made by this run <time>") and of results.json (`started_utc`).
fn stamps(files: &BTreeMap<PathBuf, Vec<u8>>) -> (String, String) {
    let text = |name: &str| String::from_utf8_lossy(&files[Path::new(name)]).into_owned();
    let page = text("index.html");
    let page = page.split("Made by this run ").nth(1).unwrap().split(' ').next().unwrap().to_string();
    let json: serde_json::Value = serde_json::from_str(&text("results.json")).unwrap();
    (page, json["provenance"]["run"]["started_utc"].as_str().unwrap().to_string())
}

#[test]
fn a_run_killed_at_any_moment_leaves_the_old_report_or_the_new_one() {
    let work = tempfile::tempdir().unwrap();
    // The earlier run (laplacian) and, for reference, a whole run of the kind that is killed
    // (isolines): their files tell the two apart (method names, result meshes, measures).
    let earlier = work.path().join("earlier");
    assert!(run("laplacian", &earlier).status().unwrap().success());
    let mut old = files(&earlier);
    old.insert(PathBuf::from("baselines/mine.json"), b"not a run's".to_vec());
    let reference = work.path().join("reference");
    let start = Instant::now();
    assert!(run("isolines", &reference).status().unwrap().success());
    let whole_run = start.elapsed();
    let new = files(&reference);
    for name in files(&earlier).keys().chain(new.keys()) {
        let top = name.components().next().unwrap().as_os_str().to_string_lossy().into_owned();
        assert!(
            harness::staged_dir::RUN_OUTPUTS.contains(&top.as_str()),
            "{top}: a run's output missing from RUN_OUTPUTS (it would be carried into later reports)"
        );
    }

    let reports = work.path().join("reports");
    let (mut kept_old, mut whole_new) = (0, 0);
    // Kill times over 20%..120% of a whole run (most of the publishing is its second half),
    // from a fixed sequence so that every run of the test tries the same moments.
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    for trial in 0..25 {
        let _ = std::fs::remove_dir_all(&reports);
        write_all(&reports, &old);
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        let fraction = 0.2 + (seed >> 11) as f64 / (1u64 << 53) as f64;
        let mut child = run("isolines", &reports).spawn().unwrap();
        std::thread::sleep(whole_run.mul_f64(fraction));
        let _ = child.kill();
        child.wait().unwrap();

        let now = files(&reports);
        assert_eq!(
            now.get(Path::new("baselines/mine.json")),
            old.get(Path::new("baselines/mine.json")),
            "trial {trial}"
        );
        let mut run_files = now.clone();
        run_files.remove(Path::new("baselines/mine.json"));
        if now == old {
            kept_old += 1;
            continue;
        }
        // Otherwise: the whole new run, and nothing of the old.
        assert_eq!(
            run_files.keys().collect::<Vec<_>>(),
            new.keys().collect::<Vec<_>>(),
            "trial {trial} (killed at {:.0}% of a run): neither the old report nor a whole new one",
            100.0 * fraction
        );
        for (name, bytes) in &run_files {
            if old.get(name).is_some_and(|o| o != &new[name]) {
                assert_ne!(Some(bytes), old.get(name), "trial {trial}: {} is the old run's", name.display());
            }
        }
        let (page, json) = stamps(&run_files);
        assert_eq!(page, json, "trial {trial}: the page and results.json are of different runs");
        whole_new += 1;
    }
    println!(
        "25 kills: {kept_old} left the old report, {whole_new} the new one (a whole run: {whole_run:?})"
    );

    // A killed run's staging directory goes with the next run.
    assert!(run("isolines", &reports).status().unwrap().success());
    let left: Vec<String> = std::fs::read_dir(work.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("staging"))
        .collect();
    assert!(left.is_empty(), "staging directories left: {left:?}");
}
