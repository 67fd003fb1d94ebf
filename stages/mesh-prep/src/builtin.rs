//! Scenes built into the binary, so `make` renders without any file. They
//! are parsed by the same code as scene files: the text is embedded or
//! generated, not the result.
//!
//! Names: `cornell-box` (the classic box), and with a triangle count
//! (`10k`, `100k`, `1m`, or a plain number): `cornell-box-4k` (the box,
//! tessellated), `plants-100k`, `sphere-20k`, `box-100k` (see
//! [`crate::procedural`]); `simple-environment` (paper 002's simple
//! environment, [`crate::procedural::SimpleEnvironment`]).

use crate::text::TextSource;
use crate::procedural;
use schemas::Error;
use std::path::{Path, PathBuf};
use std::str::FromStr;

const CORNELL_SCENE: &str = include_str!("../builtin/scene.ron");
const CORNELL_OBJ: &str = include_str!("../builtin/cornell_box.obj");
const CORNELL_MTL: &str = include_str!("../builtin/cornell_box.mtl");
/// Triangles of the classic Cornell box.
const CORNELL_TRIANGLES: usize = 46;

/// A built-in scene: its name and the text of its files.
#[derive(Clone, Debug, PartialEq)]
pub struct Builtin {
    name: String,
    files: Vec<(String, String)>,
}

/// Reads `10k`, `100k`, `1m`, `2500` as a count.
fn parse_count(text: &str) -> Option<usize> {
    let (digits, factor) = match text.chars().last()? {
        'k' | 'K' => (&text[..text.len() - 1], 1_000.0),
        'm' | 'M' => (&text[..text.len() - 1], 1_000_000.0),
        _ => (text, 1.0),
    };
    let value: f64 = digits.parse().ok()?;
    (value > 0.0 && value.is_finite() && value * factor <= 1e8).then(|| (value * factor).round() as usize)
}

impl FromStr for Builtin {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        let known = "cornell-box, cornell-box-<n>, simple-environment, plants-<n>, sphere-<n>, box-<n> (n like 10k, 100k, 1m)";
        let (kind, count) = match name.rsplit_once('-') {
            Some((kind, count)) if parse_count(count).is_some() => (kind, parse_count(count)),
            _ => (name, None),
        };
        let file = |n: &str, t: String| (n.to_string(), t);
        let files = match (kind, count) {
            ("cornell-box", None) => vec![file("scene.ron", CORNELL_SCENE.into()), file("cornell_box.obj", CORNELL_OBJ.into()), file("cornell_box.mtl", CORNELL_MTL.into())],
            ("cornell-box", Some(n)) => {
                let levels = ((n as f64 / CORNELL_TRIANGLES as f64).ln() / 4f64.ln()).ceil().max(0.0) as u32;
                vec![
                    file("scene.ron", CORNELL_SCENE.into()),
                    file("cornell_box.obj", procedural::tessellate(CORNELL_OBJ, levels)),
                    file("cornell_box.mtl", CORNELL_MTL.into()),
                ]
            }
            ("simple-environment", None) => generated(procedural::simple_environment(), "simple"),
            ("plants", Some(n)) => generated(procedural::plants(n), "plants"),
            ("sphere", Some(n)) => generated(procedural::sphere(n), "sphere"),
            ("box", Some(n)) => generated(procedural::closed_box(n), "box"),
            _ => return Err(format!("unknown built-in scene '{name}'; known: {known}")),
        };
        Ok(Builtin { name: name.to_string(), files })
    }
}

fn generated((scene, obj, mtl): (String, String, String), stem: &str) -> Vec<(String, String)> {
    vec![("scene.ron".into(), scene), (format!("{stem}.obj"), obj), (format!("{stem}.mtl"), mtl)]
}

impl Builtin {
    /// The path its scene file is known by, in messages and provenance.
    pub fn scene_path(&self) -> PathBuf {
        PathBuf::from(format!("builtin:{}/scene.ron", self.name))
    }
}

impl Builtin {
    /// The text of the built-in file `path` names, if there is one.
    fn file(&self, path: &Path) -> Option<&str> {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        self.files.iter().find(|(n, _)| *n == name).map(|(_, text)| text.as_str())
    }
}

impl TextSource for Builtin {
    fn read_bytes(&self, path: &Path) -> Result<Vec<u8>, Error> {
        self.file(path).map(|t| t.as_bytes().to_vec()).ok_or_else(|| Error::io(path, std::io::ErrorKind::NotFound.into()))
    }

    fn exists(&self, path: &Path) -> bool {
        self.file(path).is_some()
    }
}
