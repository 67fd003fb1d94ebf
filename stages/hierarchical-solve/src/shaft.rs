//! Shaft culling (Haines and Wallace, "Shaft culling for efficient
//! ray-cast radiosity", 1994): proving that nothing lies between two
//! elements, so that their link needs no visibility rays.
//!
//! Every ray of [`crate::visibility::estimate`] is a segment from a point
//! of the receiver to a point of the sender, so it lies in the convex hull
//! of the two triangles (the *shaft*); the points are interior to the
//! triangles, so the segment's inside lies in the shaft's interior. A
//! triangle that does not reach into that interior blocks none of them;
//! where no triangle of the scene but the two ends' own (and their twins,
//! which the rays skip as well, [`radiometry::rays`]) does, all rays would
//! be clear and the estimate is exactly `V = 1` with no occluder, which is
//! what the link gets without casting any. The hull of a child's link lies
//! inside its parent's, so a link proven clear passes that on to the links
//! that refine it ([`crate::links::children_links`]).
//!
//! Disjointness is proven by a separating axis: a direction along which
//! the projections of the shaft and of the triangle overlap by at most
//! [`TOUCH`] of the scene's extent (touching does not count: a floor
//! triangle next to a floor element, or a wall along its edge, meets only
//! the shaft's boundary). Tried: the two elements' normals, the triangle's
//! normal, and the normals of the shaft's side faces (an edge of one
//! element with a corner of the other). Edge-against-edge axes are not
//! tried, so some disjoint triangles are kept as possible occluders, which
//! only sends their links to the rays. The scene's triangles sit in a
//! bounding-box tree whose boxes are tested against the same axes.
//!
//! On the built-in Cornell box at `EPS` 1e-3 the rays drop from 10.3M to
//! 6.2M, and every leaf's radiosity is the same to the last bit as with
//! rays everywhere (16 of them can only differ where a ray's
//! single-precision arithmetic grazed a surface that touches the shaft).

use glam::DVec3;
use radiometry::bounds::Aabb;
use radiometry::rays::SceneRays;

/// Overlap of projections that counts as touching, as a fraction of the
/// scene's extent (round-off of coplanar and adjoining triangles).
pub const TOUCH: f64 = 1e-9;

/// Most triangles in a leaf of the box tree.
const LEAF_TRIANGLES: usize = 4;

/// A node of the box tree: its bounds; a leaf holds `order[first..first +
/// count]`, an inner node has its first child next to it and its second at
/// `second`.
#[derive(Clone, Copy, Debug)]
struct BoxNode {
    lo: DVec3,
    hi: DVec3,
    first: usize,
    count: usize,
    second: usize,
}

/// The scene's triangles as possible occluders: corners, unit normals,
/// twins, in a bounding-box tree.
pub struct Occluders {
    corners: Vec<[DVec3; 3]>,
    normals: Vec<DVec3>,
    twins: Vec<Option<u32>>,
    order: Vec<u32>,
    nodes: Vec<BoxNode>,
    touch: f64,
}

impl Occluders {
    /// The triangles `corners` (mesh order), with the twins `scene` pairs.
    pub fn new(corners: &[[DVec3; 3]], scene: &SceneRays) -> Self {
        let normals = corners.iter().map(|c| (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero()).collect();
        let twins = (0..corners.len() as u32).map(|t| scene.twin(t)).collect();
        let mut occluders = Occluders { corners: corners.to_vec(), normals, twins, order: (0..corners.len() as u32).collect(), nodes: Vec::new(), touch: 0.0 };
        if !corners.is_empty() {
            occluders.build(0, corners.len());
            let root = occluders.nodes[0];
            occluders.touch = TOUCH * (root.hi - root.lo).length();
        }
        occluders
    }

    fn bounds(&self, range: std::ops::Range<usize>) -> (DVec3, DVec3) {
        let b = Aabb::around(self.order[range].iter().flat_map(|&t| self.corners[t as usize]));
        (b.min, b.max)
    }

    /// Adds the node of `order[first..first + count]` and its subtree
    /// (median split along the longest axis of the centroids' bounds).
    fn build(&mut self, first: usize, count: usize) {
        let (lo, hi) = self.bounds(first..first + count);
        let index = self.nodes.len();
        self.nodes.push(BoxNode { lo, hi, first, count, second: 0 });
        if count <= LEAF_TRIANGLES {
            return;
        }
        let centroid = |t: u32| self.corners[t as usize].iter().sum::<DVec3>() / 3.0;
        let centroids = Aabb::around(self.order[first..first + count].iter().map(|&t| centroid(t)));
        let extent = centroids.max - centroids.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z { 0 } else if extent.y >= extent.z { 1 } else { 2 };
        let half = count / 2;
        let corners = &self.corners;
        self.order[first..first + count].select_nth_unstable_by(half, |&a, &b| {
            let key = |t: u32| (corners[t as usize][0] + corners[t as usize][1] + corners[t as usize][2])[axis];
            key(a).total_cmp(&key(b))
        });
        self.nodes[index].count = 0;
        self.build(first, half);
        self.nodes[index].second = self.nodes.len();
        self.build(first + half, count - half);
    }

    /// Whether no triangle but `ends` (the two ends' input triangles) and
    /// their twins reaches into the convex hull of `receiver` and `sender`
    /// (module docs): `true` is a proof, `false` may be wrong.
    pub fn clear(&self, receiver: &[DVec3; 3], sender: &[DVec3; 3], ends: [u32; 2]) -> bool {
        self.among(receiver, sender, ends, 0).is_some()
    }

    /// The triangles but `ends` and their twins that may reach into the
    /// convex hull of `receiver` and `sender` (every other one is proven
    /// not to, module docs), if there are at most `most` of them (at most
    /// [`MOST_AMONG`]): every segment between the two ends' interiors that
    /// a triangle blocks, one of these blocks.
    pub fn among(&self, receiver: &[DVec3; 3], sender: &[DVec3; 3], ends: [u32; 2], most: usize) -> Option<Among> {
        let mut among = Among { triangles: [0; MOST_AMONG], count: 0 };
        if self.nodes.is_empty() {
            return Some(among);
        }
        let most = most.min(MOST_AMONG);
        let mut shaft = Shaft::new(receiver, sender, self.touch);
        let skipped = |t: u32| ends.iter().any(|&e| e == t || self.twins[e as usize] == Some(t));
        // The tree is balanced, so its depth is under 64 for any mesh.
        let (mut stack, mut top) = ([0usize; 64], 1);
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top]];
            if !shaft.may_meet_box(node.lo, node.hi) {
                continue;
            }
            if node.count == 0 {
                (stack[top], stack[top + 1]) = (stack[top] + 1, node.second);
                top += 2;
                continue;
            }
            for &t in &self.order[node.first..node.first + node.count] {
                if !skipped(t) && shaft.may_meet_triangle(&self.corners[t as usize], self.normals[t as usize]) {
                    if among.count == most {
                        return None;
                    }
                    among.triangles[among.count] = t;
                    among.count += 1;
                }
            }
        }
        Some(among)
    }
}

/// Most triangles an [`Among`] holds: a ray tests each of them
/// ([`SceneRays::segment_clear_among`]), where the BVH's traversal costs
/// about what a few such tests do, so a longer list would cost what it
/// saves. On the built-in Cornell box at `EPS` 4e-4 the shafts of 6,324
/// of the 6,411 partly occluded links whose parts the last solve traces
/// hold at most 16 (5.9 on average), and the solve is 7% faster on one
/// thread (0.57 s -> 0.53 s, medians of 7 interleaved), with the same
/// solution to the bit; plants-2k's, the same too, takes as long.
pub const MOST_AMONG: usize = 16;

/// The triangles that may block the segments between two elements
/// ([`Occluders::among`]), mesh indices.
#[derive(Clone, Copy, Debug)]
pub struct Among {
    triangles: [u32; MOST_AMONG],
    count: usize,
}

impl Among {
    /// The triangles.
    pub fn triangles(&self) -> &[u32] {
        &self.triangles[..self.count]
    }
}

/// The convex hull of two triangles, by its bounding box and its extents
/// along candidate separating axes, each shrunk by the touching tolerance.
/// The side faces' axes are made only for a triangle that the box, the two
/// elements' planes and its own plane do not separate.
struct Shaft {
    ends: [[DVec3; 3]; 2],
    lo: DVec3,
    hi: DVec3,
    /// Unit axis and the hull's shrunk interval along it: the two
    /// elements' normals, then, once made, the side faces'.
    axes: Vec<(DVec3, f64, f64)>,
    touch: f64,
}

/// Most axes a shaft tries: the two elements' normals and the side
/// faces', an edge of one with a corner of the other (2 x 3 x 3).
const AXES: usize = 2 + 18;

impl Shaft {
    fn new(receiver: &[DVec3; 3], sender: &[DVec3; 3], touch: f64) -> Self {
        let ends = [*receiver, *sender];
        let b = Aabb::around(ends.as_flattened().iter().copied());
        let mut shaft = Shaft { ends, lo: b.min + DVec3::splat(touch), hi: b.max - DVec3::splat(touch), axes: Vec::with_capacity(AXES), touch };
        for t in ends {
            shaft.push((t[1] - t[0]).cross(t[2] - t[0]));
        }
        shaft
    }

    /// Adds the side faces' axes: an edge of one element with a corner of
    /// the other.
    fn push_sides(&mut self) {
        for (a, b) in [(self.ends[0], self.ends[1]), (self.ends[1], self.ends[0])] {
            for i in 0..3 {
                let edge = a[(i + 1) % 3] - a[i];
                for corner in b {
                    self.push(edge.cross(corner - a[i]));
                }
            }
        }
    }

    /// Adds `axis` (any length; a degenerate one is left out).
    fn push(&mut self, axis: DVec3) {
        let Some(axis) = axis.try_normalize() else { return };
        let (lo, hi) = self.extent(axis);
        self.axes.push((axis, lo + self.touch, hi - self.touch));
    }

    fn extent(&self, axis: DVec3) -> (f64, f64) {
        self.ends.as_flattened().iter().map(|p| p.dot(axis)).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
    }

    /// Whether the box `lo..hi` may meet the hull (neither the bounding
    /// box nor an axis made so far separates them).
    fn may_meet_box(&self, lo: DVec3, hi: DVec3) -> bool {
        if (lo.cmpge(self.hi) | hi.cmple(self.lo)).any() {
            return false;
        }
        let (centre, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        self.axes.iter().all(|&(axis, a, b)| {
            let (c, r) = (centre.dot(axis), half.dot(axis.abs()));
            c + r > a && c - r < b
        })
    }

    /// Whether the triangle `t` (unit normal `normal`) may meet the hull.
    fn may_meet_triangle(&mut self, t: &[DVec3; 3], normal: DVec3) -> bool {
        let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
        if (lo.cmpge(self.hi) | hi.cmple(self.lo)).any() {
            return false;
        }
        let separated = |&(axis, a, b): &(DVec3, f64, f64)| {
            let x = [t[0].dot(axis), t[1].dot(axis), t[2].dot(axis)];
            x[0].max(x[1]).max(x[2]) <= a || x[0].min(x[1]).min(x[2]) >= b
        };
        if self.axes.iter().take(2).any(separated) {
            return false;
        }
        // The triangle's own plane.
        if normal != DVec3::ZERO {
            let d = t[0].dot(normal);
            let (a, b) = self.extent(normal);
            if a + self.touch > d || b - self.touch < d {
                return false;
            }
        }
        if self.axes.len() <= 2 {
            self.push_sides();
        }
        !self.axes.iter().skip(2).any(separated)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use radiometry::sampling::Stream;

    fn quad(z: f64, x: f64, y: f64, half: f64) -> [[DVec3; 3]; 2] {
        let (a, b, c, d) = (dvec3(x - half, y - half, z), dvec3(x + half, y - half, z), dvec3(x + half, y + half, z), dvec3(x - half, y + half, z));
        [[a, b, c], [a, c, d]]
    }

    /// A floor and a ceiling element with a blocker between them, beside
    /// them (inside their bounding box, past the hypotenuses: only a side
    /// face of the shaft separates it), and behind one of them: the shaft
    /// is blocked only where a segment between the two elements meets the
    /// blocker, and wherever it is declared clear, 4,096 segments between
    /// the two are clear for the ray caster too.
    #[test]
    fn a_shaft_is_clear_exactly_where_no_segment_between_the_ends_is_blocked() {
        let floor = [dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)];
        let ceiling = [dvec3(0.0, 0.0, 2.0), dvec3(0.0, 1.0, 2.0), dvec3(1.0, 0.0, 2.0)];
        for (x, y, z, blocked) in [(0.3, 0.0, 1.0, true), (3.0, 0.0, 1.0, false), (0.3, 0.0, -1.0, false), (0.3, 0.0, 3.0, false), (0.8, 0.8, 1.0, false), (0.5, 0.5, 1.0, true)] {
            let mut corners = vec![floor, ceiling];
            corners.extend(quad(z, x, y, 0.15));
            let scene = SceneRays::new(&corners);
            let occluders = Occluders::new(&corners, &scene);
            let clear = occluders.clear(&floor, &ceiling, [0, 1]);
            assert_eq!(clear, !blocked, "blocker at ({x}, {y}, {z})");
            let mut stream = Stream::new(7, 1, 2);
            let mut any_blocked = false;
            for k in 0..4096 {
                let from = radiometry::sampling::stratified_point(&floor, k, 4096, &mut stream);
                let to = radiometry::sampling::stratified_point(&ceiling, k, 4096, &mut stream);
                any_blocked |= scene.first_blocker(from, to, [0, 1]).is_some();
            }
            assert_eq!(any_blocked, blocked, "rays, blocker at ({x}, {y}, {z})");
        }
    }

    /// Triangles that only touch the shaft's boundary (a neighbour in the
    /// floor's plane, a wall through the floor's and the ceiling's
    /// hypotenuses) block no segment between the ends' interiors, for the
    /// shaft and for 4,096 rays alike; the same wall tilted into the shaft
    /// blocks.
    #[test]
    fn triangles_touching_the_shaft_only_at_its_boundary_block_nothing() {
        let floor = [dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)];
        let ceiling = [dvec3(0.0, 0.0, 2.0), dvec3(0.0, 1.0, 2.0), dvec3(1.0, 0.0, 2.0)];
        let neighbour = [dvec3(1.0, 0.0, 0.0), dvec3(1.0, 1.0, 0.0), dvec3(0.0, 1.0, 0.0)];
        let wall = |tilt: f64| [dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), dvec3(0.5 - tilt, 0.5 - tilt, 2.0)];
        for (occluder, blocked) in [(neighbour, false), (wall(0.0), false), (wall(0.2), true)] {
            let corners = vec![floor, ceiling, occluder];
            let scene = SceneRays::new(&corners);
            assert_eq!(Occluders::new(&corners, &scene).clear(&floor, &ceiling, [0, 1]), !blocked, "{occluder:?}");
            let mut stream = Stream::new(7, 1, 2);
            let rays_blocked = (0..4096).any(|k| {
                let from = radiometry::sampling::stratified_point(&floor, k, 4096, &mut stream);
                let to = radiometry::sampling::stratified_point(&ceiling, k, 4096, &mut stream);
                scene.first_blocker(from, to, [0, 1]).is_some()
            });
            assert_eq!(rays_blocked, blocked, "rays, {occluder:?}");
        }
    }

    /// Of three blockers, two between a floor and a ceiling element and one
    /// beside them, the shaft's list holds the two between (one triangle
    /// each, where they block), none beside; with room for fewer it is
    /// refused; and 4,096 segments between the two ends, tested against the
    /// list alone, are blocked exactly where the BVH finds them blocked.
    #[test]
    fn the_triangles_among_a_shaft_block_every_segment_the_scene_blocks() {
        let floor = [dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)];
        let ceiling = [dvec3(0.0, 0.0, 2.0), dvec3(0.0, 1.0, 2.0), dvec3(1.0, 0.0, 2.0)];
        let mut corners = vec![floor, ceiling];
        for (x, y, z) in [(0.2, 0.2, 0.7), (3.0, 0.0, 1.0), (0.5, 0.1, 1.4)] {
            corners.extend(quad(z, x, y, 0.12));
        }
        let scene = SceneRays::new(&corners);
        let occluders = Occluders::new(&corners, &scene);
        let among = occluders.among(&floor, &ceiling, [0, 1], MOST_AMONG).expect("few enough");
        let mut listed = among.triangles().to_vec();
        listed.sort();
        assert!(listed.iter().all(|&t| [2, 3, 6, 7].contains(&t)) && listed.len() >= 2, "{listed:?}");
        assert!(occluders.among(&floor, &ceiling, [0, 1], listed.len() - 1).is_none());
        let mut stream = Stream::new(7, 1, 2);
        let (mut blocked, mut agree) = (0, 0);
        for k in 0..4096 {
            let from = radiometry::sampling::stratified_point(&floor, k, 4096, &mut stream);
            let to = radiometry::sampling::stratified_point(&ceiling, k, 4096, &mut stream);
            let clear = scene.segment_clear(from, to, [0, 1]);
            blocked += usize::from(!clear);
            agree += usize::from(clear == scene.segment_clear_among(from, to, [0, 1], among.triangles()));
        }
        assert!(blocked > 100, "{blocked} segments blocked");
        assert_eq!(agree, 4096);
    }
}
