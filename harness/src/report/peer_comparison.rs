//! Our `arap` against libigl's on each test (`harness all --peers`): both run the plain energy to
//! the same step tolerance, so they should stop at the same shape; the table gives how far apart
//! the shapes are and the ratio of the times to convergence. Written as `peers.md` and on the page.

use std::fmt::Write as _;

use crate::case::CaseResult;
use crate::suite::{PEER_OF_REFERENCE, REFERENCE_METHOD};

/// One test with both ARAPs.
#[derive(Clone, Debug, PartialEq)]
pub struct ArapAgainstLibigl {
    pub scenario: String,
    pub vertices: usize,
    pub ours_iterations: usize,
    /// Every bind and solve of the case: the wait from a handle set to the converged shape.
    pub ours_s: f64,
    pub libigl_iterations: usize,
    pub libigl_s: f64,
    /// `ours_s / libigl_s`: below 1, ours is faster.
    pub ratio: f64,
    /// RMS distance of libigl's result from ours over the rest diagonal.
    pub rms_over_diag: f64,
    pub both_converged: bool,
}

/// Bind plus solve over every step: the time to convergence after each handle edit, summed.
fn time_to_convergence(case: &CaseResult) -> f64 {
    case.steps.iter().map(|s| s.bind_s + s.solve_s).sum()
}

/// Every scenario where both `arap` and `libigl_arap` have a result, in order.
pub fn arap_against_libigl(results: &[CaseResult]) -> Vec<ArapAgainstLibigl> {
    let ok = |r: &&CaseResult| !r.status.is_failed();
    results
        .iter()
        .filter(|r| r.method == PEER_OF_REFERENCE)
        .filter(ok)
        .filter_map(|peer| {
            let ours = results
                .iter()
                .filter(ok)
                .find(|r| r.method == REFERENCE_METHOD && r.scenario == peer.scenario)?;
            let (ours_s, libigl_s) = (time_to_convergence(ours), time_to_convergence(peer));
            Some(ArapAgainstLibigl {
                scenario: peer.scenario.clone(),
                vertices: peer.vertices,
                ours_iterations: ours.iterations,
                ours_s,
                libigl_iterations: peer.iterations,
                libigl_s,
                ratio: ours_s / libigl_s,
                rms_over_diag: peer.metric(crate::metrics::Metric::RmsToArap),
                both_converged: ours.converged && peer.converged,
            })
        })
        .collect()
}

/// The rows as a markdown table (empty when there are none).
pub fn render_markdown(rows: &[ArapAgainstLibigl]) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let mut out = String::from(
        "# Our `arap` against libigl's ARAP\n\nBoth to a step below 1e-5 of the rest diagonal; time = bind + \
         solve of every edit step (libigl's `arap_precomputation` needs the handles, so it is bind). Ratio below \
         1: ours is faster.\n\n| test | #V | arap iterations | arap s | libigl iterations | libigl s | ratio | RMS \
         distance / diag | both converged |\n|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.3} | {} | {:.3} | {:.2} | {:.1e} | {} |",
            r.scenario,
            r.vertices,
            r.ours_iterations,
            r.ours_s,
            r.libigl_iterations,
            r.libigl_s,
            r.ratio,
            r.rms_over_diag,
            if r.both_converged { "yes" } else { "no" }
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::StepRecord;

    fn case(scenario: &str, method: &str, bind_s: f64, solve_s: f64, iterations: usize) -> CaseResult {
        let mut c = CaseResult::empty(scenario, method, "survey", 10, 16);
        c.iterations = iterations;
        c.converged = true;
        c.steps.push(StepRecord {
            step: 1,
            handles: 2,
            constrained_vertices: 3,
            bind_s,
            solve_s,
            iterations,
            converged: true,
            final_step: 1e-6,
            median_iteration_ms: 1.0,
            phase_timings: Vec::new(),
        });
        c
    }

    #[test]
    fn the_ratio_is_ours_over_libigls_time_to_convergence_per_test() {
        let mut peer = case("bar", PEER_OF_REFERENCE, 0.5, 3.5, 2000);
        peer.quality.set(crate::metrics::Metric::RmsToArap, Some(2e-4));
        let results = vec![
            case("bar", REFERENCE_METHOD, 0.1, 0.9, 200),
            peer,
            case("cactus", REFERENCE_METHOD, 0.1, 0.9, 200),
            case("bar", "hirm", 0.1, 0.1, 10),
        ];
        let rows = arap_against_libigl(&results);
        assert_eq!(rows.len(), 1, "cactus has no libigl row");
        let r = &rows[0];
        assert_eq!((r.scenario.as_str(), r.ours_iterations, r.libigl_iterations), ("bar", 200, 2000));
        assert!((r.ratio - 0.25).abs() < 1e-12, "{}", r.ratio);
        assert_eq!(r.rms_over_diag, 2e-4);
        assert!(render_markdown(&rows)
            .contains("| bar | 10 | 200 | 1.000 | 2000 | 4.000 | 0.25 | 2.0e-4 | yes |"));
        assert!(render_markdown(&[]).is_empty());
    }
}
