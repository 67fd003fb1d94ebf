//! Deterministic sampling: a counter-based random source seeded from the
//! identity of the work item (a link's two elements, a pixel), so results do
//! not depend on thread count or scheduling, and stratified points on
//! triangles.

use glam::DVec3;

/// SplitMix64 finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom
/// number generators", OOPSLA 2014): a bijective 64-bit mix.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A small random stream: SplitMix64 over a counter. Good statistical
/// quality for sampling, trivially seeded per work item.
#[derive(Clone, Debug)]
pub struct Stream {
    state: u64,
}

impl Stream {
    /// The stream for work item `(a, b)` under the run's `seed`.
    pub fn new(seed: u64, a: u64, b: u64) -> Self {
        Stream { state: mix64(seed ^ mix64(a.wrapping_add(0x9e37_79b9_7f4a_7c15) ^ mix64(b))) }
    }

    /// Next uniform number in [0, 1).
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Next 64 uniformly random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix64(self.state)
    }

    /// A uniformly random permutation of `0..n` (Fisher-Yates), `n - 1`
    /// numbers of the stream: pairs the `k`-th stratum of one end of a link
    /// with a shuffled stratum of the other (Latin hypercube), so that the
    /// pairs sample the product of the two ends and not its diagonal.
    pub fn permutation(&mut self, n: usize) -> Vec<usize> {
        let mut order: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            let j = (self.next_f64() * (i + 1) as f64) as usize;
            order.swap(i, j.min(i));
        }
        order
    }
}

/// Maps the unit square to barycentric coordinates on a triangle, uniformly
/// by area (Shirley's square-to-triangle map: `b0 = 1 - sqrt(u)`,
/// `b1 = v sqrt(u)`). Points of the open square land strictly inside.
#[inline]
pub fn square_to_triangle(u: f64, v: f64) -> [f64; 3] {
    let su = u.sqrt();
    let b0 = 1.0 - su;
    let b1 = v * su;
    [b0, b1, 1.0 - b0 - b1]
}

/// The point of a triangle, as a world-space point, that
/// [`square_to_triangle`] maps `(u, v)` of the unit square to.
#[inline]
pub fn point_on(corners: &[DVec3; 3], u: f64, v: f64) -> DVec3 {
    let b = square_to_triangle(u, v);
    corners[0] * b[0] + corners[1] * b[1] + corners[2] * b[2]
}

/// The `k`-th of `n` jittered stratified samples on a triangle, as a
/// world-space point: [`Strata::point`] of `Strata::of(n)`.
pub fn stratified_point(corners: &[DVec3; 3], k: usize, n: usize, stream: &mut Stream) -> DVec3 {
    Strata::of(n).point(corners, k, stream)
}

/// A `columns x rows` grid of the unit square ([`strata`]), found once for
/// the many points a caller draws from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Strata {
    columns: usize,
    rows: usize,
}

impl Strata {
    /// The grid of `n` strata ([`strata`]).
    pub fn of(n: usize) -> Self {
        let (columns, rows) = strata(n);
        Strata { columns, rows }
    }

    /// The `k`-th jittered stratified sample on a triangle, as a
    /// world-space point: the grid's `n` cells of equal area are each
    /// visited once by `k` in `0..n`, mapped to the triangle by
    /// [`square_to_triangle`].
    #[inline]
    pub fn point(&self, corners: &[DVec3; 3], k: usize, stream: &mut Stream) -> DVec3 {
        let (i, j) = (k % self.columns, (k / self.columns) % self.rows);
        // Keep the jitter off the stratum border so points stay strictly inside.
        let jitter = |s: &mut Stream| 0.001 + 0.998 * s.next_f64();
        let u = (i as f64 + jitter(stream)) / self.columns as f64;
        let v = (j as f64 + jitter(stream)) / self.rows as f64;
        point_on(corners, u, v)
    }
}

/// The `(columns, rows)` of `n` strata over the unit square: `rows` the
/// largest divisor of `n` not over `sqrt(n)`, so that `columns x rows = n`
/// exactly (`m x m` where `n = m^2`). An `m x m` grid with `m =
/// ceil(sqrt(n))` and `n` not a square leaves cells unvisited: 8 samples
/// covered 8 of 9 cells, one corner of the square never, and a visible
/// fraction estimated from them over-weighted the rest of the element:
/// with a ray count per link that was not always a square, the leaves
/// straddling a solid's footprint read 10.9% dark on average (1.9% with
/// these strata, as with 16 rays on every link).
pub fn strata(n: usize) -> (usize, usize) {
    let n = n.max(1);
    let rows = (1..=n.isqrt()).rev().find(|&r| n.is_multiple_of(r)).unwrap_or(1);
    (n / rows, rows)
}

/// Radical inverse of `k` in base `b` (van der Corput): the digits of `k`
/// in base `b` mirrored about the radix point.
pub fn radical_inverse(mut k: u64, b: u64) -> f64 {
    let (mut inv, mut f) = (0.0, 1.0 / b as f64);
    while k > 0 {
        inv += (k % b) as f64 * f;
        k /= b;
        f /= b as f64;
    }
    inv
}

/// The direction numbers (the generator matrix's columns, as 32-bit
/// fractions) of one dimension of Sobol's sequence, from its primitive
/// polynomial of degree `s` over GF(2), whose inner coefficients are the
/// bits of `a` (highest power first), and its initial odd numbers `m_1..m_s`
/// (`m_k < 2^k`), by Bratley and Fox's recurrence (ACM TOMS 14, 1988):
///
/// ```text
/// m_k = 2 a_1 m_{k-1} ^ 4 a_2 m_{k-2} ^ ... ^ 2^(s-1) a_(s-1) m_(k-s+1) ^ 2^s m_(k-s) ^ m_(k-s),
/// v_k = m_k / 2^k
/// ```
const fn directions(s: usize, a: u32, m: [u32; 3]) -> [u32; 32] {
    let mut mk = [0u32; 33];
    let mut k = 1;
    while k <= 32 {
        if k <= s {
            mk[k] = m[k - 1];
        } else {
            let mut v = mk[k - s] ^ (mk[k - s] << s);
            let mut j = 1;
            while j < s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    v ^= mk[k - j] << j;
                }
                j += 1;
            }
            mk[k] = v;
        }
        k += 1;
    }
    let mut v = [0u32; 32];
    let mut k = 1;
    while k <= 32 {
        v[k - 1] = mk[k] << (32 - k);
        k += 1;
    }
    v
}

/// The direction numbers of Sobol's first four dimensions: van der Corput
/// (the identity matrix), then Joe and Kuo's dimensions 2 to 4 (S. Joe,
/// F. Y. Kuo, "Constructing Sobol sequences with better two-dimensional
/// projections", SIAM J. Sci. Comput. 30, 2008; `new-joe-kuo-6.21201`):
/// `x + 1` with `m = 1`, `x^2 + x + 1` with `m = 1, 3`, and `x^3 + x + 1`
/// with `m = 1, 3, 1`. The second is Pascal's triangle mod 2; dimensions
/// 1-2 and 3-4 are each a (0,2)-sequence.
const SOBOL_DIRECTIONS: [[u32; 32]; 4] = {
    let mut identity = [0u32; 32];
    let mut k = 0;
    while k < 32 {
        identity[k] = 1 << (31 - k);
        k += 1;
    }
    [identity, directions(1, 0, [1, 0, 0]), directions(2, 1, [1, 3, 0]), directions(3, 1, [1, 3, 1])]
};

/// The 32-bit digits of point `k` of Sobol's sequence in its first `D`
/// dimensions (at most 4): the XOR of the direction numbers of the bits
/// set in `k`.
#[inline]
fn sobol_digits<const D: usize>(k: u32) -> [u32; D] {
    let mut digits = [0u32; D];
    let (mut i, mut bit) = (k, 0);
    while i != 0 {
        if i & 1 != 0 {
            for (d, directions) in digits.iter_mut().zip(&SOBOL_DIRECTIONS) {
                *d ^= directions[bit];
            }
        }
        i >>= 1;
        bit += 1;
    }
    digits
}

/// Point `k` of the Sobol (0,2)-sequence as 32-bit fractions, each
/// XOR-shifted by `shift`: van der Corput in base 2 (the bits of `k`
/// reversed), and Sobol's second dimension, whose generator matrix is
/// Pascal's triangle mod 2 (`SOBOL_DIRECTIONS`).
/// Every block of `2^m` consecutive points starting at a multiple of `2^m`
/// is a (0,m,2)-net, and the XOR shift keeps that.
pub fn sobol_02(k: u32, shift: [u32; 2]) -> [f64; 2] {
    let [first, second] = sobol_digits::<2>(k);
    let scale = 1.0 / 4_294_967_296.0;
    [f64::from(first ^ shift[0]) * scale, f64::from(second ^ shift[1]) * scale]
}

/// Owen's nested uniform scrambling of a 32-bit fraction (A. B. Owen,
/// "Randomly permuted (t,m,s)-nets and (t,s)-sequences", 1995): each digit
/// flipped or not by a random function of the digits above it. Hashed
/// after B. Burley, "Practical hash-based Owen scrambling" (JCGT 9(4),
/// 2020): with the bits reversed, Laine and Karras's permutation (EGSR
/// 2011), whose steps (adding the seed, XOR with the value times an even
/// constant) carry each bit's influence only upwards, flips each bit by the
/// bits below it, which are the digits above it once reversed back.
#[inline]
fn owen_scramble(x: u32, seed: u32) -> u32 {
    let mut x = x.reverse_bits().wrapping_add(seed);
    for constant in [0x6c50_b47c_u32, 0xb82f_1e52, 0xc7af_e638, 0x8d22_f6e6] {
        x ^= x.wrapping_mul(constant);
    }
    x.reverse_bits()
}

/// Owen-scrambled points of Sobol's first four dimensions: pairs of
/// points, `(u_0, u_1)` on one triangle and `(u_2, u_3)` on another, for
/// a link's visibility rays. Each point is uniform over the unit 4-cube,
/// so the estimates they make are unbiased; each aligned block of `2^m`
/// points is a (0,m,2)-net in dimensions 1-2 (stratified in every
/// elementary interval of area `2^-m`, not only in a grid of them), and a
/// (t,m,2)-net in dimensions 3-4 and 1-3, with t = 0 for 16 points (a
/// link's usual count) and at most 2 up to 256; any prefix is a
/// low-discrepancy set, so a ray count that is not a power of two keeps
/// most of it. The scrambles are independent per dimension and per link
/// ([`Stream`]).
#[derive(Clone, Copy, Debug)]
pub struct ScrambledSobol {
    /// The four dimensions' scrambling seeds.
    seeds: [u32; 4],
}

impl ScrambledSobol {
    /// A scramble drawn from `stream` (two of its numbers).
    pub fn new(stream: &mut Stream) -> Self {
        let (a, b) = (stream.next_u64(), stream.next_u64());
        ScrambledSobol { seeds: [a as u32, (a >> 32) as u32, b as u32, (b >> 32) as u32] }
    }

    /// Point `k`, each coordinate clamped to `[MARGIN, 1 - MARGIN]`: mapped
    /// by [`square_to_triangle`], a point stays strictly inside its
    /// triangle, off the edge it may share with a solid it touches. The
    /// clamp moves a millionth of the points by under a millionth, and
    /// keeps every net (a squeeze towards the centre would move points
    /// across the cells' borders).
    #[inline]
    pub fn point(&self, k: u32) -> [f64; 4] {
        /// The coordinates' distance from the unit cube's faces.
        const MARGIN: f64 = 1e-6;
        let digits = sobol_digits::<4>(k);
        std::array::from_fn(|d| ((f64::from(owen_scramble(digits[d], self.seeds[d])) + 0.5) / 4_294_967_296.0).clamp(MARGIN, 1.0 - MARGIN))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every count of strata tiles the unit square with `n` cells, each
    /// visited once by `k` in `0..n`; squares keep their `m x m` grid.
    /// Over many streams, 8 points on a triangle average to its centroid
    /// (a 3 x 3 grid with one cell never visited put the mean 0.058 off it,
    /// on a triangle of unit legs).
    #[test]
    fn strata_tile_the_square_and_sample_the_triangle_evenly() {
        for n in 1..=300 {
            let (columns, rows) = strata(n);
            assert_eq!(columns * rows, n, "n = {n}");
            assert!(rows <= columns, "n = {n}");
            let cells: std::collections::HashSet<(usize, usize)> = (0..n).map(|k| (k % columns, (k / columns) % rows)).collect();
            assert_eq!(cells.len(), n, "n = {n}: every cell once");
        }
        assert_eq!(strata(16), (4, 4));
        assert_eq!(strata(256), (16, 16));
        assert_eq!(strata(8), (4, 2));
        let corners = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let (mut sum, runs) = (DVec3::ZERO, 4000);
        for run in 0..runs {
            let mut stream = Stream::new(7, run, 0);
            for k in 0..8 {
                sum += stratified_point(&corners, k, 8, &mut stream);
            }
        }
        let mean = sum / (8 * runs) as f64;
        assert!((mean - DVec3::new(1.0 / 3.0, 1.0 / 3.0, 0.0)).length() < 3e-3, "mean {mean}");
    }

    #[test]
    fn stream_is_uniform_and_reproducible() {
        let mut s = Stream::new(1, 2, 3);
        let xs: Vec<f64> = (0..100_000).map(|_| s.next_f64()).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64;
        assert!((mean - 0.5).abs() < 0.005, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 0.002, "{var}");
        assert!(xs.iter().all(|x| (0.0..1.0).contains(x)));
        let mut again = Stream::new(1, 2, 3);
        assert_eq!(again.next_f64(), xs[0]);
        assert_ne!(Stream::new(1, 3, 2).next_f64(), xs[0]);
    }

    #[test]
    fn square_to_triangle_preserves_area() {
        // The fraction of uniform square samples landing where b0 > 1/2 must
        // be the area fraction of that corner triangle: 1/4.
        let mut s = Stream::new(7, 0, 0);
        let n = 200_000;
        let hits = (0..n).filter(|_| square_to_triangle(s.next_f64(), s.next_f64())[0] > 0.5).count();
        assert!((hits as f64 / n as f64 - 0.25).abs() < 0.004);
    }

    #[test]
    fn radical_inverse_mirrors_the_digits() {
        // 11 = 102 in base 3 -> 0.201 in base 3 = 2/3 + 0/9 + 1/27.
        assert!((radical_inverse(11, 3) - (2.0 / 3.0 + 1.0 / 27.0)).abs() < 1e-15);
        // 6 = 110 in base 2 -> 0.011 = 1/4 + 1/8.
        assert_eq!(radical_inverse(6, 2), 0.375);
        assert_eq!(radical_inverse(0, 5), 0.0);
    }

    /// Whether `points` (in dimensions `a` and `b`, `2^m` of them) is a
    /// (t,m,2)-net: each elementary interval of area `2^(t-m)` holds `2^t`
    /// points.
    fn is_net(points: &[[f64; 4]], a: usize, b: usize, t: u32) -> bool {
        let n = points.len();
        let m = n.trailing_zeros();
        t <= m
            && (0..=m - t).all(|e| {
                let (columns, rows) = (1usize << e, 1usize << (m - t - e));
                let mut count = vec![0; columns * rows];
                for p in points {
                    count[(p[b] * rows as f64) as usize * columns + (p[a] * columns as f64) as usize] += 1;
                }
                count.iter().all(|&c| c == 1 << t)
            })
    }

    /// Sobol's first points in Joe and Kuo's first four dimensions, from
    /// their direction numbers by hand: point 1 is the cube's centre,
    /// point 2 `v_2` and point 3 `v_1 ^ v_2` (`m_2 = 3` in the three
    /// last dimensions), point 4 `v_3` (`m_3 = 5, 3, 1`: 5/8, 3/8, 1/8).
    #[test]
    fn sobol_digits_begin_as_joe_and_kuo_tabulate() {
        let at = |k: u32| sobol_digits::<4>(k).map(|d| f64::from(d) / 4_294_967_296.0);
        assert_eq!(at(0), [0.0; 4]);
        assert_eq!(at(1), [0.5; 4]);
        assert_eq!(at(2), [0.25, 0.75, 0.75, 0.75]);
        assert_eq!(at(3), [0.75, 0.25, 0.25, 0.25]);
        assert_eq!(at(4), [0.125, 0.625, 0.375, 0.125]);
    }

    /// Under any scramble, aligned blocks of `2^m` points are (0,m,2)-nets
    /// in dimensions 1-2 (one end of a link), and (t,m,2)-nets in 3-4 (the
    /// other end) and 1-3 with the t-values of Joe and Kuo's matrices (0
    /// for 16 points, at most 2 up to 256), and each coordinate stays
    /// inside the margin. Scrambling keeps nets; the t-values were found
    /// by this same test on the unscrambled points.
    #[test]
    fn scrambled_sobol_blocks_are_nets_on_each_end() {
        const T_34: [u32; 9] = [0, 0, 1, 2, 0, 1, 1, 1, 1];
        const T_13: [u32; 9] = [0, 0, 0, 1, 0, 1, 1, 1, 1];
        for run in 0..20 {
            let sobol = ScrambledSobol::new(&mut Stream::new(9, run, 0));
            for m in 0..=8u32 {
                let n = 1u32 << m;
                for block in [0, 3] {
                    let points: Vec<[f64; 4]> = (block * n..(block + 1) * n).map(|k| sobol.point(k)).collect();
                    assert!(points.iter().flatten().all(|&u| (1e-6..=1.0 - 1e-6).contains(&u)));
                    for (a, b, t) in [(0, 1, 0), (2, 3, T_34[m as usize]), (0, 2, T_13[m as usize])] {
                        assert!(is_net(&points, a, b, t), "run {run}, 2^{m} points from {}, dimensions {a} and {b}, t {t}", block * n);
                    }
                }
            }
        }
    }

    /// A scrambled point is uniform: over many scrambles, point `k` (any
    /// `k`, the first included) has each coordinate's mean 1/2 and
    /// variance 1/12, falls in each eighth of the unit interval an eighth
    /// of the time, and its coordinates are uncorrelated.
    #[test]
    fn scrambled_sobol_points_are_uniform() {
        let runs = 40_000;
        for k in [0, 1, 5, 13] {
            let points: Vec<[f64; 4]> = (0..runs).map(|run| ScrambledSobol::new(&mut Stream::new(4, run, 7)).point(k)).collect();
            for d in 0..4 {
                let mean = points.iter().map(|p| p[d]).sum::<f64>() / runs as f64;
                let var = points.iter().map(|p| (p[d] - mean).powi(2)).sum::<f64>() / runs as f64;
                assert!((mean - 0.5).abs() < 0.006, "k {k}, dimension {d}: mean {mean}");
                assert!((var - 1.0 / 12.0).abs() < 0.003, "k {k}, dimension {d}: variance {var}");
                let mut eighths = [0usize; 8];
                points.iter().for_each(|p| eighths[(p[d] * 8.0) as usize] += 1);
                assert!(eighths.iter().all(|&c| (c as f64 / runs as f64 - 0.125).abs() < 0.01), "k {k}, dimension {d}: {eighths:?}");
                let e = (d + 1) % 4;
                let covariance = points.iter().map(|p| (p[d] - 0.5) * (p[e] - 0.5)).sum::<f64>() / runs as f64;
                assert!(covariance.abs() < 0.002, "k {k}, dimensions {d} and {e}: covariance {covariance}");
            }
        }
    }

    /// Every aligned block of `2^m` points, under any digital shift, is a
    /// (0,m,2)-net: each elementary interval `[i/2^a, (i+1)/2^a) x
    /// [j/2^(m-a), (j+1)/2^(m-a))` of area `2^-m` holds exactly one point.
    #[test]
    fn aligned_blocks_of_the_shifted_sobol_sequence_are_0_m_2_nets() {
        for shift in [[0, 0], [0x9e37_79b9, 0x7f4a_7c15], [u32::MAX, 1 << 31]] {
            for m in 0..=6u32 {
                let n = 1u32 << m;
                for block in [0, 1, 5] {
                    let points: Vec<[f64; 2]> = (block * n..(block + 1) * n).map(|k| sobol_02(k, shift)).collect();
                    for a in 0..=m {
                        let (cols, rows) = (1u32 << a, 1u32 << (m - a));
                        let mut count = vec![0; n as usize];
                        for p in &points {
                            let (i, j) = ((p[0] * f64::from(cols)) as u32, (p[1] * f64::from(rows)) as u32);
                            count[(j * cols + i) as usize] += 1;
                        }
                        assert!(count.iter().all(|&c| c == 1), "shift {shift:?}, block {block} of {n}, intervals {cols}x{rows}: {count:?}");
                    }
                }
            }
        }
    }
}
