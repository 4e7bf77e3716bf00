//! Why an iteration did not finish, read from its step sequence: in the `measures` crate, re-exported
//! here under the harness's `crate::step_trend` paths.

pub use measures::step_trend::*;
