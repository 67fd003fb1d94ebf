//! Adaptive subdivision at shadow boundaries (paper 004 Sec. 2.4): the
//! solver works on tiles, each a triangle of the regular 1:4 refinement of
//! an input triangle (`radiometry::subdivision`), with a lightmap region of
//! its object's size, so a split tile has four times the texels over the
//! same area. Without subdivision every input triangle is one tile.
//!
//! Splits keep the balance rule of Baum et al. (004 Sec. 2.4): tiles that
//! share an edge differ by at most one level, so a tile next to one two
//! levels finer along its edge is split too.

use glam::DVec3;
use radiometry::bounds::Aabb;
use radiometry::subdivision::{children, Corners, ROOT};
use schemas::mesh::{Mesh, Triangle};
use schemas::surface::Surface;
use std::collections::HashMap;
use stage_kit::scene::triangle_corners;

/// One tile: a triangle of the refinement of input triangle `root`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tile {
    /// The input triangle.
    pub root: u32,
    /// Barycentric corners in the input triangle.
    pub corners: Corners,
    /// Refinement level (0: the input triangle).
    pub level: u32,
}

/// One tile per input triangle.
pub fn identity(mesh: &Mesh) -> Vec<Tile> {
    (0..mesh.triangles.len() as u32).map(|root| Tile { root, corners: ROOT, level: 0 }).collect()
}

/// Barycentric `(a, b)` of a tile with `corners` to its input triangle's.
pub fn to_root(corners: &Corners, ab: [f64; 2]) -> [f64; 2] {
    std::array::from_fn(|k| corners[0][k] + ab[0] * (corners[1][k] - corners[0][k]) + ab[1] * (corners[2][k] - corners[0][k]))
}

/// The inverse of [`to_root`].
pub fn from_root(corners: &Corners, x: [f64; 2]) -> [f64; 2] {
    let (e1, e2) = ([corners[1][0] - corners[0][0], corners[1][1] - corners[0][1]], [corners[2][0] - corners[0][0], corners[2][1] - corners[0][1]]);
    let d = [x[0] - corners[0][0], x[1] - corners[0][1]];
    let det = e1[0] * e2[1] - e1[1] * e2[0];
    [(d[0] * e2[1] - d[1] * e2[0]) / det, (e1[0] * d[1] - e1[1] * d[0]) / det]
}

/// The point at barycentric `uv` of input triangle `t`, m.
fn point(mesh: &Mesh, t: usize, uv: [f64; 2]) -> DVec3 {
    let p = triangle_corners(mesh, t);
    p[0] + uv[0] * (p[1] - p[0]) + uv[1] * (p[2] - p[0])
}

/// The mesh of the tiles: one triangle each, the input triangle's
/// material, object and normal, its area over `4^level`.
pub fn mesh_of(mesh: &Mesh, tiles: &[Tile]) -> Mesh {
    let mut positions = Vec::with_capacity(3 * tiles.len());
    let mut triangles = Vec::with_capacity(tiles.len());
    for (k, tile) in tiles.iter().enumerate() {
        let root = &mesh.triangles[tile.root as usize];
        positions.extend(tile.corners.map(|c| point(mesh, tile.root as usize, c).as_vec3().to_array()));
        let base = 3 * k as u32;
        let area = (root.area as f64 / 4f64.powi(tile.level as i32)) as f32;
        triangles.push(Triangle { vertices: [base, base + 1, base + 2], area, ..*root });
    }
    Mesh { header: mesh.header.clone(), positions, triangles }
}

/// The surface detail of the tiles: corner texture coordinates and
/// shading normals interpolated at their corners, tangents as their input
/// triangle's.
pub fn surface_of(surface: &Surface, tiles: &[Tile]) -> Surface {
    let lerp = |c: &[[f32; 2]; 3], x: [f64; 2]| -> [f32; 2] { std::array::from_fn(|k| (c[0][k] as f64 + x[0] * (c[1][k] - c[0][k]) as f64 + x[1] * (c[2][k] - c[0][k]) as f64) as f32) };
    let uv: HashMap<u32, [[f32; 2]; 3]> = surface.uvs.iter().copied().collect();
    let normals: HashMap<u32, [[f32; 3]; 3]> = surface.shading_normals.iter().copied().collect();
    let tangents: HashMap<u32, [f32; 4]> = surface.tangents.iter().copied().collect();
    let mut out = Surface { header: surface.header.clone(), uvs: Vec::new(), shading_normals: Vec::new(), tangents: Vec::new(), material_maps: surface.material_maps.clone(), textures: surface.textures.clone() };
    for (k, tile) in tiles.iter().enumerate() {
        let k = k as u32;
        if let Some(c) = uv.get(&tile.root) {
            out.uvs.push((k, tile.corners.map(|x| lerp(c, x))));
        }
        if let Some(n) = normals.get(&tile.root) {
            let at = |x: [f64; 2]| -> [f32; 3] {
                let v = DVec3::from(std::array::from_fn::<f64, 3, _>(|a| n[0][a] as f64 + x[0] * (n[1][a] - n[0][a]) as f64 + x[1] * (n[2][a] - n[0][a]) as f64));
                v.normalize().as_vec3().to_array()
            };
            out.shading_normals.push((k, tile.corners.map(at)));
        }
        if let Some(t) = tangents.get(&tile.root) {
            out.tangents.push((k, *t));
        }
    }
    out
}

/// Splits the tiles `split` into their four children (in place, children
/// after the tiles that stay), then every tile an edge neighbour two
/// levels finer requires, until none does. Returns the new tiles and, for
/// each, the index of the old tile it lies in.
pub fn split(mesh: &Mesh, tiles: &[Tile], split: &[bool]) -> (Vec<Tile>, Vec<usize>) {
    let mut current: Vec<(Tile, usize)> = tiles.iter().copied().zip(0..).collect();
    let mut marked: Vec<bool> = split.to_vec();
    loop {
        let mut next = Vec::with_capacity(current.len() + 3 * marked.iter().filter(|&&m| m).count());
        for (&(tile, origin), &m) in current.iter().zip(&marked) {
            if !m {
                next.push((tile, origin));
                continue;
            }
            for corners in children(&tile.corners) {
                next.push((Tile { root: tile.root, corners, level: tile.level + 1 }, origin));
            }
        }
        current = next;
        let just: Vec<Tile> = current.iter().map(|c| c.0).collect();
        marked = unbalanced(mesh, &just);
        if !marked.contains(&true) {
            break;
        }
    }
    current.into_iter().unzip()
}

/// The tiles that have an edge neighbour at least two levels finer: a
/// tile two levels finer along an edge has a corner at that edge's end or
/// midpoint (the finer tiles along an edge cover its quarters), and two
/// corners on the edge.
fn unbalanced(mesh: &Mesh, tiles: &[Tile]) -> Vec<bool> {
    let corners: Vec<[DVec3; 3]> = tiles.iter().map(|t| t.corners.map(|c| point(mesh, t.root as usize, c))).collect();
    let bounds = Aabb::around(mesh.positions.iter().map(|p| DVec3::from(p.map(f64::from))));
    let eps = 1e-7 * (bounds.max - bounds.min).length().max(1e-30);
    let key = |p: DVec3| ((p / eps).round().as_i64vec3()).to_array();
    let mut at: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (k, c) in corners.iter().enumerate() {
        for p in c {
            at.entry(key(*p)).or_default().push(k);
        }
    }
    let on = |p: DVec3, a: DVec3, b: DVec3| {
        let (e, d) = (b - a, p - a);
        let s = d.dot(e) / e.length_squared();
        (-1e-9..=1.0 + 1e-9).contains(&s) && (d - s * e).length() <= 10.0 * eps
    };
    (0..tiles.len())
        .map(|k| {
            let c = corners[k];
            let edges = [(c[0], c[1]), (c[1], c[2]), (c[2], c[0])];
            let probes = [c[0], c[1], c[2], (c[0] + c[1]) / 2.0, (c[1] + c[2]) / 2.0, (c[2] + c[0]) / 2.0];
            probes.iter().filter_map(|p| at.get(&key(*p))).flatten().any(|&f| {
                tiles[f].level >= tiles[k].level + 2 && edges.iter().any(|&(a, b)| corners[f].iter().filter(|&&q| on(q, a, b)).count() >= 2)
            })
        })
        .collect()
}

/// Whether `tiles` is one tile per input triangle.
pub fn is_identity(tiles: &[Tile]) -> bool {
    tiles.iter().enumerate().all(|(k, t)| t.root as usize == k && t.level == 0)
}
