//! Everything the harness writes for people to read: the result tables and meshes ([`tables`]),
//! the plots ([`plots`]), quality against time with the budget tables ([`quality_time`]), our
//! `arap` against libigl's ([`peer_comparison`]), two runs compared ([`run_comparison`]), cost
//! against size on one shape at several sizes ([`size_series`]), the answer across a dataset
//! ([`dataset`]), the pictures ([`render`]), the 3D view's mesh files ([`viewer`]), the HTML page
//! ([`html`]) and the font they share ([`fonts`]). The writers hand on typed tables, images and
//! documents ([`document`]): the `.md` files and the page render the same values, one renderer
//! each. Each writer renders in memory first and writes its files atomically.

pub mod dataset;
pub mod document;
pub mod fonts;
pub mod html;
pub mod peer_comparison;
pub mod plots;
pub mod quality_time;
pub mod render;
pub mod run_comparison;
pub mod size_series;
pub mod tables;
pub mod viewer;

pub use tables::*;
