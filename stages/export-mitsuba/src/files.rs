//! Where an export's files go: the XML at the output path, its PLY meshes
//! in the folder named after it (`scene.xml` -> `scene/`), which the XML
//! names relative to itself.

use crate::Export;
use schemas::{Error, Result};
use stage_kit::run::Outputs;
use std::path::{Path, PathBuf};

/// The PLY folder of `xml`: `dir/scene.xml` -> `dir/scene`, and its name as
/// the XML refers to it.
pub fn mesh_folder(xml: &Path) -> Result<(PathBuf, String)> {
    let stem = xml.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    if stem.is_empty() || xml.extension().is_none() {
        return Err(Error::invalid(xml, None, "the output needs a name with an extension (e.g. scene.xml): its meshes go into the folder named after it"));
    }
    Ok((xml.with_file_name(&stem), stem))
}

/// Writes `exported`'s meshes into `folder` (made if missing), then the XML
/// that names them to `xml`, staged in `outputs` (put in place together at
/// the end of the run). On an error nothing is left behind: no temporary
/// file, and no folder this call made.
pub fn write(exported: &Export, folder: &Path, xml: &Path, outputs: &mut Outputs) -> Result<()> {
    let created_folder = !folder.is_dir();
    std::fs::create_dir_all(folder).map_err(|e| Error::io(folder, e))?;
    let written = exported.meshes.iter().try_for_each(|ply| outputs.write_bytes(&folder.join(&ply.file_name), &ply.bytes)).and_then(|()| outputs.write_bytes(xml, exported.xml.as_bytes()));
    if written.is_err() && created_folder {
        *outputs = Outputs::new(); // drops the staged temporaries: the folder is empty again
        let _ = std::fs::remove_dir(folder);
    }
    written
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PlyMesh;

    #[test]
    fn the_mesh_folder_is_the_xml_without_its_extension() {
        assert_eq!(mesh_folder(Path::new("out/scene.xml")).unwrap(), (PathBuf::from("out/scene"), "scene".to_string()));
        let error = mesh_folder(Path::new("out/scene")).unwrap_err().to_string();
        assert_eq!(error, "out/scene: the output needs a name with an extension (e.g. scene.xml): its meshes go into the folder named after it");
    }

    /// The meshes are staged in the folder, then the XML cannot be: the
    /// folder this write made goes again, with every temporary in it.
    #[test]
    fn a_failed_write_leaves_no_folder_and_no_temporary() {
        let dir = std::env::temp_dir().join(format!("export-mitsuba-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ply = |name: &str| PlyMesh { file_name: name.to_string(), material: 0, triangles: 1, vertices: 3, bytes: vec![1, 2, 3] };
        let exported = Export { xml: "<scene/>".to_string(), meshes: vec![ply("a.ply"), ply("b.ply")], skipped: Vec::new(), emitters: 0, film: (1, 1) };
        let (folder, xml) = (dir.join("scene"), dir.join("no/such/dir/scene.xml"));
        let mut outputs = Outputs::new();
        assert!(write(&exported, &folder, &xml, &mut outputs).is_err());
        drop(outputs);
        assert!(!folder.exists(), "{:?}", std::fs::read_dir(&folder).map(|d| d.count()));
        let xml = dir.join("scene.xml");
        let mut outputs = Outputs::new();
        write(&exported, &folder, &xml, &mut outputs).unwrap();
        outputs.keep().unwrap();
        assert_eq!(std::fs::read(folder.join("b.ply")).unwrap(), [1, 2, 3]);
        assert_eq!(std::fs::read_to_string(&xml).unwrap(), "<scene/>");
        assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 2, "only the two meshes");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
