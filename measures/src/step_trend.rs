//! Why an iteration did not finish, read from its step sequence: still contracting (the cap came
//! too early), steady (steps of one size: a slow or free mode, or a cycle too long for the window
//! to see it turn), oscillating (steps that rise and fall without a trend, a short limit cycle) or
//! growing.
//!
//! Decision (issue 51, part 3): the trend is a least-squares line through `log(step)` over the
//! last [`WINDOW`] iterations (at least [`MIN_STEPS`]); `rho = exp(slope)` is the mean contraction
//! per iteration and the residuals' standard deviation says how far the steps stray from that
//! line. A geometric sequence has zero residual; the Au et al. iteration on a mesh whose free limb
//! swings has steps that rise and fall by a factor of several within a few iterations. The
//! thresholds are stated in the constants and tested on synthetic sequences.

use std::fmt;

/// Iterations the trend is fitted over (the most recent ones).
pub const WINDOW: usize = 200;
/// Fewer steps than this say nothing.
pub const MIN_STEPS: usize = 20;
/// `rho` below `1 - CONTRACTION_MARGIN`: still contracting; above `1 + CONTRACTION_MARGIN`: growing.
pub const CONTRACTION_MARGIN: f64 = 1e-3;
/// Standard deviation of `ln(step)` about the fitted line above which the steps oscillate
/// (`ln 2`: steps a factor of two off their trend, typically).
pub const OSCILLATION_SPREAD: f64 = std::f64::consts::LN_2;

/// The trend of an unfinished iteration's last steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepTrend {
    /// Steps shrink by `rho` per iteration; `more` iterations at that rate would bring the
    /// distance bound (`step rho / (1 - rho)`) below the tolerance.
    Contracting { rho: f64, more: f64 },
    /// Steps rise and fall between `low` and `high` (over the diagonal) without shrinking.
    Oscillating { low: f64, high: f64 },
    /// Steps of about `size` (over the diagonal) that neither shrink nor swing: a slow or free
    /// mode being followed, or (steps far above the tolerance on a bounded shape) a long cycle.
    Steady { size: f64 },
    /// Steps growing by `rho` per iteration.
    Growing { rho: f64 },
}

impl StepTrend {
    /// The trend of `steps` (each over the rest diagonal, oldest first) against `tolerance`;
    /// `None` for fewer than [`MIN_STEPS`] finite positive steps in the window.
    pub fn of(steps: &[f64], tolerance: f64) -> Option<StepTrend> {
        let window = &steps[steps.len().saturating_sub(WINDOW)..];
        let points: Vec<(f64, f64)> = window
            .iter()
            .enumerate()
            .filter(|(_, s)| s.is_finite() && **s > 0.0)
            .map(|(i, s)| (i as f64, s.ln()))
            .collect();
        if points.len() < MIN_STEPS {
            return None;
        }
        let n = points.len() as f64;
        let mean_x = points.iter().map(|p| p.0).sum::<f64>() / n;
        let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
        let sxy: f64 = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
        let slope = sxy / sxx;
        let spread =
            (points.iter().map(|p| (p.1 - mean_y - slope * (p.0 - mean_x)).powi(2)).sum::<f64>() / n).sqrt();
        let rho = slope.exp();
        let (low, high) = window
            .iter()
            .filter(|s| s.is_finite())
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &s| (lo.min(s), hi.max(s)));
        if rho < 1.0 - CONTRACTION_MARGIN {
            // The step on the trend line now, then iterations until it times rho / (1 - rho)
            // falls below the tolerance.
            let last_x = points.last().map_or(0.0, |p| p.0);
            let step_now = (mean_y + slope * (last_x - mean_x)).exp();
            let needed = tolerance * (1.0 - rho) / rho;
            let more = if step_now <= needed { 0.0 } else { (needed / step_now).ln() / rho.ln() };
            Some(StepTrend::Contracting { rho, more })
        } else if spread > OSCILLATION_SPREAD {
            Some(StepTrend::Oscillating { low, high })
        } else if rho > 1.0 + CONTRACTION_MARGIN {
            Some(StepTrend::Growing { rho })
        } else {
            Some(StepTrend::Steady { size: mean_y.exp() })
        }
    }

    /// The trend with the iteration's own estimate of its distance to the fixed point taken into
    /// account: a contracting trend needs at least the iterations that bring `distance` below
    /// `tolerance` at its rate (a method whose bound sees more than its steps, as `scale_aware`'s
    /// secant contraction, would otherwise read "~0 more iterations" beside a distance far above
    /// the tolerance).
    pub fn with_distance(self, distance: f64, tolerance: f64) -> StepTrend {
        match self {
            StepTrend::Contracting { rho, more } if distance.is_finite() && distance > tolerance => {
                StepTrend::Contracting { rho, more: more.max((tolerance / distance).ln() / rho.ln()) }
            }
            trend => trend,
        }
    }
}

impl fmt::Display for StepTrend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            StepTrend::Contracting { rho, more } => {
                write!(f, "still contracting ({rho:.4} per iteration, ~{more:.0} more iterations)")
            }
            StepTrend::Oscillating { low, high } => {
                write!(f, "oscillating (steps {low:.1e} to {high:.1e} without a trend)")
            }
            StepTrend::Steady { size } => {
                write!(f, "steady (steps ~{size:.1e}, neither shrinking nor swinging)")
            }
            StepTrend::Growing { rho } => write!(f, "growing ({rho:.4} per iteration)"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_geometric_sequence_is_contracting_and_says_how_far_it_has_to_go() {
        let rho = 0.99_f64;
        let steps: Vec<f64> = (0..500).map(|k| 1e-3 * rho.powi(k)).collect();
        let Some(StepTrend::Contracting { rho: fitted, more }) = StepTrend::of(&steps, 1e-5) else {
            panic!("{:?}", StepTrend::of(&steps, 1e-5))
        };
        assert!((fitted - rho).abs() < 1e-9, "{fitted}");
        // The last step times rho / (1 - rho) is 99 x 6.6e-6; to 1e-5 needs ln(1e-5/99 / 6.6e-6) / ln rho.
        let last = steps[499];
        let expected = ((1e-5 * (1.0 - rho) / rho) / last).ln() / rho.ln();
        assert!((more - expected).abs() < 1e-6, "{more} vs {expected}");
    }

    #[test]
    fn the_reported_distance_lengthens_a_contracting_trend() {
        let trend = StepTrend::Contracting { rho: 0.9, more: 0.0 };
        let StepTrend::Contracting { more, .. } = trend.with_distance(1e-3, 1e-4) else { unreachable!() };
        assert!((more - (0.1f64).ln() / (0.9f64).ln()).abs() < 1e-12, "{more}");
        assert_eq!(trend.with_distance(1e-5, 1e-4), trend);
        assert_eq!(trend.with_distance(f64::INFINITY, 1e-4), trend);
    }

    #[test]
    fn steps_that_swing_are_oscillating_and_level_ones_steady() {
        // A two-cycle with a factor 10 between its steps: no trend, large spread.
        let swinging: Vec<f64> = (0..300).map(|k| if k % 2 == 0 { 1e-3 } else { 1e-4 }).collect();
        assert!(
            matches!(StepTrend::of(&swinging, 1e-5), Some(StepTrend::Oscillating { low, high }) if low == 1e-4 && high == 1e-3),
            "{:?}",
            StepTrend::of(&swinging, 1e-5)
        );
        // Constant steps with a little noise: steady at their size.
        let steady: Vec<f64> = (0..300).map(|k| 2e-6 * (1.0 + 0.05 * ((k as f64) * 0.7).sin())).collect();
        let Some(StepTrend::Steady { size }) = StepTrend::of(&steady, 1e-5) else {
            panic!("{:?}", StepTrend::of(&steady, 1e-5))
        };
        assert!((size / 2e-6 - 1.0).abs() < 0.05, "{size}");
        let growing: Vec<f64> = (0..300).map(|k| 1e-6 * 1.01_f64.powi(k)).collect();
        assert!(matches!(StepTrend::of(&growing, 1e-5), Some(StepTrend::Growing { .. })));
        assert_eq!(StepTrend::of(&growing[..10], 1e-5), None, "too few steps say nothing");
    }
}
