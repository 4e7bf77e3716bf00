//! The verdicts on the labelled set counted per rule: true and false positives, false negatives,
//! precision and recall per reason kind, the share of good cases flagged, and the cases judged
//! wrong with the measures the rules read.

use std::fmt::Write as _;

use measures::{reason_kind, Metric, REASON_KINDS};

use super::{Judged, Label, Skipped};

/// The counts of one reason kind.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RuleCounts {
    pub kind: &'static str,
    /// Cases that expect the kind and got it.
    pub true_positives: usize,
    /// Cases that got the kind without expecting or tolerating it.
    pub false_positives: usize,
    /// Cases that expect the kind and did not get it.
    pub false_negatives: usize,
}

impl RuleCounts {
    pub fn precision(&self) -> Option<f64> {
        ratio(self.true_positives, self.true_positives + self.false_positives)
    }
    pub fn recall(&self) -> Option<f64> {
        ratio(self.true_positives, self.true_positives + self.false_negatives)
    }
}

fn ratio(a: usize, b: usize) -> Option<f64> {
    (b > 0).then(|| a as f64 / b as f64)
}

/// The whole count.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    pub rules: Vec<RuleCounts>,
    pub good: usize,
    /// Good cases with any reason.
    pub good_flagged: Vec<String>,
    pub bad: usize,
    /// Bad cases missing one of their expected kinds, with the kinds missed.
    pub bad_missed: Vec<(String, Vec<String>)>,
    /// Bad cases with no reason at all: the verdict called them `ok`.
    pub bad_unflagged: Vec<String>,
    pub tolerated: usize,
    /// Tolerated cases with any reason.
    pub tolerated_flagged: Vec<String>,
    pub skipped: usize,
}

/// The kinds of the reasons of `case`.
fn fired(case: &Judged) -> Vec<&'static str> {
    case.judgement.reasons.iter().filter_map(|r| reason_kind(r)).collect()
}

impl Tally {
    /// Count `judged` (and how many were `skipped`).
    pub fn of(judged: &[Judged], skipped: &[Skipped]) -> Tally {
        let mut tally = Tally { skipped: skipped.len(), ..Tally::default() };
        tally.rules = REASON_KINDS.iter().map(|k| RuleCounts { kind: k, ..RuleCounts::default() }).collect();
        for case in judged {
            let got = fired(case);
            if case.label == Label::Tolerated {
                tally.tolerated += 1;
                if !case.judgement.reasons.is_empty() {
                    tally.tolerated_flagged.push(case.name.clone());
                }
                continue;
            }
            for counts in &mut tally.rules {
                let expected = case.kinds.iter().any(|k| k == counts.kind);
                let tolerated = case.also.iter().any(|k| k == counts.kind);
                let fired = got.contains(&counts.kind);
                match (expected, fired) {
                    (true, true) => counts.true_positives += 1,
                    (true, false) => counts.false_negatives += 1,
                    (false, true) if !tolerated => counts.false_positives += 1,
                    _ => {}
                }
            }
            match case.label {
                Label::Good => {
                    tally.good += 1;
                    if !case.judgement.reasons.is_empty() {
                        tally.good_flagged.push(case.name.clone());
                    }
                }
                Label::Bad => {
                    tally.bad += 1;
                    let missed: Vec<String> =
                        case.kinds.iter().filter(|k| !got.contains(&k.as_str())).cloned().collect();
                    if !missed.is_empty() {
                        tally.bad_missed.push((case.name.clone(), missed));
                    }
                    if case.judgement.reasons.is_empty() {
                        tally.bad_unflagged.push(case.name.clone());
                    }
                }
                Label::Tolerated => unreachable!("counted above"),
            }
        }
        tally
    }

    /// The share of good cases flagged.
    pub fn good_flagged_share(&self) -> f64 {
        ratio(self.good_flagged.len(), self.good).unwrap_or(0.0)
    }

    /// The precision/recall table (Markdown).
    pub fn table(&self) -> String {
        let pct = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.0}%", 100.0 * v));
        let mut out = String::from(
            "| rule kind | true pos. | false pos. | false neg. | precision | recall |\n|---|---:|---:|---:|---:|---:|\n",
        );
        for r in &self.rules {
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} |",
                r.kind,
                r.true_positives,
                r.false_positives,
                r.false_negatives,
                pct(r.precision()),
                pct(r.recall())
            );
        }
        let _ = writeln!(
            out,
            "\n{} good cases, {} flagged ({:.1}%); {} bad cases, {} flagged, {} of them with every expected kind; \
             {} tolerated cases, {} flagged; {} skipped",
            self.good,
            self.good_flagged.len(),
            100.0 * self.good_flagged_share(),
            self.bad,
            self.bad - self.bad_unflagged.len(),
            self.bad - self.bad_missed.len(),
            self.tolerated,
            self.tolerated_flagged.len(),
            self.skipped
        );
        out
    }
}

/// One line per case: its truth, its verdict and the measures the rules read.
pub fn case_lines(judged: &[Judged]) -> String {
    let mut out = String::new();
    for case in judged {
        let truth = match case.label {
            Label::Good => "good".to_string(),
            Label::Bad => format!("bad: {}", case.kinds.join(", ")),
            Label::Tolerated => "tolerated".to_string(),
        };
        let verdict = if case.judgement.reasons.is_empty() {
            "ok".to_string()
        } else {
            format!("suspect: {}", fired(case).join(", "))
        };
        let _ = writeln!(out, "{:<48} {:<30} {:<40} {}", case.name, truth, verdict, measured(case));
    }
    out
}

/// The measures the rules read, in a line.
pub fn measured(case: &Judged) -> String {
    let q = &case.judgement.quality;
    let v = |m: Metric| q.get(m).map_or("-".to_string(), |v| format!("{v:.3}"));
    format!(
        "e_iso {} area {} volume {} shrunk {} swollen {} turned {} turn_beyond {}° folds {} residual {}",
        v(Metric::EIso),
        v(Metric::AreaChange),
        v(Metric::VolumeChange),
        v(Metric::ShrunkShare),
        v(Metric::SwollenShare),
        v(Metric::TurnedShare),
        v(Metric::TurnBeyondHandles),
        q.get(Metric::Folds).map_or("-".to_string(), |f| format!("{f:.2e}")),
        q.get(Metric::HandleResidual).map_or("-".to_string(), |f| format!("{f:.1e}")),
    )
}
