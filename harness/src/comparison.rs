//! `harness compare A B`: two runs side by side, case by case. Timings are judged against their
//! noise: B is *slower* or *faster* than A only when the noise bands of the two runs do not overlap
//! and the medians differ by at least `min_change`; else they are the same within noise. A band is
//! the min–max range over the repetitions (`--repeat`), widened to an absolute floor for
//! millisecond timings ([`noise_band`]). A run of one repetition has no spread, so its timings are
//! not judged. Two runs of the same commit (same tree) with the same inputs are said to be that at
//! the top ([`Comparison::same_commit_and_inputs`]): whatever differs between them is noise.
//! Quality is judged as the regression gate judges it, with A as the baseline
//! ([`crate::regression::check`], the metric table's tolerances). Whatever differs between the runs
//! beyond the commit (machine, threads, jobs, repetitions, build profile, data, input files) is a
//! warning, never silent.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::error::HarnessError;
use crate::provenance::Provenance;
use crate::record::{CaseKey, CaseResult, TimedPhase};
use crate::regression::{self, Finding};
use crate::stored_report::{read_results, StoredReport};

/// The default smallest change of a median that can be called slower or faster: 5%.
pub const DEFAULT_MIN_CHANGE: f64 = 0.05;

/// The narrowest noise band of a timing measured as one interval (start-up, precompute, bind,
/// solve, total), seconds: 2 ms, centred on the median.
///
/// Decision (issue 60): two `--repeat 3` runs of one commit on one machine called `isolines` 1.39x
/// slower on millisecond cases, because three rounds of a 2 ms case scatter by a few hundredths of
/// a millisecond within a run while the runs differ by most of a millisecond (frequency scaling,
/// cache and page state, the scheduler): min–max ranges that do not overlap by chance. So a band is
/// the measured range, but at least 2 ms wide: the change of a sub-10 ms case must exceed 2 ms
/// (20% at 10 ms, more below) to be called a change. Above some 40 ms the floor is below the 5%
/// of `--min-change` and no longer matters.
pub const NOISE_FLOOR_S: f64 = 0.002;

/// The narrowest noise band of the median iteration, as a fraction of it: 20%. An iteration takes
/// microseconds to milliseconds, so the absolute floor would leave it never judged; 20% is what
/// [`NOISE_FLOOR_S`] is at 10 ms.
pub const ITERATION_NOISE_FLOOR: f64 = 0.2;

/// One run of a comparison: where it was read from and what it holds.
pub struct ComparedRun {
    /// The `results.json` read.
    pub path: PathBuf,
    pub report: StoredReport,
}

impl ComparedRun {
    /// Read a run from a report directory (its `results.json`) or a `results.json` file.
    pub fn read(path: &Path) -> Result<ComparedRun, HarnessError> {
        let file = if path.is_dir() { path.join("results.json") } else { path.to_path_buf() };
        if !file.is_file() {
            return Err(HarnessError::Config {
                path: path.to_path_buf(),
                message: "neither a report directory with a results.json nor a results.json".into(),
            });
        }
        let report = read_results(&file)?;
        if let Some(shard) = report.shard {
            return Err(HarnessError::Config {
                path: file,
                message: format!("a partial report (part {shard}): compare the merged report"),
            });
        }
        Ok(ComparedRun { path: file, report })
    }
}

/// How B's time compares with A's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Speed {
    Faster,
    Slower,
    /// The ranges overlap, or the medians differ by less than the smallest change.
    SameWithinNoise,
    /// One side has no spread (one repetition) or no time (a failed case).
    NotJudged,
}

impl Speed {
    pub fn label(self) -> &'static str {
        match self {
            Speed::Faster => "faster",
            Speed::Slower => "slower",
            Speed::SameWithinNoise => "same within noise",
            Speed::NotJudged => "not judged",
        }
    }
}

/// A timing of one case in one run: the median with its min and max, seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    pub median: f64,
    pub min: f64,
    pub max: f64,
    pub repetitions: usize,
}

impl Timing {
    pub fn of(case: &CaseResult, phase: TimedPhase) -> Timing {
        let spread = phase.spread(case);
        Timing {
            median: phase.median(case),
            min: spread.min,
            max: spread.max,
            repetitions: case.spread.map_or(1, |s| s.repetitions),
        }
    }
}

/// One timed phase of one case in both runs.
#[derive(Clone, Debug, PartialEq)]
pub struct PhaseChange {
    pub phase: TimedPhase,
    pub a: Timing,
    pub b: Timing,
    /// B's median over A's.
    pub ratio: f64,
    pub speed: Speed,
}

/// The noise band of timing `t` of `phase`: its min–max range over the repetitions, widened to at
/// least [`NOISE_FLOOR_S`] (the median iteration: [`ITERATION_NOISE_FLOOR`] of it) centred on its
/// median.
pub fn noise_band(phase: TimedPhase, t: Timing) -> (f64, f64) {
    let floor = match phase {
        TimedPhase::Iteration => ITERATION_NOISE_FLOOR * t.median.abs(),
        _ => NOISE_FLOOR_S,
    };
    (t.min.min(t.median - floor / 2.0), t.max.max(t.median + floor / 2.0))
}

/// Judge B's timing of `phase` against A's: slower or faster only when their noise bands
/// ([`noise_band`]) do not overlap and the medians differ by at least `min_change` (a fraction);
/// not judged without a spread on both sides.
pub fn judge_speed(phase: TimedPhase, a: Timing, b: Timing, min_change: f64) -> Speed {
    let finite = |t: Timing| t.median.is_finite() && t.min.is_finite() && t.max.is_finite();
    if !finite(a) || !finite(b) || a.repetitions < 2 || b.repetitions < 2 || a.median <= 0.0 {
        return Speed::NotJudged;
    }
    let ((a_low, a_high), (b_low, b_high)) = (noise_band(phase, a), noise_band(phase, b));
    let overlap = a_low <= b_high && b_low <= a_high;
    let ratio = b.median / a.median;
    if overlap || (ratio - 1.0).abs() < min_change {
        Speed::SameWithinNoise
    } else if ratio > 1.0 {
        Speed::Slower
    } else {
        Speed::Faster
    }
}

/// One (scenario, method) in both runs.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseChange {
    pub scenario: String,
    pub method: String,
    /// Every [`TimedPhase`], in order; the case's speed is its total's.
    pub phases: Vec<PhaseChange>,
    /// Iterations of A and B.
    pub iterations: (usize, usize),
    /// Statuses of A and B (`ok`, `suspect: …`).
    pub status: (String, String),
    /// The gate's findings about B with A as the baseline (worse, better, turned, failed).
    pub quality: Vec<Finding>,
}

impl CaseChange {
    /// The verdict on the time to a result: the total's.
    pub fn speed(&self) -> Speed {
        self.total().speed
    }

    pub fn total(&self) -> &PhaseChange {
        self.phases.iter().find(|p| p.phase == TimedPhase::Total).expect("every phase is compared")
    }

    /// Whether some quality finding fails the gate.
    pub fn is_worse(&self) -> bool {
        self.quality.iter().any(Finding::is_regression)
    }

    pub fn is_better(&self) -> bool {
        !self.quality.is_empty() && !self.is_worse()
    }
}

/// Two runs compared.
pub struct Comparison {
    pub a: PathBuf,
    pub b: PathBuf,
    /// Each run's provenance line.
    pub a_record: String,
    pub b_record: String,
    /// What differs between the runs beyond the commit, and anything that weakens the comparison.
    pub warnings: Vec<String>,
    /// Both runs are of the same commit, from a clean tree or the same uncommitted change (the same
    /// diff hash), and read the same inputs (every file's SHA-256): any difference between them is
    /// the machine's noise, and the report says so at the top.
    pub same_commit_and_inputs: bool,
    /// Cases of both runs, in B's order.
    pub cases: Vec<CaseChange>,
    /// `scenario / method` of cases in only one of the runs.
    pub only_in_a: Vec<String>,
    pub only_in_b: Vec<String>,
    pub min_change: f64,
}

/// How many cases got each verdict.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub slower: usize,
    pub faster: usize,
    pub same: usize,
    pub not_judged: usize,
    pub worse: usize,
    pub better: usize,
}

impl Comparison {
    pub fn tally(&self) -> Tally {
        let mut t = Tally::default();
        for c in &self.cases {
            match c.speed() {
                Speed::Slower => t.slower += 1,
                Speed::Faster => t.faster += 1,
                Speed::SameWithinNoise => t.same += 1,
                Speed::NotJudged => t.not_judged += 1,
            }
            t.worse += usize::from(c.is_worse());
            t.better += usize::from(c.is_better());
        }
        t
    }
}

/// Compare run `b` with run `a` (the earlier one, or the reference).
pub fn compare(a: &ComparedRun, b: &ComparedRun, min_change: f64) -> Comparison {
    let (ra, rb) = (&a.report, &b.report);
    let a_cases: BTreeMap<CaseKey, &CaseResult> = ra.cases.iter().map(|c| (c.key(), c)).collect();
    let findings = regression::check(&regression::baseline_from(&ra.cases), &rb.cases);
    let mut cases = Vec::new();
    let mut only_in_b = Vec::new();
    for cb in &rb.cases {
        let Some(ca) = a_cases.get(&cb.key()) else {
            only_in_b.push(format!("{} / {}", cb.scenario, cb.method));
            continue;
        };
        let phases = TimedPhase::ALL
            .iter()
            .map(|&phase| {
                let (ta, tb) = (Timing::of(ca, phase), Timing::of(cb, phase));
                PhaseChange {
                    phase,
                    a: ta,
                    b: tb,
                    ratio: tb.median / ta.median,
                    speed: judge_speed(phase, ta, tb, min_change),
                }
            })
            .collect();
        let quality =
            findings.iter().filter(|f| finding_case(f).as_ref() == Some(&cb.key())).cloned().collect();
        cases.push(CaseChange {
            scenario: cb.scenario.clone(),
            method: cb.method.clone(),
            phases,
            iterations: (ca.iterations, cb.iterations),
            status: (ca.status.to_string(), cb.status.to_string()),
            quality,
        });
    }
    let b_keys: BTreeSet<CaseKey> = rb.cases.iter().map(CaseResult::key).collect();
    let only_in_a = ra
        .cases
        .iter()
        .filter(|c| !b_keys.contains(&c.key()))
        .map(|c| format!("{} / {}", c.scenario, c.method))
        .collect();
    let record =
        |r: &StoredReport| r.provenance.as_ref().map_or_else(|| "no record".to_string(), Provenance::summary);
    Comparison {
        a: a.path.clone(),
        b: b.path.clone(),
        a_record: record(ra),
        b_record: record(rb),
        warnings: warnings(ra, rb),
        same_commit_and_inputs: same_commit_and_inputs(ra, rb),
        cases,
        only_in_a,
        only_in_b,
        min_change,
    }
}

/// The line at the top of a comparison of two runs of one commit and the same inputs.
pub const SAME_COMMIT_AND_INPUTS: &str = "same commit and inputs: differences are noise";

/// Whether `a` and `b` ran the same code on the same data: the same commit with a clean tree, or
/// with the same uncommitted change (its diff hash; a dirty tree without one is never the same),
/// the same data source and the same input files (by SHA-256, wherever they were read from).
fn same_commit_and_inputs(a: &StoredReport, b: &StoredReport) -> bool {
    let (Some(pa), Some(pb)) = (&a.provenance, &b.provenance) else { return false };
    let tree = |p: &Provenance| -> Option<(String, Option<String>)> {
        let commit = p.build.git_commit.clone()?;
        match p.build.git_dirty? {
            false => Some((commit, None)),
            true => Some((commit, Some(p.build.git_diff_sha256.clone()?))),
        }
    };
    tree(pa).is_some()
        && tree(pa) == tree(pb)
        && a.data_source == b.data_source
        && !pa.inputs.is_empty()
        && pa.inputs.len() == pb.inputs.len()
        && input_differences(pa, pb).is_empty()
}

/// The case a finding is about (`Missing` ones are the cases only in A, listed apart).
fn finding_case(f: &Finding) -> Option<CaseKey> {
    match f {
        Finding::Worse { scenario, method, .. }
        | Finding::Turned { scenario, method, .. }
        | Finding::Failed { scenario, method, .. }
        | Finding::NonFinite { scenario, method, .. }
        | Finding::Better { scenario, method, .. }
        | Finding::Improved { scenario, method, .. }
        | Finding::IterateNotCompared { scenario, method } => Some(CaseKey::new(scenario, method)),
        Finding::Missing { .. } => None,
    }
}

/// Everything that makes the two runs other than two runs of the same setup on the same machine.
/// A build from a tree with uncommitted changes is named too: its commit does not say what ran.
fn warnings(a: &StoredReport, b: &StoredReport) -> Vec<String> {
    let mut w = Vec::new();
    if a.data_source != b.data_source {
        w.push(format!("different data: A ran on {}, B on {}", a.data_source, b.data_source));
    }
    let (pa, pb) = match (&a.provenance, &b.provenance) {
        (Some(pa), Some(pb)) => (pa, pb),
        (None, _) | (_, None) => {
            let which = if a.provenance.is_none() { "A" } else { "B" };
            w.push(format!(
                "{which} has no provenance record (made by an older harness): machine, settings and inputs cannot be compared"
            ));
            return w;
        }
    };
    let (ma, mb) = (&pa.machine, &pb.machine);
    if (ma.cpu_model.as_str(), ma.logical_cores, ma.memory_gib.round() as i64)
        != (mb.cpu_model.as_str(), mb.logical_cores, mb.memory_gib.round() as i64)
    {
        w.push(format!(
            "different machines: A ran on {} ({} logical cores, {:.0} GiB), B on {} ({} logical cores, {:.0} GiB): \
             a timing ratio says as much about the machines as about the code",
            ma.cpu_model, ma.logical_cores, ma.memory_gib, mb.cpu_model, mb.logical_cores, mb.memory_gib
        ));
    } else if (&ma.os, &ma.kernel) != (&mb.os, &mb.kernel) {
        w.push(format!(
            "different systems: A on {} (kernel {}), B on {} (kernel {})",
            ma.os, ma.kernel, mb.os, mb.kernel
        ));
    }
    let (ra, rb) = (&pa.run, &pb.run);
    for (what, x, y) in [
        ("threads", ra.threads, rb.threads),
        ("jobs", ra.jobs, rb.jobs),
        ("repetitions", ra.repetitions, rb.repetitions),
    ] {
        if x != y {
            w.push(format!("different {what}: A ran with {x}, B with {y}"));
        }
    }
    for (name, r) in [("A", ra), ("B", rb)] {
        if r.repetitions < 2 {
            w.push(format!(
                "{name} timed each case once: without a spread no timing is judged (run both with --repeat 5)"
            ));
        }
    }
    if pa.build.profile != pb.build.profile {
        w.push(format!("different build profiles: A {}, B {}", pa.build.profile, pb.build.profile));
    }
    for (name, build) in [("A", &pa.build), ("B", &pb.build)] {
        if build.git_dirty == Some(true) {
            w.push(format!("{name} was built from a tree with uncommitted changes"));
        }
    }
    w.extend(input_differences(pa, pb));
    w
}

/// The input files that differ between the runs: changed contents, and files only one run read.
/// The checkouts and data may live in different places, so a file of A is matched with the file of
/// B of the same name whose path shares the most trailing components with its own.
fn input_differences(a: &Provenance, b: &Provenance) -> Vec<String> {
    let components = |path: &str| -> Vec<String> {
        path.split(['/', '\\']).filter(|c| !c.is_empty()).rev().map(str::to_string).collect()
    };
    let shared_tail = |x: &[String], y: &[String]| x.iter().zip(y).take_while(|(p, q)| p == q).count();
    let b_files: Vec<Vec<String>> = b.inputs.iter().map(|i| components(&i.path)).collect();
    let mut matched = vec![false; b.inputs.len()];
    let (mut changed, mut only_a) = (Vec::new(), Vec::new());
    for input in &a.inputs {
        let mine = components(&input.path);
        // The last two components name a file well enough in a message (`configs/methods.toml`).
        let name = mine.iter().take(2).rev().cloned().collect::<Vec<_>>().join("/");
        let best = (0..b.inputs.len())
            .filter(|&j| !matched[j])
            .map(|j| (shared_tail(&mine, &b_files[j]), j))
            .filter(|&(shared, _)| shared >= 1)
            .max_by_key(|&(shared, j)| (shared, std::cmp::Reverse(j)));
        match best {
            Some((_, j)) => {
                matched[j] = true;
                if b.inputs[j].sha256 != input.sha256 {
                    changed.push(name);
                }
            }
            None => only_a.push(name),
        }
    }
    let only_b: Vec<String> = b_files
        .iter()
        .zip(&matched)
        .filter(|(_, m)| !**m)
        .map(|(c, _)| c.iter().take(2).rev().cloned().collect::<Vec<_>>().join("/"))
        .collect();
    let list = |v: &[String]| {
        let shown: Vec<&str> = v.iter().take(6).map(String::as_str).collect();
        let more = if v.len() > shown.len() {
            format!(" and {} more", v.len() - shown.len())
        } else {
            String::new()
        };
        format!("{}{more}", shown.join(", "))
    };
    let mut w = Vec::new();
    if !changed.is_empty() {
        w.push(format!("different configuration or data: {} differ(s) between the runs", list(&changed)));
    }
    for (name, v) in [("A", &only_a), ("B", &only_b)] {
        if !v.is_empty() {
            w.push(format!("only {name} read {}", list(v)));
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(median: f64, min: f64, max: f64, repetitions: usize) -> Timing {
        Timing { median, min, max, repetitions }
    }

    fn judge_speed(a: Timing, b: Timing, min_change: f64) -> Speed {
        super::judge_speed(TimedPhase::Total, a, b, min_change)
    }

    #[test]
    fn millisecond_timings_change_only_beyond_the_absolute_floor() {
        // Issue 60: two runs of one commit, 2.0 and 2.78 ms with tight ranges apart: noise.
        let a = timing(0.0020, 0.00195, 0.00205, 3);
        let b = timing(0.00278, 0.00272, 0.00285, 3);
        assert_eq!(judge_speed(a, b, 0.05), Speed::SameWithinNoise);
        // Three times as long is beyond 2 ms: slower, and the other way faster.
        let c = timing(0.0060, 0.0059, 0.0061, 3);
        assert_eq!(judge_speed(a, c, 0.05), Speed::Slower);
        assert_eq!(judge_speed(c, a, 0.05), Speed::Faster);
        // Seconds are judged by their ranges as before.
        assert_eq!(
            judge_speed(timing(1.0, 0.999, 1.001, 3), timing(1.1, 1.099, 1.101, 3), 0.05),
            Speed::Slower
        );
        // The median iteration's floor is 20% of it, not 2 ms.
        let it = |m: f64| timing(m, m * 0.99, m * 1.01, 3);
        let iteration = |a, b| super::judge_speed(TimedPhase::Iteration, a, b, 0.05);
        assert_eq!(iteration(it(1e-4), it(1.15e-4)), Speed::SameWithinNoise);
        assert_eq!(iteration(it(1e-4), it(1.5e-4)), Speed::Slower);
    }

    #[test]
    fn slower_or_faster_only_when_the_ranges_part_and_the_change_is_large_enough() {
        let a = timing(1.0, 0.95, 1.05, 5);
        assert_eq!(judge_speed(a, timing(1.2, 1.15, 1.3, 5), 0.05), Speed::Slower);
        assert_eq!(judge_speed(a, timing(0.8, 0.7, 0.85, 5), 0.05), Speed::Faster);
        // Overlapping ranges: noise, however far apart the medians.
        assert_eq!(judge_speed(a, timing(1.3, 1.04, 1.4, 5), 0.05), Speed::SameWithinNoise);
        // Apart, but by less than the smallest change.
        assert_eq!(
            judge_speed(timing(1.0, 1.0, 1.0, 5), timing(1.03, 1.02, 1.04, 5), 0.05),
            Speed::SameWithinNoise
        );
        assert_eq!(judge_speed(timing(1.0, 1.0, 1.0, 5), timing(1.03, 1.02, 1.04, 5), 0.0), Speed::Slower);
        // One repetition has no spread; a failed case has no time.
        assert_eq!(judge_speed(timing(1.0, 1.0, 1.0, 1), timing(2.0, 2.0, 2.0, 5), 0.05), Speed::NotJudged);
        assert_eq!(judge_speed(a, timing(f64::NAN, f64::NAN, f64::NAN, 5), 0.05), Speed::NotJudged);
    }

    #[test]
    fn inputs_are_matched_by_their_last_two_components() {
        use crate::provenance::InputFile;
        let file = |path: &str, sha: &str| InputFile { path: path.into(), sha256: sha.into() };
        let mut a = Provenance::default();
        let mut b = Provenance::default();
        a.inputs = vec![
            file("/x/configs/methods.toml", "1"),
            file("/x/survey/bar.off", "2"),
            file("/x/configs/old.toml", "3"),
        ];
        b.inputs = vec![file("/y/configs/methods.toml", "9"), file("/y/survey/bar.off", "2")];
        let w = input_differences(&a, &b);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(w[0].contains("configs/methods.toml differ"), "{w:?}");
        assert!(w[1].contains("only A read configs/old.toml"), "{w:?}");
    }
}
