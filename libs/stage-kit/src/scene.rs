//! The prepared scene's artifacts as `radiometry` takes them: `radiometry`
//! knows no file contract, so the adapters from `schemas` types (the
//! mesh, the manifest's camera and goniometric lights, the surface
//! artifact's textures) to its data live here, one place for every stage.

use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use radiometry::photometry::{Distribution, Luminaire};
use radiometry::rays::AlphaMasks;
use radiometry::texture::{Maps, TexelGrid, Texels};
use schemas::mesh::{Camera, GoniometricLight, Mesh};
use schemas::surface::{Surface, Texture, TextureKind, NONE};

/// The geometry of every triangle of `mesh`, in f64.
pub fn mesh_triangles(mesh: &Mesh) -> Vec<TriangleGeometry> {
    let p = |i: u32| {
        let v = mesh.positions[i as usize];
        DVec3::new(v[0].into(), v[1].into(), v[2].into())
    };
    mesh.triangles.iter().map(|t| TriangleGeometry::new(t.vertices.map(p))).collect()
}

/// The pinhole camera of `camera` rendering a `width` x `height` image;
/// `None` where [`Pinhole::new`] refuses it (zero view direction, view
/// along up, field of view outside (0, 180) degrees, an empty image).
pub fn pinhole(camera: &Camera, width: u32, height: u32) -> Option<Pinhole> {
    Pinhole::new(DVec3::from(camera.eye), DVec3::from(camera.target), DVec3::from(camera.up), camera.vertical_fov_deg, width, height)
}

/// The light of one manifest entry, its table and placement checked
/// ([`Distribution::new`], [`Luminaire::new`]); the error says what is
/// wrong.
fn luminaire(light: &GoniometricLight) -> Result<Luminaire, String> {
    let distribution = Distribution::new(light.c_angles_deg.clone(), light.gamma_angles_deg.clone(), light.intensity_cd.clone())?;
    Luminaire::new(distribution, DVec3::from(light.position), DVec3::from(light.nadir), DVec3::from(light.c0), light.scale)
}

/// Every goniometric light of a manifest, or the first one's error naming
/// its index and label.
pub fn luminaires(lights: &[GoniometricLight]) -> Result<Vec<Luminaire>, String> {
    lights.iter().enumerate().map(|(k, l)| luminaire(l).map_err(|e| format!("goniometric light {k} ('{}'): {e}", l.label))).collect()
}

/// A texture of the surface artifact as the lookups read it (borrowed).
pub fn texels(t: &Texture) -> Texels<'_> {
    TexelGrid { width: t.width, height: t.height, texels: &t.texels, scale: t.scale, offset: t.offset, clamp: t.clamp }
}

/// Material `material`'s diffuse and alpha maps in `surface`.
pub fn material_maps(surface: &Surface, material: u32) -> Maps<'_> {
    let get = |kind: TextureKind| {
        surface.material_maps.get(material as usize).map(|m| m[kind.slot()]).filter(|&t| t != NONE).map(|t| texels(&surface.textures[t as usize]))
    };
    Maps { diffuse: get(TextureKind::Diffuse), alpha: get(TextureKind::Alpha) }
}

/// The alpha masks of `mesh`'s triangles in `surface` (read for this
/// mesh), for the ray caster: each triangle with texture coordinates whose
/// material has an alpha texture, the textures numbered in order of first
/// use; `None` where no triangle has one.
pub fn alpha_masks(surface: &Surface, mesh: &Mesh) -> Option<AlphaMasks> {
    let mut uv = vec![None; mesh.triangles.len()];
    for &(t, corners) in &surface.uvs {
        uv[t as usize] = Some(corners);
    }
    let mut index = vec![NONE; surface.textures.len()];
    let mut textures = Vec::new();
    let masked = mesh
        .triangles
        .iter()
        .zip(uv)
        .map(|(triangle, uv)| {
            let uv = uv?;
            let t = surface.material_maps[triangle.material as usize][TextureKind::Alpha.slot()];
            if t == NONE {
                return None;
            }
            if index[t as usize] == NONE {
                index[t as usize] = textures.len() as u32;
                textures.push(texels(&surface.textures[t as usize]).owned());
            }
            Some((uv.map(|p| p.map(f64::from)), index[t as usize]))
        })
        .collect();
    (!textures.is_empty()).then_some(AlphaMasks { masked, textures })
}
