//! The run's record: what one case of a run measured ([`CaseResult`], with its edit steps, iterations,
//! timing spreads and the solve it took from another case), as written to `results.json` and read
//! back by the reports, the gate and `compare`. Types only: nothing here runs a method.

use serde::{Deserialize, Serialize};

use crate::config::Origin;
use crate::metrics::{Metric, Quality};
use crate::verdict::Status;

/// The method every other is compared with (`rms_to_arap_over_diag`, `max_to_arap_over_diag`).
pub const REFERENCE_METHOD: &str = methods::registry::ARAP;

/// The peer that runs the reference's energy to the same tolerance (configs/peers.toml): the page
/// sets their times to convergence side by side.
pub const PEER_OF_REFERENCE: &str = "libigl_arap";

/// Our reference with the peer's weights (plain cotangents; configs/peers.toml), so the peer's
/// shape can be checked against ours like for like.
pub const LIKE_FOR_LIKE_REFERENCE: &str = "arap_cotan";

/// Which case a result is: its scenario and its method. A collection member's scenario is named
/// `{collection}-{mesh}` ([`crate::scenario`]), so the scenario names the member too, and the
/// committed baselines, which predate collections, key their cases by the same two names.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CaseKey {
    pub scenario: String,
    pub method: String,
}

impl CaseKey {
    pub fn new(scenario: &str, method: &str) -> Self {
        CaseKey { scenario: scenario.to_string(), method: method.to_string() }
    }

    /// The case of `method` on the same scenario.
    pub fn with_method(&self, method: &str) -> CaseKey {
        CaseKey::new(&self.scenario, method)
    }
}

/// A run's results with an index by [`CaseKey`]: the one way a report finds another case of the
/// same scenario (the reference's, a peer's).
pub struct CaseIndex<'a> {
    results: Vec<&'a CaseResult>,
    by_key: std::collections::HashMap<CaseKey, usize>,
}

impl<'a> CaseIndex<'a> {
    /// The index of `results` (a key seen twice keeps its first case).
    pub fn new(results: impl IntoIterator<Item = &'a CaseResult>) -> Self {
        let results: Vec<&CaseResult> = results.into_iter().collect();
        let mut by_key = std::collections::HashMap::with_capacity(results.len());
        for (i, r) in results.iter().enumerate() {
            by_key.entry(r.key()).or_insert(i);
        }
        CaseIndex { results, by_key }
    }

    /// The case `key`, if the run has it.
    pub fn get(&self, key: &CaseKey) -> Option<&'a CaseResult> {
        self.by_key.get(key).map(|&i| self.results[i])
    }

    /// The case of `method` on `case`'s scenario.
    pub fn beside(&self, case: &CaseResult, method: &str) -> Option<&'a CaseResult> {
        self.get(&case.key().with_method(method))
    }

    /// The reference method's case ([`REFERENCE_METHOD`]) on `case`'s scenario.
    pub fn reference_of(&self, case: &CaseResult) -> Option<&'a CaseResult> {
        self.beside(case, REFERENCE_METHOD)
    }

    /// The cases of scenario `scenario`, in run order.
    pub fn of_scenario<'s>(&'s self, scenario: &'s str) -> impl Iterator<Item = &'a CaseResult> + 's
    where
        'a: 's,
    {
        self.results.iter().copied().filter(move |r| r.scenario == scenario)
    }
}

/// One iteration as recorded for convergence curves.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct IterationRecord {
    /// 1-based edit step of the scenario.
    pub edit_step: usize,
    /// 0-based within the edit step.
    pub iteration: usize,
    #[serde(deserialize_with = "nan_from_null")]
    pub step: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub seconds: f64,
    /// `E_theta` / `E_phi` (degrees) of the iterate, on the iterations [`records_quality`] selects.
    pub e_theta_deg: Option<f64>,
    pub e_phi_deg: Option<f64>,
}

/// Iterations of a step whose angle errors are all recorded ([`records_quality`]).
const DENSE_QUALITY_ITERATIONS: usize = 10;

/// Ratio of the geometric grid of recorded iterations after the dense ones: about ten points per
/// decade, evenly spaced on the convergence plots' logarithmic iteration axis.
const QUALITY_GRID_RATIO: f64 = 1.25;

/// Whether the angle errors of iteration `i` (0-based, within a step) are recorded: each of the
/// first [`DENSE_QUALITY_ITERATIONS`], then the iterations `floor(10 * 1.25^k)` (10, 12, 15, 19,
/// 24, …). Each costs a full-mesh evaluation (and a reconstruction for the reduced models): every
/// iteration would dominate a run (85 ms per iterate on the 200K sweep bar, as long as `hirm`'s
/// iteration itself).
pub fn records_quality(i: usize) -> bool {
    if i < DENSE_QUALITY_ITERATIONS {
        return true;
    }
    let mut grid = DENSE_QUALITY_ITERATIONS as f64;
    while (grid as usize) < i {
        grid *= QUALITY_GRID_RATIO;
    }
    grid as usize == i
}

/// One edit step of a case: a handle set bound and solved for.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StepRecord {
    /// 1-based.
    pub step: usize,
    /// Handle regions (the fixed region counts as one, as in HIRM's Table 1).
    pub handles: usize,
    pub constrained_vertices: usize,
    /// Wall time of `bind_handles`: the handle-set update a user waits for.
    #[serde(deserialize_with = "nan_from_null")]
    pub bind_s: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub solve_s: f64,
    pub iterations: usize,
    pub converged: bool,
    /// The last iteration's step over the rest diagonal (what `converged` compared with the
    /// method's tolerance).
    #[serde(default = "nan", deserialize_with = "nan_from_null")]
    pub final_step: f64,
    /// The method's estimate of its answer's distance to its fixed point over the rest diagonal
    /// ([`methods::DistanceBound`]; `converged` compared it with the tolerance). NaN: not reported.
    #[serde(default = "nan", deserialize_with = "nan_from_null")]
    pub fixed_point_distance: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub median_iteration_ms: f64,
    /// Seconds of `solve_s` that the method took from an identical solve of another method's case
    /// instead of computing them ([`methods::DeformationMethod::reused_solve`]); 0: none.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub reused_solve_s: f64,
    /// The method's phase timings after this step (e.g. HIRM's `t_h_handle_update`).
    pub phase_timings: Vec<(String, f64)>,
}

/// Measurements of one case. Times are wall-clock seconds; the `*_over_diag` values are relative to
/// the rest bounding-box diagonal; the quality measures are those of [`crate::metrics::METRICS`].
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseResult {
    pub scenario: String,
    pub method: String,
    /// Built-in, external or peer.
    #[serde(default)]
    pub origin: Origin,
    /// What ran, in an external method's own words (its library and version), if it said.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub about: Option<String>,
    pub mesh_source: String,
    /// The collection (edit family) and mesh this case's scenario is one of, with the mesh's
    /// manifest row ([`crate::scenario::Member`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub member: Option<crate::scenario::Member>,
    /// The size series its scenario is one size of (the scenario's `series`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub series: Option<String>,
    pub vertices: usize,
    pub faces: usize,
    /// The Laplacian weights the method ran with (`weights` in configs/methods.toml).
    #[serde(default)]
    pub laplacian_weights: String,
    /// The parameter sweeps the method is a point of ([`crate::sweep`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sweeps: Vec<crate::sweep::SweepPosition>,
    /// An external method's process start-up and handshake (NaN for a built-in method): not part of
    /// `precompute_s`.
    #[serde(default = "nan", deserialize_with = "nan_from_null")]
    pub startup_s: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub precompute_s: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub bind_s: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub median_iteration_ms: f64,
    pub iterations: usize,
    #[serde(deserialize_with = "nan_from_null")]
    pub solve_s: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub total_s: f64,
    /// What the method added to the process's resident memory at its peak, from precompute to the
    /// end of the last solve of the first repetition, MiB ([`crate::memory`]; NaN when not measured:
    /// `--jobs` above 1, an external method, no Linux counters).
    #[serde(default = "nan", deserialize_with = "nan_from_null")]
    pub peak_memory_mib: f64,
    pub converged: bool,
    /// The largest of the edit steps' estimated distances to the fixed point over the rest
    /// diagonal (NaN: not reported; 0: a direct method).
    #[serde(default = "nan", deserialize_with = "nan_from_null")]
    pub fixed_point_distance: f64,
    /// An iterative method that did not say whether it converged (external `kind = "iterative"`):
    /// `converged` is then only "finished", and the case is `suspect: convergence unknown`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub convergence_unknown: bool,
    /// Every measure of the metric table, one JSON field per metric key (`null`: none).
    #[serde(flatten)]
    pub quality: Quality,
    /// Largest distance of a result vertex from its rest position.
    #[serde(default, deserialize_with = "nan_from_null")]
    pub largest_move_over_diag: f64,
    /// Largest distance of a handle target from its vertex's rest position, over every step.
    #[serde(default, deserialize_with = "nan_from_null")]
    pub largest_handle_move_over_diag: f64,
    /// open3d's `is_self_intersecting` of the result, when the run asked for it
    /// (`--self-intersections`).
    #[serde(default)]
    pub self_intersecting: Option<bool>,
    /// `ok`, `suspect: <reasons>` or `failed: <error>` ([`crate::verdict`]).
    pub status: Status,
    /// Method-specific phases (e.g. HIRM's t_e, t_b) in seconds, after the last step.
    pub phase_timings: Vec<(String, f64)>,
    /// Sizes of a reduced model (e.g. HIRM's `n_field`), after the last step.
    pub statistics: Vec<(String, f64)>,
    /// Where part of the solve was taken from another method's identical solve instead of being
    /// computed: that method and the seconds taken, which `solve_s` and `total_s` include.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reused_solve: Option<ReusedSolveRecord>,
    /// Every edit step (one for a single edit); the top-level bind, solve and iteration figures
    /// are the first step's bind and the sums and median over all steps.
    pub steps: Vec<StepRecord>,
    /// Iterations of all steps, in order.
    pub trace: Vec<IterationRecord>,
    /// What measuring this case cost the harness (excluded from the timings above).
    #[serde(default)]
    pub overhead: MeasurementTime,
    /// The spread of the timings over the repetitions (`--repeat`); the top-level `precompute_s`,
    /// `bind_s`, `solve_s` and `total_s` are their medians. The steps, the trace and every measure
    /// are the first repetition's.
    #[serde(default)]
    pub spread: Option<TimingSpread>,
    #[serde(skip)]
    pub positions: Option<Vec<[f64; 3]>>,
}

/// The solve time a case took from another method's case ([`CaseResult::reused_solve`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReusedSolveRecord {
    /// The method that computed it.
    pub from: String,
    /// Seconds taken, over all edit steps.
    pub seconds: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// The smallest and largest of a timing over the repetitions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    #[serde(deserialize_with = "nan_from_null")]
    pub min: f64,
    #[serde(deserialize_with = "nan_from_null")]
    pub max: f64,
}

/// Every timed phase of a case over its repetitions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TimingSpread {
    pub repetitions: usize,
    pub precompute_s: Spread,
    /// The first step's bind.
    pub bind_s: Spread,
    pub solve_s: Spread,
    pub total_s: Spread,
    /// The median iteration of each repetition, milliseconds.
    #[serde(default = "Spread::unknown")]
    pub median_iteration_ms: Spread,
    /// An external method's start-up (NaN for a built-in method).
    #[serde(default = "Spread::unknown")]
    pub startup_s: Spread,
}

impl Spread {
    /// No spread known (a report of an older harness).
    pub fn unknown() -> Spread {
        Spread { min: f64::NAN, max: f64::NAN }
    }
}

/// The phases of a case that are timed over the repetitions, in report order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimedPhase {
    Startup,
    Precompute,
    Bind,
    Iteration,
    Solve,
    Total,
}

impl TimedPhase {
    pub const ALL: [TimedPhase; 6] = [
        TimedPhase::Startup,
        TimedPhase::Precompute,
        TimedPhase::Bind,
        TimedPhase::Iteration,
        TimedPhase::Solve,
        TimedPhase::Total,
    ];

    /// Its name in a sentence.
    pub fn label(self) -> &'static str {
        match self {
            TimedPhase::Startup => "startup",
            TimedPhase::Precompute => "precompute",
            TimedPhase::Bind => "bind",
            TimedPhase::Iteration => "iteration",
            TimedPhase::Solve => "solve",
            TimedPhase::Total => "total",
        }
    }

    /// The results column.
    pub fn key(self) -> &'static str {
        match self {
            TimedPhase::Startup => "startup_s",
            TimedPhase::Precompute => "precompute_s",
            TimedPhase::Bind => "bind_s",
            TimedPhase::Iteration => "median_iteration_ms",
            TimedPhase::Solve => "solve_s",
            TimedPhase::Total => "total_s",
        }
    }

    /// The median (the only value, after one repetition) of `case`, seconds.
    pub fn median(self, case: &CaseResult) -> f64 {
        match self {
            TimedPhase::Startup => case.startup_s,
            TimedPhase::Precompute => case.precompute_s,
            TimedPhase::Bind => case.bind_s,
            TimedPhase::Iteration => case.median_iteration_ms / 1e3,
            TimedPhase::Solve => case.solve_s,
            TimedPhase::Total => case.total_s,
        }
    }

    /// Min and max of `case` over its repetitions (the median twice after one), seconds.
    pub fn spread(self, case: &CaseResult) -> Spread {
        let Some(spread) = case.spread else {
            let v = self.median(case);
            return Spread { min: v, max: v };
        };
        match self {
            TimedPhase::Startup => spread.startup_s,
            TimedPhase::Precompute => spread.precompute_s,
            TimedPhase::Bind => spread.bind_s,
            TimedPhase::Iteration => Spread {
                min: spread.median_iteration_ms.min / 1e3,
                max: spread.median_iteration_ms.max / 1e3,
            },
            TimedPhase::Solve => spread.solve_s,
            TimedPhase::Total => spread.total_s,
        }
    }
}

/// Wall seconds the harness spent measuring one case, kept out of the method's timings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeasurementTime {
    /// `E_theta` / `E_phi` of the iterates ([`records_quality`]).
    pub trace_quality_s: f64,
    /// The quality measures of the final shape and the verdict.
    pub evaluation_s: f64,
}

fn nan() -> f64 {
    f64::NAN
}

/// `results.json` writes a missing (NaN) number as `null`; read it back as NaN.
fn nan_from_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl CaseResult {
    /// A case that has not run yet: no timings (NaN), no measures, status `ok`, no steps or
    /// positions. For the reports' unit tests: a run builds its records in `case::CaseRecord::build`.
    #[cfg(test)]
    pub(crate) fn empty(
        scenario: &str,
        method: &str,
        mesh_source: &str,
        vertices: usize,
        faces: usize,
    ) -> Self {
        CaseResult {
            scenario: scenario.to_string(),
            method: method.to_string(),
            origin: Origin::BuiltIn,
            about: None,
            mesh_source: mesh_source.to_string(),
            member: None,
            series: None,
            vertices,
            faces,
            laplacian_weights: String::new(),
            sweeps: Vec::new(),
            startup_s: f64::NAN,
            precompute_s: f64::NAN,
            bind_s: f64::NAN,
            median_iteration_ms: f64::NAN,
            iterations: 0,
            solve_s: f64::NAN,
            total_s: f64::NAN,
            peak_memory_mib: f64::NAN,
            converged: false,
            fixed_point_distance: f64::NAN,
            convergence_unknown: false,
            quality: Quality::default(),
            largest_move_over_diag: f64::NAN,
            largest_handle_move_over_diag: f64::NAN,
            self_intersecting: None,
            status: Status::Ok,
            phase_timings: Vec::new(),
            statistics: Vec::new(),
            reused_solve: None,
            steps: Vec::new(),
            trace: Vec::new(),
            overhead: MeasurementTime::default(),
            spread: None,
            positions: None,
        }
    }

    /// Which case it is.
    pub fn key(&self) -> CaseKey {
        CaseKey::new(&self.scenario, &self.method)
    }

    /// The value of `metric`, NaN where there is none.
    pub fn metric(&self, metric: Metric) -> f64 {
        self.quality.value(metric)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quality_is_recorded_densely_then_on_a_geometric_grid() {
        let recorded: Vec<usize> = (0..200).filter(|&i| records_quality(i)).collect();
        assert_eq!(&recorded[..10], &(0..10).collect::<Vec<_>>()[..]);
        assert_eq!(&recorded[10..16], &[10, 12, 15, 19, 24, 30]);
        // About ten per decade: 100..1000 holds ten or eleven.
        let decade = (100..1000).filter(|&i| records_quality(i)).count();
        assert!((10..=11).contains(&decade), "{decade} in 100..1000");
    }
}
