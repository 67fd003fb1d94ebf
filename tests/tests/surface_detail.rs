//! The surface artifact end to end (issue 13, item 1): `mesh-prep
//! --surface` writes what the readers accept, with the same provenance as
//! the mesh: the texture of the material a quad uses, decoded, its corner
//! coordinates, and nothing at all for a scene without surface detail.

use end_to_end::{run_ok, s, scratch};
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::surface::{Surface, TextureKind, NONE};
use std::path::Path;

/// Prepares a quad (with texture coordinates) of material `tiles` whose MTL
/// entry adds `maps`, with a 2 x 1 PNG `tiles.png`; returns the surface
/// artifact, the mesh and the manifest.
fn prepared(test: &str, maps: &str) -> (Surface, Mesh, Manifest) {
    let dir = scratch(test);
    let obj = "mtllib m.mtl\nusemtl tiles\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n";
    std::fs::write(dir.join("a.obj"), obj).unwrap();
    std::fs::write(dir.join("m.mtl"), format!("newmtl tiles\nKd 0.5\n{maps}")).unwrap();
    std::fs::write(dir.join("tiles.png"), stage_kit::png::encode_png(2, 1, &[[255, 255, 255], [0, 0, 0]]).unwrap()).unwrap();
    let camera = "Camera(eye: (0.5, 0.5, 2.0), target: (0.5, 0.5, 0.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: 60.0, width: 8, height: 8)";
    let lamp = "Area(corner: (0.4, 0.4, 1.0), edge_u: (0.0, 0.2, 0.0), edge_v: (0.2, 0.0, 0.0), emission: (1.0, 1.0, 1.0))";
    std::fs::write(dir.join("scene.ron"), format!("Scene(meshes: [Obj(file: \"a.obj\")], camera: {camera}, lights: [{lamp}])")).unwrap();
    let [mesh, manifest, surface] = ["mesh.exr", "manifest.ron", "surface.exr"].map(|f| dir.join(f));
    run_ok("mesh-prep", &[s(&dir.join("scene.ron")), "--mesh", s(&mesh), "--manifest", s(&manifest), "--surface", s(&surface)]);
    let (mesh, _) = Mesh::read(&mesh).unwrap();
    let manifest = read_ron::<Manifest>(&manifest).unwrap().value;
    let (surface, _) = Surface::read(Path::new(&surface), mesh.triangles.len(), manifest.materials.len()).unwrap();
    assert_eq!(surface.header.provenance, mesh.header.provenance, "one run, one provenance");
    (surface, mesh, manifest)
}

#[test]
fn mesh_prep_writes_the_textures_and_coordinates_a_scene_uses() {
    let (surface, mesh, manifest) = prepared("surface_textured", "map_Kd -o 0.5 0 tiles.png\n");
    let tiles = manifest.materials.iter().position(|m| m.name == "tiles").unwrap();
    assert_eq!(surface.material_maps[tiles], [0, NONE, NONE]);
    let texture = &surface.textures[0];
    assert_eq!((texture.kind, texture.width, texture.height, texture.offset), (TextureKind::Diffuse, 2, 1, [0.5, 0.0]));
    assert_eq!(texture.texels, [[1.0, 1.0, 1.0, 1.0], [0.0, 0.0, 0.0, 1.0]], "white and black decode to reflectances 1 and 0");
    let quad: Vec<u32> = (0..mesh.triangles.len() as u32).filter(|&t| mesh.triangles[t as usize].material as usize == tiles).collect();
    assert_eq!(surface.uvs.iter().map(|u| u.0).collect::<Vec<_>>(), quad, "the quad's triangles have coordinates, the lamp's none");
}

#[test]
fn a_scene_without_surface_detail_has_an_empty_surface_artifact() {
    let (surface, ..) = prepared("surface_plain", "");
    assert!(surface.textures.is_empty() && surface.tangents.is_empty() && surface.shading_normals.is_empty());
    assert!(surface.material_maps.iter().all(|m| *m == [NONE; 3]));
}
