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
use crate::union_find::{find, union};
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

/// The isolux polygons of one surface, `surface_index`, from its
/// light-transfer samples (`indices` into the global sample list, with
/// their `(u, v)`), `illuminance(uv)` the direct illuminance and `levels`
/// the isolux cuts.
///
/// A triangle's band is that of the illuminance at its centroid (its
/// corners lie on contours, so their mean would sit on a cut and flip
/// between bands). Triangles whose centroid lies outside the surface (a
/// concave outline) are dropped. Regions smaller than `min_area` (m²; a
/// penumbra crosses every band in a narrow strip) are merged into the
/// neighbour they share the longest boundary with, smallest first, so
/// that no emitter is a sliver: "the emitters need not contain many
/// samples, especially in the case of the shadowed regions" (002 Section
/// 3.2). Triangles join a region only within one cell of a grid of
/// `cells` along the samples' longer side (1: by band alone, as the
/// paper): a polygon sends its mean radiosity from all of it, and a
/// region of one band can span a whole surface where the direct light has
/// no contours (a ceiling lit only by reflection), whose edges then
/// lit their neighbours with the mean of its centre. On the built-in
/// Cornell box (against the full gather of hierarchical-solve, mean signed
/// error per pixel) 4 cells took the image from -7.9% to -4.6% (back wall
/// -9.5% to -4.9%, tall block -12.0% to -6.7%), McGuire's empty white box
/// from -8.0% to -6.4%; 8 cells, whose cells fall under the default
/// `emitter_min_area` and merge again, did no better. The stage sizes the
/// cells by the scene, not the surface (its `emitter_cell`), so that a
/// small surface is not cut: McGuire's glossy box, whose sphere has a
/// thousand facets, cut into 4 x 4 cells each, stopped at the 10,000-shot
/// cap with 2.2% of its power unshot (0.27% with the cells sized by the
/// scene; 9,512 shots to converge before the shooting kept its energy).
///
/// The triangles whose corners are all `buried` (global sample index:
/// inside a solid, [`crate::burial`]) are left out of the polygons, but
/// only once the regions are formed: the dark region of a block's shadow
/// and footprint, without its footprint, fell under `min_area`, merged
/// into the lit floor beside it, and the block's face, which sees that
/// floor nearest, came out up to twice as bright as the path-traced
/// reference near its base.
#[allow(clippy::too_many_arguments)]
pub fn isolux_polygons(surface_index: u32, surface: &Surface, indices: &[u32], uv: &[DVec2], illuminance: impl Fn(DVec2) -> f64, levels: &[f64], min_area: f64, cells: usize, buried: &dyn Fn(u32) -> bool) -> Vec<Polygon> {
    let centroid = |t: &[usize; 3]| (uv[t[0]] + uv[t[1]] + uv[t[2]]) / 3.0;
    let triangles: Vec<[usize; 3]> = triangulate(uv).into_iter().filter(|t| surface.triangle_at(centroid(t)).is_some()).collect();
    let bands: Vec<usize> = triangles.iter().map(|t| band(levels, illuminance(centroid(t)))).collect();
    let areas: Vec<f64> = triangles.iter().map(|t| 0.5 * (uv[t[1]] - uv[t[0]]).perp_dot(uv[t[2]] - uv[t[0]])).collect();
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    // Edge-adjacent triangle pairs with the shared edge's length.
    let mut adjacent: Vec<(usize, usize, f64)> = Vec::new();
    let mut by_edge: HashMap<(usize, usize), usize> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            match by_edge.remove(&(b, a)) {
                Some(j) => adjacent.push((j, i, (uv[a] - uv[b]).length())),
                None => {
                    by_edge.insert((a, b), i);
                }
            }
        }
    }
    // The cell of the grid of `cells` along the samples' longer side that
    // a triangle's centroid lies in.
    let (lo, hi) = uv.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let size = (hi - lo).max_element();
    let cell = |t: &[usize; 3]| if size > 0.0 { ((centroid(t) - lo) / size * cells as f64).floor().min(DVec2::splat(cells as f64 - 1.0)).as_ivec2() } else { glam::IVec2::ZERO };
    for &(i, j, _) in &adjacent {
        if bands[i] == bands[j] && cell(&triangles[i]) == cell(&triangles[j]) {
            union(&mut parent, i, j);
        }
    }
    merge_small_regions(&mut parent, &areas, &adjacent, min_area);
    let mut polygons: Vec<Polygon> = Vec::new();
    let mut of_root: HashMap<usize, usize> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        if t.iter().all(|&k| buried(indices[k])) {
            continue;
        }
        let root = find(&mut parent, i);
        let p = *of_root.entry(root).or_insert_with(|| {
            polygons.push(Polygon { surface: surface_index, triangles: Vec::new(), vertices: Vec::new(), area: 0.0 });
            polygons.len() - 1
        });
        let polygon = &mut polygons[p];
        polygon.triangles.push(t.map(|k| indices[k]));
        polygon.vertices.extend(t.map(|k| indices[k]));
        polygon.area += areas[i];
    }
    for p in &mut polygons {
        p.vertices.sort_unstable();
        p.vertices.dedup();
    }
    polygons
}

/// Merges every region (union-find `parent` over triangles of `areas`)
/// smaller than `min_area` into the neighbour across its longest shared
/// boundary (ties: the lower root), smallest region first, pass after pass
/// until none is left that has a neighbour.
fn merge_small_regions(parent: &mut [usize], areas: &[f64], adjacent: &[(usize, usize, f64)], min_area: f64) {
    loop {
        let roots: Vec<usize> = (0..parent.len()).map(|i| find(parent, i)).collect();
        let mut area: HashMap<usize, f64> = HashMap::new();
        for (i, &r) in roots.iter().enumerate() {
            *area.entry(r).or_default() += areas[i];
        }
        let mut shared: HashMap<(usize, usize), f64> = HashMap::new();
        for &(i, j, length) in adjacent {
            let (a, b) = (roots[i], roots[j]);
            if a != b {
                *shared.entry((a, b)).or_default() += length;
                *shared.entry((b, a)).or_default() += length;
            }
        }
        let mut small: Vec<(f64, usize)> = area.iter().filter(|(_, &a)| a < min_area).map(|(&r, &a)| (a, r)).collect();
        small.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut changed: Vec<usize> = Vec::new();
        let mut merged = false;
        for (_, r) in small {
            if changed.contains(&r) {
                continue;
            }
            let best = shared.iter().filter(|((a, b), _)| *a == r && !changed.contains(b)).max_by(|x, y| x.1.total_cmp(y.1).then((y.0).1.cmp(&(x.0).1)));
            if let Some((&(_, b), _)) = best {
                union(parent, r, b);
                changed.extend([r, b]);
                merged = true;
            }
        }
        if !merged {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surfaces::rectangle;

    fn lattice() -> Vec<DVec2> {
        (0..=16).flat_map(|i| (0..=8).map(move |j| DVec2::new(0.25 * i as f64, 0.25 * j as f64))).collect()
    }

    #[test]
    fn regions_follow_the_bands_and_partition_the_surface() {
        let (surface, uv) = (rectangle(4.0, 2.0), lattice());
        let indices: Vec<u32> = (100..100 + uv.len() as u32).collect();
        // Illuminance growing with u: cuts at u = 1.1, 2.1, 3.1 make four bands.
        let polygons = isolux_polygons(7, &surface, &indices, &uv, |p| p.x, &[1.1, 2.1, 3.1], 0.0, 1, &|_| false);
        assert_eq!(polygons.len(), 4);
        let area: f64 = polygons.iter().map(|p| p.area).sum();
        assert!((area - 8.0).abs() < 1e-12, "{area}");
        for p in &polygons {
            assert_eq!(p.surface, 7);
            assert!(p.vertices.iter().all(|v| (100..100 + uv.len() as u32).contains(v)));
            // One band per polygon: every triangle's centroid on one side of each cut.
            let band_of = |t: &[u32; 3]| band(&[1.1, 2.1, 3.1], t.iter().map(|&v| uv[(v - 100) as usize].x).sum::<f64>() / 3.0);
            assert!(p.triangles.iter().all(|t| band_of(t) == band_of(&p.triangles[0])));
        }
    }

    #[test]
    fn regions_under_the_least_area_join_a_neighbour() {
        let (surface, uv) = (rectangle(4.0, 2.0), lattice());
        let indices: Vec<u32> = (0..uv.len() as u32).collect();
        // A thin band u in (1.0, 1.3) between two wide ones.
        let cuts = [1.05, 1.3];
        let thin = isolux_polygons(0, &surface, &indices, &uv, |p| p.x, &cuts, 0.0, 1, &|_| false);
        assert_eq!(thin.len(), 3);
        let merged = isolux_polygons(0, &surface, &indices, &uv, |p| p.x, &cuts, 1.0, 1, &|_| false);
        assert_eq!(merged.len(), 2, "the 0.5 m² band joins a neighbour");
        assert!(merged.iter().all(|p| p.area >= 1.0));
        let area: f64 = merged.iter().map(|p| p.area).sum();
        assert!((area - 8.0).abs() < 1e-12);
    }

    /// A block's footprint, the samples with u < 1 buried (the lattice's
    /// columns up to 0.75): the band under u = 1.3 (its triangles'
    /// centroids, so u up to 1.25) is one region of 2.5 m² before the
    /// buried triangles leave it, over the least area 1.2 m², so it does
    /// not join the wide band beside it (it would at 1 m², which is what
    /// it keeps: the triangles with an open corner, u in [0.75, 1.25]).
    #[test]
    fn buried_triangles_leave_the_polygons_after_the_regions_form() {
        let (surface, uv) = (rectangle(4.0, 2.0), lattice());
        let indices: Vec<u32> = (0..uv.len() as u32).collect();
        let buried = |i: u32| uv[i as usize].x < 0.99;
        let polygons = isolux_polygons(0, &surface, &indices, &uv, |p| p.x, &[1.3], 1.2, 1, &buried);
        assert_eq!(polygons.len(), 2, "{polygons:?}");
        let dark = polygons.iter().find(|p| p.triangles.iter().all(|t| t.iter().any(|&v| uv[v as usize].x < 1.3))).expect("the dark band");
        assert!((dark.area - 1.0).abs() < 1e-12, "{}", dark.area);
        assert!(dark.triangles.iter().all(|t| t.iter().any(|&v| !buried(v))));
        let area: f64 = polygons.iter().map(|p| p.area).sum();
        assert!((area - 6.5).abs() < 1e-12, "the 1.5 m² wholly under the block left out: {area}");
    }
}
