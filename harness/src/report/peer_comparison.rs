//! Our `arap` against libigl's on each test (`harness all --peers`). Both run Sorkine & Alexa's
//! spokes energy to the same step tolerance; libigl's uses the plain cotangent weights, ours the
//! intrinsic Delaunay ones by default, so the peers add `arap_cotan` (our `arap` with libigl's
//! weights) as the like-for-like reference: libigl's shape should be ours to the tolerance. The
//! table gives the distances and the ratio of the times to convergence. Written as `peers.md` and
//! on the page.

use super::document::{Column, Document, Table, Text};
use crate::record::CaseResult;
use crate::record::{CaseIndex, CaseKey, LIKE_FOR_LIKE_REFERENCE, PEER_OF_REFERENCE, REFERENCE_METHOD};
use crate::scenario::LoadedScenario;

/// One of our ARAP rows set against libigl's on one test.
#[derive(Clone, Debug, PartialEq)]
pub struct Side {
    pub iterations: usize,
    /// Every bind and solve of the case: the wait from a handle set to the converged shape.
    pub seconds: f64,
    pub converged: bool,
    /// `seconds` over libigl's: below 1, ours is faster.
    pub ratio: f64,
    /// RMS distance of libigl's result from this one, over the rest bounding-box diagonal.
    pub rms_over_diag: f64,
}

/// One test with both ARAPs.
#[derive(Clone, Debug, PartialEq)]
pub struct ArapAgainstLibigl {
    pub scenario: String,
    pub vertices: usize,
    pub libigl_iterations: usize,
    pub libigl_s: f64,
    pub libigl_converged: bool,
    /// Our `arap` (its configured weights).
    pub ours: Side,
    /// `arap_cotan`, when the run has it.
    pub like_for_like: Option<Side>,
}

/// Bind plus solve over every step: the time to convergence after each handle edit, summed.
fn time_to_convergence(case: &CaseResult) -> f64 {
    case.steps.iter().map(|s| s.bind_s + s.solve_s).sum()
}

/// RMS distance between two `#V x 3` results over `diagonal`.
fn rms_distance(a: &[[f64; 3]], b: &[[f64; 3]], diagonal: f64) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| {
            let d = meshes::vector::sub(*p, *q);
            meshes::vector::dot(d, d)
        })
        .sum();
    (sum / a.len().max(1) as f64).sqrt() / diagonal
}

/// Every scenario of `scenarios` where `arap` and `libigl_arap` both have a result, in order.
pub fn arap_against_libigl(results: &[CaseResult], scenarios: &[LoadedScenario]) -> Vec<ArapAgainstLibigl> {
    let index = CaseIndex::new(results);
    let find = |scenario: &str, method: &str| {
        (index.get(&CaseKey::new(scenario, method)))
            .filter(|r| !r.status.is_failed())
            .and_then(|r| Some((r, r.positions.as_deref()?)))
    };
    scenarios
        .iter()
        .filter_map(|s| {
            let name = s.spec.name.as_str();
            let (libigl, libigl_positions) = find(name, PEER_OF_REFERENCE)?;
            let diagonal = s.mesh.bbox_diagonal();
            let libigl_s = time_to_convergence(libigl);
            let side = |method: &str| {
                find(name, method).map(|(r, positions)| Side {
                    iterations: r.iterations,
                    seconds: time_to_convergence(r),
                    converged: r.converged,
                    ratio: time_to_convergence(r) / libigl_s,
                    rms_over_diag: rms_distance(libigl_positions, positions, diagonal),
                })
            };
            Some(ArapAgainstLibigl {
                scenario: name.to_string(),
                vertices: libigl.vertices,
                libigl_iterations: libigl.iterations,
                libigl_s,
                libigl_converged: libigl.converged,
                ours: side(REFERENCE_METHOD)?,
                like_for_like: side(LIKE_FOR_LIKE_REFERENCE),
            })
        })
        .collect()
}

/// The rows as a table (no rows: no test had both ARAPs).
pub fn table(rows: &[ArapAgainstLibigl]) -> Table {
    let mut header = vec![Column::left("test")];
    let titles = ["#V", "libigl iterations", "libigl s"].map(String::from).into_iter().chain(
        [REFERENCE_METHOD, LIKE_FOR_LIKE_REFERENCE]
            .into_iter()
            .flat_map(|m| [format!("{m} iterations"), "s".into(), "ratio".into(), "distance".into()]),
    );
    header.extend(titles.map(Column::right));
    let mut table = Table::with_columns(header).captioned(caption());
    for r in rows {
        let mut cells = vec![
            r.scenario.clone(),
            r.vertices.to_string(),
            format!("{}{}", r.libigl_iterations, cap(r.libigl_converged)),
            number(r.libigl_s, format!("{:.3}", r.libigl_s)),
        ];
        cells.extend(side_cells(Some(&r.ours)));
        cells.extend(side_cells(r.like_for_like.as_ref()));
        table.push_row(cells);
    }
    table
}

/// What the table's columns are, above it.
fn caption() -> Text {
    Text::plain(
        "All three run the spokes energy until the estimated distance to the fixed point is below 1e-5 of the \
         rest diagonal (ours by L-BFGS, libigl's plain local/global iteration one iteration per call). ",
    )
    .then_code(REFERENCE_METHOD)
    .then(" has our default weights (intrinsic Delaunay cotangents), ")
    .then_code(LIKE_FOR_LIKE_REFERENCE)
    .then(
        " libigl's (plain cotangents): the like-for-like comparison. Time = bind + solve of every edit step \
         (libigl's ",
    )
    .then_code("arap_precomputation")
    .then(
        " needs the handles, so it is bind); ratio = ours / libigl's, below 1 ours is faster. Distance = RMS of \
         libigl's result from ours / rest diagonal. A ",
    )
    .then_code("*")
    .then(" marks a row stopped at its iteration cap.")
}

/// `*` for a row stopped at its iteration cap.
fn cap(converged: bool) -> &'static str {
    if converged {
        ""
    } else {
        "*"
    }
}

/// `text`, or `–` when `v` is not finite (the table is printed at the end of a run too: no `NaN`
/// there).
fn number(v: f64, text: String) -> String {
    if v.is_finite() {
        text
    } else {
        "–".to_string()
    }
}

/// One of our ARAPs' cells: iterations, seconds, ratio, distance (`–` each for none).
fn side_cells(side: Option<&Side>) -> [String; 4] {
    match side {
        Some(s) => [
            format!("{}{}", s.iterations, cap(s.converged)),
            number(s.seconds, format!("{:.3}", s.seconds)),
            number(s.ratio, format!("{:.2}", s.ratio)),
            number(s.rms_over_diag, format!("{:.1e}", s.rms_over_diag)),
        ],
        None => ["–", "–", "–", "–"].map(String::from),
    }
}

/// `peers.md`: the table under its title; empty without rows.
pub fn document(table: &Table) -> Document {
    let mut document = Document::default();
    if !table.rows.is_empty() {
        document.heading(1, "Our ARAP against libigl's");
        document.table(table.clone());
    }
    document
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_sets_ratios_and_distances_against_libigl() {
        let rows = vec![ArapAgainstLibigl {
            scenario: "bar".into(),
            vertices: 10,
            libigl_iterations: 2000,
            libigl_s: 4.0,
            libigl_converged: true,
            ours: Side { iterations: 200, seconds: 1.0, converged: true, ratio: 0.25, rms_over_diag: 2e-3 },
            like_for_like: None,
        }];
        let md = document(&table(&rows)).to_markdown();
        assert!(
            md.contains("| bar | 10 | 2000 | 4.000 | 200 | 1.000 | 0.25 | 2.0e-3 | – | – | – | – |"),
            "{md}"
        );
        assert!(document(&table(&[])).is_empty());
        assert_eq!(
            rms_distance(&[[0.0; 3], [3.0, 4.0, 0.0]], &[[0.0; 3], [0.0; 3]], 2.0),
            (12.5f64).sqrt() / 2.0
        );
    }
}
