//! The full final gather of paper 000 (Sec. 4-5): its state, the lazily
//! built grid vertices and leaf checks, and the choice at a surface point
//! between the grid's interpolation and the surface-based gather.
//!
//! One section of the paper per file:
//!
//! - the grid (Sec. 4.2): [`crate::grid`];
//! - sender classification at a grid vertex (Sec. 4.3, Eq. 1-3, Fig. 2):
//!   [`crate::classification`];
//! - interpolation at a pixel (Sec. 4.4): [`crate::interpolation`];
//! - the surface-based gather where the solver's leaves are finer than
//!   the grid (Sec. 4.5): [`crate::surface_gather`];
//! - the contrast threshold, from the mask (Sec. 5.2) or the `contrast`
//!   parameter, per vertex and at a point: [`crate::contrast`];
//! - view-dependent shadow sample counts (Sec. 5.3):
//!   [`crate::shadow_samples`];
//! - the brute-force gather it is measured against: [`crate::brute`];
//! - beyond the paper, the image lattice that gathers once per lattice
//!   point and interpolates to the camera samples: [`crate::lattice`].
//!
//! # Kernel-weighted visibility
//!
//! Every visibility this gather estimates from a receiver point `p` with
//! normal `n_p` (the brute force, the resampled senders at render time, the
//! leaf checks; the vertex classification with `n_p` facing the sender) is
//! the one that makes `F(p) V` the occluded irradiance factor:
//!
//! ```text
//! V(p) = integral G(p, y) v(p, y) dA_y / integral G(p, y) dA_y
//!      ~ sum_k G(p, y_k) v_k / sum_k G(p, y_k),
//! G(p, y) = cos+(theta_p) cos+(theta_y) / d²        (radiometry's point_kernel)
//! ```
//!
//! over the sender samples `y_k` (uniform by area). The plain visible
//! fraction weights a sample behind `p`'s plane like one in front; where the
//! sender crosses that plane (the lamp, floor and walls of the Cornell box
//! cross the planes of the blocks' faces) the rays to the samples behind run
//! through the receiver's own body and are blocked, although they carry no
//! light: the blocks came out 7% to 20% too dark. Samples of zero weight
//! cast no ray. Where no sample has weight, no ray says anything about the
//! part of the sender that lights `p`, and `V = 1` (the solver's rule:
//! such support is a sliver of the sender at a contact, where nothing lies
//! between); the leaf check then keeps the link's value.

use crate::classification::VertexData;
use crate::diagnostics::Work;
use crate::grid::Grid;
use crate::senders::{SenderSample, Senders};
use crate::surface_gather::LeafCheck;
use crate::Params;
use glam::DVec3;
use radiometry::form_factor::{point_kernel, WeightedVisibility};
use radiometry::rays::SceneRays;
use schemas::solution::{Node, NONE};
use std::sync::OnceLock;

/// Per-triangle material: reflectance and emitted radiosity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Diffuse reflectance, RGB.
    pub reflectance: [f64; 3],
    /// Emitted radiosity, W/m², RGB.
    pub emission: [f64; 3],
}

/// The gather's state: the solution, the grid and its lazily built
/// vertices.
pub struct FullGather<'a> {
    /// The solution, indexed.
    pub senders: &'a Senders<'a>,
    /// The grid.
    pub grid: &'a Grid,
    /// Rays over the scene.
    pub rays: &'a SceneRays,
    /// Material per triangle.
    pub surfaces: &'a [Surface],
    /// Parameters.
    pub params: &'a Params,
    /// Contrast threshold per vertex ([`crate::contrast::vertex_contrast`]).
    pub vertex_contrast: Vec<f64>,
    /// Image width, pixels (for penumbra sizes on screen).
    pub width: u32,
    vertices: Vec<OnceLock<VertexData>>,
    leaves: Vec<OnceLock<LeafCheck>>,
}

impl<'a> FullGather<'a> {
    /// A gather over `senders` with `grid`; `vertex_contrast` gives every
    /// vertex's contrast threshold.
    pub fn new(
        senders: &'a Senders<'a>,
        grid: &'a Grid,
        rays: &'a SceneRays,
        surfaces: &'a [Surface],
        params: &'a Params,
        vertex_contrast: Vec<f64>,
        width: u32,
    ) -> Self {
        let vertices = (0..grid.vertex_count()).map(|_| OnceLock::new()).collect();
        let leaves = (0..senders.solution.elements.len()).map(|_| OnceLock::new()).collect();
        FullGather { senders, grid, rays, surfaces, params, vertex_contrast, width, vertices, leaves }
    }

    /// The checked leaves' checks.
    pub fn checked_leaves(&self) -> impl Iterator<Item = &LeafCheck> {
        self.leaves.iter().filter_map(OnceLock::get)
    }

    /// The built vertices: `(index, data)`.
    pub fn built(&self) -> impl Iterator<Item = (usize, &VertexData)> {
        self.vertices.iter().enumerate().filter_map(|(i, v)| v.get().map(|d| (i, d)))
    }

    /// Vertex `index`'s data, classified on first use.
    pub fn vertex(&self, index: usize) -> &VertexData {
        self.vertices[index].get_or_init(|| self.classify(index))
    }

    /// Leaf `leaf`'s check, made on first use by `check`.
    pub(crate) fn leaf(&self, leaf: u32, check: impl FnOnce() -> LeafCheck) -> &LeafCheck {
        self.leaves[leaf as usize].get_or_init(check)
    }

    /// Irradiance H at `p` (W/m², RGB) on `triangle` (front normal
    /// `normal`, in leaf element `leaf`) from the links in `links`, for
    /// camera sample `pass` of its pixel: by the surface-based gather where
    /// the leaf is smaller than the grid's cells at `p` (and the
    /// `surface_gather` parameter is on) and on a leaf the solver found
    /// wholly buried (whose links' visibility says nothing of `p`, which
    /// that gather then resamples, [`crate::surface_gather`]), else by the
    /// grid; 0 outside the grid.
    #[allow(clippy::too_many_arguments)]
    pub fn irradiance(&self, p: DVec3, normal: DVec3, triangle: u32, leaf: u32, links: &[usize], pass: u32, work: &mut Work) -> [f64; 3] {
        let Some(location) = self.grid.locate(p) else { return [0.0; 3] };
        let contrast = self.contrast_at(&location);
        let leaf_size = self.senders.size(Node::Element(leaf));
        if (self.params.surface_gather && leaf_size < self.grid.spacing_at(p)) || self.senders.exposure(leaf) <= 0.0 {
            return self.surface_irradiance(p, normal, triangle, leaf, links, contrast, pass, work);
        }
        self.interpolated_irradiance(p, normal, triangle, &location, links, pass, work)
    }

    /// Visible fraction from `p` on triangle `triangle` of `n` fixed
    /// samples of `node`: block `pass` of the sender's sequence, samples
    /// `pass n .. (pass + 1) n`. Camera sample `pass` of every pixel uses
    /// the same block, so each sub-image is continuous (fixed positions,
    /// Sec. 4.4.1), while a pixel's `spp` camera samples together see the
    /// first `spp n` points of the sequence rather than the same `n` again.
    /// Kernel-weighted (module docs, with `p`'s normal `normal`). Adds the
    /// rays to `work`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn fixed_visibility(&self, p: DVec3, normal: DVec3, triangle: u32, node: Node, n: u32, pass: u32, work: &mut Work) -> f64 {
        if n == 0 {
            return 1.0;
        }
        let mut visible = WeightedVisibility::default();
        let first = pass as usize * n as usize;
        let samples = self.senders.samples(node);
        for k in first..first + n as usize {
            let y = samples.at(k);
            let weight = self.sample_weight(p, normal, y);
            if weight > 0.0 {
                work.visibility_rays += 1;
                visible.add(weight, self.rays.segment_clear(p, y.point, [triangle, y.triangle]));
            }
        }
        visible.fraction().unwrap_or(1.0)
    }

    /// The kernel between `p` (unit normal `normal`) and sender sample `y`
    /// ([`sample_weight`]).
    pub(crate) fn sample_weight(&self, p: DVec3, normal: DVec3, y: SenderSample) -> f64 {
        sample_weight(self.senders, p, normal, y)
    }
}

/// The kernel between `p` (unit normal `normal`) and the sender sample `y`
/// ([`point_kernel`], with the normal of `y`'s triangle); 0 for a sample on
/// no triangle (an empty cluster's centre).
pub(crate) fn sample_weight(senders: &Senders, p: DVec3, normal: DVec3, y: SenderSample) -> f64 {
    if y.triangle == NONE {
        return 0.0;
    }
    point_kernel(p, normal, y.point, senders.triangles[y.triangle as usize].normal)
}
