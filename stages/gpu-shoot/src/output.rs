//! From the solved texels to the artifacts: the atlas image with seams
//! filled (004 Sec. 2.3.1), bilinear lookup, and a `solution.exr` whose
//! leaves average the atlas, so the preview gather renders it like a
//! hierarchical solution; a run's artifacts ([`Artifacts`]) from them.

use crate::atlas::{texel_point, Atlas};
use crate::tiling::{from_root, to_root, Tile};
use crate::{Params, Solved};
use radiometry::geometry::TriangleGeometry;
use radiometry::subdivision::{children, Corners, ROOT};
use schemas::header::{Header, Provenance, Schema};
use schemas::lightmap::{Convergence, Lightmap, COVERED, FILLED};
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::write_ron;
use schemas::solution::{Element, Solution, NONE};
use stage_kit::run::Outputs;
use std::collections::HashMap;
use std::path::Path;
use stage_kit::scene::triangle_corners;

/// A run's artifacts, each stamped with the run's provenance: the
/// solution, the lightmap atlas and the convergence record.
pub struct Artifacts {
    /// The solution whose leaves average the atlas ([`solution`]).
    pub solution: Solution,
    /// The atlas, seams filled ([`lightmap`]).
    pub lightmap: Lightmap,
    /// The unshot fraction shot by shot ([`Solved::convergence`]).
    pub convergence: Convergence,
}

impl Artifacts {
    /// The artifacts of `solved` (of `mesh` and `manifest`, with `params`:
    /// `rho x ambient` added to the solution when `params.ambient`) on
    /// `adapter`.
    pub fn of(solved: &Solved, mesh: &Mesh, manifest: &Manifest, params: &Params, provenance: Provenance, adapter: &str) -> Artifacts {
        let lightmap = lightmap(solved, &solved.tile_mesh(mesh), Lightmap::header(provenance.clone()));
        let ambient = params.ambient.then_some(solved.ambient);
        let solution = solution(&lightmap, mesh, manifest, &solved.tiles, ambient, params.texels_per_leaf, Solution::header(provenance.clone()));
        let convergence = solved.convergence(Convergence::header(provenance), adapter);
        Artifacts { solution, lightmap, convergence }
    }

    /// Writes the solution to `solution`, and the lightmap, the
    /// convergence log and its plot ([`crate::convergence::plot`]) to
    /// those of their paths that are given, through `outputs`.
    pub fn write(&self, outputs: &mut Outputs, solution: &Path, lightmap: Option<&Path>, log: Option<&Path>, plot: Option<&Path>) -> schemas::Result<()> {
        outputs.write(solution, |p| self.solution.write(p))?;
        if let Some(path) = lightmap {
            outputs.write(path, |p| self.lightmap.write(p))?;
        }
        if let Some(path) = log {
            outputs.write(path, |p| write_ron(p, &self.convergence))?;
        }
        if let Some(path) = plot {
            outputs.write_bytes(path, crate::convergence::plot(&self.convergence).as_bytes())?;
        }
        Ok(())
    }
}

/// Fills the texels of every region that are not covered but that a
/// bilinear lookup inside the triangle reads: two passes (004 Sec. 2.3.1
/// does the same, "ping-pong", twice), each giving a texel with at least
/// one covered or already filled 8-neighbour in its region a value from
/// those neighbours. Two passes reach every texel a lookup inside the
/// triangle touches: the one-texel gutter and the two texel diagonals
/// beyond the covered staircase.
///
/// The value is the mean of the linear extrapolations `2 B(P - d) - B(P -
/// 2 d)` over the 8 directions `d` whose two texels are known, clamped at
/// 0 (exact where radiosity is linear); only where no direction has two, the
/// mean of the known neighbours. The paper's plain mean holds the outer
/// row's value out to the edge, so a lookup between the last texel centre
/// and the edge missed the radiosity's slope there, steepest next to a
/// shared edge: on Howell C-14's receiver (l 0.1, w 1, h 1; 8000 texels)
/// the worst element was 3.2% low and the receiver's power 0.33% with
/// the mean, 2.0% and +0.04% extrapolated (issue 10, item 7). Filled
/// texels take no part in the solution (as in the paper); only the
/// lookups of [`solution`] and displays read them.
pub fn fill_seams(lightmap: &mut Lightmap) {
    let w = lightmap.width;
    for region in lightmap.regions.clone() {
        let (x0, y0, side) = (region.x as i64, region.y as i64, region.size as i64 + 2);
        let inside = |x: i64, y: i64| (x0..x0 + side).contains(&x) && (y0..y0 + side).contains(&y);
        for _ in 0..2 {
            let known = |lm: &Lightmap, x: i64, y: i64| inside(x, y) && lm.coverage[(y * w as i64 + x) as usize] != 0.0;
            let mut updates = Vec::new();
            for y in y0..y0 + side {
                for x in x0..x0 + side {
                    if known(lightmap, x, y) {
                        continue;
                    }
                    let at = |x: i64, y: i64| (y * w as i64 + x) as usize;
                    let (mut line, mut lines) = ([0.0f64; 6], 0usize);
                    let (mut mean, mut count) = ([0.0f64; 6], 0usize);
                    for dy in -1..=1i64 {
                        for dx in -1..=1i64 {
                            if (dx, dy) == (0, 0) || !known(lightmap, x - dx, y - dy) {
                                continue;
                            }
                            let near = at(x - dx, y - dy);
                            let value = |k: usize, c: usize| if c < 3 { lightmap.radiosity[k][c] } else { lightmap.residual[k][c - 3] } as f64;
                            for (c, m) in mean.iter_mut().enumerate() {
                                *m += value(near, c);
                            }
                            count += 1;
                            if known(lightmap, x - 2 * dx, y - 2 * dy) {
                                let far = at(x - 2 * dx, y - 2 * dy);
                                for (c, l) in line.iter_mut().enumerate() {
                                    *l += 2.0 * value(near, c) - value(far, c);
                                }
                                lines += 1;
                            }
                        }
                    }
                    let value = if lines > 0 {
                        line.map(|v| (v / lines as f64).max(0.0))
                    } else if count > 0 {
                        mean.map(|v| v / count as f64)
                    } else {
                        continue;
                    };
                    let b = [value[0], value[1], value[2]].map(|v| v as f32);
                    let r = [value[3], value[4], value[5]].map(|v| v as f32);
                    updates.push((at(x, y), b, r));
                }
            }
            for (k, b, r) in updates {
                lightmap.radiosity[k] = b;
                lightmap.residual[k] = r;
                lightmap.coverage[k] = FILLED;
            }
        }
    }
}

/// The lightmap artifact of a solve, seams filled; `mesh` is the mesh of
/// its tiles ([`Solved::tile_mesh`]).
pub fn lightmap(solved: &Solved, mesh: &Mesh, header: Header) -> Lightmap {
    lightmap_of(&solved.atlas, &solved.radiosity, &solved.residual, mesh, header)
}

/// The lightmap of `atlas` with these texel values (the atlas's order),
/// seams filled.
pub fn lightmap_of(a: &Atlas, radiosity: &[[f32; 3]], residual: &[[f32; 3]], mesh: &Mesh, header: Header) -> Lightmap {
    let (w, h) = (a.width as usize, a.height as usize);
    let mut lm = Lightmap {
        header,
        width: w,
        height: h,
        radiosity: vec![[0.0; 3]; w * h],
        residual: vec![[0.0; 3]; w * h],
        coverage: vec![0.0; w * h],
        texel_area: vec![0.0; w * h],
        position: vec![[0.0; 3]; w * h],
        normal: vec![[0.0; 3]; w * h],
        regions: a.regions.clone(),
    };
    for (k, t) in a.texels.iter().enumerate() {
        let i = t.y as usize * w + t.x as usize;
        lm.radiosity[i] = radiosity[k];
        lm.residual[i] = residual[k];
        // A buried texel holds no value: filled from its neighbours, as
        // beyond an edge.
        lm.coverage[i] = if t.buried { 0.0 } else { COVERED };
        lm.texel_area[i] = t.area;
    }
    // Positions and normals of every texel of a region, gutter included
    // (the point of the triangle's plane its centre maps to).
    for (t, r) in a.regions.iter().enumerate() {
        let tri = &mesh.triangles[t];
        let g = TriangleGeometry::new(triangle_corners(mesh, t));
        let n = r.size as f64;
        for j in 0..r.size + 2 {
            for i in 0..r.size + 2 {
                let uv = [(i as f64 - 0.5) / n, (j as f64 - 0.5) / n];
                let k = (r.y + j) as usize * w + (r.x + i) as usize;
                lm.position[k] = g.point(uv).as_vec3().to_array();
                lm.normal[k] = tri.normal;
            }
        }
    }
    fill_seams(&mut lm);
    lm
}

/// Whether barycentric `uv` of region `t` lies in a buried texel (one of
/// the triangle's texels that holds no value of its own,
/// [`crate::atlas::Texel::buried`]).
fn buried_at(lm: &Lightmap, t: usize, uv: [f64; 2]) -> bool {
    let r = lm.regions[t];
    let n = r.size as f64;
    let (i, j) = ((uv[0] * n).floor().clamp(0.0, n - 1.0) as u32, (uv[1] * n).floor().clamp(0.0, n - 1.0) as u32);
    let (x, y) = r.texel(i, j);
    r.is_covered(i, j) && lm.coverage[y as usize * lm.width + x as usize] != COVERED
}

/// Radiosity and residual for every covered texel of `atlas` (tiles
/// `tiles`, each inside the old tile `origin` of `old_tiles`, whose
/// lightmap is `old`): a tile that did not change keeps its texels'
/// values; the children of a split tile take the bilinear reconstruction
/// of their old tile at their texels' points (004 Sec. 2.4: "copied down
/// ... using linear interpolation"), scaled per channel so that together
/// they hold the old tile's power (the reconstruction's extrapolated
/// seams would otherwise add or lose some).
pub fn copy_down(old: &Lightmap, old_tiles: &[Tile], atlas: &Atlas, tiles: &[Tile], origin: &[usize]) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let split = |t: usize| old_tiles[origin[t]] != tiles[t];
    let values: Vec<([f64; 3], [f64; 3])> = atlas
        .texels
        .iter()
        .map(|x| {
            let t = x.triangle as usize;
            let o = origin[t];
            let (i, j) = x.indices(atlas.regions[t]);
            if !split(t) {
                let r = old.regions[o];
                let k = (r.y + 1 + j) as usize * old.width + (r.x + 1 + i) as usize;
                return (old.radiosity[k].map(f64::from), old.residual[k].map(f64::from));
            }
            let at = from_root(&old_tiles[o].corners, to_root(&tiles[t].corners, texel_point(atlas.regions[t], i, j)));
            (old.lookup(&old.radiosity, o, at), old.lookup(&old.residual, o, at))
        })
        .collect();
    // Power per old tile that was split: in the old lightmap, and copied.
    let mut before = vec![[0.0f64; 6]; old_tiles.len()];
    let mut after = vec![[0.0f64; 6]; old_tiles.len()];
    for (o, r) in old.regions.iter().enumerate() {
        for j in 0..r.size {
            for i in 0..r.size - j {
                let k = (r.y + 1 + j) as usize * old.width + (r.x + 1 + i) as usize;
                let a = old.texel_area[k] as f64;
                for c in 0..3 {
                    before[o][c] += old.radiosity[k][c] as f64 * a;
                    before[o][c + 3] += old.residual[k][c] as f64 * a;
                }
            }
        }
    }
    for (x, (b, r)) in atlas.texels.iter().zip(&values) {
        let a = x.area as f64;
        for c in 0..3 {
            after[origin[x.triangle as usize]][c] += b[c] * a;
            after[origin[x.triangle as usize]][c + 3] += r[c] * a;
        }
    }
    let scale = |o: usize, c: usize| if after[o][c] != 0.0 { before[o][c] / after[o][c] } else { 1.0 };
    atlas
        .texels
        .iter()
        .zip(values)
        .map(|(x, (b, r))| {
            let t = x.triangle as usize;
            if !split(t) {
                return ([b[0] as f32, b[1] as f32, b[2] as f32, 0.0], [r[0] as f32, r[1] as f32, r[2] as f32, 0.0]);
            }
            let o = origin[t];
            let f = |v: [f64; 3], at: usize| [0, 1, 2].map(|c| (v[c] * scale(o, c + at)) as f32);
            let (b, r) = (f(b, 0), f(r, 3));
            ([b[0], b[1], b[2], 0.0], [r[0], r[1], r[2], 0.0])
        })
        .unzip()
}

/// The solution: each input triangle refined (1:4, the order of
/// `radiometry::subdivision`) down to its tiles ([`crate::tiling`]; one
/// tile, the triangle, without adaptive subdivision), each tile uniformly
/// to the level whose leaves hold about
/// `texels_per_leaf` covered texels; a leaf's radiosity is the mean of the
/// bilinear reconstruction over it: the leaf split 1:4 into pieces of
/// about a texel, on each the mean of the lookups at its centroid and at
/// the three points `(2/3, 1/6, 1/6)` of its corners (Dunavant's degree-2
/// rule plus the centroid), plus
/// `rho x ambient` when asked (004 Eq. 2.4, for display). The lookups that
/// fall in a buried texel are left out, and a leaf's area is its exposed
/// part's (the fraction of its lookups kept), as hierarchical-solve's
/// solution holds it: a leaf straddling a block's footprint shows its
/// exposed part's radiosity, and one under the block weighs nothing where
/// a display averages leaves. Inner elements hold their children's area
/// and its area-weighted mean radiosity. No links, no clusters.
pub fn solution(lm: &Lightmap, mesh: &Mesh, manifest: &Manifest, tiles: &[Tile], ambient: Option<[f64; 3]>, texels_per_leaf: f64, header: Header) -> Solution {
    let mut elements: Vec<Element> = mesh.triangles.iter().enumerate().map(|(t, tri)| Element::root(t as u32, tri.area, [0.0; 3])).collect();
    // Per element: its corners in its input triangle, and below the tiles
    // its tile, its corners in the tile and its level under the tile.
    let mut corners_of: Vec<Corners> = vec![ROOT; elements.len()];
    let mut place: Vec<Option<(usize, Corners, u32)>> = vec![None; elements.len()];
    let key = |root: u32, c: &Corners| (root, c.map(|p| p.map(f64::to_bits)));
    let tile_at: HashMap<_, usize> = tiles.iter().enumerate().map(|(k, t)| (key(t.root, &t.corners), k)).collect();
    let push = |elements: &mut Vec<Element>, corners_of: &mut Vec<Corners>, place: &mut Vec<Option<(usize, Corners, u32)>>, parent: usize, corners: Corners, level: u32, at: Option<(usize, Corners, u32)>| {
        let t = elements[parent].triangle;
        elements.push(Element {
            triangle: t,
            parent: parent as u32,
            first_child: NONE,
            level,
            corners: corners.map(|c| c.map(|x| x as f32)),
            area: (mesh.triangles[t as usize].area as f64 / 4f64.powi(level as i32)) as f32,
            radiosity: [0.0; 3],
        });
        corners_of.push(corners);
        place.push(at);
    };
    for t in 0..mesh.triangles.len() {
        // The input triangle's refinement down to its tiles.
        let (mut queue, mut next) = (vec![t], 0);
        let mut at_tiles = Vec::new();
        while next < queue.len() {
            let e = queue[next];
            next += 1;
            if let Some(&tile) = tile_at.get(&key(t as u32, &corners_of[e])) {
                at_tiles.push((e, tile));
                continue;
            }
            elements[e].first_child = elements.len() as u32;
            for child in children(&corners_of[e]) {
                queue.push(elements.len());
                let level = elements[e].level + 1;
                push(&mut elements, &mut corners_of, &mut place, e, child, level, None);
            }
        }
        // Each tile uniformly down to about `texels_per_leaf` texels a leaf.
        for (e, tile) in at_tiles {
            place[e] = Some((tile, ROOT, 0));
            let covered = lm.regions[tile].covered as f64;
            let depth = ((covered / texels_per_leaf).max(1.0).ln() / 4f64.ln()).floor().clamp(0.0, 8.0) as u32;
            let mut frontier = vec![e];
            for local in 1..=depth {
                let mut next = Vec::new();
                for parent in frontier {
                    elements[parent].first_child = elements.len() as u32;
                    let (_, corners, _) = place[parent].expect("below a tile");
                    for child in children(&corners) {
                        next.push(elements.len());
                        let level = tiles[tile].level + local;
                        push(&mut elements, &mut corners_of, &mut place, parent, child.map(|c| to_root(&tiles[tile].corners, c)), level, Some((tile, child, local)));
                    }
                }
                frontier = next;
            }
        }
    }
    let rho_ambient = |t: usize| -> [f64; 3] {
        let rho = manifest.materials[mesh.triangles[t].material as usize].diffuse;
        ambient.map(|a| [0, 1, 2].map(|c| rho[c] * a[c])).unwrap_or([0.0; 3])
    };
    for e in 0..elements.len() {
        if !elements[e].is_leaf() {
            continue;
        }
        let t = elements[e].triangle as usize;
        let (tile, local, local_level) = place[e].expect("every leaf lies in a tile");
        // Sub-triangles of about one texel each, so the rule integrates the
        // bilinear reconstruction, not a handful of its values (an element
        // of 14 texels next to a shared edge, where radiosity halves within
        // the element, was 1.7% low with the rule on the element itself).
        let texels = lm.regions[tile].covered as f64 / 4f64.powi(local_level as i32);
        let levels = (texels.max(1.0).ln() / 4f64.ln()).ceil() as u32;
        let mut pieces = vec![local];
        for _ in 0..levels {
            pieces = pieces.iter().flat_map(children).collect();
        }
        let (a, b) = (2.0 / 3.0, 1.0 / 6.0);
        let points = [[1.0 / 3.0; 3], [a, b, b], [b, a, b], [b, b, a]];
        let (mut sum, mut exposed) = ([0.0; 3], 0usize);
        for c in &pieces {
            let point = |l: [f64; 3]| [l[0] * c[0][0] + l[1] * c[1][0] + l[2] * c[2][0], l[0] * c[0][1] + l[1] * c[1][1] + l[2] * c[2][1]];
            for l in points {
                let uv = point(l);
                if buried_at(lm, tile, uv) {
                    continue;
                }
                exposed += 1;
                for (s, v) in sum.iter_mut().zip(lm.radiosity_at(tile, uv)) {
                    *s += v;
                }
            }
        }
        let extra = rho_ambient(t);
        let mean = sum.map(|v| if exposed > 0 { v / exposed as f64 } else { 0.0 });
        elements[e].radiosity = [0, 1, 2].map(|k| (mean[k] + extra[k]) as f32);
        elements[e].area = (elements[e].area as f64 * exposed as f64 / (points.len() * pieces.len()) as f64) as f32;
    }
    // Inner elements: their children's exposed area and its area-weighted
    // mean radiosity, deepest first.
    for e in (0..elements.len()).rev() {
        if elements[e].is_leaf() {
            continue;
        }
        let first = elements[e].first_child as usize;
        let mut sum = [0.0f64; 3];
        let mut area = 0.0f64;
        for child in &elements[first..first + 4] {
            for (s, b) in sum.iter_mut().zip(child.radiosity) {
                *s += b as f64 * child.area as f64;
            }
            area += child.area as f64;
        }
        elements[e].radiosity = sum.map(|s| if area > 0.0 { (s / area) as f32 } else { 0.0 });
        elements[e].area = area as f32;
    }
    Solution { header, elements, clusters: Vec::new(), links: Vec::new(), slopes: Vec::new() }
}
