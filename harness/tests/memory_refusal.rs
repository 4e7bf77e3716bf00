//! Issue 60: a scenario that asks for more memory than the machine has is refused before its mesh
//! is refined or loaded: exit code 2 within a second or so, a message with the estimate, the
//! available memory, the scenario file and the key, and no report written. (Once, `refine = 12`
//! allocated ~21 GB and the kernel killed the run.) Only the refusal is tested: `--force` would
//! allocate it.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// A closed unit cube, 8 vertices and 12 triangles: refined 12 times, 100.7M vertices.
const CUBE_OFF: &str = "OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";

/// The cube as OBJ, whose size no header tells: it is read (8 vertices) and checked before refining.
const CUBE_OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

fn scenario(mesh: &str, refine: u32) -> String {
    format!(
        "name = \"probe\"\nmesh = \"{mesh}\"\nrefine = {refine}\n\
         [[regions]]\nname = \"bottom\"\nrole = \"fixed\"\nselect = {{ slab = {{ axis = \"z\", from = 0.0, to = 0.1 }} }}\n\
         [[regions]]\nname = \"top\"\nrole = \"handle\"\nselect = {{ slab = {{ axis = \"z\", from = 0.9, to = 1.0 }} }}\n\
         translate = [0.0, 0.0, 0.1]\n"
    )
}

/// Run the harness binary; its exit code, stdout and stderr, and how long it took.
fn harness(args: &[&str]) -> (i32, String, Duration) {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_harness")).args(args).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), text, start.elapsed())
}

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn refine_12_is_refused_before_anything_is_allocated_or_written() {
    if !Path::new("/proc/meminfo").exists() {
        // Where the available memory is unknown nothing is refused.
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let reports = dir.path().join("reports");
    for (mesh, text) in [("cube.off", CUBE_OFF), ("cube.obj", CUBE_OBJ)] {
        std::fs::write(dir.path().join(mesh), text).unwrap();
        let file = dir.path().join(format!("probe-{mesh}.toml"));
        std::fs::write(&file, scenario(mesh, 12)).unwrap();
        let (code, text, took) = harness(&[
            "run",
            "--quiet",
            "--method",
            "arap",
            "--method",
            "laplacian",
            "--scenario",
            file.to_str().unwrap(),
            "--reports",
            reports.to_str().unwrap(),
        ]);
        assert_eq!(code, 2, "{mesh}: {text}");
        assert!(took < Duration::from_secs(5), "{mesh}: refused after {took:?}");
        let first = text.lines().find(|l| l.starts_with("error:")).unwrap_or_else(|| panic!("{text}"));
        for part in [
            file.to_str().unwrap(),
            "`refine = 12`",
            "100.7M vertices",
            "needs an estimated",
            "`laplacian` at 7600 bytes per vertex",
            "of memory available (MemAvailable",
            "--force",
        ] {
            assert!(first.contains(part), "{mesh}: `{part}` missing from: {first}");
        }
        // Only the largest method counts (cases run one at a time).
        assert!(!first.contains("`arap`"), "{first}");
        assert!(!reports.exists(), "{mesh}: a report directory was written");
    }
    let mut expected = vec!["cube.obj", "cube.off", "probe-cube.obj.toml", "probe-cube.off.toml"];
    expected.sort();
    assert_eq!(listing(dir.path()), expected, "nothing written beside the inputs (no staging directory)");
}

#[test]
fn a_huge_procedural_mesh_is_refused_by_all_and_force_is_offered() {
    if !Path::new("/proc/meminfo").exists() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scenarios = dir.path().join("scenarios");
    std::fs::create_dir(&scenarios).unwrap();
    std::fs::write(
        scenarios.join("huge.toml"),
        "name = \"huge\"\nprocedural = { shape = \"bar\", vertices = 500000000 }\n",
    )
    .unwrap();
    let reports = dir.path().join("reports");
    let (code, text, took) = harness(&[
        "all",
        "--quiet",
        "--no-check",
        "--scenarios",
        scenarios.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{text}");
    assert!(took < Duration::from_secs(5), "refused after {took:?}");
    assert!(text.contains("`procedural = { shape = \"bar\", vertices = 500000000 }`"), "{text}");
    assert!(text.contains("huge.toml") && text.contains("--force"), "{text}");
    assert!(!reports.exists());
    for command in ["run", "all"] {
        let (code, help, _) = harness(&[command, "--help"]);
        assert_eq!(code, 0);
        assert!(help.contains("--force"), "`{command} --help` does not offer --force:\n{help}");
    }
}
