//! Wavefront OBJ, read by hand, as found in the wild: every error names the
//! file and line, no input can make a third-party parser panic, and the
//! freedoms exporters take are accepted: several libraries on one `mtllib`
//! line, library and material names with spaces, Latin-1 bytes (see
//! [`crate::text::read_text`]), lines continued with a backslash.
//!
//! Read statements (others, like `l`, `p`, `s`, are ignored):
//! `v x y z` (finite; a fourth value or a colour after them is ignored),
//! `vt u [v [w]]` (texture coordinates, finite; `v` defaults to 0, `w` is
//! ignored), `vn x y z` (a shading normal, finite and non-zero),
//! `f a b c ...` (position indices, 1-based or negative, each with optional
//! `/vt/vn` indices, checked like the positions; a polygon is triangulated
//! as a fan from its first corner),
//! `o`/`g name` (a new object), `usemtl name`, `mtllib names`. An object is
//! split where its material changes, as tobj did, so the objects and their
//! order are what earlier versions wrote. A `#` starts a comment in a line
//! of numbers; in a name it is part of the name (`usemtl Material #25`).

use crate::mtl::{parse_mtl, MtlMaterial};
use crate::text::{locate, read_text, statements};
use schemas::Error;
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

pub use crate::text::{Files, TextSource};

/// One OBJ object (`o`/`g` group with one material), triangulated.
#[derive(Debug, Clone)]
pub struct ObjObject {
    /// Object name.
    pub name: String,
    /// Index into [`ObjFile::materials`], if the object has one.
    pub material: Option<usize>,
    /// Triangles as position indices into [`ObjFile::positions`], OBJ
    /// winding.
    pub triangles: Vec<[usize; 3]>,
    /// Per triangle, its corners' indices into [`ObjFile::uvs`], where all
    /// three corners name one.
    pub uv_triangles: Vec<Option<[usize; 3]>>,
    /// Per triangle, its corners' indices into [`ObjFile::normals`], where
    /// all three corners name one.
    pub normal_triangles: Vec<Option<[usize; 3]>>,
    /// Line of each triangle's face statement.
    pub lines: Vec<usize>,
}

impl ObjObject {
    /// An object without faces or material yet.
    fn named(name: &str) -> Self {
        ObjObject { name: name.to_string(), material: None, triangles: Vec::new(), uv_triangles: Vec::new(), normal_triangles: Vec::new(), lines: Vec::new() }
    }
}

/// An OBJ file and the materials of its MTL libraries.
#[derive(Debug, Clone)]
pub struct ObjFile {
    /// The file.
    pub path: PathBuf,
    /// Vertex positions, file units.
    pub positions: Vec<[f64; 3]>,
    /// Texture coordinates `(u, v)`.
    pub uvs: Vec<[f64; 2]>,
    /// Shading normals, unit length.
    pub normals: Vec<[f64; 3]>,
    /// Objects in file order.
    pub objects: Vec<ObjObject>,
    /// Materials in library order.
    pub materials: Vec<MtlMaterial>,
    /// What the reader noticed and the user should hear of (Latin-1 text,
    /// `usemtl` naming no material), one line each, naming file and line.
    pub notes: Vec<String>,
}

/// Reads and triangulates the OBJ at `path` and its MTL libraries (paths
/// relative to the OBJ's folder, found as [`locate`] finds them), through
/// `source`. `usemtl` names are resolved once the whole file is read, so a
/// `mtllib` line after them still counts.
pub fn read_obj(source: &dyn TextSource, path: &Path) -> Result<ObjFile, Error> {
    let mut notes = Vec::new();
    let text = read_text(source, path, &mut notes)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let (mut positions, mut uvs, mut normals) = (Vec::new(), Vec::new(), Vec::new());
    let mut materials: Vec<MtlMaterial> = Vec::new();
    let mut objects: Vec<Pending> = Vec::new();
    let mut current: Pending = (ObjObject::named("unnamed_object"), None);
    for statement in statements(&text) {
        let (line, rest) = (statement.line, statement.rest.as_str());
        let error = |message: String| Error::parse(path, Some(line), message);
        match statement.keyword.as_str() {
            "v" => positions.push(numbers::<3>(statement.arguments(), 3, "vertex").map_err(error)?),
            "vt" => {
                let [u, v] = numbers::<2>(statement.arguments(), 1, "texture coordinate").map_err(error)?;
                uvs.push([u, v]);
            }
            "vn" => normals.push(normal(statement.arguments()).map_err(error)?),
            "f" => {
                let defined = [positions.len(), uvs.len(), normals.len()];
                let corners = statement.arguments().split_whitespace().map(|c| corner(c, defined)).collect::<Result<Vec<Corner>, String>>().map_err(error)?;
                if corners.len() < 3 {
                    return Err(error("face needs at least three vertices".into()));
                }
                for k in 1..corners.len() - 1 {
                    let fan = [&corners[0], &corners[k], &corners[k + 1]];
                    current.0.triangles.push(fan.map(|c| c.position));
                    let all = |i: usize| fan.iter().map(|c| c.attributes[i]).collect::<Option<Vec<usize>>>().map(|v| [v[0], v[1], v[2]]);
                    current.0.uv_triangles.push(all(0));
                    current.0.normal_triangles.push(all(1));
                    current.0.lines.push(line);
                }
            }
            "o" | "g" => {
                let name = if rest.is_empty() { "unnamed_object" } else { rest };
                let next = (ObjObject::named(name), current.1.clone());
                finish(&mut objects, &mut current, next);
            }
            "usemtl" => {
                if rest.is_empty() {
                    return Err(error("usemtl needs a material name".into()));
                }
                if current.1.as_ref().map(|(name, _)| name.as_str()) != Some(rest) {
                    let next = (ObjObject::named(&current.0.name), Some((rest.to_string(), line)));
                    finish(&mut objects, &mut current, next);
                }
            }
            "mtllib" => {
                for library in libraries(source, &base, rest).map_err(error)? {
                    let mtl = read_text(source, &library, &mut notes)?;
                    materials.extend(parse_mtl(&library, &mtl, &mut notes)?);
                }
            }
            _ => {}
        }
    }
    objects.push(current);
    // The last material of a name wins, as in every MTL reader.
    let by_name: HashMap<&str, usize> = materials.iter().enumerate().map(|(i, m)| (m.name.as_str(), i)).collect();
    let mut unknown = HashSet::new();
    let mut resolved = Vec::with_capacity(objects.len());
    for (mut object, used) in objects {
        if let Some((name, line)) = used {
            object.material = by_name.get(name.as_str()).copied();
            if object.material.is_none() && unknown.insert(name.clone()) {
                notes.push(format!("{}:{line}: usemtl '{name}' names no material of its libraries; the default grey is used", path.display()));
            }
        }
        resolved.push(object);
    }
    Ok(ObjFile { path: path.to_path_buf(), positions, uvs, normals, objects: resolved, materials, notes })
}

/// An object being read, with the material name it uses and the line that
/// names it.
type Pending = (ObjObject, Option<(String, usize)>);

/// Ends `current` (kept if it has faces) and starts `next`.
fn finish(objects: &mut Vec<Pending>, current: &mut Pending, next: Pending) {
    let done = std::mem::replace(current, next);
    if !done.0.triangles.is_empty() {
        objects.push(done);
    }
}

/// The libraries a `mtllib` line names. The format separates names by
/// spaces, but exporters also write one name with spaces in it: the split
/// names are used if they all exist, else the whole rest of the line if it
/// exists; otherwise the error names the first missing one.
fn libraries(source: &dyn TextSource, base: &Path, rest: &str) -> Result<Vec<PathBuf>, String> {
    if rest.is_empty() {
        return Err("mtllib needs a file name".into());
    }
    let split: Vec<&str> = rest.split_whitespace().collect();
    let found: Vec<Option<PathBuf>> = split.iter().map(|name| locate(source, base, name)).collect();
    if found.iter().all(Option::is_some) {
        return Ok(found.into_iter().flatten().collect());
    }
    if let Some(whole) = locate(source, base, rest) {
        return Ok(vec![whole]);
    }
    let first = split.iter().zip(&found).find(|(_, f)| f.is_none()).map_or(rest, |(name, _)| name);
    let whole = if split.len() > 1 { format!(" (nor does '{}')", base.join(rest).display()) } else { String::new() };
    Err(format!("material library '{}' does not exist{whole}", base.join(first).display()))
}

/// The first `N` finite numbers of a statement (`what`), of which at least
/// `required` must be there; those missing after them are 0 and any more
/// are ignored.
fn numbers<const N: usize>(rest: &str, required: usize, what: &str) -> Result<[f64; N], String> {
    let mut values = [0.0f64; N];
    let mut words = rest.split_whitespace();
    for (k, c) in values.iter_mut().enumerate() {
        let Some(word) = words.next() else {
            if k < required {
                return Err(format!("{what} needs {}", plural(required, "coordinate")));
            }
            break;
        };
        *c = word.parse().map_err(|_| format!("{what} coordinate '{word}' is not a number"))?;
        if !c.is_finite() {
            return Err(format!("{what} coordinate '{word}' is not finite"));
        }
    }
    Ok(values)
}

/// A `vn` statement's normal, made unit length.
fn normal(rest: &str) -> Result<[f64; 3], String> {
    let n = numbers::<3>(rest, 3, "normal")?;
    let length = n.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(length > 0.0 && length.is_finite()) {
        return Err("normal has zero length".into());
    }
    Ok(n.map(|x| x / length))
}

/// One face corner: its 0-based position index, and its texture
/// coordinate and normal indices where it names them.
struct Corner {
    position: usize,
    /// `[vt, vn]`.
    attributes: [Option<usize>; 2],
}

/// A face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`, given how many
/// positions, texture coordinates and normals are `defined` so far
/// (negative indices count back from the last).
fn corner(text: &str, defined: [usize; 3]) -> Result<Corner, String> {
    let mut parts = text.split('/');
    let mut index = |k: usize, what: &str| -> Result<Option<usize>, String> {
        let word = parts.next().unwrap_or("");
        if word.is_empty() && k > 0 {
            return Ok(None);
        }
        let i: i64 = word.parse().map_err(|_| format!("face {what} '{text}' is not an index"))?;
        let resolved = if i > 0 { i - 1 } else { defined[k] as i64 + i };
        if i == 0 || resolved < 0 || resolved >= defined[k] as i64 {
            return Err(format!("face {what} {i} does not exist ({} defined so far)", plural(defined[k], what)));
        }
        Ok(Some(resolved as usize))
    };
    let position = index(0, "vertex")?.unwrap_or_default();
    let attributes = [index(1, "texture coordinate")?, index(2, "normal")?];
    Ok(Corner { position, attributes })
}

/// `n` things, in words (`3 vertices`, `1 normal`).
fn plural(n: usize, what: &str) -> String {
    match (n, what) {
        (1, _) => format!("1 {what}"),
        (_, "vertex") => format!("{n} vertices"),
        _ => format!("{n} {what}s"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::Memory;

    fn error_of(obj: &str) -> String {
        read_obj(&Memory::text(&[("s/a.obj", obj)]), Path::new("s/a.obj")).unwrap_err().to_string()
    }

    const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

    #[test]
    fn bad_lines_are_named() {
        assert_eq!(error_of("v 0 0 0\nv 1 0 0\nv 0 nan 1\nf 1 2 3\n"), "s/a.obj:3: vertex coordinate 'nan' is not finite");
        assert_eq!(error_of("v 0 0 0\nv 1 0 x\n"), "s/a.obj:2: vertex coordinate 'x' is not a number");
        assert_eq!(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), "s/a.obj:4: face vertex 4 does not exist (3 vertices defined so far)");
        assert_eq!(error_of("v 0 0 0\nf 1 1\n"), "s/a.obj:2: face needs at least three vertices");
        assert_eq!(error_of("v 0 0\n"), "s/a.obj:1: vertex needs 3 coordinates");
        assert_eq!(error_of("vt\n"), "s/a.obj:1: texture coordinate needs 1 coordinate");
        assert_eq!(error_of("vn 0 0 0\n"), "s/a.obj:1: normal has zero length");
        assert_eq!(error_of(&format!("{TRIANGLE}vt 0 0\nf 1/1 2/2 3/1\n")), "s/a.obj:6: face texture coordinate 2 does not exist (1 texture coordinate defined so far)");
        assert_eq!(error_of(&format!("{TRIANGLE}f 1//1 2 3\n")), "s/a.obj:5: face normal 1 does not exist (0 normals defined so far)");
        assert_eq!(error_of(&format!("{TRIANGLE}usemtl\n")), "s/a.obj:5: usemtl needs a material name");
    }

    #[test]
    fn missing_material_library_is_named_with_its_line() {
        assert_eq!(error_of("mtllib gone.mtl\nv 0 0 0\n"), "s/a.obj:1: material library 's/gone.mtl' does not exist");
        assert_eq!(error_of("\nmtllib a.mtl b.mtl\n"), "s/a.obj:2: material library 's/a.mtl' does not exist (nor does 's/a.mtl b.mtl')");
    }

    #[test]
    fn quads_are_triangulated_with_materials() {
        let source = Memory::text(&[
            ("s/a.obj", "mtllib m.mtl\no quad\nusemtl red\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 2\nf -4/1 -3/2/1 -2/3/1 -1\nf 1/-3 2/-2 3/-1\n"),
            ("s/m.mtl", "newmtl red\nKd 0.5 0.1 0.1\nKe 1 2 3\n"),
        ]);
        let obj = read_obj(&source, Path::new("s/a.obj")).unwrap();
        assert_eq!(obj.objects.len(), 1);
        assert_eq!(obj.objects[0].triangles, [[0, 1, 2], [0, 2, 3], [0, 1, 2]]);
        assert_eq!(obj.objects[0].uv_triangles, [Some([0, 1, 2]), None, Some([0, 1, 2])], "a corner without a texture coordinate leaves its triangle without");
        assert_eq!(obj.objects[0].normal_triangles, [None; 3]);
        assert_eq!(obj.normals, [[0.0, 0.0, 1.0]], "normals are made unit length");
        assert_eq!(obj.objects[0].lines, [12, 12, 13]);
        assert_eq!(obj.materials[0].emissive, Some([1.0, 2.0, 3.0]));
        assert!(obj.notes.is_empty(), "{:?}", obj.notes);
    }

    /// Issue 11: one-value colours made tobj panic (exit 101).
    #[test]
    fn one_value_colours_are_grey() {
        let source = Memory::text(&[("a.obj", &format!("mtllib m.mtl\nusemtl grey\n{TRIANGLE}")), ("m.mtl", "newmtl grey\nKd 0.5\nKs 0\n")]);
        let obj = read_obj(&source, Path::new("a.obj")).unwrap();
        assert_eq!(obj.materials[0].diffuse, Some([0.5; 3]));
        assert_eq!(obj.objects[0].material, Some(0));
    }

    /// Issue 11: several libraries on one line, and a library whose name
    /// has a space, were not found.
    #[test]
    fn several_libraries_and_names_with_spaces() {
        let source = Memory::text(&[
            ("s/a.obj", &format!("mtllib one.mtl two.mtl\nmtllib my materials.mtl\nusemtl b\n{TRIANGLE}usemtl c\nf 3 2 1\n")),
            ("s/one.mtl", "newmtl a\nKd 0.1\n"),
            ("s/two.mtl", "newmtl b\nKd 0.2\n"),
            ("s/my materials.mtl", "newmtl c\nKd 0.3\n"),
        ]);
        let obj = read_obj(&source, Path::new("s/a.obj")).unwrap();
        let names: Vec<&str> = obj.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "c"]);
        let materials: Vec<Option<usize>> = obj.objects.iter().map(|o| o.material).collect();
        assert_eq!(materials, [Some(1), Some(2)]);
    }

    /// Issue 11: a Latin-1 comment made the OBJ unreadable.
    #[test]
    fn latin1_comments_and_names_are_read_with_a_note() {
        let obj = b"# Export\xe9 par Blender\nmtllib m.mtl\nusemtl caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec();
        let source = Memory(vec![("a.obj".into(), obj), ("m.mtl".into(), b"newmtl caf\xe9\nKd 0.5\n".to_vec())]);
        let file = read_obj(&source, Path::new("a.obj")).unwrap();
        assert_eq!(file.materials[0].name, "caf\u{e9}");
        assert_eq!(file.objects[0].material, Some(0), "the Latin-1 name in the OBJ matches the one in the MTL");
        assert_eq!(file.notes, ["a.obj:1: not UTF-8; read as Latin-1", "m.mtl:1: not UTF-8; read as Latin-1"]);
    }

    #[test]
    fn unknown_material_is_noted_once_and_objects_split_where_usemtl_changes() {
        let obj = format!("o box\n{TRIANGLE}usemtl nothing\nf 1 3 2\nusemtl nothing\no empty\no last\nf 2 1 3\nusemtl nothing\n");
        let file = read_obj(&Memory::text(&[("a.obj", &obj)]), Path::new("a.obj")).unwrap();
        let names: Vec<&str> = file.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["box", "box", "last"], "usemtl splits 'box'; the same name again does not; empty objects vanish");
        assert_eq!(file.objects.iter().map(|o| o.material).collect::<Vec<_>>(), [None; 3]);
        assert_eq!(file.notes, ["a.obj:6: usemtl 'nothing' names no material of its libraries; the default grey is used"]);
    }

    #[test]
    fn usemtl_before_its_mtllib_and_windows_paths_are_resolved() {
        let source = Memory::text(&[("s/a.obj", &format!("usemtl red\n{TRIANGLE}mtllib lib\\m.mtl\n")), ("s/lib/m.mtl", "newmtl red\nKd 1 0 0\n")]);
        let file = read_obj(&source, Path::new("s/a.obj")).unwrap();
        assert_eq!(file.objects[0].material, Some(0));
        assert_eq!(file.materials[0].file, Path::new("s/lib/m.mtl"));
    }
}
