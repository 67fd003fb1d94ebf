//! Texels buried inside a solid (a floor under a block standing on it),
//! which the shooting leaves out.
//!
//! No light reaches a buried texel and none leaves it. A shooting group
//! (004 Sec. 2.4's substructuring: `2^level` x `2^level` texels shooting
//! together from their centroid) that straddles a block's footprint shot
//! its texels' power from the centroid of all of them, inside the block
//! when most of the group lay under it, where the block's own faces
//! (seen from behind) took the shot. A buried texel counts as absent, as a
//! transparent texel of an alpha mask does ([`crate::atlas::Atlas::cover`]):
//! its group shoots from the centroid of its exposed texels, with their
//! area. On the built-in Cornell box at `--convergence-target` 0.999,
//! against Mitsuba (928 of 32,980 texels buried): tall block -3.2% ->
//! -2.2%, ceiling -1.2% -> -0.8%, back wall -0.6% -> -0.4%. A group
//! partly buried shoots its polygon less its buried part ([`Burial::hide`]),
//! and each of its texels stands for the part of its square outside that
//! buried part, so that the power a group is charged is the power its
//! polygon less the buried part delivers.

use crate::atlas::{area_centroid, clip_convex, convex_hull, strictly_inside, texel_point, texel_square, turn, Atlas, Texel, HIDDEN_CORNERS};
use crate::tiling::Tile;
use glam::DVec3;
use radiometry::burial::ProvenRoofs;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::SceneRays;
use radiometry::sampling::Stream;
use schemas::mesh::Mesh;
use stage_kit::scene::{mesh_triangles, triangle_corners};
use schemas::lightmap::Region;
use std::collections::HashMap;
use std::ops::Range;

/// The input mesh's rays and geometry, built once per solve: the
/// adaptive subdivision rebuilds the atlas over new tiles of the same
/// triangles.
pub struct Burial {
    scene: SceneRays,
    triangles: Vec<TriangleGeometry>,
}

impl Burial {
    /// Over the input triangles of `mesh`.
    pub fn new(mesh: &Mesh) -> Self {
        let triangles = mesh_triangles(mesh);
        Burial { scene: SceneRays::new(&triangles.iter().map(|t| t.corners).collect::<Vec<_>>()), triangles }
    }

    /// Per texel of `atlas` (over `tiles` of the input mesh), whether its
    /// point is buried ([`radiometry::burial`]), and the rays cast.
    pub fn texels(&self, atlas: &Atlas, tiles: &[Tile]) -> (Vec<bool>, u64) {
        let mut rays = 0;
        // The roofs proven a solid's over some texel of each input triangle.
        let mut roofs = vec![ProvenRoofs::default(); self.triangles.len()];
        let flags = atlas
            .texels
            .iter()
            .enumerate()
            .map(|(k, texel)| {
                let root = tiles[texel.triangle as usize].root;
                let (is_buried, cast) = self.point(DVec3::from(texel.position.map(f64::from)), root, k as u64, 0, &mut roofs[root as usize]);
                rays += cast;
                is_buried
            })
            .collect();
        (flags, rays)
    }

    /// Whether `p` on input triangle `root` is buried, and the rays cast;
    /// `(a, b)` keys the grazing rays' random turn; `roofs` are those
    /// proven a solid's over other points of `root`.
    fn point(&self, p: DVec3, root: u32, a: u64, b: u64, roofs: &mut ProvenRoofs) -> (bool, u64) {
        // Past the rounding of the f32 ray origin.
        let t_min = (1e-6 * p.abs().max_element().max(1.0)) as f32;
        let mut stream = Stream::new(BURIAL_SEED, a, b);
        let normal_of = |t: u32| self.triangles[t as usize].normal;
        roofs.buried(&self.scene, &normal_of, p, normal_of(root), root, t_min, &mut stream)
    }

    /// Gives each group of `atlas` (over `tiles`, whose triangles `mesh`
    /// holds) with buried texels (`buried`, from [`Burial::texels`]) next
    /// to exposed ones, in the group or beyond its edge, its buried part as
    /// a polygon, [`crate::atlas::Group::hidden`]; returns each texel's
    /// exposed fraction and the rays cast. The
    /// receiver pass takes the group's light as that of its polygon less
    /// this part (Lambert's formula for each), where it used to scale the
    /// whole polygon's by the exposed fraction. The two differ where the
    /// receiver's plane cuts the group: a face of the block that buries
    /// part of a floor group has that part behind it, so the clip of the
    /// polygon to the face's hemisphere removed it and the exposed fraction
    /// removed it again. A cube on an emitting floor had the texels of its
    /// faces 19% too dark in the lowest tenth of its height and 1.3% at the
    /// top (Lambert's formula per texel, `tests/tests/gpu_kernels.rs`).
    ///
    /// The part is the convex hull of the buried texels' points, of the
    /// edge of the buried region between each buried texel and an exposed
    /// 4-neighbour, found by bisecting the segment between their points
    /// ([`EDGE_STEPS`] times, keeping the buried end), and of the group's
    /// own edge where the buried region reaches it: the midpoint of a
    /// buried texel's side whose neighbour beyond the group is buried (or
    /// lies past the contact, which is then in the next group) or absent
    /// where that side is itself buried (the triangle's edge; across it may
    /// lie exposed floor of another triangle, and then the contact is
    /// bisected towards it: taken as buried, the floor's diagonal under a
    /// turned cube left 7 of its lowest texels up to 2% dark),
    /// the contact on that edge, bisected between that midpoint and the
    /// exposed neighbour's (the row through the texels' points left half a
    /// texel of it out: a cube on an emitting floor had 0.1% more exposed
    /// floor than the truth), and the corner of its square where all three
    /// neighbours round it are. The contact
    /// lies anywhere between the two points, and a part that reached past
    /// the block's face took from that face the floor just in front of
    /// it, most of what its lowest texels see (the hull of the texels'
    /// squares left them 5-19% dark), while one that stopped at the buried
    /// points let the rim beyond them shoot (the cube's faces received 1%
    /// more than the floor shot). One that stopped there at the group's
    /// edge let a strip under the block half a texel wide shoot: on the
    /// built-in Cornell box (32k texels to 99.9%, lightmap preview against
    /// Mitsuba) the tall block's face was 2% to 3.4% bright per pixel at
    /// its end by the short block, the tall block +0.83% in all; now
    /// -0.21%, and every surface within 0.50% (the ceiling -0.50%, the
    /// rest within 0.27%, where they were within 0.19%: the strip had
    /// been making up a deficit of about 0.25%, which the per-face test of
    /// the cube box in `tests/tests/gpu_kernels.rs` shows on the walls
    /// nearest the cube). That hull, cut to [`HIDDEN_CORNERS`] corners by dropping its
    /// smallest ones, is the buried part where one convex solid buries it
    /// (a block standing on a floor); where an exposed texel's point lies
    /// inside it (two solids, a concave one) the group keeps no hidden
    /// part, and shoots its polygon's light scaled by its exposed fraction
    /// (`Group::opaque`), as before.
    ///
    /// A texel of a group with a hidden part is exposed by the fraction of
    /// its square (half square on the hypotenuse) outside that part, 0
    /// under [`MIN_EXPOSED`]; one whose point is buried but whose square
    /// reaches out from under the block takes the centroid of its exposed
    /// part as its point. Counted whole by their points, the texels along
    /// the contact stood for more or less floor than the polygon less the
    /// hidden part delivers light from (a cube on an emitting floor: the
    /// floor's texels 0.21% short of the exposed floor), and a group whose
    /// every texel's point lay under the block, while a strip of it lay in
    /// front, had nothing to shoot: with the footprint's edge 0.4 texel
    /// inside such groups the cube's lowest texels in front of them, which
    /// see mostly that strip, were 22% dark.
    pub fn hide(&self, atlas: &mut Atlas, mesh: &Mesh, tiles: &[Tile], buried: &[bool]) -> (Vec<f64>, u64) {
        let mut rays = 0;
        let mut exposed_fraction: Vec<f64> = buried.iter().map(|&b| if b { 0.0 } else { 1.0 }).collect();
        for (t, range) in atlas.triangles.iter().enumerate() {
            let texels = range.first as usize..(range.first + range.count) as usize;
            if !buried[texels.clone()].contains(&true) {
                continue;
            }
            let region = atlas.regions[t];
            let indices = atlas.texels[texels.clone()].iter().map(|texel| texel.indices(region)).collect();
            let grid = TexelGrid::new(region, TriangleGeometry::new(triangle_corners(mesh, t)), tiles[t].root, range.first as usize, indices, buried);
            for g in &mut atlas.groups[range.group_first as usize..(range.group_first + range.group_count) as usize] {
                let group = g.first as usize..(g.first + g.count) as usize;
                let Some(part) = self.hidden_part(&grid, group.clone(), &mut rays) else { continue };
                for (slot, uv) in g.hidden.iter_mut().zip(&part) {
                    *slot = grid.geometry.point(*uv).as_vec3().to_array();
                }
                g.hidden_corners = part.len() as u32;
                grid.expose(&part, group, &mut atlas.texels, &mut exposed_fraction);
            }
        }
        (exposed_fraction, rays)
    }

    /// The buried part of the group of texels `group` of `grid`'s triangle
    /// ([`Burial::hide`]), in barycentrics, counter-clockwise; none where
    /// the group has no buried texel, its buried texels reach no exposed
    /// one, or an exposed texel's point lies inside their hull (no convex
    /// buried part). Counts the rays it casts into `rays`.
    fn hidden_part(&self, grid: &TexelGrid, group: Range<usize>, rays: &mut u64) -> Option<Vec<[f64; 2]>> {
        let (hidden, open): (Vec<usize>, Vec<usize>) = group.clone().partition(|&k| grid.buried[k]);
        if hidden.is_empty() {
            return None;
        }
        let mut points: Vec<[f64; 2]> = hidden.iter().map(|&k| grid.point(k)).collect();
        let mut reaches_open = !open.is_empty();
        for &k in &hidden {
            reaches_open |= self.outline(grid, &group, k, &mut points, rays);
        }
        if !reaches_open {
            return None;
        }
        let part = convex_hull(points, HIDDEN_CORNERS);
        let within = |p: [f64; 2]| strictly_inside(part.len(), |k| turn(part[k], part[(k + 1) % part.len()], p));
        (part.len() >= 3 && !open.iter().any(|&k| within(grid.point(k)))).then_some(part)
    }

    /// Adds to `points` where the buried region round buried texel `k`
    /// of `group` ends ([`Burial::hide`]): the contacts with its exposed
    /// 4-neighbours, and the group's edge where the buried region reaches
    /// it. Returns whether it found exposed floor next to the texel.
    fn outline(&self, grid: &TexelGrid, group: &Range<usize>, k: usize, points: &mut Vec<[f64; 2]>, rays: &mut u64) -> bool {
        let mut reaches_open = false;
        let (i, j) = grid.indices(k);
        let nf = f64::from(grid.region.size);
        // The triangle's texel at an offset from this one, if any;
        // whether it is in the group; the exposed one (none: no
        // texel, or buried); and the point of this texel's square
        // towards it (a side's midpoint or a corner).
        let beside = |di: i64, dj: i64| grid.at.get(&((i as i64 + di) as u32, (j as i64 + dj) as u32)).copied();
        let in_group = |di: i64, dj: i64| beside(di, dj).is_some_and(|e| group.contains(&e));
        let exposed = |di: i64, dj: i64| beside(di, dj).filter(|&e| !grid.buried[e]);
        let towards = |di: i64, dj: i64| [(i as f64 + 0.5 + di as f64 / 2.0) / nf, (j as f64 + 0.5 + dj as f64 / 2.0) / nf];
        // Whether a point is buried; `key` keys its grazing rays.
        let mut test = |uv: [f64; 2], key: u64| {
            let (is_buried, cast) = self.point(grid.geometry.point(uv), grid.root, k as u64, key, &mut ProvenRoofs::default());
            *rays += cast;
            is_buried
        };
        for (side, (di, dj)) in [(1i64, 0i64), (0, 1), (-1, 0), (0, -1)].into_iter().enumerate() {
            let edge = towards(di, dj);
            let Some(e) = exposed(di, dj) else {
                // A buried texel beyond the group's edge: the buried
                // part reaches that edge (the two texels' points lie
                // in it, and so does the middle between them). No
                // texel beyond it: the triangle ends there, and its
                // neighbour across may be exposed (a floor's other
                // triangle), so the edge is tested, and the contact
                // bisected towards it if it is not buried.
                if !in_group(di, dj) && edge[0] + edge[1] <= 1.0 {
                    if beside(di, dj).is_some() || test(edge, 41 + side as u64) {
                        points.push(edge);
                    } else {
                        reaches_open = true;
                        points.push(bisect(grid.point(k), edge, &mut test, 45 + side as u64, 4));
                    }
                }
                continue;
            };
            reaches_open = true;
            let mut contact = bisect(grid.point(k), grid.point(e), &mut test, 1 + side as u64, 4);
            // A contact past the group's edge lies in the next group:
            // this group's buried part reaches its edge.
            if !in_group(di, dj) && (contact[0] - edge[0]) * di as f64 + (contact[1] - edge[1]) * dj as f64 > 0.0 {
                contact = edge;
            }
            points.push(contact);
            // Where the buried part reaches the group's edge beside
            // this texel, the contact on that edge, between the two
            // texels' sides on it: the row through their points
            // leaves half a texel of the edge out.
            for (which, (pi, pj)) in [(dj, di), (-dj, -di)].into_iter().enumerate() {
                let (near, far) = (towards(pi, pj), towards(pi + 2 * di, pj + 2 * dj));
                let key = 21 + (2 * side + which) as u64;
                if in_group(di, dj) && !in_group(pi, pj) && exposed(pi, pj).is_none() && near[0] + near[1] <= 1.0 && far[0] + far[1] <= 1.0 && (beside(pi, pj).is_some() || test(near, key + 40)) {
                    points.push(bisect(near, far, &mut test, key, 8));
                }
            }
        }
        for (c, (di, dj)) in [(1i64, 1i64), (1, -1), (-1, 1), (-1, -1)].into_iter().enumerate() {
            let corner = towards(di, dj);
            let open_near = exposed(di, 0).is_some() || exposed(0, dj).is_some() || exposed(di, dj).is_some();
            let all_there = beside(di, 0).is_some() && beside(0, dj).is_some() && beside(di, dj).is_some();
            if !in_group(di, 0) && !in_group(0, dj) && !open_near && corner[0] + corner[1] <= 1.0 && (all_there || test(corner, 71 + c as u64)) {
                points.push(corner);
            }
        }
        reaches_open
    }
}

/// One input triangle's texels, as [`Burial::hide`] reads them.
struct TexelGrid<'a> {
    region: Region,
    geometry: TriangleGeometry,
    /// The input triangle.
    root: u32,
    /// Its first texel in the atlas.
    first: usize,
    /// `(i, j)` in `region` of each of its texels, from `first` on.
    indices: Vec<(u32, u32)>,
    /// Its texel at `(i, j)`.
    at: HashMap<(u32, u32), usize>,
    /// Per texel of the atlas, whether its point is buried.
    buried: &'a [bool],
}

impl<'a> TexelGrid<'a> {
    fn new(region: Region, geometry: TriangleGeometry, root: u32, first: usize, indices: Vec<(u32, u32)>, buried: &'a [bool]) -> Self {
        let at = indices.iter().enumerate().map(|(k, &ij)| (ij, first + k)).collect();
        TexelGrid { region, geometry, root, first, indices, at, buried }
    }

    /// `(i, j)` of texel `k`.
    fn indices(&self, k: usize) -> (u32, u32) {
        self.indices[k - self.first]
    }

    /// Texel `k`'s point, in barycentrics.
    fn point(&self, k: usize) -> [f64; 2] {
        let (i, j) = self.indices(k);
        texel_point(self.region, i, j)
    }

    /// Sets the exposed fraction of each texel of `group` to that of its
    /// square (half square on the hypotenuse) outside the buried `part`,
    /// 0 under [`MIN_EXPOSED`]; a buried one with an exposed part moves
    /// its point to that part's centroid ([`Burial::hide`]).
    fn expose(&self, part: &[[f64; 2]], group: Range<usize>, texels: &mut [Texel], exposed_fraction: &mut [f64]) {
        for k in group {
            let (i, j) = self.indices(k);
            let square = texel_square(self.region, i, j);
            let (whole, centre) = area_centroid(&square);
            let (under, under_centre) = area_centroid(&clip_convex(square, part));
            let fraction = ((whole - under) / whole).clamp(0.0, 1.0);
            exposed_fraction[k] = if fraction > MIN_EXPOSED { fraction } else { 0.0 };
            if self.buried[k] && exposed_fraction[k] > 0.0 {
                let outside = [0, 1].map(|c| (whole * centre[c] - under * under_centre[c]) / (whole - under));
                texels[k].position = self.geometry.point(outside).as_vec3().to_array();
            }
        }
    }
}

/// The buried end of the last of [`EDGE_STEPS`] halvings of the segment
/// from the buried point `inside` to the exposed `outside`, by `test`
/// (whether a point is buried, and the key of its grazing rays: `key`,
/// then `stride` more each step). The hull of [`Burial::hide`] must stay
/// inside the buried region: an exposed texel's point within it takes the
/// group's hidden part away.
fn bisect(mut inside: [f64; 2], mut outside: [f64; 2], test: &mut impl FnMut([f64; 2], u64) -> bool, key: u64, stride: u64) -> [f64; 2] {
    for step in 0..EDGE_STEPS as u64 {
        let mid = [(inside[0] + outside[0]) / 2.0, (inside[1] + outside[1]) / 2.0];
        if test(mid, key + stride * step) {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    inside
}

/// Exposed fraction of a texel's square under which it counts as buried
/// ([`Burial::hide`]): a sliver this thin carries nothing measurable, and
/// its point would sit on the contact.
pub const MIN_EXPOSED: f64 = 1e-3;

/// Bisections of the segment between a buried texel's point and an
/// exposed neighbour's that place the buried region's edge
/// ([`Burial::hide`]): to 1/32 of a texel.
pub const EDGE_STEPS: usize = 5;

/// Seed of the grazing rays' random turn per texel (gpu-shoot has no seed
/// parameter: it draws no other random numbers).
const BURIAL_SEED: u64 = 0x6275_7269_6564;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::atlas::bake;
    use crate::tiling::identity;
    use test_support::meshes::{cube_in_box, manifest, material};

    /// The floor of `cube_in_box(0.4, 0.3)` at 24,000 texels: regions of 61
    /// texels a side, so the footprint's edges lie 0.4 texel inside groups
    /// (of 8 x 8) whose texels' points are all under the cube. The exposed
    /// parts of the floor's texels sum to the floor less the footprint
    /// within 0.2% (measured +0.08%: each contact is placed on its buried
    /// side, within 1/32 of a texel, and a hull misses the footprint's
    /// corner), and every texel with an exposed part
    /// has its point outside the footprint.
    #[test]
    fn the_floors_texels_expose_the_floor_less_the_blocks_footprint() {
        let (corner, side) = (0.4, 0.3);
        let mesh = cube_in_box([corner; 2], side, 0.0);
        let m = manifest(2, vec![material([1.0; 3], [0.0; 3]), material([0.0; 3], [10.0; 3])]);
        let mut atlas = bake(&mesh, &m, 24000.0, 2, 512, 3);
        assert_eq!(atlas.regions[0].size, 61);
        let tiles = identity(&mesh);
        let burial = Burial::new(&mesh);
        let (buried, _) = burial.texels(&atlas, &tiles);
        let (exposed, _) = burial.hide(&mut atlas, &mesh, &tiles, &buried);
        let floor = |k: usize| atlas.texels[k].triangle < 2;
        let area: f64 = (0..atlas.texels.len()).filter(|&k| floor(k)).map(|k| atlas.texels[k].area as f64 * exposed[k]).sum();
        let truth = 1.0 - side * side;
        assert!((area / truth - 1.0).abs() < 0.002, "exposed floor {area} against {truth}");
        let slivers = (0..atlas.texels.len()).filter(|&k| floor(k) && buried[k] && exposed[k] > 0.0).count();
        assert!(slivers > 0, "no texel under the cube with an exposed part");
        for k in (0..atlas.texels.len()).filter(|&k| floor(k) && exposed[k] > 0.0) {
            let [x, _, z] = atlas.texels[k].position;
            let inside = |c: f32| c > corner as f32 && c < (corner + side) as f32;
            assert!(!(inside(x) && inside(z)), "texel {k} at ({x}, {z}) is exposed with its point under the cube");
        }
    }
}
