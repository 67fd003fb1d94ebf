//! Fuzz targets for the files a user writes (issue 11): OBJ, MTL and
//! scene.ron, each mutated from seed inputs and run through the whole of
//! mesh-prep's preparation in-process (parse, place, weld, check the
//! lights). Any answer is fine; a panic or a hang fails, naming the case
//! (see `end_to_end::fuzz`). `make test` runs a few hundred cases each,
//! `make fuzz` many more.

use end_to_end::fuzz::{fuzz, Kind};
use mesh_prep::text::Memory;
use std::path::Path;

const SCENE: &str = r#"Scene(
  meshes: [Obj(file: "room.obj", scale: 1.0, translate: (0.0, 0.0, 0.0))],
  camera: Camera(eye: (0.5, 0.5, 0.05), target: (0.5, 0.5, 1.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: 60.0, width: 16, height: 16),
  lights: [Area(corner: (0.4, 0.995, 0.4), edge_u: (0.2, 0.0, 0.0), edge_v: (0.0, 0.0, 0.2), emission: (10.0, 10.0, 10.0))],
  materials: { "wall": (diffuse: Some((0.6, 0.6, 0.6))) },
)"#;

/// A closed unit box, walls facing in, two materials, a polygon and
/// negative and slashed indices.
const OBJ: &str = "# a room\nmtllib room.mtl\no room\nusemtl wall\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvt 0 0\nvn 0 1 0\n\
f 1/1 2/1 3/1 4/1\nf 5 8 7 6\nf 1//1 5//1 6//1 2//1\nf -5 -6 -2 -1\ng side walls\nusemtl floor\nf 1 4 8 5\nf 2 6 7 3\n";

const MTL: &str = "# materials\nnewmtl wall\nKd 0.5 0.5 0.5\nKs 0\nillum 2\n\nnewmtl floor\nKd 0.3\nKe 0 0 0\nd 1\nTf 1 1 1\nmap_Kd -o 0.5 0.5 -bm 1 floor texture.png\nbump n.png\n";

/// The cornell box built into mesh-prep, a real exporter's file.
const CORNELL_OBJ: &str = include_str!("../../stages/mesh-prep/builtin/cornell_box.obj");
const CORNELL_MTL: &str = include_str!("../../stages/mesh-prep/builtin/cornell_box.mtl");

/// Prepares the scene of `scene`, `obj` and `mtl` text in memory (`mtl` is
/// both libraries the seed OBJs name); the answer is thrown away, only a
/// panic or a hang counts.
fn prepare(scene: &[u8], obj: &[u8], mtl: &[u8]) {
    let source = Memory(vec![
        ("s/scene.ron".into(), scene.to_vec()),
        ("s/room.obj".into(), obj.to_vec()),
        ("s/room.mtl".into(), mtl.to_vec()),
        ("s/cornell_box.mtl".into(), mtl.to_vec()),
        ("s/floor texture.png".into(), stage_kit::png::encode_png(2, 2, &[[200, 100, 50]; 4]).unwrap()),
        ("s/n.png".into(), stage_kit::png::encode_png(1, 1, &[[128, 128, 255]]).unwrap()),
    ]);
    let path = Path::new("s/scene.ron");
    if let Ok(scene) = mesh_prep::read_scene(&source, path) {
        let _ = mesh_prep::prepare(&scene, path, &source, &mesh_prep::Params::default());
    }
}

#[test]
fn fuzz_obj() {
    fuzz("obj", &[OBJ.as_bytes(), CORNELL_OBJ.as_bytes()], Kind::Text, |obj| {
        prepare(SCENE.as_bytes(), obj, MTL.as_bytes());
    });
}

#[test]
fn fuzz_mtl() {
    fuzz("mtl", &[MTL.as_bytes(), CORNELL_MTL.as_bytes()], Kind::Text, |mtl| {
        prepare(SCENE.as_bytes(), OBJ.as_bytes(), mtl);
    });
}

#[test]
fn fuzz_scene_ron() {
    fuzz("scene.ron", &[SCENE.as_bytes()], Kind::Text, |scene| {
        prepare(scene, OBJ.as_bytes(), MTL.as_bytes());
    });
}
