//! # radiometry: the math several stages share
//!
//! - [`angle`]: the angle between two vectors from their cross and dot
//!   products, the edge angle of Lambert's factor, without libm's `atan2`.
//! - [`form_factor`]: Lambert's point-to-polygon factor (paper 002 Eq. 3)
//!   and area-averaged element factors by Dunavant quadrature.
//! - [`far_field`]: Lambert's factor of a planar region far from the
//!   point, by a four-point rule exact for quadratics (three points for a
//!   triangle).
//! - [`sampling`]: deterministic per-work-item random streams, stratified
//!   points on triangles, the radical inverse, the Sobol (0,2)-sequence
//!   and Owen-scrambled Sobol points in four dimensions.
//! - [`bounds`]: axis-aligned boxes.
//! - [`burial`]: whether a surface point lies inside a closed solid.
//! - [`subdivision`]: the 1:4 element subdivision rule and point location.
//! - [`geometry`]: triangle corners, normals and areas in f64.
//! - [`rays`]: ray casting over obvhs's CWBVH.
//! - [`watertight`]: the watertight ray/triangle test (Woop et al. 2013)
//!   the ray caster uses.
//! - [`photometry`]: goniometric point lights: the type C distribution,
//!   its Catmull-Rom lookup and flux, irradiance from a luminaire.
//! - [`texture`]: texture lookups and their exact averages over elements.
//! - [`camera`]: pinhole camera rays.
//! - [`color`]: a colour's luminance and largest channel.
//!
//! Everything here takes data, not paths, never prints, and knows no
//! artifact type: the stage kit's `scene` module turns the prepared
//! scene's artifacts (mesh, camera, lights, textures) into this crate's
//! data.

pub mod angle;
pub mod bounds;
pub mod burial;
pub mod camera;
pub mod color;
pub mod far_field;
pub mod form_factor;
pub mod geometry;
pub mod photometry;
pub mod rays;
pub mod sampling;
pub mod subdivision;
pub mod texture;
pub mod watertight;
