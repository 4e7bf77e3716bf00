//! The regression gate through the `harness` binary: `baseline` writes a baseline from a run's
//! results.json, `check` passes on the same results and fails, naming the case and metric, once one
//! result is made worse on purpose; a case turning suspect, a failed case and a missing case fail it
//! too.

use std::path::Path;
use std::process::Command;

/// A results.json as a run writes it, with the given `(scenario, method, e_theta, e_phi, status)`.
fn write_results(dir: &Path, cases: &[(&str, &str, f64, f64, &str)]) {
    let cases: Vec<serde_json::Value> = cases
        .iter()
        .map(|(scenario, method, e_theta, e_phi, status)| {
            serde_json::json!({
                "scenario": scenario, "method": method, "mesh_source": "survey", "vertices": 10, "faces": 16,
                "precompute_s": 0.1, "bind_s": 0.01, "median_iteration_ms": 1.0, "iterations": 5, "solve_s": 0.2,
                "total_s": 0.3, "converged": true, "e_theta_deg": e_theta, "e_phi_deg": e_phi,
                "handle_residual_over_diag": 0.0, "rms_to_arap_over_diag": null, "status": status,
                "phase_timings": [], "statistics": [], "steps": [], "trace": []
            })
        })
        .collect();
    let report =
        serde_json::json!({ "generator": "test", "data_source": "survey data", "units": "", "cases": cases });
    std::fs::write(dir.join("results.json"), serde_json::to_vec_pretty(&report).unwrap()).unwrap();
}

fn harness(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_harness")).args(args).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), text)
}

#[test]
fn check_names_every_regression_and_passes_identical_results() {
    let dir = tempfile::tempdir().unwrap();
    let reports = dir.path().to_str().unwrap();
    let baseline = dir.path().join("baseline.json");
    let baseline = baseline.to_str().unwrap();
    let good = [
        ("bar", "arap", 2.1151, 5.7769, "ok"),
        ("cactus", "arap", 1.1910, 2.7614, "ok"),
        ("cactus", "hirm", 6.29, 0.93, "ok"),
    ];
    write_results(dir.path(), &good);

    let (code, text) = harness(&["baseline", "--reports", reports, "--baseline", baseline]);
    assert_eq!(code, 0, "{text}");
    let (code, text) = harness(&["check", "--reports", reports, "--baseline", baseline]);
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("no quality regression"), "{text}");

    // Worsen cactus/arap E_theta by 10% on purpose.
    let mut worse = good;
    worse[1].2 *= 1.1;
    write_results(dir.path(), &worse);
    let (code, text) = harness(&["check", "--reports", reports, "--baseline", baseline]);
    assert_eq!(code, 3, "{text}");
    assert!(text.contains("cactus / arap / e_theta_deg"), "{text}");
    assert!(!text.contains("bar / arap"), "only the worsened case is named: {text}");

    // A case that turns suspect (same measures).
    let mut suspect = good;
    suspect[2].4 = "suspect: folds: 0.647% of interior edges turned by more than 90°";
    write_results(dir.path(), &suspect);
    let (code, text) = harness(&["check", "--reports", reports, "--baseline", baseline]);
    assert_eq!(code, 3, "{text}");
    assert!(text.contains("turned suspect: cactus / hirm"), "{text}");

    // A failed case and a case missing from the run.
    write_results(dir.path(), &[good[0], ("cactus", "arap", f64::NAN, f64::NAN, "failed: linear solver")]);
    let (code, text) = harness(&["check", "--reports", reports, "--baseline", baseline]);
    assert_eq!(code, 3, "{text}");
    assert!(text.contains("failed: cactus / arap"), "{text}");
    assert!(text.contains("missing: cactus / hirm"), "{text}");
}

#[test]
fn check_without_results_or_baseline_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let reports = dir.path().to_str().unwrap();
    let (code, text) = harness(&["check", "--reports", reports, "--baseline", "/nonexistent/baseline.json"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("results.json"), "{text}");
    write_results(dir.path(), &[("bar", "arap", 1.0, 1.0, "ok")]);
    let (code, text) = harness(&["check", "--reports", reports, "--baseline", "/nonexistent/baseline.json"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("/nonexistent/baseline.json"), "{text}");
}

/// Issue 38, item 6: mistakes caught before any case runs. A sweep file naming a scenario that does
/// not exist, and a `--reports` path that is a file, stop the run at once with exit 2 and an error
/// naming them; an empty `DEFORMBENCH_PYTHON=` counts as unset (no "a value is required").
#[test]
fn mistakes_in_the_command_line_and_configs_stop_the_run_before_it_starts() {
    let dir = tempfile::tempdir().unwrap();
    let configs = dir.path().join("configs");
    std::fs::create_dir_all(configs.join("scenarios")).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("configs");
    for file in ["methods.toml", "verdicts.toml"] {
        std::fs::copy(root.join(file), configs.join(file)).unwrap();
    }
    std::fs::write(
        configs.join("scenarios/bar.toml"),
        "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 600 }\nmethods = [\"isolines\"]\n",
    )
    .unwrap();
    std::fs::write(
        configs.join("sweeps.toml"),
        "scenarios = [\"bra\"]\n[per_field]\nmethod = \"isolines\"\nparams = { isolines = [10, 30] }\n",
    )
    .unwrap();
    let reports = dir.path().join("reports");
    let base = ["all", "--quiet", "--no-check", "--configs", configs.to_str().unwrap()];
    let with = |extra: &[&str]| {
        let mut args: Vec<&str> = base.to_vec();
        args.extend_from_slice(extra);
        let out = Command::new(env!("CARGO_BIN_EXE_harness"))
            .args(&args)
            .env("DEFORMBENCH_PYTHON", "")
            .env_remove("DEFORM_SURVEY_DIR")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        (out.status.code().unwrap_or(-1), text)
    };
    let (code, text) = with(&["--sweeps", "--reports", reports.to_str().unwrap()]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("sweeps.toml") && text.contains("`bra`") && text.contains("known: bar"), "{text}");
    assert!(!reports.exists(), "nothing written");
    let file = dir.path().join("a-file");
    std::fs::write(&file, "not a directory").unwrap();
    let (code, text) = with(&["--reports", file.to_str().unwrap()]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("a-file") && text.contains("--reports names a file"), "{text}");
    assert!(!text.contains("time by phase"), "no case ran: {text}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "not a directory");
    // The empty DEFORMBENCH_PYTHON of `with` is no value: the run goes on without it.
    let (code, text) = with(&["--reports", reports.to_str().unwrap()]);
    assert_eq!(code, 0, "{text}");
    assert!(reports.join("results.csv").is_file());
}

/// Issue 38, item 2: an entry this machine cannot run disables itself. Beside working built-in
/// rows, an entry with an unset variable, one with a missing working directory and one whose
/// program does not exist: `list` names each with its reason, a run that does not ask for them
/// runs the others and notes them once, a run that asks for one by name fails (exit 2) with its
/// reason. A malformed entry stays an error naming file, entry and key; a name given twice names
/// both files.
#[test]
fn an_entry_that_cannot_run_here_disables_itself_and_the_others_run() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("mine.toml");
    std::fs::write(
        &file,
        "[needs_var]\ncommand = [\"${DEFORMBENCH_SURELY_UNSET_VARIABLE}\", \"m.py\"]\n\
         [no_dir]\ncommand = [\"python3\", \"m.py\"]\nworking_dir = \"nowhere\"\n\
         [no_program]\ncommand = [\"./no-such-program\"]\n",
    )
    .unwrap();
    let configs = dir.path().join("configs");
    std::fs::create_dir_all(configs.join("scenarios")).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("configs");
    for file in ["methods.toml", "verdicts.toml"] {
        std::fs::copy(root.join(file), configs.join(file)).unwrap();
    }
    std::fs::write(
        configs.join("scenarios/bar.toml"),
        "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 600 }\nmethods = [\"arap\", \"isolines\"]\n",
    )
    .unwrap();
    let harness = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_harness"))
            .args(args)
            .args(["--configs", configs.to_str().unwrap(), "--methods", file.to_str().unwrap()])
            .env_remove("DEFORMBENCH_SURELY_UNSET_VARIABLE")
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        (out.status.code().unwrap_or(-1), text)
    };
    let (code, text) = harness(&["list"]);
    assert_eq!(code, 0, "{text}");
    for (name, why) in [
        ("needs_var", "DEFORMBENCH_SURELY_UNSET_VARIABLE"),
        ("no_dir", "nowhere is not a directory"),
        ("no_program", "no-such-program does not exist"),
    ] {
        let line =
            text.lines().find(|l| l.trim_start().starts_with(name)).unwrap_or_else(|| panic!("{text}"));
        assert!(line.contains("UNAVAILABLE") && line.contains(why), "{line}");
    }
    let reports = dir.path().join("reports");
    let (code, text) = harness(&["all", "--quiet", "--no-check", "--reports", reports.to_str().unwrap()]);
    assert_eq!(code, 0, "{text}");
    assert_eq!(text.matches("method `no_dir`").count(), 1, "said once: {text}");
    let csv = std::fs::read_to_string(reports.join("results.csv")).unwrap();
    assert!(csv.contains("\nbar,arap,") && csv.contains("\nbar,isolines,") && !csv.contains(",no_"), "{csv}");
    let (code, text) = harness(&[
        "run",
        "--scenario",
        "bar",
        "--method",
        "no_program",
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("mine.toml") && text.contains("[no_program]") && text.contains("does not exist"),
        "{text}"
    );

    std::fs::write(&file, "[bad]\ncommand = [\"python3\"]\ntimeout = 3\n").unwrap();
    let (code, text) = harness(&["list"]);
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("mine.toml") && text.contains("[bad]") && text.contains("unknown key `timeout`"),
        "{text}"
    );
    std::fs::write(&file, "[arap_cotan]\nmethod = \"arap\"\n[laplacian_too]\nmethod = \"laplacian\"\n")
        .unwrap();
    let (code, text) = harness(&["list"]);
    assert_eq!(code, 0, "arap_cotan is a peer, not in methods.toml: {text}");
    std::fs::write(&file, "[arap]\ncommand = [\"python3\"]\n").unwrap();
    let (code, text) = harness(&["list"]);
    assert_eq!(code, 2, "{text}");
    assert!(
        text.contains("mine.toml: [arap]: `arap` is already an entry of")
            && text.contains("configs/methods.toml"),
        "{text}"
    );
}

/// Issue 38, item 4: `check-method` runs the protocol on a tiny mesh and says what is wrong: a
/// well-behaved toy passes (exit 0, every step `ok`), and each broken toy fails at its step with the
/// reason in plain words (exit 1).
#[test]
fn check_method_passes_a_good_method_and_names_what_a_broken_one_gets_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let toy = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().join("tests/external/toy_method.py");
    let file = dir.path().join("toys.toml");
    let entries: String = ["ok", "silent", "nan", "malformed", "old-protocol", "wrong-count"]
        .iter()
        .map(|mode| {
            let kind = if *mode == "silent" { "kind = \"iterative\"\n" } else { "" };
            format!(
                "[toy_{}]\ncommand = [\"python3\", \"{}\", \"{mode}\"]\n{kind}\n",
                mode.replace('-', "_"),
                toy.display()
            )
        })
        .collect();
    std::fs::write(&file, entries).unwrap();
    let check = |name: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_harness"))
            .args(["check-method", name, "--methods", file.to_str().unwrap()])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
        (out.status.code().unwrap_or(-1), text)
    };
    let (code, text) = check("toy_ok");
    assert_eq!(code, 0, "{text}");
    for step in ["start and hello", "precompute", "first bind", "second bind", "quit"] {
        assert!(text.lines().any(|l| l.trim_start().starts_with("ok") && l.contains(step)), "{step}: {text}");
    }
    assert!(text.contains("speaks the protocol"), "{text}");
    let (code, text) = check("toy_silent");
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("converged: not said"), "{text}");
    for (toy, step, needle) in [
        ("toy_nan", "first bind (2 regions) and solve: solve", "non-finite number (NaN)"),
        ("toy_malformed", "precompute", "not a protocol answer"),
        ("toy_old_protocol", "start and hello", "version 0"),
        ("toy_wrong_count", "first bind (2 regions) and solve: solve", "positions"),
    ] {
        let (code, text) = check(toy);
        assert_eq!(code, 1, "{toy}: {text}");
        let fail =
            text.lines().find(|l| l.trim_start().starts_with("FAIL")).unwrap_or_else(|| panic!("{text}"));
        assert!(fail.contains(step) && fail.contains(needle), "{toy}: {fail}");
    }
    let (code, text) = check("nosuch");
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("unknown method `nosuch`"), "{text}");
}
