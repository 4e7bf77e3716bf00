//! Step detection on a timeline, after asv's: the values are fitted by a piecewise-constant
//! function, each point weighed by its noise, and a step is where the fitted level changes.
//!
//! The fit is the exact minimum, over every partition of the points into runs of consecutive
//! points, of the weighted squared residuals `sum ((y_i - level)/sigma_i)^2` plus a penalty per
//! level (optimal partitioning by dynamic programming, O(n^2): fine for the hundreds of commits a
//! history holds). asv minimises absolute residuals with an automatic penalty; we use squares
//! because sigma is known per point (measured spread or the measure's floor, [`super::measures`]),
//! which makes the cost a chi-square and lets the penalty be a significance level:
//! [`default_penalty`] is `max(4 ln n, 9)`, so a single split of noise-only points is accepted with
//! a probability below ~1.5% at n = 13 (a chi-square with one degree of freedom beyond 10.3,
//! times the 12 places it could go).

/// One point of a timeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    pub value: f64,
    /// Its standard deviation (> 0).
    pub sigma: f64,
}

/// A run of consecutive points fitted by one value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    /// The first point's index.
    pub start: usize,
    /// One past the last point's index.
    pub end: usize,
    /// The weighted mean of its points.
    pub value: f64,
}

/// The penalty per level for `n` points (module doc).
pub fn default_penalty(n: usize) -> f64 {
    (4.0 * (n.max(2) as f64).ln()).max(9.0)
}

/// The levels of the best piecewise-constant fit of `points` with `penalty` per level; empty for
/// no points. Points with a non-finite value or sigma must be left out by the caller.
pub fn fit_levels(points: &[Observation], penalty: f64) -> Vec<Level> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    // Prefix sums of w, w y, w y^2 (w = 1/sigma^2), so a segment's cost is O(1).
    let mut s0 = vec![0.0; n + 1];
    let mut s1 = vec![0.0; n + 1];
    let mut s2 = vec![0.0; n + 1];
    for (i, p) in points.iter().enumerate() {
        let w = 1.0 / (p.sigma * p.sigma);
        s0[i + 1] = s0[i] + w;
        s1[i + 1] = s1[i] + w * p.value;
        s2[i + 1] = s2[i] + w * p.value * p.value;
    }
    let mean = |i: usize, j: usize| (s1[j] - s1[i]) / (s0[j] - s0[i]);
    // The residual of a segment computed about its mean, not as s2 - s1^2/s0: that difference of
    // large sums cancels for values far from zero.
    let cost = |i: usize, j: usize| {
        let m = mean(i, j);
        points[i..j].iter().map(|p| ((p.value - m) / p.sigma).powi(2)).sum::<f64>()
    };
    let mut best = vec![f64::INFINITY; n + 1];
    let mut from = vec![0usize; n + 1];
    best[0] = 0.0;
    for j in 1..=n {
        for i in 0..j {
            let c = best[i] + cost(i, j) + penalty;
            if c < best[j] {
                best[j] = c;
                from[j] = i;
            }
        }
    }
    let mut levels = Vec::new();
    let mut j = n;
    while j > 0 {
        let i = from[j];
        levels.push(Level { start: i, end: j, value: mean(i, j) });
        j = i;
    }
    levels.reverse();
    levels
}

/// A change of level between two consecutive points of a timeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// The index of the first point at the new level.
    pub at: usize,
    pub before: f64,
    pub after: f64,
}

impl Step {
    /// `after / before - 1` (infinite from zero).
    pub fn relative_change(&self) -> f64 {
        if self.before == 0.0 {
            if self.after == 0.0 {
                0.0
            } else {
                f64::INFINITY.copysign(self.after)
            }
        } else {
            self.after / self.before - 1.0
        }
    }
}

/// The steps of the fit of `points` ([`fit_levels`] with [`default_penalty`]).
pub fn detect_steps(points: &[Observation]) -> Vec<Step> {
    let levels = fit_levels(points, default_penalty(points.len()));
    levels.windows(2).map(|w| Step { at: w[1].start, before: w[0].value, after: w[1].value }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic stand-in for Gaussian noise: splitmix64 uniforms, twelve summed minus six
    /// (mean 0, variance 1).
    fn noise(seed: u64, n: usize) -> Vec<f64> {
        let mut state = seed;
        let mut uniform = || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            (z ^ (z >> 31)) as f64 / u64::MAX as f64
        };
        (0..n).map(|_| (0..12).map(|_| uniform()).sum::<f64>() - 6.0).collect()
    }

    fn observe(values: &[f64], sigma: f64) -> Vec<Observation> {
        values.iter().map(|&value| Observation { value, sigma }).collect()
    }

    #[test]
    fn a_step_of_five_sigma_is_found_where_it_is() {
        for seed in 0..20 {
            let values: Vec<f64> = noise(seed, 14)
                .iter()
                .enumerate()
                .map(|(i, e)| if i < 9 { 10.0 } else { 15.0 } + e)
                .collect();
            let steps = detect_steps(&observe(&values, 1.0));
            assert_eq!(steps.len(), 1, "seed {seed}: {steps:?}");
            assert_eq!(steps[0].at, 9, "seed {seed}");
            assert!((steps[0].after - steps[0].before - 5.0).abs() < 1.5, "{steps:?}");
        }
    }

    #[test]
    fn noise_alone_makes_no_step_in_nearly_every_series() {
        let false_steps: usize =
            (0..200).map(|seed| detect_steps(&observe(&noise(seed + 100, 13), 1.0)).len()).sum();
        assert!(false_steps <= 6, "{false_steps} false steps in 200 noise-only series of 13");
    }

    #[test]
    fn the_spread_decides_whether_a_change_is_a_step() {
        let values = [1.0, 1.0, 1.0, 1.0, 1.0, 1.3, 1.3, 1.3, 1.3];
        assert_eq!(detect_steps(&observe(&values, 0.02)).len(), 1);
        assert!(detect_steps(&observe(&values, 0.2)).is_empty());
    }

    #[test]
    fn two_steps_and_a_last_commit_step_are_each_found() {
        let values = [3.0, 3.0, 3.0, 6.0, 6.0, 6.0, 6.0, 2.0, 2.0, 2.0, 2.0, 2.0, 9.0];
        let steps = detect_steps(&observe(&values, 0.1));
        let at: Vec<usize> = steps.iter().map(|s| s.at).collect();
        assert_eq!(at, vec![3, 7, 12]);
        assert_eq!(fit_levels(&[], 9.0), Vec::new());
    }
}
