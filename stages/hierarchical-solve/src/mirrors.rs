//! Planar mirrors and thin glass by virtual senders (issue 14 item 3;
//! Sillion's mirrored shooter, paper 004 Sec. 4.3.2).
//!
//! The specular triangles are grouped into *windows*: those of one material
//! in one oriented plane. A window `P` (unit normal `n`, reflectance
//! `rho_s`, transmittance `tau_s`) gives each leaf receiver `r` light from
//! every input triangle `s`:
//!
//! - by reflection, when `r` and `s` lie in front of `P`: from the virtual
//!   sender `s'`, `s` mirrored in `P` (`y' = y - 2 ((y - p0) . n) n`),
//!
//!   ```text
//!   H_r += rho_s F(r <- s') V'(r, s') B_s
//!   ```
//!
//!   with `F` Lambert's closed form averaged over `r`
//!   ([`radiometry::form_factor::triangle_to_polygon`]) and `V'` the
//!   fraction of stratified point pairs `(x, y)` whose ray `x -> y'` meets
//!   `P` first, inside the window, on its front, and whose reflected leg
//!   from there to `y` is clear: the form factor clipped to the window as
//!   seen from `r`, and the occlusion before and after the mirror, with the
//!   same ray caster as every link;
//! - by transmission, when `r` and `s` lie on opposite sides of `P`: from
//!   `s` itself (a transmissive node keeps the shooter), `tau_s F(r <- s)
//!   V'`, `V'` the fraction of pairs whose segment meets `P` first and is
//!   clear behind it. The ordinary link `r <- s` counts the pane as an
//!   occluder, so nothing is counted twice. Refraction is neglected (a thin
//!   plate), as paper 004 does.
//!
//! Both `r` and `s` must face the window (the point kernel is positive for
//! some pair). The senders are the elements `specular_sender_level` levels
//! below each input triangle (its leaves where it is coarser), each at its
//! area-mean radiosity: exact for a uniform emitter, an approximation for
//! a sender whose radiosity varies across it (in a closed box with a mirror
//! wall, level 0 loses 0.96% of the energy, level 2 0.07%).
//!
//! Chains: an image is itself a sender for the next window (the image of
//! an image, paper 004's reflection tree), up to `specular_depth` windows
//! per path, each step chosen by the sides of the previous image and the
//! receiver as above, the coefficients multiplied; `V'` follows the pair's
//! ray back through every window in turn (each must be met first, inside
//! it) to the sender. Light that meets one window more than the depth
//! allows is stopped there. Couplings whose coefficients times `F`
//! (largest channel) fall under `specular_min_factor` are dropped, and
//! their chains not followed further (the energy bound). Goniometric point
//! lights are not mirrored. The couplings join the gather
//! ([`crate::gather::solve`]) as extra terms of the receiving leaves'
//! irradiance. They depend only on the two elements they join (their
//! corners, the windows, the scene's triangles and the seed), not on the
//! radiosity, so each leaf-sender pair's images are traced once per solve:
//! a pass traces only the pairs of the leaves and senders that refinement
//! made since the last one and takes the others as they were built
//! ([`Windows::couplings`]); the weights, and so the solution, are those a
//! rebuild would give, bit for bit. The links' refinement oracle does
//! not see this light, so a leaf whose couplings' light varies over it
//! (the spread of `F` at its quadrature points) by more than the allowance
//! is split before the next pass ([`Couplings::to_split`]).

use crate::elements::Hierarchy;
use crate::links::Allowance;
use crate::rows::Rows;
use glam::DVec3;
use radiometry::form_factor::{point_kernel, triangle_to_polygon, AreaFactor, Quadrature};
use radiometry::rays::SceneRays;
use radiometry::sampling::{stratified_point, Stream};
use rayon::prelude::*;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Node;
use std::collections::HashMap;
use std::sync::Mutex;

/// A leaf's traced pairs that are not empty, by sender element.
type Pairs = Vec<(u32, Pair)>;

/// A leaf's couplings as assembled: `(sender, weight)` pairs, their spread,
/// the rays cast, the truncated irradiance, and its traced pairs to keep.
type LeafCouplings = (Vec<(usize, [f64; 3])>, f64, u64, f64, Pairs);

/// What the images of one sender element bring one leaf
/// ([`Windows::images`]): each coupling's weight `coefficients x F x V'`
/// with its factor `F`, and the coefficients times the unoccluded factors
/// of the images one window past the depth bound.
#[derive(Clone, Debug, Default, PartialEq)]
struct Pair {
    found: Vec<([f64; 3], AreaFactor)>,
    truncated: [f64; 3],
}

impl Pair {
    /// Whether the sender brings the leaf nothing, even past the depth.
    fn is_empty(&self) -> bool {
        self.found.is_empty() && self.truncated == [0.0; 3]
    }
}

/// The pairs traced so far: the senders they were traced for (sorted) and,
/// per leaf they were traced for, those of its pairs that are not empty,
/// by sender (sorted). A pair of a leaf and a sender both listed and
/// absent from the leaf's list is empty.
#[derive(Debug, Default)]
struct Traced {
    senders: Vec<u32>,
    leaves: HashMap<u32, Pairs>,
}

/// One window: the specular triangles of one material in one plane.
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    /// A point of the plane.
    pub origin: DVec3,
    /// Unit front normal.
    pub normal: DVec3,
    /// `rho_s`, RGB.
    pub reflectance: [f64; 3],
    /// `tau_s`, RGB.
    pub transmittance: [f64; 3],
    /// Whether its material is two-sided (each face a window of its own,
    /// which transmits only from its front, so the pane counts once).
    pub two_sided: bool,
    /// The corners of its triangles.
    pub corners: Vec<DVec3>,
}

impl Window {
    /// Whether light can go from window `from` on to this one: some corner
    /// of each lies strictly on the other's side its light leaves by or
    /// arrives from (either side of a transmitting window, the front of a
    /// reflecting one). Two faces of a convex mirror never pass light on.
    fn follows(&self, from: &Window) -> bool {
        let reaches = |a: &Window, b: &Window| {
            let transmits = a.transmittance.iter().any(|&x| x > 0.0);
            b.corners.iter().any(|&p| {
                let d = (p - a.origin).dot(a.normal);
                d > 0.0 || (transmits && d < 0.0)
            })
        };
        reaches(from, self) && reaches(self, from)
    }
}

/// The knobs of the couplings (the solver's `specular_*` parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Knobs {
    /// Rays per coupling.
    pub rays: usize,
    /// Smallest `coefficients x F` kept.
    pub min_factor: f64,
    /// Quadrature depth of the form factors.
    pub quadrature: u32,
    /// Seed of the rays.
    pub seed: u64,
    /// Levels below each input triangle its senders are taken at.
    pub sender_level: u32,
    /// Most windows along a path.
    pub max_events: u32,
}

/// Most windows whose couplings a solve traces. Every leaf takes the
/// images of every sender in every window, and of those images in every
/// window again up to `specular_depth` in a row, so the work grows with
/// the windows' count to that power. A curved mirror or pane is as many
/// windows as it has facets: McGuire's `CornellBox-Sphere`, whose mirror
/// sphere and glass sphere are 2,176 of its 2,188 triangles, ran for over
/// 11 minutes on one thread at `EPS` 0.1 without finishing its first
/// pass's couplings. A scene with more windows than this is solved without
/// its specular light, and the solve says so ([`Windows::new`]; on stderr
/// and in the report's notes). The benchmark's mirror scenes have 5 and 2
/// (`bench/assets/mirror`).
pub const MAX_WINDOWS: usize = 64;

/// The scene's windows and which triangle belongs to which.
pub struct Windows {
    /// The windows.
    pub windows: Vec<Window>,
    /// Per input triangle, its window, if it is specular.
    pub of_triangle: Vec<Option<u32>>,
    /// Rays per coupling.
    rays: usize,
    /// Smallest `coefficient x F` kept.
    min_factor: f64,
    /// Quadrature depth of the form factors.
    quadrature: u32,
    /// Most windows along a path (mirror reflections and pane passages).
    max_events: u32,
    /// Seed of the rays.
    seed: u64,
    /// Levels below each input triangle its senders are taken at.
    sender_level: u32,
    /// The pairs traced in earlier passes, reused by the next.
    traced: Mutex<Traced>,
}

/// The virtual senders' couplings into the leaves, by receiver (dense node
/// index, as the gather's links).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Couplings {
    /// Row `i`: node `i`'s couplings, each the dense index of its sender
    /// (an input triangle's root) and `coefficient x F x V'`, RGB.
    rows: Rows<[f64; 3]>,
    /// Per node, what its couplings' light varies by over it: the sum of
    /// `coefficient (F_max - F_min) V' B_s` over them (largest channel,
    /// `F` at the receiver quadrature's points, `B` when they were built).
    spread: Vec<f64>,
    /// Rays cast to build them.
    pub rays: u64,
    /// Bound of the irradiance the depth bound leaves out on a leaf (the
    /// largest over leaves, brightest channel, W/m², from the radiosity the
    /// couplings were built with): what the images one window past the
    /// bound would bring unoccluded, over `1 - c`, `c` the largest specular
    /// coefficient (the further orders as a geometric series; a bound
    /// where images get no closer with each window, as between parallel
    /// mirrors).
    pub truncation: f64,
}

impl Couplings {
    /// Irradiance node `i` receives through the windows from radiosity `b`.
    pub fn gather(&self, i: usize, b: &[[f64; 3]]) -> [f64; 3] {
        let mut g = [0.0; 3];
        for (s, w) in self.rows.row(i) {
            (0..3).for_each(|c| g[c] += w[c] * b[s][c]);
        }
        g
    }

    /// Sum of node `i`'s weights, largest channel (its share of the
    /// gather's contraction bound).
    pub fn row_sum(&self, i: usize) -> f64 {
        (0..3).map(|c| self.rows.row(i).map(|(_, w)| w[c]).sum::<f64>()).fold(0.0, f64::max)
    }

    /// The leaves to split so that the light through windows is resolved
    /// as the links' is: those whose reflected spread `rho_r x spread`
    /// exceeds what the refinement allows on them, and that the area floor
    /// lets split. (The links' oracle does not see this light: under a
    /// pane, the links from the emitter are occluded.)
    pub fn to_split(&self, h: &Hierarchy, b: &[[f64; 3]], allowance: &Allowance, min_area: f64) -> Vec<u32> {
        (0..h.elements.len() as u32)
            .filter(|&e| {
                let node = Node::Element(e);
                let i = h.flat(node);
                let rho = h.node_reflectance(node).into_iter().fold(0.0, f64::max);
                h.elements[e as usize].is_leaf() && rho * self.spread.get(i).copied().unwrap_or(0.0) > allowance.at(b[i]) && h.can_split(node, min_area)
            })
            .collect()
    }

    /// Number of couplings.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

/// A sender as seen through a chain of windows.
#[derive(Clone, Debug)]
struct Image {
    /// The sender's corners, then its image after each window.
    corners: Vec<[DVec3; 3]>,
    /// Front normal of the last image.
    normal: DVec3,
    /// The windows, sender side first.
    path: Vec<u32>,
    /// Product of the specular coefficients along the path.
    coefficient: [f64; 3],
}

impl Image {
    /// The image after window `w` for a receiver with corners `receiver`:
    /// mirrored where it and the receiver lie in front of the window and
    /// the window reflects, the same where they lie on either side and it
    /// transmits (a two-sided pane from its front only); `None` otherwise.
    fn through(&self, w: u32, window: &Window, receiver: &[DVec3; 3]) -> Option<Image> {
        let last = self.corners[self.corners.len() - 1];
        let side = |p: &[DVec3; 3]| {
            let d = p.map(|q| (q - window.origin).dot(window.normal));
            if d.iter().all(|&x| x >= 0.0) {
                1
            } else if d.iter().all(|&x| x <= 0.0) {
                -1
            } else {
                0
            }
        };
        let (r_side, s_side) = (side(receiver), side(&last));
        let any = |c: [f64; 3]| c.iter().any(|&x| x > 0.0);
        let (coefficient, corners, normal) = if r_side > 0 && s_side > 0 && any(window.reflectance) {
            (window.reflectance, last.map(|p| mirror_point(p, window.origin, window.normal)), mirror_direction(self.normal, window.normal))
        } else if r_side * s_side < 0 && (r_side > 0 || !window.two_sided) && any(window.transmittance) {
            (window.transmittance, last, self.normal)
        } else {
            return None;
        };
        let mut next = self.clone();
        next.corners.push(corners);
        next.normal = normal;
        next.path.push(w);
        next.coefficient = std::array::from_fn(|c| self.coefficient[c] * coefficient[c]);
        Some(next)
    }
}

/// Barycentric weights of point `p` (in the plane of `t`) in triangle `t`.
fn barycentric(p: DVec3, t: &[DVec3; 3]) -> [f64; 3] {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let (d11, d12, d22, d1, d2) = (e1.dot(e1), e1.dot(e2), e2.dot(e2), d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 0.0 {
        return [1.0 / 3.0; 3];
    }
    let (b1, b2) = ((d22 * d1 - d12 * d2) / det, (d11 * d2 - d12 * d1) / det);
    [1.0 - b1 - b2, b1, b2]
}

/// `p` mirrored in the plane through `origin` with unit normal `n`.
pub fn mirror_point(p: DVec3, origin: DVec3, n: DVec3) -> DVec3 {
    p - 2.0 * (p - origin).dot(n) * n
}

/// Direction `d` mirrored in a plane of unit normal `n`.
pub fn mirror_direction(d: DVec3, n: DVec3) -> DVec3 {
    d - 2.0 * d.dot(n) * n
}

impl Windows {
    /// The windows of `mesh`, or `Ok(None)` when the scene has no specular
    /// reflection or transmission; `Err` with their count where there are
    /// more than [`MAX_WINDOWS`]. `rays` per coupling, couplings under
    /// `min_factor` dropped, form factors to quadrature depth `depth`.
    pub fn new(mesh: &Mesh, manifest: &Manifest, h: &Hierarchy, knobs: Knobs) -> Result<Option<Windows>, usize> {
        let e = &manifest.effects;
        if !(e.specular_reflection || e.specular_transmission) {
            return Ok(None);
        }
        let scale = h.triangles.iter().flat_map(|t| t.corners).map(|p| p.abs().max_element()).fold(1e-12, f64::max);
        let mut windows: Vec<(u32, Window)> = Vec::new();
        let mut of_triangle = vec![None; mesh.triangles.len()];
        for (t, triangle) in mesh.triangles.iter().enumerate() {
            let m = &manifest.materials[triangle.material as usize];
            if !m.specular_reflectance.iter().chain(&m.specular_transmittance).any(|&x| x > 0.0) {
                continue;
            }
            let g = &h.triangles[t];
            let same = |(material, w): &(u32, Window)| {
                *material == triangle.material && w.normal.dot(g.normal) > 1.0 - 1e-9 && (g.corners[0] - w.origin).dot(w.normal).abs() <= 1e-7 * scale
            };
            let index = match windows.iter().position(same) {
                Some(i) => i,
                None => {
                    let window = Window {
                        origin: g.corners[0],
                        normal: g.normal,
                        reflectance: m.specular_reflectance,
                        transmittance: m.specular_transmittance,
                        two_sided: m.two_sided,
                        corners: Vec::new(),
                    };
                    windows.push((triangle.material, window));
                    windows.len() - 1
                }
            };
            of_triangle[t] = Some(index as u32);
            windows[index].1.corners.extend(g.corners);
        }
        if windows.len() > MAX_WINDOWS {
            return Err(windows.len());
        }
        let Knobs { rays, min_factor, quadrature, seed, sender_level, max_events } = knobs;
        Ok(Some(Windows {
            windows: windows.into_iter().map(|(_, w)| w).collect(),
            of_triangle,
            rays,
            min_factor,
            quadrature,
            max_events,
            seed,
            sender_level,
            traced: Mutex::new(Traced::default()),
        }))
    }

    /// The couplings into the current leaves of `h` (module docs), with
    /// the spread of their light from radiosity `b` (one entry per dense
    /// node index). A pair of a leaf and a sender traced by an earlier call
    /// (both were a leaf and a sender then) is taken as traced; only the
    /// others cast rays. Every leaf's couplings are in sender order, as a
    /// rebuild would list them.
    pub fn couplings(&self, h: &Hierarchy, scene: &SceneRays, b: &[[f64; 3]]) -> Couplings {
        let nodes = b.len();
        let senders: Vec<u32> = (0..h.triangles.len() as u32).filter(|&t| self.of_triangle[t as usize].is_none()).flat_map(|t| self.senders_below(h, t)).collect();
        let leaves: Vec<u32> =
            (0..h.elements.len() as u32).filter(|&e| h.elements[e as usize].is_leaf() && self.of_triangle[h.elements[e as usize].triangle as usize].is_none()).collect();
        let mut traced = self.traced.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let before = std::mem::take(&mut traced.senders);
        let mut lists = std::mem::take(&mut traced.leaves);
        let previous: Vec<(u32, Option<Pairs>)> = leaves.iter().map(|&r| (r, lists.remove(&r))).collect();
        let per_leaf: Vec<LeafCouplings> = previous
            .into_par_iter()
            .map(|(r, mut old)| {
                let (mut found, mut spread, mut rays, mut tail, mut kept) = (Vec::new(), 0.0, 0, [0.0; 3], Vec::new());
                for &s in &senders {
                    let sender = h.flat(Node::Element(s));
                    let pair = match old.as_mut().filter(|_| before.binary_search(&s).is_ok()) {
                        Some(list) => list.binary_search_by_key(&s, |(t, _)| *t).map_or_else(|_| Pair::default(), |k| std::mem::take(&mut list[k].1)),
                        None => {
                            let (pair, cast) = self.images(h, scene, r, s);
                            rays += cast;
                            pair
                        }
                    };
                    for &(weight, f) in &pair.found {
                        // weight / F_mean x (F_max - F_min), per channel.
                        spread += (0..3).map(|c| weight[c] * b[sender][c] * (f.max - f.min) / f.mean).fold(0.0, f64::max);
                        found.push((sender, weight));
                    }
                    (0..3).for_each(|c| tail[c] += pair.truncated[c] * b[sender][c]);
                    if !pair.is_empty() {
                        kept.push((s, pair));
                    }
                }
                kept.sort_unstable_by_key(|(s, _)| *s);
                (found, spread, rays, tail.into_iter().fold(0.0, f64::max), kept)
            })
            .collect();
        let mut rows: Vec<Vec<(usize, [f64; 3])>> = vec![Vec::new(); nodes];
        let mut couplings = Couplings { spread: vec![0.0; nodes], ..Couplings::default() };
        let largest = self.windows.iter().flat_map(|w| w.reflectance.into_iter().chain(w.transmittance)).fold(0.0, f64::max);
        let mut now = Traced { senders: senders.clone(), leaves: HashMap::with_capacity(leaves.len()) };
        now.senders.sort_unstable();
        for (&r, (found, spread, rays, tail, kept)) in leaves.iter().zip(per_leaf) {
            couplings.truncation = couplings.truncation.max(if largest < 1.0 { tail / (1.0 - largest) } else { f64::INFINITY });
            let i = h.flat(Node::Element(r));
            rows[i] = found;
            couplings.spread[i] = spread;
            couplings.rays += rays;
            now.leaves.insert(r, kept);
        }
        *traced = now;
        couplings.rows = Rows::from_lists(rows);
        couplings
    }

    /// The senders of input triangle `t`: its elements `sender_level`
    /// levels down, or its leaves where it is coarser.
    fn senders_below(&self, h: &Hierarchy, t: u32) -> Vec<u32> {
        let mut found = Vec::new();
        let mut stack = vec![(t, 0)];
        while let Some((e, level)) = stack.pop() {
            let element = &h.elements[e as usize];
            if element.is_leaf() || level == self.sender_level {
                found.push(e);
            } else {
                stack.extend((0..4).map(|k| (element.first_child + k, level + 1)));
            }
        }
        found
    }

    /// The images of sender element `s` that leaf `r` sees through chains
    /// of up to `max_events` windows (module docs): for each, `weight =
    /// coefficients x F x V'` and `F`, the unclipped factor to the image;
    /// and the coefficients times unoccluded factors of the images one
    /// window past the depth bound. Returns them and the rays cast.
    fn images(&self, h: &Hierarchy, scene: &SceneRays, r: u32, s: u32) -> (Pair, u64) {
        let (re, se) = (&h.elements[r as usize], &h.elements[s as usize]);
        let nr = h.normal(r);
        let (mut pair, mut cast) = (Pair::default(), 0);
        let mut stack = vec![Image { corners: vec![se.points], normal: h.normal(s), path: Vec::new(), coefficient: [1.0; 3] }];
        while let Some(image) = stack.pop() {
            let past = image.path.len() >= self.max_events as usize;
            for (w, window) in self.windows.iter().enumerate() {
                if image.path.last().is_some_and(|&last| last as usize == w || !window.follows(&self.windows[last as usize])) {
                    continue;
                }
                let Some(next) = image.through(w as u32, window, &re.points) else { continue };
                let last = next.corners[next.corners.len() - 1];
                let f = triangle_to_polygon(&re.points, nr, &last, next.normal, Quadrature::to_depth(self.quadrature));
                if past {
                    (0..3).for_each(|c| pair.truncated[c] += next.coefficient[c] * f.mean);
                    continue;
                }
                if f.mean <= 0.0 || next.coefficient.iter().fold(0.0f64, |a, &c| a.max(c)) * f.mean < self.min_factor {
                    continue;
                }
                let (v, rays) = self.visible(h, scene, r, s, &next);
                cast += rays;
                if v > 0.0 {
                    pair.found.push((next.coefficient.map(|c| c * f.mean * v), f));
                }
                stack.push(next);
            }
        }
        (pair, cast)
    }

    /// Kernel-weighted fraction of stratified pairs `(x on r, y on the
    /// image)` whose light comes from the sender through the image's
    /// windows, in order, unoccluded (module docs). Returns the fraction
    /// and the rays cast.
    fn visible(&self, h: &Hierarchy, scene: &SceneRays, r: u32, s: u32, image: &Image) -> (f64, u64) {
        let (re, se) = (&h.elements[r as usize], &h.elements[s as usize]);
        let nr = h.normal(r);
        let path_key = image.path.iter().fold(u64::from(s), |key, &w| key.wrapping_mul(1_000_003).wrapping_add(u64::from(w) + 1));
        let mut stream = Stream::new(self.seed ^ 0x4d49_5252_4f52, r.into(), path_key);
        // Receiver stratum k with a shuffled sender stratum, as the links' rays.
        let order = stream.permutation(self.rays);
        let last = image.corners[image.corners.len() - 1];
        let (mut clear, mut total, mut cast) = (0.0, 0.0, 0u64);
        'pairs: for (k, &k_sender) in order.iter().enumerate() {
            let x = stratified_point(&re.points, k, self.rays, &mut stream);
            let seen = stratified_point(&last, k_sender, self.rays, &mut stream);
            let g = point_kernel(x, nr, seen, image.normal);
            if g <= 0.0 {
                continue;
            }
            total += g;
            // The same point on every image of the chain, back to the sender.
            let weights = barycentric(seen, &last);
            let on = |corners: &[DVec3; 3]| corners[0] * weights[0] + corners[1] * weights[1] + corners[2] * weights[2];
            let (mut from, mut skip) = (x, re.triangle);
            for (step, &w) in image.path.iter().enumerate().rev() {
                let target = on(&image.corners[step + 1]);
                let d = target - from;
                let length = d.length();
                cast += 1;
                let Some(hit) = scene.closest_hit(from, d / length, (1e-6 * length) as f32, ((1.0 - 1e-6) * length) as f32, [skip, u32::MAX]) else { continue 'pairs };
                if self.of_triangle[hit.triangle as usize] != Some(w) {
                    continue 'pairs;
                }
                from += d / length * f64::from(hit.t);
                skip = hit.triangle;
            }
            cast += 1;
            if scene.segment_clear(from, on(&image.corners[0]), [skip, se.triangle]) {
                clear += g;
            }
        }
        (if total > 0.0 { clear / total } else { 0.0 }, cast)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use std::f64::consts::TAU;
    use test_support::meshes::{manifest, material, quads};

    /// A ring of `n` mirror quads standing round a unit circle, each
    /// facing its centre: `n` planes, as a tessellated curved mirror is.
    fn ring(n: usize) -> (Mesh, Manifest) {
        let faces: Vec<_> = (0..n)
            .map(|i| {
                let a = TAU * i as f64 / n as f64;
                let tangent = dvec3(-a.sin(), a.cos(), 0.0) * 0.1;
                (dvec3(a.cos(), a.sin(), 0.0), dvec3(0.0, 0.0, 0.1), tangent, 0, 0)
            })
            .collect();
        let mut mirror = material([0.05; 3], [0.0; 3]);
        mirror.specular_reflectance = [0.9; 3];
        let mut manifest = manifest(1, vec![mirror]);
        manifest.effects.specular_reflection = true;
        (quads(&faces), manifest)
    }

    /// A curved mirror of [`MAX_WINDOWS`] facets is traced, window by
    /// window; one of a facet more is refused with its count, which the
    /// solve then reports and solves without (`lib.rs`, `report.rs`).
    #[test]
    fn a_mirror_of_more_facets_than_the_windows_traced_is_left_out() {
        let knobs = Knobs { rays: 16, min_factor: 1e-6, quadrature: 2, seed: 1, sender_level: 0, max_events: 2 };
        for (n, wanted) in [(MAX_WINDOWS, Ok(MAX_WINDOWS)), (MAX_WINDOWS + 1, Err(MAX_WINDOWS + 1))] {
            let (mesh, manifest) = ring(n);
            let h = Hierarchy::new(&mesh, &manifest, None, None);
            let windows = Windows::new(&mesh, &manifest, &h, knobs).map(|w| w.map_or(0, |w| w.windows.len()));
            assert_eq!(windows, wanted, "{n} facets");
        }
    }
}
