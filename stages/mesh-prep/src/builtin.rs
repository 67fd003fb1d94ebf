//! Scenes built into the binary, so `make` renders without any file. They
//! are parsed by the same code as scene files: the text is embedded, not
//! the result.

use crate::obj::TextSource;
use schemas::Error;
use std::path::{Path, PathBuf};

/// A built-in scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Builtin {
    /// The Cornell box: published geometry and camera, measured
    /// reflectances (as RGB), a ceiling light.
    CornellBox,
}

const CORNELL: [(&str, &str); 3] = [
    ("scene.ron", include_str!("../builtin/scene.ron")),
    ("cornell_box.obj", include_str!("../builtin/cornell_box.obj")),
    ("cornell_box.mtl", include_str!("../builtin/cornell_box.mtl")),
];

impl Builtin {
    /// The path its scene file is known by, in messages and provenance.
    pub fn scene_path(self) -> PathBuf {
        match self {
            Builtin::CornellBox => PathBuf::from("builtin:cornell-box/scene.ron"),
        }
    }
}

impl TextSource for Builtin {
    fn read(&self, path: &Path) -> Result<String, Error> {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        match self {
            Builtin::CornellBox => CORNELL.iter().find(|(n, _)| *n == name).map(|(_, text)| text.to_string()),
        }
        .ok_or_else(|| Error::io(path, std::io::ErrorKind::NotFound.into()))
    }
}
