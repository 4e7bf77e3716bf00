//! `size-series.md`: how each method's cost grows with the mesh on one shape at several sizes.
//!
//! A size series is the scenarios that share a `series` name (the procedural bar at 6K to 1M, igea
//! refined 0 to 2 times). Per series: a table of every case (method × size: precompute, bind,
//! solve, iterations, peak memory, status) with the methods a scenario left out and why, then each
//! method's fitted slopes of log cost against log #V ([`crate::report::dataset::cost_slope`]), so
//! a real shape's growth reads beside the procedural bar's. The plot is `plots/size-series`.

use std::collections::BTreeMap;

use super::document::{Column, Document, Table, Text};
use crate::record::CaseResult;
use crate::scenario::LoadedScenario;

/// The quantities whose growth with #V is fitted, with how each reads off a case.
pub const SLOPE_QUANTITIES: [(&str, fn(&CaseResult) -> f64); 4] = [
    ("time per edit (bind + solve)", |c| c.bind_s + c.solve_s),
    ("per iteration", |c| c.median_iteration_ms),
    ("precompute", |c| c.precompute_s),
    ("peak memory", |c| c.peak_memory_mib),
];

/// The cases of each series with at least two mesh sizes, by series name.
pub fn series_cases(results: &[CaseResult]) -> BTreeMap<&str, Vec<&CaseResult>> {
    let mut out: BTreeMap<&str, Vec<&CaseResult>> = BTreeMap::new();
    for r in results {
        if let Some(s) = &r.series {
            out.entry(s.as_str()).or_default().push(r);
        }
    }
    out.retain(|_, cases| {
        let first = cases[0].vertices;
        cases.iter().any(|c| c.vertices != first)
    });
    out
}

/// `size-series.md` for the series of `results`; the methods each scenario of a series left out
/// (its `left_out`) are rows too. Empty when the run has no series of two sizes or more.
pub fn document(results: &[CaseResult], scenarios: &[LoadedScenario]) -> Document {
    let mut document = Document::default();
    let series = series_cases(results);
    if series.is_empty() {
        return document;
    }
    document.heading(1, "Cost against size");
    document.paragraph(
        Text::plain("One shape at several sizes (scenarios sharing ")
            .then_code("series")
            .then(
                "): each case's time per phase, iterations, peak memory (what the method added; 0 when the \
                 allocator reused memory) and status, then each method's fitted slope of log cost against log #V \
                 (least squares over the sizes that ran; – for fewer than three).",
            ),
    );
    for (name, cases) in &series {
        let methods = crate::report::dataset::methods_of(cases);
        document.heading(2, *name);
        document.table(cases_table(cases, &methods, scenarios));
        document.table(slopes_table(cases, &methods));
    }
    document
}

/// Every case of one series, method by method from the smallest size up, with the methods a
/// scenario left out and why.
fn cases_table(cases: &[&CaseResult], methods: &[&str], scenarios: &[LoadedScenario]) -> Table {
    let mut sizes: Vec<(usize, &str)> = cases.iter().map(|c| (c.vertices, c.scenario.as_str())).collect();
    sizes.sort();
    sizes.dedup();
    let (left, right) = (Column::left, Column::right);
    let mut table = Table::with_columns(vec![
        left("method"),
        left("scenario"),
        right("#V"),
        right("precompute"),
        right("bind"),
        right("solve"),
        right("iterations"),
        right("peak memory"),
        left("status"),
    ]);
    let index = crate::record::CaseIndex::new(cases.iter().copied());
    for m in methods {
        for (vertices, scenario) in &sizes {
            let head = [m.to_string(), scenario.to_string(), vertices.to_string()];
            if let Some(c) = index.get(&crate::record::CaseKey::new(scenario, m)) {
                let measured = [
                    seconds(c.precompute_s),
                    seconds(c.bind_s),
                    seconds(c.solve_s),
                    c.iterations.to_string(),
                    mebibytes(c.peak_memory_mib),
                    c.status.to_string(),
                ];
                table.push_row(head.into_iter().chain(measured));
            } else if let Some(why) = left_out(scenarios, scenario, m) {
                let none = std::iter::repeat_n("–".to_string(), 5);
                table.push_row(head.into_iter().chain(none).chain([format!("left out: {why}")]));
            }
        }
    }
    table
}

/// Each method's fitted slopes of log cost against log #V over the sizes it ran.
fn slopes_table(cases: &[&CaseResult], methods: &[&str]) -> Table {
    let mut header = vec![Column::left("method")];
    header.extend(SLOPE_QUANTITIES.iter().map(|(label, _)| Column::right(format!("slope: {label}"))));
    header.push(Column::right("sizes"));
    let mut table = Table::with_columns(header);
    for m in methods {
        let ran: Vec<&&CaseResult> =
            cases.iter().filter(|c| c.method == *m && !c.status.is_failed()).collect();
        let slopes = SLOPE_QUANTITIES.iter().map(|(_, quantity)| {
            let (slope, _) =
                crate::report::dataset::cost_slope(ran.iter().map(|c| (c.vertices, quantity(c))));
            if slope.is_finite() {
                format!("{slope:.2}")
            } else {
                "–".into()
            }
        });
        table.push_row(std::iter::once(m.to_string()).chain(slopes).chain([ran.len().to_string()]));
    }
    table
}

/// Why `scenario` left `method` out, if it did.
fn left_out<'a>(scenarios: &'a [LoadedScenario], scenario: &str, method: &str) -> Option<&'a str> {
    scenarios.iter().find(|s| s.spec.name == scenario)?.spec.left_out.get(method).map(String::as_str)
}

/// Seconds for a table: `12.3 ms`, `4.56 s`; `–` when not measured.
fn seconds(s: f64) -> String {
    if !s.is_finite() {
        "–".into()
    } else if s < 1.0 {
        format!("{:.3} ms", s * 1e3).replace(".000 ms", " ms")
    } else {
        format!("{s:.2} s")
    }
}

/// MiB for a table, as GiB above 1024; `–` when not measured.
fn mebibytes(m: f64) -> String {
    if !m.is_finite() {
        "–".into()
    } else if m >= 1024.0 {
        format!("{:.2} GiB", m / 1024.0)
    } else {
        format!("{m:.0} MiB")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(scenario: &str, method: &str, vertices: usize, seconds: f64) -> CaseResult {
        let mut c = CaseResult::empty(scenario, method, "procedural", vertices, 2 * vertices);
        c.series = Some("bar".into());
        c.status = "ok".parse().unwrap();
        c.precompute_s = seconds;
        c.bind_s = seconds;
        c.solve_s = seconds;
        c.median_iteration_ms = 1.0;
        c.peak_memory_mib = vertices as f64 / 1000.0;
        c
    }

    #[test]
    fn a_series_of_power_laws_reads_its_exponents() {
        // Time grows as #V^1.5, memory as #V, the iteration not at all.
        let results: Vec<CaseResult> = [1_000usize, 10_000, 100_000]
            .iter()
            .map(|&v| case(&format!("bar-{v}"), "arap", v, (v as f64).powf(1.5) * 1e-6))
            .collect();
        let md = document(&results, &[]).to_markdown();
        assert!(md.contains("## bar"), "{md}");
        assert!(md.contains("| arap | 1.50 | 0.00 | 1.50 | 1.00 | 3 |"), "{md}");
        assert!(md.contains("| arap | bar-100000 | 100000 |"), "{md}");
    }

    #[test]
    fn one_size_is_no_series() {
        let results = vec![case("bar-a", "arap", 1_000, 1.0), case("bar-b", "hirm", 1_000, 1.0)];
        assert!(series_cases(&results).is_empty());
        assert!(document(&results, &[]).is_empty());
    }
}
