//! What a run makes of its cases once they have run: the peer checks, every report, the plots and
//! figures, the regression gate and the HTML index, as one function ([`publish`]) returning an
//! [`Outcome`]. The CLI only parses arguments, prints the outcome and maps it to an exit code.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::error::HarnessError;
use crate::record::CaseResult;
use crate::regression::{self, BaselineKind, GateOutcome};
use crate::report::document::{Document, Image, Table};
use crate::report::{self, html, peer_comparison, plots, render, MeshOutput};
use crate::suite::{SuiteOptions, SuiteRun};
use crate::{self_intersection, shard::Shard};

/// Which baseline a run is compared with.
#[derive(Clone, Debug, PartialEq)]
pub enum GateRequest {
    /// The baseline at this path, or (`None`) the committed one of the run's data source
    /// ([`BaselineKind::default_path`]).
    Compare(Option<PathBuf>),
    /// No comparison, and why.
    Skip(String),
}

impl GateRequest {
    /// The gate of a suite run with `options` and an optional `--baseline`: the committed baselines
    /// cover the default configuration (the workspace's `configs/`, with its scenarios, the
    /// real-mesh suite `configs/real-meshes` or the dataset's smoke set `configs/dataset-smoke`);
    /// any other run is compared only with a baseline named on purpose.
    pub fn for_suite(options: &SuiteOptions, baseline: Option<PathBuf>) -> GateRequest {
        let default_configs = match crate::paths::project_root() {
            Ok(root) => root.join("configs"),
            Err(e) => return GateRequest::Skip(format!("no project files to compare with: {e}")),
        };
        let same = |a: &Path, b: &Path| {
            a.canonicalize().ok().zip(b.canonicalize().ok()).is_some_and(|(a, b)| a == b)
        };
        let committed_scenarios = match &options.scenarios_dir {
            None => true,
            Some(dir) => ["real-meshes", "dataset-smoke"].iter().any(|d| same(dir, &default_configs.join(d))),
        };
        if baseline.is_some() {
            GateRequest::Compare(baseline)
        } else if !same(&options.configs_dir, &default_configs) || !committed_scenarios {
            GateRequest::Skip(format!(
                "the committed baselines cover the scenarios of {}, {} and {} (name one with --baseline)",
                default_configs.display(),
                default_configs.join("real-meshes").display(),
                default_configs.join("dataset-smoke").display()
            ))
        } else {
            GateRequest::Compare(None)
        }
    }
}

/// The baseline file `results` are compared with: `baseline` if given, else the committed baseline
/// of their data source among the project files ([`crate::paths::project_files`]).
pub fn baseline_path(baseline: Option<&Path>, results: &[CaseResult]) -> Result<PathBuf, HarnessError> {
    match baseline {
        Some(path) => Ok(path.to_path_buf()),
        None => Ok(BaselineKind::of(results).default_path(&crate::paths::project_root()?)),
    }
}

/// The work of a run after its cases, in the order [`publish`] does it; each is timed as a phase of
/// the run ([`Outcome::phases`]). The methods' own phases are timed per case, before any of these.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunPhase {
    /// The methods' precompute, bind and solve, summed over the cases.
    Methods,
    /// `E_theta` / `E_phi` of the iterates for the convergence curves ([`crate::record::records_quality`]).
    TraceQuality,
    /// The quality measures of the final shapes.
    Evaluation,
    /// open3d's self-intersection check (`--self-intersections`).
    PeerChecks,
    /// results.{json,csv}, convergence.csv, handle_updates.csv, table1.md and the result meshes.
    Reports,
    /// The plots (plots/*.svg, *.png).
    Plots,
    /// The rendered figures (figures/*.png).
    Figures,
    /// The regression gate and index.html.
    GateAndIndex,
}

impl RunPhase {
    /// Every phase, in run order (each at the index of its discriminant).
    pub const ALL: [RunPhase; 8] = [
        RunPhase::Methods,
        RunPhase::TraceQuality,
        RunPhase::Evaluation,
        RunPhase::PeerChecks,
        RunPhase::Reports,
        RunPhase::Plots,
        RunPhase::Figures,
        RunPhase::GateAndIndex,
    ];

    /// Label printed at the end of a run.
    pub fn label(self) -> &'static str {
        match self {
            RunPhase::Methods => "methods (precompute + bind + solve)",
            RunPhase::TraceQuality => "E_theta/E_phi of the iterates",
            RunPhase::Evaluation => "quality of the results",
            RunPhase::PeerChecks => "self-intersections (open3d)",
            RunPhase::Reports => "reports and result meshes",
            RunPhase::Plots => "plots",
            RunPhase::Figures => "figures",
            RunPhase::GateAndIndex => "regression gate and index.html",
        }
    }
}

/// How [`publish`] writes a run.
#[derive(Clone, Debug, Default)]
pub struct PublishOptions {
    /// The cross-check Python with open3d, when the self-intersection check was asked for.
    pub peer_python: Option<PathBuf>,
    /// Which result meshes to write, in which format.
    pub meshes: MeshOutput,
}

/// What a published run came to.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The regression gate's findings, or why it did not compare.
    pub gate: GateOutcome,
    /// Our ARAP against libigl's (Markdown, as in `peers.md`), empty without the peers.
    pub arap_against_libigl: String,
    /// Cases whose status is `suspect`.
    pub suspect: usize,
    /// Cases whose status is `unfinished` (stopped at their iteration cap).
    pub unfinished: usize,
    /// Cases whose status is `failed`.
    pub failed: usize,
    /// Wall seconds of each phase of the run ([`RunPhase::ALL`] order; a phase that did not run
    /// is 0).
    pub phases: Vec<(RunPhase, f64)>,
}

/// Check the results of `run` with open3d when asked, write every report, the plots and figures
/// under `options.reports_dir`, compare with the baseline `gate` asks for and write index.html.
/// Errors: a report that cannot be written, an unreadable baseline, a failed peer check.
pub fn publish(
    options: &SuiteOptions,
    run: &mut SuiteRun,
    publish: &PublishOptions,
    gate: GateRequest,
) -> Result<Outcome, HarnessError> {
    let dir = &options.reports_dir;
    let mut clock = PhaseClock::after_the_cases(&run.results);
    clock.time(RunPhase::PeerChecks, || check_self_intersections(run, publish))?;
    let reports = clock.time(RunPhase::Reports, || write_reports(dir, run, publish))?;
    let mut images = clock.time(RunPhase::Plots, || plots::write_plots(dir, &run.results))?;
    images
        .extend(clock.time(RunPhase::Figures, || render::write_figures(dir, &run.results, &run.scenarios))?);
    let gate = clock.time(RunPhase::GateAndIndex, || {
        let gate = gate_outcome(gate, &run.results)?;
        write_page(dir, run, &reports, &images, &gate)?;
        Ok::<_, HarnessError>(gate)
    })?;
    Ok(Outcome {
        gate,
        arap_against_libigl: peer_comparison::document(&reports.peers).to_markdown(),
        suspect: run.results.iter().filter(|r| r.status.is_suspect()).count(),
        unfinished: run.results.iter().filter(|r| r.status.is_unfinished()).count(),
        failed: run.results.iter().filter(|r| r.status.is_failed()).count(),
        phases: clock.phases(),
    })
}

/// The wall seconds of each phase of a run ([`RunPhase::ALL`] order).
struct PhaseClock {
    seconds: [f64; RunPhase::ALL.len()],
}

impl PhaseClock {
    /// The phases the cases timed themselves: the methods', the iterates' quality, the evaluation.
    fn after_the_cases(results: &[CaseResult]) -> PhaseClock {
        let mut seconds = [0.0; RunPhase::ALL.len()];
        seconds[RunPhase::Methods as usize] = results.iter().map(method_seconds).sum();
        seconds[RunPhase::TraceQuality as usize] = results.iter().map(|r| r.overhead.trace_quality_s).sum();
        seconds[RunPhase::Evaluation as usize] = results.iter().map(|r| r.overhead.evaluation_s).sum();
        PhaseClock { seconds }
    }

    /// Do `work` as `phase`, timed.
    fn time<T>(&mut self, phase: RunPhase, work: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = work();
        self.seconds[phase as usize] = start.elapsed().as_secs_f64();
        out
    }

    fn phases(&self) -> Vec<(RunPhase, f64)> {
        RunPhase::ALL.into_iter().zip(self.seconds).collect()
    }
}

/// open3d's self-intersection answer for every result, when `publish` asks for it.
fn check_self_intersections(run: &mut SuiteRun, publish: &PublishOptions) -> Result<(), HarnessError> {
    let Some(python) = &publish.peer_python else { return Ok(()) };
    let answers = self_intersection::self_intersections(python, &run.results, &run.scenarios)
        .map_err(|e| HarnessError::Report(format!("self-intersection check (open3d): {e}")))?;
    for (r, answer) in run.results.iter_mut().zip(answers) {
        r.self_intersecting = answer;
    }
    Ok(())
}

/// What the reports written before the page hand on to it.
struct WrittenReports {
    /// Our ARAP against libigl's (`peers.md`).
    peers: Table,
    /// `dataset.md` (empty: not written).
    dataset: Document,
    /// `size-series.md` (empty: not written).
    size_series: Document,
    /// The case file stems that open in the 3D view.
    viewable: Vec<String>,
}

/// Write the tables, the result meshes and the 3D view's files, `pareto.md`, `dataset.md` and
/// `size-series.md` of `run` under `dir`.
fn write_reports(
    dir: &Path,
    run: &SuiteRun,
    publish: &PublishOptions,
) -> Result<WrittenReports, HarnessError> {
    let peers = peer_comparison::table(&peer_comparison::arap_against_libigl(&run.results, &run.scenarios));
    report::write_reports(
        dir,
        &run.results,
        &run.scenarios,
        &run.data_source,
        &run.provenance,
        &run.skipped,
        &peer_comparison::document(&peers),
        &publish.meshes,
    )?;
    let viewable = report::viewer::write_viewer_data(dir, &run.results, &run.scenarios, |s| {
        publish.meshes.every_scenario || s.writes_result_meshes()
    })?;
    report::quality_time::write_markdown(dir, &run.results)?;
    let dataset = report::dataset::document(&run.results, &run.skipped);
    if !dataset.is_empty() {
        dataset.write_markdown(&dir.join("dataset.md"))?;
    }
    let size_series = report::size_series::document(&run.results, &run.scenarios);
    if !size_series.is_empty() {
        size_series.write_markdown(&dir.join("size-series.md"))?;
    }
    Ok(WrittenReports { peers, dataset, size_series, viewable })
}

/// The regression gate's verdict on `results`, or why it did not compare.
fn gate_outcome(gate: GateRequest, results: &[CaseResult]) -> Result<GateOutcome, HarnessError> {
    match gate {
        GateRequest::Compare(baseline) => {
            regression::gate(&baseline_path(baseline.as_deref(), results)?, results)
        }
        GateRequest::Skip(reason) => Ok(GateOutcome::NotChecked(reason)),
    }
}

/// Write `index.html` of `run` under `dir`: its reports, its `images` and the `gate`'s verdict.
fn write_page(
    dir: &Path,
    run: &SuiteRun,
    reports: &WrittenReports,
    images: &[Image],
    gate: &GateOutcome,
) -> Result<PathBuf, HarnessError> {
    let table1 = report::table1(&run.results);
    let page = html::render_index(&html::PageContext {
        results: &run.results,
        data_source: &run.data_source,
        provenance: &run.provenance.summary(),
        images,
        table1: &table1,
        peers: &reports.peers,
        gate,
        notes: &run.notes,
        scenarios: &run.scenarios,
        skipped: &run.skipped,
        viewable: &reports.viewable,
        dataset: &reports.dataset,
        size_series: &reports.size_series,
    });
    html::write_index(dir, &page)
}

/// Write part `shard` of a run (`run` holds that part's cases): `results.json` and every result
/// mesh (OFF, full precision), what `harness merge` needs. Returns the number of failed cases.
pub fn publish_partial(options: &SuiteOptions, run: &SuiteRun, shard: Shard) -> Result<usize, HarnessError> {
    report::write_partial(
        &options.reports_dir,
        &run.results,
        &run.scenarios,
        &run.data_source,
        &run.provenance,
        &run.skipped,
        shard,
    )?;
    Ok(run.results.iter().filter(|r| r.status.is_failed()).count())
}

/// Compare the `results.json` in `reports_dir` with the baseline (`baseline`, or the committed one of
/// its data source). Errors: no results, no such baseline, or a baseline of other data.
pub fn check(reports_dir: &Path, baseline: Option<&Path>) -> Result<GateOutcome, HarnessError> {
    let results_path = reports_dir.join("results.json");
    let results = crate::stored_report::read_results(&results_path)?.cases;
    let path = baseline_path(baseline, &results)?;
    if !path.is_file() {
        return Err(HarnessError::Config { path, message: "no such baseline".into() });
    }
    match regression::gate(&path, &results)? {
        GateOutcome::NotChecked(reason) => Err(HarnessError::Config { path: results_path, message: reason }),
        checked => Ok(checked),
    }
}

/// Rewrite the baseline (`baseline`, or the committed one of the data source) from the
/// `results.json` in `reports_dir`; returns the path written and the number of cases.
pub fn write_baseline(reports_dir: &Path, baseline: Option<&Path>) -> Result<(PathBuf, usize), HarnessError> {
    let results = crate::stored_report::read_results(&reports_dir.join("results.json"))?.cases;
    let new = regression::baseline_from(&results);
    let path = baseline_path(baseline, &results)?;
    regression::write_baseline(&path, &new)?;
    Ok((path, new.cases.len()))
}

/// Seconds a case's method spent in its own phases (precompute, every bind and solve); 0 for a case
/// that failed before any was timed.
fn method_seconds(r: &CaseResult) -> f64 {
    let bind: f64 = r.steps.iter().map(|s| s.bind_s).sum();
    [r.precompute_s, bind, r.solve_s].into_iter().filter(|t| t.is_finite()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_phase_sits_at_its_own_index_with_its_own_label() {
        for (i, phase) in RunPhase::ALL.into_iter().enumerate() {
            assert_eq!(phase as usize, i, "{phase:?}");
        }
        let mut labels: Vec<&str> = RunPhase::ALL.iter().map(|p| p.label()).collect();
        labels.sort_unstable();
        labels.dedup();
        assert_eq!(labels.len(), RunPhase::ALL.len(), "labels repeat");
    }
}
