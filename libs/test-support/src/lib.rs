//! # test-support: the fixtures the workspace's tests share
//!
//! A dev-dependency only: no library or stage ships any of it.
//!
//! - [`closed_form`]: closed-form answers (Howell's catalogue of
//!   configuration factors, Lambert's polygon formula, a triangle
//!   quadrature), written independently of the stages' kernels.
//! - [`scenes`]: scenes written from code as OBJ + MTL + `scene.ron`, for
//!   tests that run the stage binaries.
//! - [`meshes`]: meshes and manifests built in memory, for tests that
//!   solve in process.
//! - [`artifacts`]: small artifacts of every kind, valid by construction
//!   (the seeds of the fuzz targets).
//! - [`gpu`]: a GPU test without a GPU skips, loudly (fails under CI).
//! - [`metrics`]: error measures against a reference.

pub mod artifacts;
pub mod closed_form;
pub mod gpu;
pub mod meshes;
pub mod metrics;
pub mod scenes;
mod vec3;
