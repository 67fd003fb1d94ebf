//! The threshold model: threshold versus intensity, contrast sensitivity,
//! band-limited contrast and masking.
//!
//! # Threshold versus intensity (Ferwerda et al. 1996)
//!
//! J. A. Ferwerda, S. N. Pattanaik, P. Shirley, D. P. Greenberg, "A model
//! of visual adaptation for realistic image synthesis", SIGGRAPH 1996,
//! Eq. for the cone (photopic) system, luminances in cd/m², logs base 10:
//!
//! ```text
//! log dL = -0.72                                  if log La <= -2.6
//!        = (0.249 log La + 0.65)^2.7 - 0.72       if -2.6 < log La < 1.9
//!        = log La - 1.255                         if log La >= 1.9
//! ```
//!
//! Only the cone branch is used: a display spans about 0.5 to a few
//! hundred cd/m² (photopic and upper mesopic), and the rod branch would
//! need scotopic luminance, which needs the display's spectra.
//!
//! # Masking (Ramasubramanian, Pattanaik, Greenberg 1999)
//!
//! M. Ramasubramanian, S. N. Pattanaik, D. P. Greenberg, "A perceptually
//! based physical error metric for realistic image synthesis", SIGGRAPH
//! 1999 (paper 000's reference [15]). The spatial part of their threshold
//! model, as built here:
//!
//! 1. Band-pass decomposition of the luminance image (a Laplacian stack:
//!    `G_0 = L`, `G_{k+1}` = `G_k` blurred by the binomial kernel
//!    `[1 4 6 4 1]/16` with holes of `2^k` pixels, band `D_k = G_k -
//!    G_{k+1}`).
//! 2. Band-limited contrast (Peli 1990): `C_k = D_k / G_{k+1}`.
//! 3. Contrast sensitivity: `C'_k = |C_k| S(f_k)`, in multiples of the
//!    detection threshold, with the CSF of Movshon and Kiorpes (1988) in
//!    the form Pattanaik et al. (1998) and [15] use,
//!    `S(f) = 75 f^0.8 exp(-0.2 f)` (f in cycles/degree; peak 102 at 4
//!    cycles/degree, where paper 000 Sec. 5.1 puts it).
//! 4. Masking per band (the threshold-elevation function of Ferwerda et
//!    al. 1997, "A model of visual masking for computer graphics", used by
//!    [15]): `T_k = max(1, C'_k^s)`, `s = 0.7`.
//! 5. One elevation per pixel, the bands weighted by their sensitivity:
//!    `T_e = sum_k w_k T_k`, `w_k = S(f_k) / sum_j S(f_j)`. [15] combines
//!    the bands with the normalised CSF; the shadow a final gather adds has
//!    frequencies unknown in advance (000 Sec. 5.2.1), and a weighted mean
//!    lets a band mask in proportion to the eye's sensitivity to it.
//!
//! A uniform field has `C_k = 0` in every band, so `T_e = 1` exactly (up to
//! the rounding of the weights' sum).

/// Threshold versus intensity, cd/m²: the smallest luminance increment
/// visible on a background of adaptation luminance `la` cd/m² (Ferwerda et
/// al. 1996, cone branch; see the module docs).
pub fn tvi(la: f64) -> f64 {
    let log_la = la.max(1e-12).log10();
    let log_dl = if log_la <= -2.6 {
        -0.72
    } else if log_la >= 1.9 {
        log_la - 1.255
    } else {
        (0.249 * log_la + 0.65).powf(2.7) - 0.72
    };
    10f64.powf(log_dl)
}

/// Contrast sensitivity `S(f) = 75 f^0.8 exp(-0.2 f)` at `f` cycles/degree
/// (Movshon and Kiorpes 1988, as used in [15]): the reciprocal of the
/// threshold contrast of a grating.
pub fn contrast_sensitivity(f: f64) -> f64 {
    if f <= 0.0 {
        return 0.0;
    }
    75.0 * f.powf(0.8) * (-0.2 * f).exp()
}

/// Centre frequency of band `k` in cycles/degree at `pixels_per_degree`.
/// Band `k >= 1` lies between blurs of standard deviation `sigma_k ~
/// 2^k / sqrt 3` and `2 sigma_k` pixels; the difference of the two
/// Gaussian transfer functions peaks at `f = sqrt(ln 4 / (6 pi^2)) /
/// sigma_k = 0.265 / 2^k` cycles/pixel. Band 0 (image minus one blur) is a
/// high-pass; its centre is taken as 0.375 cycles/pixel, the middle of
/// [0.25, 0.5].
pub fn band_frequency_cpd(k: usize, pixels_per_degree: f64) -> f64 {
    let cycles_per_pixel = if k == 0 { 0.375 } else { (4f64.ln() / (6.0 * std::f64::consts::PI.powi(2))).sqrt() * 3f64.sqrt() / 2f64.powi(k as i32) };
    cycles_per_pixel * pixels_per_degree
}

/// The Laplacian stack's low-pass levels `G_0 .. G_{depth-1}` of a
/// `width` x `height` image (row-major), edges clamped.
pub fn luminance_pyramid(width: usize, height: usize, image: &[f64], depth: usize) -> Vec<Vec<f64>> {
    const KERNEL: [f64; 5] = [1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0];
    let mut levels = vec![image.to_vec()];
    for k in 0..depth.saturating_sub(1) {
        let step = 1i64 << k;
        let previous = &levels[k];
        let clamp = |v: i64, n: usize| v.clamp(0, n as i64 - 1) as usize;
        let mut rows = vec![0.0; width * height];
        for y in 0..height {
            for x in 0..width {
                rows[y * width + x] = (0..5)
                    .map(|t| KERNEL[t] * previous[y * width + clamp(x as i64 + (t as i64 - 2) * step, width)])
                    .sum();
            }
        }
        let mut next = vec![0.0; width * height];
        for y in 0..height {
            for x in 0..width {
                next[y * width + x] =
                    (0..5).map(|t| KERNEL[t] * rows[clamp(y as i64 + (t as i64 - 2) * step, height) * width + x]).sum();
            }
        }
        levels.push(next);
    }
    levels
}

/// Masking threshold elevation of one pixel from its band contrasts
/// `contrast[k] = C_k` (band-limited contrast of band `k`) at band
/// frequencies `frequency[k]` cycles/degree: `sum_k w_k max(1, (|C_k|
/// S(f_k))^s)` with `w_k = S(f_k) / sum_j S(f_j)` (see the module docs).
pub fn elevation(contrast: &[f64], frequency: &[f64], slope: f64) -> f64 {
    let total: f64 = frequency.iter().map(|&f| contrast_sensitivity(f)).sum();
    if total <= 0.0 {
        return 1.0;
    }
    contrast
        .iter()
        .zip(frequency)
        .map(|(&c, &f)| {
            let s = contrast_sensitivity(f);
            s / total * (c.abs() * s).powf(slope).max(1.0)
        })
        .sum()
}

/// Elevation of every pixel, from the pyramid's first `bands + 1` levels.
pub fn elevation_image(pyramid: &[Vec<f64>], bands: usize, pixels_per_degree: f64, slope: f64) -> Vec<f64> {
    let frequency: Vec<f64> = (0..bands).map(|k| band_frequency_cpd(k, pixels_per_degree)).collect();
    let n = pyramid[0].len();
    let mut contrast = vec![0.0; bands];
    (0..n)
        .map(|i| {
            for (k, c) in contrast.iter_mut().enumerate() {
                let mean = pyramid[k + 1][i];
                *c = if mean > 0.0 { (pyramid[k][i] - mean) / mean } else { 0.0 };
            }
            elevation(&contrast, &frequency, slope)
        })
        .collect()
}
