//! Perceptually based mesh splitting (paper 001: "for each mesh vertex we
//! transform the stimulus luminance values to predicted perceived
//! brightness using Stevens' power law, and a decision on the mesh
//! splitting is made based on the local differences in brightness").
//!
//! The paper names the law but neither its exponent nor its adaptation
//! model; we choose Stevens' power law for the brightness of an extended
//! field under a global adaptation:
//!
//! ```text
//! Q(L) = (L / L_a)^a
//! ```
//!
//! `L` the vertex's luminance (direct plus the current stochastic indirect
//! estimate, `Y(B) / pi`), `L_a` the adaptation luminance, taken as the
//! area-weighted mean luminance of the scene's surfaces (an observer
//! adapted to the scene as a whole, as in Tumblin and Rushmeier's 1993 tone
//! reproduction, which is built on the same law), and `a = 1/3`, Stevens'
//! exponent for the brightness of a 5-degree target seen by the
//! dark-adapted eye (S. S. Stevens, "To honor Fechner and repeal his law",
//! Science 133, 1961; J. C. Stevens and S. S. Stevens 1963). `Q` is 1 at
//! the adaptation level and grows compressively, so a step that is
//! conspicuous in a dark corner counts less beside a bright lamp, and the
//! indirect light, which adds to both sides of a shadow edge, makes that
//! edge less conspicuous, as the paper wants.
//!
//! "Local differences in brightness" we take as the difference, at each
//! edge midpoint of a leaf (the vertices a split would make), between the
//! brightness there and the mean of the brightness at that edge's two
//! ends: the brightness error the linear interpolation of the preview
//! (Gouraud over the vertices) makes at that point. A leaf is split when
//! one exceeds a threshold. So a shadow edge across a leaf is split, and
//! a smooth gradient that interpolates well is not, however steep.

use radiometry::color::luminance;

/// Stevens' brightness of luminance `l` under adaptation luminance
/// `adaptation` (module documentation), dimensionless.
pub fn brightness(l: f64, adaptation: f64, exponent: f64) -> f64 {
    if adaptation <= 0.0 {
        return 0.0;
    }
    (l.max(0.0) / adaptation).powf(exponent)
}

/// Luminance of radiosity `b` (W/m² per channel, a Lambertian surface):
/// `Y(B) / pi`, in the units of `b` per steradian.
pub fn surface_luminance(b: [f64; 3]) -> f64 {
    luminance(b) / std::f64::consts::PI
}

/// Whether a leaf whose corners have luminances `corners` and whose edge
/// midpoints (01, 12, 20) have `midpoints` should be split: at some
/// midpoint the brightness departs from its edge's interpolated brightness
/// by more than `threshold` (module documentation).
pub fn should_split(corners: [f64; 3], midpoints: [f64; 3], adaptation: f64, exponent: f64, threshold: f64) -> bool {
    let q = |l: f64| brightness(l, adaptation, exponent);
    [(0, 1), (1, 2), (2, 0)].iter().zip(midpoints).any(|(&(a, b), m)| (q(m) - 0.5 * (q(corners[a]) + q(corners[b]))).abs() > threshold)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brightness_follows_the_cube_root_law_and_adds_indirect_light_to_both_sides() {
        // Eight times the adaptation luminance looks twice as bright.
        assert!((brightness(8.0, 1.0, 1.0 / 3.0) - 2.0).abs() < 1e-12);
        // A 1:2 luminance step at the adaptation level inside edge 01 (the
        // midpoint as bright as corner 1): half of 2^(1/3) - 1 = 0.13.
        assert!(should_split([1.0, 2.0, 1.0], [2.0, 1.5, 1.0], 1.0, 1.0 / 3.0, 0.1));
        // The same direct step on top of indirect light 10 everywhere:
        // (12^(1/3) - 11^(1/3)) / 2 = 0.033, under the threshold.
        assert!(!should_split([11.0, 12.0, 11.0], [12.0, 11.5, 11.0], 1.0, 1.0 / 3.0, 0.1));
        // A linear 1:2 luminance gradient along edge 01 has no step: the
        // cube root bends it by 1.5^(1/3) - (1 + 2^(1/3)) / 2 = 0.015.
        assert!(!should_split([1.0, 2.0, 1.0], [1.5, 1.5, 1.0], 1.0, 1.0 / 3.0, 0.1));
    }
}
