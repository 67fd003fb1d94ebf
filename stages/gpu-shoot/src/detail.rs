//! Surface detail per texel (paper 004 Sec. 4.2, 4.3.4, 2.3.3): what each
//! covered texel of the atlas is beyond its geometry, from the textures of
//! `surface.exr`:
//!
//! - reflectance: the diffuse texture's colour over the texel (Sec. 4.2,
//!   "colors on a per-texel basis instead of using a constant color for the
//!   whole triangle"), replacing the material's `Kd`;
//! - coverage: the fraction of the texel an alpha mask leaves opaque
//!   (Sec. 4.3.4: texels with alpha 0 do not exist; the triangle's area is
//!   corrected by `n_o / n_c`, here counted over the sub-samples of each
//!   texel, so a texel cut by the mask's edge keeps its opaque part);
//! - normal: the normal map's perturbed normal (Sec. 2.3.3), in the frame
//!   of the triangle's tangent, bitangent `w n x t` and normal, for the
//!   receiver's and the shooter's cosines.
//!
//! Reflectance and coverage are the exact averages of `radiometry::texture`
//! (the bilinear reflectance over the opaque part; a point exists where its
//! alpha texel is above 0, the rule the visibility maps' alpha test
//! mirrors in `visibility.wgsl`) over the texel's square in barycentrics
//! (half of it on the hypotenuse), so a texture finer than the atlas is
//! averaged, not aliased (the paper asks for matching resolutions; this
//! keeps each texel's mean). The normal is the mean of the normal map's
//! bilinear normals on a `k x k` grid of the texel, `k` from the number of
//! map texels it spans.

use glam::DVec3;
use radiometry::texture::{average, bilinear, element_uv};
use schemas::lightmap::Region;
use schemas::mesh::{Manifest, Mesh};
use schemas::surface::{Surface, Texture, TextureKind, NONE};
use stage_kit::scene::{material_maps, texels};

/// Most sub-samples per texel side of a normal map.
const MAX_SUBSAMPLES: u32 = 8;

/// A texel's detail.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelDetail {
    /// Mean diffuse reflectance over its opaque part.
    pub rho: [f64; 3],
    /// Opaque fraction of its area, in [0, 1].
    pub coverage: f64,
    /// Unit normal for the cosines (perturbed by a normal map).
    pub normal: DVec3,
}

/// The surface detail of a scene: per triangle its corner coordinates,
/// tangent and shading normals, per material its textures.
pub struct Detail<'a> {
    surface: &'a Surface,
    uvs: Vec<Option<[[f32; 2]; 3]>>,
    tangents: Vec<Option<[f32; 4]>>,
    normals: Vec<Option<[[f32; 3]; 3]>>,
}

/// Per-triangle values of a table of `(triangle, value)` records.
fn per_triangle<T: Copy>(records: &[(u32, T)], triangles: usize) -> Vec<Option<T>> {
    let mut out = vec![None; triangles];
    for (t, v) in records {
        out[*t as usize] = Some(*v);
    }
    out
}

impl<'a> Detail<'a> {
    /// The detail of `surface`, or `None` where no triangle's material
    /// has a texture: such a scene never reads a texel.
    pub fn new(mesh: &Mesh, surface: &'a Surface) -> Option<Detail<'a>> {
        let textured = mesh.triangles.iter().any(|t| surface.material_maps[t.material as usize] != [NONE; 3]);
        textured.then(|| {
            let n = mesh.triangles.len();
            Detail { surface, uvs: per_triangle(&surface.uvs, n), tangents: per_triangle(&surface.tangents, n), normals: per_triangle(&surface.shading_normals, n) }
        })
    }

    /// The texture of `kind` triangle `t` reads, with its corner
    /// coordinates (a triangle without coordinates reads none).
    fn map(&self, mesh: &Mesh, t: usize, kind: TextureKind) -> Option<(&'a Texture, [[f32; 2]; 3])> {
        let index = self.surface.material_maps[mesh.triangles[t].material as usize][kind.slot()];
        let uv = self.uvs[t]?;
        (index != NONE).then(|| (&self.surface.textures[index as usize], uv))
    }

    /// The alpha texture and corner coordinates of triangle `t`, if masked.
    pub fn mask(&self, mesh: &Mesh, t: usize) -> Option<(&'a Texture, [[f32; 2]; 3])> {
        self.map(mesh, t, TextureKind::Alpha)
    }

    /// Whether some triangle is alpha-masked.
    pub fn masked(&self, mesh: &Mesh) -> bool {
        (0..mesh.triangles.len()).any(|t| self.mask(mesh, t).is_some())
    }

    /// The detail of covered texel `(i, j)` of triangle `t` (region
    /// `region`), or `None` where its material has no texture (or the
    /// triangle no texture coordinates). The texel's barycentric square
    /// `[i, i+1] x [j, j+1] / n` is the triangles `(i, j), (i+1, j), (i,
    /// j+1)` and, off the hypotenuse, `(i+1, j), (i+1, j+1), (i, j+1)`, of
    /// equal area.
    pub fn texel(&self, mesh: &Mesh, manifest: &Manifest, t: usize, region: Region, i: u32, j: u32) -> Option<TexelDetail> {
        let tri = &mesh.triangles[t];
        let uv = self.uvs[t]?;
        let maps = material_maps(self.surface, tri.material);
        let normal_map = self.map(mesh, t, TextureKind::Normal);
        if maps.is_empty() && normal_map.is_none() {
            return None;
        }
        let n = region.size as f64;
        let at = |a: u32, b: u32| [a as f64 / n, b as f64 / n];
        let mut halves = vec![[at(i, j), at(i + 1, j), at(i, j + 1)]];
        if i + j + 1 < region.size {
            halves.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
        let (mut coverage, mut rho) = (0.0, [0.0; 3]);
        let diffuse = manifest.materials[tri.material as usize].diffuse;
        for half in &halves {
            let mean = average(maps, element_uv(&uv, half));
            coverage += mean.coverage / halves.len() as f64;
            let r = mean.reflectance.unwrap_or(diffuse);
            (0..3).for_each(|c| rho[c] += r[c] * mean.coverage);
        }
        let geometric = DVec3::from(tri.normal.map(f64::from));
        if coverage == 0.0 {
            return Some(TexelDetail { rho: [0.0; 3], coverage, normal: geometric });
        }
        let rho = rho.map(|r| r / (coverage * halves.len() as f64));
        let normal = normal_map.map_or(geometric, |(texture, _)| self.mean_normal(t, geometric, texture, &uv, region, i, j));
        Some(TexelDetail { rho, coverage, normal })
    }

    /// The mean perturbed normal over texel `(i, j)`: the centres of a `k
    /// x k` grid of its square, weight 1 inside the triangle and 1/2 on
    /// its hypotenuse, `k` twice the normal map texels it spans (at least
    /// 2, at most [`MAX_SUBSAMPLES`]).
    #[allow(clippy::too_many_arguments)]
    fn mean_normal(&self, t: usize, geometric: DVec3, texture: &Texture, uv: &[[f32; 2]; 3], region: Region, i: u32, j: u32) -> DVec3 {
        let n = region.size;
        let size = [texture.width as f64 * texture.scale[0].abs() as f64, texture.height as f64 * texture.scale[1].abs() as f64];
        let edge = |c: usize| ((0..2).map(|a| ((uv[c][a] - uv[0][a]) as f64 * size[a]).powi(2)).sum::<f64>()).sqrt() / n as f64;
        let k = ((2.0 * edge(1).max(edge(2))).ceil() as u32).clamp(2, MAX_SUBSAMPLES);
        let nk = n * k;
        let mut sum = DVec3::ZERO;
        for b in 0..k {
            for a in 0..k {
                let w = match ((i * k + a) + (j * k + b) + 1).cmp(&nk) {
                    std::cmp::Ordering::Less => 1.0,
                    std::cmp::Ordering::Equal => 0.5,
                    std::cmp::Ordering::Greater => continue,
                };
                let bary = [(i * k + a) as f64 + 0.5, (j * k + b) as f64 + 0.5].map(|x| x / nk as f64);
                sum += w * self.perturbed(t, geometric, bary, texture, element_uv(uv, &[bary; 3])[0]);
            }
        }
        sum.try_normalize().unwrap_or(geometric)
    }

    /// Whether triangle `t` has a normal map it can read: texture
    /// coordinates and a tangent.
    pub fn normal_mapped(&self, mesh: &Mesh, t: usize) -> bool {
        self.map(mesh, t, TextureKind::Normal).is_some() && self.tangents[t].is_some()
    }

    /// The unit normal at barycentric `bary` of triangle `t`: `geometric`
    /// without a tangent; with one, the normal map's bilinear value at
    /// texture coordinates `at` perturbs the shading normal (or
    /// `geometric`) in the tangent frame:
    /// `m = 2 c - 1`, its tangential part scaled by the map's strength
    /// (MTL `-bm`), `n' = m.x t + m.y (w n x t) + m.z n` (004 Sec. 2.3.3).
    fn perturbed(&self, t: usize, geometric: DVec3, bary: [f64; 2], texture: &Texture, at: [f64; 2]) -> DVec3 {
        let Some(tangent) = self.tangents[t] else { return geometric };
        let base = self.normals[t]
            .map(|c| {
                let c = c.map(|v| DVec3::from(v.map(f64::from)));
                (c[0] + bary[0] * (c[1] - c[0]) + bary[1] * (c[2] - c[0])).normalize_or(geometric)
            })
            .unwrap_or(geometric);
        let c = bilinear(texels(texture), at);
        let s = texture.strength as f64;
        let m = DVec3::new(s * (2.0 * c[0] - 1.0), s * (2.0 * c[1] - 1.0), 2.0 * c[2] - 1.0);
        let handedness = tangent[3].signum() as f64;
        let tangent = DVec3::from([tangent[0], tangent[1], tangent[2]].map(f64::from));
        let tangent = (tangent - base * tangent.dot(base)).normalize_or(tangent);
        let bitangent = handedness * base.cross(tangent);
        (m.x * tangent + m.y * bitangent + m.z * base).normalize_or(base)
    }

    /// The alpha masks as the visibility maps read them (`visibility.wgsl`):
    /// per triangle two vec4, `(u0, v0, u1, v1)` and `(u2, v2, mask, 0)`
    /// with `mask` the bits of the offset of its texture's record in the
    /// second table, or `u32::MAX` for an unmasked triangle; the second
    /// table holds per alpha texture `[width, height, clamp, S.U, S.V, O.U,
    /// O.V]` then its `width x height` alpha values (channel A), row 0 at
    /// the top.
    pub fn mask_tables(&self, mesh: &Mesh) -> (Vec<[f32; 4]>, Vec<f32>) {
        let mut records = Vec::new();
        let mut offsets = vec![None; self.surface.textures.len()];
        let mut triangles = Vec::with_capacity(2 * mesh.triangles.len());
        for t in 0..mesh.triangles.len() {
            let Some((texture, uv)) = self.mask(mesh, t) else {
                triangles.extend([[0.0; 4], [0.0, 0.0, f32::from_bits(u32::MAX), 0.0]]);
                continue;
            };
            let index = self.surface.material_maps[mesh.triangles[t].material as usize][TextureKind::Alpha.slot()] as usize;
            let offset = *offsets[index].get_or_insert_with(|| {
                let at = records.len() as u32;
                records.extend([texture.width as f32, texture.height as f32, f32::from(u8::from(texture.clamp))]);
                records.extend(texture.scale.iter().chain(&texture.offset));
                records.extend(texture.texels.iter().map(|x| x[3]));
                at
            });
            triangles.extend([[uv[0][0], uv[0][1], uv[1][0], uv[1][1]], [uv[2][0], uv[2][1], f32::from_bits(offset), 0.0]]);
        }
        (triangles, records)
    }
}
