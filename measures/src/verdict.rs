//! The verdict on a case: `ok`, `suspect: <reasons>` (it finished, but its shape is broken in a way
//! a measure sees), `unfinished: <reasons>` (its iteration stopped at the cap before reaching its
//! tolerance: the shape is an iterate, not the method's answer; any suspect reasons follow), or
//! `failed: <error>` (no result). The thresholds are data (`configs/verdicts.toml`), each with the
//! reason for its value written there.
//!
//! This module holds the rules that make a finished case `suspect`; [`crate::status`] the status
//! they give and its text.
//!
//! Suspect and unfinished cases are still results: the run's exit code stays 0 for them, and they
//! are drawn and reported like any other, with their reasons.

use std::path::Path;

use serde::Deserialize;

use meshes::vector::{norm, sub};
use meshes::TriMesh;
use methods::{HandleSet, HandleTargets};

use crate::distance::largest_displacement;
use crate::distortion::{area_change, volume_change};
use crate::error::MeasuresError;
use crate::metric::Metric;
use crate::quality::Quality;
use crate::rest::RestGeometry;
use crate::size::{asked_size, AskedSize};
use crate::turn::{asked_turn, Bends};

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
    /// How far the total surface area may leave the range the handles ask ([`Motion::asked_size`],
    /// widened by the reference's own change), as a fraction: `swells` above, `shrinks` below. The
    /// enclosed volume of a closed mesh is judged with the same margin on lengths (its power 3/2).
    pub max_area_change_beyond_asked: f64,
    /// Largest `shrunk_share` or `swollen_share` (share of the surface resized beyond what is asked)
    /// that is still `ok`.
    pub max_resized_share: f64,
    /// Largest `turned_share` (share of the free surface turned 45° beyond what is asked) that is
    /// still `ok`.
    pub max_turned_share: f64,
}

/// What a verdict reads of a case besides its measures ([`Motion::of`] builds it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// The largest distance of any result vertex from its rest position, over the rest diagonal.
    pub largest_move: f64,
    /// The largest distance of a handle target from its vertex's rest position (over every edit
    /// step), over the rest diagonal.
    pub largest_handle_move: f64,
    /// The turn the last step's handles ask of the free surface (degrees,
    /// [`crate::turn::asked_turn`] with bends from the held regions only).
    pub asked_turn_deg: f64,
    /// The area factors the last step's handles ask, per region from its own motion
    /// ([`crate::size::asked_size`]): 1 for rigid motions and bends.
    pub asked_size: AskedSize,
    /// The reference's own `(A / A⁰, V / V⁰)` on the same edit, where it finished and is another
    /// result than this one: a size the edit needed of the reference is not held against others.
    pub reference_size: Option<(f64, Option<f64>)>,
    /// The scenario's reference (`arap`) finished (ok or suspect), so its result judges this one's
    /// turns (`turn_to_arap_deg`); an unfinished reference is an iterate, and then only the result's
    /// own measures judge it (`turn_beyond_handles_deg` among them).
    pub reference_finished: bool,
}

/// The result a case is judged beside.
#[derive(Clone, Copy, Debug)]
pub enum Reference<'a> {
    /// This result is the reference: its distances and turn to it are 0, and nothing but the
    /// handles' asking judges its size.
    Itself,
    /// The reference's `#V x 3` result on the same edit, and whether it finished (ok or suspect:
    /// not an iterate stopped at its cap).
    Of { positions: &'a [[f64; 3]], finished: bool },
    /// No reference result (not run, or failed).
    Missing,
}

impl Motion {
    /// The motion of `result` (`#V x 3`) on the rest `mesh` (with `rest_geometry`) under the
    /// edit `steps` (each step's handle set and targets; the last is judged), beside `reference`.
    pub fn of<'s>(
        rest_geometry: &RestGeometry,
        mesh: &TriMesh,
        result: &[[f64; 3]],
        steps: &[(&'s HandleSet, &'s HandleTargets)],
        reference: Reference<'_>,
    ) -> Motion {
        let rest = mesh.positions();
        let largest_handle_move = steps
            .iter()
            .flat_map(|(handles, targets)| handles.constrained().zip(targets.positions()))
            .map(|(v, t)| norm(sub(*t, rest[v as usize])))
            .fold(0.0f64, f64::max);
        let (handles, targets) = *steps.last().expect("an edit has at least one step");
        let (reference_size, reference_finished) = match reference {
            Reference::Itself => (None, true),
            Reference::Of { positions, finished } => {
                (finished.then(|| size_factors(rest_geometry, mesh, positions)), finished)
            }
            Reference::Missing => (None, false),
        };
        Motion {
            largest_move: largest_displacement(rest, result) / rest_geometry.diagonal,
            largest_handle_move: largest_handle_move / rest_geometry.diagonal,
            asked_turn_deg: asked_turn(rest, handles, targets, Bends::FromHeld).to_degrees(),
            asked_size: asked_size(rest, handles, targets),
            reference_size,
            reference_finished,
        }
    }
}

/// `(A / A⁰, V / V⁰)` of `result` on `mesh` against its `rest` geometry (the volume where
/// [`volume_change`] has one: closed meshes).
fn size_factors(rest: &RestGeometry, mesh: &TriMesh, result: &[[f64; 3]]) -> (f64, Option<f64>) {
    (1.0 + area_change(rest, mesh, result), volume_change(rest, mesh, result).map(|v| 1.0 + v))
}

impl VerdictRules {
    /// Read and check `path`.
    pub fn load(path: &Path) -> Result<Self, MeasuresError> {
        let config = |message: String| MeasuresError::Rules { path: path.to_path_buf(), message };
        let text = std::fs::read_to_string(path)
            .map_err(|error| MeasuresError::Read { path: path.to_path_buf(), error })?;
        let rules: VerdictRules = toml::from_str(&text).map_err(|e| config(e.to_string()))?;
        for (name, value) in [
            ("max_folds", rules.max_folds),
            ("max_handle_residual_over_diag", rules.max_handle_residual_over_diag),
            ("frame_margin_diagonals", rules.frame_margin_diagonals),
            ("max_turn_beyond_handles_deg", rules.max_turn_beyond_handles_deg),
            ("max_turn_to_arap_of_asked", rules.max_turn_to_arap_of_asked),
            ("min_turn_to_arap_allowed_deg", rules.min_turn_to_arap_allowed_deg),
            ("max_area_change_beyond_asked", rules.max_area_change_beyond_asked),
            ("max_resized_share", rules.max_resized_share),
            ("max_turned_share", rules.max_turned_share),
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
        let Motion { largest_move, largest_handle_move, asked_turn_deg, reference_finished, .. } = motion;
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
        } else if let Some(share) = quality.get(Metric::TurnedShare).filter(|s| *s > self.max_turned_share) {
            reasons.push(format!(
                "turns a free region: {:.1}% of its free surface turned more than {:.0}° beyond what the handles \
                 ask (> {:.1}%)",
                100.0 * share,
                crate::turn::TURNED_MARGIN_DEG,
                100.0 * self.max_turned_share
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
        reasons.extend(self.size_reasons(quality, motion));
        let allowed = largest_handle_move + self.frame_margin_diagonals;
        if largest_move > allowed {
            reasons.push(format!(
                "leaves its frame: a vertex moved {largest_move:.2} diagonals (handles at most {largest_handle_move:.2})"
            ));
        }
        reasons
    }

    /// The `shrinks` and `swells` reasons: the total area (and a closed mesh's volume) against the
    /// size the handles ask, widened by the reference's own change; else the share of the surface
    /// resized in places.
    fn size_reasons(&self, quality: &Quality, motion: Motion) -> Vec<String> {
        let margin = (1.0 + self.max_area_change_beyond_asked).ln();
        let (reference_area, reference_volume) = match motion.reference_size {
            Some((area, volume)) => (Some(area), volume),
            None => (None, None),
        };
        let asked = motion.asked_size;
        let measured = [
            ("surface area", Metric::AreaChange, asked, reference_area, margin),
            ("volume", Metric::VolumeChange, asked.volume(), reference_volume, 1.5 * margin),
        ];
        let mut totals: Vec<(&str, String)> = Vec::new();
        for (what, metric, asked, beside, margin) in measured {
            let Some(factor) = quality.get(metric).filter(|c| c.is_finite()).map(|c| 1.0 + c) else {
                continue;
            };
            let beyond = asked.with(beside).beyond(factor);
            let kind = if beyond < -margin {
                "shrinks"
            } else if beyond > margin {
                "swells"
            } else {
                continue;
            };
            // Within half a percent of no change is printed as none (round-off of the targets).
            let asked = if (asked.low - 1.0).abs() < 5e-3 && (asked.high - 1.0).abs() < 5e-3 {
                "the handles ask no change".to_string()
            } else {
                let percent = |f: f64| format!("{:+.0}%", 100.0 * (f - 1.0));
                format!("the handles ask {} to {}", percent(asked.low), percent(asked.high))
            };
            let beside =
                beside.map_or(String::new(), |r| format!(" and arap's changed {:+.1}%", 100.0 * (r - 1.0)));
            let went = if kind == "shrinks" { "fell" } else { "grew" };
            totals.push((
                kind,
                format!("its {what} {went} {:+.0}% where {asked}{beside}", 100.0 * (factor - 1.0)),
            ));
        }
        let mut reasons = Vec::new();
        for kind in ["shrinks", "swells"] {
            let parts: Vec<&str> =
                totals.iter().filter(|(k, _)| *k == kind).map(|(_, t)| t.as_str()).collect();
            if !parts.is_empty() {
                reasons.push(format!(
                    "{kind}: {} (> {:.0}% beyond)",
                    parts.join("; "),
                    100.0 * self.max_area_change_beyond_asked
                ));
                continue;
            }
            let (metric, went) = if kind == "shrinks" {
                (Metric::ShrunkShare, "lost")
            } else {
                (Metric::SwollenShare, "gained")
            };
            if let Some(share) = quality.get(metric).filter(|s| *s > self.max_resized_share) {
                reasons.push(format!(
                    "{kind} in places: {:.1}% of its surface {went} more than a factor {:.1} of area beyond what \
                     is asked and beyond arap's there (> {:.1}%)",
                    100.0 * share,
                    crate::size::LOCAL_AREA_MARGIN,
                    100.0 * self.max_resized_share
                ));
            }
        }
        reasons
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
            max_resized_share: 0.05,
            max_turned_share: 0.02,
        }
    }

    /// A case that moved `largest_move` diagonals with handles moved 0.2, asked 50 deg, judged
    /// against a finished reference.
    fn moved(largest_move: f64) -> Motion {
        Motion {
            largest_move,
            largest_handle_move: 0.2,
            asked_turn_deg: 50.0,
            asked_size: AskedSize::NONE,
            reference_size: None,
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
    }

    #[test]
    fn the_area_is_judged_against_the_scale_the_handles_ask_and_every_reason_has_its_kind() {
        let r = rules();
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
        let stretched = Motion { asked_size: AskedSize { low: 1.0, high: 1.44 }, ..moved(0.3) };
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
    fn size_is_judged_per_region_beside_the_reference_and_in_places() {
        let r = rules();
        // A bend asks nothing: -27% of area shrinks, even where the spread of the targets fell.
        let mut q = quality(0.0, 0.0);
        q.set(Metric::AreaChange, Some(-0.27));
        let reasons = r.reasons(&q, moved(0.3));
        assert!(
            reasons.len() == 1
                && reasons[0]
                    .starts_with("shrinks: its surface area fell -27% where the handles ask no change ("),
            "{reasons:?}"
        );
        // Beside a reference that lost 20% itself, -27% is inside 0.8 / 1.25.
        let beside = Motion { reference_size: Some((0.8, None)), ..moved(0.3) };
        assert!(r.reasons(&q, beside).is_empty());
        // A closed mesh's volume, with the same margin on lengths: 1.25^1.5 = 1.40.
        let mut v = quality(0.0, 0.0);
        v.set(Metric::VolumeChange, Some(-0.27));
        assert!(r.reasons(&v, moved(0.3)).is_empty(), "0.73 > 1 / 1.40");
        v.set(Metric::VolumeChange, Some(-0.31));
        let reasons = r.reasons(&v, moved(0.3));
        assert!(reasons.len() == 1 && reasons[0].starts_with("shrinks: its volume fell -31%"), "{reasons:?}");
        // Area and volume both: one reason of the kind naming both.
        v.set(Metric::AreaChange, Some(-0.3));
        let reasons = r.reasons(&v, moved(0.3));
        assert!(
            reasons.len() == 1 && reasons[0].contains("surface area") && reasons[0].contains("volume"),
            "{reasons:?}"
        );
        // In places: a share above 5% of the surface resized, when the totals pass.
        let mut local = quality(0.0, 0.0);
        local.set(Metric::ShrunkShare, Some(0.05));
        local.set(Metric::SwollenShare, Some(0.051));
        let reasons = r.reasons(&local, moved(0.3));
        assert!(
            reasons.len() == 1 && reasons[0].starts_with("swells in places: 5.1% of its surface"),
            "{reasons:?}"
        );
        assert_eq!(reason_kind(&reasons[0]), Some("swells"));
        // Turned in places: above 2% of the free surface, when the 90th percentile passes.
        let mut turned = quality(0.0, 0.0);
        turned.set(Metric::TurnBeyondHandles, Some(10.0));
        turned.set(Metric::TurnedShare, Some(0.02));
        assert!(r.reasons(&turned, moved(0.3)).is_empty());
        turned.set(Metric::TurnedShare, Some(0.03));
        let reasons = r.reasons(&turned, moved(0.3));
        assert!(
            reasons.len() == 1 && reasons[0].starts_with("turns a free region: 3.0% of its free surface"),
            "{reasons:?}"
        );
    }

    #[test]
    fn the_committed_rules_load_and_bad_values_are_named() {
        let committed = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/verdicts.toml");
        let r = VerdictRules::load(&committed).unwrap();
        assert_eq!(r.max_folds, 0.0, "any fold is suspect (issue 14)");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("verdicts.toml");
        std::fs::write(
            &path,
            "max_folds = -1\nmax_handle_residual_over_diag = 1e-3\nframe_margin_diagonals = 1\n\
             max_turn_beyond_handles_deg = 45\nmax_turn_to_arap_of_asked = 0.4\nmin_turn_to_arap_allowed_deg = 5\n\
             max_area_change_beyond_asked = 0.25\nmax_resized_share = 0.05\nmax_turned_share = 0.02\n",
        )
        .unwrap();
        let e = VerdictRules::load(&path).unwrap_err().to_string();
        assert!(e.contains("verdicts.toml") && e.contains("max_folds"), "{e}");
        std::fs::write(&path, "max_fold = 0\n").unwrap();
        let e = VerdictRules::load(&path).unwrap_err().to_string();
        assert!(e.contains("unknown field"), "{e}");
    }
}
