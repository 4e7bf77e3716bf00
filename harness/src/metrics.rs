//! The quality measures of a result against its rest mesh and their table ([`METRICS`]), which the
//! CSV/JSON writers, the printed table, `index.html`, the plots and the regression gate all read.
//! They live in the `measures` crate (computation only, usable without the harness); this module
//! re-exports them under the harness's `crate::metrics` paths.

pub use measures::distance::*;
pub use measures::distortion::*;
pub use measures::evaluation::*;
pub use measures::metric::*;
pub use measures::quality::*;
pub use measures::rest::*;
pub use measures::statistics::percentile;
pub use measures::turn::*;
pub use measures::{evaluate, evaluate_on};
