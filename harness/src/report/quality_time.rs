//! `pareto.md` and the page's "Quality against time": for every test with sweep points
//! ([`crate::sweep`]), the budget table (for each time per edit of [`BUDGETS_S`], the `ok` case with
//! the lowest error, per measure of [`MEASURES`]), the front of each measure against the time per
//! edit, and every point with its parameters, times, measures and status.

use std::path::Path;

use super::document::{write_text, Document, Table, Text};
use crate::pareto::{best_within, budget_label, ok_front, points, TimeAxis, BUDGETS_S, MEASURES};
use crate::record::CaseResult;

/// The fewest settings of one sweep on a test that make it a swept test: a trade-off needs a line,
/// and `isolines[isolines=10]` beside `isolines` in every run is not a sweep run.
pub const MIN_SWEEP_POINTS: usize = 3;

/// The tests of `results` on which some sweep has at least [`MIN_SWEEP_POINTS`] cases, in report
/// order.
pub fn swept_scenarios(results: &[CaseResult]) -> Vec<&str> {
    let mut out: Vec<&str> = Vec::new();
    let index = crate::record::CaseIndex::new(results);
    for r in results.iter().filter(|r| !r.sweeps.is_empty()) {
        if out.contains(&r.scenario.as_str()) {
            continue;
        }
        let swept = r.sweeps.iter().any(|p| {
            (index.of_scenario(&r.scenario)).filter(|c| c.sweeps.iter().any(|q| q.sweep == p.sweep)).count()
                >= MIN_SWEEP_POINTS
        });
        if swept {
            out.push(&r.scenario);
        }
    }
    out
}

/// A measure's value with its unit, if it has one: `9.07 °`, `0.0439`.
fn value_text(measure: crate::metrics::Metric, value: f64) -> String {
    let spec = measure.spec();
    let text = spec.format.apply(Some(value));
    if spec.unit.is_empty() {
        text
    } else {
        format!("{text} {}", spec.unit)
    }
}

/// A time in the unit that reads best: `0.42 ms`, `3.1 s`.
fn seconds_text(s: f64) -> String {
    if !s.is_finite() {
        "–".into()
    } else if s < 1.0 {
        format!("{:.3} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

/// The budget table of one test: a row per budget, a column per measure, each cell the best `ok`
/// case within the budget per edit, its value and its time.
pub fn budget_table(cases: &[&CaseResult]) -> Table {
    let titles = MEASURES.iter().map(|m| format!("best by {}", m.spec().label));
    let mut table = Table::new(std::iter::once("budget per edit".to_string()).chain(titles));
    // Per measure: the placed cases, their points and which are `ok`.
    let placed: Vec<_> = MEASURES
        .iter()
        .map(|&measure| {
            let placed = points(cases, TimeAxis::Edit, measure);
            let coordinates: Vec<_> = placed.iter().map(|(_, p)| *p).collect();
            let ok: Vec<bool> = placed.iter().map(|(c, _)| c.status.is_ok()).collect();
            (measure, placed, coordinates, ok)
        })
        .collect();
    for budget in BUDGETS_S {
        let best = placed.iter().map(|(measure, placed, coordinates, ok)| {
            match best_within(coordinates, ok, budget) {
                Some(i) => format!(
                    "{}: {}, {}",
                    placed[i].0.method,
                    value_text(*measure, coordinates[i].error),
                    seconds_text(coordinates[i].time)
                ),
                None => "none ok within it".to_string(),
            }
        });
        table.push_row(std::iter::once(budget_label(budget)).chain(best));
    }
    table
}

/// The front of the `ok` cases by `measure` against the time per edit (one line, fastest first).
pub fn front_list(cases: &[&CaseResult], measure: crate::metrics::Metric) -> String {
    let placed = points(cases, TimeAxis::Edit, measure);
    ok_front(&placed)
        .into_iter()
        .map(|i| {
            let (c, p) = &placed[i];
            format!("{} {} at {}", c.method, value_text(measure, p.error), seconds_text(p.time))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// "Front of `measure` against the time per edit: " and its [`front_list`].
pub fn front(cases: &[&CaseResult], measure: crate::metrics::Metric) -> Text {
    Text::plain(format!(
        "Front of {} against the time per edit: {}",
        measure.spec().label,
        front_list(cases, measure)
    ))
}

/// Every case of one test as a point: its sweeps and values, both times, the measures, the status.
pub fn points_table(cases: &[&CaseResult]) -> Table {
    let titles = ["method", "sweep: values", "per edit", "with precompute"].map(String::from).into_iter();
    let measures = MEASURES.iter().map(|m| m.spec().label.to_string());
    let mut table = Table::new(titles.chain(measures).chain(["status".to_string()]));
    for c in cases {
        let sweeps =
            c.sweeps.iter().map(|p| format!("{}: {}", p.sweep, p.values)).collect::<Vec<_>>().join("; ");
        let mut cells = vec![
            c.method.clone(),
            if sweeps.is_empty() { "–".to_string() } else { sweeps },
            seconds_text(TimeAxis::Edit.seconds(c)),
            seconds_text(TimeAxis::WithPrecompute.seconds(c)),
        ];
        cells.extend(MEASURES.iter().map(|&m| m.spec().format.apply(c.quality.get(m))));
        cells.push(c.status.kind().to_string());
        table.push_row(cells);
    }
    table
}

/// `pareto.md`: per swept test its budget table, fronts and points (empty without sweep points).
pub fn document(results: &[CaseResult]) -> Document {
    let mut document = Document::default();
    let scenarios = swept_scenarios(results);
    if scenarios.is_empty() {
        return document;
    }
    document.heading(1, "Quality against time");
    for scenario in scenarios {
        let cases: Vec<&CaseResult> = results.iter().filter(|r| r.scenario == scenario).collect();
        document.heading(2, scenario);
        document.paragraph(
            Text::plain("The ")
                .then_code("ok")
                .then(" case with the lowest error within each time per edit (bind + solve):"),
        );
        document.table(budget_table(&cases));
        for m in MEASURES {
            document.paragraph(front(&cases, m));
        }
        document.table(points_table(&cases));
    }
    document
}

/// Write `pareto.md` under `dir` (atomically) when `results` have a swept test.
pub fn write_markdown(dir: &Path, results: &[CaseResult]) -> Result<(), crate::error::HarnessError> {
    let document = document(results);
    if !document.is_empty() {
        // pareto.md has always ended in a blank line after its last table.
        write_text(&dir.join("pareto.md"), &format!("{}\n", document.to_markdown()))?;
    }
    Ok(())
}
