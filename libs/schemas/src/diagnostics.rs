//! The diagnostics artifact of grid-gather's full and brute-force gathers
//! (`--diagnostics`, schema `gather-diagnostics` 1), for redrawing paper
//! 000's Figs. 4 and 6: image layer `pixel` (work and sender classes per
//! camera sample), table layer `vertex` (class counts per built grid
//! vertex).

use crate::error::Result;
use crate::exr_io::{write_exr, Channel, ExrArtifact, Layer, LayerKind};
use crate::header::{Header, Schema};
use std::path::Path;

/// The artifact's schema.
pub struct GatherDiagnostics;

impl Schema for GatherDiagnostics {
    const NAME: &'static str = "gather-diagnostics";
    const VERSION: u32 = 1;
}

/// The four sender classes of paper 000 Sec. 4.3: channel name (in the
/// `vertex` layer; `class.` and the name in the `pixel` layer) and meaning.
pub const CLASSES: [(&str, &str); 4] = [
    ("rv_rf", "resample visibility, resample form factor"),
    ("rv_if", "resample visibility, interpolate form factor"),
    ("iv_rf", "interpolate visibility, resample form factor"),
    ("iv_if", "interpolate visibility, interpolate form factor"),
];

/// Per-pixel and per-vertex records of a full or brute-force gather.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Diagnostics {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Visibility rays per camera sample, per pixel.
    pub visibility_rays: Vec<f32>,
    /// Form-factor evaluations per camera sample, per pixel.
    pub form_factors: Vec<f32>,
    /// Senders per camera sample in each class ([`CLASSES`]), per pixel.
    pub classes: [Vec<f32>; 4],
    /// Fraction of camera samples shaded by the surface-based gather.
    pub surface: Vec<f32>,
    /// The built grid vertices.
    pub vertices: Vec<VertexRecord>,
}

/// One built grid vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexRecord {
    /// Grid coordinates.
    pub ijk: [u32; 3],
    /// Position, mesh frame, m.
    pub position: [f32; 3],
    /// Senders per class ([`CLASSES`]).
    pub classes: [u32; 4],
    /// Senders skipped as fully occluded.
    pub skipped: u32,
    /// Contrast threshold used.
    pub contrast: f32,
    /// Visibility rays cast to classify.
    pub rays: u32,
    /// Form-factor evaluations to classify.
    pub factors: u32,
}

impl Diagnostics {
    /// Writes the artifact to `path` with `header` (of schema
    /// [`GatherDiagnostics`]).
    pub fn write(&self, path: &Path, header: Header) -> Result<()> {
        let mut pixel = vec![
            Channel::f32("visibility_rays", "visibility rays per camera sample", self.visibility_rays.clone()),
            Channel::f32("form_factors", "form-factor evaluations per camera sample", self.form_factors.clone()),
            Channel::f32("surface", "fraction of camera samples shaded by the surface-based gather", self.surface.clone()),
        ];
        for (k, (name, _)) in CLASSES.iter().enumerate() {
            pixel.push(Channel::f32(&format!("class.{name}"), "senders per camera sample in this class (000 Sec. 4.3)", self.classes[k].clone()));
        }
        let v = &self.vertices;
        let u = |f: &dyn Fn(&VertexRecord) -> u32| v.iter().map(f).collect::<Vec<u32>>();
        let f = |f: &dyn Fn(&VertexRecord) -> f32| v.iter().map(f).collect::<Vec<f32>>();
        let mut columns = vec![
            Channel::u32("i", "grid vertex x index", u(&|r| r.ijk[0])),
            Channel::u32("j", "grid vertex y index (down the image)", u(&|r| r.ijk[1])),
            Channel::u32("k", "grid vertex depth index", u(&|r| r.ijk[2])),
            Channel::f32("P.X", "position, mesh frame, m", f(&|r| r.position[0])),
            Channel::f32("P.Y", "position, mesh frame, m", f(&|r| r.position[1])),
            Channel::f32("P.Z", "position, mesh frame, m", f(&|r| r.position[2])),
        ];
        for (k, (name, meaning)) in CLASSES.iter().enumerate() {
            columns.push(Channel::u32(name, &format!("senders: {meaning}"), u(&|r| r.classes[k])));
        }
        columns.extend([
            Channel::u32("skipped", "senders skipped: fully occluded by every link", u(&|r| r.skipped)),
            Channel::f32("contrast", "contrast threshold (mask average or parameter)", f(&|r| r.contrast)),
            Channel::u32("rays", "visibility rays cast to classify", u(&|r| r.rays)),
            Channel::u32("factors", "form-factor evaluations to classify", u(&|r| r.factors)),
        ]);
        let vertex = Layer::table("vertex", v.len(), columns);
        let image = Layer { name: "pixel".into(), kind: LayerKind::Image { width: self.width, height: self.height }, channels: pixel };
        write_exr(path, &ExrArtifact { header, layers: vec![image, vertex] })
    }
}
