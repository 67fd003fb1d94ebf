//! What each pixel saw, for the image's `surface` layer
//! ([`schemas::image::PixelSurfaces`]): the object and material most of
//! its camera samples hit, whether they all hit that one surface's front
//! face (no silhouette, miss or back face inside the pixel, and no crease:
//! every hit normal within the crease angle of the first, so the edge
//! between two faces of one block counts as an edge while a finely
//! tessellated curved surface does not), and whether it emits. `compare` uses it to report errors per object and material
//! and to leave out emitters and edges.

use glam::DVec3;
use schemas::image::{PixelSurfaces, EMITTER, NO_SURFACE, SINGLE_SURFACE};
use schemas::mesh::{Manifest, Mesh};

/// The surface a triangle belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceId {
    /// Index into the manifest's objects.
    pub object: u32,
    /// Index into the manifest's materials.
    pub material: u32,
    /// Whether the material's exitance is > 0 in some channel.
    pub emits: bool,
}

/// Per triangle of `mesh`, its [`SurfaceId`].
pub fn surface_ids(mesh: &Mesh, manifest: &Manifest) -> Vec<SurfaceId> {
    mesh.triangles
        .iter()
        .map(|t| SurfaceId {
            object: t.object,
            material: t.material,
            emits: manifest.materials.get(t.material as usize).is_some_and(|m| m.emission.iter().any(|&e| e > 0.0)),
        })
        .collect()
}

/// `[object, material, flags]` of a pixel no sample hit.
pub const NOTHING: [u32; 3] = [NO_SURFACE, NO_SURFACE, 0];

/// The camera samples of one pixel, counted per surface.
#[derive(Clone, Debug)]
pub struct PixelTally {
    /// Cosine of the crease angle: hit normals further apart make an edge.
    crease_cos: f64,
    /// `(surface, front-face hits)` in order of first hit.
    hits: Vec<(SurfaceId, u32)>,
    /// The first hit's normal.
    first_normal: Option<DVec3>,
    /// Whether some hit's normal is further than the crease angle from it.
    creased: bool,
    /// Samples that missed or hit a back face.
    other: u32,
}

impl PixelTally {
    /// An empty tally; normals more than `crease_angle_deg` apart make an edge.
    pub fn new(crease_angle_deg: f64) -> Self {
        PixelTally { crease_cos: crease_angle_deg.to_radians().cos(), hits: Vec::new(), first_normal: None, creased: false, other: 0 }
    }

    /// A sample that hit the front face of `surface`, of unit normal `normal`.
    pub fn front(&mut self, surface: SurfaceId, normal: DVec3) {
        match self.first_normal {
            None => self.first_normal = Some(normal),
            Some(first) => self.creased |= first.dot(normal) < self.crease_cos,
        }
        match self.hits.iter_mut().find(|(s, _)| *s == surface) {
            Some((_, n)) => *n += 1,
            None => self.hits.push((surface, 1)),
        }
    }

    /// A sample that missed, or hit a back face.
    pub fn other(&mut self) {
        self.other += 1;
    }

    /// `[object, material, flags]`: the surface with the most front-face
    /// hits (ties: the smaller `(object, material)`), [`SINGLE_SURFACE`]
    /// when it took every sample with no crease between them, [`EMITTER`]
    /// when it emits.
    pub fn finish(&self) -> [u32; 3] {
        let best = self.hits.iter().max_by(|(a, m), (b, n)| m.cmp(n).then((b.object, b.material).cmp(&(a.object, a.material))));
        match best {
            None => NOTHING,
            Some((s, _)) => {
                let single = if self.hits.len() == 1 && self.other == 0 && !self.creased { SINGLE_SURFACE } else { 0 };
                [s.object, s.material, single | if s.emits { EMITTER } else { 0 }]
            }
        }
    }
}

/// Collects [`PixelTally::finish`] results, row-major, into the layer.
pub fn collect(pixels: impl IntoIterator<Item = [u32; 3]>) -> PixelSurfaces {
    let mut out = PixelSurfaces::default();
    for [object, material, flags] in pixels {
        out.object.push(object);
        out.material.push(material);
        out.flags.push(flags);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const WALL: SurfaceId = SurfaceId { object: 2, material: 1, emits: false };
    const LAMP: SurfaceId = SurfaceId { object: 5, material: 0, emits: true };

    const UP: DVec3 = DVec3::Z;

    #[test]
    fn one_surface_everywhere_is_single() {
        let mut t = PixelTally::new(30.0);
        (0..4).for_each(|_| t.front(LAMP, UP));
        assert_eq!(t.finish(), [5, 0, SINGLE_SURFACE | EMITTER]);
    }

    #[test]
    fn majority_wins_and_mixed_pixels_are_not_single() {
        let mut t = PixelTally::new(30.0);
        t.front(LAMP, UP);
        t.front(WALL, UP);
        t.front(WALL, UP);
        assert_eq!(t.finish(), [2, 1, 0]);
        // A tie goes to the smaller (object, material).
        t.front(LAMP, UP);
        assert_eq!(t.finish(), [2, 1, 0]);
        let mut edge = PixelTally::new(30.0);
        edge.front(WALL, UP);
        edge.other();
        assert_eq!(edge.finish(), [2, 1, 0]);
        let mut miss = PixelTally::new(30.0);
        miss.other();
        assert_eq!(miss.finish(), NOTHING);
    }

    #[test]
    fn creases_are_edges_smooth_bends_are_not() {
        let tilted = |deg: f64| DVec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        let mut smooth = PixelTally::new(30.0);
        smooth.front(WALL, UP);
        smooth.front(WALL, tilted(29.0));
        assert_eq!(smooth.finish(), [2, 1, SINGLE_SURFACE]);
        let mut crease = PixelTally::new(30.0);
        crease.front(WALL, UP);
        crease.front(WALL, tilted(31.0));
        assert_eq!(crease.finish(), [2, 1, 0]);
    }
}
