//! The history page: `index.html` with the steps found first (each with the commit that made it),
//! the commits and whether each changed method code, then one section per series × scenario ×
//! method with its timelines as a PNG (a panel per measure: the values, the `--repeat` spread as a
//! band, the fitted levels, the steps as red lines) and its steps; `steps.md` holds the steps table
//! for notes. Every file is written to a temporary name and renamed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::timeline::{AttributedStep, History, Timeline};
use super::HistoryError;
use crate::report::html::escape;

/// Panels per row of a case's figure.
const COLUMNS: usize = 3;
/// One panel's pixel size.
const PANEL: (u32, u32) = (520, 300);
/// The figure's title row, pixels.
const TITLE: u32 = 30;

/// Write the page of `history` into `out`; returns the index's path.
pub fn write_page(out: &Path, history: &History, store: &Path) -> Result<PathBuf, HistoryError> {
    crate::report::fonts::register_sans_serif()?;
    let plots = out.join("plots");
    std::fs::create_dir_all(&plots).map_err(|error| HistoryError::Io { path: plots.clone(), error })?;
    let cases = history.cases();
    let mut sections = String::new();
    for (i, key) in cases.iter().enumerate() {
        let timelines = history.case(key);
        let stem =
            format!("{i:03}-{}", crate::stored_report::case_file_stem(&key.case.scenario, &key.case.method));
        let png = PathBuf::from("plots").join(format!("{stem}.png"));
        draw_case(&out.join(&png), history, &timelines)?;
        section(&mut sections, history, &timelines, &png, i);
    }
    let page = render(history, store, &sections);
    write_atomically(&out.join("index.html"), page.as_bytes())?;
    write_atomically(&out.join("steps.md"), steps_markdown(history).as_bytes())?;
    Ok(out.join("index.html"))
}

fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), HistoryError> {
    meshes::io::atomic_write(path, |w| w.write_all(bytes).map_err(meshes::MeshError::from))
        .map_err(|e| HistoryError::Report(crate::HarnessError::Mesh(e)))
}

/// Every step of the history, one line each: where, how much, made by which commit.
pub fn all_steps(history: &History) -> Vec<(&Timeline, &AttributedStep)> {
    history.timelines.iter().flat_map(|t| t.steps.iter().map(move |s| (t, s))).collect()
}

/// The first `SUBJECT_CHARS` characters of a commit subject are shown.
const SUBJECT_CHARS: usize = 90;

/// `subject`, cut after [`SUBJECT_CHARS`] characters.
pub fn short_subject(subject: &str) -> String {
    if subject.chars().count() <= SUBJECT_CHARS {
        subject.to_string()
    } else {
        format!("{}…", subject.chars().take(SUBJECT_CHARS).collect::<String>())
    }
}

/// How many points the timelines have: `12 commits`, or `12 commits and 2 uncommitted changes`.
pub fn points_text(history: &History) -> String {
    let changes = history.commits.iter().filter(|c| c.dirty.is_some()).count();
    let commits = history.commits.len() - changes;
    match changes {
        0 => format!("{commits} commits"),
        n => format!("{commits} commits and {n} uncommitted change(s)"),
    }
}

/// One line on a step of `t`: where, how much, which commit.
pub fn step_line(history: &History, t: &Timeline, s: &AttributedStep) -> String {
    let [measure, before, after, change, commit] = step_texts(history, t, s);
    format!("{} / {} {measure}: {before} -> {after} ({change}), {commit}", t.scenario, t.method)
}

/// A step's measure, before, after, change and commit, as text.
fn step_texts(history: &History, t: &Timeline, s: &AttributedStep) -> [String; 5] {
    [t.measure.key().to_string(), value(s.before), value(s.after), change(s), step_commit(history, s)]
}

/// The commit a step is named with: the commit that made it, or the range it lies in.
pub fn step_commit(history: &History, step: &AttributedStep) -> String {
    match step.made_by {
        Some(c) => format!("{} {}", history.commits[c].label(), short_subject(&history.commits[c].subject)),
        None => format!(
            "between {} and {} (`harness history find` narrows it)",
            history.commits[step.from].label(),
            history.commits[step.to].label()
        ),
    }
}

fn change(step: &AttributedStep) -> String {
    if step.relative.is_finite() {
        format!("{:+.1}%", 100.0 * step.relative)
    } else {
        "from 0".to_string()
    }
}

/// [`step_texts`] escaped for the page.
fn step_fields(history: &History, t: &Timeline, s: &AttributedStep) -> [String; 5] {
    step_texts(history, t, s).map(|text| escape(&text))
}

fn steps_markdown(history: &History) -> String {
    let mut md = String::from("| series | scenario | method | measure | before | after | change | commit |\n|---|---|---|---|---|---|---|---|\n");
    for (t, s) in all_steps(history) {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} |",
            t.series,
            t.scenario,
            t.method,
            step_texts(history, t, s).join(" | ")
        );
    }
    md
}

fn value(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-2 || v.abs() >= 1e5) {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// An axis label: four significant digits, no trailing zeros.
fn axis_value(v: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    if v.abs() < 1e-3 || v.abs() >= 1e6 {
        return format!("{v:.2e}");
    }
    let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

fn render(history: &History, store: &Path, sections: &str) -> String {
    let mut page = String::from(
        "<!doctype html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>deformbench: history</title>\
         <style>body{font-family:sans-serif;margin:1.5em;max-width:1700px}table{border-collapse:collapse;margin:.5em 0}\
         td,th{border:1px solid #ccc;padding:2px 6px;font-size:13px;text-align:left}img{max-width:100%}\
         .step{color:#b00}section{margin-top:2em}</style></head><body>\n<h1>Results across commits</h1>\n",
    );
    let _ = writeln!(
        page,
        "<p>{}, {} series, {} timelines from <code>{}</code>. A step is a change of the fitted level \
         (piecewise-constant fit, each point weighed by its spread or the measure's noise floor), named with the \
         commit that made it when the commits on either side are parent and child (or a commit and an uncommitted \
         change of it, <code>+dirty:</code> and the first digits of its diff's SHA-256).</p>",
        escape(&points_text(history)),
        history.series.len(),
        history.timelines.len(),
        escape(&store.display().to_string())
    );
    let steps = all_steps(history);
    let _ = writeln!(page, "<section id=\"steps\"><h2>Steps ({})</h2>", steps.len());
    if steps.is_empty() {
        page.push_str("<p>No step: every timeline is flat within its noise.</p>");
    } else {
        page.push_str("<table><tr><th>scenario</th><th>method</th><th>measure</th><th>before</th><th>after</th><th>change</th><th>commit</th></tr>\n");
        for (t, s) in &steps {
            let cells: Vec<String> = [escape(&t.scenario), escape(&t.method)]
                .into_iter()
                .chain(step_fields(history, t, s))
                .collect();
            let _ = writeln!(page, "<tr class=\"step\"><td>{}</td></tr>", cells.join("</td><td>"));
        }
        page.push_str("</table>\n");
    }
    if !history.status_changes.is_empty() {
        page.push_str("<h3>Verdict changes</h3><table><tr><th>scenario</th><th>method</th><th>before</th><th>after</th><th>at</th></tr>\n");
        for c in &history.status_changes {
            let _ = writeln!(
                page,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&c.scenario),
                escape(&c.method),
                escape(&c.before),
                escape(&c.after),
                escape(&history.commits[c.to].label())
            );
        }
        page.push_str("</table>\n");
    }
    page.push_str("</section>\n<section id=\"commits\"><h2>Commits</h2><table><tr><th>#</th><th>commit</th><th>date</th><th>method code changed</th><th>steps made</th><th>subject</th></tr>\n");
    for (i, c) in history.commits.iter().enumerate() {
        let made =
            steps.iter().filter(|(_, s)| s.made_by == Some(i) || (s.made_by.is_none() && s.to == i)).count();
        let changed = match history.method_change[i] {
            Some(true) => "yes",
            Some(false) => "no",
            None => "?",
        };
        let _ = writeln!(
            page,
            "<tr><td>{i}</td><td><code>{}</code></td><td>{}</td><td>{changed}</td><td>{made}</td><td>{}</td></tr>",
            c.label(),
            escape(&c.date),
            escape(&short_subject(&c.subject))
        );
    }
    page.push_str("</table></section>\n");
    page.push_str(sections);
    page.push_str(crate::report::html::IMAGE_CHECK);
    page.push_str("</body></html>\n");
    page
}

fn section(page: &mut String, history: &History, timelines: &[&Timeline], png: &Path, i: usize) {
    let Some(first) = timelines.first() else { return };
    let _ = writeln!(
        page,
        "<section class=\"history-case\" id=\"case-{i}\"><h2>{} / {}</h2><p>{}</p>",
        escape(&first.scenario),
        escape(&first.method),
        escape(&first.series)
    );
    let _ = writeln!(
        page,
        "<img src=\"{}\" alt=\"timelines of {} on {}\">",
        escape(&png.display().to_string()),
        escape(&first.method),
        escape(&first.scenario)
    );
    let steps: Vec<(&&Timeline, &AttributedStep)> =
        timelines.iter().flat_map(|t| t.steps.iter().map(move |s| (t, s))).collect();
    if steps.is_empty() {
        page.push_str("<p>No step.</p>");
    } else {
        page.push_str("<ul>");
        for (t, s) in steps {
            let [measure, before, after, change, commit] = step_fields(history, t, s);
            let _ =
                write!(page, "<li class=\"step\">{measure}: {before} → {after} ({change}), {commit}</li>");
        }
        page.push_str("</ul>");
    }
    page.push_str("</section>\n");
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// A case's figure: one panel per measure it has.
fn draw_case(path: &Path, history: &History, timelines: &[&Timeline]) -> Result<(), HistoryError> {
    let rows = timelines.len().div_ceil(COLUMNS).max(1);
    let size = (PANEL.0 * COLUMNS as u32, PANEL.1 * rows as u32 + TITLE);
    let temporary = path.with_file_name(format!(
        ".{}.partial.png",
        path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
    ));
    let fail = |m: String| HistoryError::Results { path: path.to_path_buf(), message: m };
    {
        let root = BitMapBackend::new(&temporary, size).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(err(e)))?;
        let title = timelines
            .first()
            .map_or(String::new(), |t| format!("{} / {} ({})", t.scenario, t.method, t.series));
        let root = root.titled(&title, ("sans-serif", 18)).map_err(|e| fail(err(e)))?;
        let panels = root.split_evenly((rows, COLUMNS));
        for (panel, t) in panels.iter().zip(timelines) {
            draw_panel(panel, history, t).map_err(fail)?;
        }
        root.present().map_err(|e| fail(err(e)))?;
    }
    std::fs::rename(&temporary, path).map_err(|error| HistoryError::Io { path: path.to_path_buf(), error })
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    history: &History,
    t: &Timeline,
) -> Result<(), String> {
    let n = history.commits.len();
    let lows = t.points.iter().map(|p| p.low.min(p.value));
    let highs = t.points.iter().map(|p| p.high.max(p.value));
    let (mut y0, mut y1) = (lows.fold(f64::INFINITY, f64::min), highs.fold(f64::NEG_INFINITY, f64::max));
    if !y0.is_finite() {
        return Ok(());
    }
    let pad = ((y1 - y0) * 0.1).max(y1.abs().max(y0.abs()) * 0.02).max(1e-12);
    y0 -= pad;
    y1 += pad;
    let mut chart = ChartBuilder::on(area)
        .caption(t.measure.label(), ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.5..(n as f64 - 0.5), y0..y1)
        .map_err(err)?;
    // Commits by their number in the page's commits table: seven-character hashes side by side do
    // not fit under a panel of a dozen commits.
    let label = |x: &f64| {
        let i = x.round();
        if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < n {
            format!("{i}")
        } else {
            String::new()
        }
    };
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n.min(24))
        .x_label_formatter(&label)
        .x_desc("commit (# of the commits table)")
        .y_label_formatter(&|v| axis_value(*v))
        .label_style(("sans-serif", 11))
        .draw()
        .map_err(err)?;
    let blue = RGBColor(31, 119, 180);
    if t.measure.has_spread() && t.points.iter().any(|p| p.high > p.low) {
        let mut band: Vec<(f64, f64)> = t.points.iter().map(|p| (p.commit as f64, p.high)).collect();
        band.extend(t.points.iter().rev().map(|p| (p.commit as f64, p.low)));
        chart.draw_series(std::iter::once(Polygon::new(band, blue.mix(0.2).filled()))).map_err(err)?;
    }
    for s in &t.steps {
        let x = 0.5 * (s.from as f64 + s.to as f64);
        chart
            .draw_series(std::iter::once(PathElement::new(vec![(x, y0), (x, y1)], RED.stroke_width(2))))
            .map_err(err)?;
    }
    let fitted: Vec<(f64, f64)> =
        t.points.iter().zip(&t.fitted).map(|(p, f)| (p.commit as f64, *f)).collect();
    chart.draw_series(LineSeries::new(fitted, BLACK.mix(0.6).stroke_width(1))).map_err(err)?;
    let values: Vec<(f64, f64)> = t.points.iter().map(|p| (p.commit as f64, p.value)).collect();
    chart.draw_series(LineSeries::new(values.clone(), blue.stroke_width(2))).map_err(err)?;
    chart
        .draw_series(t.points.iter().map(|p| {
            let ok = p.status.starts_with("ok");
            let color = if ok { blue.filled() } else { RGBColor(230, 120, 0).filled() };
            Circle::new((p.commit as f64, p.value), 3, color)
        }))
        .map_err(err)?;
    Ok(())
}
