//! Deformation methods of deformbench: the [`DeformationMethod`] trait and its registry, the discrete
//! operators and solvers they share, and one module per method.

pub mod arap;
pub mod drive;
pub mod error;
#[cfg(feature = "external")]
pub mod external;
pub mod handles;
pub mod hirm;
pub mod isoline_model;
pub mod isolines;
pub mod keys;
pub mod laplacian;
pub mod laplacian_coordinates;
pub mod linalg;
pub mod method;
pub mod operators;
pub mod params;
pub mod registry;
pub mod rotation_fit;
pub mod scale_aware;
pub mod spectral_mhb;

pub use error::MethodError;
pub use handles::{HandleRegion, HandleSet, HandleTargets};
pub use method::{
    require_phase, DeformationMethod, DistanceBound, IterationObserver, IterationReport, NoObserver, Phase,
    ReusedSolve, SolveSummary, Stopping,
};
