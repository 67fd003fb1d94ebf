//! From a scene to the prepared mesh: place the OBJ files, add area lights,
//! resolve materials, recentre, weld, drop degenerate and duplicate
//! triangles, and list the effects the scene calls for.

use crate::material::{self, default_material};
use crate::obj::{read_obj, TextSource};
use crate::scene::{Light, MeshFile, Scene};
use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use schemas::mesh::{Camera, Effects, GoniometricLight, Material, MeshStatistics, Triangle};
use schemas::Error;
use serde::{Deserialize, Serialize};
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// Knobs of mesh preparation.
///
/// | parameter | meaning | default |
/// |---|---|---|
/// | `weld_tolerance` | vertices closer than this times the scene diagonal merge | 1e-9 |
/// | `degenerate_area` | triangles smaller than this times the squared diagonal are dropped (f32 positions cannot resolve them) | 1e-14 |
/// | `fine_geometry_triangles` | above this many triangles the manifest flags fine geometry for clustering | 10000 |
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Weld distance, relative to the bounding-box diagonal.
    pub weld_tolerance: f64,
    /// Smallest kept area, relative to the squared diagonal.
    pub degenerate_area: f64,
    /// Triangle count above which geometry counts as fine.
    pub fine_geometry_triangles: usize,
}

impl Default for Params {
    fn default() -> Self {
        Params { weld_tolerance: 1e-9, degenerate_area: 1e-14, fine_geometry_triangles: 10_000 }
    }
}

/// The prepared scene: what `mesh.exr` and `manifest.ron` hold, less their
/// headers.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// Vertex positions, mesh frame.
    pub positions: Vec<[f32; 3]>,
    /// Kept triangles.
    pub triangles: Vec<Triangle>,
    /// World position of the mesh frame's origin.
    pub world_from_mesh_translation: [f64; 3],
    /// Camera, mesh frame.
    pub camera: Camera,
    /// Materials.
    pub materials: Vec<Material>,
    /// Object names.
    pub objects: Vec<String>,
    /// Goniometric lights, mesh frame.
    pub goniometric_lights: Vec<GoniometricLight>,
    /// Effects the scene calls for.
    pub effects: Effects,
    /// What preparation did.
    pub statistics: MeshStatistics,
}

impl Prepared {
    /// The two artifacts, stamped with `provenance`.
    pub fn into_artifacts(self, provenance: schemas::header::Provenance) -> (schemas::mesh::Mesh, schemas::mesh::Manifest) {
        use schemas::header::Schema;
        let mesh = schemas::mesh::Mesh { header: schemas::mesh::Mesh::header(provenance.clone()), positions: self.positions, triangles: self.triangles };
        let manifest = schemas::mesh::Manifest {
            header: schemas::mesh::Manifest::header(provenance),
            world_from_mesh_translation: self.world_from_mesh_translation,
            camera: self.camera,
            materials: self.materials,
            objects: self.objects,
            goniometric_lights: self.goniometric_lights,
            effects: self.effects,
            statistics: self.statistics,
        };
        (mesh, manifest)
    }
}

/// A triangle before welding: world corners, material, object.
struct RawTriangle {
    corners: [DVec3; 3],
    material: u32,
    object: u32,
}

/// Prepares `scene`, read from `scene_path` (OBJ paths are relative to its
/// directory), reading files through `source`.
pub fn prepare(scene: &Scene, scene_path: &Path, source: &dyn TextSource, params: &Params) -> Result<Prepared, Error> {
    let base = scene_path.parent().unwrap_or(Path::new(""));
    let mut materials = Vec::new();
    let mut objects = Vec::new();
    let mut raw = Vec::new();
    let mut default_index = None;
    for mesh in &scene.meshes {
        let MeshFile::Obj { file, scale, translate } = mesh;
        let path = base.join(file);
        if !(scale.is_finite() && *scale > 0.0) || !translate.iter().all(|t| t.is_finite()) {
            return Err(Error::invalid(scene_path, None, format!("mesh '{file}': scale must be positive and translate finite")));
        }
        let obj = read_obj(source, &path)?;
        let offset = materials.len() as u32;
        materials.extend(obj.materials.iter().map(material::from_mtl));
        for object in &obj.objects {
            let material = match object.material {
                Some(m) => offset + m as u32,
                None => *default_index.get_or_insert_with(|| {
                    materials.push(default_material());
                    materials.len() as u32 - 1
                }),
            };
            let object_index = objects.len() as u32;
            objects.push(object.name.clone());
            let world = |i: usize| DVec3::from(object.positions[i]) * *scale + DVec3::from(*translate);
            raw.extend(object.triangles.iter().map(|t| RawTriangle { corners: t.map(world), material, object: object_index }));
        }
    }
    let mut goniometric_lights = Vec::new();
    for (k, light) in scene.lights.iter().enumerate() {
        match light {
            Light::Area { corner, edge_u, edge_v, emission } => {
                let (c, u, v) = (DVec3::from(*corner), DVec3::from(*edge_u), DVec3::from(*edge_v));
                materials.push(Material { name: format!("area_light_{k}"), diffuse: [0.0; 3], emission: *emission, ..default_material() });
                objects.push(format!("area_light_{k}"));
                let (material, object) = (materials.len() as u32 - 1, objects.len() as u32 - 1);
                raw.push(RawTriangle { corners: [c, c + u, c + u + v], material, object });
                raw.push(RawTriangle { corners: [c, c + u + v, c + v], material, object });
            }
            Light::Goniometric { file, position, nadir, scale } => {
                let nadir = DVec3::from(*nadir).try_normalize().ok_or_else(|| {
                    Error::invalid(scene_path, None, format!("light {k}: nadir direction is zero"))
                })?;
                goniometric_lights.push(GoniometricLight {
                    file: base.join(file).display().to_string(),
                    position: *position,
                    nadir: nadir.to_array(),
                    scale: *scale,
                });
            }
        }
    }
    for (name, o) in &scene.materials {
        let mut found = false;
        for m in materials.iter_mut().filter(|m| &m.name == name) {
            material::apply(m, o);
            found = true;
        }
        if !found {
            return Err(Error::invalid(scene_path, None, format!("material override '{name}' names no material of the scene")));
        }
    }
    if let Some(problem) = materials.iter().find_map(material::check) {
        return Err(Error::invalid(scene_path, None, problem));
    }
    if raw.is_empty() {
        return Err(Error::invalid(scene_path, None, "the scene has no triangles"));
    }
    let built = build_mesh(&raw, params);
    let Some(built) = built else {
        return Err(Error::invalid(scene_path, None, "every triangle of the scene is degenerate"));
    };
    let origin = built.origin;
    let to_mesh = |p: [f64; 3]| (DVec3::from(p) - origin).to_array();
    let camera = Camera { eye: to_mesh(scene.camera.eye), target: to_mesh(scene.camera.target), ..scene.camera.clone() };
    if Pinhole::new(&camera, camera.width, camera.height).is_none() {
        return Err(Error::invalid(
            scene_path,
            None,
            "camera: eye and target must differ, up must not be parallel to the view, 0 < vertical_fov_deg < 180, width and height > 0",
        ));
    }
    for light in &mut goniometric_lights {
        light.position = to_mesh(light.position);
    }
    let mut statistics = built.statistics;
    statistics.input_triangles = raw.len();
    for t in &built.triangles {
        let m = &materials[t.material as usize];
        let area = f64::from(t.area);
        statistics.total_area += area;
        if m.emission.iter().any(|&e| e > 0.0) {
            statistics.emitting_area += area;
        }
        for c in 0..3 {
            statistics.emitted_power[c] += m.emission[c] * area;
        }
    }
    let effects = effects_of(&built.triangles, &materials, &goniometric_lights, params);
    Ok(Prepared {
        positions: built.positions,
        triangles: built.triangles,
        world_from_mesh_translation: origin.to_array(),
        camera,
        materials,
        objects,
        goniometric_lights,
        effects,
        statistics,
    })
}

struct Built {
    origin: DVec3,
    positions: Vec<[f32; 3]>,
    triangles: Vec<Triangle>,
    statistics: MeshStatistics,
}

/// Recentres, welds and filters the raw triangles. `None` if none is left.
fn build_mesh(raw: &[RawTriangle], params: &Params) -> Option<Built> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in raw.iter().flat_map(|t| t.corners) {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let origin = 0.5 * (lo + hi);
    let diagonal = (hi - lo).length().max(f64::MIN_POSITIVE);
    let cell = params.weld_tolerance * diagonal;
    let mut statistics = MeshStatistics::default();
    let mut index_of: HashMap<[i64; 3], u32> = HashMap::new();
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut weld = |p: DVec3| -> u32 {
        let local = p - origin;
        let key = (local / cell).round().as_i64vec3().to_array();
        *index_of.entry(key).or_insert_with(|| {
            positions.push(local.as_vec3().to_array());
            positions.len() as u32 - 1
        })
    };
    let indexed: Vec<[u32; 3]> = raw.iter().map(|t| t.corners.map(&mut weld)).collect();
    statistics.vertices_welded = raw.len() * 3 - positions.len();
    let min_area = params.degenerate_area * diagonal * diagonal;
    let mut seen = HashSet::new();
    let mut triangles = Vec::with_capacity(raw.len());
    for (t, v) in raw.iter().zip(indexed) {
        let corner = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
        let geometry = TriangleGeometry::new(v.map(corner));
        if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] || geometry.area <= min_area {
            statistics.degenerate_dropped += 1;
            continue;
        }
        // The same three vertices in the same cyclic order: a duplicate.
        // Reversed order is the back of the surface, and is kept.
        let first = (0..3).min_by_key(|&i| v[i]).unwrap_or(0);
        if !seen.insert([v[first], v[(first + 1) % 3], v[(first + 2) % 3]]) {
            statistics.duplicates_dropped += 1;
            continue;
        }
        triangles.push(Triangle {
            vertices: v,
            material: t.material,
            object: t.object,
            area: geometry.area as f32,
            normal: geometry.normal.as_vec3().to_array(),
        });
    }
    if triangles.is_empty() {
        return None;
    }
    statistics.triangles = triangles.len();
    statistics.vertices = positions.len();
    statistics.bounds_min = (lo - origin).to_array();
    statistics.bounds_max = (hi - origin).to_array();
    Some(Built { origin, positions, triangles, statistics })
}

/// Which phenomena the kept triangles' materials and the lights call for.
fn effects_of(triangles: &[Triangle], materials: &[Material], lights: &[GoniometricLight], params: &Params) -> Effects {
    let used: Vec<&Material> = {
        let mut used = vec![false; materials.len()];
        for t in triangles {
            used[t.material as usize] = true;
        }
        materials.iter().zip(used).filter(|(_, u)| *u).map(|(m, _)| m).collect()
    };
    let any = |f: &dyn Fn(&Material) -> bool| used.iter().any(|m| f(m));
    let positive = |v: [f64; 3]| v.iter().any(|&x| x > 0.0);
    let emits = any(&|m| positive(m.emission)) || !lights.is_empty();
    Effects {
        diffuse_interreflection: emits && any(&|m| positive(m.diffuse)),
        diffuse_transmission: any(&|m| positive(m.diffuse_transmittance)),
        specular_reflection: any(&|m| positive(m.specular_reflectance)),
        specular_transmission: any(&|m| positive(m.specular_transmittance)),
        goniometric_lights: !lights.is_empty(),
        alpha_masks: any(&|m| m.alpha_map.is_some()),
        normal_maps: any(&|m| m.normal_map.is_some()),
        textures: any(&|m| m.diffuse_map.is_some()),
        fine_clustered_geometry: triangles.len() > params.fine_geometry_triangles,
    }
}
