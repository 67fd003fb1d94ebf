//! From a scene to the prepared mesh: place the OBJ files, add area lights,
//! resolve materials, recentre, weld, drop degenerate and duplicate
//! triangles, and list the effects the scene calls for.

use crate::lighting::{self, Emitter};
use crate::material::{self, default_material};
use crate::mtl::MtlMaterial;
use crate::surface::{Corners, MapSource, Maps};
use crate::obj::{read_obj, TextSource};
use crate::text::locate;
use crate::scene::{Light, MeshFile, Scene};
use glam::DVec3;
use stage_kit::scene::pinhole;
use radiometry::bounds::Aabb;
use radiometry::geometry::TriangleGeometry;
use schemas::mesh::{cyclic, reversed, Camera, Effects, GoniometricLight, Material, MeshStatistics, Triangle};
use schemas::Error;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};

stage_kit::knobs! {
    /// Knobs of mesh preparation.
    pub struct Params {
        /// Weld vertices closer than this times the scene's diagonal.
        weld_tolerance: f64 = 1e-9, "diagonal", value(positive());
        /// Drop triangles of this area or less, times the squared diagonal (f32 positions cannot resolve smaller ones).
        degenerate_area: f64 = 1e-14, "diagonal²", value(at_least(0.0));
        /// Flag the geometry as fine (for clustering) above this many triangles.
        fine_geometry_triangles: usize = 10_000, "triangles", value;
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
    /// What the user should hear of, one line each (non-UTF-8 text, unknown
    /// materials, texture options not honoured, emitters that light nothing).
    pub warnings: Vec<String>,
    /// The surface artifact's tables (texture coordinates, shading normals,
    /// tangents, textures).
    pub surface: crate::surface::Built,
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

    /// The surface artifact, stamped with `provenance`.
    pub fn surface_artifact(&self, provenance: schemas::header::Provenance) -> schemas::surface::Surface {
        use schemas::header::Schema;
        let s = &self.surface;
        schemas::surface::Surface {
            header: schemas::surface::Surface::header(provenance),
            uvs: s.uvs.clone(),
            shading_normals: s.shading_normals.clone(),
            tangents: s.tangents.clone(),
            material_maps: s.material_maps.clone(),
            textures: s.textures.clone(),
        }
    }
}

/// Largest world coordinate accepted, m: far beyond any scene, and far
/// inside single precision (3.4e38), which the mesh is stored in.
const MAX_COORDINATE: f64 = 1e30;

/// A triangle before welding: world corners, material, object, and its
/// corners' texture coordinates and shading normals.
struct RawTriangle {
    corners: [DVec3; 3],
    material: u32,
    object: u32,
    attributes: Corners,
}

/// Where an object or material comes from: the file and line that define
/// it, for messages that name it.
#[derive(Clone, Debug)]
struct Origin {
    file: PathBuf,
    line: Option<usize>,
}

impl Origin {
    fn error(&self, message: impl Into<String>) -> Error {
        Error::invalid(&self.file, self.line, message)
    }

    fn at(&self) -> String {
        match self.line {
            Some(line) => format!("{}:{line}", self.file.display()),
            None => self.file.display().to_string(),
        }
    }
}

/// Prepares `scene`, read from `scene_path` (OBJ paths are relative to its
/// directory), reading files through `source`.
pub fn prepare(scene: &Scene, scene_path: &Path, source: &dyn TextSource, params: &Params) -> Result<Prepared, Error> {
    let base = scene_path.parent().unwrap_or(Path::new(""));
    let mut materials = Vec::new();
    let mut maps: Vec<Maps> = Vec::new();
    let mut material_origins = Vec::new();
    let mut objects = Vec::new();
    let mut object_origins = Vec::new();
    let mut raw = Vec::new();
    let mut warnings = Vec::new();
    let mut default_index = None;
    for mesh in &scene.meshes {
        let MeshFile::Obj { file, scale, translate } = mesh;
        let path = base.join(file);
        if !(scale.is_finite() && *scale > 0.0 && translate.iter().all(|t| t.is_finite())) {
            return Err(Error::invalid(scene_path, None, format!("mesh '{file}': scale must be positive and translate finite")));
        }
        let obj = read_obj(source, &path)?;
        warnings.extend(obj.notes.iter().cloned());
        let offset = materials.len() as u32;
        maps.extend(texture_maps(source, &obj.materials, &mut warnings)?);
        materials.extend(obj.materials.iter().map(material::from_mtl));
        material_origins.extend(obj.materials.iter().map(|m| Origin { file: m.file.clone(), line: Some(m.line) }));
        for object in &obj.objects {
            let material = match object.material {
                Some(m) => offset + m as u32,
                None => *default_index.get_or_insert_with(|| {
                    materials.push(default_material());
                    maps.push(Maps::default());
                    material_origins.push(Origin { file: path.clone(), line: None });
                    materials.len() as u32 - 1
                }),
            };
            let object_index = objects.len() as u32;
            objects.push(object.name.clone());
            object_origins.push(Origin { file: path.clone(), line: object.lines.first().copied() });
            for (k, (t, line)) in object.triangles.iter().zip(&object.lines).enumerate() {
                let corners = t.map(|i| DVec3::from(obj.positions[i]) * *scale + DVec3::from(*translate));
                if let Some(c) = corners.iter().find(|c| !c.is_finite() || c.abs().max_element() > MAX_COORDINATE) {
                    let what = format!(
                        "object '{}': a corner lies at {:?} once placed (its mesh entry's scale and translate): not a finite position within {MAX_COORDINATE:e} m",
                        object.name,
                        c.to_array()
                    );
                    return Err(Error::invalid(&path, Some(*line), what));
                }
                let attributes = Corners {
                    uv: object.uv_triangles[k].map(|c| c.map(|i| obj.uvs[i])),
                    // A uniform positive scale and a translation leave normals as they are.
                    normal: object.normal_triangles[k].map(|c| c.map(|i| obj.normals[i])),
                };
                raw.push(RawTriangle { corners, material, object: object_index, attributes });
            }
        }
    }
    let mut goniometric_lights = Vec::new();
    for (k, light) in scene.lights.iter().enumerate() {
        match light {
            Light::Area { corner, edge_u, edge_v, emission } => {
                let (c, u, v) = (DVec3::from(*corner), DVec3::from(*edge_u), DVec3::from(*edge_v));
                let name = format!("area_light_{k}");
                let refuse = |what: String| Error::invalid(scene_path, None, format!("light {k} (Area, '{name}'): {what}"));
                for (field, value) in [("corner", c), ("edge_u", u), ("edge_v", v)] {
                    if !value.is_finite() {
                        return Err(refuse(format!("{field} {:?} is not finite", value.to_array())));
                    }
                }
                if u.cross(v).length() == 0.0 {
                    return Err(refuse("edge_u and edge_v span no area (zero or parallel edges)".into()));
                }
                materials.push(Material { name: name.clone(), diffuse: [0.0; 3], emission: *emission, ..default_material() });
                maps.push(Maps::default());
                material_origins.push(Origin { file: scene_path.to_path_buf(), line: None });
                objects.push(name);
                object_origins.push(Origin { file: scene_path.to_path_buf(), line: None });
                let (material, object) = (materials.len() as u32 - 1, objects.len() as u32 - 1);
                let attributes = Corners::default();
                raw.push(RawTriangle { corners: [c, c + u, c + u + v], material, object, attributes });
                raw.push(RawTriangle { corners: [c, c + u + v, c + v], material, object, attributes });
            }
            Light::Goniometric { file, position, nadir, c0, scale } => {
                let placement = crate::photometry::Placement { file: file.clone(), position: *position, nadir: *nadir, c0: *c0, scale: *scale };
                goniometric_lights.push(crate::photometry::read_light(source, scene_path, k, &placement, &mut warnings)?);
            }
        }
    }
    for (name, o) in &scene.materials {
        let mut found = false;
        for ((m, origin), maps) in materials.iter_mut().zip(&mut material_origins).zip(&mut maps).filter(|((m, _), _)| &m.name == name) {
            material::apply(m, o);
            for (slot, file) in [&o.diffuse_map, &o.alpha_map, &o.normal_map].into_iter().enumerate() {
                if let Some(file) = file {
                    maps[slot] = Some(crate::surface::override_map(scene_path, file));
                }
            }
            *origin = Origin { file: scene_path.to_path_buf(), line: None };
            found = true;
        }
        if !found {
            return Err(Error::invalid(scene_path, None, format!("material override '{name}' names no material of the scene")));
        }
    }
    if let Some((problem, origin)) = materials.iter().zip(&material_origins).find_map(|(m, o)| Some((material::check(m)?, o))) {
        return Err(origin.error(problem));
    }
    if raw.is_empty() {
        return Err(Error::invalid(scene_path, None, "the scene has no triangles"));
    }
    let two_sided: Vec<bool> = materials.iter().map(|m| m.two_sided).collect();
    let built = build_mesh(&raw, &two_sided, params);
    let Some(built) = built else {
        return Err(Error::invalid(scene_path, None, "every triangle of the scene is degenerate"));
    };
    let emitters = emitters(&raw, &built.triangles, &materials, &objects, &object_origins)?;
    warnings.extend(lighting::check_emitters(&built.positions, &built.triangles, &emitters));
    let origin = built.origin;
    let to_mesh = |p: [f64; 3]| (DVec3::from(p) - origin).to_array();
    let camera = Camera { eye: to_mesh(scene.camera.eye), target: to_mesh(scene.camera.target), ..scene.camera.clone() };
    if pinhole(&camera, camera.width, camera.height).is_none() {
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
    let surface = crate::surface::build(source, &built.positions, &built.triangles, &built.attributes, &materials, &maps, &mut warnings)?;
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
        warnings,
        surface,
    })
}

/// The emitters of the scene, one per object and emitting material, with
/// their kept triangles; an error naming the emitter if one has no area
/// left (every triangle degenerate), which would otherwise vanish into the
/// count of degenerate triangles.
fn emitters(raw: &[RawTriangle], kept: &[Triangle], materials: &[Material], objects: &[String], origins: &[Origin]) -> Result<Vec<Emitter>, Error> {
    let emits = |m: u32| materials[m as usize].emission.iter().any(|&e| e > 0.0);
    let mut groups: BTreeMap<(u32, u32), (usize, Vec<u32>)> = BTreeMap::new();
    for t in raw.iter().filter(|t| emits(t.material)) {
        groups.entry((t.object, t.material)).or_default().0 += 1;
    }
    for (i, t) in kept.iter().enumerate().filter(|(_, t)| emits(t.material)) {
        groups.entry((t.object, t.material)).or_default().1.push(i as u32);
    }
    let mut out = Vec::with_capacity(groups.len());
    for ((object, material), (input, triangles)) in groups {
        let origin = &origins[object as usize];
        let label = format!("emitter '{}' (material '{}', {})", objects[object as usize], materials[material as usize].name, origin.at());
        if triangles.is_empty() {
            return Err(origin.error(format!("{label} has zero area: all {input} of its triangles are degenerate")));
        }
        out.push(Emitter { label, triangles });
    }
    Ok(out)
}

/// The maps of each MTL material: every texture it names, found relative
/// to its library's folder as [`locate`] finds it (read later, and so
/// recorded, if a kept triangle uses the material). A texture that does
/// not exist is an error naming the MTL line and the material; options
/// not honoured get a warning.
fn texture_maps(source: &dyn TextSource, materials: &[MtlMaterial], warnings: &mut Vec<String>) -> Result<Vec<Maps>, Error> {
    let mut all = Vec::with_capacity(materials.len());
    for m in materials {
        let base = m.file.parent().unwrap_or(Path::new(""));
        let mut maps = Maps::default();
        for (slot, texture) in [&m.diffuse_texture, &m.dissolve_texture, &m.normal_texture].into_iter().enumerate() {
            let Some(texture) = texture else { continue };
            if !texture.ignored.is_empty() {
                warnings.push(format!("{}:{}: texture '{}': options not honoured: {}", m.file.display(), texture.line, texture.name, texture.ignored.join(", ")));
            }
            let path = locate(source, base, &texture.name).ok_or_else(|| {
                Error::invalid(&m.file, Some(texture.line), format!("material '{}': texture '{}' does not exist", m.name, base.join(&texture.name).display()))
            })?;
            maps[slot] = Some(MapSource { path, texture: texture.clone() });
        }
        all.push(maps);
    }
    Ok(all)
}

struct Built {
    origin: DVec3,
    positions: Vec<[f32; 3]>,
    triangles: Vec<Triangle>,
    /// Each kept triangle's corner attributes.
    attributes: Vec<Corners>,
    statistics: MeshStatistics,
}

/// Recentres, welds and filters the raw triangles, and gives every kept
/// triangle of a two-sided material (`two_sided[material]`) its twin, the
/// same vertices wound the other way, appended after the input's
/// triangles. `None` if none is left.
fn build_mesh(raw: &[RawTriangle], two_sided: &[bool], params: &Params) -> Option<Built> {
    let bounds = Aabb::around(raw.iter().flat_map(|t| t.corners));
    let origin = bounds.centre();
    let diagonal = (bounds.max - bounds.min).length().max(f64::MIN_POSITIVE);
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
    let mut attributes = Vec::with_capacity(raw.len());
    for (t, v) in raw.iter().zip(indexed) {
        let corner = |i: u32| DVec3::from(positions[i as usize].map(f64::from));
        let geometry = TriangleGeometry::new(v.map(corner));
        if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] || geometry.area <= min_area {
            statistics.degenerate_dropped += 1;
            continue;
        }
        // The same three vertices in the same cyclic order: a duplicate.
        // Reversed order is the back of the surface, and is kept, except
        // for a two-sided triangle, whose back is its twin: one whose
        // front or back is already taken is a duplicate, and it takes both.
        let (face, back) = (cyclic(v), cyclic(reversed(v)));
        let both = two_sided[t.material as usize];
        if seen.contains(&face) || (both && seen.contains(&back)) {
            statistics.duplicates_dropped += 1;
            continue;
        }
        seen.insert(face);
        if both {
            seen.insert(back);
        }
        triangles.push(Triangle {
            vertices: v,
            material: t.material,
            object: t.object,
            area: geometry.area as f32,
            normal: geometry.normal.as_vec3().to_array(),
        });
        attributes.push(t.attributes);
    }
    if triangles.is_empty() {
        return None;
    }
    let twins: Vec<Triangle> = triangles
        .iter()
        .filter(|t| two_sided[t.material as usize])
        .map(|t| Triangle { vertices: reversed(t.vertices), normal: t.normal.map(|n| -n), ..*t })
        .collect();
    statistics.two_sided_twins = twins.len();
    let twin_attributes: Vec<Corners> = triangles.iter().zip(&attributes).filter(|(t, _)| two_sided[t.material as usize]).map(|(_, a)| a.reversed()).collect();
    triangles.extend(twins);
    attributes.extend(twin_attributes);
    statistics.triangles = triangles.len();
    statistics.vertices = positions.len();
    statistics.bounds_min = (bounds.min - origin).to_array();
    statistics.bounds_max = (bounds.max - origin).to_array();
    Some(Built { origin, positions, triangles, attributes, statistics })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::Memory;

    /// A closed 1 m box, walls facing in (or out, `inward` false), one
    /// material; `skip` leaves out the faces whose statements contain it.
    fn room(inward: bool, skip: Option<&str>) -> String {
        let faces = ["1 2 3 4", "5 8 7 6", "1 5 6 2", "4 3 7 8", "1 4 8 5", "2 6 7 3"];
        let mut obj = String::from("mtllib m.mtl\nusemtl wall\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n");
        for f in faces.iter().filter(|f| Some(**f) != skip) {
            let order: Vec<&str> = if inward { f.split(' ').collect() } else { f.split(' ').rev().collect() };
            obj += &format!("f {}\n", order.join(" "));
        }
        obj
    }

    /// Prepares `obj` (with a grey MTL and an emitting one) under a scene
    /// whose `lights` list is given as RON.
    fn prepare_with(obj: &str, lights: &str) -> Result<Prepared, Error> {
        let scene = format!(
            "Scene(meshes: [Obj(file: \"a.obj\")], camera: Camera(eye: (0.5, 0.5, 0.05), target: (0.5, 0.5, 1.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: 60.0, width: 8, height: 8), lights: [{lights}])"
        );
        let source = Memory::text(&[("s/scene.ron", &scene), ("s/a.obj", obj), ("s/m.mtl", "newmtl wall\nKd 0.5\n\nnewmtl glow\nKd 0\nKe 10\n")]);
        let path = Path::new("s/scene.ron");
        prepare(&crate::read_scene(&source, path)?, path, &source, &Params::default())
    }

    const DOWN: &str = "Area(corner: (0.4, 0.995, 0.4), edge_u: (0.2, 0.0, 0.0), edge_v: (0.0, 0.0, 0.2), emission: (10.0, 10.0, 10.0))";
    const UP: &str = "Area(corner: (0.4, 0.995, 0.4), edge_u: (0.0, 0.0, 0.2), edge_v: (0.2, 0.0, 0.0), emission: (10.0, 10.0, 10.0))";

    #[test]
    fn a_light_that_lights_the_room_gets_no_word() {
        let prepared = prepare_with(&room(true, None), DOWN).unwrap();
        assert!(prepared.warnings.is_empty(), "{:?}", prepared.warnings);
    }

    /// Issue 11: a light wound the wrong way under a ceiling lit the room
    /// 44x darker through the gap, with no word.
    #[test]
    fn a_light_wound_into_the_ceiling_is_named() {
        let warnings = prepare_with(&room(true, None), UP).unwrap().warnings;
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        let w = &warnings[0];
        assert!(w.starts_with("emitter 'area_light_0' (material 'area_light_0', s/scene.ron): half the rays from its front hit a surface within 0.0"), "{w}");
        assert!(w.contains("is it wound the wrong way?"), "{w}");
        // The back sees the floor and the walls, 0.5 to 1.5 m away.
        let back: f64 = w.split("travel over ").nth(1).and_then(|r| r.split(' ').next()).and_then(|x| x.parse().ok()).unwrap();
        assert!((0.5..1.5).contains(&back), "{w}");
    }

    #[test]
    fn a_light_shining_into_back_faces_is_named() {
        let warnings = prepare_with(&room(false, None), DOWN).unwrap().warnings;
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains(": 100% of the rays from its front hit the back of a surface; is it wound the wrong way?"), "{}", warnings[0]);
    }

    #[test]
    fn a_light_facing_out_of_an_open_box_is_named() {
        let open_top = room(true, Some("4 3 7 8"));
        let warnings = prepare_with(&open_top, UP).unwrap().warnings;
        assert_eq!(warnings, ["emitter 'area_light_0' (material 'area_light_0', s/scene.ron) faces away from every surface: all 256 rays from its front leave the scene"]);
        let sideways = "Area(corner: (0.5, 0.3, 0.3), edge_u: (0.0, 0.3, 0.0), edge_v: (0.0, 0.0, 0.3), emission: (1.0, 1.0, 1.0))";
        let warnings = prepare_with(&open_top, sideways).unwrap().warnings;
        assert!(warnings.is_empty(), "a light facing a wall of the open box lights it: {warnings:?}");
    }

    #[test]
    fn zero_area_and_non_finite_lights_are_errors_naming_them() {
        let error = |lights: &str| prepare_with(&room(true, None), lights).err().map(|e| e.to_string());
        let flat = "Area(corner: (0.4, 0.9, 0.4), edge_u: (0.2, 0.0, 0.0), edge_v: (0.4, 0.0, 0.0), emission: (1.0, 1.0, 1.0))";
        assert_eq!(error(flat).as_deref(), Some("s/scene.ron: light 0 (Area, 'area_light_0'): edge_u and edge_v span no area (zero or parallel edges)"));
        let nan = format!("{DOWN}, Area(corner: (0.4, NaN, 0.4), edge_u: (0.2, 0.0, 0.0), edge_v: (0.0, 0.0, 0.2), emission: (1.0, 1.0, 1.0))");
        assert_eq!(error(&nan).as_deref(), Some("s/scene.ron: light 1 (Area, 'area_light_1'): corner [0.4, NaN, 0.4] is not finite"));
        let tiny = "Area(corner: (0.4, 0.9, 0.4), edge_u: (1e-9, 0.0, 0.0), edge_v: (0.0, 0.0, 1e-9), emission: (1.0, 1.0, 1.0))";
        assert_eq!(error(tiny).as_deref(), Some("s/scene.ron: emitter 'area_light_0' (material 'area_light_0', s/scene.ron) has zero area: all 2 of its triangles are degenerate"));
        let lamp = format!("{}o lamp\nusemtl glow\nv 0.2 0.5 0.5\nv 0.4 0.5 0.5\nv 0.6 0.5 0.5\nf -3 -2 -1\n", room(true, None));
        let message = prepare_with(&lamp, "").err().map(|e| e.to_string());
        assert_eq!(message.as_deref(), Some("s/a.obj:22: emitter 'lamp' (material 'glow', s/a.obj:22) has zero area: all 1 of its triangles are degenerate"));
    }

    /// A weld cell of zero width keys every vertex by the sign of its
    /// coordinates (`x / 0`), so the knobs are checked before any work.
    #[test]
    fn knobs_out_of_range_are_refused_naming_the_knob_and_value() {
        use stage_kit::knobs::Knobs;
        let error = |p: Params| p.check("").err().map(|e| e.to_string());
        assert_eq!(error(Params::default()), None);
        assert_eq!(error(Params { weld_tolerance: 0.0, ..Params::default() }).as_deref(), Some("parameters: weld_tolerance must be a positive number, not 0"));
        assert_eq!(error(Params { weld_tolerance: f64::NAN, ..Params::default() }).as_deref(), Some("parameters: weld_tolerance must be a positive number, not NaN"));
        assert_eq!(error(Params { degenerate_area: -1e-14, ..Params::default() }).as_deref(), Some("parameters: degenerate_area must be at least 0, not -0.00000000000001"));
        assert_eq!(error(Params { degenerate_area: 0.0, ..Params::default() }), None);
    }

    #[test]
    fn a_corner_beyond_single_precision_when_scaled_is_named_by_line() {
        let source = Memory::text(&[
            ("scene.ron", "Scene(meshes: [Obj(file: \"a.obj\", scale: 1e35)], camera: Camera(eye: (0.0, 0.0, -1.0), target: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: 60.0, width: 8, height: 8))"),
            ("a.obj", "o big\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ]);
        let path = Path::new("scene.ron");
        let error = prepare(&crate::read_scene(&source, path).unwrap(), path, &source, &Params::default()).unwrap_err();
        assert_eq!(error.to_string(), "a.obj:5: object 'big': a corner lies at [1e35, 0.0, 0.0] once placed (its mesh entry's scale and translate): not a finite position within 1e30 m");
    }
}
