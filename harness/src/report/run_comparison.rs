//! `harness compare`'s report: the comparison of two runs ([`crate::comparison`]) as markdown (also
//! what the command prints) and as a standalone HTML page.

use std::fmt::Write as _;

use super::html::escape;
use crate::comparison::{CaseChange, Comparison, PhaseChange, Speed};

/// `1.23 (1.20–1.31)` seconds: the median and its range when there is one.
fn timing_text(p: &PhaseChange, b: bool) -> String {
    let t = if b { p.b } else { p.a };
    if !t.median.is_finite() {
        return "–".into();
    }
    if t.repetitions > 1 {
        format!("{} ({}–{})", seconds(t.median), seconds(t.min), seconds(t.max))
    } else {
        seconds(t.median)
    }
}

fn seconds(s: f64) -> String {
    if s >= 10.0 {
        format!("{s:.1}")
    } else if s >= 0.01 {
        format!("{s:.3}")
    } else {
        format!("{s:.2e}")
    }
}

fn ratio_text(r: f64) -> String {
    if r.is_finite() {
        format!("{r:.2}")
    } else {
        "–".into()
    }
}

/// The phases other than the total that were judged slower or faster, e.g. `solve slower (4.1x)`.
fn phase_notes(c: &CaseChange) -> String {
    c.phases
        .iter()
        .filter(|p| p.phase != crate::record::TimedPhase::Total)
        .filter(|p| matches!(p.speed, Speed::Slower | Speed::Faster))
        .map(|p| format!("{} {} ({:.2}x)", p.phase.label(), p.speed.label(), p.ratio))
        .collect::<Vec<_>>()
        .join(", ")
}

/// B's status, or `A's → B's` when it changed.
fn status_text(c: &CaseChange) -> String {
    if c.status.0 == c.status.1 {
        c.status.1.clone()
    } else {
        format!("{} → {}", c.status.0, c.status.1)
    }
}

fn quality_text(c: &CaseChange) -> String {
    if c.quality.is_empty() {
        return "same".into();
    }
    c.quality.iter().map(|f| f.to_string()).collect::<Vec<_>>().join("; ")
}

fn summary_line(comparison: &Comparison) -> String {
    let t = comparison.tally();
    format!(
        "{} cases in both runs: {} slower, {} faster, {} same within noise, {} not judged (the total time, \
         precompute + bind + solve; slower or faster only when the min–max ranges, each widened to at least {:.0} ms, \
         do not overlap and the medians differ by {:.0}% or more); quality: {} worse, {} better (the gate's \
         tolerances, A as the baseline).",
        comparison.cases.len(),
        t.slower,
        t.faster,
        t.same,
        t.not_judged,
        1e3 * crate::comparison::NOISE_FLOOR_S,
        100.0 * comparison.min_change,
        t.worse,
        t.better
    )
}

/// The comparison as markdown.
pub fn render_markdown(comparison: &Comparison) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# B against A\n");
    if comparison.same_commit_and_inputs {
        let _ = writeln!(md, "{}\n", crate::comparison::SAME_COMMIT_AND_INPUTS);
    }
    let _ = writeln!(md, "- A: `{}`: {}", comparison.a.display(), comparison.a_record);
    let _ = writeln!(md, "- B: `{}`: {}\n", comparison.b.display(), comparison.b_record);
    for w in &comparison.warnings {
        let _ = writeln!(md, "**Warning:** {w}\n");
    }
    let _ = writeln!(md, "{}\n", summary_line(comparison));
    md.push_str("| scenario | method | total A (s) | total B (s) | B / A | time | phases | iterations | status | quality |\n");
    md.push_str("|---|---|---:|---:|---:|---|---|---:|---|---|\n");
    for c in &comparison.cases {
        let total = c.total();
        let status = status_text(c);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} → {} | {} | {} |",
            c.scenario,
            c.method,
            timing_text(total, false),
            timing_text(total, true),
            ratio_text(total.ratio),
            c.speed().label(),
            phase_notes(c),
            c.iterations.0,
            c.iterations.1,
            status.replace('|', "\\|"),
            quality_text(c).replace('|', "\\|")
        );
    }
    for (name, list) in [("A", &comparison.only_in_a), ("B", &comparison.only_in_b)] {
        if !list.is_empty() {
            let _ = writeln!(md, "\nOnly in {name}: {}.", list.join(", "));
        }
    }
    md
}

/// The comparison as a page that opens from disk.
pub fn render_html(comparison: &Comparison) -> String {
    let mut page = String::from(concat!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n",
        "<title>deformbench: B against A</title>\n<style>\n",
        "body{font-family:sans-serif;margin:2em;max-width:1500px;color:#222}\n",
        "table{border-collapse:collapse;font-size:13px;margin:1em 0}\n",
        "th,td{border:1px solid #ccc;padding:3px 7px;text-align:right;white-space:nowrap}\n",
        "th{background:#f0f0f0}td.text{text-align:left;white-space:normal;max-width:420px}\n",
        "tr.slower td.speed{background:#fdd}tr.faster td.speed{background:#dfd}\n",
        "tr.worse td.quality{background:#fdd}tr.better td.quality{background:#dfd}\n",
        "p.warning{background:#fff1d6;padding:.4em .7em;border-left:4px solid #d90}\n",
        "p.same{font-weight:bold}\n",
        "</style>\n</head>\n<body>\n<h1>B against A</h1>\n"
    ));
    if comparison.same_commit_and_inputs {
        let _ = writeln!(page, "<p class=\"same\">{}</p>", crate::comparison::SAME_COMMIT_AND_INPUTS);
    }
    let _ = writeln!(
        page,
        "<ul><li>A: <code>{}</code>: {}</li><li>B: <code>{}</code>: {}</li></ul>",
        escape(&comparison.a.display().to_string()),
        escape(&comparison.a_record),
        escape(&comparison.b.display().to_string()),
        escape(&comparison.b_record)
    );
    for w in &comparison.warnings {
        let _ = writeln!(page, "<p class=\"warning\">Warning: {}</p>", escape(w));
    }
    let _ = writeln!(page, "<p id=\"summary\">{}</p>", escape(&summary_line(comparison)));
    page.push_str(
        "<table>\n<tr><th>scenario</th><th>method</th><th>total A (s)</th><th>total B (s)</th><th>B / A</th>\
         <th>time</th><th>phases</th><th>iterations</th><th>status</th><th>quality</th></tr>\n",
    );
    for c in &comparison.cases {
        let total = c.total();
        let mut classes = vec![c.speed().label().replace(' ', "-")];
        if c.is_worse() {
            classes.push("worse".into());
        } else if c.is_better() {
            classes.push("better".into());
        }
        let status = status_text(c);
        let _ = writeln!(
            page,
            "<tr class=\"{}\"><td class=\"text\">{}</td><td class=\"text\">{}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td class=\"speed\">{}</td><td class=\"text\">{}</td><td>{} → {}</td><td class=\"text\">{}</td>\
             <td class=\"text quality\">{}</td></tr>",
            classes.join(" "),
            escape(&c.scenario),
            escape(&c.method),
            timing_text(total, false),
            timing_text(total, true),
            ratio_text(total.ratio),
            c.speed().label(),
            escape(&phase_notes(c)),
            c.iterations.0,
            c.iterations.1,
            escape(&status),
            escape(&quality_text(c))
        );
    }
    page.push_str("</table>\n");
    for (name, list) in [("A", &comparison.only_in_a), ("B", &comparison.only_in_b)] {
        if !list.is_empty() {
            let _ = writeln!(page, "<p>Only in {name}: {}.</p>", escape(&list.join(", ")));
        }
    }
    page.push_str("</body>\n</html>\n");
    page
}
