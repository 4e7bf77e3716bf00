//! Quality against time: per test, every case as a point (time to a result, error), the Pareto
//! front across all methods (no other point is both faster and better), and the budget table (for
//! each time per edit, the `ok` case with the lowest error within it).
//!
//! Time is the time to a result after a handle edit, bind + solve ([`TimeAxis::Edit`]), or the
//! same with the precompute ([`TimeAxis::WithPrecompute`]); an external method's process start-up
//! is left out of both, as it is out of `precompute_s`.

use crate::metrics::Metric;
use crate::record::CaseResult;

/// The time budgets per edit of the budget table, in seconds.
pub const BUDGETS_S: [f64; 5] = [1e-3, 1e-2, 1e-1, 1.0, 10.0];

/// The quality measures drawn against time (e_iso first: the page's default ranking measure).
pub const MEASURES: [Metric; 4] = [Metric::EIso, Metric::ETheta, Metric::EPhi, Metric::EArea];

/// Which time a point is placed at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeAxis {
    /// bind + solve: the wait after a handle edit.
    Edit,
    /// precompute + bind + solve: the wait for the first result on a new mesh.
    WithPrecompute,
}

impl TimeAxis {
    pub const ALL: [TimeAxis; 2] = [TimeAxis::Edit, TimeAxis::WithPrecompute];

    /// Seconds of `case` on this axis.
    pub fn seconds(self, case: &CaseResult) -> f64 {
        match self {
            TimeAxis::Edit => case.bind_s + case.solve_s,
            TimeAxis::WithPrecompute => case.precompute_s + case.bind_s + case.solve_s,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            TimeAxis::Edit => "time per edit, bind + solve (s)",
            TimeAxis::WithPrecompute => "precompute + bind + solve (s)",
        }
    }
}

/// A case as a point: `time` in seconds, `error` the measure (lower is better).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub time: f64,
    pub error: f64,
}

/// The cases of one test that can be placed: finished (not failed or unfinished), with a finite
/// time and measure; `measure` by its magnitude (a signed change is better near 0).
pub fn points<'a>(cases: &[&'a CaseResult], axis: TimeAxis, measure: Metric) -> Vec<(&'a CaseResult, Point)> {
    cases
        .iter()
        .filter(|c| c.status.is_ok() || c.status.is_suspect())
        .filter_map(|c| {
            let error = c.quality.get(measure)?.abs();
            let time = axis.seconds(c);
            (time.is_finite() && error.is_finite()).then_some((*c, Point { time, error }))
        })
        .collect()
}

/// The front of the `ok` cases among `placed` (indices into it, fastest first): what a user can
/// take; a suspect case is drawn, not offered.
pub fn ok_front(placed: &[(&CaseResult, Point)]) -> Vec<usize> {
    let ok: Vec<usize> = (0..placed.len()).filter(|&i| placed[i].0.status.is_ok()).collect();
    let coordinates: Vec<Point> = ok.iter().map(|&i| placed[i].1).collect();
    front(&coordinates).into_iter().map(|j| ok[j]).collect()
}

/// Indices of the points on the Pareto front (minimising time and error), fastest first: a point
/// is on it when every faster point has a larger error. Of points with equal time and error, the
/// first is on it.
pub fn front(points: &[Point]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .time
            .total_cmp(&points[b].time)
            .then(points[a].error.total_cmp(&points[b].error))
            .then(a.cmp(&b))
    });
    let mut best = f64::INFINITY;
    let mut on = Vec::new();
    for i in order {
        if points[i].error < best {
            best = points[i].error;
            on.push(i);
        }
    }
    on
}

/// The index of the point with the lowest error among those with `eligible` and a time within
/// `budget` seconds (ties: the faster, then the first).
pub fn best_within(points: &[Point], eligible: &[bool], budget: f64) -> Option<usize> {
    (0..points.len()).filter(|&i| eligible[i] && points[i].time <= budget).min_by(|&a, &b| {
        points[a]
            .error
            .total_cmp(&points[b].error)
            .then(points[a].time.total_cmp(&points[b].time))
            .then(a.cmp(&b))
    })
}

/// The budget as people write it: `1 ms`, `10 s`.
pub fn budget_label(seconds: f64) -> String {
    if seconds < 1.0 {
        format!("{} ms", (seconds * 1e3).round())
    } else {
        format!("{} s", seconds.round())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(time: f64, error: f64) -> Point {
        Point { time, error }
    }

    #[test]
    fn the_front_keeps_exactly_the_points_nothing_beats_in_both() {
        // 0 fast and bad, 1 dominated by 0, 2 slower and better, 3 dominated by 2, 4 slowest and best,
        // 5 the same as 2 (a duplicate is not on it twice), 6 as fast as 0 and worse.
        let points =
            [p(1.0, 10.0), p(2.0, 12.0), p(3.0, 5.0), p(4.0, 6.0), p(9.0, 1.0), p(3.0, 5.0), p(1.0, 11.0)];
        assert_eq!(front(&points), vec![0, 2, 4]);
        // Every point off the front is beaten by one on it in both coordinates (or equals it).
        let on = front(&points);
        for (i, q) in points.iter().enumerate().filter(|(i, _)| !on.contains(i)) {
            assert!(on.iter().any(|&j| points[j].time <= q.time && points[j].error <= q.error), "point {i}");
        }
        assert!(front(&[]).is_empty());
    }

    #[test]
    fn a_budget_picks_the_best_eligible_point_within_it() {
        let points = [p(0.5e-3, 10.0), p(5e-3, 4.0), p(8e-3, 2.0), p(0.5, 1.0)];
        let eligible = [true, true, false, true];
        assert_eq!(best_within(&points, &eligible, 1e-3), Some(0));
        // The better point at 8 ms is not `ok`.
        assert_eq!(best_within(&points, &eligible, 1e-2), Some(1));
        assert_eq!(best_within(&points, &eligible, 1.0), Some(3));
        assert_eq!(best_within(&points, &eligible, 1e-4), None);
        assert_eq!(budget_label(1e-3), "1 ms");
        assert_eq!(budget_label(10.0), "10 s");
    }
}
