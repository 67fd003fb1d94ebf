//! Which scenes have an exact image, and their surfaces.
//!
//! Paper 002 (Sec. 2) solves configurations of planar diffuse polygons
//! with no occluder: planar polygonal emitters of constant exitance (Eq.
//! 2-3 are exact for them) and planar diffuse receivers that all see each
//! other whole. This module checks a prepared scene against that, and
//! refuses it naming why otherwise:
//!
//! - every material is plain diffuse (no mirror, glass, transmission,
//!   texture, alpha or normal map) and every light is an emitting surface
//!   (no goniometric light);
//! - every surface (the triangles of one object with one material) is
//!   planar: its triangles share one plane and one front normal;
//! - nothing occludes: every vertex of the scene lies on the front side of
//!   every surface's plane (or in it). The surfaces are then faces of one
//!   convex region seen from inside, and a segment between two of their
//!   points that meets a third surface lies in that surface's plane, where
//!   it carries no light (the kernel's cosine is zero) or meets it on a set
//!   of measure zero. So the form factors need no visibility. This is
//!   sufficient, not necessary: a scene it refuses may still be unoccluded.
//!
//! Lengths are compared with `PLANE_TOLERANCE` times the scene's size,
//! since mesh.exr holds f32 positions.

use glam::DVec3;
use radiometry::bounds::Aabb;
use schemas::mesh::{Manifest, Mesh};

/// Distances to a plane under this fraction of the scene's size count as
/// in the plane (f32 positions carry about 6e-8 of it).
const PLANE_TOLERANCE: f64 = 1e-6;

/// One planar diffuse surface: the triangles of one object with one
/// material.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// The object's name, from the manifest.
    pub object: String,
    /// Object and material indices.
    pub ids: (u32, u32),
    /// Its triangles, mesh frame, counter-clockwise seen from the front.
    pub triangles: Vec<[DVec3; 3]>,
    /// Unit front normal.
    pub normal: DVec3,
    /// Index into [`Configuration::planes`].
    pub plane: usize,
    /// Diffuse reflectance per channel.
    pub reflectance: [f64; 3],
    /// Emitted radiosity (exitance), W/m² per channel.
    pub emission: [f64; 3],
}

impl Surface {
    /// Whether it emits in some channel.
    pub fn emits(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }

    /// Whether it reflects in some channel.
    pub fn reflects(&self) -> bool {
        self.reflectance.iter().any(|&r| r > 0.0)
    }
}

/// A scene that has an exact image: its surfaces and planes.
#[derive(Clone, Debug, PartialEq)]
pub struct Configuration {
    /// The surfaces.
    pub surfaces: Vec<Surface>,
    /// Per mesh triangle, its surface.
    pub surface_of: Vec<usize>,
    /// The distinct planes `(unit normal, n . p)` the surfaces lie in
    /// (front normals opposite count as distinct planes).
    pub planes: Vec<(DVec3, f64)>,
}

/// The mesh triangle's corners, f64, mesh frame.
fn corners(mesh: &Mesh, t: &schemas::mesh::Triangle) -> [DVec3; 3] {
    t.vertices.map(|v| DVec3::from(mesh.positions[v as usize].map(f64::from)))
}

impl Configuration {
    /// The configuration of a prepared scene, or why it has no exact image
    /// (one line, naming the effect, object or triangle).
    pub fn new(mesh: &Mesh, manifest: &Manifest) -> Result<Self, String> {
        let e = &manifest.effects;
        let unsupported = [
            (e.specular_reflection, "specular reflection (mirrors)"),
            (e.specular_transmission, "specular transmission (glass)"),
            (e.diffuse_transmission, "diffuse transmission"),
            (e.goniometric_lights, "goniometric lights"),
            (e.textures, "diffuse textures"),
            (e.alpha_masks, "alpha masks"),
            (e.normal_maps, "normal maps"),
        ];
        if let Some((_, what)) = unsupported.iter().find(|(present, _)| *present) {
            return Err(format!("the scene has {what}; exact images take plain diffuse planar surfaces lit by emitting surfaces"));
        }
        let points: Vec<DVec3> = mesh.positions.iter().map(|p| DVec3::from(p.map(f64::from))).collect();
        let bounds = Aabb::around(points.iter().copied());
        let tolerance = PLANE_TOLERANCE * (bounds.max - bounds.min).length().max(f64::MIN_POSITIVE);
        let object_name = |o: u32| manifest.objects.get(o as usize).cloned().unwrap_or_else(|| format!("#{o}"));
        let mut surfaces: Vec<Surface> = Vec::new();
        let mut surface_of = Vec::with_capacity(mesh.triangles.len());
        for (index, t) in mesh.triangles.iter().enumerate() {
            let c = corners(mesh, t);
            let Some(normal) = (c[1] - c[0]).cross(c[2] - c[0]).try_normalize() else {
                return Err(format!("triangle {index} (object '{}') spans no area", object_name(t.object)));
            };
            let ids = (t.object, t.material);
            let k = match surfaces.iter().position(|s| s.ids == ids) {
                Some(k) => k,
                None => {
                    let m = &manifest.materials[t.material as usize];
                    surfaces.push(Surface {
                        object: object_name(t.object),
                        ids,
                        triangles: Vec::new(),
                        normal,
                        plane: 0,
                        reflectance: m.diffuse,
                        emission: m.emission,
                    });
                    surfaces.len() - 1
                }
            };
            let s = &mut surfaces[k];
            let anchor = s.triangles.first().map_or(c[0], |f| f[0]);
            let off = c.iter().map(|p| (*p - anchor).dot(s.normal).abs()).fold(0.0, f64::max);
            if normal.dot(s.normal) < 1.0 - 1e-9 || off > tolerance {
                return Err(format!(
                    "object '{}' is not planar (triangle {index} leaves the plane of its first triangle by {off:.3e} m, its normal by {:.3e} rad); exact images take planar receivers",
                    s.object,
                    normal.dot(s.normal).clamp(-1.0, 1.0).acos()
                ));
            }
            s.triangles.push(c);
            surface_of.push(k);
        }
        let mut planes: Vec<(DVec3, f64)> = Vec::new();
        for s in &mut surfaces {
            let offset = s.normal.dot(s.triangles[0][0]);
            let behind = points.iter().map(|p| offset - s.normal.dot(*p)).fold(f64::NEG_INFINITY, f64::max);
            if behind > tolerance {
                let (at, _) = points.iter().enumerate().map(|(i, p)| (i, offset - s.normal.dot(*p))).fold((0, f64::NEG_INFINITY), |b, c| if c.1 > b.1 { c } else { b });
                let owner = mesh.triangles.iter().find(|t| t.vertices.contains(&(at as u32))).map_or_else(|| "?".into(), |t| object_name(t.object));
                return Err(format!(
                    "occluders: object '{owner}' reaches {behind:.3e} m behind the plane of object '{}', so it may block light between surfaces; exact images take unoccluded scenes (every surface in front of every other's plane)",
                    s.object
                ));
            }
            s.plane = match planes.iter().position(|(n, d)| n.dot(s.normal) > 1.0 - 1e-9 && (d - offset).abs() <= tolerance) {
                Some(p) => p,
                None => {
                    planes.push((s.normal, offset));
                    planes.len() - 1
                }
            };
        }
        Ok(Configuration { surfaces, surface_of, planes })
    }

    /// The number of distinct planes holding a reflecting surface.
    pub fn reflecting_planes(&self) -> usize {
        let mut planes: Vec<usize> = self.surfaces.iter().filter(|s| s.reflects()).map(|s| s.plane).collect();
        planes.sort_unstable();
        planes.dedup();
        planes.len()
    }
}
