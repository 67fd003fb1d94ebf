//! Secondary emitters (paper 002 Section 3.2, "Light-transfer
//! reconstruction"): light-transfer samples "connected together to form
//! (usually coarse) approximations of the isolux areas", polygons of
//! nearly constant luminosity. Here: the surface's light-transfer samples
//! are triangulated (Delaunay), each triangle is given the isolux band of
//! its corners' mean illuminance, and edge-adjacent triangles of one band
//! are merged into one polygon. A polygon without holes is shot with
//! Lambert's formula as the sum over its triangles, which is exact for the
//! union (the formula is additive over a partition of the sender).

use crate::delaunay::triangulate;
use crate::surfaces::Surface;
use glam::DVec2;
use std::collections::HashMap;

/// One secondary emitter polygon.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// Surface index.
    pub surface: u32,
    /// Triangles, as global sample indices, counter-clockwise seen from
    /// the surface's front.
    pub triangles: Vec<[u32; 3]>,
    /// Its distinct vertices (sample indices), ascending.
    pub vertices: Vec<u32>,
    /// Area, m².
    pub area: f64,
}

/// The band of `value` among the cuts `levels` (ascending): how many
/// cuts lie at or below it.
fn band(levels: &[f64], value: f64) -> usize {
    levels.iter().take_while(|&&t| t <= value).count()
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The isolux polygons of one surface, `surface_index`, from its
/// light-transfer samples (`indices` into the global sample list, with
/// their `(u, v)` and direct illuminance) and its isolux cuts `levels`.
/// Triangles whose centroid lies outside the surface (a concave outline)
/// are dropped.
pub fn isolux_polygons(surface_index: u32, surface: &Surface, indices: &[u32], uv: &[DVec2], illuminance: &[f64], levels: &[f64]) -> Vec<Polygon> {
    let triangles: Vec<[usize; 3]> =
        triangulate(uv).into_iter().filter(|t| surface.triangle_at((uv[t[0]] + uv[t[1]] + uv[t[2]]) / 3.0).is_some()).collect();
    let bands: Vec<usize> = triangles.iter().map(|t| band(levels, t.iter().map(|&k| illuminance[k]).sum::<f64>() / 3.0)).collect();
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    let mut by_edge: HashMap<(usize, usize), usize> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            match by_edge.remove(&(b, a)) {
                Some(j) if bands[j] == bands[i] => {
                    let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
                    parent[ri.max(rj)] = ri.min(rj);
                }
                Some(_) => {}
                None => {
                    by_edge.insert((a, b), i);
                }
            }
        }
    }
    let mut polygons: Vec<Polygon> = Vec::new();
    let mut of_root: HashMap<usize, usize> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        let root = find(&mut parent, i);
        let p = *of_root.entry(root).or_insert_with(|| {
            polygons.push(Polygon { surface: surface_index, triangles: Vec::new(), vertices: Vec::new(), area: 0.0 });
            polygons.len() - 1
        });
        let polygon = &mut polygons[p];
        polygon.triangles.push(t.map(|k| indices[k]));
        polygon.vertices.extend(t.map(|k| indices[k]));
        polygon.area += 0.5 * (uv[t[1]] - uv[t[0]]).perp_dot(uv[t[2]] - uv[t[0]]);
    }
    for p in &mut polygons {
        p.vertices.sort_unstable();
        p.vertices.dedup();
    }
    polygons
}
