//! What each pixel saw, for the image's `surface` layer
//! ([`schemas::image::PixelSurfaces`]): the object and material most of
//! its camera samples hit, whether they all hit that one surface's front
//! face (no silhouette, miss or back face inside the pixel), and whether
//! it emits. `compare` uses it to report errors per object and material
//! and to leave out emitters and edges.

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

/// The camera samples of one pixel, counted per surface.
#[derive(Clone, Debug, Default)]
pub struct PixelTally {
    /// `(surface, front-face hits)` in order of first hit.
    hits: Vec<(SurfaceId, u32)>,
    /// Samples that missed or hit a back face.
    other: u32,
}

impl PixelTally {
    /// A sample that hit the front face of `surface`.
    pub fn front(&mut self, surface: SurfaceId) {
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
    /// when it took every sample, [`EMITTER`] when it emits.
    pub fn finish(&self) -> [u32; 3] {
        let best = self.hits.iter().max_by(|(a, m), (b, n)| m.cmp(n).then((b.object, b.material).cmp(&(a.object, a.material))));
        match best {
            None => [NO_SURFACE, NO_SURFACE, 0],
            Some((s, _)) => {
                let single = if self.hits.len() == 1 && self.other == 0 { SINGLE_SURFACE } else { 0 };
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

    #[test]
    fn one_surface_everywhere_is_single() {
        let mut t = PixelTally::default();
        (0..4).for_each(|_| t.front(LAMP));
        assert_eq!(t.finish(), [5, 0, SINGLE_SURFACE | EMITTER]);
    }

    #[test]
    fn majority_wins_and_mixed_pixels_are_not_single() {
        let mut t = PixelTally::default();
        t.front(LAMP);
        t.front(WALL);
        t.front(WALL);
        assert_eq!(t.finish(), [2, 1, 0]);
        // A tie goes to the smaller (object, material).
        t.front(LAMP);
        assert_eq!(t.finish(), [2, 1, 0]);
        let mut edge = PixelTally::default();
        edge.front(WALL);
        edge.other();
        assert_eq!(edge.finish(), [2, 1, 0]);
        let mut miss = PixelTally::default();
        miss.other();
        assert_eq!(miss.finish(), [NO_SURFACE, NO_SURFACE, 0]);
    }
}
