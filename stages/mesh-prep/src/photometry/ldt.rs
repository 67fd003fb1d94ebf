//! EULUMDAT (`.ldt`): one field per line, in the order of the format's
//! definition (Stockmar 1990; the field names below are the format's).
//! Intensities are given in cd per 1000 lm of lamp flux; the absolute
//! intensity is `value x (sum of the lamp sets' flux) / 1000 x conversion
//! factor` (line 24).

use super::{err, full_sphere, Fields};
use radiometry::photometry::Distribution;
use schemas::Error;
use std::path::Path;

/// Reads an EULUMDAT file into a full-sphere table, cd.
pub fn parse(path: &Path, text: &str) -> Result<Distribution, Error> {
    let lines: Vec<(usize, &str)> = text.lines().enumerate().map(|(i, s)| (i + 1, s.trim_end_matches('\r'))).collect();
    let last = lines.len();
    let mut l = Fields::new(path, lines, last);
    l.text("company identification")?;
    l.count("Ityp (type indicator)", 0..=3)?;
    let (isym_line, isym) = l.count("Isym (symmetry indicator)", 0..=4)?;
    let (mc_line, mc) = l.count("Mc (number of C-planes)", 1..=721)?;
    l.number("Dc (distance between C-planes)")?;
    let (_, ng) = l.count("Ng (intensities per C-plane)", 2..=721)?;
    l.number("Dg (distance between gamma angles)")?;
    for what in ["measurement report number", "luminaire name", "luminaire number", "file name", "date/user"] {
        l.text(what)?;
    }
    for what in ["length of luminaire", "width of luminaire", "height of luminaire", "length of luminous area", "width of luminous area", "height of luminous area C0", "height of luminous area C90", "height of luminous area C180", "height of luminous area C270", "DFF (downward flux fraction)", "LORL (light output ratio)"] {
        l.number(what)?;
    }
    let (conversion_line, conversion) = l.number("conversion factor for luminous intensities")?;
    l.number("tilt of luminaire during measurement")?;
    let (_, sets) = l.count("n (number of standard sets of lamps)", 1..=20)?;
    let mut flux = 0.0;
    for _ in 0..sets {
        l.number("number of lamps")?;
        l.text("type of lamps")?;
        flux += l.number("total luminous flux of lamps")?.1;
        l.text("colour appearance / colour temperature of lamps")?;
        l.text("colour rendering group / index")?;
        l.number("wattage including ballast")?;
    }
    l.numbers(10, "direct ratios for room indices")?;
    // Which C-planes the file stores, by symmetry (the format's Isym), and
    // the count each symmetry needs to split the circle evenly.
    let stored: Vec<usize> = match isym {
        0 => (0..mc).collect(),
        1 => vec![0],
        2 => (0..=mc / 2).collect(),
        3 => (mc / 4..=3 * mc / 4).collect(),
        _ => (0..=mc / 4).collect(),
    };
    let divisor = [1, 1, 2, 4, 4][isym];
    if mc % divisor != 0 {
        return Err(err(path, mc_line, format!("Mc = {mc} C-planes cannot be split by Isym {isym} (it needs a multiple of {divisor})")));
    }
    let factor = flux / 1000.0 * conversion;
    if !(factor.is_finite() && factor > 0.0) {
        return Err(err(path, conversion_line, format!("lamp flux {flux} lm / 1000 x conversion factor {conversion} = {factor} must be finite and > 0")));
    }
    let c_all: Vec<f64> = l.numbers(mc, "C angle")?.into_iter().map(|x| x.1).collect();
    let gamma: Vec<f64> = l.numbers(ng, "gamma angle")?.into_iter().map(|x| x.1).collect();
    let mut planes = Vec::with_capacity(stored.len());
    for _ in &stored {
        planes.push(l.intensities(ng, "luminous intensity", factor)?);
    }
    l.finish(&format!("Mc ({mc}), Ng ({ng}) or Isym ({isym})"))?;
    // The full set of C-planes, each taken from its stored mirror image.
    let find = |c: f64| stored.iter().position(|&k| (c_all[k] - c).abs() < 1e-6);
    let mut intensity = Vec::with_capacity(mc);
    for &c in &c_all {
        let mirror = match isym {
            0 => c,
            1 => c_all[0],
            2 => if c <= 180.0 { c } else { 360.0 - c },
            3 => if (90.0..=270.0).contains(&c) { c } else if c < 90.0 { 180.0 - c } else { 540.0 - c },
            _ => if c <= 90.0 { c } else if c <= 180.0 { 180.0 - c } else if c <= 270.0 { c - 180.0 } else { 360.0 - c },
        };
        let k = find(mirror).ok_or_else(|| err(path, isym_line, format!("C-plane {c} has no stored mirror plane under Isym {isym}")))?;
        intensity.push(planes[k].clone());
    }
    full_sphere(path, mc_line, c_all, gamma, intensity)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photometry::tests::data;
    use radiometry::photometry::catmull_rom;

    #[test]
    fn asymmetric_ldt_reproduces_its_table_at_measured_angles() {
        let (path, text) = data("lidrs_example_prolicht_E30-0019.ldt");
        let d = parse(&path, &text).unwrap();
        // Isym 0: all 20 C-planes of 18 degrees, 37 gammas of 5 degrees.
        assert_eq!((d.c_angles.len(), d.gamma_angles.len()), (20, 37));
        // The file's raw table, cd/klm x flux/1000 x conversion: read
        // independently of the parser from the tail of the file.
        let raw: Vec<f64> = text.lines().rev().take(20 * 37).map(|l| l.trim().parse::<f64>().unwrap()).collect::<Vec<_>>().into_iter().rev().collect();
        let flux = 5134.0; // line 29: total luminous flux of the lamp set
        let at = |c: usize, g: usize| d.intensity[c * 37 + g];
        for (c, &ca) in d.c_angles.iter().enumerate() {
            for (g, &ga) in d.gamma_angles.iter().enumerate() {
                let expected = raw[c * 37 + g] * flux / 1000.0;
                assert!((at(c, g) - expected).abs() < 1e-9, "C{ca} g{ga}");
                assert!((d.lookup(ca, ga) - expected).abs() < 1e-9 * d.i_max(), "lookup C{ca} g{ga}");
            }
        }
        // Between measured angles: the Catmull-Rom value of the neighbours.
        let (c, g) = (3, 10);
        let along_gamma = |ci: usize| catmull_rom(at(ci, g - 1), at(ci, g), at(ci, g + 1), at(ci, g + 2), 0.5);
        let expected = catmull_rom(along_gamma(c - 1), along_gamma(c), along_gamma(c + 1), along_gamma(c + 2), 0.5);
        let looked = d.lookup(0.5 * (d.c_angles[c] + d.c_angles[c + 1]), 0.5 * (d.gamma_angles[g] + d.gamma_angles[g + 1]));
        assert!((looked - expected).abs() < 1e-9 * d.i_max(), "{looked} vs {expected}");
        assert!(at(0, 20) != at(5, 20), "the distribution is asymmetric");
    }
}
