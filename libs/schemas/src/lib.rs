//! # schemas: the file contracts between the pipeline's stages
//!
//! Every file that passes between two stages is defined here, and nowhere
//! else: the serde types of the RON artifacts (manifest, reports,
//! parameters), the layers and channels of the EXR artifacts (mesh,
//! solution, images), their schema names and versions, and the provenance
//! every artifact carries. Readers check the format tag and the version
//! before anything else; writers are atomic and deterministic.
//!
//! | artifact | file | schema | written by |
//! |---|---|---|---|
//! | [`mesh::Mesh`] | `mesh.exr` | `mesh` 1 | mesh-prep |
//! | [`mesh::Manifest`] | `manifest.ron` | `manifest` 1 | mesh-prep |
//! | [`cluster::Clusters`] | `clusters.exr` | `clusters` 1 | cluster |
//! | [`solution::Solution`] | `solution.exr` | `solution` 1 | hierarchical-solve, gpu-shoot |
//! | [`lightmap::Lightmap`] | `lightmap.exr` | `lightmap` 1 | gpu-shoot |
//! | [`lightmap::Convergence`] | `convergence.ron` | `convergence` 1 | gpu-shoot |
//! | [`image::HdrImage`] | `*.exr` | `image` 2 | grid-gather (read also from foreign EXRs) |
//! | [`threshold::ThresholdImage`] | `threshold.exr` | `threshold` 1 | mask |
//! | [`diagnostics::Diagnostics`] | `*.diagnostics.exr` | `gather-diagnostics` 1 | grid-gather (full, brute) |
//! | [`report::Report`] | `*.report.ron` | `report` 1 | every stage |
//!
//! ```
//! use schemas::header::Schema;
//! assert_eq!(schemas::solution::Solution::NAME, "solution");
//! ```

pub mod atomic;
pub mod cluster;
pub mod diagnostics;
pub mod error;
pub mod exr_io;
pub mod header;
pub mod hierarchy;
pub mod image;
pub mod lightmap;
pub mod mesh;
pub mod report;
pub mod ron_io;
pub mod samples;
pub mod solution;
pub mod surface;
pub mod threshold;

pub use error::{Error, Result};
