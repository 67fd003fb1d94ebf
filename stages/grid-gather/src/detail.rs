//! Surface detail in the display (issue 13, items 2 to 4): diffuse
//! textures, alpha masks and normal maps from mesh-prep's surface artifact
//! ([`schemas::surface`]), looked up at the camera's hit points.
//!
//! - **Textures** (paper 004 Sec. 4.2): a point reflects `rho(x)`, the
//!   texture's bilinear reflectance there ([`radiometry::texture`]), so
//!   its radiosity is `B(x) = E + rho(x) H(x)`, `H` the irradiance. The
//!   solution stores each element's radiosity `B_e = E + rho_e H_e`, with
//!   `rho_e` the reflectance the solver transported with; the display
//!   recovers the element's irradiance `H_e = (B_e - E) / rho_e`
//!   ([`Detail::irradiance`]), so that checks finer than the elements show
//!   without the solve resolving them. A channel the solver reflected
//!   nothing in (`rho_e = 0`) has `H_e = 0` there.
//! - **Alpha masks** (004 Sec. 4.3.4): a point whose alpha texel is 0 does
//!   not exist; camera rays and visibility rays pass through it (the
//!   any-hit test of [`radiometry::rays`], given the masks by
//!   [`Detail::rays`]).
//! - **Normal maps** (004 Sec. 2.3.3): the cosines at a point take the
//!   perturbed normal `n' = normalize(s x T + s y B + z N)` from the map's
//!   tangent-space value `(x, y, z) = 2 c - 1` (`s` the MTL `-bm` strength)
//!   in the frame of the triangle's tangent `T`, bitangent `B = w N x T`
//!   and normal `N` (the interpolated shading normal where the OBJ gives
//!   one, else the face normal) ([`Detail::normal`]).
//!
//! Scenes without these effects never build a [`Detail`]: no texture is
//! read and no code path here runs.

use glam::DVec3;
use radiometry::rays::{AlphaMasks, SceneRays};
use radiometry::subdivision::Corners;
use radiometry::texture::{self, Maps};
use schemas::mesh::{Manifest, Mesh};
use schemas::surface::{Surface, Texture, NONE};
use stage_kit::scene::{alpha_masks, material_maps, texels};

/// The surface detail of every triangle.
pub struct Detail<'a> {
    /// Per triangle: its corner texture coordinates, if it has them.
    uv: Vec<Option<[[f32; 2]; 3]>>,
    /// Per triangle: its corner shading normals, if it has them.
    shading_normals: Vec<Option<[[f32; 3]; 3]>>,
    /// Per triangle: tangent and handedness, where a normal map needs them.
    tangents: Vec<Option<[f32; 4]>>,
    /// Per triangle: its material.
    material: Vec<u32>,
    /// Per material: diffuse texture and alpha mask.
    maps: Vec<Maps<'a>>,
    /// Per material: normal map.
    normal_maps: Vec<Option<&'a Texture>>,
    /// The alpha masks the rays pass through, where some triangle has one.
    alpha: Option<AlphaMasks>,
    /// Whether the solver transported with the texture averages (it read
    /// this surface artifact) rather than the materials' `diffuse`.
    solved_with_textures: bool,
}

/// The irradiance `H = (B - E) / rho` behind radiosity `radiosity` of a
/// surface emitting `emission` with reflectance `rho`; 0 in a channel where
/// `rho` is 0, and never negative.
pub fn irradiance_of(radiosity: [f64; 3], emission: [f64; 3], rho: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|c| if rho[c] > 0.0 { ((radiosity[c] - emission[c]) / rho[c]).max(0.0) } else { 0.0 })
}

/// Per-triangle values of a table of `(triangle, value)` records.
fn per_triangle<T: Copy>(records: &[(u32, T)], triangles: usize) -> Vec<Option<T>> {
    let mut out = vec![None; triangles];
    for &(t, v) in records {
        out[t as usize] = Some(v);
    }
    out
}

impl<'a> Detail<'a> {
    /// Whether `solution` was solved with the surface artifact read as
    /// `surface` (an input of the solve has the same content): its element
    /// radiosity then reflects the texture averages ([`Self::new`]).
    pub fn solved_with(solution: &schemas::solution::Solution, surface: &schemas::header::Input) -> bool {
        solution.header.provenance.inputs.iter().any(|i| i.sha256 == surface.sha256)
    }

    /// The detail of `mesh`'s triangles from `surface` (read for this
    /// mesh). `solved_with_textures`: the solution was solved with this
    /// surface artifact (its element radiosity reflects the texture
    /// averages).
    pub fn new(surface: &'a Surface, mesh: &Mesh, manifest: &Manifest, solved_with_textures: bool) -> Self {
        let n = mesh.triangles.len();
        let maps = (0..manifest.materials.len() as u32).map(|m| material_maps(surface, m)).collect();
        let normal_maps = surface.material_maps.iter().map(|m| (m[2] != NONE).then(|| &surface.textures[m[2] as usize])).collect();
        Detail {
            uv: per_triangle(&surface.uvs, n),
            shading_normals: per_triangle(&surface.shading_normals, n),
            tangents: per_triangle(&surface.tangents, n),
            material: mesh.triangles.iter().map(|t| t.material).collect(),
            maps,
            normal_maps,
            alpha: alpha_masks(surface, mesh),
            solved_with_textures,
        }
    }

    /// Texture coordinates at barycentric `b` of `triangle`, if it has them.
    fn uv(&self, triangle: u32, b: [f64; 2]) -> Option<[f64; 2]> {
        let uv = self.uv[triangle as usize]?;
        let l = [1.0 - b[0] - b[1], b[0], b[1]];
        Some(std::array::from_fn(|k| (0..3).map(|c| l[c] * f64::from(uv[c][k])).sum()))
    }

    /// The material maps of `triangle`.
    fn maps(&self, triangle: u32) -> Maps<'a> {
        self.maps[self.material[triangle as usize] as usize]
    }

    /// The diffuse texture's reflectance at barycentric `b` of `triangle`;
    /// `None` where the triangle has no diffuse texture (or no texture
    /// coordinates): its material's `diffuse` applies.
    pub fn reflectance(&self, triangle: u32, b: [f64; 2]) -> Option<[f64; 3]> {
        let t = self.maps(triangle).diffuse?;
        let v = texture::bilinear(t, self.uv(triangle, b)?);
        Some([v[0], v[1], v[2]])
    }

    /// The BVH over `corners` (the mesh's triangles), its rays passing
    /// through the cut-out texels of the alpha masks where some material
    /// has one.
    pub fn rays(&self, corners: &[[DVec3; 3]]) -> SceneRays {
        let rays = SceneRays::new(corners);
        match &self.alpha {
            Some(masks) => rays.with_alpha_masks(masks.clone()),
            None => rays,
        }
    }

    /// The reflectance the solver transported with on the element with
    /// barycentric `corners` in `triangle` of reflectance `diffuse`: the
    /// texture average over the element's opaque part where the solver
    /// read the textures, else `diffuse`.
    fn solved_reflectance(&self, triangle: u32, corners: &Corners, diffuse: [f64; 3]) -> [f64; 3] {
        let maps = self.maps(triangle);
        match (self.solved_with_textures, self.uv[triangle as usize], maps.diffuse) {
            (true, Some(uv), Some(_)) => texture::average(maps, texture::element_uv(&uv, corners)).reflectance.unwrap_or(diffuse),
            _ => diffuse,
        }
    }

    /// The irradiance `H_e = (B_e - E) / rho_e` of an element of
    /// `triangle` with barycentric `corners`, radiosity `radiosity`, its
    /// material's `emission` and `diffuse` (module docs); 0 in a channel
    /// where `rho_e` is 0, and never negative.
    pub fn irradiance(&self, triangle: u32, corners: &Corners, radiosity: [f64; 3], emission: [f64; 3], diffuse: [f64; 3]) -> [f64; 3] {
        irradiance_of(radiosity, emission, self.solved_reflectance(triangle, corners, diffuse))
    }

    /// The normal for cosines at barycentric `b` of `triangle`, whose face
    /// normal is `face`: the normal map's perturbed normal (module docs)
    /// where the material has one and the triangle a tangent, else `face`.
    pub fn normal(&self, triangle: u32, b: [f64; 2], face: DVec3) -> DVec3 {
        let (Some(map), Some(tangent), Some(uv)) = (self.normal_maps[self.material[triangle as usize] as usize], self.tangents[triangle as usize], self.uv(triangle, b)) else {
            return face;
        };
        let n = match self.shading_normals[triangle as usize] {
            Some(c) => {
                let l = [1.0 - b[0] - b[1], b[0], b[1]];
                (0..3).map(|k| DVec3::from(c[k].map(f64::from)) * l[k]).sum::<DVec3>().try_normalize().unwrap_or(face)
            }
            None => face,
        };
        let t = DVec3::new(f64::from(tangent[0]), f64::from(tangent[1]), f64::from(tangent[2]));
        // Gram-Schmidt: the tangent made perpendicular to the shading normal.
        let Some(t) = (t - n * n.dot(t)).try_normalize() else { return n };
        let bitangent = n.cross(t) * f64::from(tangent[3]);
        let c = texture::bilinear(texels(map), uv);
        let s = f64::from(map.strength);
        let [x, y, z] = [s * (2.0 * c[0] - 1.0), s * (2.0 * c[1] - 1.0), 2.0 * c[2] - 1.0];
        let perturbed = (t * x + bitangent * y + n * z).try_normalize().unwrap_or(n);
        // A map may tilt past the surface; the cosines stay on the front side.
        if perturbed.dot(face) > 0.0 {
            perturbed
        } else {
            n
        }
    }
}
