//! Surface detail on the GPU (issue 13; paper 004 Sec. 4.2, 4.3.4, 2.3.3)
//! on lavapipe or any Vulkan adapter, against closed forms written here:
//! Lambert's point-to-polygon formula (`radiometry::form_factor`) times
//! each texel's reflectance, over the opaque part of a masked emitter or
//! through the hole of a masked occluder, and for a normal map's tilted
//! normal. Only the emitter shoots (`max_shots`), so each floor texel's
//! radiosity is `rho(x) E F(x -> emitter)`. Without an adapter the tests
//! skip loudly, but fail under CI.

use glam::DVec3;
use gpu_shoot::{gpu, output, solve, Params, Solved, Visibility};
use radiometry::form_factor::point_to_polygon;
use schemas::header::{Provenance, Schema};
use schemas::lightmap::Lightmap;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use schemas::surface::{Surface, Texture, TextureKind, NONE};
use test_support::gpu::device_or_skip;
use test_support::meshes::{manifest, material, triangles};

/// Emitted radiosity of the emitter, W/m².
const E: f64 = 10.0;


/// The horizontal square `[x0, x1] x [z0, z1]` at height `y` as two right
/// triangles whose legs run along x and z (so a region's texel grid lines
/// are lines of constant x and z), facing up or down.
#[allow(clippy::too_many_arguments)]
fn square(x0: f64, x1: f64, z0: f64, z1: f64, y: f64, up: bool, material: u32, object: u32) -> Vec<([DVec3; 3], u32, u32)> {
    let p = |x: f64, z: f64| DVec3::new(x, y, z);
    let (a, b) = ([p(x0, z0), p(x0, z1), p(x1, z0)], [p(x1, z1), p(x1, z0), p(x0, z1)]);
    let flip = |t: [DVec3; 3]| if up { t } else { [t[0], t[2], t[1]] };
    vec![(flip(a), material, object), (flip(b), material, object)]
}

/// The corners of square `[x0, x1] x [z0, z1]`, for Lambert's formula.
fn polygon(x0: f64, x1: f64, z0: f64, z1: f64, y: f64) -> Vec<DVec3> {
    vec![DVec3::new(x0, y, z0), DVec3::new(x1, y, z0), DVec3::new(x1, y, z1), DVec3::new(x0, y, z1)]
}

/// A grey floor `[0, 1]^2` (rho 1/2, material 0, triangles 0 and 1)
/// under a black lamp `[0.25, 0.75]^2` at height `h` (material 1,
/// emitting `E`, triangles 2 and 3).
fn floor_and_lamp(h: f64) -> (Mesh, Manifest) {
    let mut list = square(0.0, 1.0, 0.0, 1.0, 0.0, true, 0, 0);
    list.extend(square(0.25, 0.75, 0.25, 0.75, h, false, 1, 1));
    (triangles(&list), manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [E; 3])]))
}

/// Texture coordinates `((x - x0) / (x1 - x0), (z - z0) / (z1 - z0))` for
/// the triangles `range` of `mesh`.
fn uvs(mesh: &Mesh, range: std::ops::Range<usize>, x0: f64, x1: f64, z0: f64, z1: f64) -> Vec<(u32, [[f32; 2]; 3])> {
    range
        .map(|t| {
            let uv = mesh.triangles[t].vertices.map(|v| {
                let p = mesh.positions[v as usize];
                [((p[0] as f64 - x0) / (x1 - x0)) as f32, ((p[2] as f64 - z0) / (z1 - z0)) as f32]
            });
            (t as u32, uv)
        })
        .collect()
}

/// A texture of `kind`, `width x height` texels (row 0 at the top).
fn texture(kind: TextureKind, width: usize, height: usize, texels: Vec<[f32; 4]>) -> Texture {
    Texture { kind, width, height, texels, scale: [1.0, 1.0], offset: [0.0, 0.0], clamp: false, strength: 1.0 }
}

fn surface(uvs: Vec<(u32, [[f32; 2]; 3])>, tangents: Vec<(u32, [f32; 4])>, material_maps: Vec<[u32; 3]>, textures: Vec<Texture>) -> Surface {
    Surface { header: Surface::header(Provenance::in_memory("test")), uvs, shading_normals: Vec::new(), tangents, material_maps, textures }
}

/// One shot per emitter triangle (the last two of the mesh), every
/// region `n x n` texels, texels shooting one by one.
fn params(n: u32) -> Params {
    Params { min_size: n, max_size: n, shoot_level: 0, max_shots: 2, convergence_target: 1.0, resolution: 256, overshoot: false, ..Params::default() }
}

fn run(mesh: &Mesh, m: &Manifest, surface: Option<&Surface>, params: &Params) -> Option<Solved> {
    let (device, queue) = device_or_skip(gpu::quiet_device_select_layer, gpu::acquire)?;
    Some(solve(&device, &queue, mesh, m, surface, &[], params, &mut |_| {}).unwrap())
}

/// The floor texels of a solve (triangles 0 and 1): index and point.
fn floor_texels(solved: &Solved) -> impl Iterator<Item = (usize, DVec3)> + '_ {
    solved.atlas.texels.iter().enumerate().filter(|(_, t)| t.triangle < 2).map(|(k, t)| (k, DVec3::from(t.position.map(f64::from))))
}

/// Checkerboard reflectances: `RHO[0]` where `(x < 1/2) == (z < 1/2)`.
const RHO: [[f64; 3]; 2] = [[0.8, 0.5, 0.2], [0.1, 0.3, 0.6]];

fn checker(x: f64, z: f64) -> [f64; 3] {
    RHO[usize::from((x < 0.5) != (z < 0.5))]
}

/// A floor `[0, 1]^2` with a 2 x 2 checkerboard texture of two colours
/// under a square emitter `[0.25, 0.75]^2` at height 0.5: every floor
/// texel off the checks' edges has radiosity `rho(x) E F(x)` per channel within 2% (the
/// hemicube's resolution; measured 0.02%: the checks' edges are texel
/// edges), and every solution element not touching a check's edge (whose
/// bilinear reconstruction blends the two colours over half a texel) the
/// mean of `rho E F` over it within 0.5% (measured 0.12%), the floor's
/// power within 0.5% of its reference (measured 0.09%).
#[test]
fn checkerboard_floor_takes_each_texels_reflectance() {
    let h = 0.5;
    let (mesh, m) = floor_and_lamp(h);
    // 64 x 64 texels, clamped, so the bilinear reflectance is the check's
    // but within half a texture texel (1/128) of a check's edge; row 0 is
    // the top (z near 1).
    let c = |rho: [f64; 3]| [rho[0] as f32, rho[1] as f32, rho[2] as f32, 1.0];
    let texels = (0..64 * 64).map(|k| c(checker((k % 64) as f64 / 64.0, 1.0 - (k / 64) as f64 / 64.0 - 1e-9))).collect();
    let board = Texture { clamp: true, ..texture(TextureKind::Diffuse, 64, 64, texels) };
    let s = surface(uvs(&mesh, 0..2, 0.0, 1.0, 0.0, 1.0), Vec::new(), vec![[0, NONE, NONE], [NONE; 3]], vec![board]);
    let Some(solved) = run(&mesh, &m, Some(&s), &params(32)) else { return };
    let emitter = polygon(0.25, 0.75, 0.25, 0.75, h);
    let exact = |p: DVec3| {
        let f = E * point_to_polygon(p, DVec3::Y, &emitter);
        checker(p.x, p.z).map(|r| r * f)
    };
    // The texels next to a check's edge (1/32 wide) take the blend band's mean.
    let mut worst = 0.0f64;
    for (k, p) in floor_texels(&solved).filter(|(_, p)| (p.x - 0.5).abs() > 1.0 / 32.0 && (p.z - 0.5).abs() > 1.0 / 32.0) {
        let reference = exact(p);
        for (b, r) in solved.radiosity[k].iter().zip(reference) {
            worst = worst.max((*b as f64 - r).abs() / r);
        }
    }
    eprintln!("checkerboard floor: worst texel {worst:.4}");
    assert!(worst < 0.02, "texel radiosity vs rho(x) E F(x): {worst}");

    // Elements: the stage's own solution, against a midpoint rule of rho E F.
    let lightmap = output::lightmap(&solved, &mesh, Lightmap::header(Provenance::in_memory("test")));
    let solution = output::solution(&lightmap, &mesh, &m, &solved.tiles, None, Params::default().texels_per_leaf, Solution::header(Provenance::in_memory("test")));
    let (mut worst, mut count, mut power, mut reference_power) = (0.0f64, 0, 0.0, 0.0);
    for e in solution.elements.iter().filter(|e| e.is_leaf() && e.triangle < 2) {
        let corners = mesh.triangles[e.triangle as usize].vertices.map(|v| DVec3::from(mesh.positions[v as usize].map(f64::from)));
        let at = |b: [f32; 2]| corners[0] + b[0] as f64 * (corners[1] - corners[0]) + b[1] as f64 * (corners[2] - corners[0]);
        let points = e.corners.map(at);
        let mut mean = [0.0; 3];
        let q = 16;
        let mut samples = 0.0;
        for i in 0..q {
            for j in 0..q - i {
                // The midpoints of a q x q split of the element (upright and inverted triangles).
                for (a, b, w) in [((i as f64 + 1.0 / 3.0), (j as f64 + 1.0 / 3.0), 1.0), ((i as f64 + 2.0 / 3.0), (j as f64 + 2.0 / 3.0), 1.0)] {
                    if a + b > q as f64 {
                        continue;
                    }
                    let p = points[0] + a / q as f64 * (points[1] - points[0]) + b / q as f64 * (points[2] - points[0]);
                    let r = exact(p);
                    for ch in 0..3 {
                        mean[ch] += w * r[ch];
                    }
                    samples += w;
                }
            }
        }
        let mean = mean.map(|v| v / samples);
        power += e.radiosity[0] as f64 * e.area as f64;
        reference_power += mean[0] * e.area as f64;
        let touches = points.iter().any(|p| (p.x - 0.5).abs() < 1e-6 || (p.z - 0.5).abs() < 1e-6);
        if touches {
            continue;
        }
        for (b, r) in e.radiosity.iter().zip(mean) {
            worst = worst.max((*b as f64 - r).abs() / r);
        }
        count += 1;
    }
    let power_error = (power / reference_power - 1.0).abs();
    eprintln!("checkerboard floor: worst of {count} elements {worst:.4}, floor power {power_error:.4}");
    assert!(count > 50, "{count}");
    assert!(worst < 5e-3, "element radiosity vs mean rho E F: {worst}");
    assert!(power_error < 5e-3, "floor power: {power_error}");
}

/// An alpha mask of `width x height` texels, `opaque(column, row)` 1 or 0.
fn mask(width: usize, height: usize, opaque: impl Fn(usize, usize) -> bool) -> Texture {
    let texels = (0..width * height).map(|k| [f32::from(u8::from(opaque(k % width, k / width))); 4]).collect();
    texture(TextureKind::Alpha, width, height, texels)
}

/// A floor `[0, 1]^2` (grey, rho 1/2) under the emitter `[0.25, 0.75]^2`
/// at height `h`, with or without an alpha mask of 8 stripes along x
/// that removes every second one.
fn striped_emitter(h: f64, masked: bool) -> Option<(Solved, Mesh)> {
    let (mesh, m) = floor_and_lamp(h);
    let s = surface(uvs(&mesh, 2..4, 0.25, 0.75, 0.25, 0.75), Vec::new(), vec![[NONE; 3], [NONE, 0, NONE]], vec![mask(8, 1, |x, _| x % 2 == 0)]);
    let solved = run(&mesh, &m, masked.then_some(&s), &params(32))?;
    Some((solved, mesh))
}

/// An emitter whose alpha mask removes half its area in stripes: its
/// power halves exactly, a far floor (20 emitter widths away) gets half
/// the unmasked emitter's irradiance at every texel within 1% (measured
/// 0.3%), and a near floor (one width away) Lambert's formula summed over
/// the opaque stripes within 2% per texel (measured 0.6%).
#[test]
fn an_emitter_masked_in_stripes_shoots_from_its_opaque_half() {
    let Some((full, _)) = striped_emitter(10.0, false) else { return };
    let Some((half, _)) = striped_emitter(10.0, true) else { return };
    assert!((half.emitted_power[0] / full.emitted_power[0] - 0.5).abs() < 1e-6, "{:?} vs {:?}", half.emitted_power, full.emitted_power);
    assert!(half.work.mask_texels > 0 && full.work.mask_texels == 0);
    let mut worst = 0.0f64;
    for (k, _) in floor_texels(&half) {
        worst = worst.max((half.radiosity[k][0] as f64 / full.radiosity[k][0] as f64 - 0.5).abs() / 0.5);
    }
    eprintln!("striped emitter, far floor: worst texel ratio error {worst:.4}");
    assert!(worst < 0.01, "far floor: masked / full irradiance vs 1/2: {worst}");

    let h = 0.5;
    let Some((near, _)) = striped_emitter(h, true) else { return };
    let stripes: Vec<Vec<DVec3>> = (0..8).step_by(2).map(|k| polygon(0.25 + k as f64 / 16.0, 0.25 + (k + 1) as f64 / 16.0, 0.25, 0.75, h)).collect();
    let mut worst = 0.0f64;
    for (k, p) in floor_texels(&near) {
        let exact = 0.5 * E * stripes.iter().map(|s| point_to_polygon(p, DVec3::Y, s)).sum::<f64>();
        worst = worst.max((near.radiosity[k][0] as f64 - exact).abs() / exact);
    }
    eprintln!("striped emitter, near floor: worst texel {worst:.4}");
    assert!(worst < 0.02, "near floor vs Lambert over the opaque stripes: {worst}");
}

/// A floor `[0, 1]^2` under the emitter `[0.25, 0.75]^2` at height 1,
/// with a black occluder at height 1/2 that leaves the hole `[0.375,
/// 0.625]^2` open: the square `[0, 1]^2` with an alpha mask (`masked`), or
/// the four rectangles around the hole.
fn occluder_with_a_hole(masked: bool, visibility: Visibility) -> Option<Solved> {
    let mut list = square(0.0, 1.0, 0.0, 1.0, 0.0, true, 0, 0);
    let (a, b) = (0.375, 0.625);
    if masked {
        list.extend(square(0.0, 1.0, 0.0, 1.0, 0.5, true, 2, 2));
    } else {
        for (x0, x1, z0, z1) in [(0.0, 1.0, 0.0, a), (0.0, 1.0, b, 1.0), (0.0, a, a, b), (b, 1.0, a, b)] {
            list.extend(square(x0, x1, z0, z1, 0.5, true, 2, 2));
        }
    }
    let emitter = list.len();
    list.extend(square(0.25, 0.75, 0.25, 0.75, 1.0, false, 1, 1));
    let mesh = triangles(&list);
    let m = manifest(3, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [E; 3]), material([0.0; 3], [0.0; 3])]);
    let hole = |c: usize| (3..5).contains(&c);
    let s = surface(uvs(&mesh, 2..4, 0.0, 1.0, 0.0, 1.0), Vec::new(), vec![[NONE; 3], [NONE; 3], [NONE, 0, NONE]], vec![mask(8, 8, |x, y| !(hole(x) && hole(y)))]);
    let solved = run(&mesh, &m, masked.then_some(&s), &Params { visibility, ..params(32) })?;
    let shooters = [format!("triangle {emitter}"), format!("triangle {}", emitter + 1)];
    assert!(solved.shots.iter().all(|s| shooters.contains(&s.shooter)), "{:?}", solved.shots);
    Some(solved)
}

/// An alpha-masked occluder with a hole casts the shadow of the geometry
/// it stands for: every floor texel within 0.5% of the brightest texel of
/// the run with four rectangles around the hole (measured 0.0%), and
/// both, per texel, Lambert's formula over the part of the emitter seen
/// through the hole (its image `2 q - p` on the emitter's plane, cut by
/// the emitter) within 8% of the brightest texel's, the floor's power
/// within 5% (the visibility test's neighbour pixels widen the lit patch
/// by about a pixel at the shadow's edges, with geometry as with the mask;
/// measured 6.1% and 3.6%). With the stereographic map, whose affine
/// placement of these large triangles misplaces the shadow (004 Fig. 4.4),
/// the masked occluder is no farther from Lambert than the geometry
/// (measured 13.9% and 20.6% of the peak).
#[test]
fn an_occluder_masked_with_a_hole_casts_the_shadow_of_its_geometry() {
    for visibility in [Visibility::Hemicube, Visibility::Stereographic] {
    let (Some(masked), Some(geometry)) = (occluder_with_a_hole(true, visibility), occluder_with_a_hole(false, visibility)) else { return };
    let exact = |p: DVec3| {
        let cut = |c: f64| ((0.75 - c).max(0.25), (1.25 - c).min(0.75));
        let ((x0, x1), (z0, z1)) = (cut(p.x), cut(p.z));
        if x0 >= x1 || z0 >= z1 {
            return 0.0;
        }
        0.5 * E * point_to_polygon(p, DVec3::Y, &polygon(x0, x1, z0, z1, 1.0))
    };
    let texels: Vec<(usize, DVec3)> = floor_texels(&masked).collect();
    let peak = texels.iter().map(|&(_, p)| exact(p)).fold(0.0, f64::max);
    let (mut worst, mut same, mut power, mut reference, mut geometric) = (0.0f64, 0.0f64, 0.0, 0.0, 0.0f64);
    for &(k, p) in &texels {
        let (b, x) = (masked.radiosity[k][0] as f64, exact(p));
        worst = worst.max((b - x).abs() / peak);
        geometric = geometric.max((geometry.radiosity[k][0] as f64 - x).abs() / peak);
        same = same.max((b - geometry.radiosity[k][0] as f64).abs() / peak);
        let area = masked.atlas.texels[k].area as f64;
        power += b * area;
        reference += x * area;
    }
    let power_error = (power / reference - 1.0).abs();
    eprintln!("occluder with a hole ({visibility:?}): masked vs geometry {same:.4} of the peak; vs Lambert worst texel {worst:.4} of the peak (geometry {geometric:.4}), floor power {power_error:.4}");
    if visibility == Visibility::Stereographic {
        // Large triangles: the map's affine placement misplaces geometry
        // and receivers alike; the mask is no worse than the geometry.
        assert!(worst <= geometric, "stereographic: masked {worst} vs geometry {geometric} of the peak");
        continue;
    }
    assert!(same < 5e-3, "masked occluder vs its geometry: {same} of the peak");
    assert!(peak > 0.0 && worst < 0.08, "floor through the hole vs Lambert: {worst} of the peak");
    assert!(power_error < 0.05, "floor power through the hole: {power_error}");
    }
}

/// A flat floor whose normal map tilts every normal by 30 degrees towards
/// +x (tangent x, texel `((sin a + 1) / 2, 1/2, (cos a + 1) / 2)`) under
/// the emitter `[0.25, 0.75]^2` at height 1/2: every texel's radiosity is
/// `rho E F(x, n')` for the tilted normal `n' = (sin a, cos a, 0)` within
/// 2% (measured 0.9%).
#[test]
fn a_normal_map_tilts_the_receivers_cosine() {
    let (h, angle) = (0.5, 30f64.to_radians());
    let (mesh, m) = floor_and_lamp(h);
    let texel = [((angle.sin() + 1.0) / 2.0) as f32, 0.5, ((angle.cos() + 1.0) / 2.0) as f32, 1.0];
    let tangents = vec![(0, [1.0, 0.0, 0.0, 1.0]), (1, [1.0, 0.0, 0.0, 1.0])];
    let s = surface(uvs(&mesh, 0..2, 0.0, 1.0, 0.0, 1.0), tangents, vec![[NONE, NONE, 0], [NONE; 3]], vec![texture(TextureKind::Normal, 1, 1, vec![texel])]);
    let Some(solved) = run(&mesh, &m, Some(&s), &params(32)) else { return };
    let tilted = DVec3::new(angle.sin(), angle.cos(), 0.0);
    let emitter = polygon(0.25, 0.75, 0.25, 0.75, h);
    let (mut worst, mut flat) = (0.0f64, 0.0f64);
    for (k, p) in floor_texels(&solved) {
        let exact = 0.5 * E * point_to_polygon(p, tilted, &emitter);
        let untilted = 0.5 * E * point_to_polygon(p, DVec3::Y, &emitter);
        worst = worst.max((solved.radiosity[k][0] as f64 - exact).abs() / exact);
        flat = flat.max((untilted - exact).abs() / exact);
    }
    eprintln!("normal map: worst texel {worst:.4} (the untilted normal is up to {flat:.2} off)");
    assert!(flat > 0.2, "the tilt must matter: {flat}");
    assert!(worst < 0.02, "texel radiosity vs Lambert for the tilted normal: {worst}");
}

/// A closed box whose walls take their reflectance 0.6 from a texture
/// (their material's `Kd` says 0.2; the light's untextured quad reflects
/// 0.6) balances its energy with the texture's reflectance: emitted =
/// absorbed, `sum B A = P / (1 - rho)`, within 1% (measured 0.08%; with
/// `Kd` it would be 1 / 0.4 over 1 / 0.8, twice).
#[test]
fn a_closed_box_with_textured_walls_balances_with_the_textures_reflectance() {
    let (rho, kd) = (0.6, 0.2);
    let mesh = test_support::meshes::closed_box(1.0, 0.3);
    let m = manifest(2, vec![material([kd; 3], [0.0; 3]), material([rho; 3], [E; 3])]);
    let walls: Vec<(u32, [[f32; 2]; 3])> = (0..mesh.triangles.len())
        .filter(|&t| mesh.triangles[t].material == 0)
        .map(|t| (t as u32, mesh.triangles[t].vertices.map(|v| [mesh.positions[v as usize][0] + mesh.positions[v as usize][2], mesh.positions[v as usize][1]])))
        .collect();
    let s = surface(walls, Vec::new(), vec![[0, NONE, NONE], [NONE; 3]], vec![texture(TextureKind::Diffuse, 1, 1, vec![[rho as f32, rho as f32, rho as f32, 1.0]])]);
    let params = Params { texels: 2000.0, shoot_level: 1, convergence_target: 0.999, ..Params::default() };
    let Some(solved) = run(&mesh, &m, Some(&s), &params) else { return };
    let sum: f64 = solved.atlas.texels.iter().enumerate().map(|(k, t)| solved.radiosity[k][0] as f64 * t.area as f64).sum();
    let expected = solved.emitted_power[0] / (1.0 - rho);
    let error = (sum / expected - 1.0).abs();
    eprintln!("closed box with textured walls: sum B A {sum:.4} vs P / (1 - rho) {expected:.4} ({error:.4})");
    assert!(error < 0.01, "{sum} vs {expected}");
}

/// A floor an alpha mask removes whole does not exist even with ambient
/// overshooting (its area is 0: no overshoot, no NaN): it receives
/// nothing, every value stays finite, and the solve converges.
#[test]
fn a_wholly_masked_floor_takes_no_part() {
    let (mesh, m) = floor_and_lamp(0.5);
    let s = surface(uvs(&mesh, 0..2, 0.0, 1.0, 0.0, 1.0), Vec::new(), vec![[NONE, 0, NONE], [NONE; 3]], vec![mask(2, 2, |_, _| false)]);
    let params = Params { texels: 2000.0, convergence_target: 0.999, overshoot: true, ..Params::default() };
    let Some(solved) = run(&mesh, &m, Some(&s), &params) else { return };
    assert!(solved.radiosity.iter().chain(&solved.residual).flatten().all(|v| v.is_finite()));
    assert!(floor_texels(&solved).all(|(k, _)| solved.radiosity[k] == [0.0; 3] && solved.atlas.texels[k].area == 0.0));
    assert!(solved.shots.last().is_none_or(|s| s.unshot_fraction <= 1e-3), "{:?}", solved.shots.last());
}

/// Without surface detail nothing changes: a surface artifact whose
/// materials have no texture gives the same bits as none, and allocates
/// no texture atlas (item 8).
#[test]
fn a_surface_without_textures_changes_no_bit() {
    let (mesh, m) = floor_and_lamp(0.5);
    let s = surface(uvs(&mesh, 0..4, 0.0, 1.0, 0.0, 1.0), Vec::new(), vec![[NONE; 3]; 2], Vec::new());
    let params = Params { texels: 3000.0, convergence_target: 0.999, ..Params::default() };
    let (Some(plain), Some(with)) = (run(&mesh, &m, None, &params), run(&mesh, &m, Some(&s), &params)) else { return };
    assert_eq!(plain.radiosity, with.radiosity);
    assert_eq!(plain.residual, with.residual);
    assert_eq!(plain.shots.len(), with.shots.len());
    assert_eq!((plain.work.mask_texels, with.work.mask_texels), (0, 0));
}
