//! Surface detail from `surface.exr` ([`schemas::surface`]), the standard
//! equivalents in a hierarchical solve of paper 004's per-texel treatment:
//!
//! - **Textures** (004 Sec. 4.2): each element transports with its
//!   texture-averaged reflectance, the exact mean of the bilinear texture
//!   over its footprint ([`radiometry::texture::average`]); over the opaque
//!   part only, where an alpha mask applies. The display modulates by the
//!   texture itself: with `rho_e` this average (the same function of the
//!   element's corners, so any stage recomputes it), the element's
//!   irradiance is `H_e = (B_e - E_e) / rho_e` and a point shows
//!   `E + rho(x) H_e`.
//! - **Alpha masks** (004 Sec. 4.3.4): points on transparent texels do not
//!   exist. An element's area is its opaque area (`A n_o / n_c`, its
//!   coverage times its area), which weights it in push-pull and as a
//!   cluster's surface; an element with nothing opaque neither sends nor
//!   receives. A sender's form factor is Lambert's (002 Eq. 3) summed over
//!   the polygons of its opaque texel runs ([`Detail::opaque_parts`]), or,
//!   past [`MAX_PIECE_TEXELS`], its whole factor times its coverage (the
//!   refinement then splits it toward the exact case). Visibility rays pass
//!   through transparent texels ([`radiometry::rays`]), and sample pairs
//!   with an end on a transparent texel carry no weight.
//! - **Normal maps** (004 Sec. 2.3.3): a receiver's cosine at each point of
//!   its quadrature is taken with the perturbed normal `n' = normalize(t
//!   n_x + b n_y + n n_z)`, `(n_x, n_y, n_z) = 2 c - 1` the map's bilinear
//!   texel `c` with `n_x`, `n_y` scaled by the strength (MTL `-bm`), `t`
//!   the triangle's tangent, `b = w n x t` and `n` its geometric normal
//!   ([`Detail::normal_at`]). The quadrature is the centroid rule on
//!   `4^NORMAL_MAP_LEVELS` equal sub-triangles of the receiver, each
//!   point's factor Lambert's (002 Eq. 3, clipped to the perturbed
//!   normal's hemisphere). Senders keep their geometric normals (their
//!   radiosity leaves as from a Lambertian plane), as do the luminaires'
//!   direct light and the visibility weights.
//!
//! A scene without detail builds no [`Detail`], and none of this runs.

use glam::DVec3;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::AlphaMasks;
use radiometry::subdivision::Corners;
use radiometry::texture::{self, element_uv, Average, Maps};
use schemas::mesh::Mesh;
use schemas::surface::{Surface, TextureKind, NONE};
use stage_kit::scene::{alpha_masks, material_maps, texels};

/// Most alpha texels a sender's footprint may span for its form factor to
/// be summed over its opaque runs polygon by polygon.
pub const MAX_PIECE_TEXELS: usize = 4096;

/// 1:4 levels of a normal-mapped receiver's centroid rule: 64 points.
pub const NORMAL_MAP_LEVELS: u32 = 3;

/// The average of an element without texture or mask.
const PLAIN: Average = Average { coverage: 1.0, reflectance: None };

/// A triangle's normal map: its corners' texture coordinates, the map's
/// texture index, the tangent and handedness.
type NormalMap = ([[f32; 2]; 3], u32, [f32; 4]);

/// What the solve reads of `surface.exr`, and each element's averages.
pub struct Detail {
    surface: Surface,
    /// Per input triangle: corner texture coordinates and material, where
    /// its material has a diffuse or alpha map and it has coordinates.
    mapped: Vec<Option<([[f32; 2]; 3], u32)>>,
    /// Per input triangle: corner texture coordinates, normal map and
    /// tangent frame, where its material has a normal map and mesh-prep
    /// gave it a tangent.
    normal_mapped: Vec<Option<NormalMap>>,
    /// Per element (arena order): its texture average.
    averages: Vec<Average>,
}

impl Detail {
    /// The detail of `mesh`'s triangles in `surface`; `None` where no
    /// triangle has a texture or mask to apply.
    pub fn new(surface: Surface, mesh: &Mesh) -> Option<Self> {
        let mut mapped = vec![None; mesh.triangles.len()];
        for &(t, uv) in &surface.uvs {
            let material = mesh.triangles[t as usize].material;
            if !material_maps(&surface, material).is_empty() {
                mapped[t as usize] = Some((uv, material));
            }
        }
        let mut normal_mapped = vec![None; mesh.triangles.len()];
        let uv_of = |t: u32| surface.uvs.binary_search_by_key(&t, |u| u.0).ok().map(|k| surface.uvs[k].1);
        for &(t, tangent) in &surface.tangents {
            let map = surface.material_maps[mesh.triangles[t as usize].material as usize][TextureKind::Normal.slot()];
            if let (Some(uv), true) = (uv_of(t), map != NONE) {
                normal_mapped[t as usize] = Some((uv, map, tangent));
            }
        }
        let any = mapped.iter().any(Option::is_some) || normal_mapped.iter().any(Option::is_some);
        any.then_some(Detail { surface, mapped, normal_mapped, averages: Vec::new() })
    }

    /// Whether `triangle` has a normal map.
    pub fn normal_mapped(&self, triangle: u32) -> bool {
        self.normal_mapped[triangle as usize].is_some()
    }

    /// The perturbed unit normal at barycentric `(u, v)` of `triangle`,
    /// whose geometric normal is `n` (module docs); `n` where it has no
    /// normal map.
    pub fn normal_at(&self, triangle: u32, uv: [f64; 2], n: DVec3) -> DVec3 {
        let Some((corner_uv, map, tangent)) = &self.normal_mapped[triangle as usize] else { return n };
        let texture = &self.surface.textures[*map as usize];
        let c = texture::bilinear(texels(texture), element_uv(corner_uv, &[uv; 3])[0]);
        let strength = f64::from(texture.strength);
        let local = DVec3::new(strength * (2.0 * c[0] - 1.0), strength * (2.0 * c[1] - 1.0), 2.0 * c[2] - 1.0);
        let t = DVec3::new(f64::from(tangent[0]), f64::from(tangent[1]), f64::from(tangent[2]));
        let b = f64::from(tangent[3]) * n.cross(t);
        (t * local.x + b * local.y + n * local.z).try_normalize().unwrap_or(n)
    }

    fn maps(&self, triangle: u32) -> Option<(Maps<'_>, &[[f32; 2]; 3])> {
        self.mapped[triangle as usize].as_ref().map(|(uv, m)| (material_maps(&self.surface, *m), uv))
    }

    /// Computes and appends the average of the next element, of `triangle`
    /// with barycentric `corners`.
    pub fn push(&mut self, triangle: u32, corners: &Corners) {
        let average = self.maps(triangle).map_or(PLAIN, |(maps, uv)| texture::average(maps, element_uv(uv, corners)));
        self.averages.push(average);
    }

    /// Element `e`'s average.
    pub fn average(&self, e: u32) -> Average {
        self.averages[e as usize]
    }

    /// Whether the point at barycentric `(u, v)` of `triangle` exists (is
    /// not on a transparent texel).
    pub fn exists(&self, triangle: u32, uv: [f64; 2]) -> bool {
        let Some((Maps { alpha: Some(alpha), .. }, corner_uv)) = self.maps(triangle) else { return true };
        texture::opaque(alpha, element_uv(corner_uv, &[uv; 3])[0])
    }

    /// The opaque part of the element of `triangle` (geometry `g`) with
    /// barycentric `corners`, as convex polygons in the mesh frame; `None`
    /// where no mask applies or it spans more than [`MAX_PIECE_TEXELS`].
    pub fn opaque_parts(&self, triangle: u32, corners: &Corners, g: &TriangleGeometry) -> Option<Vec<Vec<DVec3>>> {
        let (Maps { alpha: Some(alpha), .. }, uv) = self.maps(triangle)? else { return None };
        let pieces = texture::opaque_pieces(alpha, element_uv(uv, corners), MAX_PIECE_TEXELS)?;
        // Texture coordinates back to barycentrics: the inverse of the
        // triangle's affine map uv(b) = uv0 + b1 (uv1 - uv0) + b2 (uv2 - uv0).
        let c = uv.map(|p| p.map(f64::from));
        let (e1, e2) = ([c[1][0] - c[0][0], c[1][1] - c[0][1]], [c[2][0] - c[0][0], c[2][1] - c[0][1]]);
        let det = e1[0] * e2[1] - e2[0] * e1[1];
        if det == 0.0 {
            return None;
        }
        let barycentric = |p: [f64; 2]| {
            let d = [p[0] - c[0][0], p[1] - c[0][1]];
            [(d[0] * e2[1] - e2[0] * d[1]) / det, (e1[0] * d[1] - d[0] * e1[1]) / det]
        };
        Some(pieces.into_iter().map(|piece| piece.into_iter().map(|p| g.point(barycentric(p))).collect()).collect())
    }

    /// The alpha masks of `mesh` (the mesh this detail was made for) for
    /// the visibility rays, where some triangle has one.
    pub fn alpha_masks(&self, mesh: &Mesh) -> Option<AlphaMasks> {
        alpha_masks(&self.surface, mesh)
    }
}
