//! The verdict on a case: `ok`, `suspect: <reasons>` (it finished, but its shape is broken in a way
//! a measure sees), `unfinished: <reasons>` (its iteration stopped at the cap before reaching its
//! tolerance: the shape is an iterate, not the method's answer; any suspect reasons follow), or
//! `failed: <error>` (no result). The thresholds are data (`configs/verdicts.toml`), each with the
//! reason for its value written there.
//!
//! Suspect and unfinished cases are still results: the run's exit code stays 0 for them, and they
//! are drawn and reported like any other, with their reasons.

use std::fmt;
use std::path::Path;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::HarnessError;
use crate::metrics::{Metric, Quality};
use crate::step_trend::StepTrend;

/// The kinds of shape reasons [`VerdictRules::reasons`] gives, each the start of its text (the
/// dataset report counts cases per kind).
pub const REASON_KINDS: [&str; 8] = [
    "non-finite",
    "folds",
    "misses its handles",
    "turns a free region",
    "turned against arap",
    "swells",
    "shrinks",
    "leaves its frame",
];

/// The kind of a shape reason ([`REASON_KINDS`]), if it is one of them.
pub fn reason_kind(reason: &str) -> Option<&'static str> {
    REASON_KINDS.into_iter().find(|k| reason.starts_with(k))
}

/// When a finished case is suspect (`configs/verdicts.toml`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VerdictRules {
    /// Largest `folds` (fraction of interior edges) that is still `ok`.
    pub max_folds: f64,
    /// Largest handle residual (over the rest diagonal) that is still `ok`.
    pub max_handle_residual_over_diag: f64,
    /// A vertex may move at most the largest handle displacement plus this many rest diagonals.
    pub frame_margin_diagonals: f64,
    /// Largest `turn_beyond_handles_deg` (degrees) that is still `ok`.
    pub max_turn_beyond_handles_deg: f64,
    /// Largest `turn_to_arap_deg` that is still `ok`, as a fraction of the turn the handles ask
    /// (judged where the reference finished) ...
    pub max_turn_to_arap_of_asked: f64,
    /// ... but never below this many degrees.
    pub min_turn_to_arap_allowed_deg: f64,
    /// How far the total surface area may leave the range the handles ask (`Motion::asked_scale`
    /// squared, and no change), as a fraction: `swells` above, `shrinks` below.
    pub max_area_change_beyond_asked: f64,
}

/// What a verdict reads of a case besides its measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// The largest distance of any result vertex from its rest position, over the rest diagonal.
    pub largest_move: f64,
    /// The largest distance of a handle target from its vertex's rest position (over every edit
    /// step), over the rest diagonal.
    pub largest_handle_move: f64,
    /// The turn the last step's handles ask of the free surface (degrees,
    /// [`crate::metrics::asked_turn`] with bends from the held regions only).
    pub asked_turn_deg: f64,
    /// The scale the last step's handles ask ([`crate::metrics::asked_scale`]): 1 for rigid handle
    /// motions, above 1 where they pull regions apart.
    pub asked_scale: f64,
    /// The scenario's reference (`arap`) finished (ok or suspect), so its result judges this one's
    /// turns (`turn_to_arap_deg`); an unfinished reference is an iterate, and then only the result's
    /// own measures judge it (`turn_beyond_handles_deg` among them).
    pub reference_finished: bool,
}

impl VerdictRules {
    /// Read and check `path`.
    pub fn load(path: &Path) -> Result<Self, HarnessError> {
        let config = |message: String| HarnessError::Config { path: path.to_path_buf(), message };
        let text = std::fs::read_to_string(path)
            .map_err(|error| HarnessError::Io { path: path.to_path_buf(), error })?;
        let rules: VerdictRules = toml::from_str(&text).map_err(|e| config(e.to_string()))?;
        for (name, value) in [
            ("max_folds", rules.max_folds),
            ("max_handle_residual_over_diag", rules.max_handle_residual_over_diag),
            ("frame_margin_diagonals", rules.frame_margin_diagonals),
            ("max_turn_beyond_handles_deg", rules.max_turn_beyond_handles_deg),
            ("max_turn_to_arap_of_asked", rules.max_turn_to_arap_of_asked),
            ("min_turn_to_arap_allowed_deg", rules.min_turn_to_arap_allowed_deg),
            ("max_area_change_beyond_asked", rules.max_area_change_beyond_asked),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(config(format!("`{name}` must be a finite number >= 0, not {value}")));
            }
        }
        Ok(rules)
    }

    /// The reasons a finished case with `quality` and `motion` is suspect (empty: `ok`). A result is
    /// judged on itself, and against the reference's result only where that finished.
    pub fn reasons(&self, quality: &Quality, motion: Motion) -> Vec<String> {
        let Motion { largest_move, largest_handle_move, asked_turn_deg, asked_scale, reference_finished } =
            motion;
        let mut reasons = Vec::new();
        let non_finite: Vec<&str> = quality.non_finite().map(Metric::key).collect();
        if !non_finite.is_empty() || !largest_move.is_finite() {
            let mut what = non_finite;
            if !largest_move.is_finite() {
                what.push("positions");
            }
            reasons.push(format!("non-finite {}", what.join(", ")));
        }
        if let Some(f) = quality.get(Metric::Folds).filter(|f| *f > self.max_folds) {
            reasons.push(format!("folds: {:.3}% of interior edges turned by more than 90°", 100.0 * f));
        }
        if let Some(r) =
            quality.get(Metric::HandleResidual).filter(|r| *r > self.max_handle_residual_over_diag)
        {
            reasons.push(format!(
                "misses its handles: residual {r:.2e} of the diagonal (> {:.0e})",
                self.max_handle_residual_over_diag
            ));
        }
        if let Some(t) =
            quality.get(Metric::TurnBeyondHandles).filter(|t| *t > self.max_turn_beyond_handles_deg)
        {
            reasons.push(format!(
                "turns a free region: a tenth of its free vertices turned {t:.0}° beyond what the handles ask \
                 (> {:.0}°)",
                self.max_turn_beyond_handles_deg
            ));
        }
        let allowed =
            (self.max_turn_to_arap_of_asked * asked_turn_deg).max(self.min_turn_to_arap_allowed_deg);
        if let Some(t) = quality.get(Metric::TurnToArap).filter(|t| reference_finished && *t > allowed) {
            reasons.push(format!(
                "turned against arap: half of its free surface turned {t:.0}° or more from arap's result \
                 (> {allowed:.0}°, {:.1} of the {asked_turn_deg:.0}° the handles ask)",
                self.max_turn_to_arap_of_asked
            ));
        }
        if let Some(change) = quality.get(Metric::AreaChange).filter(|c| c.is_finite()) {
            // Judged on ln(A / A⁰) against [2 ln min(s, 1), 2 ln max(s, 1)]: a method may keep the area
            // or scale it as the handles do, and no further.
            let (ratio, margin) = (1.0 + change, (1.0 + self.max_area_change_beyond_asked).ln());
            let (low, high) = (asked_scale.min(1.0).powi(2), asked_scale.max(1.0).powi(2));
            let beyond = if ratio > 0.0 && ratio.ln() - high.ln() > margin {
                Some(("swells", "grew", "at most", high))
            } else if ratio <= 0.0 || low.ln() - ratio.ln() > margin {
                Some(("shrinks", "fell", "at least", low))
            } else {
                None
            };
            if let Some((kind, went, bound, asked)) = beyond {
                reasons.push(format!(
                    "{kind}: its surface area {went} {:+.0}% where the handles ask {bound} {:+.0}% \
                     (> {:.0}% beyond)",
                    100.0 * (ratio - 1.0),
                    100.0 * (asked - 1.0),
                    100.0 * self.max_area_change_beyond_asked
                ));
            }
        }
        let allowed = largest_handle_move + self.frame_margin_diagonals;
        if largest_move > allowed {
            reasons.push(format!(
                "leaves its frame: a vertex moved {largest_move:.2} diagonals (handles at most {largest_handle_move:.2})"
            ));
        }
        reasons
    }
}

/// Why a case's iteration did not finish: one edit step that stopped before its estimated distance
/// to the fixed point fell below the method's tolerance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unfinished {
    /// 1-based edit step, and how many the scenario has.
    pub step: usize,
    pub steps: usize,
    /// Iterations the step ran, and the method's `max_iterations` if it has one.
    pub iterations: usize,
    pub cap: Option<usize>,
    /// The last iteration's step over the rest diagonal, and the method's tolerance if it has one.
    pub last_step: f64,
    /// The estimated distance of the answer to the fixed point over the rest diagonal (what the
    /// tolerance bounds; [`methods::DistanceBound`]).
    pub distance: f64,
    pub tolerance: Option<f64>,
    /// What the last steps were doing ([`StepTrend`]), from the step's iteration trace.
    pub trend: Option<StepTrend>,
}

impl Unfinished {
    /// Whether `reason` (of an `unfinished` status) is the text of an [`Unfinished`], not a reason
    /// of the shape: what its `Display` starts with.
    fn wrote(reason: &str) -> bool {
        reason.starts_with("stopped ") || reason.starts_with("edit step ")
    }
}

impl fmt::Display for Unfinished {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.steps > 1 {
            write!(f, "edit step {} of {} ", self.step, self.steps)?;
        }
        match self.cap {
            Some(cap) if self.iterations >= cap => write!(f, "stopped at the {cap}-iteration cap")?,
            _ => write!(f, "stopped after {} iterations without converging", self.iterations)?,
        }
        write!(f, ", last step {:.1e} of the diagonal", self.last_step)?;
        if self.distance.is_finite() {
            write!(f, ", estimated {:.1e} from the fixed point", self.distance)?;
        } else if !self.distance.is_nan() {
            write!(f, ", steps not contracting")?;
        }
        if let Some(t) = self.tolerance {
            write!(f, " (tolerance {t:.0e})")?;
        }
        if let Some(trend) = self.trend {
            write!(f, ", {trend}")?;
        }
        Ok(())
    }
}

/// The verdict on one case.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Status {
    Ok,
    /// Finished, with these reasons to distrust the shape.
    Suspect(Vec<String>),
    /// The iteration stopped before its tolerance: the first reason says where (an [`Unfinished`]),
    /// any further ones are the shape's suspect reasons.
    Unfinished(Vec<String>),
    /// No result: the method's error.
    Failed(String),
}

/// Every status kind, from best to worst: the text before `:`, the CSS class, the summary's order.
pub const STATUS_KINDS: [&str; 4] = ["ok", "suspect", "unfinished", "failed"];

impl Status {
    pub fn is_ok(&self) -> bool {
        matches!(self, Status::Ok)
    }

    pub fn is_suspect(&self) -> bool {
        matches!(self, Status::Suspect(_))
    }

    pub fn is_unfinished(&self) -> bool {
        matches!(self, Status::Unfinished(_))
    }

    pub fn is_failed(&self) -> bool {
        matches!(self, Status::Failed(_))
    }

    /// One of [`STATUS_KINDS`], without the reasons.
    pub fn kind(&self) -> &'static str {
        match self {
            Status::Ok => STATUS_KINDS[0],
            Status::Suspect(_) => STATUS_KINDS[1],
            Status::Unfinished(_) => STATUS_KINDS[2],
            Status::Failed(_) => STATUS_KINDS[3],
        }
    }

    /// The reasons to distrust the shape itself: every reason of a suspect case, those after the
    /// unfinished steps of an unfinished one, none otherwise.
    pub fn shape_reasons(&self) -> impl Iterator<Item = &String> {
        let (reasons, skip_unfinished): (&[String], bool) = match self {
            Status::Suspect(r) => (r, false),
            Status::Unfinished(r) => (r, true),
            _ => (&[], false),
        };
        reasons.iter().filter(move |r| !(skip_unfinished && Unfinished::wrote(r)))
    }

    /// The status of a case that produced a shape: `Unfinished` when any step did not finish (its
    /// reasons first, then the shape's), else `Suspect` for any shape reason, else `Ok`.
    /// Add suspect `reasons` found after the verdict (a later repetition's): an `ok` case turns
    /// suspect; an unfinished one keeps its kind; a failed one stays failed.
    pub fn add_reasons(&mut self, reasons: Vec<String>) {
        if reasons.is_empty() {
            return;
        }
        *self = match std::mem::replace(self, Status::Ok) {
            Status::Ok => Status::Suspect(reasons),
            Status::Suspect(mut r) => {
                r.extend(reasons);
                Status::Suspect(r)
            }
            Status::Unfinished(mut r) => {
                r.extend(reasons);
                Status::Unfinished(r)
            }
            failed @ Status::Failed(_) => failed,
        };
    }

    pub fn judge(unfinished: &[Unfinished], reasons: Vec<String>) -> Status {
        if !unfinished.is_empty() {
            let mut all: Vec<String> = unfinished.iter().map(ToString::to_string).collect();
            all.extend(reasons);
            Status::Unfinished(all)
        } else if reasons.is_empty() {
            Status::Ok
        } else {
            Status::Suspect(reasons)
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Status::Ok => f.write_str("ok"),
            Status::Suspect(reasons) => write!(f, "suspect: {}", reasons.join("; ")),
            Status::Unfinished(reasons) => write!(f, "unfinished: {}", reasons.join("; ")),
            Status::Failed(error) => write!(f, "failed: {error}"),
        }
    }
}

impl FromStr for Status {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "ok" {
            Ok(Status::Ok)
        } else if let Some(reasons) = s.strip_prefix("suspect: ") {
            Ok(Status::Suspect(reasons.split("; ").map(String::from).collect()))
        } else if let Some(reasons) = s.strip_prefix("unfinished: ") {
            Ok(Status::Unfinished(reasons.split("; ").map(String::from).collect()))
        } else if let Some(error) = s.strip_prefix("failed: ") {
            Ok(Status::Failed(error.to_string()))
        } else {
            Err(format!(
                "a status is `ok`, `suspect: <reasons>`, `unfinished: <reasons>` or `failed: <error>`, not `{s}`"
            ))
        }
    }
}

impl Serialize for Status {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Status {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        String::deserialize(deserializer)?.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rules() -> VerdictRules {
        VerdictRules {
            max_folds: 0.0,
            max_handle_residual_over_diag: 1e-3,
            frame_margin_diagonals: 1.0,
            max_turn_beyond_handles_deg: 45.0,
            max_turn_to_arap_of_asked: 0.4,
            min_turn_to_arap_allowed_deg: 5.0,
            max_area_change_beyond_asked: 0.25,
        }
    }

    /// A case that moved `largest_move` diagonals with handles moved 0.2, asked 50 deg, judged
    /// against a finished reference.
    fn moved(largest_move: f64) -> Motion {
        Motion {
            largest_move,
            largest_handle_move: 0.2,
            asked_turn_deg: 50.0,
            asked_scale: 1.0,
            reference_finished: true,
        }
    }

    fn quality(folds: f64, residual: f64) -> Quality {
        let mut q = Quality::default();
        q.set(Metric::ETheta, Some(1.0));
        q.set(Metric::Folds, Some(folds));
        q.set(Metric::HandleResidual, Some(residual));
        q
    }

    #[test]
    fn each_reason_is_found_and_a_clean_case_is_ok() {
        let r = rules();
        assert!(r.reasons(&quality(0.0, 1e-9), moved(0.3)).is_empty());
        let folded = r.reasons(&quality(1e-4, 1e-9), moved(0.3));
        assert!(folded.len() == 1 && folded[0].starts_with("folds: 0.010%"), "{folded:?}");
        let missed = r.reasons(&quality(0.0, 2e-3), moved(0.3));
        assert!(missed.len() == 1 && missed[0].starts_with("misses its handles"), "{missed:?}");
        // 0.2 of handle motion + 1 diagonal of margin: 1.19 is inside, 1.21 outside.
        assert!(r.reasons(&quality(0.0, 0.0), moved(1.19)).is_empty());
        let left = r.reasons(&quality(0.0, 0.0), moved(1.21));
        assert!(left.len() == 1 && left[0].starts_with("leaves its frame"), "{left:?}");
        let mut turned = quality(0.0, 0.0);
        turned.set(Metric::TurnBeyondHandles, Some(44.0));
        assert!(r.reasons(&turned, moved(0.3)).is_empty());
        turned.set(Metric::TurnBeyondHandles, Some(61.0));
        let reasons = r.reasons(&turned, moved(0.3));
        assert!(reasons.len() == 1 && reasons[0].starts_with("turns a free region"), "{reasons:?}");
        // Against the reference: 0.4 of the 50 deg asked, judged only where the reference finished,
        // never below 5 deg.
        let mut against = quality(0.0, 0.0);
        against.set(Metric::TurnToArap, Some(19.0));
        assert!(r.reasons(&against, moved(0.3)).is_empty());
        against.set(Metric::TurnToArap, Some(21.0));
        let reasons = r.reasons(&against, moved(0.3));
        assert!(reasons.len() == 1 && reasons[0].starts_with("turned against arap: "), "{reasons:?}");
        let unfinished = Motion { reference_finished: false, ..moved(0.3) };
        assert!(r.reasons(&against, unfinished).is_empty(), "an unfinished reference judges nothing");
        let still = Motion { asked_turn_deg: 0.0, ..moved(0.3) };
        against.set(Metric::TurnToArap, Some(4.0));
        assert!(r.reasons(&against, still).is_empty(), "the 5 deg floor");
        against.set(Metric::TurnToArap, Some(6.0));
        assert_eq!(r.reasons(&against, still).len(), 1);
        // The area: +25% beyond what the handles ask is still ok, more swells; a stretch by 1.2
        // asks +44%; shrinking is judged the same way below.
        let mut area = quality(0.0, 0.0);
        area.set(Metric::AreaChange, Some(0.24));
        assert!(r.reasons(&area, moved(0.3)).is_empty());
        area.set(Metric::AreaChange, Some(0.26));
        let reasons = r.reasons(&area, moved(0.3));
        assert!(
            reasons.len() == 1 && reasons[0].starts_with("swells: its surface area grew +26%"),
            "{reasons:?}"
        );
        let stretched = Motion { asked_scale: 1.2, ..moved(0.3) };
        area.set(Metric::AreaChange, Some(0.7));
        assert!(r.reasons(&area, stretched).is_empty(), "1.44 x 1.25 = 1.8");
        area.set(Metric::AreaChange, Some(0.85));
        assert_eq!(r.reasons(&area, stretched).len(), 1);
        area.set(Metric::AreaChange, Some(-0.19));
        assert!(r.reasons(&area, moved(0.3)).is_empty(), "1 / 1.25 = 0.8");
        area.set(Metric::AreaChange, Some(-0.21));
        let reasons = r.reasons(&area, moved(0.3));
        assert!(
            reasons.len() == 1 && reasons[0].starts_with("shrinks: its surface area fell -21%"),
            "{reasons:?}"
        );
        area.set(Metric::AreaChange, Some(-1.0));
        assert_eq!(r.reasons(&area, moved(0.3)).len(), 1, "collapsed to nothing");
        let mut q = quality(0.0, 0.0);
        q.set(Metric::EArea, Some(f64::INFINITY));
        let nan = r.reasons(&q, moved(f64::NAN));
        assert_eq!(nan, vec!["non-finite e_area, positions".to_string()]);
        assert_eq!(reason_kind(&nan[0]), Some("non-finite"));
        // Every reason above has its kind; all of them at once, each once.
        let mut all = quality(1e-4, 2e-3);
        all.set(Metric::TurnBeyondHandles, Some(61.0));
        all.set(Metric::TurnToArap, Some(21.0));
        all.set(Metric::AreaChange, Some(0.5));
        let kinds: Vec<&str> = r.reasons(&all, moved(1.5)).iter().filter_map(|r| reason_kind(r)).collect();
        assert_eq!(
            kinds,
            [
                "folds",
                "misses its handles",
                "turns a free region",
                "turned against arap",
                "swells",
                "leaves its frame"
            ]
        );
    }

    #[test]
    fn status_round_trips_through_its_text() {
        for s in [
            Status::Ok,
            Status::Suspect(vec!["folds: 1%".into(), "misses its handles".into()]),
            Status::Unfinished(vec![
                "stopped at the 500-iteration cap, last step 3.0e-4 of the diagonal".into()
            ]),
            Status::Failed("solver: not positive definite".into()),
        ] {
            assert_eq!(s.to_string().parse::<Status>().unwrap(), s);
            let json = serde_json::to_string(&s).unwrap();
            assert_eq!(serde_json::from_str::<Status>(&json).unwrap(), s);
        }
        assert!("fine".parse::<Status>().is_err());
    }

    #[test]
    fn an_unfinished_step_outranks_the_shape_reasons_and_says_where_it_stopped() {
        let capped = Unfinished {
            step: 1,
            steps: 1,
            iterations: 500,
            cap: Some(500),
            last_step: 3.04e-4,
            distance: 6.1e-3,
            tolerance: Some(1e-5),
            trend: None,
        };
        let s =
            Status::judge(&[capped], vec!["folds: 0.010% of interior edges turned by more than 90°".into()]);
        assert!(s.is_unfinished() && s.kind() == "unfinished");
        assert_eq!(
            s.to_string(),
            "unfinished: stopped at the 500-iteration cap, last step 3.0e-4 of the diagonal, estimated 6.1e-3 \
             from the fixed point (tolerance 1e-5); \
             folds: 0.010% of interior edges turned by more than 90°"
        );
        assert_eq!(s.shape_reasons().count(), 1, "the fold, not the cap");
        let swinging = Unfinished { trend: Some(StepTrend::Oscillating { low: 1e-4, high: 2e-3 }), ..capped };
        assert!(
            swinging
                .to_string()
                .ends_with("(tolerance 1e-5), oscillating (steps 1.0e-4 to 2.0e-3 without a trend)"),
            "{swinging}"
        );
        let parsed: Status = Status::judge(&[swinging], vec![]).to_string().parse().unwrap();
        assert_eq!(parsed.shape_reasons().count(), 0, "the trend belongs to the unfinished reason");
        let second = Unfinished { step: 2, steps: 3, iterations: 40, cap: Some(500), ..capped };
        let both = Status::judge(&[capped, second], vec![]);
        assert_eq!(both.shape_reasons().count(), 0, "{both}");
        let parsed: Status = both.to_string().parse().unwrap();
        assert_eq!(parsed.shape_reasons().count(), 0, "read back from results.json");
        assert!(second
            .to_string()
            .starts_with("edit step 2 of 3 stopped after 40 iterations without converging"));
        assert_eq!(Status::judge(&[], vec![]), Status::Ok);
        assert!(Status::judge(&[], vec!["x".into()]).is_suspect());
    }

    #[test]
    fn the_committed_rules_load_and_bad_values_are_named() {
        let committed = crate::paths::tests::checkout_root().join("configs/verdicts.toml");
        let r = VerdictRules::load(&committed).unwrap();
        assert_eq!(r.max_folds, 0.0, "any fold is suspect (issue 14)");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("verdicts.toml");
        std::fs::write(
            &path,
            "max_folds = -1\nmax_handle_residual_over_diag = 1e-3\nframe_margin_diagonals = 1\n\
             max_turn_beyond_handles_deg = 45\nmax_turn_to_arap_of_asked = 0.4\nmin_turn_to_arap_allowed_deg = 5\n\
             max_area_change_beyond_asked = 0.25\n",
        )
        .unwrap();
        let e = VerdictRules::load(&path).unwrap_err().to_string();
        assert!(e.contains("verdicts.toml") && e.contains("max_folds"), "{e}");
        std::fs::write(&path, "max_fold = 0\n").unwrap();
        let e = VerdictRules::load(&path).unwrap_err().to_string();
        assert!(e.contains("unknown field"), "{e}");
    }
}
