//! The surface artifact's content ([`schemas::surface::Surface`]): corner
//! texture coordinates and shading normals carried over from the OBJ, the
//! textures the used materials name, decoded (PNG, JPEG, TGA) and converted
//! once, and a tangent frame for every normal-mapped triangle.
//!
//! Conversions, so that no later stage needs to know a file format:
//! a diffuse texture's colour is sRGB-encoded (as image editors write it)
//! and is decoded to linear reflectance with the sRGB transfer function
//! (IEC 61966-2-1); alpha and normal maps hold data, not colour, and are
//! read as written (value / maximum).

use crate::mtl::TextureRef;
use crate::text::TextSource;
use glam::{DVec2, DVec3};
use schemas::mesh::{Material, Triangle};
use schemas::surface::{Texture, TextureKind, NONE};
use schemas::Error;
use std::path::{Path, PathBuf};

/// Where one of a material's maps comes from: the file (found) and the
/// statement's options.
#[derive(Clone, Debug)]
pub struct MapSource {
    /// The file, as found.
    pub path: PathBuf,
    /// The MTL statement (or the scene's override), with its options.
    pub texture: TextureRef,
}

/// A material's diffuse, alpha and normal maps, in
/// [`TextureKind::slot`] order.
pub type Maps = [Option<MapSource>; 3];

/// Corner attributes of one triangle, as the OBJ gives them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Corners {
    /// Texture coordinates, where all three corners have them.
    pub uv: Option<[[f64; 2]; 3]>,
    /// Unit shading normals, where all three corners have them.
    pub normal: Option<[[f64; 3]; 3]>,
}

impl Corners {
    /// The attributes of the triangle wound the other way (its twin):
    /// corners 1 and 2 swapped, normals turned to the other side.
    pub fn reversed(self) -> Self {
        Corners { uv: self.uv.map(|[a, b, c]| [a, c, b]), normal: self.normal.map(|[a, b, c]| [a, c, b].map(|n| n.map(|x| -x))) }
    }
}

/// sRGB-encoded `c` in [0, 1] to linear (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Decodes `map` as a texture of `kind` for material `material`: errors
/// name the file and the material.
pub fn decode(source: &dyn TextSource, material: &str, kind: TextureKind, map: &MapSource) -> Result<Texture, Error> {
    let bytes = source.read_bytes(&map.path)?;
    let refuse = |what: String| Error::invalid(&map.path, None, format!("texture of material '{material}': {what}"));
    let format = image::guess_format(&bytes).map_err(|_| refuse("not a PNG, JPEG or TGA image".into()))?;
    let decoded = image::load_from_memory_with_format(&bytes, format).map_err(|e| refuse(format!("cannot be decoded ({e})")))?;
    let has_alpha = decoded.color().has_alpha();
    let rgba = decoded.to_rgba32f();
    let (width, height) = (rgba.width() as usize, rgba.height() as usize);
    if width == 0 || height == 0 {
        return Err(refuse("the image is empty".into()));
    }
    let t = &map.texture;
    let texels = rgba
        .pixels()
        .map(|p| {
            let [r, g, b, a] = p.0;
            match kind {
                TextureKind::Diffuse => [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a],
                TextureKind::Alpha => {
                    let value = match t.channel {
                        Some('r') => r,
                        Some('g') => g,
                        Some('b') => b,
                        Some('l') | Some('z') => 0.2126 * r + 0.7152 * g + 0.0722 * b,
                        _ if has_alpha => a,
                        _ => 0.2126 * r + 0.7152 * g + 0.0722 * b,
                    };
                    [value; 4]
                }
                TextureKind::Normal => [r, g, b, 1.0],
            }
        })
        .collect();
    let strength = if kind == TextureKind::Normal { t.bump_multiplier as f32 } else { 1.0 };
    Ok(Texture { kind, width, height, texels, scale: t.scale.map(|x| x as f32), offset: t.offset.map(|x| x as f32), clamp: t.clamp, strength })
}

/// Why a diffuse texture makes `m` unphysical, if it does: its brightest
/// texel per channel with the material's other coefficients scatters more
/// than it receives.
pub fn check_diffuse(m: &Material, texture: &Texture) -> Option<String> {
    (0..3).find_map(|c| {
        let brightest = texture.texels.iter().map(|t| f64::from(t[c])).fold(0.0, f64::max);
        let total = brightest + m.specular_reflectance[c] + m.specular_transmittance[c] + m.diffuse_transmittance[c];
        (total > 1.0 + 1e-9).then(|| format!("material '{}': its texture's reflectance {brightest} in channel {c} with its other coefficients scatters {total}, more than it receives", m.name))
    })
}

/// The tangent frame of a triangle with `corners` and texture coordinates
/// `uv`, front normal `n`: the direction of increasing `u` in its plane,
/// unit, and the handedness `w` with which `w n x t` is the direction of
/// increasing `v` (Lengyel's per-triangle construction). `None` where the
/// texture coordinates span no area.
pub fn tangent(corners: [DVec3; 3], uv: [[f64; 2]; 3], n: DVec3) -> Option<[f32; 4]> {
    let (e1, e2) = (corners[1] - corners[0], corners[2] - corners[0]);
    let (d1, d2) = (DVec2::from(uv[1]) - DVec2::from(uv[0]), DVec2::from(uv[2]) - DVec2::from(uv[0]));
    let det = d1.x * d2.y - d2.x * d1.y;
    if det.abs() <= 1e-12 * d1.length() * d2.length() || det == 0.0 {
        return None;
    }
    let along_u = (e1 * d2.y - e2 * d1.y) / det;
    let along_v = (e2 * d1.x - e1 * d2.x) / det;
    let t = (along_u - n * n.dot(along_u)).try_normalize()?;
    let w = if n.cross(t).dot(along_v) < 0.0 { -1.0 } else { 1.0 };
    Some([t.x as f32, t.y as f32, t.z as f32, w])
}

/// The surface artifact's tables for the kept triangles: corner texture
/// coordinates and shading normals, the textures of the materials they
/// use, decoded, and the tangents of normal-mapped triangles.
#[derive(Clone, Debug, Default)]
pub struct Built {
    /// `(triangle, corner uvs)`.
    pub uvs: Vec<(u32, [[f32; 2]; 3])>,
    /// `(triangle, corner shading normals)`.
    pub shading_normals: Vec<(u32, [[f32; 3]; 3])>,
    /// `(triangle, tangent and handedness)`.
    pub tangents: Vec<(u32, [f32; 4])>,
    /// Per material, its textures' indices.
    pub material_maps: Vec<[u32; 3]>,
    /// The textures.
    pub textures: Vec<Texture>,
}

/// Builds the surface tables: see [`Built`]. The textures are those of
/// the materials `triangles` use; `maps[m]` are material `m`'s.
pub fn build(
    source: &dyn TextSource,
    positions: &[[f32; 3]],
    triangles: &[Triangle],
    corners: &[Corners],
    materials: &[Material],
    maps: &[Maps],
    warnings: &mut Vec<String>,
) -> Result<Built, Error> {
    // Where a triangle's material has a normal map but the triangle no
    // usable texture coordinates, `warnings` gets a line.
    let mut used = vec![false; materials.len()];
    for t in triangles {
        used[t.material as usize] = true;
    }
    let mut textures = Vec::new();
    let mut material_maps = vec![[NONE; 3]; materials.len()];
    for (m, material) in materials.iter().enumerate().filter(|(m, _)| used[*m]) {
        for (kind, map) in [TextureKind::Diffuse, TextureKind::Alpha, TextureKind::Normal].into_iter().zip(&maps[m]) {
            let Some(map) = map else { continue };
            let texture = decode(source, &material.name, kind, map)?;
            if kind == TextureKind::Diffuse {
                if let Some(problem) = check_diffuse(material, &texture) {
                    return Err(Error::invalid(&map.path, None, problem));
                }
            }
            material_maps[m][kind.slot()] = textures.len() as u32;
            textures.push(texture);
        }
    }
    let as_f32 = |v: [[f64; 2]; 3]| v.map(|c| c.map(|x| x as f32));
    let uvs = corners.iter().enumerate().filter_map(|(i, c)| Some((i as u32, as_f32(c.uv?)))).collect();
    let shading_normals = corners.iter().enumerate().filter_map(|(i, c)| Some((i as u32, c.normal?.map(|n| n.map(|x| x as f32))))).collect();
    let mut tangents = Vec::new();
    let mut unmapped = vec![0usize; materials.len()];
    for (i, (t, c)) in triangles.iter().zip(corners).enumerate() {
        if material_maps[t.material as usize][TextureKind::Normal.slot()] == NONE {
            continue;
        }
        let p = t.vertices.map(|v| DVec3::from(positions[v as usize].map(f64::from)));
        match c.uv.and_then(|uv| tangent(p, uv, DVec3::from(t.normal.map(f64::from)))) {
            Some(frame) => tangents.push((i as u32, frame)),
            None => unmapped[t.material as usize] += 1,
        }
    }
    for (m, &n) in unmapped.iter().enumerate().filter(|(_, n)| **n > 0) {
        warnings.push(format!("material '{}': its normal map cannot apply to {n} triangles without texture coordinates that span an area", materials[m].name));
    }
    Ok(Built { uvs, shading_normals, tangents, material_maps, textures })
}

/// The map of an override (`diffuse_map: Some("wood.png")`), relative to
/// the scene file's folder, with default options.
pub fn override_map(scene_path: &Path, name: &str) -> MapSource {
    let base = scene_path.parent().unwrap_or(Path::new(""));
    MapSource { path: base.join(name), texture: TextureRef::named(name, 0) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::prepare::{prepare, Params, Prepared};
    use crate::text::Memory;
    use glam::dvec3;

    /// A unit quad in z = 0 with texture coordinates, material `leaf`
    /// with the MTL statements `maps`, two-sided where asked, and the
    /// extra files `files`; prepared.
    fn prepared(maps: &str, two_sided: bool, files: Vec<(String, Vec<u8>)>) -> Result<Prepared, Error> {
        let obj = "mtllib m.mtl\nusemtl leaf\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
        let two = if two_sided { "materials: { \"leaf\": (two_sided: Some(true)) }," } else { "" };
        let scene = format!(
            "Scene(meshes: [Obj(file: \"a.obj\")], camera: Camera(eye: (0.5, 0.5, 2.0), target: (0.5, 0.5, 0.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: 60.0, width: 8, height: 8), {two})"
        );
        let mut source = Memory::text(&[("s/scene.ron", &scene), ("s/a.obj", obj), ("s/m.mtl", &format!("newmtl leaf\nKd 0.5\n{maps}"))]);
        source.0.extend(files);
        let path = Path::new("s/scene.ron");
        prepare(&crate::read_scene(&source, path)?, path, &source, &Params::default())
    }

    /// A 2 x 1 PNG: a red texel and a mid-grey one (sRGB 128).
    fn png(name: &str) -> (String, Vec<u8>) {
        (format!("s/{name}"), stage_kit::png::encode_png(2, 1, &[[255, 0, 0], [128, 128, 128]]).unwrap())
    }

    #[test]
    fn a_textured_two_sided_quad_carries_its_coordinates_textures_and_tangents() {
        let p = prepared("map_Kd -s 2 2 leaf.png\nnorm -bm 0.5 n.png\n", true, vec![png("leaf.png"), png("n.png")]).unwrap();
        let s = &p.surface;
        assert_eq!(p.triangles.len(), 4, "two triangles and their twins");
        assert_eq!(s.uvs.iter().map(|u| u.0).collect::<Vec<_>>(), [0, 1, 2, 3]);
        assert_eq!(s.uvs[0].1, [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]);
        assert_eq!(s.uvs[2].1, [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0]], "the twin's corners 1 and 2 swap with its vertices");
        assert_eq!(p.triangles[2].vertices, schemas::mesh::reversed(p.triangles[0].vertices));
        let [diffuse, normal] = [&s.textures[0], &s.textures[1]];
        assert_eq!((diffuse.kind, diffuse.width, diffuse.height, diffuse.scale), (TextureKind::Diffuse, 2, 1, [2.0, 2.0]));
        assert_eq!(diffuse.texels[0], [1.0, 0.0, 0.0, 1.0]);
        let grey = srgb_to_linear(128.0 / 255.0);
        assert!((diffuse.texels[1][0] - grey).abs() < 1e-6 && (grey - 0.2158).abs() < 1e-4, "sRGB 128 is 0.216 linear");
        assert_eq!((normal.kind, normal.strength), (TextureKind::Normal, 0.5));
        assert!((normal.texels[1][0] - 128.0 / 255.0).abs() < 1e-6, "a normal map is data: not decoded as colour");
        assert_eq!(s.material_maps, [[0, NONE, 1]]);
        // Every triangle is normal-mapped: u runs along x on both faces;
        // the twin, facing -z, sees v on the other hand.
        assert_eq!(s.tangents.iter().map(|t| t.1).collect::<Vec<_>>(), [[1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0], [1.0, 0.0, 0.0, -1.0], [1.0, 0.0, 0.0, -1.0]]);
    }

    #[test]
    fn missing_unreadable_and_unphysical_textures_are_errors_naming_file_and_material() {
        let message = |maps: &str, files: Vec<(String, Vec<u8>)>| prepared(maps, false, files).unwrap_err().to_string();
        assert_eq!(message("map_Kd gone.png\n", vec![]), "s/m.mtl:3: material 'leaf': texture 's/gone.png' does not exist");
        assert_eq!(message("map_Kd t.png\n", vec![("s/t.png".into(), b"not an image".to_vec())]), "s/t.png: texture of material 'leaf': not a PNG, JPEG or TGA image");
        let bright = message("Ks 0.5\nillum 3\nmap_Kd t.png\n", vec![png("t.png")]);
        assert_eq!(bright, "s/t.png: material 'leaf': its texture's reflectance 1 in channel 0 with its other coefficients scatters 1.5, more than it receives");
        let p = prepared("", false, vec![]).unwrap();
        assert!(p.surface.textures.is_empty() && p.surface.tangents.is_empty(), "no map, no texture");
        assert_eq!(p.surface.uvs.len(), 2);
    }

    #[test]
    fn srgb_decoding_matches_the_standard_at_its_knee_and_ends() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear(0.04045) - 0.04045 / 12.92).abs() < 1e-7);
        // 0.5 encoded is 0.214 linear (the standard's tables).
        assert!((srgb_to_linear(0.5) - 0.21404).abs() < 1e-4);
    }

    #[test]
    fn the_tangent_follows_increasing_u_and_the_handedness_increasing_v() {
        let p = [dvec3(0.0, 0.0, 0.0), dvec3(2.0, 0.0, 0.0), dvec3(0.0, 3.0, 0.0)];
        let n = DVec3::Z;
        assert_eq!(tangent(p, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], n), Some([1.0, 0.0, 0.0, 1.0]));
        // u along y, v along x: the tangent is y and v runs along -(n x t) = x.
        assert_eq!(tangent(p, [[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]], n), Some([0.0, 1.0, 0.0, -1.0]));
        assert_eq!(tangent(p, [[0.5, 0.5]; 3], n), None, "coordinates that span no area give no frame");
    }

    #[test]
    fn a_twin_gets_its_corners_swapped_and_its_normals_turned() {
        let c = Corners { uv: Some([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]), normal: Some([[0.0, 0.0, 1.0], [0.0, 0.6, 0.8], [0.6, 0.0, 0.8]]) };
        let r = c.reversed();
        assert_eq!(r.uv, Some([[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]));
        assert_eq!(r.normal, Some([[-0.0, -0.0, -1.0], [-0.6, -0.0, -0.8], [-0.0, -0.6, -0.8]]));
    }
}
