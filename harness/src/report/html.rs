//! `reports/index.html`: the provenance and regression verdict, "Which method" (a ranking per test),
//! the results table, the 3D view of a case, quality against time, HIRM's Table 1, the rendered
//! figures and every plot on one page that opens from disk (relative links only, no server, no
//! external resources). Its scripts (`page.js`: ranking, sorting, filtering, the address;
//! `viewer.js`: the 3D view, whose meshes [`crate::report::viewer`] writes) are inlined. A script
//! at the end counts the images that loaded and writes the count into `#image-check`
//! (`data-loaded` / `data-total` attributes), which the browser test reads.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::document::html::{figure, link};
use super::document::{html as render, Block, Document, Image, ImageGroup, Table};
use crate::config::Origin;
use crate::error::HarnessError;
use crate::metrics::METRICS;
use crate::record::CaseResult;
use crate::regression::GateOutcome;

pub(crate) use super::document::html::escape;

fn number(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "–".into()
    }
}

/// What every section of the page reads: the run's records and what the run wrote beside them.
pub struct PageContext<'a> {
    pub results: &'a [CaseResult],
    /// Where the meshes came from, in words.
    pub data_source: &'a str,
    /// The run's provenance line.
    pub provenance: &'a str,
    /// Plots and figures (their PNGs, relative to the report directory).
    pub images: &'a [Image],
    /// HIRM's Table 1, as in `table1.md` (no rows: no scenario ran both of its sides).
    pub table1: &'a Table,
    /// Our ARAP against libigl's, as in `peers.md` (no rows: none).
    pub peers: &'a Table,
    pub gate: &'a GateOutcome,
    /// Notes on the inputs.
    pub notes: &'a [String],
    /// The scenarios the run loaded (what `repair = true` changed in their meshes).
    pub scenarios: &'a [crate::scenario::LoadedScenario],
    /// The meshes of collections skipped before any case ran.
    pub skipped: &'a [crate::scenario::SkippedInput],
    /// The case file stems that open in the 3D view.
    pub viewable: &'a [String],
    /// `dataset.md` (empty: not a dataset run).
    pub dataset: &'a Document,
    /// `size-series.md` (empty: no series).
    pub size_series: &'a Document,
}

/// A section of the page: appends its HTML (nothing when it has nothing to show).
type Section = fn(&mut String, &PageContext);

/// The page, top to bottom: adding a section is one function and one line here.
const SECTIONS: &[Section] = &[
    head,
    regression_gate,
    skipped_and_repaired,
    across_the_dataset,
    answer_first,
    cost_against_size,
    results_table,
    view_3d,
    glossary,
    input_notes,
    arap_against_libigl,
    below_the_reference,
    quality_against_time,
    rendered_results,
    plots,
    table1,
    every_render,
    scripts,
];

/// The page of a run, its sections ([`SECTIONS`]) over one `context`.
pub fn render_index(context: &PageContext) -> String {
    let mut page = String::new();
    for section in SECTIONS {
        section(&mut page, context);
    }
    page
}

impl PageContext<'_> {
    /// The images of `group`, in the run's order.
    fn images<'a>(&'a self, group: &'a ImageGroup) -> impl Iterator<Item = &'a Image> {
        self.images.iter().filter(move |i| i.group == *group)
    }

    /// The figures of the images of `group`.
    fn figures(&self, group: &ImageGroup) -> String {
        self.images(group).map(figure).collect()
    }
}

/// `document`'s blocks as the page shows them under its section's own heading: its headings of
/// `kept.0` as paragraphs that begin with `kept.1` (the families of `dataset.md`, the series of
/// `size-series.md`), its other headings left out.
fn under_section_heading(document: &Document, kept: (u8, &str)) -> Document {
    let (level, label) = kept;
    let blocks = document.blocks.iter().filter_map(|block| match block {
        Block::Heading { level: l, text } if *l == level => Some(Block::Paragraph(text.clone().after(label))),
        Block::Heading { .. } => None,
        other => Some(other.clone()),
    });
    Document { blocks: blocks.collect() }
}

/// The document head, the title, the data source and the provenance.
fn head(page: &mut String, context: &PageContext) {
    page.push_str(concat!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n",
        "<title>deformbench report</title>\n<style>\n",
        "body{font-family:sans-serif;margin:2em;max-width:1500px;color:#222}\n",
        "table{border-collapse:collapse;font-size:13px;margin:1em 0}\n",
        "th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}\n",
        "th{background:#f0f0f0}td.text{text-align:left}\n",
        "span.origin{font-size:11px;color:#fff;background:#557;border-radius:3px;padding:0 4px;margin-left:4px}\n",
        "tr.failed td{background:#fdd}tr.suspect td{background:#fff1d6}tr.unfinished td{background:#e4e8ff}\n",
        "td.status{min-width:260px;max-width:360px;font-size:12px}td{white-space:nowrap}\n",
        "td.status{white-space:normal}div.scroll{overflow-x:auto}dl.metrics dt{font-weight:bold;margin-top:.3em}\n",
        ".pass{color:#060}.fail{color:#a00}\n",
        "img{max-width:100%;border:1px solid #ddd;margin:4px 0}\n",
        "figure{margin:1em 0}figcaption{font-size:13px;color:#555}\n",
        "div.scroll{max-height:85vh;overflow:auto}#results-table{margin:0}\n",
        "#results-table thead th{position:sticky;top:0;z-index:2}\n",
        "#results-table td:nth-child(-n+2),#results-table th:nth-child(-n+2){position:sticky;left:0;z-index:1}\n",
        "#results-table thead th:nth-child(-n+2){z-index:3}#results-table td:nth-child(-n+2){background:#fff}\n",
        "tr.suspect td:nth-child(-n+2){background:#fff1d6}tr.failed td:nth-child(-n+2){background:#fdd}\n",
        "tr.unfinished td:nth-child(-n+2){background:#e4e8ff}\n",
        "tr.viewable{cursor:pointer}tr.viewable:hover td{outline:1px solid #99c}\n",
        "#viewer .viewer-pane{position:relative;display:inline-block;max-width:48%;margin-right:8px;\
         vertical-align:top}\n",
        "#viewer canvas{display:block;max-width:100%;border:1px solid #ccc;cursor:crosshair}\n",
        "#viewer .viewer-name{position:absolute;left:9px;top:5px;font:14px sans-serif;color:#222;\
         pointer-events:none}\n",
        "#viewer .viewer-pick{position:absolute;margin:6px 0 0 6px;padding:1px 4px;font:12px sans-serif;\
         white-space:nowrap;background:#fffe;border:1px solid #444;pointer-events:none}\n",
        "#viewer .viewer-pick::before{content:'';position:absolute;left:-11px;top:-11px;width:7px;height:7px;\
         border-radius:50%;background:#000;border:1px solid #fff}\n",
        "th.sortable{cursor:pointer}th.sorted-up::after{content:' ▲'}th.sorted-down::after{content:' ▼'}\n",
        "#filters label{margin-right:1em;font-size:14px}#row-count{font-size:13px;color:#555}\n",
        "div.ranking-grid{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start}table.ranking{margin:0}\n",
        "table.ranking caption,#median-ranks caption{font-weight:bold;text-align:left}\n",
        "table.ranking tr.ok td{background:#e6f5e6}\n",
        "ul.unranked{list-style:none;padding:0;margin:.3em 0;max-width:22em;font-size:90%}ul.unranked li.suspect{background:#fff4d6}\n",
        "</style>\n</head>\n<body>\n",
        "<h1>deformbench: handle-based mesh deformation, side by side</h1>\n"
    ));
    let _ = writeln!(
        page,
        "<p>Data: {}. Times in seconds, iteration times in milliseconds.</p>",
        escape(context.data_source)
    );
    let _ = writeln!(page, "<p id=\"provenance\">Made by this {}.</p>", escape(context.provenance));
}

/// The quality-regression gate's verdict.
fn regression_gate(page: &mut String, context: &PageContext) {
    let gate = context.gate;
    page.push_str("<h2 id=\"verdict\">Quality regression gate</h2>\n");
    match gate {
        GateOutcome::Checked { baseline, findings } => {
            let regressions = gate.regressions();
            let name = escape(&baseline.display().to_string());
            if regressions == 0 {
                let _ = writeln!(page, "<p class=\"pass\">No regression against <code>{name}</code>.</p>");
            } else {
                let _ = writeln!(
                    page,
                    "<p class=\"fail\">{regressions} regression(s) against <code>{name}</code>:</p>"
                );
            }
            if !findings.is_empty() {
                page.push_str("<ul>\n");
                for f in findings {
                    let _ = writeln!(page, "<li>{}</li>", escape(&f.to_string()));
                }
                page.push_str("</ul>\n");
            }
        }
        GateOutcome::NotChecked(reason) => {
            let _ = writeln!(page, "<p>Not checked: {}</p>", escape(reason));
        }
    }
}

/// Across the dataset: `dataset.md`'s tables, the error distributions, the cost curves and each
/// family's worst results.
fn across_the_dataset(page: &mut String, context: &PageContext) {
    if context.dataset.is_empty() {
        return;
    }
    page.push_str(
        "<h2 id=\"dataset\">Across the dataset</h2>\n<p>The same tables as <code>dataset.md</code>: how often \
         each method broke per edit family, how its error spreads, what it costs and how that grows with the mesh; \
         then the error distributions, the cost curves and each family's worst <code>ok</code> results beside arap's. \
         The results table below filters by family, mesh, surface, genus and size.</p>\n",
    );
    page.push_str(&under_section_heading(context.dataset, (3, "Edit family: ")).to_html());
    page.push_str(&context.figures(&ImageGroup::Dataset));
}

/// Cost against size: `size-series.md` and its plots.
fn cost_against_size(page: &mut String, context: &PageContext) {
    if context.size_series.is_empty() {
        return;
    }
    page.push_str(
        "<h2 id=\"size-series\">Cost against size</h2>\n<p>(Also in <code>size-series.md</code>.)</p>\n",
    );
    page.push_str(&under_section_heading(context.size_series, (2, "Series: ")).to_html());
    page.push_str(&context.figures(&ImageGroup::SizeSeries));
}

/// The results table: a row per case, every timing and measure, sortable and filtered by the page
/// script; a row with a result mesh opens the 3D view.
fn results_table(page: &mut String, context: &PageContext) {
    results_header(page);
    for r in context.results {
        result_row(page, r, context.viewable);
    }
    page.push_str("</tbody></table></div>\n");
}

/// The section's heading, the filters' place and the table's header row: a column per timing and
/// measure, each with the key the page script sorts and ranks by.
fn results_header(page: &mut String) {
    page.push_str(
        "<h2 id=\"results\">Results</h2>\n<div id=\"filters\"></div>\n<div class=\"scroll\"><table id=\"results-table\">\n<thead><tr>\
         <th data-key=\"scenario\">scenario</th><th data-key=\"method\">method</th>\
         <th data-key=\"status\">status</th><th data-key=\"vertices\">#V</th>\
         <th data-key=\"iterations\">iterations</th><th data-key=\"converged\">converged</th>\
         <th data-key=\"startup_s\" title=\"an external method's process start-up, not part of precompute\">startup</th>\
         <th data-key=\"precompute_s\">precompute</th><th data-key=\"bind_s\">bind</th><th data-key=\"solve_s\">solve</th>\
         <th data-key=\"total_s\">total</th><th data-key=\"median_iteration_ms\">iteration (ms)</th>\
         <th data-key=\"peak_memory_mib\" title=\"what the method added to the resident memory at its peak (one case at a time only)\">peak memory (MiB)</th>",
    );
    for spec in &METRICS {
        let _ = write!(
            page,
            "<th data-key=\"{}\" data-better=\"{}\" title=\"{}\">{}</th>",
            spec.key,
            better_word(spec.better),
            escape(spec.doc),
            escape(spec.label)
        );
    }
    page.push_str(
        "<th data-key=\"self_intersecting\">self-intersecting (open3d)</th></tr></thead>\n<tbody>\n",
    );
}

/// One case's row: its data attributes for the filters and the 3D view, then its cells.
fn result_row(page: &mut String, r: &CaseResult, viewable: &[String]) {
    let (class, badge) = origin_mark(r);
    let _ = write!(
        page,
        "<tr class=\"{class}\" data-scenario=\"{}\" data-method=\"{}\" data-status=\"{}\" data-why=\"{}\" data-source=\"{}\"{}{}>\
         <td class=\"text\">{}</td><td class=\"text\">{}{badge}</td><td class=\"text status\">{}</td>\
         <td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td>{}</td>",
        escape(&r.scenario),
        escape(&r.method),
        r.status.kind(),
        escape(&reason_kinds(&r.status)),
        escape(&r.mesh_source),
        member_attributes(r),
        view_attributes(r, viewable),
        escape(&r.scenario),
        escape(&r.method),
        escape(&r.status.to_string()),
        r.vertices,
        r.vertices,
        r.iterations,
        r.iterations,
        if r.convergence_unknown {
            "unknown"
        } else if r.converged {
            "yes"
        } else {
            "no"
        },
    );
    page.push_str(&timing_cells(r));
    page.push_str(&measure_cells(r));
    let _ = writeln!(
        page,
        "<td>{}</td></tr>",
        r.self_intersecting.map_or("not checked", |b| if b { "yes" } else { "no" }),
    );
}

/// The kinds of a status's shape reasons, each once, in order (`folds, shrinks`): the short form
/// the ranking's "not ranked" lists show (the full text is the row's status cell).
fn reason_kinds(status: &crate::verdict::Status) -> String {
    let mut kinds: Vec<&str> = Vec::new();
    for kind in status.shape_reasons().filter_map(|r| crate::verdict::reason_kind(r)) {
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    kinds.join(", ")
}

/// A row's class (its status, and its origin when not built in) and the mark beside its method: a
/// peer's or an external program's origin, or the method whose identical solve it reuses.
fn origin_mark(r: &CaseResult) -> (String, String) {
    match r.origin {
        Origin::BuiltIn => (
            r.status.kind().to_string(),
            r.reused_solve.as_ref().map_or(String::new(), |reused| {
                format!(
                    "<span class=\"origin\" title=\"{}\">reuses {}</span>",
                    escape(&format!(
                        "its solve time includes {:.3} s of {}'s identical solve on this case, \
                         taken from that case instead of computed again",
                        reused.seconds, reused.from
                    )),
                    escape(&reused.from)
                )
            }),
        ),
        other => (
            format!("{} {}", r.status.kind(), other.label()),
            format!(
                "<span class=\"origin\" title=\"{}\">{}</span>",
                escape(r.about.as_deref().unwrap_or("")),
                other.label()
            ),
        ),
    }
}

/// The attributes that open a case in the 3D view (its mesh files' stems), when it has them.
fn view_attributes(r: &CaseResult, viewable: &[String]) -> String {
    let stem = crate::stored_report::case_file_stem(&r.scenario, &r.method);
    if viewable.contains(&stem) {
        format!(
            " data-view=\"{}\" data-rest=\"{}.rest\"",
            escape(&stem),
            escape(&crate::stored_report::file_name(&r.scenario))
        )
    } else {
        String::new()
    }
}

/// The timing cells (startup, precompute, bind, solve, total, iteration) and the peak memory.
fn timing_cells(r: &CaseResult) -> String {
    let spread = |phase: fn(&crate::record::TimingSpread) -> crate::record::Spread| {
        r.spread.map(|s| (s.repetitions, phase(&s)))
    };
    [
        timing(r.startup_s, spread(|s| s.startup_s), 3),
        timing(r.precompute_s, spread(|s| s.precompute_s), 3),
        timing(r.bind_s, spread(|s| s.bind_s), 4),
        timing(r.solve_s, spread(|s| s.solve_s), 3),
        timing(r.total_s, spread(|s| s.total_s), 3),
        timing(r.median_iteration_ms, spread(|s| s.median_iteration_ms), 3),
        format!("<td data-v=\"{}\">{}</td>", sort_value(r.peak_memory_mib), number(r.peak_memory_mib, 0)),
    ]
    .concat()
}

/// A cell per measure of [`METRICS`]: the value as the measure formats it, sorted by the full number.
fn measure_cells(r: &CaseResult) -> String {
    let mut cells = String::new();
    for spec in &METRICS {
        let value = r.quality.get(spec.metric);
        let _ = write!(
            cells,
            "<td data-v=\"{}\">{}</td>",
            value.map_or(String::new(), sort_value),
            escape(&spec.format.apply(value))
        );
    }
    cells
}

/// The 3D view (filled by `viewer.js` when a row is clicked).
fn view_3d(page: &mut String, _: &PageContext) {
    page.push_str(concat!(
        "<div id=\"viewer\" hidden><p><b id=\"viewer-title\"></b> &mdash; drag to turn, wheel to zoom ",
        "<button id=\"viewer-reset\">reset</button> colour <select id=\"viewer-colour\">",
        "<option value=\"shaded\">shaded: fixed blue, handles red</option>",
        "<option value=\"angle\">angle error, 0&ndash;10&deg;</option>",
        "<option value=\"area\">area distortion, &times;0.5 blue to &times;2 red</option></select> ",
        "left <select id=\"viewer-left\"></select> <button id=\"viewer-close\">close</button></p>",
        "<span class=\"viewer-pane\"><canvas id=\"viewer-left-canvas\" width=\"640\" height=\"520\"></canvas>",
        "<span class=\"viewer-name\" id=\"viewer-left-name\"></span>",
        "<span class=\"viewer-pick\" id=\"viewer-left-pick\" hidden></span></span>",
        "<span class=\"viewer-pane\"><canvas id=\"viewer-right-canvas\" width=\"640\" height=\"520\"></canvas>",
        "<span class=\"viewer-name\" id=\"viewer-right-name\"></span>",
        "<span class=\"viewer-pick\" id=\"viewer-right-pick\" hidden></span></span></div>\n"
    ));
}

/// What the columns mean: every measure of the metric table, and the statuses.
fn glossary(page: &mut String, _: &PageContext) {
    page.push_str("<h2 id=\"measures\">What the columns mean</h2>\n<p>Every measure compares the result with the rest mesh:</p>\n");
    page.push_str("<dl class=\"metrics\">\n");
    for spec in &METRICS {
        let unit = if spec.unit.is_empty() { String::new() } else { format!(" ({})", spec.unit) };
        let _ = writeln!(
            page,
            "<dt>{}{} <code>{}</code></dt><dd>{}</dd>",
            escape(spec.label),
            escape(&unit),
            spec.key,
            escape(spec.doc)
        );
    }
    page.push_str(
        "</dl>\n<p>Status: <code>ok</code>; <code>suspect</code> (highlighted) when the result folds, misses its \
         handles, leaves its frame or turns a free region far beyond its handles, with the reasons (thresholds in \
         <code>configs/verdicts.toml</code>); <code>unfinished</code> (blue) when its iteration stopped at the \
         cap before its tolerance, so the measures are of an iterate, not of the method's answer; \
         <code>failed</code> (red) when the method gave no result. Rows marked <span class=\"origin\">peer</span> are \
         peer libraries' methods (<code>--peers</code>, <code>configs/peers.toml</code>), <span class=\"origin\">external</span> \
         other programs over the method protocol (README); hover the mark for what ran.</p>\n",
    );
}

/// The meshes of collections skipped before any case ran, with their reasons, and the meshes
/// `repair = true` changed, with what it changed: high on the page, since no row of the results
/// table shows either.
fn skipped_and_repaired(page: &mut String, context: &PageContext) {
    let repaired: Vec<(&str, &crate::scenario::Repaired)> =
        context.scenarios.iter().filter_map(|s| Some((s.spec.name.as_str(), s.repaired.as_ref()?))).collect();
    if context.skipped.is_empty() && repaired.is_empty() {
        return;
    }
    page.push_str("<h2 id=\"inputs\">Meshes skipped or repaired</h2>\n");
    fn table(page: &mut String, last: &str, rows: Vec<(&str, &Path, &str)>) {
        let _ = writeln!(page, "<table>\n<tr><th>scenario</th><th>file</th><th>{last}</th></tr>");
        for (scenario, file, what) in rows {
            let _ = writeln!(
                page,
                "<tr><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(scenario),
                escape(&file.display().to_string()),
                escape(what)
            );
        }
        page.push_str("</table>\n");
    }
    if !context.skipped.is_empty() {
        let _ = writeln!(
            page,
            "<p>{} mesh(es) of collections were skipped: no case ran on them, for the reason given \
             (<code>repair = true</code> fixes broken faces).</p>",
            context.skipped.len()
        );
        let rows = context.skipped.iter().map(|s| (s.scenario.as_str(), s.file.as_path(), s.reason.as_str()));
        table(page, "reason", rows.collect());
    }
    if !repaired.is_empty() {
        let _ = writeln!(
            page,
            "<p>{} mesh(es) were changed by <code>repair = true</code> before any case ran; their results are \
             of the repaired mesh.</p>",
            repaired.len()
        );
        let rows = repaired.iter().map(|(name, r)| (*name, r.file.as_path(), r.changes.as_str()));
        table(page, "what changed", rows.collect());
    }
}

/// Notes on the inputs (skipped meshes, repairs).
fn input_notes(page: &mut String, context: &PageContext) {
    let notes = context.notes;
    if !notes.is_empty() {
        page.push_str("<h2 id=\"notes\">Notes on the inputs</h2>\n<ul>\n");
        for n in notes {
            let _ = writeln!(page, "<li>{}</li>", escape(n));
        }
        page.push_str("</ul>\n");
    }
}

/// Our arap against libigl's (`peers.md`).
fn arap_against_libigl(page: &mut String, context: &PageContext) {
    if !context.peers.rows.is_empty() {
        page.push_str("<h2 id=\"arap-libigl\">Our arap against libigl's</h2>\n");
        page.push_str(&render::table(context.peers));
    }
}

/// A result whose ARAP energy is below the reference's by more than this fraction is listed: it
/// found a lower minimum of the energy the reference minimizes (differences of rounding are not).
pub const LOWER_ENERGY_MARGIN: f64 = 1e-6;

/// The cases whose result has a lower ARAP energy than the reference's on the same scenario.
pub fn below_the_reference_cases(results: &[CaseResult]) -> Vec<(&CaseResult, f64, f64)> {
    use crate::metrics::Metric;
    let mut below = Vec::new();
    let index = crate::record::CaseIndex::new(results);
    for r in results {
        if r.method == crate::record::REFERENCE_METHOD {
            continue;
        }
        let reference = index.reference_of(r);
        let (Some(mine), Some(theirs)) =
            (r.quality.get(Metric::ArapEnergy), reference.and_then(|q| q.quality.get(Metric::ArapEnergy)))
        else {
            continue;
        };
        if mine < theirs * (1.0 - LOWER_ENERGY_MARGIN) {
            below.push((r, mine, theirs));
        }
    }
    below
}

/// "Below the reference's energy": the ARAP energy is not convex, and the reference keeps libigl's
/// start; a method that ended in a lower minimum is named, with both energies.
fn below_the_reference(page: &mut String, context: &PageContext) {
    let below = below_the_reference_cases(context.results);
    if below.is_empty() {
        return;
    }
    page.push_str(
        "<h2 id=\"lower-energy\">Lower ARAP energy than the reference</h2>\n<p>The ARAP energy is not \
         convex: these results reach a lower value of the energy <code>arap</code> minimizes than \
         <code>arap</code> does from its start (the rest shape, libigl's), so distances to the \
         reference there measure a different minimum, not an error.</p>\n<ul>\n",
    );
    for (r, mine, theirs) in below {
        let _ = writeln!(
            page,
            "<li><code>{}</code> on <code>{}</code>: {:.4e} against {:.4e}</li>",
            escape(&r.method),
            escape(&r.scenario),
            mine,
            theirs
        );
    }
    page.push_str("</ul>\n");
}

/// The rendered result grids.
fn rendered_results(page: &mut String, context: &PageContext) {
    let grids = context.figures(&ImageGroup::Grid);
    if !grids.is_empty() {
        page.push_str("<h2 id=\"figures\">Rendered results</h2>\n");
        page.push_str(&grids);
    }
}

/// Every other plot.
fn plots(page: &mut String, context: &PageContext) {
    let plots = context.figures(&ImageGroup::Plot);
    if !plots.is_empty() {
        page.push_str("<h2 id=\"plots\">Plots</h2>\n");
        page.push_str(&plots);
    }
}

/// HIRM's Table 1, when a scenario ran both of its sides.
fn table1(page: &mut String, context: &PageContext) {
    if !context.table1.rows.is_empty() {
        page.push_str("<h2 id=\"table1\">Handle-set update (HIRM Table 1)</h2>\n");
        page.push_str(&render::table(context.table1));
    }
}

/// Every single render (rest shapes, results, heat maps), folded.
fn every_render(page: &mut String, context: &PageContext) {
    let single: Vec<&Image> = context.images(&ImageGroup::Render).collect();
    if !single.is_empty() {
        let _ = writeln!(
            page,
            "<h2 id=\"renders\">Every render</h2>\n<details><summary>{} images: rest shapes, results and \
             angle-error heat maps (0–10°) and area-distortion maps (×0.5–×2) of every case</summary>",
            single.len()
        );
        for p in single {
            let _ = writeln!(
                page,
                "<img src=\"{u}\" alt=\"{u}\" title=\"{u}\" loading=\"eager\" style=\"max-width:240px\">",
                u = escape(&link(&p.path)),
            );
        }
        page.push_str("</details>\n");
    }
}

/// The image check the browser tests read: once the page has loaded, `#image-check` holds the
/// images that loaded, all images, and the sources of those that did not.
pub(crate) const IMAGE_CHECK: &str = concat!(
    "<p id=\"image-check\" data-loaded=\"\" data-total=\"\"></p>\n",
    "<script>\n",
    "window.addEventListener('load', function () {\n",
    "  var images = Array.prototype.slice.call(document.images);\n",
    "  var loaded = images.filter(function (i) { return i.complete && i.naturalWidth > 0; });\n",
    "  var broken = images.filter(function (i) { return !(i.complete && i.naturalWidth > 0); })\n",
    "    .map(function (i) { return i.getAttribute('src'); });\n",
    "  var p = document.getElementById('image-check');\n",
    "  p.dataset.loaded = loaded.length; p.dataset.total = images.length;\n",
    "  p.dataset.broken = broken.join(' ');\n",
    "  p.textContent = 'Images loaded: ' + loaded.length + ' of ' + images.length + '.';\n",
    "});\n",
    "</script>\n"
);

/// The page's scripts, inlined, and the image check the browser test reads.
fn scripts(page: &mut String, _: &PageContext) {
    page.push_str("<script>\n");
    page.push_str(include_str!("page.js"));
    page.push_str(include_str!("viewer.js"));
    page.push_str("</script>\n");
    page.push_str(IMAGE_CHECK);
    page.push_str("</body>\n</html>\n");
}

/// "Quality against time": per test with sweep points its plot, budget table, fronts and points.
fn quality_against_time(page: &mut String, context: &PageContext) {
    let scenarios = super::quality_time::swept_scenarios(context.results);
    if scenarios.is_empty() {
        return;
    }
    page.push_str(
        "<h2 id=\"quality-time\">Quality against time (sweeps)</h2>\n<p>Each method's parameters swept \
         (<code>--sweeps</code>, <code>configs/sweeps.toml</code>): every setting is a point named by its values, \
         <code>isolines[isolines=10]</code>. Time per edit is bind + solve, what a user waits after moving a \
         handle; the plots' right column adds the precompute. The budget table gives, for each time per edit, \
         the <code>ok</code> setting with the lowest error within it.</p>\n",
    );
    for scenario in scenarios {
        quality_against_time_of(page, context, scenario);
    }
}

/// Quality against time on one test: its plot, budget table and fronts, and every point folded.
fn quality_against_time_of(page: &mut String, context: &PageContext, scenario: &str) {
    use super::quality_time::{budget_table, front, points_table};
    let cases: Vec<&CaseResult> = context.results.iter().filter(|r| r.scenario == scenario).collect();
    let _ = writeln!(page, "<h3 id=\"quality-time-{s}\">{s}</h3>", s = escape(scenario));
    page.push_str(&context.figures(&ImageGroup::QualityTime(scenario.to_string())));
    page.push_str(&render::table(&budget_table(&cases)));
    for m in crate::pareto::MEASURES {
        page.push_str(&render::block(&Block::Paragraph(front(&cases, m))));
    }
    let _ =
        writeln!(page, "<details><summary>Every point of {} ({})</summary>", escape(scenario), cases.len());
    page.push_str(&render::table(&points_table(&cases)));
    page.push_str("</details>\n");
}

/// A timing cell (`<td>`, sorted by its value): the value, and below it the min–max range when it
/// is a median of repetitions.
fn timing(value: f64, spread: Option<(usize, crate::record::Spread)>, digits: usize) -> String {
    let text = match spread {
        Some((n, s)) if n > 1 => format!(
            "{}<br><small title=\"min–max over {n} repetitions\">{}–{}</small>",
            number(value, digits),
            number(s.min, digits),
            number(s.max, digits)
        ),
        _ => number(value, digits),
    };
    format!("<td data-v=\"{}\">{text}</td>", sort_value(value))
}

/// A cell's value for sorting (`data-v`): the number in full, empty when not finite.
fn sort_value(v: f64) -> String {
    if v.is_finite() {
        format!("{v:e}")
    } else {
        String::new()
    }
}

/// How a measure is better, for the page script's ranking (`data-better`).
fn better_word(better: crate::metrics::Better) -> &'static str {
    match better {
        crate::metrics::Better::Lower => "lower",
        crate::metrics::Better::NearZero => "near-zero",
    }
}

/// "Which method": per test the methods ranked by a measure the reader picks, with their verdicts
/// and time per edit, and each method's median rank across the tests; the page script fills it
/// from the results table (`page.js`).
fn answer_first(page: &mut String, _: &PageContext) {
    page.push_str(
        "<h2 id=\"answer\">Which method</h2>\n<p>Rank by <select id=\"rank-by\"></select> \
         <label><input type=\"checkbox\" id=\"rank-suspect\"> rank suspect results too</label>: per test, \
         the <code>ok</code> results from best to worst, with the time per edit (bind + solve); under each \
         table the results not ranked (suspect, unfinished, failed) with their reasons; then each method's \
         median rank over the tests where it was ranked. The default measure, e_iso, sees size and angle \
         together (a swollen or shrunk result ranks low by it, where E_θ and E_φ do not see size). Sort \
         and filter the full table below, and click a row to turn its result in 3D; the address keeps \
         the choice (<code>?rank=e_phi_deg&amp;suspect=1&amp;sort=total_s&amp;status=ok</code>).</p>\n\
         <div id=\"ranking\"></div>\n",
    );
}

/// The data attributes of a collection's case for the page's filters: its edit family and mesh,
/// and from the mesh's manifest row whether it is closed, its genus (0, 1, 2-4, 5+) and size class
/// (by vertices: < 5K, 5-30K, 30-100K, >= 100K); nothing for other cases.
fn member_attributes(case: &CaseResult) -> String {
    let Some(member) = &case.member else { return String::new() };
    let mut out =
        format!(" data-family=\"{}\" data-mesh=\"{}\"", escape(&member.collection), escape(&member.mesh));
    if let Some(watertight) = member.attribute("watertight") {
        let surface = if watertight == "true" { "closed" } else { "open or not manifold" };
        let _ = write!(out, " data-surface=\"{surface}\"");
    }
    if let Some(genus) = member.attribute("genus").and_then(|g| g.parse::<f64>().ok()) {
        let class = match genus {
            g if g < 0.5 => "0",
            g if g < 1.5 => "1",
            g if g < 4.5 => "2-4",
            _ => "5+",
        };
        let _ = write!(out, " data-genus=\"{class}\"");
    }
    let size = match case.vertices {
        v if v < 5_000 => "< 5K",
        v if v < 30_000 => "5K-30K",
        v if v < 100_000 => "30K-100K",
        _ => ">= 100K",
    };
    let _ = write!(out, " data-size=\"{}\"", escape(size));
    out
}

/// Write `index.html` under `dir` atomically.
pub fn write_index(dir: &Path, page: &str) -> Result<PathBuf, HarnessError> {
    let path = dir.join("index.html");
    meshes::io::atomic_write(&path, |w| w.write_all(page.as_bytes()).map_err(meshes::MeshError::from))?;
    Ok(path)
}
