//! Fuzz targets for the pipeline's own artifacts (issue 11): every EXR
//! kind (mesh, clusters, solution, lightmap, image, surface) and `manifest.ron`,
//! each mutated byte by byte from a valid file the `schemas` writers made,
//! and read back by the reader every stage uses; and the records of every
//! table layer mutated as words (`fuzz_*_tables`), which reach the
//! structural checks that byte mutations of a compressed file rarely do.
//! Any answer is fine; a panic or a hang fails, naming the case (see
//! `end_to_end::fuzz`). The cluster hierarchy is fuzzed with the solver
//! walking it in hierarchical-solve's tests.

use end_to_end::fuzz::{fuzz, Kind};
use schemas::cluster::Clusters;
use schemas::exr_io::{read_exr, write_exr};
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::lightmap::Lightmap;
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::{read_ron, write_ron};
use schemas::solution::Solution;
use schemas::surface::Surface;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use test_support::artifacts::{closed_box, clusters_over, image, lightmap, solution, surface, table_words, with_layer_words};

/// A fresh path for one case's file (cases run on threads of their own).
fn case_path(extension: &str) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!("fuzz-artifacts-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(format!("{}.{extension}", NEXT.fetch_add(1, Ordering::Relaxed)))
}

/// The bytes of the file `write` writes.
fn written(extension: &str, write: impl FnOnce(&Path) -> schemas::Result<()>) -> Vec<u8> {
    let path = case_path(extension);
    write(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    bytes
}

/// Fuzzes `read`, given the path of a file holding each mutant of `seed`.
fn fuzz_file(target: &str, seed: &[u8], kind: Kind, extension: &'static str, read: fn(&Path)) {
    fuzz(target, &[seed], kind, move |bytes| {
        let path = case_path(extension);
        std::fs::write(&path, bytes).unwrap();
        read(&path);
        let _ = std::fs::remove_file(&path);
    });
}

#[test]
fn fuzz_mesh_exr() {
    let (mesh, _) = closed_box();
    fuzz_file("mesh.exr", &written("exr", |p| mesh.write(p)), Kind::Binary, "exr", |path| {
        if let Ok((mesh, _)) = Mesh::read(path) {
            let _ = closed_box().1.check_mesh(path, &mesh);
        }
    });
}

#[test]
fn fuzz_manifest_ron() {
    let (_, manifest) = closed_box();
    fuzz_file("manifest.ron", &written("ron", |p| write_ron(p, &manifest)), Kind::Text, "ron", |path| {
        let _ = read_ron::<Manifest>(path);
    });
}

#[test]
fn fuzz_clusters_exr() {
    let clusters = clusters_over(&closed_box().0);
    fuzz_file("clusters.exr", &written("exr", |p| clusters.write(p)), Kind::Binary, "exr", |path| {
        let _ = Clusters::read(path, 12);
    });
}

#[test]
fn fuzz_solution_exr() {
    let solution = solution(&closed_box().0);
    fuzz_file("solution.exr", &written("exr", |p| solution.write(p)), Kind::Binary, "exr", |path| {
        let _ = Solution::read(path);
    });
}

#[test]
fn fuzz_lightmap_exr() {
    let lightmap = lightmap(&closed_box().0);
    fuzz_file("lightmap.exr", &written("exr", |p| lightmap.write(p)), Kind::Binary, "exr", |path| {
        let _ = Lightmap::read(path);
    });
}

#[test]
fn fuzz_image_exr() {
    let image = image();
    fuzz_file("image.exr", &written("exr", |p| image.write(p)), Kind::Binary, "exr", |path| {
        let _ = HdrImage::read_any(path);
    });
}

/// Fuzzes `read` on artifacts of schema `S` whose table layers `layers`
/// are, one at a time, replaced by mutants of their records; `write`
/// writes the valid artifact the mutants start from.
fn fuzz_tables<S: Schema>(target: &str, layers: &[&'static str], write: impl FnOnce(&Path) -> schemas::Result<()>, read: fn(&Path)) {
    let seed = case_path("exr");
    write(&seed).unwrap();
    let (artifact, _) = read_exr::<S>(&seed).unwrap();
    std::fs::remove_file(&seed).unwrap();
    for &layer in layers {
        let words = table_words(artifact.layer(&seed, layer).unwrap());
        let artifact = artifact.clone();
        fuzz(&format!("{target} layer {layer}"), &[&words], Kind::Binary, move |bytes| {
            let path = case_path("exr");
            write_exr(&path, &with_layer_words(&artifact, layer, bytes)).unwrap();
            read(&path);
            let _ = std::fs::remove_file(&path);
        });
    }
}

#[test]
fn fuzz_mesh_tables() {
    let (mesh, _) = closed_box();
    fuzz_tables::<Mesh>("mesh.exr", &["vertex", "triangle"], |p| mesh.write(p), |path| {
        if let Ok((mesh, _)) = Mesh::read(path) {
            let _ = closed_box().1.check_mesh(path, &mesh);
        }
    });
}

#[test]
fn fuzz_clusters_tables() {
    let clusters = clusters_over(&closed_box().0);
    fuzz_tables::<Clusters>("clusters.exr", &["cluster", "order"], |p| clusters.write(p), |path| {
        let _ = Clusters::read(path, 12);
    });
}

#[test]
fn fuzz_solution_tables() {
    let solution = solution(&closed_box().0);
    fuzz_tables::<Solution>("solution.exr", &["element", "cluster", "link", "slope"], |p| solution.write(p), |path| {
        let _ = Solution::read(path);
    });
}

#[test]
fn fuzz_lightmap_tables() {
    let lightmap = lightmap(&closed_box().0);
    fuzz_tables::<Lightmap>("lightmap.exr", &["region"], |p| lightmap.write(p), |path| {
        let _ = Lightmap::read(path);
    });
}

/// The closed box's surface artifact, and the reader's arguments for it.
fn box_surface() -> (Surface, usize, usize) {
    let (mesh, manifest) = closed_box();
    (surface(&mesh, manifest.materials.len()), mesh.triangles.len(), manifest.materials.len())
}

#[test]
fn fuzz_surface_exr() {
    let (s, ..) = box_surface();
    fuzz_file("surface.exr", &written("exr", |p| s.write(p)), Kind::Binary, "exr", |path| {
        let (_, triangles, materials) = box_surface();
        let _ = Surface::read(path, triangles, materials);
    });
}

#[test]
fn fuzz_surface_tables() {
    let (s, ..) = box_surface();
    fuzz_tables::<Surface>("surface.exr", &["uv", "shading_normal", "tangent", "material_maps", "texture"], |p| s.write(p), |path| {
        let (_, triangles, materials) = box_surface();
        let _ = Surface::read(path, triangles, materials);
    });
}

