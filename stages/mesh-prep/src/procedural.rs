//! Procedural scenes, sized by a triangle count, written as OBJ and scene
//! text and then read by the same code as user files. They measure how the
//! pipeline scales (10k to 1M triangles) and check it against closed forms.
//!
//! - `plants`: a 6 x 6 x 3 m room lit by a ceiling panel, with plants of
//!   thin, randomly oriented leaves (paper 000's kind of scene: most light
//!   arrives at clusters of foliage).
//! - `sphere`: an integrating sphere (geodesic), radius 1 m, inward
//!   normals, uniform reflectance 0.5, one emitting cap: every other
//!   surface has the same radiosity in closed form.
//! - `box`: a closed 1 m box, walls finely tessellated, uniform reflectance
//!   0.8, an emitting square in the ceiling.
//! - `cornell-box` with a size: the built-in Cornell box with every
//!   triangle split 1:4 until it has at least that many.
//! - `simple-environment`: paper 002's "simple" environment (Sec. 2.3,
//!   Table 1), a light, a receiver A opposite it and a receiver B beside
//!   the light that only A lights ([`SimpleEnvironment`]).

use radiometry::sampling::Stream;
use std::f64::consts::PI;
use std::fmt::Write as _;

/// OBJ text under construction.
#[derive(Default)]
pub struct ObjWriter {
    text: String,
    vertices: usize,
}

impl ObjWriter {
    /// Starts object `name` with material `material`.
    pub fn object(&mut self, name: &str, material: &str) {
        let _ = writeln!(self.text, "o {name}\nusemtl {material}");
    }

    /// Adds a polygon (3 or 4 corners, counter-clockwise seen from its front).
    pub fn polygon(&mut self, corners: &[[f64; 3]]) {
        for p in corners {
            let _ = writeln!(self.text, "v {} {} {}", p[0], p[1], p[2]);
        }
        self.text.push('f');
        for k in 0..corners.len() {
            let _ = write!(self.text, " {}", self.vertices + k + 1);
        }
        self.text.push('\n');
        self.vertices += corners.len();
    }

    /// The OBJ text, with its material library line.
    pub fn finish(self, library: &str) -> String {
        format!("mtllib {library}\n{}", self.text)
    }
}

/// A grid of `n x n` quads over the parallelogram `origin + s u + t v`.
fn grid(obj: &mut ObjWriter, origin: [f64; 3], u: [f64; 3], v: [f64; 3], n: usize) {
    let at = |s: f64, t: f64| [0, 1, 2].map(|k| origin[k] + s * u[k] + t * v[k]);
    let step = 1.0 / n as f64;
    for i in 0..n {
        for j in 0..n {
            let (s, t) = (i as f64 * step, j as f64 * step);
            obj.polygon(&[at(s, t), at(s + step, t), at(s + step, t + step), at(s, t + step)]);
        }
    }
}

/// The six inward faces of the box `[0, size]^3` as `(origin, u, v)` with
/// `u x v` pointing into the box; the ceiling (z = size) last.
fn box_faces(size: f64) -> [([f64; 3], [f64; 3], [f64; 3]); 6] {
    let s = size;
    [
        ([0.0, 0.0, 0.0], [s, 0.0, 0.0], [0.0, s, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, s], [s, 0.0, 0.0]),
        ([0.0, s, 0.0], [s, 0.0, 0.0], [0.0, 0.0, s]),
        ([0.0, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]),
        ([s, 0.0, 0.0], [0.0, 0.0, s], [0.0, s, 0.0]),
        ([0.0, 0.0, s], [0.0, s, 0.0], [s, 0.0, 0.0]),
    ]
}

/// A closed room of side `size` with walls of about `wall_triangles`
/// triangles in all, the ceiling's middle ninth emitting.
fn room(obj: &mut ObjWriter, size: f64, wall_triangles: usize, wall: &str, lamp: &str) {
    let n = ((wall_triangles as f64 / 12.0).sqrt().round() as usize).max(1);
    let faces = box_faces(size);
    for (k, (o, u, v)) in faces.iter().enumerate().take(5) {
        obj.object(&format!("wall{k}"), wall);
        grid(obj, *o, *u, *v, n);
    }
    // Ceiling: 3 x 3 panels, the middle one the lamp, each panel n/3 quads a side.
    let (o, u, v) = faces[5];
    let m = (n / 3).max(1);
    for i in 0..3 {
        for j in 0..3 {
            let lamp_panel = (i, j) == (1, 1);
            obj.object(if lamp_panel { "lamp" } else { "ceiling" }, if lamp_panel { lamp } else { wall });
            let origin = [0, 1, 2].map(|k| o[k] + u[k] * i as f64 / 3.0 + v[k] * j as f64 / 3.0);
            grid(obj, origin, u.map(|x| x / 3.0), v.map(|x| x / 3.0), m);
        }
    }
}

fn scene_text(obj_file: &str, eye: [f64; 3], target: [f64; 3], up: [f64; 3], fov: f64) -> String {
    format!(
        "Scene(\n  meshes: [Obj(file: \"{obj_file}\")],\n  camera: Camera(eye: ({}, {}, {}), target: ({}, {}, {}), up: ({}, {}, {}), vertical_fov_deg: {fov}, width: 256, height: 256),\n)\n",
        eye[0], eye[1], eye[2], target[0], target[1], target[2], up[0], up[1], up[2]
    )
}

/// Paper 002's "simple" environment (Sec. 2.2-2.3, Figure 1, Table 1): a
/// square diffuse light LS on the floor plane facing up, a receiver A on
/// the ceiling plane directly opposite it facing down, and a receiver B on
/// the floor plane beside LS facing up. LS and B are coplanar, so B gets no
/// light from LS directly, only what A reflects: the paper's one-bounce
/// configuration (as in the end-to-end tests' `one_bounce` scene, at the
/// paper's sizes). World frame: metres, z up; planes z = 0 and z = `height`.
///
/// Table 1 gives areas, power, "aspect ratio 2.2", "offset of LS 1.2" and
/// 200 x 200 pixels; the paper is ambiguous about the rest, so this is a
/// fixed choice:
/// - LS is a 3 x 3 square (area 9) centred on the origin; A and B are 5 x 5
///   squares (area 25).
/// - "Aspect ratio" is read as Howell's dimensionless ratio for parallel
///   plates (side over separation, X = a / c, [SiHo72] being the paper's
///   source of configuration factors): A's side 5 over the planes'
///   separation, so `height` = 5 / 2.2.
/// - "Offset of LS" is read as the gap between LS's edge and B's edge in
///   their common plane: B spans x in [1.5 + 1.2, 1.5 + 1.2 + 5].
/// - A is centred over LS ("directly opposing" it, Sec. 2.2).
/// - Power 12 per channel over area 9: exitance 12 / 9 W/m² per channel.
///   LS is black (it reflects nothing of what A sends back).
/// - Reflectances, which the paper does not give: 0.8 grey for A and B
///   (white paint), so that the reflected light the paper studies is as
///   large as a plain diffuse surface makes it.
/// - Camera (200 x 200, 80 degrees vertical field of view): between the
///   planes at mid-height, 2 m in front of A's and B's near edges
///   (y = -2.5), looking along +y at the middle of LS, the gap and B: the
///   whole depth of both receivers' fronts is in view (their near corners
///   leave it at the sides), about 27% of the pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimpleEnvironment {
    /// LS's corners, counter-clockwise seen from its front (+z), m.
    pub light: [[f64; 3]; 4],
    /// A's corners, counter-clockwise seen from its front (-z), m.
    pub a: [[f64; 3]; 4],
    /// B's corners, counter-clockwise seen from its front (+z), m.
    pub b: [[f64; 3]; 4],
    /// LS's emitted radiosity (exitance), W/m² per channel.
    pub emission: f64,
    /// A's diffuse reflectance.
    pub rho_a: f64,
    /// B's diffuse reflectance.
    pub rho_b: f64,
    /// The separation of the two planes, m.
    pub height: f64,
}

const SIMPLE_HEIGHT: f64 = 5.0 / 2.2;

/// The simple environment's fixed geometry ([`SimpleEnvironment`]).
pub const SIMPLE_ENVIRONMENT: SimpleEnvironment = SimpleEnvironment {
    light: [[-1.5, -1.5, 0.0], [1.5, -1.5, 0.0], [1.5, 1.5, 0.0], [-1.5, 1.5, 0.0]],
    a: [[-2.5, -2.5, SIMPLE_HEIGHT], [-2.5, 2.5, SIMPLE_HEIGHT], [2.5, 2.5, SIMPLE_HEIGHT], [2.5, -2.5, SIMPLE_HEIGHT]],
    b: [[2.7, -2.5, 0.0], [7.7, -2.5, 0.0], [7.7, 2.5, 0.0], [2.7, 2.5, 0.0]],
    emission: 12.0 / 9.0,
    rho_a: 0.8,
    rho_b: 0.8,
    height: SIMPLE_HEIGHT,
};

/// The simple environment as `(scene, obj, mtl)`: objects `LS`, `A`, `B`
/// (materials `light`, `upper`, `lower`), LS's exitance set in the scene
/// file (MTL's `Ke` is radiance).
pub fn simple_environment() -> (String, String, String) {
    let s = SIMPLE_ENVIRONMENT;
    let mut obj = ObjWriter::default();
    for (name, material, corners) in [("LS", "light", s.light), ("A", "upper", s.a), ("B", "lower", s.b)] {
        obj.object(name, material);
        obj.polygon(&corners);
    }
    let mtl = format!("newmtl light\nKd 0 0 0\n\nnewmtl upper\nKd {a} {a} {a}\n\nnewmtl lower\nKd {b} {b} {b}\n", a = s.rho_a, b = s.rho_b);
    let (mid, e) = (0.5 * s.height, s.emission);
    let scene = format!(
        "Scene(\n  meshes: [Obj(file: \"simple.obj\")],\n  camera: Camera(eye: (2.6, -4.5, {mid:?}), target: (2.6, 0.0, {mid:?}), up: (0.0, 0.0, 1.0), vertical_fov_deg: 80.0, width: 200, height: 200),\n  materials: {{ \"light\": (emission: Some(({e:?}, {e:?}, {e:?}))) }},\n)\n"
    );
    (scene, obj.finish("simple.mtl"), mtl)
}

/// The closed box of `triangles` triangles: `(scene, obj, mtl)`.
pub fn closed_box(triangles: usize) -> (String, String, String) {
    let mut obj = ObjWriter::default();
    room(&mut obj, 1.0, triangles, "wall", "lamp");
    let mtl = "newmtl wall\nKd 0.8 0.8 0.8\n\nnewmtl lamp\nKd 0.8 0.8 0.8\nKe 10 10 10\n".to_string();
    (scene_text("box.obj", [0.5, 0.05, 0.5], [0.5, 1.0, 0.5], [0.0, 0.0, 1.0], 90.0), obj.finish("box.mtl"), mtl)
}

/// The integrating sphere of at least `triangles` triangles: a geodesic
/// sphere (an icosahedron split 1:4 and pushed onto the unit sphere), whose
/// triangles are all nearly equilateral: a UV sphere's slivers at the poles
/// were measured to break the closed form by 18% next to a polar lamp. The
/// triangles within 14 degrees of the +z pole emit; normals point inward.
pub fn sphere(triangles: usize) -> (String, String, String) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices: Vec<[f64; 3]> = [
        [-1.0, t, 0.0], [1.0, t, 0.0], [-1.0, -t, 0.0], [1.0, -t, 0.0],
        [0.0, -1.0, t], [0.0, 1.0, t], [0.0, -1.0, -t], [0.0, 1.0, -t],
        [t, 0.0, -1.0], [t, 0.0, 1.0], [-t, 0.0, -1.0], [-t, 0.0, 1.0],
    ]
    .map(normalize)
    .to_vec();
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
        [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
    ];
    while faces.len() < triangles {
        let mut midpoints = std::collections::HashMap::new();
        let mut midpoint = |a: usize, b: usize, vertices: &mut Vec<[f64; 3]>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push(normalize([0, 1, 2].map(|k| vertices[a][k] + vertices[b][k])));
                vertices.len() - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (midpoint(a, b, &mut vertices), midpoint(b, c, &mut vertices), midpoint(c, a, &mut vertices));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    let lamp_cos = 14f64.to_radians().cos();
    let mut obj = ObjWriter::default();
    for lamp in [true, false] {
        obj.object(if lamp { "lamp" } else { "shell" }, if lamp { "lamp" } else { "shell" });
        for &[a, b, c] in &faces {
            let centroid_z = (vertices[a][2] + vertices[b][2] + vertices[c][2]) / 3.0;
            if (centroid_z >= lamp_cos * 0.99) == lamp {
                // The icosahedron's faces wind outward: reversed, they face in.
                obj.polygon(&[vertices[a], vertices[c], vertices[b]]);
            }
        }
    }
    let mtl = "newmtl shell\nKd 0.5 0.5 0.5\n\nnewmtl lamp\nKd 0.5 0.5 0.5\nKe 10 10 10\n".to_string();
    (scene_text("sphere.obj", [0.0, -0.9, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 90.0), obj.finish("sphere.mtl"), mtl)
}

/// The plant room of about `triangles` triangles: a 6 x 6 x 3 m room whose
/// walls take a tenth of the triangles, the rest in leaves (two triangles
/// each, 6 x 3 cm) on plants spread over the floor, at most 2,000 leaves a
/// plant. Leaves are placed by a fixed-seed random stream.
pub fn plants(triangles: usize) -> (String, String, String) {
    let mut obj = ObjWriter::default();
    let (w, h) = (6.0, 3.0);
    let wall_triangles = (triangles / 10).max(12);
    // Room: floor, four walls, ceiling with a lamp panel, as a scaled box.
    let n = ((wall_triangles as f64 / 12.0).sqrt().round() as usize).max(1);
    for (k, (o, u, v)) in box_faces(1.0).iter().enumerate() {
        let scale = |p: [f64; 3]| [p[0] * w, p[1] * w, p[2] * h];
        obj.object(&format!("room{k}"), if k == 5 { "ceiling" } else { "wall" });
        grid(&mut obj, scale(*o), scale(*u), scale(*v), n);
    }
    obj.object("lamp", "lamp");
    obj.polygon(&[[2.5, 2.5, h - 0.01], [2.5, 3.5, h - 0.01], [3.5, 3.5, h - 0.01], [3.5, 2.5, h - 0.01]]);
    let leaves = (triangles.saturating_sub(wall_triangles) / 2).max(1);
    let plants = leaves.div_ceil(2000).max(1);
    let mut stream = Stream::new(2024, 0, 0);
    let per_side = (plants as f64).sqrt().ceil() as usize;
    obj.object("leaves", "leaf");
    for p in 0..plants {
        let (cx, cy) = (0.5 + 5.0 * ((p % per_side) as f64 + 0.5) / per_side as f64, 0.5 + 5.0 * ((p / per_side) as f64 + 0.5) / per_side as f64);
        let count = if p + 1 == plants { leaves - 2000 * (plants - 1) } else { 2000 };
        for _ in 0..count {
            // Leaf centre in a cylinder around the stem, random orientation.
            let (r, a, z) = (0.35 * stream.next_f64().sqrt(), 2.0 * PI * stream.next_f64(), 0.2 + 1.2 * stream.next_f64());
            let centre = [cx + r * a.cos(), cy + r * a.sin(), z];
            let (theta, phi) = ((2.0 * stream.next_f64() - 1.0).acos(), 2.0 * PI * stream.next_f64());
            let normal = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
            let helper = if normal[2].abs() < 0.9 { [0.0, 0.0, 1.0] } else { [1.0, 0.0, 0.0] };
            let u = normalize(cross(helper, normal));
            let v = cross(normal, u);
            let corner = |s: f64, t: f64| [0, 1, 2].map(|k| centre[k] + 0.03 * s * u[k] + 0.015 * t * v[k]);
            obj.polygon(&[corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)]);
        }
    }
    let mtl = "newmtl wall\nKd 0.6 0.6 0.6\n\nnewmtl ceiling\nKd 0.8 0.8 0.8\n\nnewmtl leaf\nKd 0.1 0.4 0.08\n\nnewmtl lamp\nKd 0 0 0\nKe 30 30 28\n"
        .to_string();
    (scene_text("plants.obj", [3.0, 0.3, 1.5], [3.0, 3.0, 1.0], [0.0, 0.0, 1.0], 70.0), obj.finish("plants.mtl"), mtl)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|x| x / l)
}

/// OBJ text with every triangle split 1:4 and every quadrilateral into four
/// quadrilaterals, `levels` times; objects, materials and library lines
/// kept. Written out anew, so faces index the vertices written with them.
pub fn tessellate(obj: &str, levels: u32) -> String {
    let mut vertices: Vec<[f64; 3]> = Vec::new();
    let mut out = ObjWriter::default();
    for line in obj.lines() {
        let mut fields = line.split_whitespace();
        match fields.next() {
            Some("v") => {
                let p: Vec<f64> = fields.take(3).filter_map(|x| x.parse().ok()).collect();
                vertices.push([p.first().copied().unwrap_or(0.0), p.get(1).copied().unwrap_or(0.0), p.get(2).copied().unwrap_or(0.0)]);
            }
            Some("f") => {
                let count = vertices.len() as i64;
                let corners: Option<Vec<[f64; 3]>> = fields
                    .map(|c| {
                        let i: i64 = c.split('/').next()?.parse().ok()?;
                        let at = if i > 0 { i - 1 } else { count + i };
                        vertices.get(usize::try_from(at).ok()?).copied()
                    })
                    .collect();
                if let Some(corners) = corners {
                    split(&corners, levels, &mut |piece| out.polygon(piece));
                }
            }
            Some("o" | "g" | "usemtl" | "mtllib") => {
                out.text.push_str(line);
                out.text.push('\n');
            }
            _ => {}
        }
    }
    out.text
}

fn midpoint(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]))
}

/// Splits a triangle 1:4 or a quadrilateral into four, `levels` times;
/// other polygons are passed through.
fn split(corners: &[[f64; 3]], levels: u32, emit: &mut dyn FnMut(&[[f64; 3]])) {
    if levels == 0 {
        return emit(corners);
    }
    match *corners {
        [a, b, c] => {
            let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
            for t in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [bc, ca, ab]] {
                split(&t, levels - 1, emit);
            }
        }
        [a, b, c, d] => {
            let (ab, bc, cd, da, centre) = (midpoint(a, b), midpoint(b, c), midpoint(c, d), midpoint(d, a), midpoint(midpoint(a, c), midpoint(b, d)));
            for q in [[a, ab, centre, da], [ab, b, bc, centre], [centre, bc, c, cd], [da, centre, cd, d]] {
                split(&q, levels - 1, emit);
            }
        }
        _ => emit(corners),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }

    #[test]
    fn tessellation_keeps_area_and_multiplies_faces() {
        let obj = "mtllib m.mtl\no q\nusemtl a\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf -3 -2 -1\n";
        let out = tessellate(obj, 2);
        assert_eq!(out.lines().filter(|l| l.starts_with("f ")).count(), 32);
        assert!(out.starts_with("mtllib m.mtl\no q\nusemtl a\n"));
        // Quads count twice after the OBJ reader's triangulation: 16 quads (2 m^2) + 16 triangles (0.5 m^2).
        let mut area = 0.0;
        let v: Vec<[f64; 3]> = out.lines().filter(|l| l.starts_with("v ")).map(|l| {
            let p: Vec<f64> = l.split_whitespace().skip(1).map(|x| x.parse().unwrap()).collect();
            [p[0], p[1], p[2]]
        }).collect();
        for f in out.lines().filter(|l| l.starts_with("f ")) {
            let idx: Vec<usize> = f.split_whitespace().skip(1).map(|x| x.parse::<usize>().unwrap() - 1).collect();
            for k in 1..idx.len() - 1 {
                let (a, b, c) = (v[idx[0]], v[idx[k]], v[idx[k + 1]]);
                let n = cross([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
                area += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            }
        }
        assert!((area - 2.5).abs() < 1e-12, "{area}");
    }

    #[test]
    fn box_faces_point_into_the_box() {
        let centre = [0.5, 0.5, 0.5];
        for (o, u, v) in box_faces(1.0) {
            let n = cross(u, v);
            let middle = [0, 1, 2].map(|k| o[k] + 0.5 * u[k] + 0.5 * v[k]);
            let inward: f64 = (0..3).map(|k| n[k] * (centre[k] - middle[k])).sum();
            assert!(inward > 0.0, "face at {o:?} faces out");
        }
    }

    /// Table 1's figures, from the corners: areas 9, 25, 25, power 12,
    /// aspect ratio 2.2 (A's side over the separation), offset 1.2 (LS's
    /// edge to B's); LS and B share a plane, so B sees none of LS.
    #[test]
    fn simple_environment_has_table_1_figures() {
        let s = SIMPLE_ENVIRONMENT;
        // A planar quadrilateral's area: half the length of its diagonals' cross product.
        let area = |c: [[f64; 3]; 4]| 0.5 * cross(sub(c[2], c[0]), sub(c[3], c[1])).iter().map(|x| x * x).sum::<f64>().sqrt();
        let normal_z = |c: [[f64; 3]; 4]| cross(sub(c[1], c[0]), sub(c[2], c[0]))[2].signum();
        assert!((area(s.light) - 9.0).abs() < 1e-12 && (area(s.a) - 25.0).abs() < 1e-12 && (area(s.b) - 25.0).abs() < 1e-12);
        assert!((s.emission * area(s.light) - 12.0).abs() < 1e-12);
        assert_eq!((normal_z(s.light), normal_z(s.a), normal_z(s.b)), (1.0, -1.0, 1.0));
        assert!(((s.a[2][0] - s.a[0][0]) / (s.a[0][2] - s.light[0][2]) - 2.2).abs() < 1e-12);
        assert!((s.b[0][0] - s.light[1][0] - 1.2).abs() < 1e-12);
        assert!(s.light.iter().chain(&s.b).all(|p| p[2] == 0.0) && s.a.iter().all(|p| p[2] == s.height));
    }

    #[test]
    fn sizes_are_about_what_was_asked() {
        let faces = |obj: &str| obj.lines().filter(|l| l.starts_with("f ")).map(|l| l.split_whitespace().count() - 3).sum::<usize>();
        for n in [10_000, 100_000] {
            let (_, obj, _) = plants(n);
            let got = faces(&obj);
            assert!(got.abs_diff(n) < n / 10, "plants {n}: {got} triangles");
            let (_, obj, _) = closed_box(n);
            assert!(faces(&obj).abs_diff(n) < n / 5, "box {n}: {}", faces(&obj));
            let (_, obj, _) = sphere(n);
            assert!(faces(&obj) >= n && faces(&obj) < 4 * n, "sphere {n}: {}", faces(&obj));
        }
    }
}
