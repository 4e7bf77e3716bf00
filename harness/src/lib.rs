//! The deformbench harness: scenarios and method parameters from `configs/`, running every method
//! through its phases with timings, quality metrics, and reports in `reports/`.
//!
//! The modules form a stack: each imports only from its own layer or the layers below it, never
//! from one above (`scripts/check-imports` checks this list against the code, with no circles).
//! Top to bottom:
//!
//! ```text
//! cli, method_check              the command line: parse, print, exit codes; `check-method`
//! history/                       results across commits: store, timelines and steps, page, worktree runs
//! pipeline                       publish a run: reports, plots, figures, gate, the page, in one directory
//! report/                        the files people read, from records: tables, plots, pictures, page
//! comparison                     two stored runs compared, case by case
//! suite                          load a run's inputs, schedule its cases (jobs, shards), merge parts
//! labelled                       the labelled verdict set: results of known truth judged by the rules
//! case, self_intersection        run one case through its phases; open3d's check of a result
//! stored_report, regression, pareto   records on disk (results.json), the gate, the fronts
//! record, provenance             the run's record: what each case measured; where and how it ran
//! config, scenario, shard, sweep, metrics, verdict, step_trend   what a run is made of, measures,
//!                                verdict rules, why an iteration did not finish (the last three
//!                                re-exports of the `measures` crate)
//! paths, error, threads, variables, memory, staged_dir   the workspace, errors, threads, ${VAR},
//!                                RSS, a directory replaced whole
//! ```

pub mod case;
pub mod cli;
pub mod comparison;
pub mod config;
pub mod error;
pub mod history;
pub mod labelled;
pub mod memory;
pub mod method_check;
pub mod metrics;
pub mod pareto;
pub mod paths;
pub mod pipeline;
pub mod provenance;
pub mod record;
pub mod regression;
pub mod report;
pub mod scenario;
pub mod self_intersection;
pub mod shard;
pub mod staged_dir;
pub mod step_trend;
pub mod stored_report;
pub mod suite;
pub mod sweep;
pub mod threads;
pub mod variables;
pub mod verdict;

pub use error::HarnessError;
