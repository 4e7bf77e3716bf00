//! The frictions a newcomer hit (issue 60), through the `harness` binary: what `run` takes from a
//! scenario, what the errors name, `.dmat` selections of both kinds, what a run says about the
//! meshes it skipped or repaired, the console tables, and a report directory that cannot be written.

use std::path::Path;
use std::process::Command;

/// Run the binary with `args`: exit code, stdout, stderr.
fn harness(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_harness")).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A small procedural bar scenario named `name`, with `extra` lines (e.g. `methods = [...]`).
fn bar_scenario(dir: &Path, name: &str, extra: &str) -> String {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(
        &path,
        format!("name = \"{name}\"\nprocedural = {{ shape = \"bar\", vertices = 500 }}\n{extra}"),
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

/// `(scenario, method)` of every row of `results.csv` in `reports`.
fn cases(reports: &Path) -> Vec<(String, String)> {
    let mut reader = csv::Reader::from_path(reports.join("results.csv")).unwrap();
    let headers = reader.headers().unwrap().clone();
    let column = |name: &str| headers.iter().position(|h| h == name).unwrap();
    let (s, m) = (column("scenario"), column("method"));
    reader.records().map(|r| r.unwrap()).map(|r| (r[s].to_string(), r[m].to_string())).collect()
}

#[test]
fn run_without_method_runs_each_scenarios_own_list() {
    let dir = tempfile::tempdir().unwrap();
    let first = bar_scenario(dir.path(), "first", "methods = [\"arap\", \"laplacian\"]\n");
    let second = bar_scenario(dir.path(), "second", "methods = [\"laplacian\"]\n");
    let reports = dir.path().join("reports");
    let reports = reports.to_str().unwrap();
    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &first, "--scenario", &second, "--reports", reports]);
    assert_eq!(code, 0, "{out}{err}");
    let pair = |s: &str, m: &str| (s.to_string(), m.to_string());
    assert_eq!(
        cases(Path::new(reports)),
        [pair("first", "laplacian"), pair("first", "arap"), pair("second", "laplacian")]
    );

    // A scenario without `methods` and no --method: an error naming it and what to give.
    let bare = bar_scenario(dir.path(), "bare", "");
    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &first, "--scenario", &bare, "--reports", reports]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("`bare`") && err.contains("bare.toml") && err.contains("--method"), "{err}");
    assert!(!err.contains("`first`"), "only the scenario without a list is named: {err}");
}
