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

/// The corners of triangle `t` of `mesh`, in f64.
pub fn triangle_corners(mesh: &Mesh, t: usize) -> [DVec3; 3] {
    mesh.triangles[t].vertices.map(|v| DVec3::from(mesh.positions[v as usize].map(f64::from)))
}

/// The geometry of every triangle of `mesh`, in f64.
pub fn mesh_triangles(mesh: &Mesh) -> Vec<TriangleGeometry> {
    (0..mesh.triangles.len()).map(|t| TriangleGeometry::new(triangle_corners(mesh, t))).collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use schemas::header::{Provenance, Schema};
    use schemas::mesh::Triangle;

    /// A 1 x 1 texture of `kind` holding `value` in every channel.
    fn texture(kind: TextureKind, value: f32) -> Texture {
        Texture { kind, width: 1, height: 1, texels: vec![[value; 4]], scale: [2.0, 1.0], offset: [0.5, 0.0], clamp: true, strength: 1.0 }
    }

    /// Materials 0 (diffuse texture 1, alpha 3), 1 (alpha 2), 2 (diffuse
    /// texture 0); triangles of materials 1, 0, 0, 1, of which 0 and 2 have
    /// texture coordinates.
    fn scene() -> (Surface, Mesh) {
        let uv = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let surface = Surface {
            header: Surface::header(Provenance::in_memory("test")),
            uvs: vec![(0, uv), (2, uv)],
            shading_normals: Vec::new(),
            tangents: Vec::new(),
            material_maps: vec![[1, 3, NONE], [NONE, 2, NONE], [0, NONE, NONE]],
            textures: vec![texture(TextureKind::Diffuse, 0.125), texture(TextureKind::Diffuse, 0.25), texture(TextureKind::Alpha, 0.0), texture(TextureKind::Alpha, 1.0)],
        };
        let triangle = |material: u32| Triangle { vertices: [0, 1, 2], material, object: 0, area: 0.5, normal: [0.0, 0.0, 1.0] };
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        (surface, Mesh { header: Mesh::header(Provenance::in_memory("test")), positions, triangles: [1, 0, 0, 1].map(triangle).to_vec() })
    }

    #[test]
    fn material_maps_and_alpha_masks_follow_the_surface_tables() {
        let (surface, mesh) = scene();
        let maps = material_maps(&surface, 0);
        let (diffuse, alpha) = (maps.diffuse.unwrap(), maps.alpha.unwrap());
        assert_eq!((diffuse.texels, alpha.texels), (&[[0.25; 4]][..], &[[1.0; 4]][..]));
        assert_eq!((diffuse.width, diffuse.height, diffuse.scale, diffuse.offset, diffuse.clamp), (1, 1, [2.0, 1.0], [0.5, 0.0], true));
        assert!(material_maps(&surface, 1).diffuse.is_none() && material_maps(&surface, 2).alpha.is_none());
        assert!(material_maps(&surface, 3).is_empty(), "a material past the table has no maps");
        // Triangle 0 (material 1) first uses alpha texture 2, triangle 2
        // (material 0) texture 3; triangles 1 and 3 have no coordinates.
        let masks = alpha_masks(&surface, &mesh).unwrap();
        assert_eq!(masks.masked.iter().map(|m| m.map(|(_, k)| k)).collect::<Vec<_>>(), [Some(0), None, Some(1), None]);
        assert_eq!(masks.masked[2].unwrap().0, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert_eq!((masks.textures[0].texels.clone(), masks.textures[1].texels.clone()), (vec![[0.0; 4]], vec![[1.0; 4]]));
        let unmasked = Surface { material_maps: vec![[1, NONE, NONE]; 3], ..surface };
        assert!(alpha_masks(&unmasked, &mesh).is_none());
    }

    #[test]
    fn the_manifest_s_camera_and_lights_are_placed_and_a_bad_light_is_named() {
        let camera = Camera { eye: [0.0, 0.0, 0.0], target: [0.0, 0.0, -5.0], up: [0.0, 1.0, 0.0], vertical_fov_deg: 90.0, width: 4, height: 2 };
        let centre = pinhole(&camera, 200, 100).unwrap().direction(100.0, 50.0);
        assert!((centre - DVec3::NEG_Z).length() < 1e-12);
        assert!(pinhole(&Camera { vertical_fov_deg: 180.0, ..camera }, 200, 100).is_none());
        let light = |label: &str, scale: f64| GoniometricLight {
            label: label.into(),
            position: [1.0, 2.0, 3.0],
            nadir: [0.0, 0.0, -1.0],
            c0: [1.0, 0.0, 0.0],
            scale,
            c_angles_deg: vec![0.0],
            gamma_angles_deg: vec![0.0, 180.0],
            intensity_cd: vec![683.0, 683.0],
            flux_lm: 0.0,
        };
        let placed = luminaires(&[light("a.ies", 2.0)]).unwrap();
        assert_eq!((placed[0].position, placed[0].frame[2], placed[0].w_per_sr_per_cd), (DVec3::new(1.0, 2.0, 3.0), DVec3::NEG_Z, 2.0 / 683.0));
        let error = luminaires(&[light("a.ies", 2.0), light("b.ldt", -1.0)]).unwrap_err();
        assert_eq!(error, "goniometric light 1 ('b.ldt'): scale -1 must be finite and > 0 (and scale x largest intensity finite)");
    }
}
