//! Planar mirrors and thin glass: paper 004's reflection tree (Sec.
//! 4.3.2-4.3.3, issue 14 item 2), built during each shot.
//!
//! When a batch of a shot's samples lights specular triangles (the mark
//! pass, `mark_specular` in mirrors.wgsl: a texel of a triangle with
//! `rho_s > 0` or `tau_s > 0` that gathers light), they are grouped by
//! plane, and each group becomes a child node: a *mirror* node reflects the
//! samples across the plane (Sillion's virtual shooter: position, frame
//! and polygon, `y' = y - 2 (n . y + w) n`), a *pane* node keeps them (the
//! transmissive node of Sec. 4.3.3: refraction is neglected, a thin
//! plate). A surface both reflecting and transmitting gives one node of
//! each. Each node renders, from each virtual sample, the scene beyond the
//! window's plane with a perspective projection towards the window (the
//! paper's frustum, Fig. 4.3; [`view`]), and every texel in front of the
//! window gathers from the virtual samples (Eq. 4.7-4.8)
//!
//! ```text
//! H += c_1 c_2 ... c_n  B_s F(s(m_1 ... m_n) -> texel) V
//! ```
//!
//! `c` the windows' `rho_s` (mirror) or `tau_s` (pane) of the triangles
//! the path crosses, `F` the solver's transfer from the mirrored sample
//! (Eq. 4.5), `V` the visibility of every leg: the texel in the node's
//! map, then the crossing point on each window in its parent's map, up to
//! the real sample's own maps. So a deeper node sees only through its
//! ancestors' windows, and whatever the parent's map shows in front of a
//! window occludes it (mirror-object-mirror occlusion, Fig. 4.1; the paper
//! does both with the stencil buffer in one map). The node's lit specular
//! triangles become its children, depth first.
//!
//! A child is rendered while its depth is at most `reflection_depth` and
//! its bound `sum_s F_e(s) P_s c*` is at least `reflection_threshold` of
//! the emitted power, `P_s` the sample's power (W; a light's intensity,
//! W/sr), `c*` the product of its windows' largest coefficients, `F_e`
//! Eq. 4.6's frustum estimate made a bound ([`bound`]); a cut child adds
//! its bound to [`TreeWork::truncated`], which bounds the power the cut
//! leaves out (all of it would pass that window). Powers are summed over
//! R, G and B, as the emitted power they are compared with. Not simulated:
//! glossy reflection, refraction bending, alpha masks in the frustum maps
//! (masked surfaces are opaque there), and curved mirrors, which are their
//! facets (each facet's plane its own node).

use crate::gpu::{Gpu, GpuLevel, GpuParams, GpuSample, GpuView, NodeData};
use glam::DVec3;
use radiometry::geometry::frame_with_normal;
use schemas::mesh::{Manifest, Mesh};
use std::f64::consts::PI;
use std::time::Instant;
use stage_kit::scene::triangle_corners;

/// Two triangles lie in one window's plane when their unit normals differ
/// by less than this and their planes' offsets by less than this times
/// the scene's diagonal.
const COPLANAR: f64 = 1e-4;

/// The specular side of a scene: per triangle its `rho_s` and `tau_s`.
#[derive(Clone, Debug)]
pub struct Specular {
    /// Per triangle: `(rho_s, tau_s)`, RGB.
    pub coefficients: Vec<([f64; 3], [f64; 3])>,
}

impl Specular {
    /// The specular coefficients of `mesh`'s triangles, or `None` where no
    /// material is specular (then no reflection-tree code runs).
    pub fn of(mesh: &Mesh, manifest: &Manifest) -> Option<Specular> {
        let coefficients: Vec<_> = mesh
            .triangles
            .iter()
            .map(|t| {
                let m = &manifest.materials[t.material as usize];
                (m.specular_reflectance, m.specular_transmittance)
            })
            .collect();
        let scene = Specular { coefficients };
        scene.flags().contains(&1).then_some(scene)
    }

    /// Per triangle: 1 where it is specular (the mark pass's flags).
    pub fn flags(&self) -> Vec<u32> {
        self.coefficients.iter().map(|(rho, tau)| u32::from(rho.iter().chain(tau).any(|&x| x > 0.0))).collect()
    }
}

/// A window's plane `n . x + w = 0`, oriented so that the node's virtual
/// shooter lies behind it (`n . x + w < 0`) and its receivers in front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: DVec3,
    /// Offset.
    pub offset: f64,
}

impl Plane {
    /// The mirror image of the point `p`.
    pub fn reflect_point(&self, p: DVec3) -> DVec3 {
        p - 2.0 * (self.normal.dot(p) + self.offset) * self.normal
    }

    /// The mirror image of the direction `d`.
    pub fn reflect_vector(&self, d: DVec3) -> DVec3 {
        d - 2.0 * self.normal.dot(d) * self.normal
    }
}

/// A node's kind: a mirror reflects the shooter, a pane keeps it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `rho_s`: the virtual shooter is mirrored in the plane.
    Mirror,
    /// `tau_s`: the shooter stays; its light goes through.
    Pane,
}

/// A group of lit specular triangles in one plane, of one kind: a child
/// node of the reflection tree.
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    /// Mirror or pane.
    pub kind: Kind,
    /// The oriented plane (front normal for a mirror, back for a pane).
    pub plane: Plane,
    /// `(triangle, coefficient)`: `rho_s` or `tau_s`.
    pub triangles: Vec<(u32, [f64; 3])>,
}

impl Window {
    /// The largest coefficient of its triangles (any channel).
    pub fn largest(&self) -> f64 {
        self.triangles.iter().flat_map(|(_, c)| *c).fold(0.0, f64::max)
    }

    /// The window entries as the GPU reads them.
    pub fn entries(&self) -> Vec<[f32; 4]> {
        self.triangles.iter().map(|&(t, c)| [c[0] as f32, c[1] as f32, c[2] as f32, f32::from_bits(t)]).collect()
    }
}

/// Groups the lit specular triangles `lit` into windows: per plane (the
/// triangle's front plane, within `COPLANAR`), a mirror of those with
/// `rho_s > 0` and a pane of those with `tau_s > 0`.
pub fn windows(mesh: &Mesh, specular: &Specular, lit: &[u32], diagonal: f64) -> Vec<Window> {
    let mut out: Vec<Window> = Vec::new();
    for &t in lit {
        let p = triangle_corners(mesh, t as usize);
        let Some(n) = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize() else { continue };
        let (rho, tau) = specular.coefficients[t as usize];
        for (kind, c, sign) in [(Kind::Mirror, rho, 1.0), (Kind::Pane, tau, -1.0)] {
            if c.iter().all(|&x| x <= 0.0) {
                continue;
            }
            let plane = Plane { normal: sign * n, offset: -sign * n.dot(p[0]) };
            let same = |w: &Window| w.kind == kind && (w.plane.normal - plane.normal).length() < COPLANAR && (w.plane.offset - plane.offset).abs() < COPLANAR * diagonal;
            match out.iter_mut().find(|w| same(w)) {
                Some(w) => w.triangles.push((t, c)),
                None => out.push(Window { kind, plane, triangles: vec![(t, c)] }),
            }
        }
    }
    out
}

fn v3(a: [f32; 4]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

fn f4(v: DVec3, w: f32) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w]
}

/// The sample `s` as the window shows it: mirrored in a mirror's plane
/// (position, frame, polygon, so a light's table is read in its own
/// angles), unchanged through a pane.
pub fn virtual_sample(s: &GpuSample, window: &Window) -> GpuSample {
    if window.kind == Kind::Pane {
        return *s;
    }
    let plane = window.plane;
    let point = |a: [f32; 4]| f4(plane.reflect_point(v3(a)), a[3]);
    let vector = |a: [f32; 4]| f4(plane.reflect_vector(v3(a)), a[3]);
    GpuSample {
        position_area: point(s.position_area),
        t: vector(s.t),
        b: vector(s.b),
        n: vector(s.n),
        power: s.power,
        shading: vector(s.shading),
        polygon: s.polygon.map(point),
        hidden: s.hidden.map(point),
        // Read only by the receiver pass of the shot itself (variation).
        quadrants: [[0.0; 4]; 8],
    }
}

/// The frustum from `eye` through the window (004 Fig. 4.3): the axis
/// towards the window's corners' centroid (the window's plane normal
/// where some corner lies near or behind that axis' plane), and
/// `k = 1 / tan(alpha / 2)`, the smallest field of view that holds every
/// corner.
pub fn view(mesh: &Mesh, window: &Window, eye: DVec3) -> GpuView {
    let points: Vec<DVec3> = window.triangles.iter().flat_map(|&(t, _)| triangle_corners(mesh, t as usize)).map(|p| p - eye).collect();
    let centroid = points.iter().sum::<DVec3>() / points.len() as f64;
    let mut axis = centroid.normalize_or(window.plane.normal);
    if points.iter().any(|p| p.dot(axis) < 0.1 * p.length()) {
        axis = window.plane.normal;
    }
    let [right, up, axis] = frame_with_normal(axis);
    let spread = points.iter().map(|p| (p.dot(right).abs().max(p.dot(up).abs())) / p.dot(axis).max(1e-12)).fold(1e-6, f64::max);
    // A hair wider, so corners on the frustum's edges stay inside.
    let k = 1.0 / (spread * (1.0 + 1e-3));
    GpuView { right: f4(right * k, 0.0), up: f4(up * k, 0.0), axis: f4(axis, k as f32) }
}

/// Eq. 4.6 made a bound: the frustum's solid angle `4 asin(sin^2(alpha /
/// 2))` over pi times the largest cosine between the sample's normal and
/// a direction inside it (the angle `Theta` to the axis less the half
/// diagonal `beta`, where the paper takes `cos Theta`), times the sample's
/// power `B A` (W); for a light `I Omega` (W). This bounds the power the
/// sample sends through the window.
pub fn bound(s: &GpuSample, view: &GpuView) -> f64 {
    let k = view.axis[3] as f64;
    let half = (1.0 / k).atan();
    let omega = 4.0 * (half.sin().powi(2)).asin();
    let power: f64 = s.power[..3].iter().map(|&x| x.max(0.0) as f64).sum();
    if s.power[3] != 0.0 {
        return power * omega;
    }
    let theta = v3(s.n).angle_between(v3(view.axis));
    let beta = (2f64.sqrt() / k).atan();
    omega / PI * (theta - beta).max(0.0).cos() * power * s.position_area[3] as f64
}

/// The GPU description of a node whose maps start at `first_layer`.
pub fn level(window: &Window, first_layer: u32) -> GpuLevel {
    GpuLevel { plane: f4(window.plane.normal, window.plane.offset as f32), window: [0, 0, first_layer, 0] }
}

/// The reflection tree's work over a solve.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreeWork {
    /// Nodes rendered (each a frustum map per sample of its batch).
    pub nodes: u64,
    /// The deepest node rendered (windows on its path).
    pub depth: u32,
    /// Sum of the rendered nodes' bounds, W (R + G + B): the power they
    /// carried is at most this.
    pub bound: f64,
    /// Sum of the cut nodes' bounds, W (R + G + B): the power the depth
    /// and the threshold left out is at most this.
    pub truncated: f64,
    /// Frustum maps rendered.
    pub layers: u64,
    /// Seconds in the specular recursion (004 Table 4.1's t_spec): the
    /// mark passes, the nodes' maps and receiver passes.
    pub seconds: f64,
}

/// Where the reflection tree stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knobs {
    /// Most windows on a path (`reflection_depth`).
    pub depth: u32,
    /// A node whose bound is under this many W is cut
    /// (`reflection_threshold` times the emitted power).
    pub cut: f64,
    /// The scene's diagonal, m.
    pub diagonal: f64,
}

/// The reflection tree's inputs for a shot.
pub struct Tree<'a> {
    /// The mesh the GPU holds.
    pub mesh: &'a Mesh,
    /// Its specular coefficients.
    pub specular: &'a Specular,
    /// Where it stops.
    pub knobs: Knobs,
    /// The first virtual sample in the samples buffer.
    pub virtual_base: u32,
}

impl Tree<'_> {
    /// The tree under one batch of a shot, right after its receiver pass
    /// (its maps still in the first `sample_count x layers_per_sample`
    /// layers; `root` its samples with their powers): the specular
    /// triangles it lit, their windows, and so on depth first (004
    /// Listing 4.1).
    pub fn shoot(&self, gpu: &Gpu, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams, root: &[GpuSample], work: &mut TreeWork) {
        // The batch's own passes finish first, so t_spec counts only the tree.
        device.poll(wgpu::PollType::wait_indefinitely()).expect("waiting for the GPU");
        let started = Instant::now();
        let params = GpuParams { level: 0, virtual_base: self.virtual_base, ..*params };
        let lit = gpu.lit_specular(device, queue, &params);
        self.children(gpu, device, queue, &params, root, 1.0, &lit, work);
        work.seconds += started.elapsed().as_secs_f64();
    }

    /// The children of the node at `params.level` (0: the root), whose
    /// samples are `parent`, coefficient product `chain`, that lit `lit`.
    #[allow(clippy::too_many_arguments)]
    fn children(&self, gpu: &Gpu, device: &wgpu::Device, queue: &wgpu::Queue, params: &GpuParams, parent: &[GpuSample], chain: f64, lit: &[u32], work: &mut TreeWork) {
        let level = params.level;
        let count = params.sample_count;
        for window in windows(self.mesh, self.specular, lit, self.knobs.diagonal) {
            let samples: Vec<GpuSample> = parent.iter().map(|s| virtual_sample(s, &window)).collect();
            let views: Vec<GpuView> = samples.iter().map(|s| view(self.mesh, &window, v3(s.position_area))).collect();
            let carried = chain * window.largest();
            let bound = carried * samples.iter().zip(&views).map(|(s, v)| bound(s, v)).sum::<f64>();
            if level >= self.knobs.depth || bound < self.knobs.cut {
                work.truncated += bound;
                continue;
            }
            work.nodes += 1;
            work.depth = work.depth.max(level + 1);
            work.bound += bound;
            work.layers += count as u64;
            let first_layer = count * (params.layers_per_sample + level);
            let entries = window.entries();
            let data = NodeData { level: self::level(&window, first_layer), windows: &entries, samples: &samples, views: &views };
            gpu.write_node(queue, level, self.virtual_base, &data);
            let node = GpuParams { level: level + 1, ..*params };
            gpu.shoot_node(device, queue, &node, first_layer);
            let lit = gpu.lit_specular(device, queue, &node);
            self.children(gpu, device, queue, &node, &samples, carried, &lit, work);
        }
    }
}
