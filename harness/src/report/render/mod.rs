//! Rendered figures of the report: a small software z-buffer rasterizer (no display, no GPU) and the
//! figure writer ([`write_figures`]).
//!
//! - Projection: orthographic. Every figure of a scenario (its rest shape and every method's result)
//!   is seen by one [`Camera`] looking from [`VIEW_FROM`] (front left, above; `+z` up, the axis the
//!   survey meshes stand on), framed on the union of the bounding boxes of the rest shape and all
//!   results, so shapes are comparable across a row and nothing is cut off. The direction is fixed
//!   rather than fitted per mesh because one oblique direction shows all four survey edits: the bar's
//!   twist about `z`, the cylinder's bend in the `xz` plane, the cactus' bend in the `yz` plane and
//!   the plane's lifted strip.
//! - Shading: Lambert with a little ambient, lit by a headlight raised slightly above the eye; both
//!   sides of a face are lit (the side facing the eye), since survey meshes can be open. Per-pixel
//!   interpolated vertex normals except across creases (the bar's edges stay sharp); 2 x 2
//!   supersampling.
//! - Colours: vertex roles (fixed blue, handle orange, free light grey, nearest corner per pixel so
//!   region borders stay crisp) or the per-vertex angle error ([`vertex_angle_errors`]) on the fixed
//!   scale `0..`[`HEAT_MAX_DEG`] degrees, interpolated across faces.
//! - Same inputs, byte-identical PNGs: rendering is sequential per image and the encoder is fixed.

mod camera;
mod canvas;
mod figures;
mod glyphs;
mod heat;
mod raster;
mod shade;
mod text;

pub use camera::{union_bbox, Camera, VIEW_FROM, VIEW_UP};
pub use canvas::RgbImage;
pub use figures::{write_figures, CELL_SIZE};
pub use heat::{heat_color, vertex_angle_errors, HEAT_MAX_DEG};
pub use raster::{rasterize, Fragments};
pub use shade::{render, Paint, VertexRole, SUPERSAMPLING};
