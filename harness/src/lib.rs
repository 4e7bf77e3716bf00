//! The deformbench harness: scenarios and method parameters from `configs/`, running every method
//! through its phases with timings, quality metrics, and reports in `reports/`.

pub mod case;
pub mod cli;
pub mod comparison;
pub mod config;
pub mod error;
pub mod memory;
pub mod method_check;
pub mod metrics;
pub mod pareto;
pub mod peers;
pub mod pipeline;
pub mod provenance;
pub mod regression;
pub mod report;
pub mod scenario;
pub mod shard;
pub mod suite;
pub mod sweep;
pub mod threads;
pub mod variables;
pub mod verdict;

pub use error::HarnessError;
