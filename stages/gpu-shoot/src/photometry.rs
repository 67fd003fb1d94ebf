//! Goniometric light distributions: EULUMDAT (.ldt) and IESNA LM-63 (.ies,
//! type C) files, their expansion to a full sphere of C-planes, the light
//! distribution "texture" normalised by `I_max` (paper 004 Sec. 2.3.2,
//! 3.4) and its lookup with bicubic Catmull-Rom interpolation (3.4.1).
//!
//! No parser crate is used: the well-known one for EULUMDAT is AGPL-3.0,
//! which this MIT/Apache project cannot depend on. Both parsers are small,
//! read numbers token by token with the file's line numbers, and every
//! error names the file and the line.
//!
//! # Angles
//!
//! Type C photometry: `gamma` is the angle from the luminaire's nadir
//! (0 = straight down the nadir axis, 180 = straight up), `C` the azimuth
//! of the half-plane containing the direction, measured from the `C0`
//! reference direction `r0` towards `u0 = n0 x r0` (004 Eq. 3.2-3.3: `t =
//! phi / 2 pi` on the `u0 . d > 0` side, `1 - phi / 2 pi` on the other, that
//! is the azimuth in `[0, 2 pi)`).
//!
//! # Units
//!
//! The files hold luminous intensity (cd; EULUMDAT as cd per 1000 lm of
//! lamp flux). The radiosity solver works in radiometric units; following
//! 004 Eq. 2.12 (a monochromatic 555 nm source, `I_e = I_v / 683`), the
//! radiant intensity is `I_e = scale x I_v / 683` W/sr, the same in R, G, B.

use std::path::Path;

/// Luminous efficacy of 555 nm radiation, lm/W (004 Eq. 2.11-2.12).
pub const K_M: f64 = 683.0;

/// A light distribution on a full sphere: intensities at every
/// `(C, gamma)` of a grid, cd.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution {
    /// C angles, degrees, increasing, in `[0, 360)`; the grid wraps from the
    /// last back to the first (+360).
    pub c_angles: Vec<f64>,
    /// Gamma angles, degrees, increasing, from 0 to 180 (missing ends are
    /// filled with zero intensity, as a luminaire that emits nothing there).
    pub gamma_angles: Vec<f64>,
    /// Absolute intensity, cd, `[c][gamma]`.
    pub intensity: Vec<Vec<f64>>,
}

fn err(path: &Path, line: usize, message: impl Into<String>) -> schemas::Error {
    schemas::Error::parse(path, Some(line), message)
}

/// Lines with their 1-based numbers.
struct Lines<'a> {
    path: &'a Path,
    lines: Vec<(usize, &'a str)>,
    next: usize,
}

impl<'a> Lines<'a> {
    fn new(path: &'a Path, text: &'a str) -> Self {
        Lines { path, lines: text.lines().enumerate().map(|(i, l)| (i + 1, l.trim_end_matches('\r'))).collect(), next: 0 }
    }
    fn line(&mut self, what: &str) -> schemas::Result<(usize, &'a str)> {
        let found = self.lines.get(self.next).copied();
        self.next += 1;
        found.ok_or_else(|| err(self.path, self.lines.len().max(1), format!("file ends before {what}")))
    }
    fn number(&mut self, what: &str) -> schemas::Result<(usize, f64)> {
        let (n, text) = self.line(what)?;
        let t = text.trim().replace(',', ".");
        t.parse::<f64>().ok().filter(|v| v.is_finite()).map(|v| (n, v)).ok_or_else(|| err(self.path, n, format!("{what}: '{}' is not a number", text.trim())))
    }
    fn integer(&mut self, what: &str) -> schemas::Result<(usize, i64)> {
        let (n, v) = self.number(what)?;
        if v.fract() != 0.0 {
            return Err(err(self.path, n, format!("{what}: {v} is not a whole number")));
        }
        Ok((n, v as i64))
    }
}

/// Reads an EULUMDAT file. Intensities (cd/klm) are converted to cd with
/// the lamp flux of all lamp sets (`|lamps| x flux` is the set's total
/// flux in the format) times the conversion factor of line 24.
pub fn parse_ldt(path: &Path, text: &str) -> schemas::Result<Distribution> {
    let mut l = Lines::new(path, text);
    l.line("company")?;
    l.integer("Ityp")?;
    let (isym_line, isym) = l.integer("Isym")?;
    let (mc_line, mc) = l.integer("Mc (number of C-planes)")?;
    l.number("Dc")?;
    let (ng_line, ng) = l.integer("Ng (intensities per C-plane)")?;
    l.number("Dg")?;
    for what in ["report number", "luminaire name", "luminaire number", "file name", "date/user"] {
        l.line(what)?;
    }
    for what in ["length", "width", "height", "luminous length", "luminous width", "height C0", "height C90", "height C180", "height C270", "DFF", "LORL"] {
        l.number(what)?;
    }
    let (_, conversion) = l.number("conversion factor")?;
    l.number("tilt")?;
    let (sets_line, sets) = l.integer("number of lamp sets")?;
    if !(1..=20).contains(&sets) {
        return Err(err(path, sets_line, format!("{sets} lamp sets (expected 1 to 20)")));
    }
    if !(1..=721).contains(&mc) {
        return Err(err(path, mc_line, format!("Mc = {mc} C-planes (expected 1 to 721)")));
    }
    if !(2..=721).contains(&ng) {
        return Err(err(path, ng_line, format!("Ng = {ng} intensities per plane (expected 2 to 721)")));
    }
    let mut flux = 0.0;
    for _ in 0..sets {
        l.number("number of lamps")?;
        l.line("lamp type")?;
        flux += l.number("total luminous flux of lamps")?.1;
        l.line("colour temperature")?;
        l.line("colour rendering")?;
        l.number("wattage")?;
    }
    for _ in 0..10 {
        l.number("direct ratio")?;
    }
    let (mc, ng) = (mc as usize, ng as usize);
    let c_all: Vec<f64> = (0..mc).map(|_| l.number("C angle").map(|x| x.1)).collect::<schemas::Result<_>>()?;
    let gamma: Vec<f64> = (0..ng).map(|_| l.number("gamma angle").map(|x| x.1)).collect::<schemas::Result<_>>()?;
    // Which C-planes the file stores, by symmetry (EULUMDAT spec, Isym).
    let stored: Vec<usize> = match isym {
        0 => (0..mc).collect(),
        1 => vec![0],
        2 => (0..=mc / 2).collect(),
        3 => (mc / 4..=3 * mc / 4).collect(),
        4 => (0..=mc / 4).collect(),
        _ => return Err(err(path, isym_line, format!("Isym = {isym} (expected 0 to 4)"))),
    };
    let scale = flux / 1000.0 * conversion;
    let mut planes = Vec::with_capacity(stored.len());
    for _ in &stored {
        let plane: Vec<f64> = (0..ng).map(|_| l.number("intensity").map(|x| x.1 * scale)).collect::<schemas::Result<_>>()?;
        planes.push(plane);
    }
    check_increasing(path, ng_line, &gamma, "gamma angles")?;
    check_increasing(path, mc_line, &c_all, "C angles")?;
    // The full set of C-planes, each taken from its stored mirror image.
    let find = |c: f64| -> Option<usize> { stored.iter().position(|&k| (c_all[k] - c).abs() < 1e-6) };
    let mut intensity = Vec::with_capacity(mc);
    for &c in &c_all {
        let mirror = match isym {
            0 => Some(c),
            1 => Some(c_all[0]),
            2 => Some(if c <= 180.0 { c } else { 360.0 - c }),
            3 => Some(if (90.0..=270.0).contains(&c) { c } else if c < 90.0 { 180.0 - c } else { 540.0 - c }),
            _ => Some(if c <= 90.0 { c } else if c <= 180.0 { 180.0 - c } else if c <= 270.0 { c - 180.0 } else { 360.0 - c }),
        };
        let k = mirror.and_then(find).ok_or_else(|| err(path, isym_line, format!("C-plane {c} has no stored mirror plane under Isym {isym}")))?;
        intensity.push(planes[stored.iter().position(|&s| s == k).expect("found among stored")].clone());
    }
    full_sphere(path, ng_line, c_all, gamma, intensity)
}

fn check_increasing(path: &Path, line: usize, v: &[f64], what: &str) -> schemas::Result<()> {
    if v.windows(2).any(|w| w[1] <= w[0]) {
        return Err(err(path, line, format!("{what} are not strictly increasing")));
    }
    Ok(())
}

/// Completes a distribution to gamma in [0, 180] (zero where not measured)
/// and checks C angles lie in [0, 360).
fn full_sphere(path: &Path, line: usize, c: Vec<f64>, mut gamma: Vec<f64>, mut intensity: Vec<Vec<f64>>) -> schemas::Result<Distribution> {
    if gamma.first().is_some_and(|&g| g < 0.0) || gamma.last().is_some_and(|&g| g > 180.0) {
        return Err(err(path, line, "gamma angles outside 0..180 degrees"));
    }
    if c.first().is_some_and(|&x| x < 0.0) || c.last().is_some_and(|&x| x >= 360.0 + 1e-9) {
        return Err(err(path, line, "C angles outside 0..360 degrees"));
    }
    if gamma[0] > 0.0 {
        gamma.insert(0, 0.0);
        intensity.iter_mut().for_each(|p| p.insert(0, 0.0));
    }
    if *gamma.last().expect("non-empty") < 180.0 {
        gamma.push(180.0);
        intensity.iter_mut().for_each(|p| p.push(0.0));
    }
    let (mut c, mut intensity) = (c, intensity);
    if c.len() > 1 && (c[c.len() - 1] - 360.0).abs() < 1e-9 {
        c.pop();
        intensity.pop();
    }
    if intensity.iter().flatten().any(|&v| v < 0.0) {
        return Err(err(path, line, "negative intensity"));
    }
    Ok(Distribution { c_angles: c, gamma_angles: gamma, intensity })
}

/// Reads an IESNA LM-63 file (1995 or 2002 keywords; photometric type C
/// only). `TILT=INCLUDE` data are read past; the tilt factors are not
/// applied (our lights are placed untilted). Absolute intensity = candela
/// value x multiplier x ballast factor.
pub fn parse_ies(path: &Path, text: &str) -> schemas::Result<Distribution> {
    let lines: Vec<(usize, &str)> = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim_end_matches('\r'))).collect();
    let tilt = lines.iter().position(|(_, l)| l.trim_start().starts_with("TILT=")).ok_or_else(|| err(path, 1, "no TILT= line"))?;
    let tilt_kind = lines[tilt].1.trim()[5..].trim().to_string();
    // Every later field is whitespace-separated numbers across lines.
    let mut tokens = lines[tilt + 1..].iter().flat_map(|&(n, l)| l.split_whitespace().map(move |t| (n, t)));
    let last_line = lines.last().map(|l| l.0).unwrap_or(1);
    let mut number = |what: &str| -> schemas::Result<(usize, f64)> {
        let (n, t) = tokens.next().ok_or_else(|| err(path, last_line, format!("file ends before {what}")))?;
        t.replace(',', ".").parse::<f64>().ok().filter(|v| v.is_finite()).map(|v| (n, v)).ok_or_else(|| err(path, n, format!("{what}: '{t}' is not a number")))
    };
    if tilt_kind == "INCLUDE" {
        number("lamp-to-luminaire geometry")?;
        let (n, pairs) = number("number of tilt angles")?;
        if !(0.0..=1000.0).contains(&pairs) || pairs.fract() != 0.0 {
            return Err(err(path, n, format!("{pairs} tilt angles")));
        }
        for _ in 0..2 * pairs as usize {
            number("tilt data")?;
        }
    } else if tilt_kind != "NONE" {
        return Err(err(path, lines[tilt].0, format!("TILT={tilt_kind}: only NONE and INCLUDE are read (a tilt file is not)")));
    }
    number("number of lamps")?;
    number("lumens per lamp")?;
    let (_, multiplier) = number("candela multiplier")?;
    let (nv_line, nv) = number("number of vertical angles")?;
    let (nh_line, nh) = number("number of horizontal angles")?;
    let (pt_line, photometric_type) = number("photometric type")?;
    if photometric_type != 1.0 {
        return Err(err(path, pt_line, format!("photometric type {photometric_type}: only type C (1) is read")));
    }
    for what in ["units type", "width", "length", "height"] {
        number(what)?;
    }
    let (_, ballast) = number("ballast factor")?;
    number("future use / ballast-lamp photometric factor")?;
    number("input watts")?;
    let count = |v: f64, line: usize, what: &str| -> schemas::Result<usize> {
        if v >= 1.0 && v <= 1441.0 && v.fract() == 0.0 {
            Ok(v as usize)
        } else {
            Err(err(path, line, format!("{v} {what}")))
        }
    };
    let (nv, nh) = (count(nv, nv_line, "vertical angles")?, count(nh, nh_line, "horizontal angles")?);
    let vertical: Vec<f64> = (0..nv).map(|_| number("vertical angle").map(|x| x.1)).collect::<schemas::Result<_>>()?;
    let horizontal: Vec<f64> = (0..nh).map(|_| number("horizontal angle").map(|x| x.1)).collect::<schemas::Result<_>>()?;
    let scale = multiplier * ballast;
    let mut planes = Vec::with_capacity(nh);
    for _ in 0..nh {
        planes.push((0..nv).map(|_| number("candela value").map(|x| x.1 * scale)).collect::<schemas::Result<Vec<f64>>>()?);
    }
    check_increasing(path, nv_line, &vertical, "vertical angles")?;
    check_increasing(path, nh_line, &horizontal, "horizontal angles")?;
    // Horizontal symmetry (LM-63 type C): last angle 0 (axial), 90
    // (quadrant), 180 (bilateral) or 360 (none); 90..270 is bilateral about
    // the 90-270 plane.
    let (h0, h1) = (horizontal[0], horizontal[nh - 1]);
    let (c, intensity): (Vec<f64>, Vec<Vec<f64>>) = if nh == 1 {
        (vec![0.0], planes)
    } else if h0 == 0.0 && h1 == 90.0 {
        mirror(&horizontal, &planes, &[(180.0, -1.0), (180.0, 1.0), (360.0, -1.0)])
    } else if h0 == 0.0 && h1 == 180.0 {
        mirror(&horizontal, &planes, &[(360.0, -1.0)])
    } else if h0 == 90.0 && h1 == 270.0 {
        let (mut c, mut i) = (Vec::new(), Vec::new());
        for (k, &h) in horizontal.iter().enumerate() {
            c.push(h);
            i.push(planes[k].clone());
        }
        for (k, &h) in horizontal.iter().enumerate() {
            let m = (540.0 - h) % 360.0;
            if !c.iter().any(|&x| (x - m).abs() < 1e-9) {
                c.push(m);
                i.push(planes[k].clone());
            }
        }
        sort_planes(c, i)
    } else if h0 == 0.0 && h1 == 360.0 {
        (horizontal.clone(), planes)
    } else {
        return Err(err(path, nh_line, format!("horizontal angles {h0}..{h1}: expected 0, 0..90, 0..180, 90..270 or 0..360")));
    };
    full_sphere(path, nv_line, c, vertical, intensity)
}

/// The planes plus their mirror images `a + s h` for each `(a, s)`.
fn mirror(h: &[f64], planes: &[Vec<f64>], images: &[(f64, f64)]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let (mut c, mut i): (Vec<f64>, Vec<Vec<f64>>) = (h.to_vec(), planes.to_vec());
    for &(a, s) in images {
        for (k, &x) in h.iter().enumerate() {
            let m = a + s * x;
            if (0.0..=360.0).contains(&m) && !c.iter().any(|&y| (y - m).abs() < 1e-9) {
                c.push(m);
                i.push(planes[k].clone());
            }
        }
    }
    sort_planes(c, i)
}

fn sort_planes(c: Vec<f64>, i: Vec<Vec<f64>>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let mut both: Vec<(f64, Vec<f64>)> = c.into_iter().zip(i).collect();
    both.sort_by(|a, b| a.0.total_cmp(&b.0));
    both.into_iter().unzip()
}

/// Reads `.ldt` or `.ies` by extension (case-insensitive).
pub fn parse(path: &Path, text: &str) -> schemas::Result<Distribution> {
    match path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).as_deref() {
        Some("ldt") | Some("eul") => parse_ldt(path, text),
        Some("ies") => parse_ies(path, text),
        _ => Err(schemas::Error::invalid(path, None, "unknown photometric file type (expected .ldt or .ies)")),
    }
}

/// Catmull-Rom interpolation of `p1 .. p2` at `t` in [0, 1] with the outer
/// neighbours `p0`, `p3` (004 Sec. 3.4.1: an interpolating cubic, so the
/// measured values are reproduced exactly at the measured angles).
pub fn catmull_rom(p0: f64, p1: f64, p2: f64, p3: f64, t: f64) -> f64 {
    let t2 = t * t;
    let t3 = t2 * t;
    0.5 * (2.0 * p1 + (p2 - p0) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2 + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

/// The interval `[i, i+1]` of `angles` holding `x` and the fraction within.
fn interval(angles: &[f64], x: f64) -> (usize, f64) {
    let n = angles.len();
    if n == 1 || x <= angles[0] {
        return (0, 0.0);
    }
    let k = angles.partition_point(|&a| a <= x).min(n - 1).max(1) - 1;
    let t = ((x - angles[k]) / (angles[k + 1] - angles[k])).clamp(0.0, 1.0);
    (k, t)
}

/// The light distribution texture (004 Sec. 2.3.2): intensities divided by
/// `I_max`, laid out as in the file's grid, flattened for the GPU.
#[derive(Clone, Debug, PartialEq)]
pub struct Ldt {
    /// Largest intensity, cd.
    pub i_max: f64,
    /// C angles, degrees.
    pub c_angles: Vec<f64>,
    /// Gamma angles, degrees.
    pub gamma_angles: Vec<f64>,
    /// Normalised intensity in [0, 1], `[c * gamma_count + gamma]`.
    pub values: Vec<f64>,
}

impl Ldt {
    /// Normalises `d` by its largest intensity.
    pub fn new(d: &Distribution) -> Self {
        let i_max = d.intensity.iter().flatten().fold(0.0f64, |a, &b| a.max(b));
        let norm = if i_max > 0.0 { i_max } else { 1.0 };
        Ldt {
            i_max,
            c_angles: d.c_angles.clone(),
            gamma_angles: d.gamma_angles.clone(),
            values: d.intensity.iter().flatten().map(|v| v / norm).collect(),
        }
    }

    /// Normalised intensity at `(c, gamma)` degrees, bicubic Catmull-Rom
    /// over the grid's indices: along gamma with clamped ends, along C
    /// periodically (C wraps at 360). Between measured angles of uneven
    /// spacing the spline runs in index space (as a texture would). Never
    /// negative: the cubic's overshoot below zero is clamped.
    pub fn lookup(&self, c: f64, gamma: f64) -> f64 {
        let ng = self.gamma_angles.len();
        let nc = self.c_angles.len();
        let (gi, gt) = interval(&self.gamma_angles, gamma);
        let row = |ci: usize| -> f64 {
            let at = |k: isize| self.values[ci * ng + k.clamp(0, ng as isize - 1) as usize];
            let k = gi as isize;
            catmull_rom(at(k - 1), at(k), at(k + 1), at(k + 2), gt)
        };
        if nc == 1 {
            return row(0).max(0.0);
        }
        let c = c.rem_euclid(360.0);
        // Periodic C grid: append the first angle + 360.
        let mut angles = self.c_angles.clone();
        angles.push(self.c_angles[0] + 360.0);
        let c = if c < self.c_angles[0] { c + 360.0 } else { c };
        let (ci, ct) = interval(&angles, c);
        let wrap = |k: isize| k.rem_euclid(nc as isize) as usize;
        let k = ci as isize;
        catmull_rom(row(wrap(k - 1)), row(wrap(k)), row(wrap(k + 1)), row(wrap(k + 2)), ct).max(0.0)
    }

    /// Total flux of the distribution scaled by `i_max`, in the file's
    /// units x sr (lm for cd): `integral I dOmega` by the midpoint rule on
    /// a 0.5 degree grid.
    pub fn flux(&self) -> f64 {
        let (ng, nc) = (360, 720);
        let (dg, dc) = (180.0 / ng as f64, 360.0 / nc as f64);
        let mut sum = 0.0;
        for g in 0..ng {
            let gamma = (g as f64 + 0.5) * dg;
            let mut ring = 0.0;
            for c in 0..nc {
                ring += self.lookup((c as f64 + 0.5) * dc, gamma);
            }
            sum += ring * gamma.to_radians().sin();
        }
        sum * dg.to_radians() * dc.to_radians() * self.i_max
    }
}

/// The angles `(C, gamma)` in degrees of direction `d` (unit, from the
/// light) in the light's frame `(n0 nadir, r0 C0 direction, u0 = n0 x r0)`:
/// `gamma = acos(n0 . d)` (004 Eq. 3.1), `C` the azimuth from `r0` towards
/// `u0` (Eq. 3.2-3.3).
pub fn angles(d: [f64; 3], n0: [f64; 3], r0: [f64; 3], u0: [f64; 3]) -> (f64, f64) {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let gamma = dot(d, n0).clamp(-1.0, 1.0).acos().to_degrees();
    let c = dot(d, u0).atan2(dot(d, r0)).to_degrees().rem_euclid(360.0);
    (c, gamma)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(name: &str) -> (std::path::PathBuf, String) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        (path, text)
    }

    #[test]
    fn catmull_rom_interpolates_and_reproduces_lines() {
        assert_eq!(catmull_rom(1.0, 2.0, 5.0, 3.0, 0.0), 2.0);
        assert_eq!(catmull_rom(1.0, 2.0, 5.0, 3.0, 1.0), 5.0);
        // A straight line stays a straight line.
        assert!((catmull_rom(1.0, 2.0, 3.0, 4.0, 0.25) - 2.25).abs() < 1e-12);
        // Hand computation: t = 0.5 -> (-p0 + 9 p1 + 9 p2 - p3) / 16.
        assert!((catmull_rom(1.0, 2.0, 5.0, 3.0, 0.5) - (-1.0 + 18.0 + 45.0 - 3.0) / 16.0).abs() < 1e-12);
    }

    #[test]
    fn asymmetric_ldt_reproduces_its_table_at_measured_angles() {
        let (path, text) = data("lidrs_example_prolicht_E30-0019.ldt");
        let d = parse_ldt(&path, &text).unwrap();
        let ldt = Ldt::new(&d);
        // Isym 0: all 20 C-planes of 18 degrees, 37 gammas of 5 degrees.
        assert_eq!(d.c_angles.len(), 20);
        assert_eq!(d.gamma_angles.len(), 37);
        // The file's raw table, cd/klm x flux/1000 x conversion: read
        // independently of the parser from the tail of the file.
        let raw: Vec<f64> = text.lines().rev().take(20 * 37).map(|l| l.trim().parse::<f64>().unwrap()).collect::<Vec<_>>().into_iter().rev().collect();
        let flux = 5134.0; // line 29: total luminous flux of the lamp set
        for (c, &ca) in d.c_angles.iter().enumerate() {
            for (g, &ga) in d.gamma_angles.iter().enumerate() {
                let expected = raw[c * 37 + g] * flux / 1000.0;
                assert!((d.intensity[c][g] - expected).abs() < 1e-9, "C{ca} g{ga}");
                let looked = ldt.lookup(ca, ga) * ldt.i_max;
                assert!((looked - expected).abs() < 1e-9 * ldt.i_max, "lookup C{ca} g{ga}: {looked} vs {expected}");
            }
        }
        // Between measured angles: the Catmull-Rom value of the neighbours.
        let (c, g) = (3, 10);
        let along_gamma = |ci: usize| catmull_rom(d.intensity[ci][g - 1], d.intensity[ci][g], d.intensity[ci][g + 1], d.intensity[ci][g + 2], 0.5);
        let expected = catmull_rom(along_gamma(c - 1), along_gamma(c), along_gamma(c + 1), along_gamma(c + 2), 0.5);
        let looked = ldt.lookup(0.5 * (d.c_angles[c] + d.c_angles[c + 1]), 0.5 * (d.gamma_angles[g] + d.gamma_angles[g + 1])) * ldt.i_max;
        assert!((looked - expected).abs() < 1e-9 * ldt.i_max, "{looked} vs {expected}");
        assert!(d.intensity[0] != d.intensity[5], "the distribution is asymmetric");
    }

    #[test]
    fn ies_type_c_with_tilt_include_reproduces_its_table() {
        let (path, text) = data("lidrs_iesna2002_example_typec_tilt_include.ies");
        let d = parse_ies(&path, &text).unwrap();
        // 0..90 horizontal -> quadrant symmetry -> C 0..337.5 (8 planes).
        assert_eq!(d.c_angles, vec![0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0]);
        // Vertical 0..90 is completed with zero intensity at 180.
        assert_eq!(d.gamma_angles, vec![0.0, 22.5, 45.0, 67.5, 90.0, 180.0]);
        let ldt = Ldt::new(&d);
        // Multiplier 1, ballast factor 1: the table as written.
        let table = [[100000.0, 50000.0, 25000.0, 10000.0, 5000.0], [100000.0, 35000.0, 16000.0, 8000.0, 3000.0], [100000.0, 20000.0, 10000.0, 5000.0, 1000.0]];
        for (h, c) in [(0usize, 0.0), (1, 45.0), (2, 90.0), (1, 135.0), (0, 180.0), (1, 225.0), (2, 270.0), (1, 315.0)] {
            for (v, g) in [0.0, 22.5, 45.0, 67.5, 90.0].iter().enumerate() {
                assert_eq!(ldt.lookup(c, *g) * ldt.i_max, table[h][v], "C{c} g{g}");
            }
        }
        // Halfway in gamma on C0: Catmull-Rom of 100000, 50000 | 25000, 10000.
        let expected = catmull_rom(100000.0, 50000.0, 25000.0, 10000.0, 0.5);
        assert!((ldt.lookup(0.0, 33.75) * ldt.i_max - expected).abs() < 1e-6);
    }

    #[test]
    fn errors_name_the_file_and_line() {
        let path = Path::new("broken.ldt");
        let (_, text) = data("lidrs_example_prolicht_E30-0019.ldt");
        let broken = text.replacen("\n20\n", "\nmany\n", 1);
        let message = parse_ldt(path, &broken).unwrap_err().to_string();
        assert!(message.starts_with("broken.ldt:4:") && message.contains("Mc"), "{message}");
        let short: String = text.lines().take(50).collect::<Vec<_>>().join("\n");
        let message = parse_ldt(path, &short).unwrap_err().to_string();
        assert!(message.contains("broken.ldt:") && message.contains("file ends"), "{message}");
        let message = parse_ies(Path::new("x.ies"), "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 2 1 2\n").unwrap_err().to_string();
        assert!(message.starts_with("x.ies:3:") && message.contains("type C"), "{message}");
    }

    #[test]
    fn constant_distribution_has_flux_4_pi_i() {
        let d = Distribution { c_angles: vec![0.0], gamma_angles: vec![0.0, 90.0, 180.0], intensity: vec![vec![7.0; 3]] };
        let ldt = Ldt::new(&d);
        assert!((ldt.flux() - 4.0 * std::f64::consts::PI * 7.0).abs() < 1e-3 * ldt.flux());
        let (c, g) = angles([0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!((c - 90.0).abs() < 1e-12 && (g - 90.0).abs() < 1e-12);
    }
}
