//! Texture lookups and texture averages over triangles, for the stages
//! that simulate surface detail (paper 004 Sec. 4.2, per-texel colour, and
//! Sec. 4.3.4, masking). A texture reaches these functions as [`Texels`]:
//! its texels and how texture coordinates map onto them, borrowed from
//! wherever it is kept (the stage kit's `scene` module lends those of
//! `surface.exr`).
//!
//! # Coordinates
//!
//! A point's texture coordinates `uv` (interpolated from the corners')
//! become `s = scale uv + offset` (MTL `-s`, `-o`), and texel space
//!
//! ```text
//! x = s_u W,   y = (1 - s_v) H          (row 0 is the top of the image, v = 1)
//! ```
//!
//! so texel `(i, j)` covers `[i, i + 1) x [j, j + 1)` and its centre is
//! `(i + 1/2, j + 1/2)`. Texel indices outside the image repeat (`i mod W`)
//! or, with MTL `-clamp on`, clamp to the edge (`min(max(i, 0), W - 1)`),
//! which is the same as clamping `s` to [0, 1].
//!
//! # What is looked up
//!
//! - Reflectance (a diffuse texture, linear): bilinear between the four
//!   nearest texel centres, `rho(x, y) = sum (1 - |x - x_c|)+ (1 - |y -
//!   y_c|)+ rho_c`.
//! - Coverage (an alpha texture): a point exists where the texel holding
//!   it has alpha above 0 (004 Sec. 4.3.4: alpha 0 is fully transparent,
//!   any other value opaque); no filtering, so a mask's edges are its
//!   texels' edges at every resolution of the solution.
//!
//! # Averages over a triangle
//!
//! [`average`] integrates over a triangle's footprint in texture space,
//! which the affine map from the triangle to its texture coordinates makes
//! an average by area on the triangle. Both lookups are polynomials of
//! degree at most 2 on the cells of a grid (bilinear between four texel
//! centres: the grid of texel centres; coverage: the texel grid), so the
//! average is exact up to round-off: the footprint is clipped against the
//! grid (Sutherland-Hodgman, one convex piece per cell), each piece is
//! fanned into triangles, and each triangle is integrated by the
//! edge-midpoint rule, `integral f dA = A/3 (f(m_01) + f(m_12) + f(m_20))`,
//! exact for quadratics (Strang and Fix). Where the alpha map and the
//! diffuse texture both apply, the reflectance is averaged over the opaque
//! part only (each opaque piece is clipped again against the diffuse
//! texture's grid): points that do not exist reflect nothing.
//!
//! A footprint covering more than [`MAX_CELLS`] grid cells (a large
//! repeating texture on one triangle) is instead split 1:4 into
//! `4^FALLBACK_LEVELS` equal sub-triangles, each taking the lookup at its
//! centroid (the centroid rule), whose error is of the order of the
//! texture's variation over a sub-triangle. A footprint without area in
//! texture space (all corners at one coordinate, or along a line) takes
//! the lookup at its centroid.

use crate::subdivision::{children, Corners};

/// Most grid cells an exact average clips against (see the module docs).
pub const MAX_CELLS: f64 = 65_536.0;

/// 1:4 levels of the centroid rule past [`MAX_CELLS`]: `4^8 = 65,536`
/// sub-triangles.
pub const FALLBACK_LEVELS: u32 = 8;

/// A point in texture or texel space.
type P2 = [f64; 2];

/// A texture as the lookups read it: `width x height` RGBA texels, row 0
/// the top of the image (`v = 1`), and how texture coordinates map onto
/// them (module docs). `D` holds the texels: a borrowed slice for the
/// lookups ([`Texels`]), a `Vec` where a texture is kept
/// ([`crate::rays::AlphaMasks`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelGrid<D> {
    /// Texels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width x height` texels, RGBA, row by row from the top.
    pub texels: D,
    /// MTL `-s`: texture coordinates are `scale * uv + offset`.
    pub scale: [f32; 2],
    /// MTL `-o`.
    pub offset: [f32; 2],
    /// MTL `-clamp on`: coordinates clamp to [0, 1]; otherwise they repeat.
    pub clamp: bool,
}

/// A texture the lookups read, its texels borrowed.
pub type Texels<'a> = TexelGrid<&'a [[f32; 4]]>;

impl TexelGrid<Vec<[f32; 4]>> {
    /// The texture with its texels borrowed, for the lookups.
    pub fn view(&self) -> Texels<'_> {
        TexelGrid { width: self.width, height: self.height, texels: &self.texels, scale: self.scale, offset: self.offset, clamp: self.clamp }
    }
}

impl Texels<'_> {
    /// A copy that owns its texels, to keep.
    pub fn owned(&self) -> TexelGrid<Vec<[f32; 4]>> {
        TexelGrid { width: self.width, height: self.height, texels: self.texels.to_vec(), scale: self.scale, offset: self.offset, clamp: self.clamp }
    }
}

/// Texture coordinates `uv` to texel space (module docs).
fn texel_space(t: Texels, uv: P2) -> P2 {
    let s = [f64::from(t.scale[0]) * uv[0] + f64::from(t.offset[0]), f64::from(t.scale[1]) * uv[1] + f64::from(t.offset[1])];
    [s[0] * t.width as f64, (1.0 - s[1]) * t.height as f64]
}

/// Texel space back to texture coordinates (the inverse of
/// [`texel_space`]; the scale must not be 0).
fn texture_space(t: Texels, p: P2) -> P2 {
    let s = [p[0] / t.width as f64, 1.0 - p[1] / t.height as f64];
    [(s[0] - f64::from(t.offset[0])) / f64::from(t.scale[0]), (s[1] - f64::from(t.offset[1])) / f64::from(t.scale[1])]
}

/// The texel at column `i`, row `j`, repeated or clamped (module docs).
fn texel(t: Texels, i: i64, j: i64) -> [f32; 4] {
    let fold = |k: i64, n: usize| if t.clamp { k.clamp(0, n as i64 - 1) as usize } else { k.rem_euclid(n as i64) as usize };
    t.texels[fold(j, t.height) * t.width + fold(i, t.width)]
}

/// Bilinear value in the cell of texel centres whose top left centre is
/// `(i, j)` at fractions `(f, g)` across it.
fn bilinear_in(t: Texels, i: i64, j: i64, f: f64, g: f64) -> [f64; 4] {
    let (a, b, c, d) = (texel(t, i, j), texel(t, i + 1, j), texel(t, i, j + 1), texel(t, i + 1, j + 1));
    std::array::from_fn(|k| {
        (1.0 - f) * (1.0 - g) * f64::from(a[k]) + f * (1.0 - g) * f64::from(b[k]) + (1.0 - f) * g * f64::from(c[k]) + f * g * f64::from(d[k])
    })
}

/// The texture's bilinear value (RGBA) at texture coordinates `uv`.
pub fn bilinear(t: Texels, uv: P2) -> [f64; 4] {
    let [x, y] = texel_space(t, uv);
    let (cx, cy) = (x - 0.5, y - 0.5);
    let (i, j) = (cx.floor(), cy.floor());
    bilinear_in(t, i as i64, j as i64, cx - i, cy - j)
}

/// Whether the texel holding `uv` is opaque: its alpha (channel A, which an
/// alpha texture holds its coverage in) is above 0.
pub fn opaque(t: Texels, uv: P2) -> bool {
    let [x, y] = texel_space(t, uv);
    texel(t, x.floor() as i64, y.floor() as i64)[3] > 0.0
}

/// A material's maps that change what a point reflects or whether it
/// exists (the normal map changes directions and is read apart).
#[derive(Clone, Copy, Debug, Default)]
pub struct Maps<'a> {
    /// Diffuse texture: linear reflectance in R, G, B.
    pub diffuse: Option<Texels<'a>>,
    /// Alpha texture: coverage.
    pub alpha: Option<Texels<'a>>,
}

impl Maps<'_> {
    /// Whether neither map is there.
    pub fn is_empty(&self) -> bool {
        self.diffuse.is_none() && self.alpha.is_none()
    }
}

/// A texture average over a triangle's footprint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Average {
    /// Opaque fraction of the area, in [0, 1] (1 without an alpha map):
    /// the `n_o / n_c` of 004 Sec. 4.3.4.
    pub coverage: f64,
    /// Mean reflectance over the opaque part, where a diffuse texture
    /// applies (over the whole footprint if nothing of it is opaque).
    pub reflectance: Option<[f64; 3]>,
}

/// Texture coordinates of the corners of the element with barycentric
/// `corners` in a triangle whose corners have texture coordinates `uv`.
pub fn element_uv(uv: &[[f32; 2]; 3], corners: &Corners) -> [P2; 3] {
    corners.map(|[a, b]| std::array::from_fn(|k| (1.0 - a - b) * f64::from(uv[0][k]) + a * f64::from(uv[1][k]) + b * f64::from(uv[2][k])))
}

/// Twice the signed area of a polygon.
fn twice_area(p: &[P2]) -> f64 {
    (0..p.len()).map(|k| {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        a[0] * b[1] - b[0] * a[1]
    }).sum()
}

/// The part of convex polygon `p` where `sign (p[axis] - at) >= 0`.
fn clip(p: &[P2], axis: usize, at: f64, sign: f64) -> Vec<P2> {
    let mut out = Vec::with_capacity(p.len() + 2);
    for k in 0..p.len() {
        let (a, b) = (p[k], p[(k + 1) % p.len()]);
        let (da, db) = (sign * (a[axis] - at), sign * (b[axis] - at));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let s = da / (da - db);
            out.push([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]);
        }
    }
    out
}

/// Calls `f(i, j, piece)` for each non-empty piece of convex polygon `p`
/// in the unit cell `[i, i + 1) x [j, j + 1)`.
fn for_each_cell(p: &[P2], mut f: impl FnMut(i64, i64, &[P2])) {
    let lo = |k: usize| p.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min).floor() as i64;
    let hi = |k: usize| p.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max).ceil() as i64;
    for i in lo(0)..hi(0) {
        let column = clip(&clip(p, 0, i as f64, 1.0), 0, (i + 1) as f64, -1.0);
        if column.len() < 3 {
            continue;
        }
        for j in lo(1)..hi(1) {
            let piece = clip(&clip(&column, 1, j as f64, 1.0), 1, (j + 1) as f64, -1.0);
            if piece.len() >= 3 {
                f(i, j, &piece);
            }
        }
    }
}

/// Grid cells the bounding box of `p` spans.
fn cells(p: &[P2]) -> f64 {
    let span = |k: usize| {
        let (lo, hi) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| (lo.min(q[k]), hi.max(q[k])));
        hi.floor() - lo.floor() + 1.0
    };
    span(0) * span(1)
}

/// `integral f dA` over convex polygon `p` by the edge-midpoint rule on a
/// fan (exact for quadratics, module docs).
fn integrate<const N: usize>(p: &[P2], f: impl Fn(P2) -> [f64; N]) -> [f64; N] {
    let mid = |a: P2, b: P2| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let mut sum = [0.0; N];
    for k in 1..p.len() - 1 {
        let (a, b, c) = (p[0], p[k], p[k + 1]);
        let w = (0.5 * twice_area(&[a, b, c])).abs() / 3.0;
        for m in [mid(a, b), mid(b, c), mid(c, a)] {
            let v = f(m);
            for n in 0..N {
                sum[n] += w * v[n];
            }
        }
    }
    sum
}

/// `(integral rho dA, area)` of the diffuse texture over convex polygon
/// `uv` in texture coordinates, the area in texel units (exact, module
/// docs).
fn reflectance_integral(t: Texels, uv: &[P2]) -> ([f64; 3], f64) {
    // Texel space shifted by half a texel: the grid of texel centres.
    let p: Vec<P2> = uv.iter().map(|&q| texel_space(t, q)).map(|[x, y]| [x - 0.5, y - 0.5]).collect();
    let mut sum = [0.0; 3];
    for_each_cell(&p, |i, j, piece| {
        let v = integrate(piece, |[x, y]| {
            let rgba = bilinear_in(t, i, j, x - i as f64, y - j as f64);
            [rgba[0], rgba[1], rgba[2]]
        });
        (0..3).for_each(|c| sum[c] += v[c]);
    });
    (sum, 0.5 * twice_area(&p).abs())
}

/// The average over the triangle with corner texture coordinates `uv`
/// (module docs: exact, or the centroid rule past [`MAX_CELLS`]).
pub fn average(maps: Maps, uv: [P2; 3]) -> Average {
    let per_texel = |t: Texels| f64::from(t.scale[0] * t.scale[1]).abs() * (t.width * t.height) as f64;
    let texels = |t: Texels| uv.map(|q| texel_space(t, q));
    let flat = |t: Texels| twice_area(&texels(t)).abs() <= 1e-12 * per_texel(t).max(1.0) || per_texel(t) == 0.0;
    let too_many = |t: Texels| cells(&texels(t)) > MAX_CELLS;
    let all = [maps.diffuse, maps.alpha];
    if all.iter().flatten().any(|t| flat(*t)) {
        return at_point(maps, centroid(&uv));
    }
    if all.iter().flatten().any(|t| too_many(*t)) {
        return centroid_rule(maps, uv);
    }
    let reflectance = |uv: &[P2]| maps.diffuse.map(|t| reflectance_integral(t, uv));
    let Some(alpha) = maps.alpha else {
        let reflectance = reflectance(&uv).map(|(sum, area)| sum.map(|s| s / area));
        return Average { coverage: 1.0, reflectance };
    };
    // Opaque pieces, in texture coordinates, and their area in alpha texels.
    let (mut opaque_area, mut sum, mut diffuse_area) = (0.0, [0.0; 3], 0.0);
    let p = texels(alpha);
    for_each_cell(&p, |i, j, piece| {
        if texel(alpha, i, j)[3] > 0.0 {
            opaque_area += 0.5 * twice_area(piece).abs();
            if let Some((s, a)) = reflectance(&piece.iter().map(|&q| texture_space(alpha, q)).collect::<Vec<_>>()) {
                (0..3).for_each(|c| sum[c] += s[c]);
                diffuse_area += a;
            }
        }
    });
    let coverage = (opaque_area / (0.5 * twice_area(&p).abs())).min(1.0);
    let reflectance = if diffuse_area > 0.0 { Some(sum.map(|s| s / diffuse_area)) } else { reflectance(&uv).map(|(sum, area)| sum.map(|s| s / area)) };
    Average { coverage, reflectance }
}

/// The opaque part of the triangle with corner texture coordinates `uv`
/// under alpha texture `t`, as convex polygons in texture coordinates: per
/// texel row, one polygon per run of consecutive opaque texels. `None`
/// where the footprint spans more than `limit` texels or has no area.
pub fn opaque_pieces(t: Texels, uv: [P2; 3], limit: usize) -> Option<Vec<Vec<P2>>> {
    let p = uv.map(|q| texel_space(t, q));
    if cells(&p) > limit as f64 || twice_area(&p).abs() <= 1e-12 || t.scale.contains(&0.0) {
        return None;
    }
    let mut pieces = Vec::new();
    let (lo, hi) = p.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| (lo.min(q[1]), hi.max(q[1])));
    for j in lo.floor() as i64..hi.ceil() as i64 {
        let row = clip(&clip(&p, 1, j as f64, 1.0), 1, (j + 1) as f64, -1.0);
        if row.len() < 3 {
            continue;
        }
        let (x0, x1) = row.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| (lo.min(q[0]), hi.max(q[0])));
        let (first, last) = (x0.floor() as i64, x1.ceil() as i64);
        let mut i = first;
        while i < last {
            if texel(t, i, j)[3] <= 0.0 {
                i += 1;
                continue;
            }
            let start = i;
            while i < last && texel(t, i, j)[3] > 0.0 {
                i += 1;
            }
            let run = clip(&clip(&row, 0, start as f64, 1.0), 0, i as f64, -1.0);
            if run.len() >= 3 {
                pieces.push(run.iter().map(|&q| texture_space(t, q)).collect());
            }
        }
    }
    Some(pieces)
}

fn centroid(uv: &[P2; 3]) -> P2 {
    std::array::from_fn(|k| (uv[0][k] + uv[1][k] + uv[2][k]) / 3.0)
}

/// The lookups at one point, as an average.
fn at_point(maps: Maps, uv: P2) -> Average {
    let rgb = |t: Texels| {
        let v = bilinear(t, uv);
        [v[0], v[1], v[2]]
    };
    Average { coverage: maps.alpha.map_or(1.0, |t| f64::from(u8::from(opaque(t, uv)))), reflectance: maps.diffuse.map(rgb) }
}

/// The centroid rule on `4^FALLBACK_LEVELS` equal sub-triangles (module
/// docs); the reflectance over the opaque centroids.
fn centroid_rule(maps: Maps, uv: [P2; 3]) -> Average {
    let mut parts: Vec<Corners> = vec![uv];
    for _ in 0..FALLBACK_LEVELS {
        parts = parts.iter().flat_map(children).collect();
    }
    let points: Vec<Average> = parts.iter().map(|p| at_point(maps, centroid(p))).collect();
    let opaque = points.iter().filter(|a| a.coverage > 0.0).count();
    let mean_over = |keep: &dyn Fn(&Average) -> bool| {
        let chosen: Vec<[f64; 3]> = points.iter().filter(|a| keep(a)).filter_map(|a| a.reflectance).collect();
        (!chosen.is_empty()).then(|| std::array::from_fn(|c| chosen.iter().map(|r| r[c]).sum::<f64>() / chosen.len() as f64))
    };
    let reflectance = if opaque > 0 { mean_over(&|a| a.coverage > 0.0) } else { mean_over(&|_| true) };
    Average { coverage: opaque as f64 / points.len() as f64, reflectance }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w x h` texture whose texel `(i, j)` is `value(i, j)` in every
    /// channel.
    fn texture(w: usize, h: usize, value: impl Fn(usize, usize) -> f32) -> TexelGrid<Vec<[f32; 4]>> {
        let texels = (0..w * h).map(|k| [value(k % w, k / w); 4]).collect();
        TexelGrid { width: w, height: h, texels, scale: [1.0, 1.0], offset: [0.0, 0.0], clamp: false }
    }

    /// 2 x 2 checks of `n x n` texels each: 0.25 at top left and bottom
    /// right, 0.625 elsewhere (exact in f32).
    fn checks(n: usize) -> TexelGrid<Vec<[f32; 4]>> {
        texture(2 * n, 2 * n, |i, j| if (i / n + j / n).is_multiple_of(2) { 0.25 } else { 0.625 })
    }

    #[test]
    fn bilinear_hits_texel_centres_and_interpolates_between_them() {
        let t = texture(4, 2, |i, j| (i + 10 * j) as f32);
        // Texel (1, 0), top row, centre (1.5, 0.5) -> uv (1.5/4, 1 - 0.5/2).
        assert!((bilinear(t.view(), [0.375, 0.75])[0] - 1.0).abs() < 1e-12);
        // Halfway between the centres of (1, 0) and (2, 1): mean of 1, 2, 11, 12.
        assert!((bilinear(t.view(), [0.5, 0.5])[0] - 6.5).abs() < 1e-12);
        // Repeat: u = 1 is between texels 3 and 0 (3 and 0 -> 1.5 in row 0).
        assert!((bilinear(t.view(), [1.0, 0.75])[0] - 1.5).abs() < 1e-12);
        // Clamp: past the edge, the edge texel.
        let clamped = TexelGrid { clamp: true, ..t.clone() };
        assert!((bilinear(clamped.view(), [1.3, 0.75])[0] - 3.0).abs() < 1e-12);
        // Scale and offset: s = 2 u + 0.125 maps u = 0.125 to s = 0.375.
        let moved = TexelGrid { scale: [2.0, 1.0], offset: [0.125, 0.0], ..t };
        assert!((bilinear(moved.view(), [0.125, 0.75])[0] - 1.0).abs() < 1e-12);
    }

    /// The unit square of texture coordinates as two triangles:
    /// coverage, and reflectance over the opaque part.
    fn square(maps: Maps) -> (f64, f64) {
        let halves = [average(maps, [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), average(maps, [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]])];
        let coverage = 0.5 * (halves[0].coverage + halves[1].coverage);
        let rho = halves.iter().map(|h| h.coverage * h.reflectance.map_or(0.0, |r| r[0])).sum::<f64>() / (2.0 * coverage);
        (coverage, rho)
    }

    #[test]
    fn a_checkerboard_averages_to_the_fractions_of_its_checks_a_triangle_covers() {
        let t = TexelGrid { clamp: true, ..checks(8) };
        let maps = Maps { diffuse: Some(t.view()), alpha: None };
        // The triangle (0,0), (1,0), (0,1) covers all of the bottom-left
        // check (0.625, area 1/4) and half of the bottom-right and top-left
        // ones (0.25, 1/8 each). Bilinear blurs each check edge over a
        // texel, antisymmetrically about the edge, so the blur adds
        // nothing where the triangle holds both sides of an edge; at the
        // centre, where the hypotenuse cuts the 2 x 2 blurred texels
        // diagonally, the bilinear 0.4375 - 1.5 a b is symmetric in (a, b)
        // and its half-cell integral is the checks' either way; clamped
        // edges do not blur.
        let half = average(maps, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]).reflectance.unwrap()[0];
        let expected = (0.25 * 0.625 + 0.125 * 0.25 + 0.125 * 0.25) / 0.5;
        assert!((half - expected).abs() < 1e-12, "{half} vs {expected}");
        // The whole square, repeating: each texel's tent integrates to one
        // texel over a period, so the mean of the checks, 0.4375.
        let repeating = checks(8);
        let (_, mean) = square(Maps { diffuse: Some(repeating.view()), alpha: None });
        assert!((mean - 0.4375).abs() < 1e-12, "{mean}");
        // Inside one check, a texel away from its edges: its value.
        let inside = average(maps, [[0.1, 0.1], [0.4, 0.1], [0.1, 0.4]]).reflectance.unwrap()[0];
        assert!((inside - 0.625).abs() < 1e-12, "{inside}");
    }

    #[test]
    fn the_average_of_a_bilinear_ramp_is_its_value_at_the_centroid() {
        // Texel i has value i: between centres the bilinear lookup is the
        // linear ramp x - 1/2, whose mean over a triangle is its value at
        // the centroid (a closed form independent of the clipping).
        let t = TexelGrid { clamp: true, ..texture(64, 4, |i, _| i as f32) };
        let maps = Maps { diffuse: Some(t.view()), alpha: None };
        let tri = [[0.11, 0.2], [0.83, 0.35], [0.4, 0.9]];
        let got = average(maps, tri).reflectance.unwrap()[0];
        let expected = (tri[0][0] + tri[1][0] + tri[2][0]) / 3.0 * 64.0 - 0.5;
        assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
    }

    #[test]
    fn alpha_stripes_cover_the_fraction_of_their_opaque_texels_and_the_reflectance_counts_only_them() {
        // Columns alternate opaque, transparent: half of the square.
        let alpha = texture(8, 1, |i, _| if i % 2 == 0 { 1.0 } else { 0.0 });
        let maps = Maps { diffuse: None, alpha: Some(alpha.view()) };
        assert!((square(maps).0 - 0.5).abs() < 1e-12);
        // A triangle over the first stripe only: all opaque.
        assert!((average(maps, [[0.01, 0.0], [0.12, 0.0], [0.05, 1.0]]).coverage - 1.0).abs() < 1e-12);
        // The triangle (0,0), (1,0), (0,1): stripe k, u in [k/8, (k+1)/8),
        // holds the area integral of (1 - u) du there; opaque stripes k even.
        let expected: f64 = (0..8)
            .step_by(2)
            .map(|k| {
                let (a, b) = (k as f64 / 8.0, (k + 1) as f64 / 8.0);
                (b - a) - 0.5 * (b * b - a * a)
            })
            .sum::<f64>()
            / 0.5;
        let lower = average(maps, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert!((lower.coverage - expected).abs() < 1e-12, "{lower:?} vs {expected}");
        // A diffuse texture in the same stripes (0.75 opaque, 0.125
        // transparent, 32 texels a stripe): over the opaque part, the
        // opaque stripes' mean. Bilinear ramps from 0.4375 at a stripe's
        // edge to 0.75 half a texel in, at each of its two edges.
        let diffuse = texture(8 * 32, 1, |i, _| if (i / 32) % 2 == 0 { 0.75 } else { 0.125 });
        let (coverage, rho) = square(Maps { diffuse: Some(diffuse.view()), alpha: Some(alpha.view()) });
        let blurred = (31.0 * 0.75 + (0.4375 + 0.75) / 2.0) / 32.0;
        assert!((rho - blurred).abs() < 1e-9, "{rho} vs {blurred}");
        assert!((coverage - 0.5).abs() < 1e-12);
    }

    #[test]
    fn opaque_pieces_are_the_runs_of_opaque_texels_and_cover_what_the_average_says() {
        let alpha = texture(8, 2, |i, j| if i % 4 < 2 || j == 0 { 1.0 } else { 0.0 });
        let tri = [[0.05, 0.1], [0.95, 0.2], [0.4, 0.9]];
        let pieces = opaque_pieces(alpha.view(), tri, 1000).unwrap();
        let area: f64 = pieces.iter().map(|p| 0.5 * twice_area(p).abs()).sum();
        let coverage = average(Maps { diffuse: None, alpha: Some(alpha.view()) }, tri).coverage;
        assert!((area / (0.5 * twice_area(&tri).abs()) - coverage).abs() < 1e-12);
        // The top row is one run, the bottom row's runs are columns 0-1
        // and 4-5 (the triangle reaches column 1 and 4 at least).
        assert_eq!(pieces.len(), 3, "{pieces:?}");
        assert!(opaque_pieces(alpha.view(), tri, 4).is_none());
    }

    #[test]
    fn element_averages_of_the_four_children_average_to_the_parent() {
        let t = checks(5);
        let alpha = texture(7, 3, |i, j| ((i * 3 + j) % 4 != 0) as u8 as f32);
        let maps = Maps { diffuse: Some(t.view()), alpha: Some(alpha.view()) };
        let uv = [[0.1f32, 0.05], [0.9, 0.2], [0.3, 0.95]];
        let parent = average(maps, element_uv(&uv, &crate::subdivision::ROOT));
        let kids: Vec<Average> = children(&crate::subdivision::ROOT).iter().map(|c| average(maps, element_uv(&uv, c))).collect();
        let coverage = kids.iter().map(|k| k.coverage).sum::<f64>() / 4.0;
        assert!((coverage - parent.coverage).abs() < 1e-12);
        // The reflectance over the opaque part: weighted by coverage.
        let rho = kids.iter().map(|k| k.coverage * k.reflectance.unwrap()[0]).sum::<f64>() / (4.0 * coverage);
        assert!((rho - parent.reflectance.unwrap()[0]).abs() < 1e-12);
    }

    #[test]
    fn large_and_flat_footprints_fall_back_to_point_rules() {
        let t = checks(8);
        let maps = Maps { diffuse: Some(t.view()), alpha: None };
        // 200 repeats each way: far past MAX_CELLS; the mean is 0.4375 up
        // to the centroid rule's sampling of the checks.
        let big = average(maps, [[0.0, 0.0], [200.0, 0.0], [200.0, 200.0]]).reflectance.unwrap()[0];
        assert!((big - 0.4375).abs() < 0.02, "{big}");
        // All corners at one coordinate: the texel there.
        let flat = average(maps, [[0.1, 0.1]; 3]).reflectance.unwrap()[0];
        assert!((flat - 0.625).abs() < 1e-12, "{flat}");
    }
}
