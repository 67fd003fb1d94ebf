//! The lightmap atlas (paper 004, Sec. 2.3 and 4.2): a square region of
//! texels per triangle, a texel size per object, coverage, the area each
//! texel stands for, and the world position and normal of every covered
//! texel, baked once.
//!
//! The paper rasterizes each triangle orthographically into its texture to
//! find the covered texels and their positions. Here the covered texels of
//! a region are known in closed form (see [`schemas::lightmap`]: texel
//! `(i, j)` with centre at barycentric `((i+1/2)/n, (j+1/2)/n)`, covered
//! when `i + j + 1 <= n`), so positions are computed on the CPU in f64 and
//! uploaded once; the GPU then works on the compact list of covered texels.
//!
//! Substructuring (004 Sec. 2.3, "shooting from a coarser mipmap level"):
//! the covered texels of a triangle are grouped into blocks of `2^level` x
//! `2^level` texels; each block with at least one covered texel is one
//! shooting sample. Texels are stored group by group, so each group is a
//! contiguous range and the mip level is a sum over a range.

use glam::DVec3;
use radiometry::geometry::TriangleGeometry;
use schemas::lightmap::Region;
use schemas::mesh::{Manifest, Mesh};
use stage_kit::scene::triangle_corners;

/// One covered texel, as the GPU reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texel {
    /// Atlas column.
    pub x: u32,
    /// Atlas row.
    pub y: u32,
    /// The triangle it lies on.
    pub triangle: u32,
    /// Texel centre, mesh frame, m.
    pub position: [f32; 3],
    /// Area it stands for, m².
    pub area: f32,
    /// Buried inside a solid ([`crate::exposure`]): absent, as a
    /// transparent texel is, and in the lightmap a texel without a value,
    /// filled from its exposed neighbours ([`crate::output::fill_seams`]).
    pub buried: bool,
}

impl Texel {
    /// Its interior texel indices `(i, j)` in its triangle's `region`.
    pub fn indices(&self, region: Region) -> (u32, u32) {
        (self.x - region.x - 1, self.y - region.y - 1)
    }

    /// Whether it lies on the hypotenuse `i + j + 1 = n`, half its square
    /// inside the triangle.
    pub fn on_hypotenuse(&self, region: Region) -> bool {
        let (i, j) = self.indices(region);
        i + j + 1 == region.size
    }
}

/// One shooting sample: a group of covered texels of one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Group {
    /// First texel of the group in [`Atlas::texels`].
    pub first: u32,
    /// Number of texels.
    pub count: u32,
    /// Area-weighted centroid of the group's texel centres, mesh frame, m.
    pub centroid: [f32; 3],
    /// Total area of the group, m² (its opaque part under an alpha mask).
    pub area: f32,
    /// Area of `polygon`, m²: the group's size, masks and burial aside,
    /// which decides how the receiver pass integrates it (a group mostly
    /// buried is still as wide as its polygon).
    pub extent: f32,
    /// The group's opaque area over the nominal area of the texels that
    /// `polygon` less `hidden` stands for ([`Atlas::cover`]): 1, less where
    /// an alpha mask removes texels, or where buried texels have no
    /// `hidden` part to leave them out.
    pub opaque: f32,
    /// The part of the triangle the group covers, mesh frame, m: its block
    /// of texels, `[gi g, (gi + 1) g] x [gj g, (gj + 1) g] / n` in
    /// barycentrics, cut by the region's edge and the hypotenuse `u + v =
    /// 1`; `corners` of the 5 are used.
    pub polygon: [[f32; 3]; 5],
    /// Corners of `polygon` (3 to 5).
    pub corners: u32,
    /// The buried part of `polygon` (under a solid standing on it), convex,
    /// mesh frame, m; `hidden_corners` of them are used, none where the
    /// group has no buried texel or its buried part is not convex
    /// ([`crate::exposure::Burial::hide`]).
    pub hidden: [[f32; 3]; HIDDEN_CORNERS],
    /// Corners of `hidden` (0, or 3 to [`HIDDEN_CORNERS`]).
    pub hidden_corners: u32,
}

impl Group {
    /// Whether `p`, on the group's plane, lies inside [`Group::hidden`].
    pub fn in_hidden(&self, p: DVec3) -> bool {
        let n = self.hidden_corners as usize;
        let corner = |k: usize| DVec3::from(self.hidden[k % n].map(f64::from));
        // Turns measured along the polygon's own normal, so its corners
        // turn counter-clockwise about it.
        let normal = if n >= 3 { (corner(1) - corner(0)).cross(corner(2) - corner(0)) } else { DVec3::ZERO };
        strictly_inside(n, |k| (corner(k + 1) - corner(k)).cross(p - corner(k)).dot(normal))
    }
}

/// Whether a point lies strictly inside a convex polygon of `n` corners
/// whose turns are counter-clockwise: `turn_at(k)`, the turn from its edge
/// `k -> k + 1` to the point ([`turn`] in the plane), is positive for
/// every edge. A polygon of fewer than 3 corners holds nothing. Used in
/// barycentrics on a group's buried part ([`crate::exposure`]) and in 3D
/// on the part as stored ([`Group::in_hidden`]).
pub fn strictly_inside(n: usize, turn_at: impl Fn(usize) -> f64) -> bool {
    n >= 3 && (0..n).all(|k| turn_at(k) > 0.0)
}

/// Most corners of a group's buried part ([`Group::hidden`]).
pub const HIDDEN_CORNERS: usize = 8;

/// Twice the signed area of the triangle `o`, `a`, `b`: positive where
/// `b` lies left of the line from `o` to `a` (a counter-clockwise turn).
pub fn turn(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// The convex hull of `points`, counter-clockwise, collinear points
/// dropped (Andrew's monotone chain), cut down to at most `most` corners
/// by dropping, one at a time, the corner whose triangle with its two
/// neighbours is smallest (the hull only shrinks).
pub fn convex_hull(mut points: Vec<[f64; 2]>, most: usize) -> Vec<[f64; 2]> {
    points.sort_by(|a, b| a.partial_cmp(b).expect("finite barycentrics"));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * points.len());
    for pass in [points.clone(), points.into_iter().rev().collect()] {
        let start = hull.len();
        for p in pass {
            while hull.len() >= start + 2 && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    while hull.len() > most.max(3) {
        let n = hull.len();
        let corner = |k: usize| turn(hull[(k + n - 1) % n], hull[k], hull[(k + 1) % n]);
        let smallest = (0..n).min_by(|&a, &b| corner(a).total_cmp(&corner(b))).expect("a corner");
        hull.remove(smallest);
    }
    hull
}

/// The barycentric square `[u0, u1] x [v0, v1]` cut by the hypotenuse
/// `u + v <= 1`, counter-clockwise.
pub fn block_polygon(u0: f64, u1: f64, v0: f64, v1: f64) -> Vec<[f64; 2]> {
    clip_line(&[[u0, v0], [u1, v0], [u1, v1], [u0, v1]], |p| 1.0 - p[0] - p[1])
}

/// The part of polygon `p` where `side` is not negative (Sutherland-Hodgman
/// against one line): a corner on the line is kept and makes no crossing.
fn clip_line(p: &[[f64; 2]], side: impl Fn([f64; 2]) -> f64) -> Vec<[f64; 2]> {
    let mut kept = Vec::with_capacity(p.len() + 1);
    for k in 0..p.len() {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        let (da, db) = (side(a), side(b));
        if da >= 0.0 {
            kept.push(a);
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            let t = da / (da - db);
            kept.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    kept
}

/// Per-triangle ranges into the texel and group lists.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleTexels {
    /// First texel in [`Atlas::texels`].
    pub first: u32,
    /// Covered texels.
    pub count: u32,
    /// First group in [`Atlas::groups`].
    pub group_first: u32,
    /// Groups (shooting samples).
    pub group_count: u32,
}

/// The baked atlas.
#[derive(Clone, Debug)]
pub struct Atlas {
    /// Atlas width, texels.
    pub width: u32,
    /// Atlas height, texels.
    pub height: u32,
    /// One region per triangle.
    pub regions: Vec<Region>,
    /// Per-triangle ranges.
    pub triangles: Vec<TriangleTexels>,
    /// Covered texels, triangle by triangle, group by group.
    pub texels: Vec<Texel>,
    /// Shooting samples, triangle by triangle.
    pub groups: Vec<Group>,
    /// Texel size (interior texels per region side) per object.
    pub object_sizes: Vec<u32>,
}

/// Covered texels of a region of `size` texels per side: `n (n + 1) / 2`.
pub fn covered_count(size: u32) -> u32 {
    size * (size + 1) / 2
}

/// The region size of every object, chosen from its area (004 Sec. 4.2:
/// one size for all over- and under-samples mixed meshes). With a density
/// of `texels / total area` texels per m², an object whose mean triangle
/// area is `a` gets the size `n` whose covered count `n (n+1)/2` is nearest
/// to `a x density`, clamped to `[min_size, max_size]`. All triangles of an
/// object share it (a size varying across one object shows seams at the
/// boundaries, 004 Sec. 4.2 footnote).
pub fn object_sizes(mesh: &Mesh, objects: usize, texels: f64, min_size: u32, max_size: u32) -> Vec<u32> {
    let total: f64 = mesh.triangles.iter().map(|t| t.area as f64).sum();
    let density = texels / total.max(f64::MIN_POSITIVE);
    let mut area = vec![0.0f64; objects];
    let mut count = vec![0usize; objects];
    for t in &mesh.triangles {
        area[t.object as usize] += t.area as f64;
        count[t.object as usize] += 1;
    }
    (0..objects)
        .map(|o| {
            if count[o] == 0 {
                return min_size;
            }
            let want = area[o] / count[o] as f64 * density;
            let n = ((1.0 + 8.0 * want).sqrt() - 1.0) / 2.0;
            (n.round() as u32).clamp(min_size, max_size)
        })
        .collect()
}

/// The barycentric point a covered texel `(i, j)` stands for: its centre
/// ([`Region::uv`]), except on the hypotenuse (`i + j + 1 = n`), where the
/// centre lies on the triangle's edge and the point is the centroid of the
/// half square inside the triangle, `((i + 1/3) / n, (j + 1/3) / n)`. A
/// point on the edge would, where the edge is a concave crease (a box's
/// corner line), shoot half its power through the neighbouring wall's
/// plane and see that wall edge-on as a receiver: the closed box lost a
/// few percent of its energy that way.
pub fn texel_point(region: Region, i: u32, j: u32) -> [f64; 2] {
    let n = region.size as f64;
    if i + j + 1 == region.size {
        [(i as f64 + 1.0 / 3.0) / n, (j as f64 + 1.0 / 3.0) / n]
    } else {
        region.uv(i, j)
    }
}

/// The square of texel `(i, j)` of `region` in barycentrics,
/// counter-clockwise: the half inside the triangle on the hypotenuse.
pub fn texel_square(region: Region, i: u32, j: u32) -> Vec<[f64; 2]> {
    let n = region.size as f64;
    let (u0, v0, u1, v1) = (i as f64 / n, j as f64 / n, (i + 1) as f64 / n, (j + 1) as f64 / n);
    if i + j + 1 == region.size {
        vec![[u0, v0], [u1, v0], [u0, v1]]
    } else {
        vec![[u0, v0], [u1, v0], [u1, v1], [u0, v1]]
    }
}

/// Area and centroid of the simple polygon `p` (counter-clockwise; no
/// corners: area 0 and the origin).
pub fn area_centroid(p: &[[f64; 2]]) -> (f64, [f64; 2]) {
    let (mut twice, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for k in 0..p.len() {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        let c = a[0] * b[1] - b[0] * a[1];
        twice += c;
        cx += (a[0] + b[0]) * c;
        cy += (a[1] + b[1]) * c;
    }
    if twice.abs() <= 0.0 {
        return (0.0, [0.0, 0.0]);
    }
    (twice / 2.0, [cx / (3.0 * twice), cy / (3.0 * twice)])
}

/// The part of the convex polygon `p` inside the convex polygon `by`
/// (both counter-clockwise): [`clip_line`] by one edge of `by` at a time.
pub fn clip_convex(mut p: Vec<[f64; 2]>, by: &[[f64; 2]]) -> Vec<[f64; 2]> {
    for k in 0..by.len() {
        let (a, b) = (by[k], by[(k + 1) % by.len()]);
        p = clip_line(&p, |q| turn(a, b, q));
        if p.is_empty() {
            break;
        }
    }
    p
}

/// Bakes the atlas: region sizes per object, shelf packing (regions sorted
/// by decreasing size, then triangle index, into rows of a power-of-two
/// wide atlas), covered texels with positions and areas, and groups of
/// `2^level` x `2^level` texels for substructured shooting (finer for a
/// small emitter clear of other surfaces, [`crate::emitters`]).
pub fn bake(mesh: &Mesh, manifest: &Manifest, texels: f64, min_size: u32, max_size: u32, level: u32) -> Atlas {
    let sizes = object_sizes(mesh, manifest.objects.len(), texels, min_size, max_size);
    let levels = crate::emitters::shoot_levels(mesh, manifest, &sizes, level);
    bake_sized(mesh, sizes, &levels)
}

/// Groups of `2^level` x `2^level` texels that hold a covered texel in a
/// region of `size` texels a side: the blocks `(a, b)` whose first texel
/// is covered, `(a + b) 2^level < size`.
pub fn group_count(size: u32, level: u32) -> u32 {
    let g = 1u32 << level;
    let blocks = size.div_ceil(g);
    (0..blocks).map(|a| (0..blocks).filter(|&b| (a + b) * g < size).count() as u32).sum()
}

/// [`bake`] with given region sizes per object (the input mesh's, for the
/// tiles of an adaptive subdivision, [`crate::tiling`]) and shooting
/// levels per triangle ([`crate::emitters::shoot_levels`]).
pub fn bake_sized(mesh: &Mesh, sizes: Vec<u32>, levels: &[u32]) -> Atlas {
    let size_of = |t: usize| sizes[mesh.triangles[t].object as usize];
    let footprint: u64 = (0..mesh.triangles.len()).map(|t| ((size_of(t) + 2) as u64).pow(2)).sum();
    let largest = (0..mesh.triangles.len()).map(|t| size_of(t) + 2).max().unwrap_or(1);
    let width = ((footprint as f64).sqrt().ceil() as u32).max(largest).next_power_of_two();
    let mut order: Vec<usize> = (0..mesh.triangles.len()).collect();
    order.sort_by_key(|&t| (std::cmp::Reverse(size_of(t)), t));
    let mut regions = vec![Region { x: 0, y: 0, size: 0, covered: 0, texel_area: 0.0 }; mesh.triangles.len()];
    let (mut x, mut y, mut row_height) = (0u32, 0u32, 0u32);
    for &t in &order {
        let side = size_of(t) + 2;
        if x + side > width {
            x = 0;
            y += row_height;
            row_height = 0;
        }
        let size = size_of(t);
        let covered = covered_count(size);
        let texel_area = 2.0 * mesh.triangles[t].area as f64 / (size as f64 * size as f64);
        regions[t] = Region { x, y, size, covered, texel_area: texel_area as f32 };
        x += side;
        row_height = row_height.max(side);
    }
    let height = (y + row_height).max(1);
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    let mut all_texels = Vec::new();
    let mut groups = Vec::new();
    for t in 0..mesh.triangles.len() {
        let geometry = TriangleGeometry::new(triangle_corners(mesh, t));
        let region = regions[t];
        let n = region.size;
        let g = 1u32 << levels[t];
        let (first, group_first) = (all_texels.len() as u32, groups.len() as u32);
        let blocks = n.div_ceil(g);
        for gj in 0..blocks {
            for gi in 0..blocks {
                let start = all_texels.len() as u32;
                let mut sum = DVec3::ZERO;
                let mut area = 0.0f64;
                for j in gj * g..((gj + 1) * g).min(n) {
                    for i in gi * g..((gi + 1) * g).min(n) {
                        if !region.is_covered(i, j) {
                            continue;
                        }
                        let p = geometry.point(texel_point(region, i, j));
                        let w = if i + j + 1 == n { 0.5 } else { 1.0 };
                        sum += p * w;
                        area += w;
                        let (x, y) = region.texel(i, j);
                        // Texels on the hypotenuse have half their square inside the
                        // triangle: interior texels stand for 2 A / n^2, those
                        // A / n^2, and the areas sum to A exactly.
                        let area = if i + j + 1 == n { region.texel_area * 0.5 } else { region.texel_area };
                        all_texels.push(Texel { x, y, triangle: t as u32, position: p.as_vec3().to_array(), area, buried: false });
                    }
                }
                let count = all_texels.len() as u32 - start;
                if count > 0 {
                    let centroid = (sum / area).as_vec3().to_array();
                    let nf = n as f64;
                    let corners = block_polygon((gi * g) as f64 / nf, (((gi + 1) * g).min(n)) as f64 / nf, (gj * g) as f64 / nf, (((gj + 1) * g).min(n)) as f64 / nf);
                    let mut polygon = [[0.0f32; 3]; 5];
                    for (slot, uv) in polygon.iter_mut().zip(&corners) {
                        *slot = geometry.point(*uv).as_vec3().to_array();
                    }
                    let area = (region.texel_area as f64 * area) as f32;
                    groups.push(Group { first: start, count, centroid, area, extent: area, opaque: 1.0, polygon, corners: corners.len() as u32, hidden: [[0.0; 3]; HIDDEN_CORNERS], hidden_corners: 0 });
                }
            }
        }
        triangles.push(TriangleTexels {
            first,
            count: all_texels.len() as u32 - first,
            group_first,
            group_count: groups.len() as u32 - group_first,
        });
    }
    Atlas { width, height, regions, triangles, texels: all_texels, groups, object_sizes: sizes }
}

impl Atlas {
    /// Applies an alpha mask (004 Sec. 4.3.4) and burial: texel `k` keeps
    /// the fraction `exposed[k] coverage[k]` of its area (0: it does not
    /// exist; `exposed` from [`crate::exposure::Burial::hide`], called
    /// first), and the groups of the triangles `masked` picks get their
    /// opaque area, its centroid (the area-weighted mean of their texels'
    /// points; a group with nothing opaque keeps its own) and their opaque
    /// fraction of the polygon less its hidden part. The areas of a
    /// triangle then sum to `A n_o / n_c`, counted over sub-samples of the
    /// texels ([`crate::detail`]), less its buried part.
    pub fn cover(&mut self, exposed: &[f64], coverage: &[f64], masked: &dyn Fn(usize) -> bool) {
        for (t, range) in self.triangles.iter().enumerate() {
            if !masked(t) {
                continue;
            }
            for g in &mut self.groups[range.group_first as usize..(range.group_first + range.group_count) as usize] {
                // `open`: the nominal area of the texels `polygon` less
                // `hidden` stands for (their exposed parts where the group
                // has a hidden part).
                let (mut sum, mut area, mut open) = (DVec3::ZERO, 0.0f64, 0.0f64);
                let range = g.first as usize..(g.first + g.count) as usize;
                for ((texel, &fraction), &exposure) in self.texels[range.clone()].iter_mut().zip(&coverage[range.clone()]).zip(&exposed[range.clone()]) {
                    open += texel.area as f64 * if g.hidden_corners == 0 { 1.0 } else { exposure };
                    texel.area = (texel.area as f64 * exposure * fraction) as f32;
                    sum += DVec3::from(texel.position.map(f64::from)) * texel.area as f64;
                    area += texel.area as f64;
                }
                if area > 0.0 {
                    let centroid = sum / area;
                    // The exposed part of a group round a block's corner is
                    // not convex, and its centroid may lie under the block,
                    // whose faces then hide everything from the group's
                    // point: there the group shoots from its exposed texel
                    // nearest to it (the cube of tests/tests/gpu_kernels.rs
                    // at (0.3, 0.3): two such groups shot nothing, and the
                    // walls nearest the cube got 0.8% to 1.2% too little).
                    let point = |x: &Texel| DVec3::from(x.position.map(f64::from));
                    let nearest = || self.texels[range].iter().filter(|x| x.area > 0.0).map(point).min_by(|a, b| a.distance_squared(centroid).total_cmp(&b.distance_squared(centroid)));
                    g.centroid = if g.in_hidden(centroid) { nearest().unwrap_or(centroid) } else { centroid }.as_vec3().to_array();
                }
                g.area = area as f32;
                g.opaque = if open > 0.0 { (area / open) as f32 } else { 0.0 };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemas::header::{Provenance, Schema};
    use schemas::mesh::Triangle;

    pub(crate) fn two_triangle_mesh() -> (Mesh, Manifest) {
        let positions = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0], [0.1, 0.0, 1.0], [0.0, 0.1, 1.0]];
        let triangles = vec![
            Triangle { vertices: [0, 1, 2], material: 0, object: 0, area: 2.0, normal: [0.0, 0.0, 1.0] },
            Triangle { vertices: [3, 4, 5], material: 0, object: 1, area: 0.005, normal: [0.0, 0.0, 1.0] },
        ];
        let mesh = Mesh { header: Mesh::header(Provenance::in_memory("test")), positions, triangles };
        let manifest = test_support::meshes::manifest(2, vec![test_support::meshes::material([0.5; 3], [0.0; 3])]);
        (mesh, manifest)
    }

    #[test]
    fn a_square_clipped_by_a_triangle_keeps_the_overlaps_area_and_centroid() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        // The triangle's long edge is x + y = 1.5: it cuts the corner
        // (1, 0.5), (1, 1), (0.5, 1), of area 1/8 and centroid (5/6, 5/6).
        let triangle = [[-1.0, -1.0], [2.5, -1.0], [-1.0, 2.5]];
        let (area, centroid) = area_centroid(&clip_convex(square.to_vec(), &triangle));
        let expected = (0.5 - 0.125 * 5.0 / 6.0) / 0.875;
        assert!((area - 0.875).abs() < 1e-12 && centroid.iter().all(|c| (c - expected).abs() < 1e-12), "{area} {centroid:?}");
        assert!(clip_convex(square.to_vec(), &[[2.0, 2.0], [3.0, 2.0], [2.0, 3.0]]).is_empty());
        let region = Region { x: 0, y: 0, size: 4, covered: covered_count(4), texel_area: 0.0 };
        assert!((area_centroid(&texel_square(region, 1, 1)).0 - 1.0 / 16.0).abs() < 1e-15);
        assert!((area_centroid(&texel_square(region, 2, 1)).0 - 1.0 / 32.0).abs() < 1e-15);
    }

    #[test]
    fn the_hull_keeps_the_extreme_points_counter_clockwise_and_sheds_its_smallest_corner() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let mut points = vec![[0.5, 0.5], [0.5, 0.0], [0.25, 0.75]];
        points.extend(square.iter().rev());
        assert_eq!(convex_hull(points.clone(), 8), square.to_vec());
        // A fifth corner barely outside the square's top edge goes first.
        points.push([0.5, 1.01]);
        assert_eq!(convex_hull(points.clone(), 8).len(), 5);
        assert_eq!(convex_hull(points, 4), square.to_vec());
    }

    /// The buried part's test in barycentrics and in 3D: a unit square,
    /// counter-clockwise, holds its middle and a point just inside an edge,
    /// not a point on an edge or outside; the same square placed on a
    /// tilted plane (either winding as seen from its front) answers alike,
    /// and a part of fewer than 3 corners holds nothing.
    #[test]
    fn a_point_is_inside_the_hidden_part_alike_in_the_plane_and_in_3d() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let points = [([0.5, 0.5], true), ([0.999, 0.5], true), ([1.0, 0.5], false), ([0.5, -0.01], false), ([1.5, 1.5], false)];
        let flat = |p: [f64; 2]| strictly_inside(4, |k| turn(square[k], square[(k + 1) % 4], p));
        let (o, u, v) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.6, 0.0, 0.8), DVec3::new(0.0, 1.0, 0.0));
        let at = |p: [f64; 2]| o + p[0] * u + p[1] * v;
        for reversed in [false, true] {
            let mut group = Group { first: 0, count: 0, centroid: [0.0; 3], area: 0.0, extent: 0.0, opaque: 1.0, polygon: [[0.0; 3]; 5], corners: 3, hidden: [[0.0; 3]; HIDDEN_CORNERS], hidden_corners: 4 };
            for (k, c) in square.iter().enumerate() {
                group.hidden[if reversed { 3 - k } else { k }] = at(*c).as_vec3().to_array();
            }
            for (p, inside) in points {
                assert_eq!(flat(p), inside, "{p:?} in the plane");
                assert_eq!(group.in_hidden(at(p)), inside, "{p:?} in 3D, reversed {reversed}");
            }
            group.hidden_corners = 2;
            assert!(!group.in_hidden(at([0.5, 0.5])));
        }
    }

    #[test]
    fn texel_areas_sum_to_triangle_areas_and_regions_do_not_overlap() {
        let (mesh, manifest) = two_triangle_mesh();
        let atlas = bake(&mesh, &manifest, 2000.0, 2, 256, 2);
        assert!(atlas.object_sizes[0] > atlas.object_sizes[1], "{:?}", atlas.object_sizes);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let r = atlas.triangles[t];
            let sum: f64 = atlas.texels[r.first as usize..(r.first + r.count) as usize].iter().map(|x| x.area as f64).sum();
            assert!((sum - tri.area as f64).abs() < 1e-5 * tri.area as f64, "{sum} vs {}", tri.area);
            let groups: u32 = atlas.groups[r.group_first as usize..(r.group_first + r.group_count) as usize].iter().map(|g| g.count).sum();
            assert_eq!(groups, r.count);
        }
        let mut owner = vec![u32::MAX; (atlas.width * atlas.height) as usize];
        for (t, r) in atlas.regions.iter().enumerate() {
            for y in r.y..r.y + r.size + 2 {
                for x in r.x..r.x + r.size + 2 {
                    let k = (y * atlas.width + x) as usize;
                    assert_eq!(owner[k], u32::MAX, "regions overlap at ({x}, {y})");
                    owner[k] = t as u32;
                }
            }
        }
        // 2000 texels over 2.005 m^2: the large triangle holds about 1995.
        let covered = atlas.triangles[0].count as f64;
        assert!((covered - 1995.0).abs() < 80.0, "{covered}");
    }
}
