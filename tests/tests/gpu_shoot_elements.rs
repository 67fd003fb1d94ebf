//! gpu-shoot per element and per texel against closed forms (issue 10,
//! item 7): Lambert's polygon formula under a tilted triangular emitter,
//! Howell C-11 (parallel rectangles) and C-14 (perpendicular rectangles
//! sharing an edge) at two aspect ratios each, a sliver before a large
//! wall, and the flux of an open scene. The references are the closed
//! forms of `test_support::closed_form`, evaluated on the mesh gpu-shoot
//! read, averaged over each element by a quadrature of their own; only the
//! emitter's triangles shoot (`--max-shots`, every other surface black or
//! its light leaving the scene), so each receiver's radiosity is `rho B F(point ->
//! emitter)`. gpu-shoot needs a Vulkan adapter (lavapipe is enough):
//! without one each test skips loudly, but fails when CI is set.

use end_to_end::{run, run_ok, s, scratch, skipped_without_gpu};
use schemas::lightmap::{Lightmap, COVERED};
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use test_support::closed_form::{clip_to_front, lambert_polygon, parallel_rectangles, perpendicular_rectangles};

/// Emitted radiosity of every emitter, W/m².
const EMISSION: f64 = 10.0;
/// Emitted radiosity of the `dim` emitters, W/m².
const DIM: f64 = 4.0;
/// Reflectance of every receiver.
const RHO: f64 = 0.5;

/// A scene of planar polygons (triangles or quads, corners in order, front
/// face by the right-hand rule) on five materials: `emitter` and `dim`
/// (black, emitting [`EMISSION`] and [`DIM`]), `receiver` (grey),
/// `panel` (grey, two-sided) and `black`.
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
        let mtl = format!("newmtl emitter\nKd 0 0 0\nnewmtl dim\nKd 0 0 0\nnewmtl receiver\nKd {RHO} {RHO} {RHO}\nnewmtl panel\nKd {RHO} {RHO} {RHO}\nnewmtl black\nKd 0 0 0\n");
        std::fs::write(dir.join("scene.mtl"), mtl).unwrap();
        let (e, dim) = (EMISSION, DIM);
        let scene = format!(
            "Scene(\n  meshes: [Obj(file: \"scene.obj\")],\n  camera: Camera(eye: (0.5, -3.0, 1.0), target: (0.5, 0.5, 0.0), up: (0.0, 0.0, 1.0), vertical_fov_deg: 60.0, width: 16, height: 16),\n  lights: [],\n  materials: {{ \"emitter\": (emission: Some(({e:?}, {e:?}, {e:?}))), \"dim\": (emission: Some(({dim:?}, {dim:?}, {dim:?}))), \"panel\": (two_sided: Some(true)) }},\n)\n"
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

    /// `rho sum B_e F(point -> e)` over the emitting triangles `e`, their
    /// part in front of the point (Lambert's formula), occlusion aside.
    fn exact(&self, t: usize, p: [f64; 3]) -> f64 {
        let normal = self.mesh.triangles[t].normal.map(f64::from);
        let emission = |e: usize| self.manifest.materials[self.mesh.triangles[e].material as usize].emission[0];
        (0..self.mesh.triangles.len())
            .filter(|&e| emission(e) > 0.0)
            .map(|e| {
                let front = clip_to_front(&self.corners(e), p, normal);
                if front.len() < 3 {
                    0.0
                } else {
                    emission(e) * lambert_polygon(p, normal, &front)
                }
            })
            .sum::<f64>()
            * RHO
    }

    /// The mean of [`Solved::exact`] over the element with barycentric
    /// `corners`: the midpoint rule on its 4^5 = 1024 congruent
    /// sub-triangles (4^3 left 1% at the ends of a shared edge).
    fn exact_mean(&self, t: usize, corners: [[f64; 2]; 3]) -> f64 {
        let mut triangles = vec![corners];
        for _ in 0..5 {
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
    /// exact means, and their number; the leaves with a corner at one of
    /// `singular` (points where the exact radiosity jumps) apart: their
    /// worst error.
    fn element_errors(&self, singular: &[[f64; 3]]) -> (f64, f64, usize, f64) {
        self.element_errors_on(&|t| self.object_of(t) == "receiver", singular)
    }

    /// [`Solved::element_errors`] on the triangles `on` picks.
    fn element_errors_on(&self, on: &dyn Fn(usize) -> bool, singular: &[[f64; 3]]) -> (f64, f64, usize, f64) {
        let (mut errors, mut at_singular) = (Vec::new(), 0.0f64);
        for e in self.solution.elements.iter().filter(|e| e.is_leaf()) {
            let t = e.triangle as usize;
            if !on(t) {
                continue;
            }
            let exact = self.exact_mean(t, e.corners.map(|c| c.map(f64::from)));
            let error = f64::from(e.radiosity[0]) / exact - 1.0;
            let corners = e.corners.map(|c| self.point(t, c.map(f64::from)));
            let distance = |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
            if corners.iter().any(|&c| singular.iter().any(|&q| distance(c, q) < 1e-5)) {
                at_singular = at_singular.max(error.abs());
            } else {
                errors.push(error);
            }
        }
        let worst = errors.iter().fold(0.0f64, |w, e| w.max(e.abs()));
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
        (worst, rms, errors.len(), at_singular)
    }

    /// Worst relative error of the receiver's covered texels against
    /// [`Solved::exact`] at the point each stands for, the largest texel
    /// radiosity over its exact value, and the largest texel radiosity.
    fn texel_errors(&self) -> (f64, f64, f64) {
        let lm = &self.lightmap;
        let (mut worst, mut highest, mut brightest) = (0.0f64, 0.0f64, 0.0f64);
        for (t, r) in lm.regions.iter().enumerate() {
            if self.object_of(t) != "receiver" {
                continue;
            }
            for j in 0..r.size {
                for i in 0..r.size - j {
                    let (x, y) = r.texel(i, j);
                    let k = y as usize * lm.width + x as usize;
                    assert_eq!(lm.coverage[k], COVERED);
                    // A texel on the hypotenuse stands for the centroid of its
                    // half square inside the triangle, the others for their centre.
                    let n = f64::from(r.size);
                    let uv = if i + j + 1 == r.size { [(f64::from(i) + 1.0 / 3.0) / n, (f64::from(j) + 1.0 / 3.0) / n] } else { r.uv(i, j) };
                    let exact = self.exact(t, self.point(t, uv));
                    let ratio = f64::from(lm.radiosity[k][0]) / exact;
                    worst = worst.max((ratio - 1.0).abs());
                    highest = highest.max(ratio);
                    brightest = brightest.max(f64::from(lm.radiosity[k][0]));
                }
            }
        }
        (worst, highest, brightest)
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

/// Runs gpu-shoot on `scene` with `extra` arguments and, unless they set a
/// convergence target, as many shots as the emitters have triangles (each
/// shoots once, before any receiver, which gets less power); `None` when
/// there is no adapter.
fn shoot(test: &str, scene: &Polygons, extra: &[&str]) -> Option<Solved> {
    let dir = scratch(test);
    let (mesh, manifest) = scene.prepare(&dir);
    let (solution, lightmap) = (dir.join("solution.exr"), dir.join("lightmap.exr"));
    let shots = scene.0.iter().filter(|p| ["emitter", "dim"].contains(&p.1)).map(|p| p.2.len() - 2).sum::<usize>().to_string();
    let mut args = vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&solution), "--lightmap", s(&lightmap)];
    if !extra.contains(&"--convergence-target") {
        args.extend(["--max-shots", &shots]);
    }
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
    let (worst, rms, count, _) = solved.element_errors(&[]);
    let (texels, _, _) = solved.texel_errors();
    eprintln!("tilted triangle: {count} floor elements, worst {worst:.4}, rms {rms:.4}; texels worst {texels:.4}");
    assert!(count > 500, "{count} elements");
    assert!(texels < 0.02, "worst texel {texels}");
    assert!(worst < 0.02, "worst element {worst} (rms {rms})");
}

/// Checks the receiver of a one-shot scene: every element within 2% of its
/// exact mean, and its power within 0.5% of `rho B A_e F` (`A_e` the
/// emitter's area, `F` the catalogue's factor from emitter to receiver).
/// The elements touching a corner the receiver shares with the emitter
/// (the ends of a shared edge) are held to 4%: there the exact radiosity
/// jumps from `rho B / 2` along the edge to `rho B / 4` at the corner, a
/// variation at every scale that no fixed texel grid resolves (2.9% at
/// 8000 texels, the rest of such a receiver within 1.3%). Every texel
/// within 2% of Lambert's formula at the point it stands for.
fn check_receiver(name: &str, solved: &Solved, emitter_area: f64, factor: f64) {
    let vertices_of = |object: &str| -> Vec<[f64; 3]> {
        let triangles = (0..solved.mesh.triangles.len()).filter(|&t| solved.object_of(t) == object);
        triangles.flat_map(|t| solved.corners(t)).collect()
    };
    let emitter = vertices_of("emitter");
    let shared: Vec<[f64; 3]> = vertices_of("receiver").into_iter().filter(|v| emitter.contains(v)).collect();
    let (worst, rms, count, at_corners) = solved.element_errors(&shared);
    let (texels, highest, _) = solved.texel_errors();
    let flux = solved.receiver_flux() / (RHO * EMISSION * emitter_area * factor) - 1.0;
    eprintln!(
        "{name}: {count} elements, worst {worst:.4}, rms {rms:.4}, at shared corners {at_corners:.4}; texels worst {texels:.4}, highest ratio {highest:.4}; receiver power {:+.3}%",
        100.0 * flux
    );
    assert!(count > 200, "{name}: {count} elements");
    assert!(worst < 0.02, "{name}: worst element {worst} (rms {rms})");
    assert!(texels < 0.02, "{name}: worst texel {texels}");
    assert!(at_corners < 0.04, "{name}: worst element at a shared corner {at_corners}");
    assert!(flux.abs() < 0.005, "{name}: receiver power {:+.3}% off the catalogue", 100.0 * flux);
}

/// Howell C-11: an `a x b` emitter at `z = c` facing down over the
/// receiver `[0, a] x [0, b]` facing up, for a square (1 x 1, 1 apart) and
/// a strip (1 x 0.2, 0.3 apart).
#[test]
fn parallel_rectangles_match_howell_c11_per_element() {
    for (a, b, c) in [(1.0, 1.0, 1.0), (1.0, 0.2, 0.3)] {
        let scene = Polygons::default()
            .add("receiver", "receiver", &[[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]])
            .add("emitter", "emitter", &[[0.0, 0.0, c], [0.0, b, c], [a, b, c], [a, 0.0, c]]);
        let Some(solved) = shoot("gpu_elements_c11", &scene, &["--texels", "8000"]) else { return };
        check_receiver(&format!("C-11 {a} x {b}, {c} apart"), &solved, a * b, parallel_rectangles(a, b, c));
    }
}

/// Howell C-14: an emitter `w x l` in the plane `z = 0` facing up and a
/// receiver `h x l` in the plane `x = 0` facing `+x`, sharing the edge of
/// length `l` along `y`, for `(l, w, h) = (1, 0.2, 3)` and `(0.1, 1, 1)`.
/// Near the shared edge the texels were off by up to +-90% in the period
/// of the shooting groups (8 texels), which the totals (1-3.5%) hid.
#[test]
fn perpendicular_rectangles_sharing_an_edge_match_howell_c14_per_element() {
    for (l, w, h) in [(1.0, 0.2, 3.0), (0.1, 1.0, 1.0)] {
        let scene = Polygons::default()
            .add("receiver", "receiver", &[[0.0, 0.0, 0.0], [0.0, l, 0.0], [0.0, l, h], [0.0, 0.0, h]])
            .add("emitter", "emitter", &[[0.0, 0.0, 0.0], [w, 0.0, 0.0], [w, l, 0.0], [0.0, l, 0.0]]);
        let Some(solved) = shoot("gpu_elements_c14", &scene, &["--texels", "8000"]) else { return };
        check_receiver(&format!("C-14 l {l} w {w} h {h}"), &solved, w * l, perpendicular_rectangles(w, h, l));
    }
}

/// A sliver (1 m x 1e-6 m) before a 10 m square emitter: facing it 1 m
/// away, and at right angles to it with one long edge touching it. No
/// texel may exceed what the emitter can give (`rho B`, a form factor of
/// 1), and every texel is within 2% of Lambert's formula. (The texel's
/// own patch, 1e-6 m wide, was the one integrated: f32 lost its solid
/// angle and the facing sliver read 21.6 times the maximum.)
#[test]
fn a_sliver_before_a_large_emitter_gets_at_most_what_the_emitter_gives() {
    let (d, z) = (1e-6, 1.0);
    let wall = [[-5.0, -5.0, z], [-5.0, 5.0, z], [5.0, 5.0, z], [5.0, -5.0, z]];
    let facing = [[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.5, d, 0.0], [-0.5, d, 0.0]];
    let touching = [[-0.5, 0.0, z - d], [-0.5, 0.0, z], [0.5, 0.0, z], [0.5, 0.0, z - d]];
    for (name, sliver) in [("facing, 1 m away", facing), ("at right angles, touching", touching)] {
        let scene = Polygons::default().add("receiver", "receiver", &sliver).add("emitter", "emitter", &wall);
        let Some(solved) = shoot("gpu_elements_sliver", &scene, &["--texels", "4000"]) else { return };
        let (texels, highest, brightest) = solved.texel_errors();
        eprintln!("sliver {name}: texels worst {texels:.4}, highest ratio {highest:.4}, brightest texel {brightest:.4} of at most {}", RHO * EMISSION);
        assert!(brightest <= RHO * EMISSION, "{name}: a texel at {brightest}, over rho B = {}", RHO * EMISSION);
        assert!(texels < 0.02, "{name}: worst texel {texels} (highest ratio {highest})");
    }
}

/// Two-sided surfaces: a 1.2 m square of the two-sided `panel` (mesh-prep
/// gives each triangle a twin facing down, over the same corners) with an
/// emitter 0.2 m above it and a receiver 1 m below it that only the
/// square's bottom face can light. The top face's elements match Lambert's
/// formula within 2%; the bottom face, which no light reaches, and the
/// receiver stay dark (under 1e-4 of the top's brightest) through the
/// whole solve, so neither the twins' shared corners in the visibility
/// maps nor a shot from one face leaks light to the other side. Lit from
/// both sides (a dimmer emitter 0.2 m below instead of the receiver), each
/// face matches Lambert's formula for its own emitter within 2%.
#[test]
fn the_faces_of_a_two_sided_square_keep_their_own_radiosity() {
    let square = [[-0.6, -0.6, 1.0], [0.6, -0.6, 1.0], [0.6, 0.6, 1.0], [-0.6, 0.6, 1.0]];
    let lamp = |z: f64, down: bool| {
        let q = [[-0.25, -0.25, z], [0.25, -0.25, z], [0.25, 0.25, z], [-0.25, 0.25, z]];
        if down { [q[0], q[3], q[2], q[1]] } else { q }
    };
    let floor = [[-0.25, -0.25, 0.0], [0.25, -0.25, 0.0], [0.25, 0.25, 0.0], [-0.25, 0.25, 0.0]];
    let faces = |solved: &Solved| {
        let side = |t: usize| solved.mesh.triangles[t].normal[2];
        let top = solved.element_errors_on(&|t| solved.object_of(t) == "panel" && side(t) > 0.0, &[]);
        let bottom = solved.element_errors_on(&|t| solved.object_of(t) == "panel" && side(t) < 0.0, &[]);
        (top, bottom)
    };
    let brightest = |solved: &Solved, on: &dyn Fn(usize) -> bool| {
        let leaves = solved.solution.elements.iter().filter(|e| e.is_leaf() && on(e.triangle as usize));
        leaves.map(|e| f64::from(e.radiosity[0])).fold(0.0f64, f64::max)
    };

    let scene = Polygons::default().add("panel", "panel", &square).add("emitter", "emitter", &lamp(1.2, true)).add("receiver", "receiver", &floor);
    let Some(solved) = shoot("gpu_elements_two_sided", &scene, &["--texels", "8000", "--convergence-target", "0.999"]) else { return };
    assert_eq!(solved.manifest.statistics.two_sided_twins, 2, "mesh-prep made no twins");
    let ((worst, rms, count, _), _) = faces(&solved);
    let panel = |t: usize| solved.object_of(t) == "panel";
    let top = brightest(&solved, &|t| panel(t) && solved.mesh.triangles[t].normal[2] > 0.0);
    let bottom = brightest(&solved, &|t| panel(t) && solved.mesh.triangles[t].normal[2] < 0.0);
    let receiver = brightest(&solved, &|t| solved.object_of(t) == "receiver");
    eprintln!("two-sided, lit from above: top {count} elements worst {worst:.4} rms {rms:.4}; brightest bottom {bottom:.3e}, receiver {receiver:.3e} of top {top:.4}");
    assert!(count > 200 && worst < 0.02, "top face: worst element {worst} over {count}");
    assert!(bottom < 1e-4 * top && receiver < 1e-4 * top, "light through the square: bottom {bottom}, receiver {receiver}, top {top}");

    let scene = Polygons::default().add("panel", "panel", &square).add("emitter", "emitter", &lamp(1.2, true)).add("dim", "dim", &lamp(0.8, false));
    let Some(solved) = shoot("gpu_elements_two_sided", &scene, &["--texels", "8000", "--convergence-target", "0.999"]) else { return };
    let ((top, top_rms, top_count, _), (bottom, bottom_rms, bottom_count, _)) = faces(&solved);
    eprintln!("two-sided, lit from both sides: top worst {top:.4} rms {top_rms:.4} ({top_count}), bottom worst {bottom:.4} rms {bottom_rms:.4} ({bottom_count})");
    assert!(top_count > 200 && bottom_count > 200, "{top_count} and {bottom_count} elements");
    assert!(top < 0.02 && bottom < 0.02, "worst element: top {top}, bottom {bottom}");
}

/// A hard shadow: a 1 cm square lamp 1 m over the unit floor, facing
/// down, and a 0.3 m square plate (facing the lamp) halfway between, whose
/// umbra on the floor is `[0.205, 0.795]^2` (every lamp point hidden: the
/// plate's edge at 0.35 seen from the lamp's far edge at 0.505 lands at
/// 2 x 0.35 - 0.505) and whose penumbra ends at 0.195 and 0.805. Only the
/// lamp shoots. Every floor texel whose square lies inside the umbra must
/// stay dark (under 1e-3 of the brightest texel), and every texel outside
/// the penumbra within 2% of Lambert's formula (the plate hides none of
/// the lamp from it). The visibility maps' neighbour test once counted any
/// occluder's edge pixels as showing the floor behind them: a pixel-wide
/// band inside every shadow was lit, here texels inside the umbra at 68%
/// of the brightest (the Cornell box's floor +6.4%).
#[test]
fn a_hard_shadow_stays_dark_inside_its_umbra() {
    let scene = Polygons::default()
        .add("receiver", "receiver", &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
        .add("plate", "receiver", &[[0.35, 0.35, 0.5], [0.65, 0.35, 0.5], [0.65, 0.65, 0.5], [0.35, 0.65, 0.5]])
        .add("emitter", "emitter", &[[0.495, 0.495, 1.0], [0.495, 0.505, 1.0], [0.505, 0.505, 1.0], [0.505, 0.495, 1.0]]);
    let Some(solved) = shoot("gpu_elements_hard_shadow", &scene, &["--texels", "8000"]) else { return };
    let lm = &solved.lightmap;
    // The mesh frame is the scene's, moved by the manifest's translation.
    let shift = solved.manifest.world_from_mesh_translation;
    let world = |p: [f64; 3]| [0, 1, 2].map(|k| p[k] + shift[k]);
    let (mut umbra, mut brightest, mut lit_worst, mut lit) = (Vec::new(), 0.0f64, 0.0f64, 0usize);
    for (t, r) in lm.regions.iter().enumerate() {
        if solved.object_of(t) != "receiver" {
            continue;
        }
        let n = f64::from(r.size);
        for j in 0..r.size {
            for i in 0..r.size - j {
                let (x, y) = r.texel(i, j);
                let b = f64::from(lm.radiosity[y as usize * lm.width + x as usize][0]);
                brightest = brightest.max(b);
                // The corners of the texel's square.
                let square: Vec<[f64; 3]> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .iter()
                    .map(|&(du, dv)| world(solved.point(t, [(f64::from(i) + du) / n, (f64::from(j) + dv) / n])))
                    .collect();
                let inside = |lo: f64, hi: f64| square.iter().all(|p| (lo..=hi).contains(&p[0]) && (lo..=hi).contains(&p[1]));
                let outside = square.iter().all(|p| p[0] < 0.195 || p[0] > 0.805 || p[1] < 0.195 || p[1] > 0.805);
                if inside(0.205, 0.795) {
                    umbra.push(b);
                } else if outside {
                    let exact = solved.exact(t, solved.point(t, r.uv(i, j)));
                    lit_worst = lit_worst.max((b / exact - 1.0).abs());
                    lit += 1;
                }
            }
        }
    }
    let darkest_lit = umbra.iter().fold(0.0f64, |m, b| m.max(*b));
    eprintln!("hard shadow: {} umbra texels, brightest {darkest_lit:.3e} of {brightest:.4}; {lit} lit texels, worst {lit_worst:.4}", umbra.len());
    assert!(umbra.len() > 500 && lit > 500, "{} umbra texels, {lit} lit", umbra.len());
    assert!(darkest_lit < 1e-3 * brightest, "an umbra texel at {darkest_lit}, the brightest {brightest}");
    assert!(lit_worst < 0.02, "a lit texel {lit_worst} off Lambert");
}

/// A black slab 2 mm tall standing on the floor under a lamp, its
/// footprint's edges across texels and leaves: every floor leaf crossing
/// the footprint shows its exposed part's radiosity (the mean of Lambert's
/// formula over that part, midpoint rule on 1024 sub-triangles; the slab
/// hides no lamp light from it at this height), and its area is that
/// part's (to the texels' granularity: a leaf of a few texels gains or
/// loses a row). 12 leaves cross it at 8000 texels: bias +0.38%, worst
/// 2.5%, area off by 0.14 of the leaf at worst. The buried texels once
/// entered the leaves' lookups as radiosity 0 and their area as exposed:
/// -26%, 56%, 0.67.
#[test]
fn a_leaf_crossing_a_solids_footprint_shows_its_exposed_part() {
    let (x0, x1, y0, y1, h) = (0.23, 0.41, 0.27, 0.43, 0.002);
    let mut scene = Polygons::default()
        .add("receiver", "receiver", &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
        .add("emitter", "emitter", &[[0.4, 0.4, 0.4], [0.4, 0.6, 0.4], [0.6, 0.6, 0.4], [0.6, 0.4, 0.4]])
        .add("slab", "black", &[[x0, y0, h], [x1, y0, h], [x1, y1, h], [x0, y1, h]]);
    for side in [[[x0, y0], [x0, y1]], [[x0, y1], [x1, y1]], [[x1, y1], [x1, y0]], [[x1, y0], [x0, y0]]] {
        let [a, b] = side;
        scene = scene.add("slab", "black", &[[a[0], a[1], 0.0], [a[0], a[1], h], [b[0], b[1], h], [b[0], b[1], 0.0]]);
    }
    let Some(solved) = shoot("gpu_elements_buried", &scene, &["--texels", "8000"]) else { return };
    let shift = solved.manifest.world_from_mesh_translation;
    let exposed = |p: [f64; 3]| {
        let (x, y) = (p[0] + shift[0], p[1] + shift[1]);
        !((x0..=x1).contains(&x) && (y0..=y1).contains(&y))
    };
    let (mut bias, mut weight, mut worst, mut area_worst, mut count) = (0.0, 0.0, 0.0f64, 0.0f64, 0);
    for e in solved.solution.elements.iter().filter(|e| e.is_leaf()) {
        let t = e.triangle as usize;
        if solved.object_of(t) != "receiver" {
            continue;
        }
        let mut parts = vec![e.corners.map(|c| c.map(f64::from))];
        for _ in 0..5 {
            parts = parts.iter().flat_map(|&[a, b, c]| {
                let mid = |p: [f64; 2], q: [f64; 2]| [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0];
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            }).collect();
        }
        let centroids: Vec<[f64; 3]> = parts.iter().map(|[a, b, c]| solved.point(t, [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0])).collect();
        let open: Vec<&[f64; 3]> = centroids.iter().filter(|p| exposed(**p)).collect();
        let fraction = open.len() as f64 / centroids.len() as f64;
        if !(0.3..0.97).contains(&fraction) {
            continue;
        }
        let want = open.iter().map(|p| solved.exact(t, **p)).sum::<f64>() / open.len() as f64;
        let error = f64::from(e.radiosity[0]) / want - 1.0;
        let geometric = solved.mesh.triangles[t].area as f64 / 4f64.powi(e.level as i32);
        bias += fraction * error;
        weight += fraction;
        worst = worst.max(error.abs());
        area_worst = area_worst.max((f64::from(e.area) / geometric - fraction).abs());
        count += 1;
    }
    let bias = bias / weight;
    eprintln!("buried: {count} leaves crossing the footprint, bias {:+.2}%, worst {:.2}%, exposed area off by {:.3} of the leaf at worst", 100.0 * bias, 100.0 * worst, area_worst);
    assert!(count >= 8, "{count} leaves cross the footprint; the scene does not test");
    assert!(bias.abs() < 0.02 && worst < 0.06, "bias {bias}, worst {worst}");
    assert!(area_worst < 0.25, "a leaf's area is off its exposed part's by {area_worst} of the leaf");
}
