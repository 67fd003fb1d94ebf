//! In-memory scenes: meshes built from triangles or quads, a closed box
//! with a light patch, a manifest with given materials (written for
//! gpu-shoot's tests and benchmark, used by any test that solves in
//! memory).

use glam::{DMat3, DVec3};
use schemas::header::{Provenance, Schema};
use schemas::mesh::{Camera, Effects, Manifest, Material, Mesh, MeshStatistics, Triangle};

/// A material with reflectance `rho` and emitted exitance `emission` W/m².
pub fn material(rho: [f64; 3], emission: [f64; 3]) -> Material {
    Material::diffuse("m", rho, emission)
}

/// A manifest with `objects` objects and these materials.
pub fn manifest(objects: usize, materials: Vec<Material>) -> Manifest {
    Manifest {
        header: Manifest::header(Provenance::in_memory("gpu-shoot test")),
        world_from_mesh_translation: [0.0; 3],
        camera: Camera { eye: [0.0, 0.0, 3.0], target: [0.0; 3], up: [0.0, 1.0, 0.0], vertical_fov_deg: 60.0, width: 32, height: 32 },
        materials,
        objects: (0..objects).map(|i| format!("object_{i}")).collect(),
        goniometric_lights: Vec::new(),
        effects: Effects { diffuse_interreflection: true, ..Default::default() },
        statistics: MeshStatistics::default(),
    }
}

/// Builds a mesh from triangles `(corners, material, object)` (front face
/// by the right-hand rule).
pub fn triangles(list: &[([DVec3; 3], u32, u32)]) -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for &(corners, material, object) in list {
        let base = positions.len() as u32;
        positions.extend(corners.map(|p| p.as_vec3().to_array()));
        let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        let (normal, area) = (cross.normalize().as_vec3().to_array(), (cross.length() / 2.0) as f32);
        triangles.push(Triangle { vertices: [base, base + 1, base + 2], material, object, area, normal });
    }
    Mesh { header: Mesh::header(Provenance::in_memory("gpu-shoot test")), positions, triangles }
}

/// Builds a mesh from quads `(corner, edge_u, edge_v, material, object)`,
/// each split into two triangles `[c, c+u, c+u+v]`, `[c, c+u+v, c+v]`
/// (front face: `u x v`).
pub fn quads(quads: &[(DVec3, DVec3, DVec3, u32, u32)]) -> Mesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for &(c, u, v, material, object) in quads {
        let base = positions.len() as u32;
        for p in [c, c + u, c + u + v, c + v] {
            positions.push(p.as_vec3().to_array());
        }
        let normal = u.cross(v).normalize().as_vec3().to_array();
        let area = (u.cross(v).length() / 2.0) as f32;
        triangles.push(Triangle { vertices: [base, base + 1, base + 2], material, object, area, normal });
        triangles.push(Triangle { vertices: [base, base + 2, base + 3], material, object, area, normal });
    }
    Mesh { header: Mesh::header(Provenance::in_memory("gpu-shoot test")), positions, triangles }
}

/// A closed box `[0, s]^3` with inward faces, all of material 0 and
/// object 0, except a `light x light` patch in the middle of the ceiling
/// (material 1, object 1) set into it as its own quad; the rest of the
/// ceiling is four quads around it.
pub fn closed_box(s: f64, light: f64) -> Mesh {
    let (x, y, z) = (DVec3::X * s, DVec3::Y * s, DVec3::Z * s);
    let o = DVec3::ZERO;
    let mut q = vec![
        (o, z, x, 0, 0),         // floor y=0, normal +y
        (o, y, z, 0, 0),         // wall x=0, normal +x
        (x, z, y, 0, 0),         // wall x=s, normal -x
        (o, x, y, 0, 0),         // wall z=0, normal +z
        (z, y, x, 0, 0),         // wall z=s, normal -z
    ];
    // Ceiling y = s, normal -y: quads with u x v = -y, i.e. (u, v) = (x, z).
    let a = (s - light) / 2.0;
    let b = a + light;
    let rect = |x0: f64, x1: f64, z0: f64, z1: f64, m: u32, ob: u32| (DVec3::new(x0, s, z0), DVec3::X * (x1 - x0), DVec3::Z * (z1 - z0), m, ob);
    q.push(rect(0.0, s, 0.0, a, 0, 0));
    q.push(rect(0.0, s, b, s, 0, 0));
    q.push(rect(0.0, a, a, b, 0, 0));
    q.push(rect(b, s, a, b, 0, 0));
    q.push(rect(a, b, a, b, 1, 1));
    quads(&q)
}

/// A unit box `[0, 1]^3` with inward faces and a cube of `side` standing on
/// its floor, its lowest corner at `(corner[0], 0, corner[1])` before it turns by
/// `angle` radians about the vertical through its centre (a turn
/// about +y, right-handed): the floor (material 1, object 0; triangles 0-1), the
/// walls x = 0, x = 1, z = 0, z = 1 and the ceiling (material 0, object 0;
/// triangles 2-11), then the cube's top and its faces towards -x, +x, -z,
/// +z before turning (material 0, object 1; triangles 12-21).
pub fn cube_in_box(corner: [f64; 2], side: f64, angle: f64) -> Mesh {
    let (o, x, y, z) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
    let lo = DVec3::new(corner[0], 0.0, corner[1]);
    let centre = lo + DVec3::new(side / 2.0, 0.0, side / 2.0);
    let turn = |v: DVec3| DMat3::from_rotation_y(angle) * v;
    let at = |p: DVec3| centre + turn(p - centre);
    let (cx, cy, cz) = (turn(x * side), y * side, turn(z * side));
    quads(&[
        (o, z, x, 1, 0), // floor y = 0, normal +y
        (o, y, z, 0, 0), // walls facing in
        (x, z, y, 0, 0),
        (o, x, y, 0, 0),
        (z, y, x, 0, 0),
        (y, x, z, 0, 0),              // ceiling y = 1, normal -y
        (at(lo) + cy, cz, cx, 0, 1),  // the cube's top, normal +y
        (at(lo), cz, cy, 0, 1),       // normal -x before turning
        (at(lo) + cx, cy, cz, 0, 1),  // normal +x
        (at(lo), cy, cx, 0, 1),       // normal -z
        (at(lo) + cz, cx, cy, 0, 1),  // normal +z
    ])
}
