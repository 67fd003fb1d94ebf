//! Photometric files: EULUMDAT ([`ldt`]) and IESNA LM-63 ([`ies`], type C),
//! read and validated completely here, the one door through which they
//! enter the pipeline. Each becomes a full-sphere table in candela
//! ([`radiometry::photometry::Distribution`]) that the manifest carries
//! ([`schemas::mesh::GoniometricLight`]); no later stage opens the file.
//!
//! No parser crate is used: the well-known one for EULUMDAT is AGPL-3.0,
//! which this MIT/Apache project cannot depend on. Both parsers are small,
//! read numbers token by token with the file's line numbers, and every
//! error is one line naming the file, the line and the field.
//!
//! What is refused: a count (C-planes, gammas, lamp sets, angles) out of
//! range or inconsistent with the symmetry; numbers left over after the
//! intensity table (an `Ng` that says 3 where the file has 37 gammas
//! leaves the rest of the table unread); a non-number or non-finite
//! number in any numeric field; an intensity that is negative or not
//! finite once multiplied by the file's own factors (EULUMDAT's lamp flux
//! and conversion factor, IES's candela multiplier and ballast factor: a
//! `1e308` candela value overflows there); angles not strictly increasing
//! or outside 0..180 (gamma) and 0..360 (C); an illegal symmetry flag.

pub mod ies;
pub mod ldt;

use crate::text::TextSource;
use glam::DVec3;
use radiometry::geometry::frame_with_normal;
use radiometry::photometry::{Distribution, K_M};
use schemas::mesh::GoniometricLight;
use schemas::Error;
use std::path::Path;

/// Where a scene places a goniometric light: the `Goniometric` entry's
/// fields.
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// Photometric file, relative to the scene file's folder.
    pub file: String,
    /// Position, world frame, m.
    pub position: [f64; 3],
    /// Direction the luminaire's nadir (gamma = 0) points to.
    pub nadir: [f64; 3],
    /// Direction of the C = 0 half-plane, if the scene gives one.
    pub c0: Option<[f64; 3]>,
    /// Multiplier on the file's intensities.
    pub scale: f64,
}

fn err(path: &Path, line: usize, message: impl Into<String>) -> Error {
    Error::parse(path, Some(line), message)
}

/// A numeric field of `text` (the decimal comma of some EULUMDAT writers
/// read as a point), finite.
fn number(path: &Path, line: usize, what: &str, text: &str) -> Result<f64, Error> {
    let t = text.trim();
    t.replace(',', ".").parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| err(path, line, format!("{what}: '{t}' is not a finite number")))
}

/// A count read as a number: a whole number in `range`.
fn count(path: &Path, line: usize, what: &str, value: f64, range: std::ops::RangeInclusive<usize>) -> Result<usize, Error> {
    if value.fract() == 0.0 && value >= *range.start() as f64 && value <= *range.end() as f64 {
        Ok(value as usize)
    } else {
        Err(err(path, line, format!("{what} = {value} (expected a whole number from {} to {})", range.start(), range.end())))
    }
}

/// `value x factor`, an absolute intensity in cd: refused unless finite
/// and non-negative.
fn scaled(path: &Path, line: usize, what: &str, value: f64, factor: f64) -> Result<f64, Error> {
    let v = value * factor;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(err(path, line, format!("{what}: {} x {} = {} cd is not a finite non-negative intensity", short(value), short(factor), short(v))))
    }
}

/// A number as a message shows it: in exponent form when very large or
/// small, so `1e308` does not print as 309 digits.
fn short(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The fields of a photometric file in order, each with its 1-based line:
/// EULUMDAT has one field per line, IES one per whitespace-separated token
/// after `TILT=`.
struct Fields<'a> {
    path: &'a Path,
    items: Vec<(usize, &'a str)>,
    next: usize,
    /// Line an error at the end of the file names.
    last_line: usize,
}

impl<'a> Fields<'a> {
    fn new(path: &'a Path, items: Vec<(usize, &'a str)>, last_line: usize) -> Self {
        Fields { path, items, next: 0, last_line: last_line.max(1) }
    }

    /// The next field as text.
    fn text(&mut self, what: &str) -> Result<(usize, &'a str), Error> {
        let found = self.items.get(self.next).copied().ok_or_else(|| err(self.path, self.last_line, format!("file ends before {what}")))?;
        self.next += 1;
        Ok(found)
    }

    fn number(&mut self, what: &str) -> Result<(usize, f64), Error> {
        let (n, text) = self.text(what)?;
        Ok((n, number(self.path, n, what, text)?))
    }

    fn count(&mut self, what: &str, range: std::ops::RangeInclusive<usize>) -> Result<(usize, usize), Error> {
        let (n, v) = self.number(what)?;
        Ok((n, count(self.path, n, what, v, range)?))
    }

    fn numbers(&mut self, k: usize, what: &str) -> Result<Vec<(usize, f64)>, Error> {
        (0..k).map(|_| self.number(what)).collect()
    }

    /// `k` intensities, each times `factor` ([`scaled`]).
    fn intensities(&mut self, k: usize, what: &str, factor: f64) -> Result<Vec<f64>, Error> {
        self.numbers(k, what)?.into_iter().map(|(n, v)| scaled(self.path, n, what, v, factor)).collect()
    }

    /// The fields not read yet, not counting empty ones; error if any is
    /// left: `counts` says which counts the data then contradicts.
    fn finish(&self, counts: &str) -> Result<(), Error> {
        let left: Vec<&(usize, &str)> = self.items[self.next.min(self.items.len())..].iter().filter(|(_, t)| !t.trim().is_empty()).collect();
        match left.first() {
            Some(&&(n, _)) => Err(err(self.path, n, format!("{} fields left over after the intensity table: {counts} do not match the data", left.len()))),
            None => Ok(()),
        }
    }
}

/// The full-sphere table, or the table error at `line` (the line of the
/// counts the angles were read with).
fn full_sphere(path: &Path, line: usize, c: Vec<f64>, gamma: Vec<f64>, planes: Vec<Vec<f64>>) -> Result<Distribution, Error> {
    Distribution::full_sphere(c, gamma, planes).map_err(|m| err(path, line, m))
}

/// Reads `.ldt` or `.ies` by extension (case-insensitive).
pub fn parse(path: &Path, text: &str) -> Result<Distribution, Error> {
    match path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).as_deref() {
        Some("ldt") | Some("eul") => ldt::parse(path, text),
        Some("ies") => ies::parse(path, text),
        _ => Err(Error::invalid(path, None, "unknown photometric file type (expected .ldt or .ies)")),
    }
}

/// A scene's `Goniometric` light `k` as manifest data, position still in
/// the world frame: reads `file` (relative to the scene file's folder)
/// through `source` (which records it
/// as an input), validates the placement (`scale` finite and > 0,
/// `position` finite, `nadir` finite and non-zero: errors name the scene
/// file and the field) and the file (errors name it and its line), and
/// records the C0 direction the solvers use: the scene's `c0` made
/// perpendicular to the nadir, or, where the scene gives none, the
/// mesh-frame x axis made perpendicular to it ([`frame_with_normal`]).
/// An IES file's `TILT=INCLUDE` factors are not applied (they scale the
/// output of a luminaire aimed away from its measured orientation): that
/// gets a line in `warnings`.
pub fn read_light(source: &dyn TextSource, scene_path: &Path, k: usize, light: &Placement, warnings: &mut Vec<String>) -> Result<GoniometricLight, Error> {
    let Placement { file, position, nadir, c0, scale } = light;
    let (position, nadir, scale) = (*position, *nadir, *scale);
    let field = |name: &str, message: String| Error::invalid(scene_path, None, format!("lights[{k}] (Goniometric '{file}'): {name}: {message}"));
    if !(scale.is_finite() && scale > 0.0) {
        return Err(field("scale", format!("{scale} must be finite and > 0")));
    }
    if !position.iter().all(|x| x.is_finite()) {
        return Err(field("position", format!("{position:?} must be finite")));
    }
    let n0 = DVec3::from(nadir);
    let n0 = n0.is_finite().then(|| n0.try_normalize()).flatten().ok_or_else(|| field("nadir", format!("{nadir:?} must be finite and non-zero")))?;
    let path = scene_path.parent().unwrap_or(Path::new("")).join(file);
    if !source.exists(&path) {
        return Err(field("file", format!("photometric file '{}' does not exist", path.display())));
    }
    let text = source.read(&path)?;
    let distribution = parse(&path, &text)?;
    let flux_lm = scale * distribution.flux();
    if !(flux_lm.is_finite() && (scale * distribution.i_max() / K_M).is_finite()) {
        return Err(field("scale", format!("{scale} x the table of '{}' overflows", path.display())));
    }
    let c0 = match c0 {
        None => frame_with_normal(n0)[0],
        Some(c) => {
            let c = DVec3::from(*c);
            let across = c - c.dot(n0) * n0;
            across.try_normalize().filter(|_| c.is_finite() && across.length() > 1e-6 * c.length()).ok_or_else(|| {
                field("c0", format!("{:?} must be finite and not parallel to the nadir {nadir:?}", c.to_array()))
            })?
        }
    };
    if text.lines().any(|l| l.trim_start().starts_with("TILT=INCLUDE")) {
        warnings.push(format!("{}: TILT=INCLUDE: the tilt factors are not applied; the luminaire emits as measured, untilted", path.display()));
    }
    Ok(GoniometricLight {
        label: file.to_string(),
        position,
        nadir: n0.to_array(),
        c0: c0.to_array(),
        scale,
        c_angles_deg: distribution.c_angles,
        gamma_angles_deg: distribution.gamma_angles,
        intensity_cd: distribution.intensity,
        flux_lm,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::path::PathBuf;

    /// A photometric test file of `tests/data/photometry` (see its NOTICE.md).
    pub(crate) fn data(name: &str) -> (PathBuf, String) {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/photometry").join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        (path, text)
    }

    /// The luminous flux integrated from each table with the solvers'
    /// interpolation, against the flux Photometric Toolbox computed for
    /// the same files (`tests/data/photometry/NOTICE.md`).
    #[test]
    fn flux_matches_photometric_toolbox_within_half_a_percent() {
        for (file, published) in [("echowuzangye_2.IES", 5834.2), ("echowuzangye_3.IES", 13359.57), ("echowuzangye_7.IES", 531.98)] {
            let (path, text) = data(file);
            let flux = parse(&path, &text).unwrap().flux();
            let error = flux / published - 1.0;
            eprintln!("{file}: {flux:.2} lm vs {published} lm published: {:+.3}%", 100.0 * error);
            assert!(error.abs() < 5e-3, "{file}: {flux} lm vs {published} lm");
        }
    }

    /// The message of parsing `text` as `name`, which must fail.
    fn refused(name: &str, text: &str) -> String {
        parse(Path::new(name), text).unwrap_err().to_string()
    }

    #[test]
    fn ldt_errors_name_the_file_line_and_field() {
        let (_, text) = data("lidrs_example_prolicht_E30-0019.ldt");
        let lines: Vec<&str> = text.lines().collect();
        let with = |n: usize, value: &str| {
            let mut l = lines.clone();
            l[n - 1] = value;
            l.join("\n")
        };
        // Ng says 3 instead of 37: the rest of the table is left over.
        let m = refused("a.ldt", &with(6, "3"));
        assert!(m.starts_with("a.ldt:") && m.contains("left over") && m.contains("Ng"), "{m}");
        let m = refused("a.ldt", &with(4, "many"));
        assert!(m.starts_with("a.ldt:4:") && m.contains("Mc"), "{m}");
        let m = refused("a.ldt", &with(3, "7"));
        assert!(m.starts_with("a.ldt:3:") && m.contains("Isym"), "{m}");
        // Mc says 21 instead of 20: the file ends before the table does.
        let m = refused("a.ldt", &with(4, "21"));
        assert!(m.starts_with("a.ldt:") && m.contains("file ends before luminous intensity"), "{m}");
        // An intensity of 1e308 overflows once scaled by the lamp flux.
        let last = lines.len();
        let m = refused("a.ldt", &with(last, "1e308"));
        assert!(m.starts_with(&format!("a.ldt:{last}:")) && m.contains("luminous intensity"), "{m}");
        let m = refused("a.ldt", &with(last, "-1"));
        assert!(m.starts_with(&format!("a.ldt:{last}:")) && m.contains("non-negative"), "{m}");
        let m = refused("a.ldt", &with(last, "nan"));
        assert!(m.starts_with(&format!("a.ldt:{last}:")) && m.contains("finite"), "{m}");
        let m = refused("a.ldt", &with(24, "0"));
        assert!(m.starts_with("a.ldt:24:") && m.contains("conversion factor"), "{m}");
        let m = refused("a.ldt", &format!("{}\n12.5\n", text.trim_end()));
        assert!(m.starts_with(&format!("a.ldt:{}:", last + 1)) && m.contains("left over"), "{m}");
        let short: String = lines[..50].join("\n");
        let m = refused("a.ldt", &short);
        assert!(m.starts_with("a.ldt:") && m.contains("file ends"), "{m}");
        assert_eq!(m.lines().count(), 1, "{m}");
    }

    #[test]
    fn ies_errors_name_the_file_line_and_field() {
        let m = refused("x.ies", "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 2 1 2\n");
        assert!(m.starts_with("x.ies:3:") && m.contains("type C"), "{m}");
        let (_, text) = data("echowuzangye_7.IES");
        let m = refused("x.ies", &format!("{text}\n7\n"));
        assert!(m.starts_with("x.ies:") && m.contains("left over"), "{m}");
        let m = refused("x.ies", &text.replacen("24 -1 1 37", "24 -1 1e308 37", 1));
        assert!(m.contains("candela value") && m.contains("finite"), "{m}");
        let m = refused("x.ies", &text.replacen("24 -1 1 37", "24 -1 1 36", 1));
        assert!(m.contains("left over") || m.contains("vertical"), "{m}");
        let m = refused("x.ies", "IESNA:LM-63-2002\nno tilt here\n");
        assert!(m.starts_with("x.ies:1:") && m.contains("TILT"), "{m}");
        let m = refused("x.txt", "");
        assert!(m.starts_with("x.txt:") && m.contains("photometric file type"), "{m}");
    }
}
