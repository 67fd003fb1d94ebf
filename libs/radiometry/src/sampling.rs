//! Deterministic sampling: a counter-based random source seeded from the
//! identity of the work item (a link's two elements, a pixel), so results do
//! not depend on thread count or scheduling, and stratified points on
//! triangles.

use glam::DVec3;

/// SplitMix64 finaliser (Steele, Lea, Flood, "Fast splittable pseudorandom
/// number generators", OOPSLA 2014): a bijective 64-bit mix.
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
    pub fn next_f64(&mut self) -> f64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        (mix64(self.state) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// Maps the unit square to barycentric coordinates on a triangle, uniformly
/// by area (Shirley's square-to-triangle map: `b0 = 1 - sqrt(u)`,
/// `b1 = v sqrt(u)`). Points of the open square land strictly inside.
pub fn square_to_triangle(u: f64, v: f64) -> [f64; 3] {
    let su = u.sqrt();
    let b0 = 1.0 - su;
    let b1 = v * su;
    [b0, b1, 1.0 - b0 - b1]
}

/// The `k`-th of `n` jittered stratified samples on a triangle (strata are
/// an `m x m` grid of the unit square, `m = ceil(sqrt(n))`, visited in a
/// fixed order), as a world-space point.
pub fn stratified_point(corners: &[DVec3; 3], k: usize, n: usize, stream: &mut Stream) -> DVec3 {
    let m = (n as f64).sqrt().ceil().max(1.0) as usize;
    let (i, j) = (k % m, (k / m) % m);
    // Keep the jitter off the stratum border so points stay strictly inside.
    let jitter = |s: &mut Stream| 0.001 + 0.998 * s.next_f64();
    let u = (i as f64 + jitter(stream)) / m as f64;
    let v = (j as f64 + jitter(stream)) / m as f64;
    let b = square_to_triangle(u, v);
    corners[0] * b[0] + corners[1] * b[1] + corners[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
