//! The answer across a dataset (issue 36): for the cases of collections (scenarios with a
//! [`Member`]: an edit family run over many meshes), `dataset.md` and the page's section with
//! - robustness: per family and method, how many cases were ok / suspect / unfinished / failed,
//!   and how many meshes were skipped before any method ran;
//! - error spread: per family and method, the median and 90th percentile of e_iso, E_theta, E_phi,
//!   e_area and the RMS distance to arap, over the cases with a finished shape (ok or suspect);
//! - cost: the median time per edit (bind + solve) and with the precompute, and the fitted slope
//!   of log time against log #V ([`cost_slope`]), the cost growth the papers claim;
//! - rank: each method's median rank by e_iso among the `ok` cases on the same mesh and edit
//!   ([`ranks`]); the cases not ranked are counted under each table with their reasons.
//! The plots (ECDFs, cost against #V) are in [`super::plots`], the worst-case sheets in
//! [`super::render`].

use std::collections::BTreeMap;

use super::document::{Document, Table, Text};
use crate::metrics::{percentile, Metric};
use crate::pareto::TimeAxis;
use crate::record::CaseResult;
use crate::scenario::SkippedInput;
use crate::verdict::{reason_kind, REASON_KINDS, STATUS_KINDS};

/// The measures whose spread the report gives, lower is better for each.
pub const SPREAD_MEASURES: [Metric; 5] =
    [Metric::EIso, Metric::ETheta, Metric::EPhi, Metric::EArea, Metric::RmsToArap];

/// How many of a method's worst `ok` cases per family a worst-case sheet shows.
pub const WORST_PER_METHOD: usize = 5;

/// The measure worst-case sheets and ranks order by: e_iso, which sees size and angle together
/// (issue 62: by E_phi, blind to size, scale_aware ranked first on bend and stretch with the largest
/// e_area of any method there).
pub const RANK_MEASURE: Metric = Metric::EIso;

/// The cases of `results` that belong to a collection, if any.
pub fn dataset_cases(results: &[CaseResult]) -> Vec<&CaseResult> {
    results.iter().filter(|r| r.member.is_some()).collect()
}

/// The collections (families) of `cases`, in order of first appearance.
pub fn families<'a>(cases: &[&'a CaseResult]) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for c in cases {
        let family = c.member.as_ref().map_or("", |m| m.collection.as_str());
        if !out.contains(&family) {
            out.push(family);
        }
    }
    out
}

/// The methods of `cases`, in order of first appearance (the run's plan order).
pub fn methods_of<'a>(cases: &[&'a CaseResult]) -> Vec<&'a str> {
    let mut out: Vec<&str> = Vec::new();
    for c in cases {
        if !out.contains(&c.method.as_str()) {
            out.push(&c.method);
        }
    }
    out
}

fn family_of(case: &CaseResult) -> &str {
    case.member.as_ref().map_or("", |m| m.collection.as_str())
}

/// Whether a case left a finished shape to measure (ok or suspect).
fn finished(case: &CaseResult) -> bool {
    case.status.is_ok() || case.status.is_suspect()
}

/// Median and 90th percentile (nearest rank) of the finite values; NaN for none.
pub fn median_and_p90(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let values: Vec<f64> = values.filter(|v| v.is_finite()).collect();
    if values.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    (percentile(values.clone(), 0.5), percentile(values, 0.9))
}

/// The least-squares slope of `ln time` against `ln vertices` over the points with a positive,
/// finite time, and how many there were; NaN with fewer than 3 points or one mesh size only.
pub fn cost_slope(points: impl Iterator<Item = (usize, f64)>) -> (f64, usize) {
    let logs: Vec<(f64, f64)> = points
        .filter(|(v, t)| *v > 0 && t.is_finite() && *t > 0.0)
        .map(|(v, t)| ((v as f64).ln(), t.ln()))
        .collect();
    let n = logs.len();
    if n < 3 {
        return (f64::NAN, n);
    }
    let (mx, my) = logs.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n as f64, b + y / n as f64));
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    (if sxx > 0.0 { sxy / sxx } else { f64::NAN }, n)
}

/// Each `ok` case's rank by [`RANK_MEASURE`] among the `ok` cases of its scenario (1 = best; ties
/// share the better rank), keyed by (scenario, method). Suspect, unfinished and failed cases have
/// no rank (issue 62: a broken result ranked among clean ones misleads; [`unranked`] lists them).
pub fn ranks(cases: &[&CaseResult]) -> BTreeMap<(String, String), usize> {
    let mut by_scenario: BTreeMap<&str, Vec<&CaseResult>> = BTreeMap::new();
    for c in cases.iter().filter(|c| c.status.is_ok() && c.metric(RANK_MEASURE).is_finite()) {
        by_scenario.entry(&c.scenario).or_default().push(c);
    }
    let mut out = BTreeMap::new();
    for (scenario, group) in by_scenario {
        for c in &group {
            let v = c.metric(RANK_MEASURE);
            let rank = 1 + group.iter().filter(|o| o.metric(RANK_MEASURE) < v).count();
            out.insert((scenario.to_string(), c.method.clone()), rank);
        }
    }
    out
}

/// Per method of `methods`, how many of its cases in `family` (all: `None`) have no rank in `ranks`
/// ([`ranks`] of `cases`), and why: `scale_aware 7 (suspect 6: swells 4, shrinks 2; unfinished 1)`;
/// `None` when every case is ranked.
pub fn unranked(
    cases: &[&CaseResult],
    methods: &[&str],
    family: Option<&str>,
    ranks: &BTreeMap<(String, String), usize>,
) -> Option<String> {
    let mut parts = Vec::new();
    for m in methods {
        let left: Vec<&CaseResult> = (cases.iter().copied())
            .filter(|c| c.method == *m && family.is_none_or(|f| family_of(c) == f))
            .filter(|c| !ranks.contains_key(&(c.scenario.clone(), c.method.clone())))
            .collect();
        if left.is_empty() {
            continue;
        }
        let mut why = Vec::new();
        for kind in STATUS_KINDS {
            let of: Vec<&CaseResult> = left.iter().copied().filter(|c| c.status.kind() == kind).collect();
            if of.is_empty() {
                continue;
            }
            let reasons: Vec<String> = REASON_KINDS
                .iter()
                .filter_map(|r| {
                    let n = of
                        .iter()
                        .filter(|c| c.status.shape_reasons().any(|t| reason_kind(t) == Some(r)))
                        .count();
                    (n > 0 && kind == STATUS_KINDS[1]).then(|| format!("{r} {n}"))
                })
                .collect();
            let reasons =
                if reasons.is_empty() { String::new() } else { format!(": {}", reasons.join(", ")) };
            why.push(format!("{kind} {}{reasons}", of.len()));
        }
        parts.push(format!("{m} {} ({})", left.len(), why.join("; ")));
    }
    (!parts.is_empty()).then(|| format!("Not ranked: {}.", parts.join("; ")))
}

/// For each family, each method's [`WORST_PER_METHOD`] `ok` cases with the largest
/// [`RANK_MEASURE`], worst first: (family, method, cases).
pub fn worst_ok<'a>(cases: &[&'a CaseResult]) -> Vec<(String, String, Vec<&'a CaseResult>)> {
    let mut out = Vec::new();
    for family in families(cases) {
        for method in methods_of(cases) {
            let mut ok: Vec<&CaseResult> = cases
                .iter()
                .copied()
                .filter(|c| family_of(c) == family && c.method == method && c.status.is_ok())
                .filter(|c| c.metric(RANK_MEASURE).is_finite())
                .collect();
            ok.sort_by(|a, b| b.metric(RANK_MEASURE).total_cmp(&a.metric(RANK_MEASURE)));
            ok.truncate(WORST_PER_METHOD);
            if !ok.is_empty() {
                out.push((family.to_string(), method.to_string(), ok));
            }
        }
    }
    out
}

/// A number for a table: 3 significant digits, `–` for NaN.
fn num(v: f64) -> String {
    if !v.is_finite() {
        "–".into()
    } else if v == 0.0 {
        "0".into()
    } else if v.abs() >= 100.0 {
        format!("{v:.0}")
    } else {
        let digits = (2 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.digits$}")
    }
}

/// Seconds as a short time: `12 ms`, `3.4 s`.
fn time(s: f64) -> String {
    if !s.is_finite() {
        "–".into()
    } else if s < 1.0 {
        format!("{} ms", num(s * 1e3))
    } else {
        format!("{} s", num(s))
    }
}

/// `dataset.md`: every table of the module doc, for the dataset cases of `results` and the
/// `skipped` meshes; empty when the run has no collection.
pub fn document(results: &[CaseResult], skipped: &[SkippedInput]) -> Document {
    let mut document = Document::default();
    let cases = dataset_cases(results);
    if cases.is_empty() {
        return document;
    }
    let methods = methods_of(&cases);
    document.heading(1, "Across the dataset");
    document.paragraph(summary(&cases, skipped));
    document.heading(2, "Robustness");
    document.table(robustness_table(&cases, &methods, skipped));
    document.heading(2, "Why suspect");
    document.table(reasons_table(&cases, &methods));
    error_spread_cost_and_rank(&mut document, &cases, &methods);
    document.heading(2, "Cost growth");
    document.table(cost_growth_table(&cases, &methods));
    worst_ok_results(&mut document, &cases);
    inputs_and_failures(&mut document, &cases, skipped);
    document
}

/// How many cases, families, methods and meshes ran, and how many meshes were skipped.
fn summary(cases: &[&CaseResult], skipped: &[SkippedInput]) -> String {
    let meshes: std::collections::BTreeSet<&str> =
        cases.iter().filter_map(|c| c.member.as_ref().map(|m| m.mesh.as_str())).collect();
    format!(
        "{} cases: {} edit families × {} methods on {} meshes that ran; {} (family, mesh) pairs skipped \
         before any method ran (listed at the end).",
        cases.len(),
        families(cases).len(),
        methods_of(cases).len(),
        meshes.len(),
        skipped.len()
    )
}

/// Per method and family (and all families), the cases per status; then the meshes of each family
/// skipped at load.
fn robustness_table(cases: &[&CaseResult], methods: &[&str], skipped: &[SkippedInput]) -> Table {
    let families = families(cases);
    let mut table = Table::new(std::iter::once("method").chain(families.iter().copied()).chain(["all"]))
        .captioned(
            "Cases per status (ok / suspect / unfinished / failed), and the meshes of the family skipped at \
             load (every method alike).",
        );
    for m in methods {
        let counts = |family: Option<&str>| {
            let of: Vec<&&CaseResult> =
                cases.iter().filter(|c| c.method == *m && family.is_none_or(|f| family_of(c) == f)).collect();
            STATUS_KINDS
                .iter()
                .map(|k| of.iter().filter(|c| c.status.kind() == *k).count().to_string())
                .collect::<Vec<_>>()
                .join(" / ")
        };
        let per_family = families.iter().map(|f| counts(Some(f)));
        table.push_row(std::iter::once(m.to_string()).chain(per_family).chain([counts(None)]));
    }
    let per_family =
        families.iter().map(|f| skipped.iter().filter(|s| s.member.collection == *f).count().to_string());
    table.push_row(
        std::iter::once("skipped meshes".to_string()).chain(per_family).chain([skipped.len().to_string()]),
    );
    table
}

/// Per method, how many cases (all families) carry each kind of shape reason
/// ([`crate::verdict::REASON_KINDS`]; a case may have several): what makes the suspect cases suspect.
fn reasons_table(cases: &[&CaseResult], methods: &[&str]) -> Table {
    let mut table = Table::new(std::iter::once("method").chain(REASON_KINDS)).captioned(
        "Cases of all families whose shape a verdict flags, per reason (a case may have several; unfinished \
         cases count too, their shape reasons follow the cap).",
    );
    for m in methods {
        let counts = REASON_KINDS.iter().map(|kind| {
            cases
                .iter()
                .filter(|c| c.method == *m && c.status.shape_reasons().any(|r| reason_kind(r) == Some(kind)))
                .count()
                .to_string()
        });
        table.push_row(std::iter::once(m.to_string()).chain(counts));
    }
    table
}

/// "Error spread, cost and rank": what the tables give, then a table per family and one over all
/// families.
fn error_spread_cost_and_rank(document: &mut Document, cases: &[&CaseResult], methods: &[&str]) {
    document.heading(2, "Error spread, cost and rank");
    document.paragraph(
        "Median and 90th percentile over the cases with a finished shape (ok or suspect); times are medians \
         over the cases that ran (failed ones have none); rank by e_iso (size and angle together) among the \
         ok cases on the same mesh and edit (1 = best); the median rank counts ranked cases only, and the \
         cases not ranked (suspect, unfinished, failed) are counted under each table with their reasons.",
    );
    let ranks = ranks(cases);
    for family in families(cases).into_iter().map(Some).chain([None]) {
        document.heading(3, family.unwrap_or("all families"));
        document.table(spread_table(cases, methods, family, &ranks));
        if let Some(note) = unranked(cases, methods, family, &ranks) {
            document.paragraph(note);
        }
    }
}

/// Per method, over the cases of `family` (all: `None`): the spread of each measure of
/// [`SPREAD_MEASURES`], the median times and the median rank.
fn spread_table(
    cases: &[&CaseResult],
    methods: &[&str],
    family: Option<&str>,
    ranks: &BTreeMap<(String, String), usize>,
) -> Table {
    let spreads = SPREAD_MEASURES.iter().map(|m| format!("{} median / p90", m.spec().label));
    let titles = ["method", "finished"].map(String::from).into_iter().chain(spreads);
    let mut table = Table::new(
        titles.chain(["time per edit", "with precompute", "ranked", "median rank"].map(String::from)),
    );
    for m in methods {
        let of: Vec<&CaseResult> = cases
            .iter()
            .copied()
            .filter(|c| c.method == *m && family.is_none_or(|f| family_of(c) == f))
            .collect();
        let done: Vec<&CaseResult> = of.iter().copied().filter(|c| finished(c)).collect();
        let mut cells = vec![m.to_string(), format!("{} of {}", done.len(), of.len())];
        for measure in SPREAD_MEASURES {
            let (median, p90) = median_and_p90(done.iter().map(|c| c.metric(measure)));
            cells.push(format!("{} / {}", num(median), num(p90)));
        }
        let ran = || of.iter().filter(|c| !c.status.is_failed());
        let (edit, _) = median_and_p90(ran().map(|c| TimeAxis::Edit.seconds(c)));
        let (with, _) = median_and_p90(ran().map(|c| TimeAxis::WithPrecompute.seconds(c)));
        let rank: Vec<f64> = of
            .iter()
            .filter_map(|c| ranks.get(&(c.scenario.clone(), c.method.clone())))
            .map(|&r| r as f64)
            .collect();
        let ranked = format!("{} of {}", rank.len(), of.len());
        let (rank, _) = median_and_p90(rank.into_iter());
        cells.extend([time(edit), time(with), ranked, num(rank)]);
        table.push_row(cells);
    }
    table
}

/// Per method, the slope of log time against log #V over its cases that ran (all families).
fn cost_growth_table(cases: &[&CaseResult], methods: &[&str]) -> Table {
    let mut table = Table::new(["method", "cases", "time per edit", "per iteration", "precompute"])
        .captioned(
            "Least-squares slope of log time against log #V over every case of the method that ran (all \
         families): 1 is linear in the mesh size. The reduced models claim a per-iteration cost independent \
         of #V (slope near 0) and pay for it in the precompute.",
        );
    for m in methods {
        let of: Vec<&CaseResult> =
            cases.iter().copied().filter(|c| c.method == *m && !c.status.is_failed()).collect();
        let slope = |t: &dyn Fn(&CaseResult) -> f64| cost_slope(of.iter().map(|c| (c.vertices, t(c)))).0;
        table.push_row([
            m.to_string(),
            of.len().to_string(),
            num(slope(&|c| TimeAxis::Edit.seconds(c))),
            num(slope(&|c| c.median_iteration_ms)),
            num(slope(&|c| c.precompute_s)),
        ]);
    }
    table
}

/// "Worst ok results": per family and method the worst `ok` meshes by [`RANK_MEASURE`].
fn worst_ok_results(document: &mut Document, cases: &[&CaseResult]) {
    document.heading(2, "Worst ok results");
    document.paragraph(
        Text::plain("Per family, each method's five ")
            .then_code("ok")
            .then(" cases with the largest E_phi (the sheets ")
            .then_code("figures/worst-<family>.png")
            .then(" draw them beside arap's result): garbage called ok is one look away."),
    );
    let items = worst_ok(cases).into_iter().map(|(family, method, worst)| {
        let list = worst
            .iter()
            .map(|c| {
                let mesh = c.member.as_ref().map_or("", |m| m.mesh.as_str());
                format!("{mesh} ({}°)", num(c.metric(RANK_MEASURE)))
            })
            .collect::<Vec<_>>()
            .join(", ");
        Text::plain(format!("{family} / {method}: {list}"))
    });
    document.list(items.collect());
}

/// The failed cases, the meshes `repair = true` changed and the skipped meshes, each when there are
/// any.
fn inputs_and_failures(document: &mut Document, cases: &[&CaseResult], skipped: &[SkippedInput]) {
    let failed: Vec<Text> = cases
        .iter()
        .filter(|c| c.status.is_failed())
        .map(|c| Text::plain(format!("{} / {}: {}", c.scenario, c.method, c.status)))
        .collect();
    if !failed.is_empty() {
        document.heading(2, "Failed cases");
        document.list(failed);
    }
    let mut repaired: Vec<(&str, &str)> = cases
        .iter()
        .filter_map(|c| c.member.as_ref())
        .filter_map(|m| m.repaired.as_deref().map(|r| (m.mesh.as_str(), r)))
        .collect();
    repaired.sort();
    repaired.dedup();
    if !repaired.is_empty() {
        document.heading(2, Text::plain("Repaired meshes (").then_code("repair = true").then(")"));
        document
            .list(repaired.into_iter().map(|(mesh, what)| Text::plain(format!("{mesh}: {what}"))).collect());
    }
    if !skipped.is_empty() {
        document.heading(2, "Skipped meshes");
        let items =
            skipped.iter().map(|s| format!("skipped: {} ({}): {}", s.scenario, s.file.display(), s.reason));
        document.list(items.map(Text::plain).collect());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Member;
    use crate::verdict::Status;

    fn case(
        family: &str,
        mesh: &str,
        method: &str,
        vertices: usize,
        e_phi: f64,
        status: Status,
    ) -> CaseResult {
        let mut c = CaseResult::empty(&format!("{family}-{mesh}"), method, "file", vertices, 2 * vertices);
        c.member = Some(Member {
            collection: family.into(),
            mesh: mesh.into(),
            attributes: Vec::new(),
            repaired: None,
        });
        c.quality.set(Metric::EPhi, e_phi.is_finite().then_some(e_phi));
        c.quality.set(RANK_MEASURE, e_phi.is_finite().then_some(e_phi));
        c.status = status;
        c
    }

    #[test]
    fn the_cost_slope_of_a_power_law_is_its_exponent() {
        let points = [1_000usize, 4_000, 16_000, 64_000].map(|v| (v, 3e-6 * (v as f64).powf(1.5)));
        let (slope, n) = cost_slope(points.into_iter());
        assert!((slope - 1.5).abs() < 1e-12 && n == 4, "{slope}");
        let (slope, n) = cost_slope([(1_000usize, 0.1), (2_000, f64::NAN)].into_iter());
        assert!(slope.is_nan() && n == 1);
    }

    #[test]
    fn only_ok_cases_are_ranked_ties_share_and_the_others_are_listed_with_their_reasons() {
        let cases = [
            case("bend", "a", "arap", 10, 1.0, Status::Ok),
            case("bend", "a", "hirm", 10, 3.0, Status::Suspect(vec!["folds".into()])),
            case("bend", "a", "laplacian", 10, 1.0, Status::Ok),
            case("bend", "a", "isolines", 10, 0.5, Status::Unfinished(vec!["cap".into()])),
            case("bend", "a", "spectral_mhb", 10, f64::NAN, Status::Failed("x".into())),
        ];
        let refs: Vec<&CaseResult> = cases.iter().collect();
        let r = ranks(&refs);
        let rank = |m: &str| r.get(&("bend-a".to_string(), m.to_string())).copied();
        assert_eq!(
            [rank("arap"), rank("laplacian"), rank("hirm"), rank("isolines"), rank("spectral_mhb")],
            [Some(1), Some(1), None, None, None]
        );
        let methods = methods_of(&refs);
        assert_eq!(
            unranked(&refs, &methods, None, &r).unwrap(),
            "Not ranked: hirm 1 (suspect 1: folds 1); isolines 1 (unfinished 1); spectral_mhb 1 (failed 1)."
        );
        assert_eq!(unranked(&refs[..2], &methods, Some("twist"), &r), None);
    }

    #[test]
    fn worst_sheets_take_the_largest_rank_measure_of_ok_cases_only() {
        let mut cases: Vec<CaseResult> =
            (0..8).map(|i| case("twist", &format!("m{i}"), "hirm", 100, i as f64, Status::Ok)).collect();
        cases.push(case("twist", "bad", "hirm", 100, 90.0, Status::Suspect(vec!["folds".into()])));
        let refs: Vec<&CaseResult> = cases.iter().collect();
        let worst = worst_ok(&refs);
        assert_eq!(worst.len(), 1);
        let meshes: Vec<&str> = worst[0].2.iter().map(|c| c.member.as_ref().unwrap().mesh.as_str()).collect();
        assert_eq!(meshes, ["m7", "m6", "m5", "m4", "m3"]);
    }

    #[test]
    fn the_robustness_table_counts_statuses_and_skipped_meshes() {
        let cases = [
            case("bend", "a", "arap", 10, 1.0, Status::Ok),
            case("bend", "b", "arap", 10, 1.0, Status::Failed("x".into())),
            case(
                "bend",
                "a",
                "hirm",
                10,
                1.0,
                Status::Suspect(vec!["swells: +40%".into(), "folds: 1%".into()]),
            ),
            case(
                "bend",
                "b",
                "hirm",
                10,
                1.0,
                Status::Unfinished(vec!["stopped at the cap".into(), "swells: +30%".into()]),
            ),
        ];
        let skipped = [SkippedInput {
            scenario: "bend-c".into(),
            file: "c.obj".into(),
            reason: "face 3: zero area".into(),
            member: Member {
                collection: "bend".into(),
                mesh: "c".into(),
                attributes: Vec::new(),
                repaired: None,
            },
        }];
        let md = document(&cases, &skipped).to_markdown();
        assert!(md.contains("| arap | 1 / 0 / 0 / 1 | 1 / 0 / 0 / 1 |"), "{md}");
        assert!(md.contains("| skipped meshes | 1 | 1 |"), "{md}");
        // Why suspect: hirm swells twice (suspect and unfinished) and folds once; arap is clean.
        assert!(md.contains("| hirm | 0 | 1 | 0 | 0 | 0 | 2 | 0 | 0 |"), "{md}");
        assert!(md.contains("| arap | 0 | 0 | 0 | 0 | 0 | 0 | 0 | 0 |"), "{md}");
        assert!(md.contains("skipped: bend-c (c.obj): face 3: zero area"), "{md}");
        assert!(document(&[CaseResult::empty("bar", "arap", "survey", 1, 1)], &[]).is_empty());
    }
}
