//! Test scenes written from code: quads with materials, as OBJ + MTL +
//! scene.ron in a directory.

use crate::vec3::{cross, sub};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A material: diffuse reflectance and emitted radiosity (exitance, W/m²).
#[derive(Clone, Debug)]
pub struct TestMaterial {
    /// MTL name.
    pub name: String,
    /// Diffuse reflectance, grey.
    pub reflectance: f64,
    /// Emitted radiosity, W/m², grey.
    pub emission: f64,
}

/// A scene of planar quads.
#[derive(Clone, Debug, Default)]
pub struct QuadScene {
    /// `(object, material, corners)`; corners are reordered to face `normal`.
    pub quads: Vec<(String, String, [[f64; 3]; 4])>,
    /// Materials by name.
    pub materials: Vec<TestMaterial>,
    /// Camera eye and target.
    pub camera: ([f64; 3], [f64; 3]),
    /// Lights besides the emitting materials, as `scene.ron` entries, e.g.
    /// `Goniometric(file: "lamp.ldt", position: (0.0, 0.0, 1.0), nadir: (0.0, 0.0, -1.0))`.
    pub lights: Vec<String>,
    /// Names of the materials made two-sided in `scene.ron`.
    pub two_sided: Vec<String>,
}

impl QuadScene {
    /// Adds a quad (corners in order around it) whose front faces `normal`.
    pub fn quad(&mut self, object: &str, material: &str, corners: [[f64; 3]; 4], normal: [f64; 3]) -> &mut Self {
        let n = cross(sub(corners[1], corners[0]), sub(corners[2], corners[0]));
        let facing = n[0] * normal[0] + n[1] * normal[1] + n[2] * normal[2] > 0.0;
        let mut c = corners;
        if !facing {
            c.reverse();
        }
        self.quads.push((object.into(), material.into(), c));
        self
    }

    /// Adds a material.
    pub fn material(&mut self, name: &str, reflectance: f64, emission: f64) -> &mut Self {
        self.materials.push(TestMaterial { name: name.into(), reflectance, emission });
        self
    }

    /// Writes `scene.obj`, `scene.mtl` and `scene.ron` into `dir`; returns
    /// the scene file's path. Emission is set in scene.ron as exitance.
    pub fn write(&self, dir: &Path) -> PathBuf {
        let mut obj = String::from("mtllib scene.mtl\n");
        for (object, material, corners) in &self.quads {
            writeln!(obj, "o {object}\nusemtl {material}").unwrap();
            for v in corners {
                writeln!(obj, "v {:.17} {:.17} {:.17}", v[0], v[1], v[2]).unwrap();
            }
            obj.push_str("f -4 -3 -2 -1\n");
        }
        let mut mtl = String::new();
        let mut overrides = String::new();
        for m in &self.materials {
            writeln!(mtl, "newmtl {}\nKd {r} {r} {r}", m.name, r = m.reflectance).unwrap();
            let two_sided = if self.two_sided.contains(&m.name) { ", two_sided: Some(true)" } else { "" };
            writeln!(overrides, "    \"{}\": (emission: Some(({e:?}, {e:?}, {e:?})){two_sided}),", m.name, e = m.emission).unwrap();
        }
        let (eye, target) = self.camera;
        let lights: String = self.lights.iter().map(|l| format!("    {l},\n")).collect();
        let scene = format!(
            "Scene(\n  meshes: [Obj(file: \"scene.obj\")],\n  camera: Camera(eye: {eye:?}, target: {target:?}, up: (0.0, 0.0, 1.0), vertical_fov_deg: 60.0, width: 64, height: 64),\n  lights: [\n{lights}  ],\n  materials: {{\n{overrides}  }},\n)\n",
            eye = (eye[0], eye[1], eye[2]),
            target = (target[0], target[1], target[2]),
        );
        std::fs::write(dir.join("scene.obj"), obj).unwrap();
        std::fs::write(dir.join("scene.mtl"), mtl).unwrap();
        let path = dir.join("scene.ron");
        std::fs::write(&path, scene).unwrap();
        path
    }
}

/// An axis-aligned rectangle in the plane `axis = at`, spanning `lo..hi` in
/// the two other axes (in cyclic order after `axis`).
pub fn rectangle(axis: usize, at: f64, lo: [f64; 2], hi: [f64; 2]) -> [[f64; 3]; 4] {
    let point = |u: f64, v: f64| {
        let mut p = [0.0; 3];
        p[axis] = at;
        p[(axis + 1) % 3] = u;
        p[(axis + 2) % 3] = v;
        p
    };
    [point(lo[0], lo[1]), point(hi[0], lo[1]), point(hi[0], hi[1]), point(lo[0], hi[1])]
}

/// A closed `size`-sided cube room, walls facing in, uniform reflectance
/// `rho`; the ceiling (z = size) is split 3 x 3 and its centre square emits
/// `emission`. Returns the scene.
pub fn closed_box(size: f64, rho: f64, emission: f64) -> QuadScene {
    let mut scene = QuadScene { camera: ([0.5 * size, 0.1 * size, 0.5 * size], [0.5 * size, size, 0.5 * size]), ..Default::default() };
    scene.material("wall", rho, 0.0).material("lamp", rho, emission);
    for axis in 0..3 {
        for (at, sign) in [(0.0, 1.0), (size, -1.0)] {
            let mut normal = [0.0; 3];
            normal[axis] = sign;
            if axis == 2 && at > 0.0 {
                let cuts = [0.0, size / 3.0, 2.0 * size / 3.0, size];
                for i in 0..3 {
                    for j in 0..3 {
                        let (object, material) = if (i, j) == (1, 1) { ("lamp", "lamp") } else { ("ceiling", "wall") };
                        scene.quad(object, material, rectangle(2, at, [cuts[i], cuts[j]], [cuts[i + 1], cuts[j + 1]]), normal);
                    }
                }
            } else {
                scene.quad(&format!("wall{axis}{}", at > 0.0), "wall", rectangle(axis, at, [0.0, 0.0], [size, size]), normal);
            }
        }
    }
    scene
}

/// A receiver square R (1 m, the plane x = 0, facing +x, reflectance
/// `rho`) that is the front face of a closed black box `x in [-1, 0]`, lit
/// by a 2 x 2 m black emitter (exitance `emission`) 0.5 m above the box,
/// facing down, that straddles R's plane: `x in [-0.7, 1.3]`, `y in [-0.5,
/// 1.5]`, `z = 1.5` (off-centre, so that no midpoint subdivision of the
/// emitter ever falls on R's plane). Nothing occludes the emitter's front
/// part from R; its back part is behind R's plane, above the box's body.
/// Objects `R`, `box`, `lamp`.
pub fn straddled_receiver(rho: f64, emission: f64) -> QuadScene {
    let mut scene = QuadScene { camera: ([3.0, 0.5, 0.8], [0.0, 0.5, 0.5]), ..Default::default() };
    scene.material("receiving", rho, 0.0).material("black", 0.0, 0.0).material("emitting", 0.0, emission);
    scene.quad("R", "receiving", rectangle(0, 0.0, [0.0, 0.0], [1.0, 1.0]), [1.0, 0.0, 0.0]);
    scene.quad("box", "black", rectangle(0, -1.0, [0.0, 0.0], [1.0, 1.0]), [-1.0, 0.0, 0.0]);
    for (at, sign) in [(0.0, -1.0), (1.0, 1.0)] {
        scene.quad("box", "black", rectangle(1, at, [0.0, -1.0], [1.0, 0.0]), [0.0, sign, 0.0]);
        scene.quad("box", "black", rectangle(2, at, [-1.0, 0.0], [0.0, 1.0]), [0.0, 0.0, sign]);
    }
    scene.quad("lamp", "emitting", rectangle(2, 1.5, [-0.7, -0.5], [1.3, 1.5]), [0.0, 0.0, -1.0]);
    scene
}

/// Paper 002's one-bounce configuration: a 1 m square emitter L (black,
/// exitance `emission`, `x in [0, 1]`, `y in [0, 1]`, `z = 0`) and a 1 m
/// square receiver B beside it in the same plane (`x in [1, 2]`,
/// reflectance `rho_b`), both facing up at a 2 x 1 m receiver A
/// (reflectance `rho_a`) 0.5 m above them, facing down. L and B are
/// coplanar, so B gets only what A reflects. Objects `L`, `A`, `B`.
pub fn one_bounce(rho_a: f64, rho_b: f64, emission: f64) -> QuadScene {
    let mut scene = QuadScene { camera: ([1.0, -1.5, 0.25], [1.0, 0.5, 0.25]), ..Default::default() };
    scene.material("emitting", 0.0, emission).material("upper", rho_a, 0.0).material("lower", rho_b, 0.0);
    scene.quad("L", "emitting", rectangle(2, 0.0, [0.0, 0.0], [1.0, 1.0]), [0.0, 0.0, 1.0]);
    scene.quad("B", "lower", rectangle(2, 0.0, [1.0, 0.0], [2.0, 1.0]), [0.0, 0.0, 1.0]);
    scene.quad("A", "upper", rectangle(2, 0.5, [0.0, 0.0], [2.0, 1.0]), [0.0, 0.0, -1.0]);
    scene
}

/// An EULUMDAT file (`.ldt`) of a rotationally symmetric luminaire (Isym
/// 1, one C-plane) with luminous intensity `intensity(gamma)` cd at gamma
/// = 0, 5, ..., 180 degrees (one lamp set of 1000 lm and conversion factor
/// 1, so the table's cd/klm are cd).
pub fn rotational_ldt(intensity: &dyn Fn(f64) -> f64) -> String {
    let mut lines: Vec<String> = ["test luminaire", "1", "1", "1", "0", "37", "5", "report", "luminaire", "number", "lamp.ldt", "date"].map(String::from).to_vec();
    lines.extend(["100", "100", "10", "100", "100", "0", "0", "0", "0", "100", "100", "1", "0", "1"].map(String::from));
    lines.extend(["1", "LED", "1000", "3000K", "80", "10"].map(String::from));
    lines.extend((0..10).map(|_| "0.5".to_string()));
    lines.push("0".into());
    lines.extend((0..37).map(|g| format!("{}", 5 * g)));
    lines.extend((0..37).map(|g| format!("{:.9}", intensity(5.0 * g as f64))));
    lines.join("\n") + "\n"
}
