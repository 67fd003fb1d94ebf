//! The surface artifact (`surface.exr`): what `mesh-prep` read of the
//! surfaces besides their shape, for the stages that simulate surface
//! detail (paper 004 Sec. 2.3.3, 4.2, 4.3.4): texture coordinates and
//! shading normals per triangle corner (from the OBJ's `vt` and `vn`),
//! tangent frames where a normal map needs them, and the textures the
//! materials name, decoded and converted once.
//!
//! A scene without surface detail has empty tables and no texture: no
//! stage loads an image or allocates a texture atlas for it.
//!
//! Layers: tables `uv` (`triangle`, `U0`..`V2`), `shading_normal`
//! (`triangle`, `N0.X`..`N2.Z`), `tangent` (`triangle`, `T.X`, `T.Y`,
//! `T.Z`, `T.W`), `material_maps` (one record per manifest material:
//! `diffuse`, `alpha`, `normal`, texture indices or [`NONE`]), `texture`
//! (one record per texture: `kind`, `clamp`, `S.U`, `S.V`, `O.U`, `O.V`,
//! `strength`), and one image layer `texture.<k>` (`R`, `G`, `B`, `A`) per
//! texture. Triangle indices are the mesh's, strictly increasing.

use crate::error::{Error, Result};
use crate::exr_io::{check_finite, read_exr, write_exr, Channel, ExrArtifact, Layer, LayerKind};
use crate::header::{Header, Input, Schema};
use std::path::Path;

/// No texture in a [`Surface::material_maps`] slot.
pub const NONE: u32 = u32::MAX;

/// What a texture holds, and so how its texels read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureKind {
    /// `map_Kd`: linear diffuse reflectance in R, G, B (the file's sRGB
    /// decoded), the file's alpha in A.
    Diffuse,
    /// `map_d`: coverage (1 opaque, 0 cut out) in every channel, from the
    /// channel `-imfchan` names (default: the alpha channel where the file
    /// has one, else its luminance).
    Alpha,
    /// `norm`/`bump`: the file's R, G, B in [0, 1] as written (a
    /// tangent-space normal is `2 c - 1`), A 1.
    Normal,
}

impl TextureKind {
    const ALL: [TextureKind; 3] = [TextureKind::Diffuse, TextureKind::Alpha, TextureKind::Normal];

    /// The kind's slot in [`Surface::material_maps`].
    pub fn slot(self) -> usize {
        self as usize
    }
}

/// One decoded texture.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// What it holds.
    pub kind: TextureKind,
    /// Texels per row.
    pub width: usize,
    /// Rows; row 0 is the top of the image (`v = 1`).
    pub height: usize,
    /// `width x height` texels, RGBA, finite.
    pub texels: Vec<[f32; 4]>,
    /// MTL `-s`: texture coordinates are `scale * uv + offset`.
    pub scale: [f32; 2],
    /// MTL `-o`.
    pub offset: [f32; 2],
    /// MTL `-clamp on`: coordinates clamp to [0, 1]; otherwise they repeat.
    pub clamp: bool,
    /// MTL `-bm`: the strength of a normal map (1 for other kinds).
    pub strength: f32,
}

/// `surface.exr`.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Header with provenance.
    pub header: Header,
    /// Corner texture coordinates of the triangles that have them.
    pub uvs: Vec<(u32, [[f32; 2]; 3])>,
    /// Corner shading normals (unit, mesh frame) of the triangles that
    /// have them.
    pub shading_normals: Vec<(u32, [[f32; 3]; 3])>,
    /// Tangent (unit, along increasing `u`, in the triangle's plane) and
    /// handedness `w = +-1` (bitangent `w n x t`) of the normal-mapped
    /// triangles.
    pub tangents: Vec<(u32, [f32; 4])>,
    /// Per manifest material: its diffuse, alpha and normal texture.
    pub material_maps: Vec<[u32; 3]>,
    /// The textures.
    pub textures: Vec<Texture>,
}

impl Schema for Surface {
    const NAME: &'static str = "surface";
    const VERSION: u32 = 1;
}

/// A table of `records` whose `channels(k)` are each record's values.
fn table<const N: usize>(name: &str, records: &[(u32, [f32; N])], channels: &[(&str, &str)]) -> Layer {
    let mut all = vec![Channel::u32("triangle", "mesh triangle index", records.iter().map(|r| r.0).collect())];
    for (k, (channel, meaning)) in channels.iter().enumerate() {
        all.push(Channel::f32(channel, meaning, records.iter().map(|r| r.1[k]).collect()));
    }
    Layer::table(name, records.len(), all)
}

/// Reads a table written by [`table`]: triangle indices strictly
/// increasing and below `triangles`, values finite.
fn read_table<const N: usize>(path: &Path, artifact: &ExrArtifact, name: &str, channels: &[&str], triangles: usize) -> Result<Vec<(u32, [f32; N])>> {
    let layer = artifact.layer(path, name)?;
    check_finite(path, layer, name, channels)?;
    let index = layer.u32s(path, "triangle")?;
    let values = channels.iter().map(|c| layer.f32s(path, c)).collect::<Result<Vec<_>>>()?;
    let mut out = Vec::with_capacity(layer.len());
    for (i, &t) in index.iter().enumerate() {
        if t as usize >= triangles || out.last().is_some_and(|(last, _)| *last >= t) {
            return Err(Error::invalid(path, None, format!("layer '{name}' record {i}: triangle {t} is out of order or not below the mesh's {triangles}")));
        }
        out.push((t, std::array::from_fn(|k| values[k][i])));
    }
    Ok(out)
}

const UV: [(&str, &str); 6] = [("U0", "u, corner 0"), ("V0", "v, corner 0"), ("U1", "u, corner 1"), ("V1", "v, corner 1"), ("U2", "u, corner 2"), ("V2", "v, corner 2")];
const NORMAL: [(&str, &str); 9] = [
    ("N0.X", "shading normal x, corner 0"),
    ("N0.Y", "shading normal y, corner 0"),
    ("N0.Z", "shading normal z, corner 0"),
    ("N1.X", "shading normal x, corner 1"),
    ("N1.Y", "shading normal y, corner 1"),
    ("N1.Z", "shading normal z, corner 1"),
    ("N2.X", "shading normal x, corner 2"),
    ("N2.Y", "shading normal y, corner 2"),
    ("N2.Z", "shading normal z, corner 2"),
];
const TANGENT: [(&str, &str); 4] = [("T.X", "tangent x"), ("T.Y", "tangent y"), ("T.Z", "tangent z"), ("T.W", "handedness: bitangent = w n x t")];
const RGBA: [&str; 4] = ["R", "G", "B", "A"];

/// Per-corner records as flat rows (`N = 3 A`: corner 0's values first).
fn flatten<const A: usize, const N: usize>(records: &[(u32, [[f32; A]; 3])]) -> Vec<(u32, [f32; N])> {
    records.iter().map(|(t, v)| (*t, std::array::from_fn(|k| v[k / A][k % A]))).collect()
}

/// Flat rows back as per-corner records.
fn unflatten<const A: usize, const N: usize>(rows: Vec<(u32, [f32; N])>) -> Vec<(u32, [[f32; A]; 3])> {
    rows.into_iter().map(|(t, x)| (t, std::array::from_fn(|c| std::array::from_fn(|a| x[c * A + a])))).collect()
}

fn names<const N: usize>(channels: &[(&'static str, &'static str); N]) -> [&'static str; N] {
    channels.map(|c| c.0)
}

impl Surface {
    /// Writes `surface.exr`.
    pub fn write(&self, path: &Path) -> Result<()> {
        let (uvs, normals) = (flatten::<2, 6>(&self.uvs), flatten::<3, 9>(&self.shading_normals));
        let mut layers = vec![table("uv", &uvs, &UV), table("shading_normal", &normals, &NORMAL), table("tangent", &self.tangents, &TANGENT)];
        let slot = |s: usize| self.material_maps.iter().map(|m| m[s]).collect();
        layers.push(Layer::table(
            "material_maps",
            self.material_maps.len(),
            vec![
                Channel::u32("diffuse", "diffuse texture index, or 2^32-1", slot(0)),
                Channel::u32("alpha", "alpha texture index, or 2^32-1", slot(1)),
                Channel::u32("normal", "normal map index, or 2^32-1", slot(2)),
            ],
        ));
        let t = &self.textures;
        let f = |get: &dyn Fn(&Texture) -> f32| t.iter().map(get).collect();
        layers.push(Layer::table(
            "texture",
            t.len(),
            vec![
                Channel::u32("kind", "0 diffuse, 1 alpha, 2 normal", t.iter().map(|x| x.kind as u32).collect()),
                Channel::u32("clamp", "1: coordinates clamp, 0: they repeat", t.iter().map(|x| u32::from(x.clamp)).collect()),
                Channel::f32("S.U", "u scale", f(&|x| x.scale[0])),
                Channel::f32("S.V", "v scale", f(&|x| x.scale[1])),
                Channel::f32("O.U", "u offset", f(&|x| x.offset[0])),
                Channel::f32("O.V", "v offset", f(&|x| x.offset[1])),
                Channel::f32("strength", "normal map strength", f(&|x| x.strength)),
            ],
        ));
        for (k, texture) in t.iter().enumerate() {
            let channels = RGBA.iter().enumerate().map(|(c, name)| Channel::f32(name, "texel", texture.texels.iter().map(|x| x[c]).collect())).collect();
            layers.push(Layer { name: format!("texture.{k}"), kind: LayerKind::Image { width: texture.width, height: texture.height }, channels });
        }
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers })
    }

    /// Reads and validates `surface.exr` for a mesh of `triangles`
    /// triangles and `materials` materials: indices in range and in order,
    /// values finite, shading normals and tangents unit, every material's
    /// texture of the kind its slot names.
    pub fn read(path: &Path, triangles: usize, materials: usize) -> Result<(Surface, Input)> {
        let (artifact, input) = read_exr::<Surface>(path)?;
        let uvs = unflatten::<2, 6>(read_table(path, &artifact, "uv", &names(&UV), triangles)?);
        let normals = read_table::<9>(path, &artifact, "shading_normal", &names(&NORMAL), triangles)?;
        let tangents = read_table::<4>(path, &artifact, "tangent", &names(&TANGENT), triangles)?;
        let unit = |v: &[f32]| (v.iter().map(|x| x * x).sum::<f32>().sqrt() - 1.0).abs() <= 1e-3;
        if let Some((t, _)) = normals.iter().find(|(_, n)| !n.chunks(3).all(unit)) {
            return Err(Error::invalid(path, None, format!("layer 'shading_normal': triangle {t}: a normal is not unit length")));
        }
        if let Some((t, _)) = tangents.iter().find(|(_, x)| !unit(&x[..3]) || x[3].abs() != 1.0) {
            return Err(Error::invalid(path, None, format!("layer 'tangent': triangle {t}: not a unit tangent with handedness +-1")));
        }
        let shading_normals = unflatten::<3, 9>(normals);

        let meta = artifact.layer(path, "texture")?;
        check_finite(path, meta, "texture", &["S.U", "S.V", "O.U", "O.V", "strength"])?;
        let (kind, clamp) = (meta.u32s(path, "kind")?, meta.u32s(path, "clamp")?);
        let (su, sv, ou, ov, strength) = (meta.f32s(path, "S.U")?, meta.f32s(path, "S.V")?, meta.f32s(path, "O.U")?, meta.f32s(path, "O.V")?, meta.f32s(path, "strength")?);
        let mut textures = Vec::with_capacity(meta.len());
        for k in 0..meta.len() {
            let name = format!("texture.{k}");
            let Some(&kind) = TextureKind::ALL.get(kind[k] as usize) else {
                return Err(Error::invalid(path, None, format!("layer 'texture' record {k}: field kind is {}, not 0, 1 or 2", kind[k])));
            };
            let layer = artifact.layer(path, &name)?;
            let LayerKind::Image { width, height } = layer.kind else {
                return Err(Error::invalid(path, None, format!("layer '{name}' is not an image")));
            };
            check_finite(path, layer, &name, &RGBA)?;
            let c = RGBA.iter().map(|c| layer.f32s(path, c)).collect::<Result<Vec<_>>>()?;
            let texels = (0..width * height).map(|i| std::array::from_fn(|k| c[k][i])).collect();
            textures.push(Texture { kind, width, height, texels, scale: [su[k], sv[k]], offset: [ou[k], ov[k]], clamp: clamp[k] != 0, strength: strength[k] });
        }

        let maps = artifact.layer(path, "material_maps")?;
        if maps.len() != materials {
            return Err(Error::invalid(path, None, format!("layer 'material_maps' has {} records for the manifest's {materials} materials", maps.len())));
        }
        let slots = [maps.u32s(path, "diffuse")?, maps.u32s(path, "alpha")?, maps.u32s(path, "normal")?];
        let material_maps: Vec<[u32; 3]> = (0..materials).map(|m| std::array::from_fn(|s| slots[s][m])).collect();
        for (m, entry) in material_maps.iter().enumerate() {
            for (slot, &t) in entry.iter().enumerate() {
                if t != NONE && textures.get(t as usize).is_none_or(|x: &Texture| x.kind.slot() != slot) {
                    return Err(Error::invalid(path, None, format!("layer 'material_maps' record {m}: texture {t} is missing or not of the kind its slot names")));
                }
            }
        }
        Ok((Surface { header: artifact.header, uvs, shading_normals, tangents, material_maps, textures }, input))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::Provenance;

    fn surface() -> Surface {
        let texture = Texture {
            kind: TextureKind::Diffuse,
            width: 2,
            height: 1,
            texels: vec![[0.25, 0.5, 0.75, 1.0], [0.1, 0.2, 0.3, 0.0]],
            scale: [2.0, 1.0],
            offset: [0.5, 0.0],
            clamp: true,
            strength: 1.0,
        };
        Surface {
            header: Surface::header(Provenance::in_memory("test")),
            uvs: vec![(1, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])],
            shading_normals: vec![(0, [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])],
            tangents: vec![(1, [1.0, 0.0, 0.0, -1.0])],
            material_maps: vec![[0, NONE, NONE], [NONE; 3]],
            textures: vec![texture],
        }
    }

    fn round_trip(name: &str, edit: impl FnOnce(&mut Surface)) -> Result<Surface> {
        let mut s = surface();
        edit(&mut s);
        let path = std::env::temp_dir().join(format!("surface-{name}-{}.exr", std::process::id()));
        s.write(&path).unwrap();
        let read = Surface::read(&path, 2, 2).map(|r| r.0);
        std::fs::remove_file(&path).unwrap();
        read
    }

    #[test]
    fn a_surface_reads_back_as_written_and_an_empty_one_too() {
        assert_eq!(round_trip("full", |_| ()).unwrap(), surface());
        let empty = |s: &mut Surface| {
            s.uvs.clear();
            s.shading_normals.clear();
            s.tangents.clear();
            s.textures.clear();
            s.material_maps = vec![[NONE; 3]; 2];
        };
        let read = round_trip("empty", empty).unwrap();
        assert!(read.uvs.is_empty() && read.textures.is_empty() && read.material_maps == [[NONE; 3]; 2]);
    }

    #[test]
    fn bad_indices_kinds_and_normals_are_refused() {
        let message = |name: &str, edit: fn(&mut Surface)| round_trip(name, edit).unwrap_err().to_string();
        assert!(message("order", |s| s.uvs.push((0, [[0.0; 2]; 3]))).contains("layer 'uv' record 1: triangle 0 is out of order"));
        assert!(message("range", |s| s.tangents[0].0 = 2).contains("layer 'tangent' record 0: triangle 2"));
        assert!(message("unit", |s| s.shading_normals[0].1[1] = [0.0, 2.0, 0.0]).contains("not unit length"));
        assert!(message("slot", |s| s.material_maps[1] = [NONE, 0, NONE]).contains("record 1: texture 0 is missing or not of the kind"));
        assert!(message("texel", |s| s.textures[0].texels[1][2] = f32::NAN).contains("texture.0"));
    }
}
