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

/// [`harness`] in the working directory `dir`.
fn harness_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_harness")).current_dir(dir).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fixed slab at the bottom of a mesh and a handle slab at its top, moved sideways.
const FIXED_AND_HANDLE: &str = "[[regions]]\nname = \"base\"\nrole = \"fixed\"\n\
    select = { slab = { axis = \"z\", from = 0.0, to = 0.05 } }\n\
    [[regions]]\nname = \"top\"\nrole = \"handle\"\nselect = { slab = { axis = \"z\", from = 0.95, to = 1.0 } }\n\
    translate = [0.1, 0.0, 0.0]\n";

#[test]
fn a_missing_relative_mesh_names_the_scenario_file_the_key_and_the_absolute_path() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("mine")).unwrap();
    let scenario =
        format!("name = \"dragon\"\nmesh = \"models/dragon.ply\"\nmethods = [\"arap\"]\n{FIXED_AND_HANDLE}");
    std::fs::write(dir.path().join("mine/dragon.toml"), scenario).unwrap();
    // A relative scenario path from the working directory: the message still shows where it looked.
    let (code, out, err) =
        harness_in(dir.path(), &["run", "--quiet", "--scenario", "mine/dragon.toml", "--reports", "reports"]);
    assert_eq!(code, 2, "{out}{err}");
    let absolute = dir.path().canonicalize().unwrap().join("mine/models/dragon.ply");
    for needle in [
        "scenario `dragon`",
        "mine/dragon.toml",
        "mesh = \"models/dragon.ply\"",
        &format!("{} does not exist", absolute.display()),
    ] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
    assert!(!dir.path().join("reports").exists(), "nothing written");
}

#[test]
fn unknown_names_get_the_nearest_one_and_are_blamed_on_where_they_came_from() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = bar_scenario(dir.path(), "first", "methods = [\"arap\"]\n");
    let reports = dir.path().join("reports");
    let reports = reports.to_str().unwrap();
    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &scenario, "--method", "isoline", "--reports", reports]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("--method isoline") && err.contains("did you mean `isolines`?"), "{err}");
    assert!(!err.contains("methods.toml"), "the name came from the command line: {err}");

    let listed = bar_scenario(dir.path(), "listed", "methods = [\"arap\", \"lapalcian\"]\n");
    let (code, out, err) = harness(&["run", "--quiet", "--scenario", &listed, "--reports", reports]);
    assert_eq!(code, 2, "{out}{err}");
    for needle in ["listed.toml", "methods", "unknown method `lapalcian`", "did you mean `laplacian`?"] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
    assert!(!err.contains("methods.toml"), "the name came from the scenario: {err}");

    let left_out =
        bar_scenario(dir.path(), "left", "methods = [\"arap\"]\n[left_out]\nscale_awar = \"too slow\"\n");
    let (code, out, err) = harness(&["run", "--quiet", "--scenario", &left_out, "--reports", reports]);
    assert_eq!(code, 2, "{out}{err}");
    for needle in ["left.toml", "left_out.scale_awar", "did you mean `scale_aware`?"] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
    assert!(!err.contains("methods.toml"), "the name came from the scenario: {err}");

    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", "cylindre", "--method", "arap", "--reports", reports]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("cylindre") && err.contains("did you mean `cylinder`?"), "{err}");
}

/// The results of `reports` as `(scenario, method) -> row`, each row its column -> value.
fn rows(reports: &Path) -> Vec<std::collections::BTreeMap<String, String>> {
    let mut reader = csv::Reader::from_path(reports.join("results.csv")).unwrap();
    let headers = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| headers.iter().zip(r.unwrap().iter()).map(|(h, v)| (h.to_string(), v.to_string())).collect())
        .collect()
}

/// `.dmat` selections of both kinds on a bar written as OFF: a per-vertex file of region ids
/// (`id`) and an index list (`form = "indices"`) select the same handle, so both scenarios give the
/// same result; an index list read as region ids is an error that says so and names the key.
#[test]
fn a_dmat_selection_reads_region_ids_or_an_index_list_and_says_which_it_looks_like() {
    let dir = tempfile::tempdir().unwrap();
    let bar = meshes::shapes::generate(meshes::shapes::ShapeKind::Bar, 500).unwrap().mesh;
    meshes::io::write_off(dir.path().join("bar.off"), &bar).unwrap();
    let (lo, hi) = bar.bbox();
    let height = |p: [f64; 3]| (p[2] - lo[2]) / (hi[2] - lo[2]);
    let ids: Vec<i64> = bar
        .positions()
        .iter()
        .map(|&p| {
            if height(p) <= 0.05 {
                0
            } else if height(p) >= 0.95 {
                1
            } else {
                -1
            }
        })
        .collect();
    let dmat = |values: &[i64]| {
        format!("1 {}\n{}\n", values.len(), values.iter().map(i64::to_string).collect::<Vec<_>>().join("\n"))
    };
    std::fs::write(dir.path().join("regions.dmat"), dmat(&ids)).unwrap();
    let top: Vec<i64> = (0..ids.len() as i64).filter(|&v| ids[v as usize] == 1).collect();
    std::fs::write(dir.path().join("top.dmat"), dmat(&top)).unwrap();
    let scenario = |name: &str, top_select: &str| {
        let text = format!(
            "name = \"{name}\"\nmesh = \"bar.off\"\nmethods = [\"arap\"]\n\
             [[regions]]\nname = \"base\"\nrole = \"fixed\"\nselect = {{ dmat = {{ file = \"regions.dmat\", id = 0 }} }}\n\
             [[regions]]\nname = \"top\"\nrole = \"handle\"\nselect = {top_select}\ntranslate = [0.1, 0.0, 0.0]\n"
        );
        let path = dir.path().join(format!("{name}.toml"));
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let by_id = scenario("by-id", "{ dmat = { file = \"regions.dmat\", id = 1 } }");
    let by_index = scenario("by-index", "{ dmat = { file = \"top.dmat\", form = \"indices\" } }");
    let reports = dir.path().join("reports");
    let (code, out, err) = harness(&[
        "run",
        "--quiet",
        "--scenario",
        &by_id,
        "--scenario",
        &by_index,
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{out}{err}");
    let rows = rows(&reports);
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["status"], "ok");
    for column in ["e_theta_deg", "e_phi_deg", "largest_handle_move_over_diag", "iterations"] {
        assert_eq!(rows[0][column], rows[1][column], "{column}: the two forms select the same vertices");
    }

    // The index list given with `id`: it has fewer values than the mesh has vertices.
    let wrong = scenario("wrong", "{ dmat = { file = \"top.dmat\", id = 1 } }");
    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &wrong, "--reports", reports.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}{err}");
    for needle in [
        "wrong.toml",
        "region `top`",
        "top.dmat",
        &format!("{} values", top.len()),
        "looks like an index list",
        "form = \"indices\"",
    ] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
}

/// A collection of two bars, one with two zero-area faces: without `repair` that mesh is skipped,
/// with it repaired; either way the closing summary (after the `reports:` line) and the page say
/// which mesh, with its file and the reason or what changed.
#[test]
fn skipped_and_repaired_meshes_are_in_the_closing_summary_and_on_the_page() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("m")).unwrap();
    let bar = meshes::shapes::generate(meshes::shapes::ShapeKind::Bar, 500).unwrap().mesh;
    meshes::io::write_off(dir.path().join("m/good.off"), &bar).unwrap();
    let mut flat = bar.positions().to_vec();
    let t0 = bar.triangles()[0];
    flat[t0[2] as usize] = flat[t0[0] as usize];
    let mut off = format!("OFF\n{} {} 0\n", flat.len(), bar.n_faces());
    flat.iter().for_each(|p| off += &format!("{} {} {}\n", p[0], p[1], p[2]));
    bar.triangles().iter().for_each(|t| off += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
    std::fs::write(dir.path().join("m/flat.off"), off).unwrap();
    let scenario = |repair: bool| {
        let text = format!("name = \"set\"\nmeshes = \"m/*.off\"\nrepair = {repair}\nmethods = [\"laplacian\"]\n{FIXED_AND_HANDLE}");
        let path = dir.path().join("set.toml");
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let reports = dir.path().join("reports");
    let flat_file = dir.path().join("m/flat.off").display().to_string();
    let closing = |out: &str| out[out.find("\nreports: ").unwrap_or_else(|| panic!("{out}"))..].to_string();

    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &scenario(false), "--reports", reports.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    let summary = closing(&out);
    let line =
        summary.lines().find(|l| l.contains("skipped set-flat")).unwrap_or_else(|| panic!("{summary}"));
    assert!(line.contains(&flat_file) && line.contains("zero area"), "{line}");
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    let section = &page[page.find("id=\"inputs\"").expect("the page's section on skipped meshes")..];
    let section = &section[..section.find("<h2").unwrap_or(section.len())];
    assert!(
        section.contains("set-flat") && section.contains(&flat_file) && section.contains("zero area"),
        "{section}"
    );

    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &scenario(true), "--reports", reports.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    let summary = closing(&out);
    let line =
        summary.lines().find(|l| l.contains("repaired set-flat")).unwrap_or_else(|| panic!("{summary}"));
    assert!(line.contains(&flat_file) && line.contains("2 zero-area faces dropped"), "{line}");
    assert!(!summary.contains("set-good"), "the good mesh was neither skipped nor repaired: {summary}");
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    let section = &page[page.find("id=\"inputs\"").expect("the page's section on repaired meshes")..];
    assert!(section.contains("set-flat") && section.contains("2 zero-area faces dropped"), "{section}");
}

/// Where the columns of `row` start (in characters): its cells are separated by at least two
/// spaces and hold no two spaces in a row themselves, but the last (free text) may.
fn column_starts(row: &str, columns: usize) -> Vec<usize> {
    let chars: Vec<char> = row.chars().collect();
    let mut starts = vec![chars.iter().position(|c| *c != ' ').unwrap()];
    while starts.len() < columns {
        let mut i = *starts.last().unwrap();
        while i + 1 < chars.len() && !(chars[i] == ' ' && chars[i + 1] == ' ') {
            i += 1;
        }
        while i < chars.len() && chars[i] == ' ' {
            i += 1;
        }
        starts.push(i);
    }
    starts
}

#[test]
fn list_aligns_its_columns() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("mine.toml");
    std::fs::write(
        &file,
        "[a_rather_long_external_method_name]\ncommand = [\"python3\", \"mine.py\"]\nsummary = \"mine\"\n",
    )
    .unwrap();
    let (code, out, err) = harness(&["list", "--methods", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    let lines: Vec<&str> = out.lines().collect();
    let methods_at = lines.iter().position(|l| l.starts_with("methods (")).unwrap();
    let scenarios_at = lines.iter().position(|l| l.starts_with("scenarios (")).unwrap();
    let methods = &lines[methods_at + 1..scenarios_at];
    let scenarios = &lines[scenarios_at + 1..];
    assert!(methods.iter().any(|l| l.contains("a_rather_long_external_method_name")), "{out}");
    assert!(methods.iter().any(|l| l.contains("isolines[isolines=10]")), "{out}");
    let first = column_starts(methods[0], 3);
    for row in methods {
        assert_eq!(column_starts(row, 3), first, "method columns of {row:?} in\n{out}");
    }
    let first = column_starts(scenarios[0], 2);
    for row in scenarios {
        assert_eq!(column_starts(row, 2), first, "scenario columns of {row:?} in\n{out}");
    }
}

/// A directory made unwritable for this process until dropped: the immutable flag for root (whom
/// permission bits do not stop), read-only permissions otherwise. `None` when neither works here.
struct Unwritable(std::path::PathBuf);

impl Unwritable {
    fn new(dir: &Path) -> Option<Unwritable> {
        let root = Command::new("id").arg("-u").output().is_ok_and(|o| o.stdout.starts_with(b"0\n"));
        let made = if root {
            Command::new("chattr").arg("+i").arg(dir).status().is_ok_and(|s| s.success())
        } else {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o555)).is_ok()
        };
        let guard = made.then(|| Unwritable(dir.to_path_buf()));
        // Whatever was done, it must hold: a probe file cannot be made.
        let probe = dir.join(".probe");
        if std::fs::write(&probe, "").is_ok() {
            let _ = std::fs::remove_file(probe);
            return None;
        }
        guard
    }
}

impl Drop for Unwritable {
    fn drop(&mut self) {
        use std::os::unix::fs::PermissionsExt;
        let _ = Command::new("chattr").arg("-i").arg(&self.0).status();
        let _ = std::fs::set_permissions(&self.0, std::fs::Permissions::from_mode(0o755));
    }
}

#[test]
fn a_report_directory_that_cannot_be_written_stops_the_run_before_it_starts() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = bar_scenario(dir.path(), "first", "methods = [\"arap\", \"laplacian\"]\n");
    let reports = dir.path().join("reports");
    std::fs::create_dir(&reports).unwrap();
    std::fs::write(reports.join("index.html"), "old page").unwrap();
    let Some(_locked) = Unwritable::new(&reports) else {
        eprintln!("SKIPPED: cannot make a directory unwritable here");
        return;
    };
    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &scenario, "--reports", reports.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains(&reports.display().to_string()) && err.contains("cannot be written"), "{err}");
    assert!(!out.contains("time by phase") && !out.contains("laplacian"), "no case ran: {out}");
    assert_eq!(std::fs::read_to_string(reports.join("index.html")).unwrap(), "old page");

    // A report directory not made yet, under one that cannot be written: named too.
    let below = reports.join("new/reports");
    let (code, out, err) =
        harness(&["run", "--quiet", "--scenario", &scenario, "--reports", below.to_str().unwrap()]);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains(&reports.display().to_string()) && err.contains("cannot be written"), "{err}");
    assert!(err.contains(&below.display().to_string()), "{err}");
}

/// The README's own-mesh example is a scenario file the harness accepts (no unknown key), and it
/// shows what a newcomer needs: `up`, `repair`, and both kinds of `.dmat` selection.
#[test]
fn the_readme_scenario_example_parses_and_shows_up_repair_and_both_dmat_forms() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md")).unwrap();
    let start = readme.find("<!-- own-mesh-scenario -->").expect("the example's marker");
    let end = readme.find("<!-- /own-mesh-scenario -->").expect("the example's end marker");
    let block = &readme[start..end];
    let toml = &block[block.find("```toml\n").unwrap() + 8..block.rfind("```").unwrap()];
    for needle in ["up = \"y\"", "repair = true", "id = ", "form = \"indices\""] {
        assert!(toml.contains(needle), "{needle:?} not in the example:\n{toml}");
    }
    // The commented alternative is a selection too: uncommented in place of the first, it parses.
    let alternative = toml.lines().find(|l| l.starts_with("# select = { dmat")).unwrap();
    let with_indices = toml
        .lines()
        .filter(|l| !l.contains("id = 2"))
        .map(|l| if l == alternative { &l[2..] } else { l })
        .collect::<Vec<_>>()
        .join("\n");
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in [("dragon.toml", toml.to_string()), ("dragon-indices.toml", with_indices)] {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let spec = harness::scenario::load_spec(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(spec.repair && spec.up.is_some() && spec.regions.len() == 3, "{name}");
    }
}

/// `harness list | head -1`: the reader closes the pipe after its first line; the harness ends
/// as Unix tools do, without a panic on the failed write. The listing is made longer than a pipe's
/// buffer (2,000 scenarios), so that the harness is still writing when the pipe closes.
#[test]
fn a_closed_pipe_ends_the_listing_without_a_panic() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let (code, _, stderr) = harness(&["configs", "export", dir.path().to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    let configs = dir.path().join("configs");
    for i in 0..2000 {
        bar_scenario(&configs.join("scenarios"), &format!("a-long-listing-{i:04}"), "");
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_harness"))
        .args(["list", "--configs", configs.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut first).unwrap();
    // The reader is dropped here: the pipe is closed with most of the listing unwritten.
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(first.starts_with("methods"), "{first}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
