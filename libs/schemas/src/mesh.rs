//! The mesh artifact (`mesh.exr`) and its manifest (`manifest.ron`), both
//! written by `mesh-prep` and read by every later stage.
//!
//! Frames and units: positions are in the *mesh frame*, metres, which is the
//! world frame translated by `-world_from_mesh_translation` so that the scene
//! is centred on the origin: f32 positions then keep their precision even
//! when the scene file places the model a thousand kilometres away.

use crate::error::{Error, Result};
use crate::exr_io::{check_finite, read_exr, write_exr, Channel, ExrArtifact, Layer};
use crate::header::{Header, Input, Provenance, Schema};
use crate::ron_io::RonArtifact;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One triangle of the prepared mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// Indices into the vertex table, counter-clockwise seen from the front.
    pub vertices: [u32; 3],
    /// Index into [`Manifest::materials`].
    pub material: u32,
    /// Index into [`Manifest::objects`].
    pub object: u32,
    /// Area in m².
    pub area: f32,
    /// Unit normal of the front face, mesh frame.
    pub normal: [f32; 3],
}

/// The mesh: welded vertices and non-degenerate triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Header with provenance.
    pub header: Header,
    /// Vertex positions, mesh frame, metres.
    pub positions: Vec<[f32; 3]>,
    /// Triangles.
    pub triangles: Vec<Triangle>,
}

impl Schema for Mesh {
    const NAME: &'static str = "mesh";
    const VERSION: u32 = 1;
}

impl Mesh {
    /// Each triangle's twin, if it has one: the first triangle over the
    /// same vertices wound the other way ([`reversed`]), the other face of
    /// a two-sided surface (mesh-prep makes them; [`Manifest::check_mesh`]
    /// checks that every two-sided triangle has one of its material).
    pub fn twins(&self) -> Vec<Option<u32>> {
        let mut first = std::collections::HashMap::with_capacity(self.triangles.len());
        for (i, t) in self.triangles.iter().enumerate() {
            first.entry(cyclic(t.vertices)).or_insert(i as u32);
        }
        self.triangles.iter().map(|t| first.get(&cyclic(reversed(t.vertices))).copied()).collect()
    }

    /// Writes `mesh.exr`: layers `vertex` and `triangle`.
    pub fn write(&self, path: &Path) -> Result<()> {
        let p = &self.positions;
        let t = &self.triangles;
        let vertex = Layer::table(
            "vertex",
            p.len(),
            vec![
                Channel::f32("P.X", "position x, mesh frame, m", p.iter().map(|v| v[0]).collect()),
                Channel::f32("P.Y", "position y, mesh frame, m", p.iter().map(|v| v[1]).collect()),
                Channel::f32("P.Z", "position z, mesh frame, m", p.iter().map(|v| v[2]).collect()),
            ],
        );
        let triangle = Layer::table(
            "triangle",
            t.len(),
            vec![
                Channel::u32("v0", "first vertex index", t.iter().map(|t| t.vertices[0]).collect()),
                Channel::u32("v1", "second vertex index", t.iter().map(|t| t.vertices[1]).collect()),
                Channel::u32("v2", "third vertex index", t.iter().map(|t| t.vertices[2]).collect()),
                Channel::u32("material", "index into manifest materials", t.iter().map(|t| t.material).collect()),
                Channel::u32("object", "index into manifest objects", t.iter().map(|t| t.object).collect()),
                Channel::f32("area", "area, m^2", t.iter().map(|t| t.area).collect()),
                Channel::f32("N.X", "front-face unit normal x", t.iter().map(|t| t.normal[0]).collect()),
                Channel::f32("N.Y", "front-face unit normal y", t.iter().map(|t| t.normal[1]).collect()),
                Channel::f32("N.Z", "front-face unit normal z", t.iter().map(|t| t.normal[2]).collect()),
            ],
        );
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![vertex, triangle] })
    }

    /// Reads and validates `mesh.exr`: at least one triangle (mesh-prep
    /// refuses an empty scene), positions, areas and normals finite, every
    /// vertex index in range. The material and object indices are
    /// checked against the manifest by [`Manifest::check_mesh`].
    pub fn read(path: &Path) -> Result<(Mesh, Input)> {
        let (artifact, input) = read_exr::<Mesh>(path)?;
        let vertex = artifact.layer(path, "vertex")?;
        check_finite(path, vertex, "vertex", &["P.X", "P.Y", "P.Z"])?;
        let (x, y, z) = (vertex.f32s(path, "P.X")?, vertex.f32s(path, "P.Y")?, vertex.f32s(path, "P.Z")?);
        let positions: Vec<[f32; 3]> = (0..vertex.len()).map(|i| [x[i], y[i], z[i]]).collect();
        let tri = artifact.layer(path, "triangle")?;
        if tri.is_empty() {
            return Err(Error::invalid(path, None, "layer 'triangle' holds no triangle"));
        }
        check_finite(path, tri, "triangle", &["area", "N.X", "N.Y", "N.Z"])?;
        let v = [tri.u32s(path, "v0")?, tri.u32s(path, "v1")?, tri.u32s(path, "v2")?];
        let (material, object, area) = (tri.u32s(path, "material")?, tri.u32s(path, "object")?, tri.f32s(path, "area")?);
        let n = [tri.f32s(path, "N.X")?, tri.f32s(path, "N.Y")?, tri.f32s(path, "N.Z")?];
        let mut triangles = Vec::with_capacity(tri.len());
        for i in 0..tri.len() {
            let vertices = [v[0][i], v[1][i], v[2][i]];
            if let Some(k) = vertices.iter().position(|&k| k as usize >= positions.len()) {
                return Err(Error::invalid(path, None, format!("triangle {i}: field v{k} names vertex {}, but the mesh has {}", vertices[k], positions.len())));
            }
            triangles.push(Triangle { vertices, material: material[i], object: object[i], area: area[i], normal: [n[0][i], n[1][i], n[2][i]] });
        }
        Ok((Mesh { header: artifact.header, positions, triangles }, input))
    }
}

/// A pinhole camera, mesh frame.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Eye position, m.
    pub eye: [f64; 3],
    /// A point the camera looks at.
    pub target: [f64; 3],
    /// Up direction (need not be orthogonal to the view direction).
    pub up: [f64; 3],
    /// Full vertical field of view, degrees.
    pub vertical_fov_deg: f64,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
}

/// A surface material. Colours are linear RGB.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Name from the MTL file or the scene.
    pub name: String,
    /// Diffuse reflectance rho, in [0, 1).
    pub diffuse: [f64; 3],
    /// Emitted radiosity (radiant exitance), W/m², front face only.
    pub emission: [f64; 3],
    /// Ideal specular reflectance.
    pub specular_reflectance: [f64; 3],
    /// Ideal specular transmittance.
    pub specular_transmittance: [f64; 3],
    /// Diffuse transmittance.
    pub diffuse_transmittance: [f64; 3],
    /// Diffuse texture file, if any.
    pub diffuse_map: Option<String>,
    /// Alpha (cut-out) mask file, if any.
    pub alpha_map: Option<String>,
    /// Normal map file, if any.
    pub normal_map: Option<String>,
    /// Whether the surface reflects on both faces (leaves, paper, thin
    /// panels): `mesh-prep` gives every triangle of a two-sided material a
    /// *twin*, the same three vertices wound the other way, so each face is
    /// a one-sided surface with its own radiosity and every solver needs
    /// nothing more than one-sided surfaces (see [`Manifest::check_mesh`]).
    /// Emission stays one-sided: an emitting material cannot be two-sided.
    #[serde(default)]
    pub two_sided: bool,
}

impl Material {
    /// A diffuse material: reflectance `diffuse`, exitance `emission`,
    /// nothing specular or transmitted, no maps.
    pub fn diffuse(name: &str, diffuse: [f64; 3], emission: [f64; 3]) -> Self {
        Material {
            name: name.into(),
            diffuse,
            emission,
            specular_reflectance: [0.0; 3],
            specular_transmittance: [0.0; 3],
            diffuse_transmittance: [0.0; 3],
            diffuse_map: None,
            alpha_map: None,
            normal_map: None,
            two_sided: false,
        }
    }
}

/// A goniometric point light (luminaire) as data: `mesh-prep` read and
/// validated its EULUMDAT or IES file, expanded the file's symmetry to a
/// full sphere of type C angles and converted it to absolute candela; no
/// later stage opens a photometric file. The radiant intensity towards a
/// direction with angles `(C, gamma)` in the frame `(c0, nadir x c0,
/// nadir)` is `scale x I(C, gamma) / 683` W/sr (paper 004 Eq. 2.12, 3.4),
/// `I` the bicubic Catmull-Rom interpolation of the table
/// (`radiometry::photometry`).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct GoniometricLight {
    /// The photometric file it was read from, as the scene names it: a
    /// label only (the table below is the data).
    pub label: String,
    /// Position, mesh frame, m.
    pub position: [f64; 3],
    /// Direction of the luminaire's nadir (gamma = 0), unit.
    pub nadir: [f64; 3],
    /// Direction of the C0 half-plane, unit, perpendicular to `nadir`.
    pub c0: [f64; 3],
    /// Multiplier on the table's intensities, finite and > 0.
    pub scale: f64,
    /// C angles, degrees, strictly increasing in `[0, 360)`; periodic.
    pub c_angles_deg: Vec<f64>,
    /// Gamma angles, degrees, strictly increasing from 0 to 180.
    pub gamma_angles_deg: Vec<f64>,
    /// Luminous intensity, cd, before `scale`: `[c * gamma_angles_deg.len()
    /// + gamma]`.
    pub intensity_cd: Vec<f64>,
    /// Total luminous flux of the light as placed (`scale` included), lm,
    /// integrated from the interpolated table.
    pub flux_lm: f64,
}

/// Which phenomena the scene contains. Every stage reads this and runs only
/// the code paths a scene needs; its report says what it skipped and why.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    /// Some surface emits and some surface reflects diffusely.
    pub diffuse_interreflection: bool,
    /// Some material transmits diffusely.
    pub diffuse_transmission: bool,
    /// Some material reflects specularly (mirrors).
    pub specular_reflection: bool,
    /// Some material transmits specularly (glass, water).
    pub specular_transmission: bool,
    /// The scene has goniometric point lights.
    pub goniometric_lights: bool,
    /// Some material has an alpha mask.
    pub alpha_masks: bool,
    /// Some material has a normal map.
    pub normal_maps: bool,
    /// Some material has a diffuse texture.
    pub textures: bool,
    /// The mesh is fine enough that clustering pays (many small triangles).
    pub fine_clustered_geometry: bool,
}

impl Effects {
    /// Whether the scene has surface detail the surface artifact
    /// (`mesh-prep --surface`) carries: textures, alpha masks or normal
    /// maps. Stages read that artifact only then.
    pub fn surface_detail(&self) -> bool {
        self.textures || self.alpha_masks || self.normal_maps
    }

    /// The report's `skipped` list: the note of every `(present, note)`
    /// pair whose effect the scene has, in order. Each stage passes its own
    /// notes for the effects it does not simulate.
    pub fn skipped(notes: &[(bool, &str)]) -> Vec<String> {
        notes.iter().filter(|(present, _)| *present).map(|(_, note)| note.to_string()).collect()
    }
}

/// What `mesh-prep` did to the input geometry.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct MeshStatistics {
    /// Triangles after triangulating the input faces.
    pub input_triangles: usize,
    /// Triangles dropped because their area is (numerically) zero.
    pub degenerate_dropped: usize,
    /// Triangles dropped because they repeat another (same three vertices
    /// in the same order, or either order for a two-sided triangle).
    pub duplicates_dropped: usize,
    /// Twins added for two-sided materials (counted in `triangles`).
    #[serde(default)]
    pub two_sided_twins: usize,
    /// Vertices merged into another at the same position.
    pub vertices_welded: usize,
    /// Triangles kept.
    pub triangles: usize,
    /// Vertices kept.
    pub vertices: usize,
    /// Total surface area, m².
    pub total_area: f64,
    /// Area of emitting surfaces, m².
    pub emitting_area: f64,
    /// Total emitted power, W per channel.
    pub emitted_power: [f64; 3],
    /// Mesh-frame bounding box: min corner.
    pub bounds_min: [f64; 3],
    /// Mesh-frame bounding box: max corner.
    pub bounds_max: [f64; 3],
}

/// `manifest.ron`: what the scene is made of besides its triangles.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Header with provenance.
    pub header: Header,
    /// World position of the mesh frame's origin, m (f64: it may be large).
    pub world_from_mesh_translation: [f64; 3],
    /// The camera, mesh frame.
    pub camera: Camera,
    /// Materials, indexed by the triangles' `material`.
    pub materials: Vec<Material>,
    /// Object names, indexed by the triangles' `object`.
    pub objects: Vec<String>,
    /// Goniometric point lights.
    pub goniometric_lights: Vec<GoniometricLight>,
    /// Which phenomena the scene contains.
    pub effects: Effects,
    /// What preparation did.
    pub statistics: MeshStatistics,
}

impl Schema for Manifest {
    const NAME: &'static str = "manifest";
    const VERSION: u32 = 3;
}

impl RonArtifact for Manifest {
    fn provenance(&self) -> &Provenance {
        &self.header.provenance
    }
}

impl Manifest {
    /// Checks that `mesh` fits this manifest: every material and object
    /// index in range of its lists, and every triangle of a two-sided
    /// material paired with its twin (the same vertices wound the other
    /// way, the same material), which is what makes the material two-sided
    /// for every solver. (That both come from one run is checked by
    /// `stage_kit::run::read_prepared`.)
    pub fn check_mesh(&self, mesh_path: &Path, mesh: &Mesh) -> Result<()> {
        for (i, t) in mesh.triangles.iter().enumerate() {
            for (field, index, count) in [("material", t.material, self.materials.len()), ("object", t.object, self.objects.len())] {
                if index as usize >= count {
                    return Err(Error::invalid(mesh_path, None, format!("triangle {i}: field {field} is {index}, but the manifest has {count} {field}s")));
                }
            }
        }
        let two_sided = |t: &Triangle| self.materials[t.material as usize].two_sided;
        let wound: std::collections::HashSet<([u32; 3], u32)> =
            mesh.triangles.iter().filter(|t| two_sided(t)).map(|t| (cyclic(t.vertices), t.material)).collect();
        if let Some((i, t)) = mesh.triangles.iter().enumerate().find(|(_, t)| two_sided(t) && !wound.contains(&(cyclic(reversed(t.vertices)), t.material))) {
            let name = &self.materials[t.material as usize].name;
            return Err(Error::invalid(mesh_path, None, format!("triangle {i}: material '{name}' is two-sided, but the triangle has no twin (its vertices wound the other way)")));
        }
        Ok(())
    }
}

/// The same triangle wound the other way: its twin, facing the other side.
pub fn reversed<T: Copy>(v: [T; 3]) -> [T; 3] {
    [v[0], v[2], v[1]]
}

/// The corners (vertex indices, or positions) rotated to start at the
/// smallest: equal for the same triangle whichever corner it starts at,
/// different for its twin.
pub fn cyclic<T: Ord + Copy>(v: [T; 3]) -> [T; 3] {
    let first = (0..3).min_by_key(|&i| v[i]).unwrap_or(0);
    [v[first], v[(first + 1) % 3], v[(first + 2) % 3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The message reading one triangle over three vertices gives, after
    /// `edit`; it names the file.
    fn refusal(name: &str, edit: impl FnOnce(&mut Mesh)) -> String {
        let triangle = Triangle { vertices: [0, 1, 2], material: 0, object: 0, area: 0.5, normal: [0.0, 0.0, 1.0] };
        let mut mesh = Mesh { header: Mesh::header(Provenance::in_memory("test")), positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], triangles: vec![triangle] };
        edit(&mut mesh);
        let path = std::env::temp_dir().join(format!("mesh-{name}-{}.exr", std::process::id()));
        mesh.write(&path).unwrap();
        let message = Mesh::read(&path).unwrap_err().to_string();
        std::fs::remove_file(&path).unwrap();
        message.strip_prefix(&format!("{}: ", path.display())).unwrap_or_else(|| panic!("{message}")).to_string()
    }

    #[test]
    fn an_empty_mesh_a_vertex_out_of_range_and_a_nan_are_refused() {
        assert_eq!(refusal("empty", |m| m.triangles.clear()), "layer 'triangle' holds no triangle");
        assert_eq!(refusal("vertex", |m| m.triangles[0].vertices[2] = 3), "triangle 0: field v2 names vertex 3, but the mesh has 3");
        assert_eq!(refusal("nan", |m| m.positions[1][1] = f32::NAN), "vertex 1: field P.Y is NaN");
    }

    #[test]
    fn a_two_sided_triangle_needs_its_twin() {
        let mut manifest: Manifest = Manifest {
            header: Manifest::header(Provenance::in_memory("test")),
            world_from_mesh_translation: [0.0; 3],
            camera: Camera { eye: [0.0, 0.0, 1.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], vertical_fov_deg: 40.0, width: 4, height: 4 },
            materials: vec![Material { two_sided: true, ..Material::diffuse("leaf", [0.5; 3], [0.0; 3]) }],
            objects: vec!["o".into()],
            goniometric_lights: Vec::new(),
            effects: Effects::default(),
            statistics: MeshStatistics::default(),
        };
        let front = Triangle { vertices: [0, 1, 2], material: 0, object: 0, area: 0.5, normal: [0.0, 0.0, 1.0] };
        let mut mesh = Mesh { header: Mesh::header(Provenance::in_memory("test")), positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], triangles: vec![front] };
        let path = Path::new("mesh.exr");
        let message = manifest.check_mesh(path, &mesh).unwrap_err().to_string();
        assert_eq!(message, "mesh.exr: triangle 0: material 'leaf' is two-sided, but the triangle has no twin (its vertices wound the other way)");
        // The same winding started at another corner is the same face, not its twin.
        mesh.triangles.push(Triangle { vertices: [1, 2, 0], ..front });
        assert!(manifest.check_mesh(path, &mesh).is_err());
        assert_eq!(mesh.twins(), [None, None]);
        mesh.triangles[1] = Triangle { vertices: [2, 1, 0], normal: [0.0, 0.0, -1.0], ..front };
        manifest.check_mesh(path, &mesh).unwrap();
        assert_eq!(mesh.twins(), [Some(1), Some(0)]);
        manifest.materials[0].two_sided = false;
        manifest.check_mesh(path, &mesh).unwrap();
    }
}
