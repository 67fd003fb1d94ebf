//! What the full and brute-force gathers record of their work: per camera
//! sample ([`Work`]), per pixel and per built grid vertex (the
//! `--diagnostics` artifact, [`schemas::diagnostics::Diagnostics`]), and
//! the report's counters.

use crate::classification::LinkClass;
use crate::full_gather::FullGather;
use crate::specular::Followed;
use schemas::diagnostics::{Diagnostics, VertexRecord};
use std::collections::BTreeMap;

/// Work done for one camera sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Work {
    /// Visibility rays cast.
    pub visibility_rays: u64,
    /// Form-factor evaluations.
    pub form_factors: u64,
    /// Sender contributions per class ([`LinkClass::index`]; in the grid
    /// gather the class at the heaviest vertex).
    pub classes: [u64; 4],
    /// 1 when the surface-based gather shaded the sample.
    pub surface: u64,
    /// 1 when the sample's irradiance was interpolated on the lattice
    /// ([`crate::lattice`]).
    pub interpolated: u64,
}

impl Work {
    /// Adds `o` to `self`.
    pub fn add(&mut self, o: &Work) {
        self.visibility_rays += o.visibility_rays;
        self.form_factors += o.form_factors;
        self.surface += o.surface;
        self.interpolated += o.interpolated;
        for k in 0..4 {
            self.classes[k] += o.classes[k];
        }
    }

    /// Counts one sender contribution of class `class`.
    pub fn count(&mut self, class: LinkClass) {
        self.classes[class.index()] += 1;
    }
}

/// What a full or brute-force image took, as [`record`] reads it.
pub struct Tally<'a> {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Camera samples per pixel.
    pub spp: u32,
    /// Each pixel's work over its camera samples, row-major.
    pub pixels: &'a [Work],
    /// Camera rays that hit a surface.
    pub hits: u64,
    /// Rays continued through mirrors and glass, in a scene that has some.
    pub specular: Option<Followed>,
    /// Points of the irradiance lattice, where the gather has one.
    pub lattice_points: Option<u64>,
}

/// The diagnostics and the report's counters of an image whose work was
/// `tally`, gathered with `gather`'s vertices and leaf checks.
pub fn record(tally: &Tally, gather: &FullGather) -> (Diagnostics, BTreeMap<String, f64>) {
    let (width, height, spp) = (tally.width, tally.height, tally.spp);
    let mut d = Diagnostics { width: width as usize, height: height as usize, ..Diagnostics::default() };
    let mut total = Work::default();
    let per = 1.0 / f64::from(spp);
    for work in tally.pixels {
        d.visibility_rays.push((work.visibility_rays as f64 * per) as f32);
        d.form_factors.push((work.form_factors as f64 * per) as f32);
        for c in 0..4 {
            d.classes[c].push((work.classes[c] as f64 * per) as f32);
        }
        d.surface.push((work.surface as f64 * per) as f32);
        total.add(work);
    }
    let grid = gather.grid;
    let (mut class_rays, mut class_factors, mut vertex_classes, mut skipped) = (0u64, 0u64, [0u64; 4], 0u64);
    for (index, data) in gather.built() {
        class_rays += data.rays;
        class_factors += data.factors;
        let counts = data.class_counts();
        (0..4).for_each(|c| vertex_classes[c] += u64::from(counts[c]));
        skipped += u64::from(data.skipped);
        let ijk = grid.vertex_of(index);
        d.vertices.push(VertexRecord {
            ijk: ijk.map(|x| x as u32),
            position: grid.vertex(ijk).as_vec3().to_array(),
            classes: counts,
            skipped: data.skipped,
            contrast: data.contrast as f32,
            rays: data.rays as u32,
            factors: data.factors as u32,
        });
    }
    for check in gather.checked_leaves() {
        class_rays += check.rays;
        class_factors += check.factors;
    }
    let pixels = f64::from(width) * f64::from(height);
    let hits = tally.hits;
    let mut c = BTreeMap::new();
    c.insert("pixels".into(), pixels);
    c.insert("samples_per_pixel".into(), f64::from(spp));
    c.insert("rays_cast".into(), pixels * f64::from(spp) + pixels + tally.lattice_points.unwrap_or(0) as f64);
    c.insert("ray_hits".into(), hits as f64);
    c.insert("visibility_rays".into(), total.visibility_rays as f64);
    c.insert("form_factor_evaluations".into(), total.form_factors as f64);
    c.insert("visibility_rays_per_hit".into(), total.visibility_rays as f64 / hits.max(1) as f64);
    c.insert("form_factors_per_hit".into(), total.form_factors as f64 / hits.max(1) as f64);
    c.insert("surface_gather_hits".into(), total.surface as f64);
    c.insert("classification_visibility_rays".into(), class_rays as f64);
    c.insert("classification_form_factors".into(), class_factors as f64);
    c.insert("grid_vertices".into(), grid.vertex_count() as f64);
    c.insert("grid_vertices_built".into(), d.vertices.len() as f64);
    c.insert("senders_skipped_occluded".into(), skipped as f64);
    if let Some(points) = tally.lattice_points {
        c.insert("lattice_points".into(), points as f64);
        c.insert("samples_interpolated".into(), total.interpolated as f64);
    }
    if let Some(specular) = tally.specular {
        crate::specular::count(&mut c, specular);
    }
    for class in LinkClass::ALL {
        let k = class.index();
        c.insert(format!("vertex_senders_{}", class.name()), vertex_classes[k] as f64);
        c.insert(format!("pixel_senders_{}", class.name()), total.classes[k] as f64);
    }
    (d, c)
}
