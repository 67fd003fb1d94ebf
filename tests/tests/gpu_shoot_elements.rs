//! gpu-shoot per element and per texel against closed forms (issue 10,
//! item 7): Lambert's polygon formula under a tilted triangular emitter,
//! Howell C-11 (parallel rectangles) and C-14 (perpendicular rectangles
//! sharing an edge) at two aspect ratios each, a sliver before a large
//! wall, and the flux of an open scene. The references are the closed
//! forms of `end_to_end::closed_form`, evaluated on the mesh gpu-shoot
//! read, averaged over each element by a quadrature of their own; only the
//! emitter shoots (`--max-shots 1`, every other surface black or its light
//! leaving the scene), so each receiver's radiosity is `rho B F(point ->
//! emitter)`. gpu-shoot needs a Vulkan adapter (lavapipe is enough):
//! without one each test skips loudly, but fails when CI is set.

use end_to_end::closed_form::{clip_to_front, lambert_polygon, parallel_rectangles, perpendicular_rectangles};
use end_to_end::{run, run_ok, s, scratch, skipped_without_gpu};
use schemas::lightmap::{Lightmap, COVERED};
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Emitted radiosity of every emitter, W/m².
const EMISSION: f64 = 10.0;
/// Reflectance of every receiver.
const RHO: f64 = 0.5;

/// A scene of planar polygons (triangles or quads, corners in order, front
/// face by the right-hand rule) on three materials: `emitter` (black,
/// emitting), `receiver` (grey) and `black`.
#[derive(Default)]
struct Polygons(Vec<(&'static str, &'static str, Vec<[f64; 3]>)>);

impl Polygons {
    fn add(mut self, object: &'static str, material: &'static str, corners: &[[f64; 3]]) -> Self {
        self.0.push((object, material, corners.to_vec()));
        self
    }

    /// Writes the scene and runs mesh-prep; returns (mesh, manifest).
    fn prepare(&self, dir: &Path) -> (PathBuf, PathBuf) {
        let mut obj = String::from("mtllib scene.mtl\n");
        for (object, material, corners) in &self.0 {
            writeln!(obj, "o {object}\nusemtl {material}").unwrap();
            for v in corners {
                writeln!(obj, "v {:.17} {:.17} {:.17}", v[0], v[1], v[2]).unwrap();
            }
            let face: Vec<String> = (0..corners.len()).map(|k| format!("-{}", corners.len() - k)).collect();
            writeln!(obj, "f {}", face.join(" ")).unwrap();
        }
        std::fs::write(dir.join("scene.obj"), obj).unwrap();
        std::fs::write(dir.join("scene.mtl"), format!("newmtl emitter\nKd 0 0 0\nnewmtl receiver\nKd {RHO} {RHO} {RHO}\nnewmtl black\nKd 0 0 0\n")).unwrap();
        let e = EMISSION;
        let scene = format!(
            "Scene(\n  meshes: [Obj(file: \"scene.obj\")],\n  camera: Camera(eye: (0.5, -3.0, 1.0), target: (0.5, 0.5, 0.0), up: (0.0, 0.0, 1.0), vertical_fov_deg: 60.0, width: 16, height: 16),\n  lights: [],\n  materials: {{ \"emitter\": (emission: Some(({e:?}, {e:?}, {e:?}))) }},\n)\n"
        );
        std::fs::write(dir.join("scene.ron"), scene).unwrap();
        let (mesh, manifest) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
        run_ok("mesh-prep", &[s(&dir.join("scene.ron")), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
        (mesh, manifest)
    }
}

/// What one gpu-shoot run left, read back.
struct Solved {
    mesh: Mesh,
    manifest: Manifest,
    solution: Solution,
    lightmap: Lightmap,
}

impl Solved {
    fn object_of(&self, t: usize) -> &str {
        &self.manifest.objects[self.mesh.triangles[t].object as usize]
    }

    fn corners(&self, t: usize) -> [[f64; 3]; 3] {
        self.mesh.triangles[t].vertices.map(|v| self.mesh.positions[v as usize].map(f64::from))
    }

    /// The point at barycentric `(u, v)` of triangle `t`.
    fn point(&self, t: usize, uv: [f64; 2]) -> [f64; 3] {
        let [p0, p1, p2] = self.corners(t);
        [0, 1, 2].map(|k| p0[k] + uv[0] * (p1[k] - p0[k]) + uv[1] * (p2[k] - p0[k]))
    }

    /// `rho B F(point -> emitter)`, the emitter's part in front of the point
    /// (Lambert's formula over each emitting triangle).
    fn exact(&self, t: usize, p: [f64; 3]) -> f64 {
        let normal = self.mesh.triangles[t].normal.map(f64::from);
        (0..self.mesh.triangles.len())
            .filter(|&e| self.object_of(e) == "emitter")
            .map(|e| {
                let front = clip_to_front(&self.corners(e), p, normal);
                if front.len() < 3 {
                    0.0
                } else {
                    lambert_polygon(p, normal, &front)
                }
            })
            .sum::<f64>()
            * RHO
            * EMISSION
    }

    /// The mean of [`Solved::exact`] over the element with barycentric
    /// `corners`: the midpoint rule on its 4^3 = 64 congruent sub-triangles.
    fn exact_mean(&self, t: usize, corners: [[f64; 2]; 3]) -> f64 {
        let mut triangles = vec![corners];
        for _ in 0..3 {
            triangles = triangles
                .iter()
                .flat_map(|&[a, b, c]| {
                    let mid = |p: [f64; 2], q: [f64; 2]| [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0];
                    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
                })
                .collect();
        }
        let n = triangles.len() as f64;
        triangles.iter().map(|[a, b, c]| self.exact(t, self.point(t, [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0]))).sum::<f64>() / n
    }

    /// Worst relative error and RMS of the receiver's leaves against their
    /// exact means, and their number.
    fn element_errors(&self) -> (f64, f64, usize) {
        let mut errors = Vec::new();
        for e in self.solution.elements.iter().filter(|e| e.is_leaf()) {
            let t = e.triangle as usize;
            if self.object_of(t) != "receiver" {
                continue;
            }
            let exact = self.exact_mean(t, e.corners.map(|c| c.map(f64::from)));
            errors.push(f64::from(e.radiosity[0]) / exact - 1.0);
        }
        let worst = errors.iter().fold(0.0f64, |w, e| w.max(e.abs()));
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
        (worst, rms, errors.len())
    }

    /// Worst relative error of the receiver's covered texels against
    /// [`Solved::exact`] at the point each stands for, and the largest
    /// texel radiosity over its exact value.
    fn texel_errors(&self) -> (f64, f64) {
        let lm = &self.lightmap;
        let (mut worst, mut highest) = (0.0f64, 0.0f64);
        for (t, r) in lm.regions.iter().enumerate() {
            if self.object_of(t) != "receiver" {
                continue;
            }
            for j in 0..r.size {
                for i in 0..r.size - j {
                    let (x, y) = r.texel(i, j);
                    let k = y as usize * lm.width + x as usize;
                    assert_eq!(lm.coverage[k], COVERED);
                    let exact = self.exact(t, lm.position[k].map(f64::from));
                    let ratio = f64::from(lm.radiosity[k][0]) / exact;
                    worst = worst.max((ratio - 1.0).abs());
                    highest = highest.max(ratio);
                }
            }
        }
        (worst, highest)
    }

    /// Power (W, channel 0) leaving the receiver: leaves' area x radiosity.
    fn receiver_flux(&self) -> f64 {
        self.solution
            .elements
            .iter()
            .filter(|e| e.is_leaf() && self.object_of(e.triangle as usize) == "receiver")
            .map(|e| f64::from(e.area) * f64::from(e.radiosity[0]))
            .sum()
    }
}

/// Runs gpu-shoot on `scene` with the emitter's one shot and `extra`
/// arguments; `None` when there is no adapter.
fn shoot(test: &str, scene: &Polygons, extra: &[&str]) -> Option<Solved> {
    let dir = scratch(test);
    let (mesh, manifest) = scene.prepare(&dir);
    let (solution, lightmap) = (dir.join("solution.exr"), dir.join("lightmap.exr"));
    let mut args = vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--lightmap", s(&lightmap), "--max-shots", "1"];
    args.extend(extra);
    if skipped_without_gpu(&run("gpu-shoot", &args), test) {
        return None;
    }
    Some(Solved {
        mesh: Mesh::read(&mesh).unwrap().0,
        manifest: schemas::ron_io::read_ron::<Manifest>(&manifest).unwrap().value,
        solution: Solution::read(&solution).unwrap().0,
        lightmap: Lightmap::read(&lightmap).unwrap().0,
    })
}

/// The unit floor `[0, 1]^2` facing up under a tilted triangle facing down
/// whose plane passes above the whole floor: every element of the floor
/// within 2% of the mean of Lambert's formula over it, every texel within
/// 2% at the point it stands for. (The solution's lookup read the atlas
/// half a texel off: 5.4% where the texels were within 1.2%.)
#[test]
fn floor_elements_under_a_tilted_triangle_match_lambert() {
    let scene = Polygons::default()
        .add("receiver", "receiver", &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
        .add("emitter", "emitter", &[[0.2, 0.2, 0.45], [0.4, 0.85, 0.35], [0.85, 0.3, 0.65]]);
    let Some(solved) = shoot("gpu_elements_tilted", &scene, &["--texels", "8000"]) else { return };
    let (worst, rms, count) = solved.element_errors();
    let (texels, _) = solved.texel_errors();
    eprintln!("tilted triangle: {count} floor elements, worst {worst:.4}, rms {rms:.4}; texels worst {texels:.4}");
    assert!(count > 500, "{count} elements");
    assert!(texels < 0.02, "worst texel {texels}");
    assert!(worst < 0.02, "worst element {worst} (rms {rms})");
}
