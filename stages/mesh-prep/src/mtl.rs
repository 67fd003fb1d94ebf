//! Wavefront MTL material libraries, read by hand: the format is a few
//! statements, and real files use its freedoms (a colour given as one grey
//! value, `Ks 0`; texture options before a file name; names with spaces)
//! that crate parsers reject or panic on. Every error names the file and
//! line.
//!
//! Read statements, in any letter case (others, like `Ka`, `Ns`, `Ni`, are
//! ignored; a `#` ends a line of numbers):
//!
//! | statement | meaning |
//! |---|---|
//! | `newmtl name` | starts a material (the whole rest of the line is the name, `#` included) |
//! | `Kd`, `Ks`, `Ke`, `Tf` | a colour: `r g b`, or one value `g` meaning `g g g` |
//! | `d` | dissolve (opacity), one value (`d -halo f` reads `f`) |
//! | `illum` | illumination model, an integer 0 to 10 |
//! | `map_Kd`, `map_d`, `norm`, `bump`, `map_Bump` | a texture: options (`-o u v w`, `-bm f`, ...), then the file name (the rest of the line) |
//!
//! Texture options kept ([`TextureRef`]): `-s u v` and `-o u v` (the
//! texture coordinates used are `s * uv + o`), `-clamp on|off` (off,
//! the default, repeats), `-bm f` (the bump or normal map's strength) and
//! `-imfchan r|g|b|m|l|z` (the channel a scalar map such as `map_d` reads).
//! The others (`-blendu`, `-blendv`, `-boost`, `-cc`, `-mm`, `-texres`,
//! `-type`, `-t`, and a third `-s`/`-o` value, for 3D textures) do not
//! change what a diffuse solution sees or cannot be honoured; they are
//! named in the texture's `ignored`, which mesh-prep turns into a note.

use schemas::Error;
use std::path::{Path, PathBuf};

/// A texture a material names, with the options that say how to read it.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureRef {
    /// The file name as the MTL writes it (relative to the MTL's folder).
    pub name: String,
    /// Line of the statement that names it.
    pub line: usize,
    /// `-s`: texture coordinates are scaled by this, then offset.
    pub scale: [f64; 2],
    /// `-o`: offset added to the scaled texture coordinates.
    pub offset: [f64; 2],
    /// `-clamp on`: coordinates clamp to [0, 1] instead of repeating.
    pub clamp: bool,
    /// `-bm`: strength of a bump or normal map.
    pub bump_multiplier: f64,
    /// `-imfchan`: the channel a scalar texture reads (`r`, `g`, `b`, `m`
    /// matte, `l` luminance, `z` depth), if given.
    pub channel: Option<char>,
    /// Options given but not honoured, as written (`-cc on`).
    pub ignored: Vec<String>,
}

impl TextureRef {
    /// A texture named `name` on line `line`, with every option at its
    /// default.
    pub fn named(name: &str, line: usize) -> Self {
        TextureRef { name: name.into(), line, scale: [1.0; 2], offset: [0.0; 2], clamp: false, bump_multiplier: 1.0, channel: None, ignored: Vec::new() }
    }
}

/// One `newmtl` entry.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MtlMaterial {
    /// Material name.
    pub name: String,
    /// The library it comes from.
    pub file: PathBuf,
    /// Line of its `newmtl`.
    pub line: usize,
    /// `Kd`: diffuse reflectance.
    pub diffuse: Option<[f64; 3]>,
    /// `Ks`: specular reflectance.
    pub specular: Option<[f64; 3]>,
    /// `Ke`: emission (radiance, as path tracers read it).
    pub emissive: Option<[f64; 3]>,
    /// `Tf`: transmission filter.
    pub transmission_filter: Option<[f64; 3]>,
    /// `d`: dissolve (1 opaque).
    pub dissolve: Option<f64>,
    /// `illum`: illumination model.
    pub illumination_model: Option<u32>,
    /// `map_Kd`.
    pub diffuse_texture: Option<TextureRef>,
    /// `map_d`.
    pub dissolve_texture: Option<TextureRef>,
    /// `norm`, `bump` or `map_Bump`.
    pub normal_texture: Option<TextureRef>,
}

/// Texture options and how many values each takes (`-o`, `-s`, `-t` take
/// one to three numbers: as many as follow).
const TEXTURE_OPTIONS: &[(&str, usize)] = &[
    ("-blendu", 1),
    ("-blendv", 1),
    ("-bm", 1),
    ("-boost", 1),
    ("-cc", 1),
    ("-clamp", 1),
    ("-imfchan", 1),
    ("-mm", 2),
    ("-texres", 1),
    ("-type", 1),
    ("-o", 3),
    ("-s", 3),
    ("-t", 3),
];

/// Parses the MTL library `text` read from `path`. `notes` receives a line
/// for each statement that is ignored although it looks meant (a colour
/// before any `newmtl`).
pub fn parse_mtl(path: &Path, text: &str, notes: &mut Vec<String>) -> Result<Vec<MtlMaterial>, Error> {
    let mut materials: Vec<MtlMaterial> = Vec::new();
    for statement in crate::text::statements(text) {
        let (line, keyword, rest) = (statement.line, statement.keyword.as_str(), statement.rest.as_str());
        let error = |message: String| Error::parse(path, Some(line), message);
        // Keywords in any case: exporters write `map_kd` and `map_Bump`.
        let lower = keyword.to_ascii_lowercase();
        if lower == "newmtl" {
            if rest.is_empty() {
                return Err(error("newmtl needs a material name".into()));
            }
            materials.push(MtlMaterial { name: rest.to_string(), file: path.to_path_buf(), line, ..Default::default() });
            continue;
        }
        let known = matches!(lower.as_str(), "kd" | "ks" | "ke" | "tf" | "d" | "illum" | "map_kd" | "map_d" | "norm" | "bump" | "map_bump");
        let Some(current) = materials.last_mut() else {
            if known {
                notes.push(format!("{}:{line}: '{keyword}' before any newmtl is ignored", path.display()));
            }
            continue;
        };
        let arguments = statement.arguments();
        match lower.as_str() {
            "kd" => current.diffuse = Some(colour(keyword, arguments).map_err(error)?),
            "ks" => current.specular = Some(colour(keyword, arguments).map_err(error)?),
            "ke" => current.emissive = Some(colour(keyword, arguments).map_err(error)?),
            "tf" => current.transmission_filter = Some(colour(keyword, arguments).map_err(error)?),
            "d" => {
                let value = arguments.split_whitespace().last().ok_or_else(|| error("d needs a value".into()))?;
                current.dissolve = Some(number(keyword, value).map_err(error)?);
            }
            "illum" => {
                let model = arguments.parse::<u32>().ok().filter(|m| *m <= 10);
                current.illumination_model = Some(model.ok_or_else(|| error(format!("illum '{arguments}' is not an illumination model (0 to 10)")))?);
            }
            "map_kd" => current.diffuse_texture = Some(texture(keyword, rest, line).map_err(error)?),
            "map_d" => current.dissolve_texture = Some(texture(keyword, rest, line).map_err(error)?),
            "norm" | "bump" | "map_bump" => current.normal_texture = Some(texture(keyword, rest, line).map_err(error)?),
            _ => {}
        }
    }
    Ok(materials)
}

/// The first word of `text` and the trimmed rest of it.
fn split_word(text: &str) -> (&str, &str) {
    match text.split_once(char::is_whitespace) {
        Some((keyword, rest)) => (keyword, rest.trim()),
        None => (text, ""),
    }
}

/// A finite number.
fn number(keyword: &str, text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("{keyword}: '{text}' is not finite")),
        Err(_) => Err(format!("{keyword}: '{text}' is not a number")),
    }
}

/// A colour: three numbers, or one meaning grey.
fn colour(keyword: &str, rest: &str) -> Result<[f64; 3], String> {
    let words: Vec<&str> = rest.split_whitespace().collect();
    if matches!(words.first(), Some(&("spectral" | "xyz"))) {
        return Err(format!("{keyword}: {} colours are not supported; give r g b", words[0]));
    }
    let values = words.iter().map(|w| number(keyword, w)).collect::<Result<Vec<f64>, String>>()?;
    match values.as_slice() {
        [g] => Ok([*g; 3]),
        [r, g, b] => Ok([*r, *g, *b]),
        _ => Err(format!("{keyword} needs one value (grey) or three (r g b), found {}", values.len())),
    }
}

/// A texture statement: options, then the file name (the rest of the line).
fn texture(keyword: &str, rest: &str, line: usize) -> Result<TextureRef, String> {
    let mut remaining = rest;
    let mut options = Vec::new();
    loop {
        let (word, after) = split_word(remaining);
        let Some(&(option, arity)) = TEXTURE_OPTIONS.iter().find(|(name, _)| *name == word) else {
            break;
        };
        remaining = after;
        let mut values = Vec::new();
        for taken in 0..arity {
            let (value, after) = split_word(remaining);
            // -o, -s and -t take up to three numbers: stop at the first word
            // that is not one.
            if arity == 3 && taken > 0 && value.parse::<f64>().is_err() {
                break;
            }
            if value.is_empty() {
                return Err(format!("{keyword}: option {word} needs a value"));
            }
            values.push(value);
            remaining = after;
        }
        options.push((option, values));
    }
    if remaining.is_empty() {
        return Err(format!("{keyword} needs a file name"));
    }
    let mut texture = TextureRef::named(remaining, line);
    for (option, values) in options {
        let numbers = || values.iter().map(|v| number(&format!("{keyword} {option}"), v)).collect::<Result<Vec<f64>, String>>();
        match option {
            "-s" | "-o" => {
                let v = numbers()?;
                let target = if option == "-s" { &mut texture.scale } else { &mut texture.offset };
                // One value is u alone (v keeps its default), as the format says.
                target[0] = v[0];
                if let Some(&second) = v.get(1) {
                    target[1] = second;
                }
                if v.len() == 3 {
                    texture.ignored.push(format!("{option}'s third value {} (3D textures)", values[2]));
                }
            }
            "-clamp" => {
                texture.clamp = match values[0].to_ascii_lowercase().as_str() {
                    "on" => true,
                    "off" => false,
                    other => return Err(format!("{keyword}: -clamp '{other}' is neither on nor off")),
                }
            }
            "-bm" => texture.bump_multiplier = numbers()?[0],
            "-imfchan" => {
                let c = values[0].to_ascii_lowercase();
                texture.channel = Some(match c.as_str() {
                    "r" | "g" | "b" | "m" | "l" | "z" => c.chars().next().unwrap_or('m'),
                    other => return Err(format!("{keyword}: -imfchan '{other}' is not one of r, g, b, m, l, z")),
                });
            }
            _ => texture.ignored.push(format!("{option} {}", values.join(" "))),
        }
    }
    Ok(texture)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Vec<MtlMaterial>, String> {
        parse_mtl(Path::new("m.mtl"), text, &mut Vec::new()).map_err(|e| e.to_string())
    }

    #[test]
    fn one_value_is_grey_and_three_are_rgb() {
        let m = parse("newmtl a\nKd 0.5\nks 0 # none\nKe 1 2 3\n").unwrap();
        assert_eq!(m[0].diffuse, Some([0.5; 3]));
        assert_eq!(m[0].specular, Some([0.0; 3]));
        assert_eq!(m[0].emissive, Some([1.0, 2.0, 3.0]));
        assert_eq!(m[0].line, 1);
    }

    #[test]
    fn bad_colours_are_named_by_line() {
        assert_eq!(parse("newmtl a\nKd 0.5 0.5\n").unwrap_err(), "m.mtl:2: Kd needs one value (grey) or three (r g b), found 2");
        assert_eq!(parse("newmtl a\n\nKe 1 nan 1\n").unwrap_err(), "m.mtl:3: Ke: 'nan' is not finite");
        assert_eq!(parse("newmtl a\nKd\n").unwrap_err(), "m.mtl:2: Kd needs one value (grey) or three (r g b), found 0");
        assert_eq!(parse("newmtl a\nKd spectral x.rfl\n").unwrap_err(), "m.mtl:2: Kd: spectral colours are not supported; give r g b");
        assert_eq!(parse("newmtl a\nillum 2.5\n").unwrap_err(), "m.mtl:2: illum '2.5' is not an illumination model (0 to 10)");
        assert_eq!(parse("newmtl\n").unwrap_err(), "m.mtl:1: newmtl needs a material name");
    }

    #[test]
    fn names_with_spaces_and_texture_options() {
        let m = parse("newmtl Brushed Steel #2\nmap_kd -o 0.5 0.5 -bm 1.0 textures/steel plate.png\nmap_Bump -bm 0.3 n.png\nd -halo 0.8\n").unwrap();
        assert_eq!(m[0].name, "Brushed Steel #2");
        let steel = TextureRef { offset: [0.5, 0.5], ..TextureRef::named("textures/steel plate.png", 2) };
        assert_eq!(m[0].diffuse_texture, Some(steel));
        assert_eq!(m[0].normal_texture, Some(TextureRef { bump_multiplier: 0.3, ..TextureRef::named("n.png", 3) }));
        assert_eq!(m[0].dissolve, Some(0.8));
        assert_eq!(parse("newmtl a\nmap_Kd -clamp on\n").unwrap_err(), "m.mtl:2: map_Kd needs a file name");
    }

    #[test]
    fn texture_options_are_kept_or_listed_as_ignored() {
        let m = parse("newmtl a\nmap_Kd -s 2 4 1 -clamp ON -cc on -imfchan l -o 0.25 wood.png\nmap_d -imfchan m -mm 0 1 mask.png\n").unwrap();
        let wood = m[0].diffuse_texture.as_ref().unwrap();
        assert_eq!((wood.scale, wood.offset, wood.clamp, wood.channel), ([2.0, 4.0], [0.25, 0.0], true, Some('l')));
        assert_eq!(wood.ignored, ["-s's third value 1 (3D textures)", "-cc on"]);
        assert_eq!(m[0].dissolve_texture.as_ref().unwrap().ignored, ["-mm 0 1"]);
        assert_eq!(parse("newmtl a\nmap_Kd -clamp maybe w.png\n").unwrap_err(), "m.mtl:2: map_Kd: -clamp 'maybe' is neither on nor off");
        assert_eq!(parse("newmtl a\nmap_Kd -s x w.png\n").unwrap_err(), "m.mtl:2: map_Kd -s: 'x' is not a number");
        assert_eq!(parse("newmtl a\nmap_d -imfchan q w.png\n").unwrap_err(), "m.mtl:2: map_d: -imfchan 'q' is not one of r, g, b, m, l, z");
    }

    #[test]
    fn colour_before_newmtl_is_noted_not_applied() {
        let mut notes = Vec::new();
        let m = parse_mtl(Path::new("m.mtl"), "Kd 1 0 0\nnewmtl a\n", &mut notes).unwrap();
        assert_eq!(m[0].diffuse, None);
        assert_eq!(notes, ["m.mtl:1: 'Kd' before any newmtl is ignored"]);
    }
}
