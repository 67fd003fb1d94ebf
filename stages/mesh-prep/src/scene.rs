//! The scene file (`scene.ron`) a user writes: meshes, camera, lights and
//! material overrides. Parsed strictly: a misspelt field is an error with
//! its line number, not a silent default.
//!
//! | field | type | meaning | default |
//! |---|---|---|---|
//! | `meshes` | list of `Obj(file, scale, translate)` | OBJ files, relative to the scene file; world = scale * p + translate | required |
//! | `camera` | `Camera(eye, target, up, vertical_fov_deg, width, height)` | pinhole camera, world frame | required |
//! | `lights` | list of `Area(..)` / `Goniometric(..)` | lights added to the meshes' emitters | `[]` |
//! | `materials` | map name -> `Override(..)` | per-material changes to the MTL values (`diffuse`, `emission`, ..., `two_sided: Some(true)`) | `{}` |

use schemas::mesh::Camera;
use serde::Deserialize;
use std::collections::BTreeMap;

/// A scene description.
#[derive(Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Geometry files.
    pub meshes: Vec<MeshFile>,
    /// The camera, world frame.
    pub camera: Camera,
    /// Lights besides emitting materials.
    #[serde(default)]
    pub lights: Vec<Light>,
    /// Material overrides by material name.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialOverride>,
}

/// One OBJ file placed in the world.
#[derive(Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum MeshFile {
    /// A Wavefront OBJ (with its MTL libraries).
    Obj {
        /// Path, relative to the scene file's directory.
        file: String,
        /// Uniform scale to metres.
        #[serde(default = "one")]
        scale: f64,
        /// World translation after scaling, metres.
        #[serde(default)]
        translate: [f64; 3],
    },
}

fn one() -> f64 {
    1.0
}

/// A light.
#[derive(Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum Light {
    /// A one-sided emitting parallelogram `corner + s edge_u + t edge_v`,
    /// emitting on the side of `edge_u x edge_v`.
    Area {
        /// One corner, world frame, m.
        corner: [f64; 3],
        /// First edge, m.
        edge_u: [f64; 3],
        /// Second edge, m.
        edge_v: [f64; 3],
        /// Emitted radiosity (exitance), W/m² per channel.
        emission: [f64; 3],
    },
    /// A goniometric point light from an EULUMDAT (.ldt) or IES file.
    Goniometric {
        /// Photometric file, relative to the scene file's directory.
        file: String,
        /// Position, world frame, m.
        position: [f64; 3],
        /// Direction the luminaire's nadir points to.
        #[serde(default = "down")]
        nadir: [f64; 3],
        /// Direction of the table's C = 0 half-plane (made perpendicular
        /// to the nadir); default: the mesh frame's x axis made so.
        #[serde(default)]
        c0: Option<[f64; 3]>,
        /// Multiplier on the file's intensities.
        #[serde(default = "one")]
        scale: f64,
    },
}

fn down() -> [f64; 3] {
    [0.0, -1.0, 0.0]
}

/// Changes to one material; absent fields keep the MTL value.
#[derive(Deserialize, Clone, Debug, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct MaterialOverride {
    /// Diffuse reflectance.
    pub diffuse: Option<[f64; 3]>,
    /// Emitted radiosity (exitance), W/m².
    pub emission: Option<[f64; 3]>,
    /// Ideal specular reflectance.
    pub specular_reflectance: Option<[f64; 3]>,
    /// Ideal specular transmittance.
    pub specular_transmittance: Option<[f64; 3]>,
    /// Diffuse transmittance.
    pub diffuse_transmittance: Option<[f64; 3]>,
    /// Alpha mask file.
    pub alpha_map: Option<String>,
    /// Normal map file.
    pub normal_map: Option<String>,
    /// Diffuse texture file.
    pub diffuse_map: Option<String>,
    /// Both faces reflect (leaves, paper): `true` gives each triangle a
    /// reversed twin ([`schemas::mesh::Material::two_sided`]).
    pub two_sided: Option<bool>,
}
