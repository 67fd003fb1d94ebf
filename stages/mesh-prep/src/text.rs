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
/// `notes`. A leading UTF-8 byte-order mark is dropped.
pub fn read_text<S: TextSource + ?Sized>(source: &S, path: &Path, notes: &mut Vec<String>) -> Result<String, Error> {
    let bytes = source.read_bytes(path)?;
    match String::from_utf8(bytes) {
        Ok(text) => Ok(without_bom(text)),
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
    let text = String::from_utf8(bytes).map_err(|e| {
        let line = 1 + e.as_bytes()[..e.utf8_error().valid_up_to()].iter().filter(|&&b| b == b'\n').count();
        Error::parse(path, Some(line), "not UTF-8 text")
    })?;
    Ok(without_bom(text))
}

/// `text` without the byte-order mark some Windows editors put first,
/// which would otherwise glue itself to the first keyword.
fn without_bom(text: String) -> String {
    match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    }
}

/// One statement of OBJ or MTL text: a keyword and the rest of its line.
#[derive(Clone, Debug, PartialEq)]
pub struct Statement {
    /// 1-based line number (of the first line, for a continued one).
    pub line: usize,
    /// The first word.
    pub keyword: String,
    /// The rest of the line, trimmed, comment included: names keep a `#`
    /// (exporters write names like `Material #25`).
    pub rest: String,
}

impl Statement {
    /// The rest of the line up to a `#` comment, trimmed: the arguments of
    /// a statement of numbers or indices (`v 1 2 3 # corner`).
    pub fn arguments(&self) -> &str {
        self.rest.split('#').next().unwrap_or("").trim()
    }
}

/// The statements of OBJ and MTL text: comment lines (starting with `#`)
/// and blank lines dropped, a trailing backslash joining the next line
/// (except on a comment line), `\r` dropped.
pub fn statements(text: &str) -> Vec<Statement> {
    let mut out = Vec::new();
    let mut pending: Option<(usize, String)> = None;
    let mut finish = |line: usize, joined: &str| {
        let code = joined.trim();
        if !code.is_empty() && !code.starts_with('#') {
            let (keyword, rest) = code.split_once(char::is_whitespace).unwrap_or((code, ""));
            out.push(Statement { line, keyword: keyword.to_string(), rest: rest.trim().to_string() });
        }
    };
    for (index, raw) in text.split('\n').enumerate() {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        if pending.is_none() && line.trim_start().starts_with('#') {
            // A comment line never continues onto the next.
            continue;
        }
        let (number, mut joined) = pending.take().unwrap_or((index + 1, String::new()));
        match line.strip_suffix('\\') {
            Some(head) => {
                joined.push_str(head);
                joined.push(' ');
                pending = Some((number, joined));
            }
            None => {
                joined.push_str(line);
                finish(number, &joined);
            }
        }
    }
    if let Some((number, joined)) = pending {
        finish(number, &joined);
    }
    out
}

/// Where a file name written in an OBJ or MTL file is, relative to the
/// folder `base` of the file that names it: as written; else with
/// backslashes read as folder separators (Windows exporters); else its last
/// component alone, beside the file (an absolute path from the author's
/// machine). `None` if none of these exists.
pub fn locate(source: &dyn TextSource, base: &Path, name: &str) -> Option<std::path::PathBuf> {
    let forward = name.replace('\\', "/");
    let last = forward.rsplit('/').next().unwrap_or(&forward).to_string();
    [name.to_string(), forward, last].into_iter().map(|n| base.join(n)).find(|p| source.exists(p))
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
    fn statements_drop_comment_lines_and_join_continued_lines() {
        let lines = statements("# header\nv 1 2 3 # end\r\nf 1 \\\n 2 3\n\n  \n\tusemtl Material #25\\");
        let seen: Vec<(usize, &str, &str)> = lines.iter().map(|s| (s.line, s.keyword.as_str(), s.rest.as_str())).collect();
        assert_eq!(seen, [(2, "v", "1 2 3 # end"), (3, "f", "1   2 3"), (7, "usemtl", "Material #25")]);
        assert_eq!(lines[0].arguments(), "1 2 3");
        let continued_comment = statements("# C:\\dir\\\nv 0 0 0\n");
        assert_eq!(continued_comment.len(), 1, "a comment line ending in a backslash does not swallow the next");
    }

    #[test]
    fn a_byte_order_mark_is_dropped() {
        let source = Memory(vec![("a.obj".into(), b"\xef\xbb\xbfmtllib m.mtl\n".to_vec())]);
        assert_eq!(read_text(&source, Path::new("a.obj"), &mut Vec::new()).unwrap(), "mtllib m.mtl\n");
        assert_eq!(read_utf8(&source, Path::new("a.obj")).unwrap(), "mtllib m.mtl\n");
    }

    #[test]
    fn names_are_located_as_written_with_forward_slashes_or_beside_the_file() {
        let source = Memory::text(&[("m/a b.png", ""), ("m/tex/w.png", ""), ("m/c.png", "")]);
        let at = |name: &str| locate(&source, Path::new("m"), name).map(|p| p.display().to_string());
        assert_eq!(at("a b.png").as_deref(), Some("m/a b.png"));
        assert_eq!(at("tex\\w.png").as_deref(), Some("m/tex/w.png"));
        assert_eq!(at("C:\\Users\\me\\c.png").as_deref(), Some("m/c.png"));
        assert_eq!(at("d.png"), None);
    }
}
