//! The page's 3D view in headless Chromium: drawn with WebGL 2 where the browser has it (here
//! SwiftShader, Chromium's software GPU), with the 2D canvas where WebGL is off. The view reports
//! what it drew on `<div id="viewer">` (report/viewer.js): the renderer, the non-background pixels
//! of the smaller view, a checksum of both pictures, the left view's centre pixel, the picked vertex.

mod support;

use std::path::{Path, PathBuf};

/// Chromium's flags for WebGL 2 on SwiftShader: asked for by name, as the automatic fallback to it
/// (which `--disable-gpu` alone still gets) is deprecated.
const WEBGL: &[&str] = &["--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"];
/// No WebGL at all: `getContext('webgl2')` gives null and the view falls back to the 2D canvas.
const NO_WEBGL: &[&str] = &["--disable-gpu", "--disable-webgl"];

fn run(args: &[&str]) -> anyhow::Result<std::process::ExitCode> {
    let mut full = vec!["harness"];
    full.extend_from_slice(args);
    harness::cli::run(full)
}

/// The start tag of `<div id="viewer">` after headless Chromium (with `flags`) ran the page at
/// `url`, and what Chromium said on stderr.
fn viewer_after(chromium: &Path, url: &str, flags: &[&str]) -> (String, String) {
    let profile = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(chromium)
        .args(support::HEADLESS)
        .arg("--virtual-time-budget=30000")
        .args(flags)
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg("--dump-dom")
        .arg(url)
        .output()
        .expect("run chromium");
    let dom = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let tag = dom
        .split("<div id=\"viewer\"")
        .nth(1)
        .and_then(|rest| rest.split('>').next())
        .unwrap_or_else(|| panic!("no #viewer in the DOM of {url}; chromium said: {stderr}"))
        .to_string();
    (tag, stderr)
}

/// The value of attribute `name` in the start tag `tag` (its text up to `>`).
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    tag.split(&format!(" {name}=\"")).nth(1).and_then(|v| v.split('"').next())
}

/// The view as the page at `index` with `query` drew it in Chromium with `flags`.
struct Drawn {
    tag: String,
    stderr: String,
}

impl Drawn {
    fn open(chromium: &Path, index: &Path, query: &str, flags: &[&str]) -> Drawn {
        let url = format!("file://{}?{query}", index.display());
        let (tag, stderr) = viewer_after(chromium, &url, flags);
        Drawn { tag, stderr }
    }

    fn get(&self, name: &str) -> &str {
        attribute(&self.tag, name).unwrap_or_else(|| {
            panic!("no {name} on <div id=\"viewer\"{}>; chromium said: {}", self.tag, self.stderr)
        })
    }

    fn number(&self, name: &str) -> f64 {
        let value = self.get(name);
        value.parse().unwrap_or_else(|_| panic!("{name} = {value:?}"))
    }

    /// Drawn by `renderer`, with more than `pixels` non-background pixels in the smaller view and
    /// the mesh (not the white background) at the left view's centre, where the rest mesh's
    /// centre is.
    fn assert_drawn(&self, renderer: &str, pixels: f64) {
        assert_eq!(self.get("data-renderer"), renderer, "<div id=\"viewer\"{}>; {}", self.tag, self.stderr);
        assert_eq!(self.get("data-view"), "bar-arap");
        let drawn = self.number("data-pixels");
        assert!(drawn > pixels, "{renderer}: {drawn} drawn pixels in the smaller view");
        let centre: Vec<u8> = self.get("data-centre").split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(centre.len(), 3);
        assert!(centre.iter().any(|&c| c < 250), "{renderer}: the centre pixel {centre:?} is background");
        assert!(self.number("data-load-ms") >= 0.0 && self.number("data-redraw-ms") >= 0.0);
    }
}

/// A report of a procedural bar (2,000 vertices) deformed by laplacian and arap, in a temporary
/// directory: `(its directory, index.html)`.
fn bar_report() -> (tempfile::TempDir, PathBuf) {
    let configs = tempfile::tempdir().unwrap();
    std::fs::create_dir(configs.path().join("scenarios")).unwrap();
    for file in ["methods.toml", "verdicts.toml"] {
        std::fs::copy(support::workspace_root().join("configs").join(file), configs.path().join(file))
            .unwrap();
    }
    std::fs::write(
        configs.path().join("scenarios/bar.toml"),
        "name = \"bar\"\nprocedural = { shape = \"bar\", vertices = 2000 }\nmethods = [\"laplacian\", \"arap\"]\n",
    )
    .unwrap();
    let reports = tempfile::tempdir().unwrap();
    let code = run(&[
        "all",
        "--quiet",
        "--no-check",
        "--configs",
        configs.path().to_str().unwrap(),
        "--reports",
        reports.path().to_str().unwrap(),
    ])
    .unwrap();
    assert_eq!(code, std::process::ExitCode::SUCCESS);
    let index = reports.path().join("index.html").canonicalize().unwrap();
    (reports, index)
}

#[test]
fn the_view_draws_with_webgl2_and_without_it_on_the_2d_canvas_in_chromium() {
    let Some(chromium) = support::chromium() else { return };
    let (_reports, index) = bar_report();

    // WebGL 2: the mesh where it is expected, both views loaded and drawn with timings.
    let shaded = Drawn::open(&chromium, &index, "view=bar-arap&colour=shaded", WEBGL);
    shaded.assert_drawn("webgl2", 5_000.0);
    assert_eq!(shaded.get("data-left"), "rest");
    // Another colouring changes the picture, and so does turning the camera.
    let angle = Drawn::open(&chromium, &index, "view=bar-arap&colour=angle", WEBGL);
    angle.assert_drawn("webgl2", 5_000.0);
    assert_ne!(angle.get("data-checksum"), shaded.get("data-checksum"), "angle colouring drew the same");
    let turned = Drawn::open(&chromium, &index, "view=bar-arap&colour=shaded&yaw=2.1", WEBGL);
    turned.assert_drawn("webgl2", 5_000.0);
    assert_ne!(turned.get("data-checksum"), shaded.get("data-checksum"), "turning drew the same");
    // The same address draws the same picture (the checksum is of the picture, not of chance).
    let again = Drawn::open(&chromium, &index, "view=bar-arap&colour=shaded", WEBGL);
    assert_eq!(again.get("data-checksum"), shaded.get("data-checksum"));
    // Turning redraws: their median time. A click at the right view's centre picks a vertex (the
    // bar covers it from the default camera).
    let spun = Drawn::open(&chromium, &index, "view=bar-arap&left=laplacian&spin=5&pick=320,260", WEBGL);
    spun.assert_drawn("webgl2", 5_000.0);
    assert_eq!(spun.get("data-left"), "laplacian");
    assert_ne!(spun.get("data-checksum"), shaded.get("data-checksum"), "laplacian on the left, turned");
    assert!(spun.number("data-spin-ms") > 0.0);
    assert!(spun.number("data-picked") >= 0.0, "picked vertex {}", spun.get("data-picked"));

    // Above `turning=N` faces a turning redraw draws a coarser copy of the mesh (vertex clusters),
    // closed where the mesh is: about as many pixels as the full mesh; once the turning stops the
    // full mesh is drawn again, the very picture drawn without the copy.
    let coarse =
        Drawn::open(&chromium, &index, "view=bar-arap&left=laplacian&spin=5&pick=320,260&turning=400", WEBGL);
    let faces = coarse.number("data-turning-faces");
    assert!(faces > 100.0 && faces < 1_000.0, "{faces} faces while turning (the bar has about 4,000)");
    assert!(spun.number("data-turning-faces") > 3_000.0, "below the threshold every face is drawn");
    let (turning, still) = (coarse.number("data-turning-pixels"), coarse.number("data-pixels"));
    assert!((turning - still).abs() < 0.1 * still, "{turning} pixels while turning, {still} at rest");
    assert_eq!(coarse.get("data-checksum"), spun.get("data-checksum"), "the full mesh once turning stops");

    // No WebGL: the 2D canvas draws the same views, colours and picks.
    let fallback = Drawn::open(&chromium, &index, "view=bar-arap&colour=shaded&pick=320,260", NO_WEBGL);
    fallback.assert_drawn("canvas", 5_000.0);
    let fallback_angle = Drawn::open(&chromium, &index, "view=bar-arap&colour=angle", NO_WEBGL);
    fallback_angle.assert_drawn("canvas", 5_000.0);
    assert_ne!(fallback_angle.get("data-checksum"), fallback.get("data-checksum"));
    assert_eq!(fallback.get("data-picked"), spun.get("data-picked"), "both renderers pick the same vertex");
    // Both draw the same mesh from the same camera: their pixel counts agree to within 8%
    // (the 2D canvas smooths its edges, WebGL on a software GPU does not).
    let (gl, canvas) = (shaded.number("data-pixels"), fallback.number("data-pixels"));
    assert!((gl - canvas).abs() < 0.08 * canvas, "webgl2 drew {gl} pixels, the 2D canvas {canvas}");
}
