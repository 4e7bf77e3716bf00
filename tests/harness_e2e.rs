//! End-to-end tests of `harness all`: reports on the survey data and on the procedural look-alikes,
//! and every kind of bad input rejected with an error that names the file and element, leaving the
//! reports directory untouched.

mod support;

use std::path::{Path, PathBuf};

use meshes::shapes::{generate, ShapeKind};

fn run(args: &[&str]) -> anyhow::Result<std::process::ExitCode> {
    let mut full = vec!["harness"];
    full.extend_from_slice(args);
    harness::cli::run(full)
}

#[test]
fn all_on_survey_data_writes_reports_that_meet_the_acceptance_figures() {
    let Some(survey) = support::survey_dir() else { return };
    let reports = tempfile::tempdir().unwrap();
    let code = run(&[
        "all",
        "--quiet",
        "--survey-dir",
        survey.to_str().unwrap(),
        "--reports",
        reports.path().to_str().unwrap(),
    ])
    .unwrap();
    assert_eq!(code, std::process::ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.path().join("results.csv"));
    // Issue 18: lean outputs. The resolution sweeps write no meshes unless asked (`--every-mesh`),
    // and the whole report stays under 50 MB.
    assert!(rows.iter().any(|r| r["scenario"] == "bar-sweep-200k"));
    let sweep_meshes = std::fs::read_dir(reports.path().join("meshes"))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().contains("-sweep-"))
        .count();
    assert_eq!(sweep_meshes, 0, "sweep meshes written by default");
    let bytes = support::directory_bytes(reports.path());
    assert!(bytes < 50_000_000, "reports/ is {:.1} MB", bytes as f64 / 1e6);
    // scale_aware_ora takes scale_aware's identical solve of each single-step case (issue 39), and
    // its solve time still counts it.
    for scenario in ["bar", "cactus", "cylinder", "plane"] {
        let row =
            |method: &str| rows.iter().find(|r| r["scenario"] == scenario && r["method"] == method).unwrap();
        let (plain, ora) = (row("scale_aware"), row("scale_aware_ora"));
        let reused = support::num(ora, "reused_solve_s");
        assert!(reused > 0.0 && support::num(ora, "solve_s") >= reused, "{scenario}: {reused} s taken");
        assert!(plain["reused_solve_s"].is_empty(), "{scenario}: scale_aware computes its own solve");
        assert_eq!(support::num(ora, "iterations"), support::num(plain, "iterations") + 1.0);
    }
    for scenario in ["bar", "cactus", "cylinder", "plane"] {
        for method in methods::registry::method_names() {
            let row = rows
                .iter()
                .find(|r| r["scenario"] == scenario && r["method"] == method)
                .unwrap_or_else(|| panic!("no row for {scenario} / {method}"));
            assert!(!row["status"].starts_with("failed"), "{scenario}/{method}: {}", row["status"]);
            assert_eq!(row["mesh_source"], "survey");
            assert_eq!(
                row["laplacian_weights"], "tufted_delaunay",
                "{scenario}/{method}: the default is reported"
            );
            let residual = support::num(row, "handle_residual_over_diag");
            // The bounds for the references; the reduced models only approximate their handles.
            let bound = match method {
                "arap" => 1e-9,
                "laplacian" => 1e-3,
                _ => 5e-2,
            };
            assert!(residual <= bound, "{scenario}/{method}: handle residual {residual:e} > {bound:e}");
            for key in [
                "e_theta_deg",
                "e_phi_deg",
                "e_area",
                "e_length",
                "folds",
                "turn_beyond_handles_deg",
                "precompute_s",
                "bind_s",
                "median_iteration_ms",
                "rms_to_arap_over_diag",
                "max_to_arap_over_diag",
            ] {
                let v = support::num(row, key);
                assert!(v.is_finite() && v >= 0.0, "{scenario}/{method}: {key} = {v}");
            }
            // GLB by default; OFF only with `--mesh-format off|both`.
            let stem = harness::stored_report::case_file_stem(scenario, method);
            let glb = reports.path().join(format!("meshes/{stem}.glb"));
            let result = meshes::io::read_mesh(&glb).unwrap();
            assert_eq!(result.n_vertices(), row["vertices"].parse::<usize>().unwrap());
            assert_eq!(result.n_faces(), row["faces"].parse::<usize>().unwrap());
            assert!(!reports.path().join(format!("meshes/{stem}.off")).exists());
        }
        let arap = rows.iter().find(|r| r["scenario"] == scenario && r["method"] == "arap").unwrap();
        assert_eq!(support::num(arap, "rms_to_arap_over_diag"), 0.0);
        // The isoline model reaches its hard handles, does not fold and stays in its frame; on the
        // cylinder its bend loses 27% of the area, which the size verdict sees (issue 62).
        let isolines = rows.iter().find(|r| r["scenario"] == scenario && r["method"] == "isolines").unwrap();
        if scenario == "cylinder" {
            assert!(
                isolines["status"].starts_with("suspect: shrinks: its surface area fell"),
                "{}",
                isolines["status"]
            );
        } else {
            assert_eq!(isolines["status"], "ok", "{scenario}/isolines");
        }
    }
    // Issue 14: what the angles hide. The survey bar is open (no volume); the scale-aware balloon on it
    // shows in e_area, many times arap's.
    let case = |scenario: &str, method: &str| {
        rows.iter().find(|r| r["scenario"] == scenario && r["method"] == method).unwrap()
    };
    assert!(case("bar", "arap")["volume_change"].is_empty(), "the survey bar is open");
    let (balloon, arap) =
        (support::num(case("bar", "scale_aware"), "e_area"), support::num(case("bar", "arap"), "e_area"));
    assert!(balloon > 0.4 && balloon > 5.0 * arap, "bar e_area: scale_aware {balloon}, arap {arap}");
    // The closed cylinder: the linear-ish methods and scale_aware shrink it, arap far less.
    let arap_volume = support::num(case("cylinder", "arap"), "volume_change");
    for method in ["laplacian", "isolines", "scale_aware"] {
        let (area, volume) = (
            support::num(case("cylinder", method), "e_area"),
            support::num(case("cylinder", method), "volume_change"),
        );
        assert!(
            area > 0.3 && volume < -0.2 && volume < 2.0 * arap_volume,
            "cylinder/{method}: e_area {area}, volume {volume}"
        );
    }
    // HIRM with 10 close handles on the cactus: with the paper's 6 fields it tore and folded (a
    // `suspect` verdict, issue 14); with at least 10 fields it bends without folds, within 1.5x of the
    // isoline model's E_theta (issue 16).
    let (hirm, isolines) = (case("cactus-handles", "hirm"), case("cactus-handles", "isolines"));
    assert_eq!(hirm["status"], "ok", "cactus-handles/hirm");
    assert_eq!(support::num(hirm, "folds"), 0.0);
    let ratio = support::num(hirm, "e_theta_deg") / support::num(isolines, "e_theta_deg");
    assert!(ratio <= 1.5, "cactus-handles: hirm E_theta {ratio:.2}x that of isolines");
    // hirm converges on every survey test (the 200K-vertex sweep bar aside).
    for scenario in
        ["bar", "cactus", "cylinder", "plane", "bar-handles", "cactus-handles", "cactus-incremental"]
    {
        assert_eq!(case(scenario, "hirm")["converged"], "true", "{scenario}/hirm");
    }
    // Au et al. 2007, Fig. 9: on the bar twist, fewer isolines show more of the linear effect (kinks
    // between isolines): 20 isolines must bend no worse than 10 (E_phi, the kinks). E_theta is not
    // part of the claim (20 isolines are 2% worse there, 7.64 vs 7.50 degrees), nor is the distance to
    // the arap reference: with the intrinsic Delaunay weights the reference moved and 20 isolines are
    // 1.2% farther from it (RMS 0.0453 vs 0.0447 of the diagonal; with cotan weights 20 were nearer).
    let bar = |method: &str| rows.iter().find(|r| r["scenario"] == "bar" && r["method"] == method).unwrap();
    let (fine, coarse) =
        (support::num(bar("isolines"), "e_phi_deg"), support::num(bar("isolines[isolines=10]"), "e_phi_deg"));
    assert!(fine <= coarse, "bar: e_phi_deg with 20 isolines {fine} > with 10 {coarse}");
    // The standard suite ends with the regression gate (the exit code above says it passed) and
    // a page with every plot and figure.
    let page = std::fs::read_to_string(reports.path().join("index.html")).unwrap();
    assert!(page.contains("No regression against"), "regression verdict missing from index.html");
    for plot in ["scaling", "table1", "cactus-errors", "cactus-timings", "cactus-convergence"] {
        assert!(reports.path().join(format!("plots/{plot}.png")).is_file(), "missing plots/{plot}.png");
    }
    for scenario in ["bar", "cactus", "cylinder", "plane"] {
        for method in methods::registry::method_names() {
            let render = reports.path().join(format!("figures/{scenario}-{method}.png"));
            assert!(render.is_file(), "missing {}", render.display());
        }
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(reports.path().join("results.json")).unwrap()).unwrap();
    let cases = json["cases"].as_array().unwrap();
    assert_eq!(cases.len(), rows.len());
    assert!(cases.iter().all(|c| !c["trace"].as_array().unwrap().is_empty()));

    // Per-iteration angle errors (the scale-aware paper's Fig. 6): Algorithm 1 ends well below its
    // Laplacian initialization (iteration 0) on the cactus.
    let convergence = support::csv_rows(&reports.path().join("convergence.csv"));
    for method in ["scale_aware", "scale_aware_ora"] {
        let rows: Vec<_> =
            convergence.iter().filter(|r| r["scenario"] == "cactus" && r["method"] == method).collect();
        // The angle errors are evaluated on the first ten iterations, then on a geometric grid.
        let curve: Vec<_> = rows.iter().filter(|r| !r["e_theta_deg"].is_empty()).collect();
        assert!(curve.len() >= 3, "cactus/{method}: {} iterations with E_theta", curve.len());
        assert!(curve.len() < rows.len(), "cactus/{method}: {} iterations, all evaluated", rows.len());
        assert!(curve.iter().all(|r| !r["e_phi_deg"].is_empty()));
        for key in ["e_theta_deg", "e_phi_deg"] {
            let (first, last) = (support::num(curve[0], key), support::num(curve[curve.len() - 1], key));
            assert!(
                last < 0.5 * first,
                "cactus/{method}: {key} {first} at the initialization, {last} at the end"
            );
        }
    }

    // Incremental editing (HIRM section 4.5): every method runs both steps; the second adds a handle.
    let updates = support::csv_rows(&reports.path().join("handle_updates.csv"));
    for scenario in ["bar-incremental", "cactus-incremental"] {
        for method in methods::registry::method_names() {
            let row = rows.iter().find(|r| r["scenario"] == scenario && r["method"] == method).unwrap();
            assert!(!row["status"].starts_with("failed"), "{scenario}/{method}: {}", row["status"]);
            let steps: Vec<_> =
                updates.iter().filter(|u| u["scenario"] == scenario && u["method"] == method).collect();
            let handles: Vec<&str> = steps.iter().map(|u| u["handles"].as_str()).collect();
            assert_eq!(handles, ["2", "3"], "{scenario}/{method}");
            assert!(steps.iter().all(|u| support::num(u, "bind_ms") >= 0.0));
        }
    }
    // HIRM's Table 1: 2, 6 and 10 handles on the bar and the cactus, with the field count.
    let table1 = std::fs::read_to_string(reports.path().join("table1.md")).unwrap();
    for scenario in ["bar-handles", "cactus-handles"] {
        for n_h in ["2", "6", "10"] {
            let row = updates
                .iter()
                .find(|u| u["scenario"] == scenario && u["method"] == "hirm" && u["handles"] == n_h);
            let row = row.unwrap_or_else(|| panic!("{scenario}: no hirm step with {n_h} handles"));
            assert!(
                support::num(row, "t_h_ms") > 0.0
                    && support::num(row, "t_h_ms") <= support::num(row, "bind_ms")
            );
        }
        assert_eq!(
            table1.lines().filter(|l| l.starts_with(&format!("| {scenario} |"))).count(),
            3,
            "{table1}"
        );
    }
    let hirm_fields = cases
        .iter()
        .filter(|c| c["method"] == "hirm")
        .map(|c| {
            c["statistics"]
                .as_array()
                .unwrap()
                .iter()
                .find(|s| s[0] == methods::keys::statistic::N_FIELD)
                .map(|s| s[1].as_f64().unwrap())
        })
        .collect::<Vec<_>>();
    assert!(
        !hirm_fields.is_empty() && hirm_fields.iter().all(|n| n.is_some_and(|n| n >= 1.0)),
        "{hirm_fields:?}"
    );
}

#[test]
fn without_survey_data_the_procedural_look_alikes_run_and_are_labelled() {
    let reports = tempfile::tempdir().unwrap();
    let configs = tempfile::tempdir().unwrap();
    // Small look-alikes keep the test quick; the shapes are the same generators `all` uses.
    std::fs::create_dir(configs.path().join("scenarios")).unwrap();
    for file in ["methods.toml", "verdicts.toml"] {
        std::fs::copy(support::workspace_root().join("configs").join(file), configs.path().join(file))
            .unwrap();
    }
    for shape in ["bar", "cylinder", "cactus", "plane"] {
        std::fs::write(
            configs.path().join(format!("scenarios/{shape}.toml")),
            // No `survey` key: DEFORM_SURVEY_DIR may be set in the environment of the test run.
            format!("name = \"{shape}\"\nprocedural = {{ shape = \"{shape}\", vertices = 1500 }}\n"),
        )
        .unwrap();
    }
    // With the cross-check Python, every result is also checked for self-intersections by open3d
    // (the small look-alikes keep that quick).
    let python = support::python();
    let mut args = vec![
        "all",
        "--quiet",
        "--configs",
        configs.path().to_str().unwrap(),
        "--reports",
        reports.path().to_str().unwrap(),
    ];
    if let Some(python) = &python {
        args.extend(["--self-intersections", "--python", python.to_str().unwrap()]);
    }
    let code = run(&args).unwrap();
    assert_eq!(code, std::process::ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.path().join("results.csv"));
    assert_eq!(rows.len(), 4 * configured_methods(), "every method of configs/methods.toml on each test");
    for row in &rows {
        assert_eq!(row["mesh_source"], "procedural look-alike");
        assert!(
            !row["status"].starts_with("failed"),
            "{}/{}: {}",
            row["scenario"],
            row["method"],
            row["status"]
        );
        if python.is_some() {
            let answer = row["self_intersecting"].as_str();
            assert!(
                answer == "true" || answer == "false",
                "{}/{}: self_intersecting {answer:?}",
                row["scenario"],
                row["method"]
            );
        }
    }
    let json = std::fs::read_to_string(reports.path().join("results.json")).unwrap();
    assert!(json.contains("procedural look-alikes"));

    // Plots per test, and the page that shows everything, checked in a real browser.
    for shape in ["bar", "cylinder", "cactus", "plane"] {
        for plot in ["errors", "timings", "convergence"] {
            for ext in ["png", "svg"] {
                let path = reports.path().join(format!("plots/{shape}-{plot}.{ext}"));
                assert!(path.is_file(), "missing {}", path.display());
            }
        }
    }
    for figure in ["grid", "grid_heat", "grid_area", "bar-rest", "bar-arap", "bar-arap-heat", "bar-arap-area"]
    {
        assert!(
            reports.path().join(format!("figures/{figure}.png")).is_file(),
            "missing figures/{figure}.png"
        );
    }
    let index = reports.path().join("index.html");
    let page = std::fs::read_to_string(&index).unwrap();
    assert!(page.contains("Not checked"), "a procedural run is not compared with the survey baseline");
    let Some(chromium) = support::chromium() else { return };
    let (loaded, total) = support::images_loaded_in_chromium(&chromium, &index);
    let expected = page.matches("<img ").count();
    assert!(expected >= 12, "index.html links {expected} images");
    assert_eq!((loaded, total), (expected, expected), "images loaded / present in index.html");
}

/// How many methods configs/methods.toml gives a run: the registered ones and its variants and
/// sweep points (`isolines[isolines=10]`).
fn configured_methods() -> usize {
    let path = support::workspace_root().join("configs/methods.toml");
    harness::config::MethodCatalog::load(&path).unwrap().methods().len()
}

/// The value of attribute `name` in the start tag `tag` (its text up to `>`).
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    tag.split(&format!(" {name}=\"")).nth(1).and_then(|v| v.split('"').next())
}

#[test]
fn the_page_ranks_sorts_and_filters_as_its_address_asks_in_chromium() {
    // spectral_mhb misses its soft handles on these two: suspect rows beside ok ones.
    let scenario = |shape: &str, n: usize| {
        (
            format!("{shape}.toml"),
            format!(
                "name = \"{shape}\"\nprocedural = {{ shape = \"{shape}\", vertices = {n} }}\n\
                 methods = [\"laplacian\", \"arap\", \"isolines\", \"spectral_mhb\"]\n"
            ),
        )
    };
    let configs = configs_with(&[scenario("bar", 2000), scenario("cylinder", 1500)]);
    let reports = tempfile::tempdir().unwrap();
    let args = ["all", "--quiet", "--no-check", "--configs", configs.path().to_str().unwrap()];
    assert_eq!(
        run(&[&args[..], &["--reports", reports.path().to_str().unwrap()]].concat()).unwrap(),
        std::process::ExitCode::SUCCESS
    );
    let Some(chromium) = support::chromium() else { return };
    let rows = support::csv_rows(&reports.path().join("results.csv"));
    let index = reports.path().join("index.html").canonicalize().unwrap();
    let url = format!("file://{}?sort=e_theta_deg&desc=1&status=ok&rank=e_phi_deg", index.display());
    let (dom, stderr) = support::dump_dom(&chromium, &url);
    let table = dom.split("id=\"results-table\"").nth(1).unwrap_or_else(|| panic!("no table; {stderr}"));
    let body = table.split("<tbody>").nth(1).unwrap().split("</tbody>").next().unwrap();
    // (method, scenario, status, hidden) of each row, in the order the page shows them.
    let shown: Vec<(String, String, String, bool)> = body
        .split("<tr ")
        .skip(1)
        .map(|tr| {
            let tag = tr.split('>').next().unwrap();
            let get =
                |n: &str| attribute(tag, n).unwrap_or_else(|| panic!("no {n} in <tr {tag}>")).to_string();
            (get("data-method"), get("data-scenario"), get("data-status"), tag.contains(" hidden"))
        })
        .collect();
    assert_eq!(shown.len(), rows.len(), "every case is a row");
    let visible: Vec<&(String, String, String, bool)> = shown.iter().filter(|r| !r.3).collect();
    let ok = rows.iter().filter(|r| r["status"] == "ok").count();
    assert!(ok > 0 && ok < rows.len(), "the fixture has ok and other cases ({ok} of {})", rows.len());
    assert_eq!(visible.len(), ok, "status=ok shows the ok rows only");
    assert!(visible.iter().all(|r| r.2 == "ok"));
    let e_theta = |r: &(String, String, String, bool)| {
        let row = rows.iter().find(|c| c["method"] == r.0 && c["scenario"] == r.1).unwrap();
        support::num(row, "e_theta_deg")
    };
    let order: Vec<f64> = visible.iter().map(|r| e_theta(r)).collect();
    assert!(order.windows(2).all(|w| w[0] >= w[1]), "sorted by E_theta descending: {order:?}");
    assert!(dom.contains(&format!("data-shown=\"{ok}\"")), "the row count says {ok}");
    // The ranking by E_phi: per test, the best `ok` case first; the others are not ranked, and are
    // listed under the table.
    for scenario in ["bar", "cylinder"] {
        let ranked = dom
            .split(&format!("<table class=\"ranking\" data-scenario=\"{scenario}\">"))
            .nth(1)
            .unwrap_or_else(|| panic!("no ranking of {scenario}"));
        let (table, after) = ranked.split_once("</table>").unwrap();
        for r in rows.iter().filter(|r| r["scenario"] == scenario && r["status"] != "ok") {
            let tag = format!("data-method=\"{}\"", r["method"]);
            assert!(!table.contains(&tag), "{scenario}: {} ({}) is not ranked", r["method"], r["status"]);
            let listed = after.split("</ul>").next().unwrap();
            assert!(listed.contains(&tag), "{scenario}: {} is listed under the ranking", r["method"]);
        }
        let first = table.split("<tr class=\"").nth(1).unwrap();
        let first = format!(" class=\"{first}");
        let first_method = attribute(first.split('>').next().unwrap(), "data-method").unwrap();
        let best = rows
            .iter()
            .filter(|r| r["scenario"] == scenario && r["status"] == "ok")
            .min_by(|a, b| support::num(a, "e_phi_deg").total_cmp(&support::num(b, "e_phi_deg")))
            .unwrap();
        assert_eq!(first_method, best["method"], "{scenario}: best by E_phi");
    }
    assert!(dom.contains("id=\"median-ranks\""));

    // The 3D view of a case opened from the address, with another method on the left: it loads
    // the case's files and draws both canvases (pixels that are not background).
    let url = format!("file://{}?view=bar-arap&left=isolines&colour=angle", index.display());
    let (dom, stderr) = support::dump_dom(&chromium, &url);
    let viewer = dom.split("<div id=\"viewer\"").nth(1).unwrap_or_else(|| panic!("no viewer; {stderr}"));
    let tag = viewer.split('>').next().unwrap();
    assert!(!tag.contains(" hidden"), "the view is open: <div id=\"viewer\"{tag}>");
    assert_eq!(attribute(tag, "data-view"), Some("bar-arap"));
    let pixels: usize =
        attribute(tag, "data-pixels").unwrap_or_else(|| panic!("not drawn; {stderr}")).parse().unwrap();
    assert!(pixels > 5_000, "{pixels} drawn pixels in the smaller canvas");
    assert_eq!(attribute(tag, "data-left"), Some("isolines"), "isolines on the left");
    // Every case with a result has its file; the page itself carries no mesh.
    for row in &rows {
        let stem = harness::stored_report::case_file_stem(&row["scenario"], &row["method"]);
        assert!(reports.path().join(format!("viewer/{stem}.js")).is_file(), "viewer/{stem}.js");
    }
}

/// A tiny survey-format data set (procedural bar written as .off/.sel/.def) and a configs directory
/// with one scenario using it, plus a reports directory holding a sentinel file.
struct BadInputFixture {
    _root: tempfile::TempDir,
    data: PathBuf,
    configs: PathBuf,
    reports: PathBuf,
}

impl BadInputFixture {
    fn new() -> Self {
        let root = tempfile::tempdir().unwrap();
        let data = root.path().join("data");
        let configs = root.path().join("configs");
        let reports = root.path().join("reports");
        for d in [&data, &configs.join("scenarios"), &reports] {
            std::fs::create_dir_all(d).unwrap();
        }
        let shape = generate(ShapeKind::Bar, 500).unwrap();
        meshes::io::write_off(data.join("tiny.off"), &shape.mesh).unwrap();
        meshes::io::write_selection(data.join("tiny.sel"), &shape.selection).unwrap();
        meshes::io::write_transform(data.join("tiny.def"), &shape.transform).unwrap();
        std::fs::write(configs.join("methods.toml"), "[arap]\nmax_iterations = 3\n").unwrap();
        std::fs::copy(support::workspace_root().join("configs/verdicts.toml"), configs.join("verdicts.toml"))
            .unwrap();
        std::fs::write(configs.join("scenarios/tiny.toml"), "name = \"tiny\"\nsurvey = \"tiny\"\n").unwrap();
        std::fs::write(reports.join("sentinel.txt"), "untouched").unwrap();
        Self { _root: root, data, configs, reports }
    }

    fn file(&self, name: &str) -> PathBuf {
        self.data.join(name)
    }

    /// Replace the `line`-th line (1-based) of a data file.
    fn edit_line(&self, name: &str, line: usize, new: &str) {
        let text = std::fs::read_to_string(self.file(name)).unwrap();
        let mut lines: Vec<String> = text.lines().map(String::from).collect();
        lines[line - 1] = new.to_string();
        std::fs::write(self.file(name), lines.join("\n") + "\n").unwrap();
    }

    /// Run `all`; it must fail with a message containing every one of `needles`, and write nothing.
    /// The message.
    fn expect_error(&self, needles: &[&str]) -> String {
        let result = run(&[
            "all",
            "--quiet",
            "--survey-dir",
            self.data.to_str().unwrap(),
            "--configs",
            self.configs.to_str().unwrap(),
            "--reports",
            self.reports.to_str().unwrap(),
        ]);
        let message = format!("{:#}", result.expect_err("bad input must be an error"));
        for needle in needles {
            assert!(message.contains(needle), "error {message:?} does not mention {needle:?}");
        }
        let written: Vec<_> =
            std::fs::read_dir(&self.reports).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(written, vec![std::ffi::OsString::from("sentinel.txt")], "reports/ was written to");
        message
    }
}

/// Line number (1-based) of the first vertex and first face of an OFF written by `write_off`.
fn off_layout(path: &Path) -> (usize, usize, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let counts = lines.iter().position(|l| l.split_whitespace().count() == 3 && !l.starts_with('#')).unwrap();
    let nv: usize = lines[counts].split_whitespace().next().unwrap().parse().unwrap();
    (counts + 2, counts + 2 + nv, nv)
}

#[test]
fn fixture_is_valid() {
    let f = BadInputFixture::new();
    let code = run(&[
        "all",
        "--quiet",
        "--survey-dir",
        f.data.to_str().unwrap(),
        "--configs",
        f.configs.to_str().unwrap(),
        "--reports",
        f.reports.to_str().unwrap(),
    ])
    .unwrap();
    assert_eq!(code, std::process::ExitCode::SUCCESS);
}

#[test]
fn malformed_number_names_file_and_line() {
    let f = BadInputFixture::new();
    let (first_vertex, _, _) = off_layout(&f.file("tiny.off"));
    f.edit_line("tiny.off", first_vertex + 3, "1.0 abc 2.0");
    f.expect_error(&["tiny.off", &format!("line {}", first_vertex + 3)]);
}

#[test]
fn truncated_off_is_rejected() {
    let f = BadInputFixture::new();
    let text = std::fs::read_to_string(f.file("tiny.off")).unwrap();
    let keep: Vec<&str> = text.lines().collect();
    std::fs::write(f.file("tiny.off"), keep[..keep.len() - 10].join("\n")).unwrap();
    f.expect_error(&["tiny.off", "end of file"]);
}

#[test]
fn out_of_range_index_names_the_face() {
    let f = BadInputFixture::new();
    let (_, first_face, nv) = off_layout(&f.file("tiny.off"));
    f.edit_line("tiny.off", first_face + 5, &format!("3 0 1 {}", nv + 7));
    f.expect_error(&["tiny.off", "face 5", &format!("{}", nv + 7), "out of range"]);
}

#[test]
fn nan_coordinate_names_the_vertex() {
    let f = BadInputFixture::new();
    let (first_vertex, _, _) = off_layout(&f.file("tiny.off"));
    f.edit_line("tiny.off", first_vertex + 4, "0.5 NaN 1.0");
    f.expect_error(&["tiny.off", "vertex 4", "NaN"]);
}

#[test]
fn zero_area_triangle_names_the_face() {
    let f = BadInputFixture::new();
    let mesh = meshes::io::read_mesh(f.file("tiny.off")).unwrap();
    // Move a vertex onto the midpoint of the opposite edge of its first face: that face has zero area.
    let [a, b, c] = mesh.triangles()[0];
    let mut p = mesh.positions().to_vec();
    let (pb, pc) = (p[b as usize], p[c as usize]);
    p[a as usize] = [(pb[0] + pc[0]) / 2.0, (pb[1] + pc[1]) / 2.0, (pb[2] + pc[2]) / 2.0];
    meshes::io::write_off(f.file("tiny.off"), &mesh.with_positions(p).unwrap()).unwrap();
    f.expect_error(&["tiny.off", "face 0", "zero area"]);
}

#[test]
fn non_manifold_edge_is_rejected() {
    let f = BadInputFixture::new();
    let mesh = meshes::io::read_mesh(f.file("tiny.off")).unwrap();
    // An interior edge (the bar is open at the bottom, so avoid face 0 on the rim).
    let [a, b, _] = mesh.triangles()[mesh.n_faces() / 2];
    // The vertex making the largest triangle with (a, b), so the new face is not degenerate.
    let p = mesh.positions();
    let area = |v: u32| meshes::geometry::triangle_area(p, &[a, b, v]);
    let other = (0..mesh.n_vertices() as u32).max_by(|&u, &v| area(u).total_cmp(&area(v))).unwrap();
    // A third face on edge (a, b) (both orientations are taken already by the two existing faces).
    let mut tris = mesh.triangles().to_vec();
    tris.push([a, b, other]);
    let bad = meshes::TriMesh::new(mesh.positions().to_vec(), tris).unwrap();
    meshes::io::write_off(f.file("tiny.off"), &bad).unwrap();
    f.expect_error(&["tiny.off", "non-manifold", &format!("({}, {})", a.min(b), a.max(b))]);
}

#[test]
fn selection_of_wrong_length_is_rejected() {
    let f = BadInputFixture::new();
    let text = std::fs::read_to_string(f.file("tiny.sel")).unwrap();
    std::fs::write(f.file("tiny.sel"), text + "1\n").unwrap();
    f.expect_error(&["tiny.sel", "entries but the mesh has"]);
}

#[test]
fn transform_that_is_not_4x4_is_rejected() {
    let f = BadInputFixture::new();
    std::fs::write(f.file("tiny.def"), "# 4x4\n1 0 0 0\n0 1 0 0\n0 0 1 0\n").unwrap();
    f.expect_error(&["tiny.def"]);
}

#[test]
fn empty_handle_set_is_rejected() {
    let f = BadInputFixture::new();
    let text = std::fs::read_to_string(f.file("tiny.sel")).unwrap();
    std::fs::write(f.file("tiny.sel"), text.replace('2', "1")).unwrap();
    f.expect_error(&["scenario `tiny`", "no handle vertices"]);
}

#[test]
fn scenario_naming_an_unknown_method_is_rejected() {
    let f = BadInputFixture::new();
    std::fs::write(
        f.configs.join("scenarios/tiny.toml"),
        "name = \"tiny\"\nsurvey = \"tiny\"\nmethods = [\"arap\", \"hirn\"]\n",
    )
    .unwrap();
    f.expect_error(&["tiny.toml", "unknown method `hirn`"]);
}

#[test]
fn unknown_method_parameter_is_rejected() {
    let f = BadInputFixture::new();
    std::fs::write(f.configs.join("methods.toml"), "[arap]\nmax_iter = 3\n").unwrap();
    f.expect_error(&["methods.toml", "max_iter"]);
}

/// Issue 60: the key and value at fault, not every rule of the method.
#[test]
fn a_bad_method_parameter_names_its_file_key_and_value_alone() {
    let f = BadInputFixture::new();
    std::fs::write(f.configs.join("methods.toml"), "[arap]\ntolerance = nan\n").unwrap();
    let message = f.expect_error(&["methods.toml: arap: tolerance = NaN: must be a finite number >= 0"]);
    assert!(!message.contains("lbfgs") && !message.contains("max_iterations"), "{message}");
    std::fs::write(
        f.configs.join("methods.toml"),
        "[scale_aware]\nrefactor_turn = -0.5\nnormal_sweeps = 0\n",
    )
    .unwrap();
    let message = f.expect_error(&[
        "methods.toml: scale_aware: normal_sweeps = 0: must be >= 1; refactor_turn = -0.5: must be a finite number >= 0",
    ]);
    assert!(!message.contains("constraint_weight") && !message.contains("anderson_depth"), "{message}");
}

#[test]
fn missing_or_bad_verdict_rules_are_rejected() {
    let f = BadInputFixture::new();
    std::fs::write(f.configs.join("verdicts.toml"), "max_folds = 0\nmax_handle_residual_over_diag = 1e-3\n")
        .unwrap();
    f.expect_error(&["verdicts.toml", "frame_margin_diagonals"]);
    std::fs::remove_file(f.configs.join("verdicts.toml")).unwrap();
    f.expect_error(&["verdicts.toml"]);
}

#[test]
fn missing_survey_directory_is_rejected() {
    let f = BadInputFixture::new();
    std::fs::remove_file(f.file("tiny.off")).unwrap();
    f.expect_error(&["tiny.off"]);
}

/// `harness all --quiet` with the configs directory `configs`, writing to `reports`.
fn all_with(configs: &Path, reports: &Path) -> anyhow::Result<std::process::ExitCode> {
    run(&["all", "--quiet", "--configs", configs.to_str().unwrap(), "--reports", reports.to_str().unwrap()])
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .unwrap()
}

/// Replace the first `from` at or after `[laplacian]` in `configs`' methods.toml by `to` (a test
/// that breaks the method on purpose); fails when there is no such line.
fn edit_laplacian_section(configs: &Path, from: &str, to: &str) {
    let methods_toml = configs.join("methods.toml");
    let text = std::fs::read_to_string(&methods_toml).unwrap();
    let (head, tail) = text.split_at(text.find("[laplacian]").unwrap());
    let edited = format!("{head}{}", tail.replacen(from, to, 1));
    assert_ne!(edited, text, "`{from}` in [laplacian]");
    std::fs::write(&methods_toml, edited).unwrap();
}

/// A configs directory (the committed methods.toml and verdicts.toml) with `scenarios` as
/// `(file name, contents)`.
fn configs_with(scenarios: &[(String, String)]) -> tempfile::TempDir {
    let configs = tempfile::tempdir().unwrap();
    std::fs::create_dir(configs.path().join("scenarios")).unwrap();
    for file in ["methods.toml", "verdicts.toml"] {
        std::fs::copy(support::workspace_root().join("configs").join(file), configs.path().join(file))
            .unwrap();
    }
    for (name, text) in scenarios {
        std::fs::write(configs.path().join("scenarios").join(name), text).unwrap();
    }
    configs
}

/// Scenario files `(file name, contents)` of procedural `(shape, vertices)` running laplacian, arap
/// (the reference) and isolines.
fn small_procedural(shapes: &[(&str, usize)]) -> Vec<(String, String)> {
    shapes
        .iter()
        .map(|(shape, n)| {
            (
                format!("{shape}.toml"),
                format!(
                    "name = \"{shape}\"\nprocedural = {{ shape = \"{shape}\", vertices = {n} }}\n\
                     methods = [\"laplacian\", \"arap\", \"isolines\"]\n"
                ),
            )
        })
        .collect()
}

#[test]
fn shards_merged_equal_one_run_to_the_last_digit() {
    // Three small look-alikes of different cost, so the cost balance puts them on different shards.
    let configs = configs_with(&small_procedural(&[("bar", 2400), ("cylinder", 1200), ("cactus", 1600)]));
    let configs = configs.path().to_str().unwrap();
    let work = tempfile::tempdir().unwrap();
    let dir = |name: &str| work.path().join(name).to_str().unwrap().to_string();
    let baseline = dir("baseline.json");
    let ok = std::process::ExitCode::SUCCESS;

    assert_eq!(run(&["all", "--quiet", "--configs", configs, "--reports", &dir("first")]).unwrap(), ok);
    assert_eq!(run(&["baseline", "--reports", &dir("first"), "--baseline", &baseline]).unwrap(), ok);
    let whole = ["all", "--quiet", "--configs", configs, "--reports", &dir("whole"), "--baseline", &baseline];
    assert_eq!(run(&whole).unwrap(), ok);
    for k in 1..=3 {
        let shard = format!("{k}/3");
        let part = dir(&format!("part{k}"));
        let args = ["all", "--quiet", "--configs", configs, "--reports", &part, "--shard", &shard];
        assert_eq!(run(&args).unwrap(), ok, "shard {shard}");
        let report = read_json(&work.path().join(format!("part{k}/results.json")));
        assert_eq!(report["shard"], shard);
        // Each part holds whole scenarios: one each here, as the three have different costs.
        let cases = report["cases"].as_array().unwrap();
        assert_eq!(cases.len(), 3, "shard {shard}: {} cases", cases.len());
        assert!(!work.path().join(format!("part{k}/index.html")).exists(), "a part writes no page");
    }
    let (p1, p2, p3, merged) = (dir("part1"), dir("part2"), dir("part3"), dir("merged"));
    let merge = [
        "merge",
        &p2,
        &p3,
        &p1,
        "--quiet",
        "--configs",
        configs,
        "--reports",
        &merged,
        "--baseline",
        &baseline,
    ];
    assert_eq!(run(&merge).unwrap(), ok);

    let whole = read_json(&work.path().join("whole/results.json"));
    let merged = read_json(&work.path().join("merged/results.json"));
    assert_eq!(whole["data_source"], merged["data_source"]);
    assert!(merged.get("shard").is_none(), "the merged report is whole");
    // The merge keeps each part's record, in part order.
    let parts = merged["provenance"]["parts"].as_array().expect("the parts' records");
    assert_eq!(parts.len(), 3);
    assert!(parts.iter().all(|p| p["run"]["command_line"]
        .as_array()
        .unwrap()
        .iter()
        .any(|a| a == "--shard")));
    assert!(whole["provenance"].get("parts").is_none());
    let (a, b) = (whole["cases"].as_array().unwrap(), merged["cases"].as_array().unwrap());
    assert_eq!(a.len(), 9);
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(support::timeless(x), support::timeless(y), "{} / {}", x["scenario"], x["method"]);
    }
    // The same verdict, from the same baseline, and every picture.
    for report in ["whole", "merged"] {
        let page = std::fs::read_to_string(work.path().join(report).join("index.html")).unwrap();
        assert!(page.contains("No regression against"), "{report}: no verdict");
        assert!(work.path().join(report).join("figures/grid.png").is_file());
    }
    // Parts missing, repeated or not partial are errors that name them, and write nothing.
    let bad = dir("bad");
    let error = |args: &[&str]| format!("{:#}", run(args).expect_err("must fail"));
    let e = error(&["merge", &p1, &p2, "--configs", configs, "--reports", &bad]);
    assert!(e.contains("lacks part(s) 3/3"), "{e}");
    let e = error(&["merge", &p1, &p1, "--configs", configs, "--reports", &bad]);
    assert!(e.contains("part 1/3 is also in"), "{e}");
    let e = error(&["merge", &dir("whole"), "--configs", configs, "--reports", &bad]);
    assert!(e.contains("not a partial report"), "{e}");
    assert!(!work.path().join("bad").exists(), "a failed merge writes nothing");
}

#[test]
fn jobs_run_cases_at_once_and_report_what_one_job_does() {
    // Two scenarios with the reference and two others each: with 2 jobs, a scenario's other cases
    // wait for (or run) its reference, and the report comes back in plan order.
    let configs = configs_with(&small_procedural(&[("bar", 1800), ("cactus", 1200)]));
    let configs = configs.path().to_str().unwrap();
    let work = tempfile::tempdir().unwrap();
    let dir = |name: &str| work.path().join(name).to_str().unwrap().to_string();
    let ok = std::process::ExitCode::SUCCESS;
    for (name, jobs) in [("one", "1"), ("two", "2")] {
        let args = ["all", "--quiet", "--no-check", "--threads", "1", "--jobs", jobs, "--configs", configs];
        assert_eq!(run(&[&args[..], &["--reports", &dir(name)]].concat()).unwrap(), ok, "--jobs {jobs}");
    }
    let one = read_json(&work.path().join("one/results.json"));
    let two = read_json(&work.path().join("two/results.json"));
    assert_eq!(two["provenance"]["run"]["jobs"], 2);
    assert_eq!(two["provenance"]["run"]["threads"], 1);
    let (a, b) = (one["cases"].as_array().unwrap(), two["cases"].as_array().unwrap());
    assert_eq!(a.len(), 6);
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(support::timeless(x), support::timeless(y), "{} / {}", x["scenario"], x["method"]);
        assert!(x["rms_to_arap_over_diag"].is_number(), "compared with the reference");
        // Memory is measured one case at a time only: the counter is the process's.
        assert!(x["peak_memory_mib"].as_f64().is_some_and(|m| m >= 0.0), "{}", x["peak_memory_mib"]);
        assert!(y["peak_memory_mib"].is_null(), "{}", y["peak_memory_mib"]);
    }
    let page = std::fs::read_to_string(work.path().join("two/index.html")).unwrap();
    assert!(page.contains("1 thread(s), 2 job(s)"), "the page says how the cases ran");
}

#[test]
fn compare_calls_a_slower_method_slower_and_says_what_differs_between_the_runs() {
    // A bend, not the twisted bar: the bar's symmetric twist is a saddle of the ARAP energy that
    // L-BFGS converges to and the plain iteration leaves (docs/results.md, issue 51), so there the
    // two runs would compare two stationary points.
    let scenario = (
        "cylinder.toml".to_string(),
        "name = \"cylinder\"\nprocedural = { shape = \"cylinder\", vertices = 1500 }\n\
         methods = [\"laplacian\", \"arap\", \"isolines\"]\n"
            .to_string(),
    );
    let configs = configs_with(std::slice::from_ref(&scenario));
    // B: arap by the plain local/global iteration, neither L-BFGS nor Anderson (and room to
    // converge without them).
    let plain = configs_with(&[scenario]);
    let methods = std::fs::read_to_string(plain.path().join("methods.toml")).unwrap();
    let arap = methods.find("[arap]").unwrap();
    let tail = methods[arap..]
        .replacen("solver = \"lbfgs\"", "solver = \"local_global\"", 1)
        .replacen("acceleration = \"anderson\"", "acceleration = \"none\"", 1)
        .replacen("max_iterations = 2000", "max_iterations = 20000", 1);
    std::fs::write(plain.path().join("methods.toml"), format!("{}{tail}", &methods[..arap])).unwrap();
    let work = tempfile::tempdir().unwrap();
    let dir = |name: &str| work.path().join(name).to_str().unwrap().to_string();
    let ok = std::process::ExitCode::SUCCESS;
    for (name, configs, repeat) in [("a", &configs, "3"), ("b", &plain, "3"), ("once", &configs, "1")] {
        let args = [
            "all",
            "--quiet",
            "--no-check",
            "--repeat",
            repeat,
            "--configs",
            configs.path().to_str().unwrap(),
        ];
        assert_eq!(run(&[&args[..], &["--reports", &dir(name)]].concat()).unwrap(), ok, "{name}");
    }
    let read = |name: &str| harness::comparison::ComparedRun::read(Path::new(&dir(name))).unwrap();
    let (a, b, once) = (read("a"), read("b"), read("once"));

    let plain_arap = harness::comparison::compare(&a, &b, harness::comparison::DEFAULT_MIN_CHANGE);
    let arap = plain_arap.cases.iter().find(|c| c.method == "arap").unwrap();
    assert_eq!(arap.speed(), harness::comparison::Speed::Slower, "{arap:?}");
    assert!(arap.iterations.1 > 2 * arap.iterations.0, "{:?}", arap.iterations);
    assert!(arap.total().ratio > 1.5, "{arap:?}");
    assert!(!arap.is_worse(), "the same fixed point: {:?}", arap.quality);
    assert!(
        plain_arap.warnings.iter().any(|w| w.contains("/methods.toml differ")),
        "the changed configuration is named: {:?}",
        plain_arap.warnings
    );
    // A run compared with itself: nothing slower, faster or worse.
    let itself = harness::comparison::compare(&a, &read("a"), harness::comparison::DEFAULT_MIN_CHANGE);
    let t = itself.tally();
    assert_eq!((t.slower, t.faster, t.worse, t.better, t.not_judged), (0, 0, 0, 0, 0), "{t:?}");
    // (A working tree with uncommitted changes is worth a warning, but not this test's business.)
    let warnings: Vec<&String> = itself.warnings.iter().filter(|w| !w.contains("uncommitted")).collect();
    assert!(warnings.is_empty(), "{warnings:?}");
    // One repetition has no spread: nothing judged, and a warning says why.
    let unjudged = harness::comparison::compare(&once, &a, harness::comparison::DEFAULT_MIN_CHANGE);
    assert_eq!(unjudged.tally().not_judged, 3);
    assert!(
        unjudged.warnings.iter().any(|w| w.contains("A timed each case once")),
        "{:?}",
        unjudged.warnings
    );
    assert!(unjudged.warnings.iter().any(|w| w.contains("different repetitions: A ran with 1, B with 3")));

    // The command: printed, written, and its exit codes.
    let out = dir("comparison");
    let compare = |extra: &[&str]| {
        run(&[&["compare", &dir("a"), &dir("b"), "--out", &out][..], extra].concat()).unwrap()
    };
    assert_eq!(compare(&[]), ok);
    assert_eq!(compare(&["--fail-on", "worse"]), ok);
    assert_eq!(
        compare(&["--fail-on", "slower,worse"]),
        std::process::ExitCode::from(harness::cli::EXIT_SLOWER)
    );
    let md = std::fs::read_to_string(work.path().join("comparison/compare.md")).unwrap();
    assert!(md.contains("| cylinder | arap |") && md.contains("slower"), "{md}");
    let html = std::fs::read_to_string(work.path().join("comparison/compare.html")).unwrap();
    assert!(html.contains("<tr class=\"slower\">") && html.contains("class=\"warning\""), "{html}");
    // A quality regression fails --fail-on worse: B's results.json with arap's E_theta made worse.
    let mut results = read_json(&work.path().join("a/results.json"));
    let cases = results["cases"].as_array_mut().unwrap();
    let case = cases.iter_mut().find(|c| c["method"] == "arap").unwrap();
    case["e_theta_deg"] = serde_json::json!(case["e_theta_deg"].as_f64().unwrap() * 1.5 + 1.0);
    let worse = work.path().join("worse.json");
    std::fs::write(&worse, serde_json::to_vec(&results).unwrap()).unwrap();
    let code =
        run(&["compare", &dir("a"), worse.to_str().unwrap(), "--out", &out, "--fail-on", "worse"]).unwrap();
    assert_eq!(code, std::process::ExitCode::from(harness::cli::EXIT_REGRESSION));
    let md = std::fs::read_to_string(work.path().join("comparison/compare.md")).unwrap();
    assert!(md.contains("worse: cylinder / arap / e_theta_deg"), "{md}");
    // Not a run: an error that names it.
    let e = format!("{:#}", run(&["compare", &dir("a"), &dir("nowhere")]).unwrap_err());
    assert!(e.contains("nowhere") && e.contains("results.json"), "{e}");
}

/// The procedural bar written to `dir` as GLB, then the mesh read back from it written as OFF and
/// binary PLY, so all three files hold the same numbers (GLB stores f32 positions).
fn bar_in_three_formats(dir: &Path) {
    let shape = generate(ShapeKind::Bar, 800).unwrap();
    meshes::io::write_glb(dir.join("bar.glb"), &shape.mesh, None).unwrap();
    let mesh = meshes::io::read_mesh(dir.join("bar.glb")).unwrap();
    meshes::io::write_off(dir.join("bar.off"), &mesh).unwrap();
    meshes::io::write_ply(dir.join("bar.ply"), &mesh).unwrap();
}

#[test]
fn the_same_mesh_in_off_ply_and_glb_gives_the_same_results() {
    let data = tempfile::tempdir().unwrap();
    bar_in_three_formats(data.path());
    let scenario = |ext: &str| {
        (
            format!("bar-{ext}.toml"),
            format!(
                "name = \"bar-{ext}\"\nmesh = \"{}\"\nmethods = [\"laplacian\", \"arap\", \"isolines\"]\n{FIXED_AND_HANDLE}",
                data.path().join(format!("bar.{ext}")).display()
            ),
        )
    };
    let configs = configs_with(&[scenario("off"), scenario("ply"), scenario("glb")]);
    let reports = tempfile::tempdir().unwrap();
    assert_eq!(all_with(configs.path(), reports.path()).unwrap(), std::process::ExitCode::SUCCESS);
    let json = read_json(&reports.path().join("results.json"));
    let cases = json["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 9);
    let of = |ext: &str| -> Vec<serde_json::Value> {
        cases
            .iter()
            .filter(|c| c["scenario"] == format!("bar-{ext}"))
            .map(|c| {
                let mut c = support::timeless(c);
                c.as_object_mut().unwrap().remove("scenario");
                c
            })
            .collect()
    };
    assert_eq!(of("off"), of("ply"), "PLY and OFF differ");
    assert_eq!(of("off"), of("glb"), "GLB and OFF differ");
    assert!(of("off").iter().all(|c| c["mesh_source"] == "file" && c["e_theta_deg"].as_f64().unwrap() > 0.1));
}

/// A fixed slab at the bottom of the bar and a handle slab at its top, moved sideways.
const FIXED_AND_HANDLE: &str = "[[regions]]\nname = \"base\"\nrole = \"fixed\"\n\
    select = { slab = { axis = \"z\", from = 0.0, to = 0.05 } }\n\
    [[regions]]\nname = \"top\"\nrole = \"handle\"\nselect = { slab = { axis = \"z\", from = 0.95, to = 1.0 } }\n\
    translate = [0.1, 0.0, 0.0]\n";

/// A scenario `tiny` with the line `mesh_line` (`DATA` stands for a data directory that `prepare`
/// fills; the procedural bar is there as `tiny.off`) and `regions`: `all` must fail naming every one
/// of `needles`, leaving the reports directory untouched.
fn expect_mesh_scenario_error(regions: &str, mesh_line: &str, prepare: impl Fn(&Path), needles: &[&str]) {
    let root = tempfile::tempdir().unwrap();
    let data = root.path().join("data");
    std::fs::create_dir(&data).unwrap();
    meshes::io::write_off(data.join("tiny.off"), &generate(ShapeKind::Bar, 500).unwrap().mesh).unwrap();
    prepare(&data);
    let text = format!("name = \"tiny\"\n{}\n{regions}", mesh_line.replace("DATA", data.to_str().unwrap()));
    let configs = configs_with(&[("tiny.toml".to_string(), text)]);
    let reports = root.path().join("reports");
    std::fs::create_dir(&reports).unwrap();
    std::fs::write(reports.join("sentinel.txt"), "untouched").unwrap();
    let result = all_with(configs.path(), &reports);
    let message = format!("{:#}", result.expect_err("bad input must be an error"));
    for needle in needles {
        assert!(message.contains(needle), "error {message:?} does not mention {needle:?}");
    }
    let written: Vec<_> = std::fs::read_dir(&reports).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(written, vec![std::ffi::OsString::from("sentinel.txt")], "reports/ was written to");
}

#[test]
fn a_glob_matching_nothing_is_rejected() {
    let needles = ["scenario `tiny`", "*.ply", "matches no file"];
    expect_mesh_scenario_error(FIXED_AND_HANDLE, "meshes = \"DATA/*.ply\"", |_| {}, &needles);
}

#[test]
fn an_empty_region_and_a_region_outside_the_mesh_are_rejected() {
    let top = "select = { slab = { axis = \"z\", from = 0.95, to = 1.0 } }";
    let with_top = |select: &str| FIXED_AND_HANDLE.replace(top, select);
    let mesh = "mesh = \"DATA/tiny.off\"";
    let outside = with_top("select = { box = { min = [2.0, 2.0, 2.0], max = [3.0, 3.0, 3.0] } }");
    expect_mesh_scenario_error(
        &outside,
        mesh,
        |_| {},
        &["scenario `tiny`", "region `top`", "holds no vertex"],
    );
    let empty = with_top("select = { vertices = [] }");
    expect_mesh_scenario_error(&empty, mesh, |_| {}, &["region `top`", "lists no vertex"]);
    let out_of_range = with_top("select = { vertices = [3, 100000] }");
    expect_mesh_scenario_error(
        &out_of_range,
        mesh,
        |_| {},
        &["region `top`", "vertex 100000 is out of range"],
    );
    let overlapping = with_top("select = { slab = { axis = \"z\", from = 0.0, to = 0.5 } }");
    expect_mesh_scenario_error(
        &overlapping,
        mesh,
        |_| {},
        &["scenario `tiny`", "in both handle `base` and handle `top`"],
    );
}

#[test]
fn a_ply_face_that_cannot_be_triangulated_names_the_file_and_face() {
    let write_ply = |data: &Path| {
        let ply =
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
                   element face 2\nproperty list uchar int vertex_indices\nend_header\n\
                   0 0 0\n1 0 0\n1 1 0\n0 1 1\n3 0 1 2\n2 2 3\n";
        std::fs::write(data.join("bad.ply"), ply).unwrap();
    };
    expect_mesh_scenario_error(
        FIXED_AND_HANDLE,
        "mesh = \"DATA/bad.ply\"",
        write_ply,
        &["bad.ply", "face 1"],
    );
}

#[test]
fn a_component_without_a_constrained_vertex_is_rejected() {
    // The bar and a copy far along x, which no region reaches.
    let two_bars = |data: &Path| {
        let bar = generate(ShapeKind::Bar, 500).unwrap().mesh;
        let n = bar.n_vertices() as u32;
        let mut p = bar.positions().to_vec();
        p.extend(bar.positions().iter().map(|q| [q[0] + 1000.0, q[1], q[2]]));
        let mut t = bar.triangles().to_vec();
        t.extend(bar.triangles().iter().map(|f| f.map(|v| v + n)));
        meshes::io::write_off(data.join("two.off"), &meshes::TriMesh::new(p, t).unwrap()).unwrap();
    };
    let near_only = FIXED_AND_HANDLE
        .replace(
            "select = { slab = { axis = \"z\", from = 0.0, to = 0.05 } }",
            "select = { box = { min = [0.0, 0.0, 0.0], max = [0.01, 1.0, 0.05] } }",
        )
        .replace(
            "select = { slab = { axis = \"z\", from = 0.95, to = 1.0 } }",
            "select = { box = { min = [0.0, 0.0, 0.95], max = [0.01, 1.0, 1.0] } }",
        );
    let needles = ["two.off", "connected component 1 of 2", "no fixed or handle vertex"];
    expect_mesh_scenario_error(&near_only, "mesh = \"DATA/two.off\"", two_bars, &needles);
}

#[test]
fn unreferenced_vertices_are_dropped_and_results_keep_the_input_order() {
    let root = tempfile::tempdir().unwrap();
    let bar = generate(ShapeKind::Bar, 500).unwrap().mesh;
    // Vertex 0 becomes an unreferenced stray: every face index moves up by one.
    let mut p = vec![[5.0, 5.0, 5.0]];
    p.extend_from_slice(bar.positions());
    let t: Vec<[u32; 3]> = bar.triangles().iter().map(|f| f.map(|v| v + 1)).collect();
    let path = root.path().join("stray.off");
    meshes::io::write_off(&path, &meshes::TriMesh::new(p.clone(), t).unwrap()).unwrap();
    let text =
        format!("name = \"stray\"\nmesh = \"{}\"\nmethods = [\"arap\"]\n{FIXED_AND_HANDLE}", path.display());
    let configs = configs_with(&[("stray.toml".to_string(), text)]);
    let reports = root.path().join("reports");
    assert_eq!(all_with(configs.path(), &reports).unwrap(), std::process::ExitCode::SUCCESS);
    let result = meshes::io::read_mesh(reports.join("meshes/stray-arap.glb")).unwrap();
    assert_eq!(result.n_vertices(), p.len(), "written in the input's vertex order, the stray included");
    assert_eq!(result.positions()[0], [5.0, 5.0, 5.0], "the stray stays where it was");
    assert_eq!(result.triangles()[0], bar.triangles()[0].map(|v| v + 1));
    let page = std::fs::read_to_string(reports.join("index.html")).unwrap();
    assert!(page.contains("1 unreferenced vertices dropped"), "the note is on the page");
}

/// `refine`: each level makes four faces of one, and a slab picks the same old vertices on the
/// refined mesh (midpoint keeps the file's shape and box) with new ones between them; Loop keeps the
/// boundary loops and the Euler characteristic (a closed mesh stays closed and of its genus; the
/// meshes crate tests that on closed shapes too). Regions by vertex id and procedural
/// shapes are refused, naming the key.
#[test]
fn a_refined_mesh_file_keeps_its_regions_and_topology() {
    use harness::scenario::{load_spec, DataSource};
    let root = tempfile::tempdir().unwrap();
    let bar = generate(ShapeKind::Bar, 600).unwrap().mesh;
    let path = root.path().join("bar.off");
    meshes::io::write_off(&path, &bar).unwrap();
    let load = |refine: u32, scheme: &str| {
        let file = root.path().join(format!("bar-{refine}-{scheme}.toml"));
        let text = format!(
            "name = \"bar\"\nmesh = \"{}\"\nrefine = {refine}\nrefine_scheme = \"{scheme}\"\n{FIXED_AND_HANDLE}",
            path.display()
        );
        std::fs::write(&file, text).unwrap();
        let mut loaded = load_spec(&file).unwrap().load(&DataSource::Procedural).unwrap();
        loaded.scenarios.remove(0)
    };
    let euler = |s: &harness::scenario::LoadedScenario| {
        s.mesh.n_vertices() as i64 - s.topology.edges().len() as i64 + s.mesh.n_faces() as i64
    };
    let plain = load(0, "midpoint");
    let regions = |s: &harness::scenario::LoadedScenario| -> Vec<Vec<u32>> {
        s.steps[0].handles.regions().iter().map(|r| r.vertices.clone()).collect()
    };
    for levels in 1..=2u32 {
        let fine = load(levels, "midpoint");
        assert_eq!(fine.mesh.n_faces(), bar.n_faces() * 4usize.pow(levels));
        assert_eq!(euler(&fine), euler(&plain));
        for (old, new) in regions(&plain).iter().zip(regions(&fine)) {
            let kept: Vec<u32> = new.iter().copied().filter(|&v| (v as usize) < bar.n_vertices()).collect();
            assert_eq!(&kept, old, "the same old vertices");
            assert!(
                new.len() > 2 * old.len(),
                "and the new ones between them: {} of {}",
                new.len(),
                old.len()
            );
        }
        assert!(
            fine.notes.iter().any(|n| n.contains("refined by") && n.contains("midpoint")),
            "{:?}",
            fine.notes
        );
    }
    let smooth = load(1, "loop");
    assert_eq!(smooth.topology.is_closed(), plain.topology.is_closed());
    assert_eq!(smooth.topology.boundary_loops().len(), plain.topology.boundary_loops().len());
    assert_eq!(euler(&smooth), euler(&plain), "the same genus");
    for (old, new) in regions(&plain).iter().zip(regions(&smooth)) {
        let kept = new.iter().filter(|&&v| (v as usize) < bar.n_vertices() && old.contains(&v)).count();
        assert!(
            kept as f64 >= 0.9 * old.len() as f64,
            "Loop moves the surface little: {kept} of {}",
            old.len()
        );
    }
    let refused = |text: String| {
        let file = root.path().join("refused.toml");
        std::fs::write(&file, text).unwrap();
        load_spec(&file).unwrap_err().to_string()
    };
    let e = refused("name = \"p\"\nprocedural = { shape = \"bar\" }\nrefine = 1\n".into());
    assert!(e.contains("refine") && e.contains("refused.toml"), "{e}");
    let e = refused(format!(
        "name = \"ids\"\nmesh = \"{}\"\nrefine = 1\n[[regions]]\nname = \"few\"\nrole = \"fixed\"\n\
         select = {{ vertices = [0, 1, 2] }}\n",
        path.display()
    ));
    assert!(e.contains("region `few`") && e.contains("bounding-box coordinates"), "{e}");
}

/// The real-mesh suite (`configs/real-meshes`): four meshes of `../shared/real-meshes` in OFF and
/// OBJ and an open terrain of its dataset, edited by scenarios written only in TOML (the knight and
/// the head bust with libigl's own `.dmat` selections, the bunny, the 43K armadillo and the terrain
/// with shape selections), every method run on each, and the run gated against its own committed
/// baseline (`reports/baselines/real-meshes.json`, issue 35).
#[test]
fn the_real_mesh_suite_runs_from_toml_alone_and_passes_its_gate() {
    let Some(_) = support::real_meshes_dir() else { return };
    let reports = tempfile::tempdir().unwrap();
    let scenarios = support::workspace_root().join("configs/real-meshes");
    let args = [
        "all",
        "--quiet",
        "--scenarios",
        scenarios.to_str().unwrap(),
        "--reports",
        reports.path().to_str().unwrap(),
    ];
    assert_eq!(run(&args).unwrap(), std::process::ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.path().join("results.csv"));
    let tests = [("knight", 502), ("max", 5272), ("bunny", 3485), ("armadillo", 43243), ("mountain", 25600)];
    assert_eq!(
        rows.len(),
        tests.len() * configured_methods(),
        "every method of configs/methods.toml on each test"
    );
    for (scenario, vertices) in tests {
        for row in rows.iter().filter(|r| r["scenario"] == scenario) {
            assert_eq!(row["mesh_source"], "file");
            assert_eq!(row["vertices"], vertices.to_string(), "{scenario}");
            assert!(!row["status"].starts_with("failed"), "{scenario}/{}: {}", row["method"], row["status"]);
        }
    }
    // The run was gated: its page names the real-mesh baseline, and `check` reads the same one.
    let page = std::fs::read_to_string(reports.path().join("index.html")).unwrap();
    assert!(page.contains("real-meshes.json"), "the page names the baseline it was checked against");
    let dir = reports.path().to_str().unwrap();
    assert_eq!(run(&["check", "--reports", dir]).unwrap(), std::process::ExitCode::SUCCESS);
    // libigl's knight selection: region 0 held, 1 and 2 moved (three regions, 73 vertices).
    let updates = support::csv_rows(&reports.path().join("handle_updates.csv"));
    let knight = updates.iter().find(|u| u["scenario"] == "knight" && u["method"] == "arap").unwrap();
    assert_eq!((knight["handles"].as_str(), knight["constrained_vertices"].as_str()), ("3", "73"));
    let result = meshes::io::read_mesh(reports.path().join("meshes/max-isolines.glb")).unwrap();
    assert_eq!(result.n_vertices(), 5272, "written in the OBJ's vertex order");
}

/// Issue 35: the real-mesh gate catches a method's own regression on real data. `laplacian` with
/// the one-ring frame of its Laplacian coordinates (commit 1744ef1's, which crumpled open scans) on
/// the open terrain of the real-mesh suite fails the gate against the committed baseline.
#[test]
fn the_real_mesh_gate_catches_laplacian_with_the_one_ring_frame() {
    let Some(_) = support::real_meshes_dir() else { return };
    let root = support::workspace_root();
    let terrain = std::fs::read_to_string(root.join("configs/real-meshes/mountain.toml")).unwrap();
    let terrain = terrain.replacen("[[regions]]", "methods = [\"arap\", \"laplacian\"]\n\n[[regions]]", 1);
    let configs = configs_with(&[("mountain.toml".to_string(), terrain)]);
    edit_laplacian_section(configs.path(), "delta_frame = \"normal_edge\"", "delta_frame = \"one_ring\"");
    let reports = tempfile::tempdir().unwrap();
    let baseline = root.join("reports/baselines/real-meshes.json");
    let code = run(&[
        "all",
        "--quiet",
        "--configs",
        configs.path().to_str().unwrap(),
        "--baseline",
        baseline.to_str().unwrap(),
        "--reports",
        reports.path().to_str().unwrap(),
    ])
    .unwrap();
    assert_eq!(code, std::process::ExitCode::from(harness::cli::EXIT_REGRESSION));
    let rows = support::csv_rows(&reports.path().join("results.csv"));
    let status = |method: &str| rows.iter().find(|r| r["method"] == method).unwrap()["status"].clone();
    assert_eq!(status("arap"), "ok", "the reference is untouched");
    assert!(
        status("laplacian").starts_with("unfinished: stopped at the 2000-iteration cap"),
        "{}",
        status("laplacian")
    );
    let page = std::fs::read_to_string(reports.path().join("index.html")).unwrap();
    assert!(page.contains("turned unfinished: mountain / laplacian"), "the gate names the case");
    assert!(page.contains("worse: mountain / laplacian / e_phi_deg"), "and its E_phi");
}

/// A collection: one scenario `<name>-<stem>` per file the glob matches (sorted), the same shape
/// rule on each, and the `{stem}` of a region file naming each mesh's own.
#[test]
fn a_collection_runs_one_scenario_per_matching_mesh() {
    let root = tempfile::tempdir().unwrap();
    for (stem, n) in [("b-large", 900), ("a-small", 500)] {
        let shape = generate(ShapeKind::Bar, n).unwrap();
        meshes::io::write_off(root.path().join(format!("{stem}.off")), &shape.mesh).unwrap();
        meshes::io::write_selection(root.path().join(format!("{stem}.sel")), &shape.selection).unwrap();
    }
    std::fs::write(root.path().join("notes.txt"), "not a mesh").unwrap();
    let text = format!(
        "name = \"bars\"\nmeshes = \"{}/*.off\"\nmethods = [\"arap\"]\n\
         [[regions]]\nname = \"base\"\nrole = \"fixed\"\nselect = {{ sel = {{ file = \"{}/{{stem}}.sel\", status = 0 }} }}\n\
         [[regions]]\nname = \"top\"\nrole = \"handle\"\nselect = {{ slab = {{ axis = \"z\", from = 0.95, to = 1.0 }} }}\n\
         translate = [0.1, 0.0, 0.0]\n",
        root.path().display(),
        root.path().display()
    );
    let configs = configs_with(&[("bars.toml".to_string(), text)]);
    let reports = root.path().join("reports");
    assert_eq!(all_with(configs.path(), &reports).unwrap(), std::process::ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.join("results.csv"));
    let names: Vec<(&str, &str)> =
        rows.iter().map(|r| (r["scenario"].as_str(), r["vertices"].as_str())).collect();
    let sizes: Vec<usize> = ["a-small", "b-large"]
        .iter()
        .map(|s| meshes::io::read_mesh(root.path().join(format!("{s}.off"))).unwrap().n_vertices())
        .collect();
    assert_eq!(
        names,
        [("bars-a-small", sizes[0].to_string().as_str()), ("bars-b-large", sizes[1].to_string().as_str())]
    );
    assert!(rows.iter().all(|r| r["status"] == "ok"), "{rows:?}");
}

/// Issue 18: result meshes are GLB by default, OFF or both on request, and a scenario with
/// `result_meshes = false` writes none unless `--every-mesh` asks.
#[test]
fn mesh_format_and_every_mesh_choose_the_result_files() {
    let scenario = |name: &str, extra: &str| {
        (
            format!("{name}.toml"),
            format!(
                "name = \"{name}\"\nprocedural = {{ shape = \"bar\", vertices = 600 }}\n\
                 methods = [\"laplacian\"]\n{extra}"
            ),
        )
    };
    let configs = configs_with(&[scenario("kept", ""), scenario("sweep", "result_meshes = false\n")]);
    let work = tempfile::tempdir().unwrap();
    let files = |args: &[&str]| -> Vec<String> {
        let reports = work.path().join(args.join("_").replace('-', ""));
        let mut full = vec![
            "all",
            "--quiet",
            "--configs",
            configs.path().to_str().unwrap(),
            "--reports",
            reports.to_str().unwrap(),
        ];
        full.extend_from_slice(args);
        full.push("--no-check");
        assert_eq!(run(&full).unwrap(), std::process::ExitCode::SUCCESS, "{args:?}");
        let mut names: Vec<String> = std::fs::read_dir(reports.join("meshes"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    };
    assert_eq!(files(&[]), ["kept-laplacian.glb"]);
    assert_eq!(files(&["--mesh-format", "off"]), ["kept-laplacian.off"]);
    assert_eq!(
        files(&["--mesh-format", "both", "--every-mesh"]),
        ["kept-laplacian.glb", "kept-laplacian.off", "sweep-laplacian.glb", "sweep-laplacian.off"]
    );
    // The OFF file holds the full-precision shape, the GLB the same mesh in f32.
    let dir = work.path().join("meshformat_both_everymesh/meshes");
    let (off, glb) = (
        meshes::io::read_mesh(dir.join("kept-laplacian.off")).unwrap(),
        meshes::io::read_mesh(dir.join("kept-laplacian.glb")).unwrap(),
    );
    assert_eq!(off.triangles(), glb.triangles());
    let worst = off
        .positions()
        .iter()
        .zip(glb.positions())
        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
        .fold(0.0, f64::max);
    // f32 rounding: half a unit in the last place, about 6e-8 of the coordinates' size.
    assert!(worst <= 1e-7 * off.bbox_diagonal(), "GLB positions {worst:e} from the OFF ones");
}

/// Issue 37: scenarios sharing `series` are one shape at several sizes: `size-series.md` has a row
/// per case and per method a scenario left out (with its reason, also a note on the page), the
/// fitted slopes, and `plots/size-series`. `left_out` naming no method, or without a reason, is
/// refused; meshes above 200K vertices write no result mesh or view file unless asked.
#[test]
fn a_size_series_tabulates_its_cases_slopes_and_left_out_methods() {
    let bar = |name: &str, n: usize, extra: &str| {
        (
            format!("{name}.toml"),
            format!(
                "name = \"{name}\"\nprocedural = {{ shape = \"bar\", vertices = {n} }}\nseries = \"bar\"\n\
                 methods = [\"laplacian\", \"arap\", \"isolines\"]\n{extra}"
            ),
        )
    };
    let configs = configs_with(&[
        bar("bar-a", 600, ""),
        bar("bar-b", 1500, ""),
        bar("bar-c", 3000, "[left_out]\nisolines = \"too slow here: 1 h measured\"\n"),
    ]);
    let reports = tempfile::tempdir().unwrap();
    let args = ["--no-check"];
    let mut full = vec!["all", "--quiet", "--configs", configs.path().to_str().unwrap()];
    full.extend(["--reports", reports.path().to_str().unwrap()]);
    full.extend(args);
    assert_eq!(run(&full).unwrap(), std::process::ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.path().join("results.csv"));
    assert_eq!(rows.len(), 8, "3 methods x 3 sizes, less the one left out");
    let md = std::fs::read_to_string(reports.path().join("size-series.md")).unwrap();
    assert!(md.contains("## bar"), "{md}");
    assert!(
        md.contains("| isolines | bar-c |") && md.contains("left out: too slow here: 1 h measured"),
        "{md}"
    );
    for method in ["laplacian", "arap"] {
        let slopes =
            md.lines().find(|l| l.starts_with(&format!("| {method} | ")) && l.ends_with(" 3 |")).unwrap();
        let per_edit: f64 = slopes.split('|').nth(2).unwrap().trim().parse().unwrap();
        assert!(per_edit > 0.0 && per_edit < 4.0, "{method}: time per edit grows with #V: {slopes}");
    }
    assert!(reports.path().join("plots/size-series.png").is_file());
    let page = std::fs::read_to_string(reports.path().join("index.html")).unwrap();
    assert!(page.contains("Cost against size") && page.contains("left out `isolines` on `bar-c`"));

    use harness::scenario::{load_spec, DataSource};
    let refused = |text: &str| {
        let file = configs.path().join("refused.toml");
        std::fs::write(&file, text).unwrap();
        load_spec(&file).unwrap_err().to_string()
    };
    let e = refused("name = \"p\"\nprocedural = { shape = \"bar\" }\n[left_out]\narap = \" \"\n");
    assert!(e.contains("left_out.arap") && e.contains("reason"), "{e}");
    std::fs::write(
        configs.path().join("scenarios/bar-d.toml"),
        "name = \"d\"\nprocedural = { shape = \"bar\" }\n[left_out]\nhirn = \"x\"\n",
    )
    .unwrap();
    let err = format!("{:#}", all_with(configs.path(), &reports.path().join("again")).unwrap_err());
    assert!(err.contains("bar-d.toml") && err.contains("unknown method `hirn`"), "{err}");

    let writes = |n: usize, extra: &str| {
        let file = configs.path().join("size.toml");
        std::fs::write(
            &file,
            format!("name = \"s\"\nprocedural = {{ shape = \"bar\", vertices = {n} }}\n{extra}"),
        )
        .unwrap();
        load_spec(&file).unwrap().load(&DataSource::Procedural).unwrap().scenarios[0].writes_result_meshes()
    };
    assert!(writes(600, ""));
    assert!(!writes(600, "result_meshes = false\n"));
    assert!(!writes(250_000, ""), "above 200K vertices: only when asked");
    assert!(writes(250_000, "result_meshes = true\n"));
}

/// Issue 24: a case stopped at its iteration cap is `unfinished` (with where it stopped) in the
/// CSV and on the page, and the gate fails when a case that was `ok` in the baseline ends so.
#[test]
fn a_case_stopped_at_its_cap_is_unfinished_and_the_gate_sees_it() {
    let scenario = (
        "bar.toml".to_string(),
        "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 600 }\nmethods = [\"arap\", \"laplacian\"]\n"
            .to_string(),
    );
    let configs = configs_with(&[scenario]);
    let work = tempfile::tempdir().unwrap();
    let dir = |name: &str| work.path().join(name).to_str().unwrap().to_string();
    let (config_dir, baseline) = (configs.path().to_str().unwrap(), dir("baseline.json"));
    let all = |reports: &str| {
        run(&["all", "--quiet", "--configs", config_dir, "--reports", reports, "--baseline", &baseline])
            .unwrap()
    };
    let first = dir("first");
    let first_run =
        run(&["all", "--quiet", "--configs", config_dir, "--reports", &first, "--no-check"]).unwrap();
    assert_eq!(first_run, std::process::ExitCode::SUCCESS);
    assert!(support::csv_rows(&work.path().join("first/results.csv")).iter().all(|r| r["status"] == "ok"));
    assert_eq!(
        run(&["baseline", "--reports", &first, "--baseline", &baseline]).unwrap(),
        std::process::ExitCode::SUCCESS
    );
    assert_eq!(all(&dir("same")), std::process::ExitCode::SUCCESS, "the same run passes its own baseline");

    // laplacian capped at 2 iterations: it cannot reach its tolerance.
    edit_laplacian_section(configs.path(), "max_iterations = 2000", "max_iterations = 2");
    let second = dir("second");
    assert_eq!(all(&second), std::process::ExitCode::from(harness::cli::EXIT_REGRESSION));
    let rows = support::csv_rows(&work.path().join("second/results.csv"));
    let status = |method: &str| rows.iter().find(|r| r["method"] == method).unwrap()["status"].clone();
    assert_eq!(status("arap"), "ok");
    let laplacian = status("laplacian");
    assert!(
        laplacian.starts_with("unfinished: stopped at the 2-iteration cap, last step ")
            && laplacian.contains("of the diagonal, estimated ")
            && laplacian.contains("from the fixed point (tolerance 1e-5)"),
        "{laplacian}"
    );
    let page = std::fs::read_to_string(work.path().join("second/index.html")).unwrap();
    assert!(
        page.contains("<tr class=\"unfinished\" data-scenario=\"bar\" data-method=\"laplacian\"")
            && page.contains("turned unfinished: bar / laplacian")
    );
    assert_eq!(
        run(&["check", "--reports", &second, "--baseline", &baseline]).unwrap(),
        std::process::ExitCode::from(harness::cli::EXIT_REGRESSION)
    );
}

#[test]
fn sweeps_add_points_named_by_their_values_and_a_budget_table_that_picks_the_best_ok_one() {
    // No `methods` list: every method runs on it, and the sweep points where sweeps.toml says.
    let configs = configs_with(&[(
        "bar.toml".to_string(),
        "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 800 }\n".to_string(),
    )]);
    std::fs::write(
        configs.path().join("sweeps.toml"),
        "scenarios = [\"bar\"]\n[per_field]\nmethod = \"isolines\"\nparams = { isolines = [5, 10, 20] }\n\
         [arap_tolerance]\nmethod = \"arap\"\nparams = { tolerance = [1e-3, 1e-5] }\n",
    )
    .unwrap();
    let reports = tempfile::tempdir().unwrap();
    let configs = configs.path().to_str().unwrap();
    let out = reports.path().to_str().unwrap();
    let args = ["all", "--quiet", "--sweeps", "--configs", configs, "--reports", out, "--no-check"];
    assert_eq!(run(&args).unwrap(), std::process::ExitCode::SUCCESS);

    let rows = support::csv_rows(&reports.path().join("results.csv"));
    let names: Vec<&str> = rows.iter().map(|r| r["method"].as_str()).collect();
    for point in ["isolines[isolines=5]", "isolines[isolines=10]", "arap[tolerance=1e-3]"] {
        assert!(names.contains(&point), "{point} missing from {names:?}");
    }
    // The points equal to their base's table are the base methods, not run twice.
    assert!(
        !names.iter().any(|n| *n == "isolines[isolines=20]" || *n == "arap[tolerance=1e-5]"),
        "{names:?}"
    );
    let json = read_json(&reports.path().join("results.json"));
    let isolines = json["cases"].as_array().unwrap().iter().find(|c| c["method"] == "isolines").unwrap();
    assert_eq!(isolines["sweeps"][0]["sweep"], "per_field");
    assert_eq!(isolines["sweeps"][0]["position"], 2);
    // A point runs with its values: its model has fewer isolines than the base's 20 per field.
    let case =
        |name: &str| json["cases"].as_array().unwrap().iter().find(|c| c["method"] == name).unwrap().clone();
    let isolines_of = |c: &serde_json::Value| {
        let stats = c["statistics"].as_array().unwrap();
        let n = stats.iter().find(|s| s[0] == methods::keys::statistic::N_ISOLINES).expect("n_isolines");
        n[1].as_f64().unwrap()
    };
    let (coarse, base) = (isolines_of(&case("isolines[isolines=5]")), isolines_of(&case("isolines")));
    assert!(coarse > 0.0 && coarse < base, "n_isolines: {coarse} with 5 per field, {base} with 20");

    assert!(reports.path().join("plots/bar-pareto.png").is_file());
    let page = std::fs::read_to_string(reports.path().join("index.html")).unwrap();
    assert!(page.contains("id=\"quality-time\"") && page.contains("plots/bar-pareto.png"));
    // The 10 s row of the budget table names the ok case with the lowest E_theta within 10 s per edit.
    let pareto = std::fs::read_to_string(reports.path().join("pareto.md")).unwrap();
    let row = pareto.lines().find(|l| l.starts_with("| 10 s |")).expect("a 10 s row");
    let best = rows
        .iter()
        .filter(|r| r["status"] == "ok" && support::num(r, "bind_s") + support::num(r, "solve_s") <= 10.0)
        .min_by(|a, b| support::num(a, "e_theta_deg").total_cmp(&support::num(b, "e_theta_deg")))
        .unwrap();
    let cell = row.split('|').nth(2).unwrap().trim();
    assert!(
        cell.starts_with(&format!("{}:", best["method"])),
        "10 s row `{cell}`, best ok {}",
        best["method"]
    );
}

/// Issue 36: a collection from a manifest, its rows filtered by their columns, an edit taken from
/// another file (`extends`); a mesh that cannot run (a zero-area face; a component no region
/// reaches) is skipped with its reason, listed in results.json and on the page, and the others run.
/// A collection whose every mesh is skipped is an error that names the first reason.
#[test]
fn a_manifest_collection_skips_the_meshes_that_cannot_run_and_runs_the_others() {
    let data = tempfile::tempdir().unwrap();
    let bar = generate(ShapeKind::Bar, 500).unwrap().mesh;
    meshes::io::write_off(data.path().join("good.off"), &bar).unwrap();
    meshes::io::write_off(data.path().join("big.off"), &generate(ShapeKind::Bar, 2000).unwrap().mesh)
        .unwrap();
    let mut flat = bar.positions().to_vec();
    let t0 = bar.triangles()[0];
    flat[t0[2] as usize] = flat[t0[0] as usize];
    std::fs::write(data.path().join("flat.off"), {
        let mut off = format!("OFF\n{} {} 0\n", flat.len(), bar.n_faces());
        flat.iter().for_each(|p| off += &format!("{} {} {}\n", p[0], p[1], p[2]));
        bar.triangles().iter().for_each(|t| off += &format!("3 {} {} {}\n", t[0], t[1], t[2]));
        off
    })
    .unwrap();
    // The bar and a small copy of it beside its middle, which neither end region reaches.
    let n = bar.n_vertices() as u32;
    let (lo, hi) = bar.bbox();
    let middle: [f64; 3] = std::array::from_fn(|c| 0.5 * (lo[c] + hi[c]));
    let mut p = bar.positions().to_vec();
    p.extend(bar.positions().iter().map(|q| {
        std::array::from_fn(|c| {
            middle[c] + 0.05 * (q[c] - middle[c]) + if c == 0 { 2.0 * (hi[0] - lo[0]) } else { 0.0 }
        })
    }));
    let mut t = bar.triangles().to_vec();
    t.extend(bar.triangles().iter().map(|f| f.map(|v| v + n)));
    meshes::io::write_off(data.path().join("two.off"), &meshes::TriMesh::new(p, t).unwrap()).unwrap();
    let manifest =
        "file,vertices,category\ngood.off,500,bar\nflat.off,500,bar\ntwo.off,1000,pair\nbig.off,2000,bar\n";
    std::fs::write(data.path().join("MANIFEST.csv"), manifest).unwrap();

    let edit = "name = \"bend\"\nmethods = [\"arap\", \"laplacian\"]\nframe = \"principal\"\n\
                [[regions]]\nname = \"held\"\nrole = \"fixed\"\nselect = { box = { min = [0.0, 0.0, 0.0], max = [0.1, 1.0, 1.0] } }\n\
                [[regions]]\nname = \"moved\"\nrole = \"handle\"\nselect = { box = { min = [0.9, 0.0, 0.0], max = [1.0, 1.0, 1.0] } }\n\
                rotate = { axis = [0, 1, 0], degrees = 30, about = \"centroid\" }\n";
    let family = tempfile::tempdir().unwrap();
    std::fs::write(family.path().join("bend.toml"), edit).unwrap();
    let tier = |conditions: &str| {
        format!(
            "extends = \"{}\"\n[manifest]\nfile = \"{}\"\nwhere = [{conditions}]\n",
            family.path().join("bend.toml").display(),
            data.path().join("MANIFEST.csv").display()
        )
    };
    let configs = configs_with(&[("bend.toml".to_string(), tier("\"vertices <= 1000\""))]);
    let reports = tempfile::tempdir().unwrap();
    let code = all_with(configs.path(), reports.path()).unwrap();
    assert_eq!(code, std::process::ExitCode::SUCCESS);
    let rows = support::csv_rows(&reports.path().join("results.csv"));
    let cases: Vec<(&str, &str)> =
        rows.iter().map(|r| (r["scenario"].as_str(), r["method"].as_str())).collect();
    assert_eq!(cases, [("bend-good", "laplacian"), ("bend-good", "arap")], "big.off is filtered out");
    let json = read_json(&reports.path().join("results.json"));
    let skipped = json["skipped"].as_array().expect("results.json lists the skipped meshes");
    let reasons: Vec<(&str, &str)> =
        skipped.iter().map(|s| (s["scenario"].as_str().unwrap(), s["reason"].as_str().unwrap())).collect();
    assert_eq!(reasons.len(), 2, "{reasons:?}");
    assert_eq!(reasons[0].0, "bend-flat");
    assert!(reasons[0].1.contains("flat.off") && reasons[0].1.contains("zero area"), "{reasons:?}");
    assert_eq!(reasons[1].0, "bend-two");
    assert!(reasons[1].1.contains("connected component 1 of 2"), "{reasons:?}");
    assert_eq!(json["cases"][0]["member"]["collection"], "bend");
    assert_eq!(json["cases"][0]["member"]["mesh"], "good");
    let page = std::fs::read_to_string(reports.path().join("index.html")).unwrap();
    assert!(page.contains("skipped `bend-flat`") && page.contains("skipped `bend-two`"));

    // `repair = true` drops the zero-area face: the mesh runs and its record says what changed.
    let repaired = format!("repair = true\n{}", tier("\"vertices <= 500\""));
    let configs = configs_with(&[("bend.toml".to_string(), repaired)]);
    assert_eq!(all_with(configs.path(), reports.path()).unwrap(), std::process::ExitCode::SUCCESS);
    let json = read_json(&reports.path().join("results.json"));
    let flat = json["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["scenario"] == "bend-flat")
        .expect("bend-flat ran");
    assert_eq!(flat["status"], "ok");
    let what = flat["member"]["repaired"].as_str().unwrap();
    // Vertex t0[2] moved onto t0[0]: face 0 and its neighbour across that edge lose their area.
    assert!(what.starts_with("2 zero-area faces dropped (e.g. face 0)"), "{what}");
    let dataset = std::fs::read_to_string(reports.path().join("dataset.md")).unwrap();
    assert!(dataset.contains("- flat: 2 zero-area faces dropped"), "{dataset}");

    let configs = configs_with(&[("bend.toml".to_string(), tier("\"category = \\\"pair\\\"\""))]);
    let message = format!("{:#}", all_with(configs.path(), reports.path()).unwrap_err());
    assert!(
        message.contains("every one of its 1 meshes was skipped") && message.contains("two.off"),
        "{message}"
    );
    let configs = configs_with(&[("bend.toml".to_string(), tier("\"genus >= 1\""))]);
    let message = format!("{:#}", all_with(configs.path(), reports.path()).unwrap_err());
    assert!(message.contains("no column `genus`"), "{message}");
}

/// Issue 36: the dataset's smoke set (six small meshes of the 79, every edit family, every method
/// the families name) runs from its TOML files alone, repairs the mesh with zero-area faces, writes
/// the dataset report (robustness table, error spread, cost slopes, ECDF and cost plots, one
/// worst-case sheet per family, the page's section and filters) and passes its committed gate.
#[test]
fn the_dataset_smoke_set_runs_every_family_and_passes_its_gate() {
    let Some(_) = support::dataset_dir() else { return };
    let reports = tempfile::tempdir().unwrap();
    let scenarios = support::workspace_root().join("configs/dataset-smoke");
    let args = [
        "all",
        "--quiet",
        "--scenarios",
        scenarios.to_str().unwrap(),
        "--reports",
        reports.path().to_str().unwrap(),
    ];
    let code = run(&args).unwrap();
    let json = read_json(&reports.path().join("results.json"));
    let cases = json["cases"].as_array().unwrap();
    let families = ["bend", "pull", "stretch", "twist", "two-handles"];
    let meshes = ["africanhead", "alligator", "bamboopen", "block", "goathead", "shark"];
    let methods = ["laplacian", "arap", "hirm", "spectral_mhb", "scale_aware", "isolines"];
    assert_eq!(cases.len(), families.len() * meshes.len() * methods.len());
    assert!(json.get("skipped").is_none(), "every mesh of the smoke set runs (shark repaired)");
    for c in cases {
        let member = &c["member"];
        assert!(families.contains(&member["collection"].as_str().unwrap()), "{member}");
        assert!(meshes.contains(&member["mesh"].as_str().unwrap()), "{member}");
        let repaired = member["repaired"].as_str();
        assert_eq!(repaired.is_some(), member["mesh"] == "shark", "{member}");
    }
    assert_eq!(
        code,
        std::process::ExitCode::SUCCESS,
        "no failed case and no regression against the committed gate"
    );

    let dataset = std::fs::read_to_string(reports.path().join("dataset.md")).unwrap();
    for method in methods {
        assert!(dataset.contains(&format!("\n| {method} | ")), "dataset.md has a row for {method}");
    }
    for heading in
        ["## Robustness", "## Error spread, cost and rank", "## Cost growth", "## Worst ok results"]
    {
        assert!(dataset.contains(heading), "dataset.md: {heading}");
    }
    assert!(dataset.contains("- shark: 4 zero-area faces dropped"), "{dataset}");
    for file in ["plots/dataset-ecdf.png", "plots/dataset-cost.png", "plots/dataset-cost.svg"] {
        assert!(reports.path().join(file).is_file(), "{file}");
    }
    for family in families {
        assert!(reports.path().join(format!("figures/worst-{family}.png")).is_file(), "worst-{family}.png");
    }
    let page = std::fs::read_to_string(reports.path().join("index.html")).unwrap();
    assert!(page.contains("id=\"dataset\"") && page.contains("worst-twist.png"));
    assert!(
        page.contains("data-family=\"bend\" data-mesh=\"goathead\" data-surface=\"closed\" data-genus=\"0\"")
    );
    assert!(page.contains("dataset-smoke.json"), "the run was gated against the smoke set's baseline");
}
