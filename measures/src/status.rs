//! A case's [`Status`] (`ok`, `suspect`, `unfinished` or `failed`, with its reasons) and its text in
//! results.json; [`Unfinished`] says where an iteration stopped before its tolerance.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::step_trend::StepTrend;

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

    /// The status of a case that produced a shape: `Unfinished` when any step did not finish (its
    /// reasons first, then the shape's), else `Suspect` for any shape reason, else `Ok`.
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
}
