//! Where scene, OBJ, MTL and other files come from (the file system, or
//! text built into the binary), and how their bytes become text: UTF-8, or,
//! for files exporters write in other encodings, Latin-1 with a note.

use schemas::Error;
use std::path::Path;

/// Where input files come from: the file system, or files built into the
/// binary (the built-in scenes).
pub trait TextSource {
    /// The bytes of `path`, or an error naming it.
    fn read_bytes(&self, path: &Path) -> Result<Vec<u8>, Error>;

    /// Whether `path` names a file this source can read.
    fn exists(&self, path: &Path) -> bool;

    /// The text of `path` as [`read_text`] reads it, without the note.
    fn read(&self, path: &Path) -> Result<String, Error> {
        read_text(self, path, &mut Vec::new())
    }
}

/// The file system.
pub struct Files;

impl TextSource for Files {
    fn read_bytes(&self, path: &Path) -> Result<Vec<u8>, Error> {
        std::fs::read(path).map_err(|e| Error::io(path, e))
    }

    fn exists(&self, path: &Path) -> bool {
        path.is_file()
    }
}

/// The text of `path` read through `source`. Bytes that are not UTF-8
/// (exporters write Latin-1 or Windows-1252 names and comments) are read as
/// Latin-1, every byte one character, so no name is lost or merged with
/// another; a note naming the file and the first such line is pushed to
/// `notes`.
pub fn read_text<S: TextSource + ?Sized>(source: &S, path: &Path, notes: &mut Vec<String>) -> Result<String, Error> {
    let bytes = source.read_bytes(path)?;
    match String::from_utf8(bytes) {
        Ok(text) => Ok(text),
        Err(e) => {
            let bytes = e.into_bytes();
            let valid = std::str::from_utf8(&bytes).map_or_else(|e| e.valid_up_to(), str::len);
            let line = 1 + bytes[..valid].iter().filter(|&&b| b == b'\n').count();
            notes.push(format!("{}:{line}: not UTF-8; read as Latin-1", path.display()));
            Ok(bytes.iter().map(|&b| char::from(b)).collect())
        }
    }
}

/// The text of `path`, which must be UTF-8 (a file written for this
/// pipeline, like `scene.ron`): an error names the line of the first byte
/// that is not.
pub fn read_utf8(source: &dyn TextSource, path: &Path) -> Result<String, Error> {
    let bytes = source.read_bytes(path)?;
    String::from_utf8(bytes).map_err(|e| {
        let line = 1 + e.as_bytes()[..e.utf8_error().valid_up_to()].iter().filter(|&&b| b == b'\n').count();
        Error::parse(path, Some(line), "not UTF-8 text")
    })
}

/// The logical lines of OBJ and MTL text, numbered from 1: comments (from
/// `#`) removed, a trailing backslash joining the next line (the line
/// number is that of the first), `\r` dropped.
pub fn statements(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    for (index, raw) in text.split('\n').enumerate() {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let (number, mut joined) = pending.take().unwrap_or((index + 1, String::new()));
        match line.strip_suffix('\\') {
            Some(head) => {
                joined.push_str(head);
                joined.push(' ');
                pending = Some((number, joined));
            }
            None => {
                joined.push_str(line);
                let code = joined.split('#').next().unwrap_or("").trim().to_string();
                if !code.is_empty() {
                    out.push((number, code));
                }
            }
        }
    }
    if let Some((number, joined)) = pending {
        let code = joined.split('#').next().unwrap_or("").trim().to_string();
        if !code.is_empty() {
            out.push((number, code));
        }
    }
    out
}

/// Files in memory, by path: for tests and for callers that build a scene
/// in code. A path is looked up as written (`Path::to_string_lossy`).
#[derive(Clone, Debug, Default)]
pub struct Memory(pub Vec<(String, Vec<u8>)>);

impl Memory {
    /// Text files, `(path, text)`.
    pub fn text(files: &[(&str, &str)]) -> Self {
        Memory(files.iter().map(|(p, t)| (p.to_string(), t.as_bytes().to_vec())).collect())
    }
}

impl TextSource for Memory {
    fn read_bytes(&self, path: &Path) -> Result<Vec<u8>, Error> {
        let key = path.to_string_lossy();
        self.0.iter().find(|(p, _)| *p == key).map(|(_, t)| t.clone()).ok_or_else(|| Error::io(path, std::io::ErrorKind::NotFound.into()))
    }

    fn exists(&self, path: &Path) -> bool {
        let key = path.to_string_lossy();
        self.0.iter().any(|(p, _)| *p == key)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latin1_is_read_byte_for_byte_with_one_note() {
        let source = Memory(vec![("a.obj".into(), b"# caf\xe9\nv 0 0 0\n# na\xefve\n".to_vec())]);
        let mut notes = Vec::new();
        let text = read_text(&source, Path::new("a.obj"), &mut notes).unwrap();
        assert_eq!(text, "# caf\u{e9}\nv 0 0 0\n# na\u{ef}ve\n");
        assert_eq!(notes, ["a.obj:1: not UTF-8; read as Latin-1"]);
        assert_eq!(read_utf8(&Memory(vec![("s.ron".into(), b"(\n\n a: \xe9)".to_vec())]), Path::new("s.ron")).unwrap_err().to_string(), "s.ron:3: not UTF-8 text");
    }

    #[test]
    fn statements_drop_comments_and_join_continued_lines() {
        let lines = statements("# header\nv 1 2 3 # end\r\nf 1 \\\n 2 3\n\n  \nusemtl a\\");
        assert_eq!(lines, [(2, "v 1 2 3".to_string()), (3, "f 1   2 3".to_string()), (7, "usemtl a".to_string())]);
    }
}
