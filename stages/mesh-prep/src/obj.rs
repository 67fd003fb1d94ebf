//! Reading Wavefront OBJ/MTL through tobj, with a line-checking pass first:
//! tobj reports *what* failed but not *where*, and accepts `nan` as a
//! coordinate; the pass finds the offending line so the error can name it.

use schemas::Error;
use std::io::BufReader;
use std::path::{Path, PathBuf};

/// Where OBJ and MTL text comes from: the file system, or text built into
/// the binary (the default scene).
pub trait TextSource {
    /// The text of `path`, or an error naming it.
    fn read(&self, path: &Path) -> Result<String, Error>;
}

/// The file system.
pub struct Files;

impl TextSource for Files {
    fn read(&self, path: &Path) -> Result<String, Error> {
        std::fs::read_to_string(path).map_err(|e| Error::io(path, e))
    }
}

/// One OBJ object (`o`/`g` group with one material), triangulated.
#[derive(Debug, Clone)]
pub struct ObjObject {
    /// Object name.
    pub name: String,
    /// Index into [`ObjFile::materials`], if the object has one.
    pub material: Option<usize>,
    /// Positions, file units.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as indices into `positions`, OBJ winding.
    pub triangles: Vec<[usize; 3]>,
}

/// An OBJ file and the materials of its MTL libraries.
#[derive(Debug, Clone)]
pub struct ObjFile {
    /// Objects in file order.
    pub objects: Vec<ObjObject>,
    /// Materials in library order.
    pub materials: Vec<tobj::Material>,
}

/// Reads and triangulates the OBJ at `path` and its MTL libraries.
pub fn read_obj(source: &dyn TextSource, path: &Path) -> Result<ObjFile, Error> {
    let text = source.read(path)?;
    check_lines(path, &text)?;
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let failed_library = std::cell::RefCell::new(None::<Error>);
    let loaded = tobj::load_obj_buf(&mut BufReader::new(text.as_bytes()), &options, |library| {
        let library_path: PathBuf = base.join(library);
        match source.read(&library_path) {
            Ok(mtl) => tobj::load_mtl_buf(&mut BufReader::new(mtl.as_bytes())).map_err(|e| {
                failed_library.replace(Some(Error::parse(&library_path, None, format!("malformed MTL: {e}"))));
                e
            }),
            Err(e) => {
                failed_library.replace(Some(e));
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    });
    let (models, materials) = loaded.map_err(|e| Error::parse(path, None, format!("malformed OBJ: {e}")))?;
    if let Some(e) = failed_library.into_inner() {
        return Err(e);
    }
    let materials = materials.map_err(|e| Error::parse(path, None, format!("cannot load its materials: {e}")))?;
    let objects = models
        .into_iter()
        .map(|m| ObjObject {
            name: m.name,
            material: m.mesh.material_id,
            positions: m.mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
            triangles: m.mesh.indices.chunks_exact(3).map(|t| [t[0] as usize, t[1] as usize, t[2] as usize]).collect(),
        })
        .collect();
    Ok(ObjFile { objects, materials })
}

/// Checks the lines tobj would accept silently or reject without a line
/// number: vertex coordinates must be finite numbers, face indices must
/// name vertices defined before them.
fn check_lines(path: &Path, text: &str) -> Result<(), Error> {
    let mut vertices: i64 = 0;
    for (number, line) in text.lines().enumerate() {
        let line_no = Some(number + 1);
        let line = line.split('#').next().unwrap_or("");
        let mut fields = line.split_whitespace();
        match fields.next() {
            Some("v") => {
                let coordinates: Vec<&str> = fields.take(3).collect();
                if coordinates.len() < 3 {
                    return Err(Error::parse(path, line_no, "vertex needs three coordinates"));
                }
                for c in coordinates {
                    let value: f64 = c.parse().map_err(|_| Error::parse(path, line_no, format!("vertex coordinate '{c}' is not a number")))?;
                    if !value.is_finite() {
                        return Err(Error::invalid(path, line_no, format!("vertex coordinate '{c}' is not finite")));
                    }
                }
                vertices += 1;
            }
            Some("f") => {
                let corners: Vec<&str> = fields.collect();
                if corners.len() < 3 {
                    return Err(Error::parse(path, line_no, "face needs at least three vertices"));
                }
                for corner in corners {
                    let index = corner.split('/').next().unwrap_or("");
                    let i: i64 = index.parse().map_err(|_| Error::parse(path, line_no, format!("face vertex '{corner}' is not an index")))?;
                    let resolved = if i > 0 { i - 1 } else { vertices + i };
                    if i == 0 || resolved < 0 || resolved >= vertices {
                        return Err(Error::parse(path, line_no, format!("face vertex {i} does not exist ({vertices} vertices defined so far)")));
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Memory(Vec<(&'static str, &'static str)>);
    impl TextSource for Memory {
        fn read(&self, path: &Path) -> Result<String, Error> {
            let key = path.to_string_lossy();
            self.0.iter().find(|(p, _)| *p == key).map(|(_, t)| t.to_string()).ok_or_else(|| Error::io(path, std::io::ErrorKind::NotFound.into()))
        }
    }

    fn error_of(obj: &'static str) -> String {
        read_obj(&Memory(vec![("s/a.obj", obj)]), Path::new("s/a.obj")).unwrap_err().to_string()
    }

    #[test]
    fn bad_lines_are_named() {
        assert_eq!(error_of("v 0 0 0\nv 1 0 0\nv 0 nan 1\nf 1 2 3\n"), "s/a.obj:3: vertex coordinate 'nan' is not finite");
        assert_eq!(error_of("v 0 0 0\nv 1 0 x\n"), "s/a.obj:2: vertex coordinate 'x' is not a number");
        assert_eq!(error_of("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), "s/a.obj:4: face vertex 4 does not exist (3 vertices defined so far)");
        assert_eq!(error_of("v 0 0 0\nf 1 1\n"), "s/a.obj:2: face needs at least three vertices");
    }

    #[test]
    fn missing_material_library_is_named() {
        let message = error_of("mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        assert!(message.starts_with("s/gone.mtl:"), "{message}");
    }

    #[test]
    fn quads_are_triangulated_with_materials() {
        let source = Memory(vec![
            ("s/a.obj", "mtllib m.mtl\no quad\nusemtl red\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n"),
            ("s/m.mtl", "newmtl red\nKd 0.5 0.1 0.1\nKe 1 2 3\n"),
        ]);
        let obj = read_obj(&source, Path::new("s/a.obj")).unwrap();
        assert_eq!(obj.objects.len(), 1);
        assert_eq!(obj.objects[0].triangles.len(), 2);
        assert_eq!(obj.materials[0].emissive, Some([1.0, 2.0, 3.0]));
    }
}
