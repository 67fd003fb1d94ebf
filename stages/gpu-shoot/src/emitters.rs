//! How finely an emitter's texels are grouped to shoot ([`shoot_levels`]).
//!
//! A group shoots from its centroid, so each group casts a hard shadow,
//! and an emitter's penumbrae are as many hard shadows as it has groups, a
//! group's width apart scaled by the occluder's distances. The Cornell
//! box's lamp (two regions of 15 texels a side at 32k texels) shot from 7
//! groups of 8 x 8 texels at the default level 3, and the floor in the
//! short block's penumbra was 20% to 55% dark per pixel against Mitsuba
//! (the preview from the lightmap). From each texel (240 groups), to 99% on
//! lavapipe: relative RMSE 1.75% -> 1.20%, pixels over 10% 1.93% -> 0.13%
//! (the floor's 9.6% -> 1.2%), the short block's mean -1.56% -> -0.84%,
//! 53 s -> 58-60 s; from 2 x 2 texels (72 groups) 1.26% and 0.37%.
//!
//! A group under [`crate::reference::RECIPROCAL`] texels lights a receiver
//! in its near field from its centroid, as a point, and next to a receiver
//! that is coarse: an emitter touching its receiver and shooting from each
//! texel put Howell C-14's texels by the shared edge 48% high, and a cube
//! standing on an emitting floor 209% high at its base. So only an emitter
//! clear of every surface in front of it by a coarse group's side
//! ([`clear`]) shoots from finer groups.

use glam::DVec3;
use radiometry::bounds::Aabb;
use schemas::mesh::{Manifest, Mesh};
use stage_kit::scene::triangle_corners;

/// Groups an emitting object shoots from at least, where its texels allow
/// and it is [`clear`] (module docs).
pub const EMITTER_GROUPS: u32 = 256;

/// Pairs of (emitting, other) triangles [`clear`] measures at most for
/// one object; beyond, the object keeps the coarse groups.
pub const MOST_PAIRS: usize = 1 << 22;

/// The level at which each triangle's texels are grouped to shoot
/// ([`crate::atlas::Group`]): `level`, but the emitting triangles (a
/// material with emission) of an object that is [`clear`] at the coarsest
/// level at which they hold at least [`EMITTER_GROUPS`] groups together,
/// 0 where none does. `sizes`: the region size per object
/// ([`crate::atlas::object_sizes`]).
pub fn shoot_levels(mesh: &Mesh, manifest: &Manifest, sizes: &[u32], level: u32) -> Vec<u32> {
    let emits: Vec<bool> = mesh.triangles.iter().map(|t| manifest.materials[t.material as usize].emission.iter().any(|&e| e > 0.0)).collect();
    let mut emitting = vec![Vec::new(); sizes.len()];
    for (t, tri) in mesh.triangles.iter().enumerate().filter(|&(t, _)| emits[t]) {
        emitting[tri.object as usize].push(t);
    }
    let finer: Vec<u32> = (0..sizes.len())
        .map(|o| {
            let own = &emitting[o];
            let groups = |l: u32| own.len() as u32 * crate::atlas::group_count(sizes[o], l);
            let fine = (0..=level).rev().find(|&l| groups(l) >= EMITTER_GROUPS).unwrap_or(0);
            if own.is_empty() || fine == level {
                return level;
            }
            // A coarse group's side: 2^level texels of the widest region.
            let side = own.iter().map(|&t| (2.0 * f64::from(mesh.triangles[t].area)).sqrt()).fold(0.0, f64::max) * f64::from(1u32 << level) / f64::from(sizes[o]);
            if clear(mesh, own, side) {
                fine
            } else {
                level
            }
        })
        .collect();
    mesh.triangles.iter().enumerate().map(|(t, tri)| if emits[t] { finer[tri.object as usize] } else { level }).collect()
}

/// Whether every triangle of `mesh` that lies partly in front of one of the
/// triangles `own` (not wholly on or behind its plane, so it may receive
/// from it) is at least `distance` from it. Measures at most
/// [`MOST_PAIRS`] pairs (after a bounding-box test), else says no.
pub fn clear(mesh: &Mesh, own: &[usize], distance: f64) -> bool {
    let corners = |t: usize| triangle_corners(mesh, t);
    let bounds = Aabb::around(own.iter().flat_map(|&e| corners(e)));
    let (lo, hi) = (bounds.min - DVec3::splat(distance), bounds.max + DVec3::splat(distance));
    let mut is_own = vec![false; mesh.triangles.len()];
    own.iter().for_each(|&t| is_own[t] = true);
    let near: Vec<usize> = (0..mesh.triangles.len())
        .filter(|&t| !is_own[t])
        .filter(|&t| {
            let c = corners(t);
            let (a, b) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
            a.cmple(hi).all() && b.cmpge(lo).all()
        })
        .collect();
    if near.len() * own.len() > MOST_PAIRS {
        return false;
    }
    own.iter().all(|&e| {
        let a = corners(e);
        let normal = (a[1] - a[0]).cross(a[2] - a[0]);
        near.iter().all(|&t| {
            let b = corners(t);
            let in_front = b.iter().any(|&p| (p - a[0]).dot(normal) > 1e-9 * normal.length() * (p - a[0]).length().max(f64::MIN_POSITIVE));
            !in_front || triangle_distance(&a, &b) >= distance
        })
    })
}

/// Distance between triangles `a` and `b`: 0 where an edge of one crosses
/// the other, else the least of the corners' distances to the other
/// triangle and the edges' distances to each other's.
pub fn triangle_distance(a: &[DVec3; 3], b: &[DVec3; 3]) -> f64 {
    let edges = |t: &[DVec3; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    let crosses = edges(a).iter().any(|&(p, q)| segment_crosses(p, q, b)) || edges(b).iter().any(|&(p, q)| segment_crosses(p, q, a));
    if crosses {
        return 0.0;
    }
    let corners = a.iter().map(|&p| p.distance(closest_on_triangle(p, b))).chain(b.iter().map(|&p| p.distance(closest_on_triangle(p, a))));
    let sides = edges(a).into_iter().flat_map(|(p, q)| edges(b).map(|(r, s)| segment_distance(p, q, r, s)));
    corners.chain(sides).fold(f64::INFINITY, f64::min)
}

/// The point of triangle `t` nearest to `p` (by the region of the
/// triangle's plane `p` projects into: a corner, an edge or the inside).
fn closest_on_triangle(p: DVec3, t: &[DVec3; 3]) -> DVec3 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denominator = va + vb + vc;
    if denominator <= 0.0 {
        // A degenerate triangle: its nearest corner.
        return *t.iter().min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p))).expect("three corners");
    }
    a + ab * (vb / denominator) + ac * (vc / denominator)
}

/// Distance between segments `p q` and `r s`.
fn segment_distance(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> f64 {
    let (d1, d2, w) = (q - p, s - r, p - r);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(w));
    let (u, v) = if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        (0.0, 0.0)
    } else if a <= f64::MIN_POSITIVE {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(w);
        if e <= f64::MIN_POSITIVE {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denominator = a * e - b * b;
            let mut u = if denominator > 0.0 { ((b * f - c * e) / denominator).clamp(0.0, 1.0) } else { 0.0 };
            let mut v = (b * u + f) / e;
            if v < 0.0 {
                (u, v) = ((-c / a).clamp(0.0, 1.0), 0.0);
            } else if v > 1.0 {
                (u, v) = (((b - c) / a).clamp(0.0, 1.0), 1.0);
            }
            (u, v)
        }
    };
    (p + d1 * u).distance(r + d2 * v)
}

/// Whether segment `p q` crosses triangle `t`'s inside or boundary.
fn segment_crosses(p: DVec3, q: DVec3, t: &[DVec3; 3]) -> bool {
    let [a, b, c] = *t;
    let n = (b - a).cross(c - a);
    let (dp, dq) = ((p - a).dot(n), (q - a).dot(n));
    if dp * dq > 0.0 || dp == dq {
        return false;
    }
    let x = p + (q - p) * (dp / (dp - dq));
    let side = |u: DVec3, v: DVec3| (v - u).cross(x - u).dot(n);
    let (s0, s1, s2) = (side(a, b), side(b, c), side(c, a));
    (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [DVec3; 3] {
        [DVec3::from(a), DVec3::from(b), DVec3::from(c)]
    }

    /// Distances by construction: parallel triangles one above the other,
    /// a corner above the other's inside, edges skew to each other, and a
    /// triangle piercing another.
    #[test]
    fn triangle_distances_match_their_constructions() {
        let floor = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!((triangle_distance(&floor, &tri([0.0, 0.0, 0.3], [1.0, 0.0, 0.3], [0.0, 1.0, 0.3])) - 0.3).abs() < 1e-12);
        // A vertical triangle whose lowest corner is 0.2 above (0.2, 0.2, 0).
        assert!((triangle_distance(&floor, &tri([0.2, 0.2, 0.2], [0.2, 0.9, 1.0], [0.9, 0.2, 1.0])) - 0.2).abs() < 1e-12);
        // The nearest point of a vertical triangle at y = 0.5, x >= 2 is (2, 0.5, 0); the floor's, the
        // corner (1, 0, 0), sqrt(1 + 0.25) away.
        assert!((triangle_distance(&floor, &tri([2.0, 0.5, 1.0], [2.0, 0.5, -1.0], [3.0, 0.5, 0.0])) - 1.25f64.sqrt()).abs() < 1e-12);
        // A segment-to-segment case: edge along x at y = -0.5, z = 0.5 above the floor's edge y = 0.
        assert!((triangle_distance(&floor, &tri([-1.0, -0.5, 0.5], [2.0, -0.5, 0.5], [0.5, -2.0, 0.5])) - 0.5f64.hypot(0.5)).abs() < 1e-12);
        assert_eq!(triangle_distance(&floor, &tri([0.2, 0.2, -0.5], [0.3, 0.2, 0.5], [0.2, 0.3, 0.5])), 0.0);
    }

    /// A small emitter (object 1) 1 m above a floor (object 0) shoots from
    /// groups of one texel; touched by a wall in front of it (object 2), from
    /// the given level, as does the floor; a triangle behind its plane does
    /// not count.
    #[test]
    fn a_small_emitter_shoots_from_each_texel_where_nothing_is_near_it() {
        use schemas::header::{Provenance, Schema};
        use schemas::mesh::Triangle;
        use test_support::meshes::{manifest, material};
        let positions = vec![
            [-1.0, -1.0, 0.0], [2.0, -1.0, 0.0], [-1.0, 2.0, 0.0],
            [0.0, 0.0, 1.0], [0.0, 0.1, 1.0], [0.1, 0.0, 1.0],
            [0.0, 0.0, 1.0], [0.0, 0.1, 1.0], [0.0, 0.0, 0.5],
            [0.0, 0.0, 1.5], [0.0, 0.1, 1.5], [0.1, 0.0, 1.5],
        ];
        let triangle = |v: [u32; 3], material: u32, object: u32| Triangle { vertices: v, material, object, area: 0.005, normal: [0.0, 0.0, 1.0] };
        let mut triangles = vec![triangle([0, 1, 2], 0, 0), triangle([3, 4, 5], 1, 1)];
        let m = manifest(3, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [1.0; 3])]);
        let sizes = [64, 16, 16];
        let levels = |triangles: &[Triangle]| {
            let mesh = Mesh { header: Mesh::header(Provenance::in_memory("test")), positions: positions.clone(), triangles: triangles.to_vec() };
            shoot_levels(&mesh, &m, &sizes, 3)
        };
        // 16 texels a side hold 136: no level reaches EMITTER_GROUPS.
        assert_eq!(levels(&triangles), [3, 0]);
        // Above the emitter's plane (z = 1; it faces down).
        triangles.push(triangle([9, 10, 11], 0, 2));
        assert_eq!(levels(&triangles), [3, 0, 3]);
        triangles.push(triangle([6, 7, 8], 0, 2));
        assert_eq!(levels(&triangles), [3, 3, 3, 3]);
    }
}
