//! External methods through the whole harness: the README's one-file example runs as written; a
//! broken method beside built-in ones fails alone (built-in rows bitwise equal to a run without it,
//! exit code 1 naming the failed cases, nothing left running); the peers run beside `arap` and land
//! near it, and without their Python the run says so.

mod support;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn run(args: &[&str]) -> anyhow::Result<ExitCode> {
    let mut full = vec!["harness"];
    full.extend_from_slice(args);
    harness::cli::run(full)
}

fn row<'a>(rows: &'a [HashMap<String, String>], method: &str) -> &'a HashMap<String, String> {
    rows.iter().find(|r| r["method"] == method).unwrap_or_else(|| panic!("no row of {method}"))
}

/// A copy of the committed configs (methods, verdicts, peers) in `dir/configs`, its scenarios
/// replaced by `scenarios` (file name, contents), and `extra` appended to methods.toml.
fn configs_in(dir: &Path, scenarios: &[(&str, String)], extra: &str) -> PathBuf {
    let configs = dir.join("configs");
    std::fs::create_dir_all(configs.join("scenarios")).unwrap();
    let root = support::workspace_root();
    for file in ["methods.toml", "verdicts.toml", "peers.toml"] {
        std::fs::copy(root.join("configs").join(file), configs.join(file)).unwrap();
    }
    let methods = std::fs::read_to_string(configs.join("methods.toml")).unwrap();
    std::fs::write(configs.join("methods.toml"), format!("{methods}\n{extra}")).unwrap();
    for (name, text) in scenarios {
        std::fs::write(configs.join("scenarios").join(name), text).unwrap();
    }
    // `working_dir = ".."` of the committed entries is the workspace: give the copy the same layout.
    std::os::unix::fs::symlink(root.join("external"), dir.join("external")).unwrap();
    configs
}

/// The fenced block that follows `marker` in the README.
fn readme_block(marker: &str) -> String {
    let readme = std::fs::read_to_string(support::workspace_root().join("README.md")).unwrap();
    let after = &readme[readme.find(marker).unwrap_or_else(|| panic!("README lacks {marker}"))..];
    let start = after.find("```").unwrap();
    let body = &after[start..];
    let body = &body[body.find('\n').unwrap() + 1..];
    let end = body.find("```").unwrap();
    body[..end].lines().map(str::trim).collect::<Vec<_>>().join("\n")
}

/// The README's recipe as written, from a folder outside the repository: the method's two files
/// copied there (the README's entry block is the committed method file), the README's command run
/// with `--methods` pointing at the copy. No file of the repository is touched.
#[test]
fn the_readme_example_method_runs_as_written() {
    let Some(python) = support::python() else { return };
    // Step 1 of the README exports DEFORMBENCH_PYTHON; scripts/test has done so.
    assert_eq!(std::env::var_os("DEFORMBENCH_PYTHON").map(PathBuf::from), Some(python));
    let dir = tempfile::tempdir().unwrap();
    let root = support::workspace_root();
    let entry = readme_block("<!-- example-method-entry -->");
    let committed =
        std::fs::read_to_string(root.join("external/example/harmonic_displacement.toml")).unwrap();
    assert_eq!(entry.trim(), committed.trim(), "the README shows the committed method file");
    let mine = dir.path().join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::copy(
        root.join("external/example/harmonic_displacement.py"),
        mine.join("harmonic_displacement.py"),
    )
    .unwrap();
    std::fs::write(mine.join("harmonic_displacement.toml"), &entry).unwrap();
    let command = readme_block("<!-- example-method-run -->");
    let args: Vec<String> = command
        .split_once("harness -- ")
        .expect("a harness command")
        .1
        .split_whitespace()
        .map(|a| {
            if a.ends_with("harmonic_displacement.toml") {
                mine.join("harmonic_displacement.toml").to_string_lossy().into_owned()
            } else {
                a.to_string()
            }
        })
        .collect();
    assert!(args.iter().any(|a| a.starts_with(mine.to_str().unwrap())), "the command names the method file");
    let reports = dir.path().join("reports");
    let mut full: Vec<&str> = args.iter().map(String::as_str).collect();
    full.extend(["--quiet", "--reports", reports.to_str().unwrap()]);
    assert_eq!(run(&full).unwrap(), ExitCode::SUCCESS, "{command}");

    let rows = support::csv_rows(&reports.join("results.csv"));
    let example = row(&rows, "harmonic_displacement");
    assert_eq!(example["origin"], "external");
    assert!(!example["status"].starts_with("failed"), "{}", example["status"]);
    assert!(support::num(example, "startup_s") > 0.0);
    // A direct method that puts every handle on its target, exactly as the pipe carries it.
    assert!(
        support::num(example, "handle_residual_over_diag") < 1e-12,
        "{}",
        example["handle_residual_over_diag"]
    );
    assert!(
        support::num(example, "e_theta_deg") > support::num(row(&rows, "arap"), "e_theta_deg"),
        "no rotations: worse than arap"
    );
    assert_eq!(row(&rows, "arap")["origin"], "built-in");
    assert!(reports.join("logs/cylinder-harmonic_displacement.stderr.txt").is_file());
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    assert!(page.contains("harmonic_displacement<span class=\"origin\""), "the page marks the external row");
}

/// Process ids of every running process whose command line contains `needle`.
fn processes_with(needle: &str) -> Vec<u32> {
    let mut pids = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else { continue };
        let Ok(cmdline) = std::fs::read(entry.path().join("cmdline")) else { continue };
        let stat = std::fs::read_to_string(entry.path().join("stat")).unwrap_or_default();
        let zombie = stat.rsplit_once(')').is_some_and(|(_, rest)| rest.trim_start().starts_with(['Z', 'X']));
        if !zombie && String::from_utf8_lossy(&cmdline).replace('\0', " ").contains(needle) {
            pids.push(pid);
        }
    }
    pids
}

#[test]
fn a_broken_method_beside_built_in_ones_fails_alone_and_leaves_nothing_running() {
    let dir = tempfile::tempdir().unwrap();
    // A copy of its own: the processes it looks for afterwards are this test's, not the toys other
    // tests of this file run at the same time.
    let toy = dir.path().join("toy_method.py");
    std::fs::copy(support::workspace_root().join("tests/external/toy_method.py"), &toy).unwrap();
    let pid_file = dir.path().join("grandchild.pid");
    let toys = format!(
        "[toy_crash]\ncommand = [\"python3\", \"{toy}\", \"crash-in-solve\"]\n\n\
         [toy_hang]\ncommand = [\"python3\", \"{toy}\", \"hang\", \"{pid}\"]\ntimeout_s = 5\n\n\
         [toy_nan]\ncommand = [\"python3\", \"{toy}\", \"nan\"]\n\n\
         [toy_ok]\ncommand = [\"python3\", \"{toy}\", \"ok\"]\n\n\
         [toy_silent]\ncommand = [\"python3\", \"{toy}\", \"silent\"]\nkind = \"iterative\"\n\n\
         [toy_direct]\ncommand = [\"python3\", \"{toy}\", \"silent\"]\nkind = \"direct\"\n",
        toy = toy.display(),
        pid = pid_file.display()
    );
    let scenario = |methods: &str| {
        format!("name = \"bar\"\nprocedural = {{ shape = \"bar\", vertices = 800 }}\nmethods = [{methods}]\n")
    };
    let built_in = "\"laplacian\", \"arap\", \"isolines\"";
    let with_toys = format!(
        "{built_in}, \"toy_crash\", \"toy_hang\", \"toy_nan\", \"toy_ok\", \"toy_silent\", \"toy_direct\""
    );
    let broken = configs_in(&dir.path().join("broken"), &[("bar.toml", scenario(&with_toys))], &toys);
    let plain = configs_in(&dir.path().join("plain"), &[("bar.toml", scenario(built_in))], "");
    let all = |configs: &Path, reports: &str| {
        let reports = dir.path().join(reports);
        let code = run(&[
            "all",
            "--quiet",
            "--configs",
            configs.to_str().unwrap(),
            "--reports",
            reports.to_str().unwrap(),
        ]);
        (code.unwrap(), reports)
    };
    let (code, broken_reports) = all(&broken, "broken-reports");
    assert_eq!(code, ExitCode::from(harness::cli::EXIT_CASE_FAILED));
    let (code, plain_reports) = all(&plain, "plain-reports");
    assert_eq!(code, ExitCode::SUCCESS);

    let rows = support::csv_rows(&broken_reports.join("results.csv"));
    let status = |m: &str| row(&rows, m)["status"].clone();
    for (method, needles) in [
        (
            "toy_crash",
            &["failed: external method `toy_crash`: `solve`", "exit status: 3", "ZeroDivisionError"][..],
        ),
        ("toy_hang", &["failed: external method `toy_hang`: `solve`", "timeout of 5 s", "toy: solve"][..]),
        ("toy_nan", &["failed: external method `toy_nan`: `solve`", "non-finite number (NaN)"][..]),
    ] {
        for n in needles {
            assert!(status(method).contains(n), "{method}: `{n}` not in {}", status(method));
        }
    }
    // The well-behaved toy moves only its handles; the verdict sees the tear like any method's.
    assert!(status("toy_ok").starts_with("suspect: folds"), "{}", status("toy_ok"));
    // An iterative method that says nothing of its convergence is not silently finished (issue 38);
    // the same answers from a direct method are.
    assert!(status("toy_silent").contains("convergence unknown"), "{}", status("toy_silent"));
    assert_eq!(row(&rows, "toy_silent")["converged"], "unknown");
    assert!(!status("toy_direct").contains("convergence unknown"), "{}", status("toy_direct"));
    assert_eq!(row(&rows, "toy_direct")["converged"], "true");
    assert_eq!(row(&rows, "toy_ok")["origin"], "external");

    // The built-in rows are those of a run without the toys, to the last bit.
    let cases = |reports: &Path| -> Vec<serde_json::Value> {
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(reports.join("results.json")).unwrap()).unwrap();
        json["cases"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["origin"] == "built-in")
            .map(support::timeless)
            .collect()
    };
    let (with, without) = (cases(&broken_reports), cases(&plain_reports));
    assert_eq!(with.len(), 3);
    assert_eq!(with, without);

    // Nothing outlives the run: neither a toy nor the grandchild the hanging one started.
    let grandchild: u32 = std::fs::read_to_string(&pid_file).unwrap().trim().parse().unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(2);
    while (!processes_with(&toy.display().to_string()).is_empty()
        || std::path::Path::new(&format!("/proc/{grandchild}/cmdline")).exists()
            && !processes_with("sleep 600").is_empty())
        && std::time::Instant::now() < deadline
    {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    assert_eq!(processes_with(&toy.display().to_string()), Vec::<u32>::new(), "toy processes left running");
    let stat = std::fs::read_to_string(format!("/proc/{grandchild}/stat")).unwrap_or_default();
    let alive = stat.rsplit_once(')').is_some_and(|(_, rest)| !rest.trim_start().starts_with(['Z', 'X']));
    assert!(!alive, "the hanging toy's grandchild {grandchild} outlived the run");
}

#[test]
fn peers_run_beside_arap_and_land_near_it() {
    let Some(python) = support::python() else { return };
    let dir = tempfile::tempdir().unwrap();
    let bar = "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 1500 }\n".to_string();
    let configs = configs_in(dir.path(), &[("bar.toml", bar)], "");
    let reports = dir.path().join("reports");
    let mut args =
        vec!["run", "--peers", "--python", python.to_str().unwrap(), "--scenario", "bar", "--quiet"];
    for m in ["arap", "libigl_arap", "libigl_biharmonic", "open3d_arap", "open3d_arap_smoothed"] {
        args.extend(["--method", m]);
    }
    args.extend(["--configs", configs.to_str().unwrap(), "--reports", reports.to_str().unwrap()]);
    assert_eq!(run(&args).unwrap(), ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.join("results.csv"));
    assert_eq!(rows.len(), 5);
    for r in rows.iter().filter(|r| r["method"] != "arap") {
        assert_eq!(r["origin"], "peer", "{}", r["method"]);
        assert!(!r["status"].starts_with("failed"), "{}: {}", r["method"], r["status"]);
    }
    // The same energy to the same distance bound: the same stationary point up to the weights
    // (ours are the intrinsic Delaunay cotangents) and libigl's single-precision rotation fit, or a
    // lower one. On this bar the symmetric twist is a saddle of the energy (docs/results.md, issues
    // 51 and 63): our L-BFGS converges to it and its saddle test leaves it for the buckled minimum
    // that libigl's plain local/global iteration finds. Should they still end apart, the page
    // names libigl's where it is the lower energy.
    let libigl = row(&rows, "libigl_arap");
    assert_eq!(libigl["converged"], "true");
    let distance = support::num(libigl, "rms_to_arap_over_diag");
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    if distance >= 1e-3 {
        let (theirs, ours) =
            (support::num(libigl, "arap_energy"), support::num(row(&rows, "arap"), "arap_energy"));
        assert!(theirs < ours * (1.0 - 1e-3), "{distance:e} apart, yet not lower: {theirs:e} vs {ours:e}");
        let listed = page.split("id=\"lower-energy\"").nth(1).unwrap_or_default();
        assert!(listed.contains("<code>libigl_arap</code> on <code>bar</code>"), "{listed}");
    }
    // Linear: a twist it cannot follow without rotations.
    assert!(
        support::num(row(&rows, "libigl_biharmonic"), "e_theta_deg")
            > support::num(row(&rows, "arap"), "e_theta_deg")
    );
    // The provenance names what each peer said it is.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(reports.join("results.json")).unwrap()).unwrap();
    let external = json["provenance"]["external"].as_array().unwrap();
    assert_eq!(external.len(), 4, "{external:?}");
    assert!(external
        .iter()
        .any(|e| e["method"] == "libigl_arap" && e["about"].as_str().unwrap().contains("libigl 2.6.3")));
    let peers = std::fs::read_to_string(reports.join("peers.md")).unwrap();
    assert!(peers.contains("| bar | "), "{peers}");
    assert!(page.contains("Our arap against libigl's") && page.contains("<span class=\"origin\""));

    // Without the Python the run says so and runs the rest.
    let reports = dir.path().join("reports-without");
    let args = [
        "run",
        "--peers",
        "--python",
        "/nonexistent/python",
        "--scenario",
        "bar",
        "--method",
        "arap",
        "--quiet",
        "--configs",
        configs.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ];
    assert_eq!(run(&args).unwrap(), ExitCode::SUCCESS);
    assert_eq!(support::csv_rows(&reports.join("results.csv")).len(), 1);
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    assert!(page.contains("peers not run: the Python /nonexistent/python does not exist"));
}

#[test]
fn repetitions_give_a_spread_and_catch_a_non_deterministic_method() {
    let dir = tempfile::tempdir().unwrap();
    let toy = support::workspace_root().join("tests/external/toy_method.py");
    let toys = format!(
        "[toy_random]\ncommand = [\"python3\", \"{toy}\", \"random\"]\n\n[toy_ok]\ncommand = [\"python3\", \"{toy}\", \"ok\"]\n",
        toy = toy.display()
    );
    let bar = "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 800 }\n\
               methods = [\"laplacian\", \"isolines\", \"toy_random\", \"toy_ok\"]\n"
        .to_string();
    let configs = configs_in(dir.path(), &[("bar.toml", bar)], &toys);
    let reports = dir.path().join("reports");
    let args = [
        "run",
        "--repeat",
        "3",
        "--scenario",
        "bar",
        "--quiet",
        "--configs",
        configs.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
        "--method",
        "laplacian",
        "--method",
        "isolines",
        "--method",
        "toy_random",
        "--method",
        "toy_ok",
    ];
    assert_eq!(run(&args).unwrap(), ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.join("results.csv"));
    for method in ["laplacian", "isolines", "toy_ok"] {
        let r = row(&rows, method);
        assert!(!r["status"].contains("non-deterministic"), "{method}: {}", r["status"]);
        assert_eq!(r["repetitions"], "3");
        let mut phases = vec!["precompute_s", "bind_s", "median_iteration_ms", "solve_s", "total_s"];
        if method == "toy_ok" {
            phases.push("startup_s");
        }
        for phase in phases {
            let (min, median, max) = (
                support::num(r, &format!("{phase}_min")),
                support::num(r, phase),
                support::num(r, &format!("{phase}_max")),
            );
            assert!(min <= median && median <= max, "{method} {phase}: {min} {median} {max}");
        }
    }
    let random = &row(&rows, "toy_random")["status"];
    assert!(random.contains("non-deterministic: repetition 2's result differs from the first"), "{random}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(reports.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["provenance"]["run"]["repetitions"], 3);
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    assert!(page.contains("min–max over 3 repetitions"));
}
