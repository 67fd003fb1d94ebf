//! IESNA LM-63 (`.ies`, 1995 and 2002 keywords), photometric type C only.
//! After the keyword lines and `TILT=`, every field is a whitespace
//! separated number, across lines. `TILT=INCLUDE` data are read past; the
//! tilt factors are not applied (lights are placed untilted). Absolute
//! intensity = candela value x candela multiplier x ballast factor.

use super::{err, full_sphere, Fields};
use radiometry::photometry::Distribution;
use schemas::Error;
use std::path::Path;

/// Reads an IES file into a full-sphere table, cd.
pub fn parse(path: &Path, text: &str) -> Result<Distribution, Error> {
    let lines: Vec<(usize, &str)> = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim_end_matches('\r'))).collect();
    let tilt = lines.iter().position(|(_, l)| l.trim_start().starts_with("TILT=")).ok_or_else(|| err(path, 1, "TILT: no 'TILT=' line"))?;
    let tilt_kind = lines[tilt].1.trim().trim_start_matches("TILT=").trim().to_string();
    let tokens = lines[tilt + 1..].iter().flat_map(|&(n, l)| l.split_whitespace().map(move |t| (n, t))).collect();
    let mut t = Fields::new(path, tokens, lines.last().map_or(1, |l| l.0));
    if tilt_kind == "INCLUDE" {
        t.number("lamp-to-luminaire geometry")?;
        let (_, pairs) = t.count("number of tilt angles", 0..=1000)?;
        t.numbers(2 * pairs, "tilt angles and factors")?;
    } else if tilt_kind != "NONE" {
        return Err(err(path, lines[tilt].0, format!("TILT={tilt_kind}: only NONE and INCLUDE are read (a tilt file is not)")));
    }
    t.number("number of lamps")?;
    t.number("lumens per lamp")?;
    let (multiplier_line, multiplier) = t.number("candela multiplier")?;
    let (nv_line, nv) = t.count("number of vertical angles", 1..=1441)?;
    let (nh_line, nh) = t.count("number of horizontal angles", 1..=1441)?;
    let (pt_line, photometric_type) = t.number("photometric type")?;
    if photometric_type != 1.0 {
        return Err(err(path, pt_line, format!("photometric type {photometric_type}: only type C (1) is read")));
    }
    for what in ["units type", "width", "length", "height"] {
        t.number(what)?;
    }
    let (_, ballast) = t.number("ballast factor")?;
    t.number("future use / ballast-lamp photometric factor")?;
    t.number("input watts")?;
    let factor = multiplier * ballast;
    if !(factor.is_finite() && factor > 0.0) {
        return Err(err(path, multiplier_line, format!("candela multiplier {multiplier} x ballast factor {ballast} = {factor} must be finite and > 0")));
    }
    let vertical: Vec<f64> = t.numbers(nv, "vertical angle")?.into_iter().map(|x| x.1).collect();
    let horizontal: Vec<f64> = t.numbers(nh, "horizontal angle")?.into_iter().map(|x| x.1).collect();
    let mut planes = Vec::with_capacity(nh);
    for _ in 0..nh {
        planes.push(t.intensities(nv, "candela value", factor)?);
    }
    t.finish(&format!("the angle counts ({nv} vertical, {nh} horizontal)"))?;
    if nv < 2 {
        return Err(err(path, nv_line, "number of vertical angles = 1: a distribution needs at least 2"));
    }
    if horizontal.windows(2).any(|w| w[1] <= w[0]) {
        return Err(err(path, nh_line, "horizontal angles are not strictly increasing"));
    }
    // Horizontal symmetry (LM-63 type C): last angle 0 (axial), 90
    // (quadrant), 180 (bilateral) or 360 (none); 90..270 is bilateral about
    // the 90-270 plane.
    let (h0, h1) = (horizontal[0], horizontal[nh - 1]);
    let (c, intensity) = if nh == 1 && h0 == 0.0 {
        (vec![0.0], planes)
    } else if h0 == 0.0 && h1 == 90.0 {
        mirror(&horizontal, &planes, &[(180.0, -1.0), (180.0, 1.0), (360.0, -1.0)])
    } else if h0 == 0.0 && h1 == 180.0 {
        mirror(&horizontal, &planes, &[(360.0, -1.0)])
    } else if h0 == 90.0 && h1 == 270.0 {
        mirror(&horizontal, &planes, &[(540.0, -1.0), (180.0, -1.0)])
    } else if h0 == 0.0 && h1 == 360.0 {
        (horizontal, planes)
    } else {
        return Err(err(path, nh_line, format!("horizontal angles {h0}..{h1}: expected 0, 0..90, 0..180, 90..270 or 0..360")));
    };
    full_sphere(path, nv_line, c, vertical, intensity)
}

/// The planes plus their mirror images `a + s h` for each `(a, s)` that
/// fall in `[0, 360]` and are not already there, sorted by angle.
fn mirror(h: &[f64], planes: &[Vec<f64>], images: &[(f64, f64)]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut both: Vec<(f64, Vec<f64>)> = h.iter().copied().zip(planes.iter().cloned()).collect();
    for &(a, s) in images {
        for (k, &x) in h.iter().enumerate() {
            let m = a + s * x;
            if (0.0..=360.0).contains(&m) && !both.iter().any(|(y, _)| (y - m).abs() < 1e-9) {
                both.push((m, planes[k].clone()));
            }
        }
    }
    both.sort_by(|a, b| a.0.total_cmp(&b.0));
    both.into_iter().unzip()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photometry::tests::data;
    use radiometry::photometry::catmull_rom;

    #[test]
    fn ies_type_c_with_tilt_include_reproduces_its_table() {
        let (path, text) = data("lidrs_iesna2002_example_typec_tilt_include.ies");
        let d = parse(&path, &text).unwrap();
        // 0..90 horizontal -> quadrant symmetry -> C 0..337.5 (8 planes).
        assert_eq!(d.c_angles, vec![0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]);
        // Vertical 0..90 is completed with zero intensity one step past
        // the measured range, and at 180.
        assert_eq!(d.gamma_angles, vec![0.0, 22.5, 45.0, 67.5, 90.0, 112.5, 180.0]);
        // Multiplier 1, ballast factor 1: the table as written.
        let table = [[100000.0, 50000.0, 25000.0, 10000.0, 5000.0], [100000.0, 35000.0, 16000.0, 8000.0, 3000.0], [100000.0, 20000.0, 10000.0, 5000.0, 1000.0]];
        for (h, c) in [(0usize, 0.0), (1, 45.0), (2, 90.0), (1, 135.0), (0, 180.0), (1, 225.0), (2, 270.0), (1, 315.0)] {
            for (v, g) in [0.0, 22.5, 45.0, 67.5, 90.0].iter().enumerate() {
                assert_eq!(d.lookup(c, *g), table[h][v], "C{c} g{g}");
            }
        }
        // Halfway in gamma on C0: Catmull-Rom of 100000, 50000 | 25000, 10000.
        let expected = catmull_rom(100000.0, 50000.0, 25000.0, 10000.0, 0.5);
        assert!((d.lookup(0.0, 33.75) - expected).abs() < 1e-6);
    }
}
