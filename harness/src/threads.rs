//! The threads of a run (`--threads N`): one rayon pool of N workers in which every case runs, so our
//! methods' parallel loops and faer's kernels (`Par::rayon(0)` follows the pool) use N threads; and
//! the usual thread variables set to N for external programs (OpenMP, OpenBLAS, MKL, libigl). The
//! default is every logical core, shared among the cases that run at a time (`--jobs J`: J pools). `hirm` keeps its background precompute thread (the paper's design,
//! section 4.4) beside the pool.

use crate::error::HarnessError;

/// Workers of a pool are named `deformbench-worker-<i>` (the thread-count test reads the names).
pub const WORKER_NAME: &str = "deformbench-worker";

/// The thread of each of `--jobs J` concurrent cases is `deformbench-job-<j>`; it waits while its
/// pool runs the cases.
pub const JOB_NAME: &str = "deformbench-job";

/// The environment variables that set an external program's thread count.
pub const THREAD_VARIABLES: [&str; 4] =
    ["OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "IGL_NUM_THREADS"];

/// The machine's logical cores (1 when unknown).
pub fn logical_cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The logical cores of the machine shared among `jobs` concurrent cases, at least 1 each.
pub fn default_threads(jobs: usize) -> usize {
    (logical_cores() / jobs.max(1)).max(1)
}

/// A pool of `threads` named workers.
pub fn pool(threads: usize) -> Result<rayon::ThreadPool, HarnessError> {
    if threads == 0 {
        return Err(HarnessError::Report("--threads must be at least 1".into()));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("{WORKER_NAME}-{i}"))
        .build()
        .map_err(|e| HarnessError::Report(format!("thread pool of {threads}: {e}")))
}

/// [`THREAD_VARIABLES`], each `threads`, for an external program's environment.
pub fn external_environment(threads: usize) -> Vec<(String, String)> {
    THREAD_VARIABLES.iter().map(|v| (v.to_string(), threads.to_string())).collect()
}
