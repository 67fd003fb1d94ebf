//! The textured-floor room of `make bench-mask`: a unit box open at the
//! front (y up), white back wall and ceiling, red left and green right
//! walls, a white block on the floor casting a soft shadow, a square area
//! light under the ceiling, and a floor whose diffuse texture is a
//! checkerboard of `checks` x `checks` squares of sRGB bytes
//! [`DARK`] and [`LIGHT`] (reflectance 0.08 and 0.80): high contrast at a
//! fine scale, the pattern that masks errors in the shadow laid over it
//! (paper 000 Sec. 5.2, Fig. 4). The camera stands inside the box near its
//! open side, looking down at the floor.

use stage_kit::png::encode_png;

/// sRGB byte of the dark checks (linear reflectance 0.08).
pub const DARK: u8 = 79;
/// sRGB byte of the light checks (linear reflectance 0.80).
pub const LIGHT: u8 = 231;
/// Texels per check side in the floor texture (nearest checks stay sharp
/// under bilinear filtering).
const TEXELS_PER_CHECK: usize = 4;
/// The block's extent along x and z, and its height, m.
const BLOCK_X: (f64, f64) = (0.2, 0.5);
const BLOCK_Z: (f64, f64) = (0.35, 0.65);
const BLOCK_HEIGHT: f64 = 0.3;
/// Light exitance, W/m², per channel.
const EXITANCE: f64 = 15.0;

/// The scene's files: name and bytes, all written into one directory.
pub fn files(checks: usize, width: u32, height: u32) -> Result<Vec<(&'static str, Vec<u8>)>, String> {
    if checks == 0 {
        return Err("--checks must be at least 1".into());
    }
    Ok(vec![("checks.png", checkerboard_png(checks)?), ("scene.obj", obj().into_bytes()), ("scene.mtl", MTL.as_bytes().to_vec()), ("scene.ron", scene_ron(width, height).into_bytes())])
}

/// Whether floor texture coordinate `(u, v)` lies on a light check.
pub fn is_light(checks: usize, u: f64, v: f64) -> bool {
    let cell = |t: f64| ((t * checks as f64).floor() as i64).clamp(0, checks as i64 - 1);
    (cell(u) + cell(v)) % 2 == 1
}

/// The checkerboard PNG, `checks * TEXELS_PER_CHECK` texels a side, row 0
/// at v = 1.
fn checkerboard_png(checks: usize) -> Result<Vec<u8>, String> {
    let n = checks * TEXELS_PER_CHECK;
    let texels: Vec<[u8; 3]> = (0..n * n)
        .map(|k| {
            let (u, v) = (((k % n) as f64 + 0.5) / n as f64, 1.0 - ((k / n) as f64 + 0.5) / n as f64);
            [if is_light(checks, u, v) { LIGHT } else { DARK }; 3]
        })
        .collect();
    encode_png(n, n, &texels)
}

/// The materials: the textured floor and the plain walls and block.
const MTL: &str = "newmtl floor\nKd 0.44 0.44 0.44\nmap_Kd -clamp on checks.png\nnewmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.08 0.08\nnewmtl green\nKd 0.1 0.5 0.1\n";

/// A quad `corner, corner + u, corner + u + v, corner + v` (front face
/// along `u x v`) of `material`.
struct Quad {
    material: &'static str,
    corner: [f64; 3],
    u: [f64; 3],
    v: [f64; 3],
}

/// A quad of `material` from its corner and edges.
fn quad(material: &'static str, corner: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Quad {
    Quad { material, corner, u, v }
}

/// The room's quads, front faces inward: floor, ceiling, back, left and
/// right walls.
fn room() -> Vec<Quad> {
    vec![
        quad("floor", [0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        quad("white", [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        quad("white", [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        quad("red", [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        quad("green", [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
    ]
}

/// The block's quads, front faces outward: top, front, back, left, right
/// of the box `[X0, X1] x [0, H] x [Z0, Z1]`.
fn block() -> Vec<Quad> {
    let (dx, dz) = (BLOCK_X.1 - BLOCK_X.0, BLOCK_Z.1 - BLOCK_Z.0);
    let ((x0, x1), (z0, z1), h) = (BLOCK_X, BLOCK_Z, BLOCK_HEIGHT);
    vec![
        quad("white", [x0, h, z0], [0.0, 0.0, dz], [dx, 0.0, 0.0]),
        quad("white", [x0, 0.0, z1], [dx, 0.0, 0.0], [0.0, h, 0.0]),
        quad("white", [x0, 0.0, z0], [0.0, h, 0.0], [dx, 0.0, 0.0]),
        quad("white", [x0, 0.0, z0], [0.0, 0.0, dz], [0.0, h, 0.0]),
        quad("white", [x1, 0.0, z0], [0.0, h, 0.0], [0.0, 0.0, dz]),
    ]
}

/// The OBJ: texture coordinates `(x, z)` on the floor (the first quad's
/// corners take vt 1..4 in order), the others reuse them unread.
fn obj() -> String {
    let mut out = String::from("mtllib scene.mtl\nvt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n");
    for (k, quad) in room().iter().chain(&block()).enumerate() {
        let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
        let corners = [quad.corner, add(quad.corner, quad.u), add(add(quad.corner, quad.u), quad.v), add(quad.corner, quad.v)];
        out += &format!("o quad{k}\nusemtl {}\n", quad.material);
        for p in corners {
            out += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        let first = 4 * k + 1;
        out += &format!("f {}/1 {}/2 {}/3 {}/4\n", first, first + 1, first + 2, first + 3);
    }
    out
}

/// The scene file: the OBJ, the camera at `width` x `height`, the light
/// (a 0.3 m square just under the ceiling, emitting down: `edge_u x
/// edge_v` points along -y).
fn scene_ron(width: u32, height: u32) -> String {
    format!(
        "Scene(meshes: [Obj(file: \"scene.obj\")], camera: Camera(eye: (0.5, 0.75, 0.97), target: (0.5, 0.1, 0.35), up: (0.0, 1.0, 0.0), vertical_fov_deg: 60.0, width: {width}, height: {height}), lights: [Area(corner: (0.35, 0.999, 0.35), edge_u: (0.3, 0.0, 0.0), edge_v: (0.0, 0.0, 0.3), emission: ({EXITANCE:?}, {EXITANCE:?}, {EXITANCE:?}))])"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    }

    /// `(normal . (centre of the quad - inside)) / |normal|`: negative
    /// where the front face looks towards `inside`.
    fn facing(q: &Quad, inside: [f64; 3]) -> f64 {
        let n = cross(q.u, q.v);
        let centre: Vec<f64> = (0..3).map(|k| q.corner[k] + 0.5 * (q.u[k] + q.v[k]) - inside[k]).collect();
        (n[0] * centre[0] + n[1] * centre[1] + n[2] * centre[2]) / (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
    }

    #[test]
    fn the_room_faces_in_the_block_faces_out_and_the_floor_looks_up() {
        // Every room wall is 0.5 m from the box's centre, every block face
        // half the block's side from the block's centre (its top: the height).
        for q in room() {
            assert!((facing(&q, [0.5, 0.5, 0.5]) + 0.5).abs() < 1e-12, "room quad {} at {:?}", q.material, q.corner);
        }
        let centre = [0.5 * (BLOCK_X.0 + BLOCK_X.1), 0.0, 0.5 * (BLOCK_Z.0 + BLOCK_Z.1)];
        let distances = [BLOCK_HEIGHT, 0.15, 0.15, 0.15, 0.15];
        for (q, d) in block().iter().zip(distances) {
            assert!((facing(q, centre) - d).abs() < 1e-12, "block quad at {:?}", q.corner);
        }
        let floor = &room()[0];
        assert_eq!((floor.material, cross(floor.u, floor.v)), ("floor", [0.0, 1.0, 0.0]));
    }

    #[test]
    fn the_texture_alternates_dark_and_light_checks_with_the_stated_reflectances() {
        let linear = |byte: u8| ((f64::from(byte) / 255.0 + 0.055) / 1.055).powf(2.4);
        assert!((linear(DARK) - 0.08).abs() < 2e-3 && (linear(LIGHT) - 0.80).abs() < 2e-3, "{} {}", linear(DARK), linear(LIGHT));
        // 4 checks: the check at (u, v) in [0.25, 0.5) x [0, 0.25) is light, its neighbours dark.
        assert!(is_light(4, 0.3, 0.1) && !is_light(4, 0.1, 0.1) && !is_light(4, 0.3, 0.3) && is_light(4, 0.6, 0.3));
        assert!(!is_light(4, 1.0, 1.0), "u = v = 1 lies in the last check, (3, 3): dark");
        assert!(files(0, 8, 8).is_err());
        let names: Vec<&str> = files(2, 8, 8).unwrap().iter().map(|(n, _)| *n).collect();
        assert_eq!(names, ["checks.png", "scene.obj", "scene.mtl", "scene.ron"]);
    }
}
