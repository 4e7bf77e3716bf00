//! Everything the harness writes for people to read: the result tables and meshes ([`tables`]),
//! the plots ([`plots`]), our `arap` against libigl's ([`peer_comparison`]), two runs compared ([`run_comparison`]), the pictures ([`render`]), the HTML page ([`html`]) and the font they
//! share ([`fonts`]). Each writer renders in memory first and writes its files atomically.

pub mod fonts;
pub mod html;
pub mod peer_comparison;
pub mod plots;
pub mod render;
pub mod run_comparison;
pub mod tables;

pub use tables::*;
