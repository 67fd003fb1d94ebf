//! hierarchical-solve where a box's bottom face hovers a tenth of a
//! millimetre over the floor, facing it, as in McGuire's
//! `CornellBox-Glossy` (Williams College, 2011, CC BY 3.0: its room and
//! short box, vertices as published, the sphere left out; see
//! `bench/assets/mirror` for the archive). Between the two faces Lambert's
//! kernel is a step, 1 under the footprint and 0 beside it. The floor's
//! parts that shared a link from the bottom face by their own factors
//! found too little of the footprint, and the link's flux, kept whole,
//! gave floor leaves a factor of 2 to that face; with the face lighting
//! them back, Jacobi diverged (radiosity 1e26 after 2,000 iterations at
//! `EPS` 1e-4, written with exit 0).
//!
//! What must hold whatever the estimates: no surface of a scene whose
//! emitters have exitance at most `E` and whose reflectances are at most
//! `rho` has a radiosity over `E / (1 - rho)` (a point receives at most
//! the largest radiosity round it).

use end_to_end::{scratch, Solved};
use std::f64::consts::PI;

const OBJ: &str = "\
    mtllib room.mtl
    v -0.8677 -0.0001 0.0703
    v -0.4117 0.0001 -0.4921
    v 0.1507 0.0001 -0.0362
    v -0.3052 -0.0001 0.5262
    v -0.8678 0.7239 0.0705
    v -0.3054 0.7239 0.5264
    v 0.1506 0.7241 -0.0360
    v -0.4118 0.7241 -0.4920
    v 1.0000 0.0000 -1.0400
    v -0.9900 0.0000 -1.0400
    v -1.0100 0.0000 0.9900
    v 1.0000 0.0000 0.9900
    v 1.0000 1.5900 -1.0400
    v 1.0000 1.5900 0.9900
    v -1.0200 1.5900 0.9900
    v -1.0200 1.5900 -1.0400
    v 1.0000 1.5900 -1.0400
    v -1.0200 1.5900 -1.0400
    v -0.9900 0.0000 -1.0400
    v 1.0000 0.0000 -1.0400
    v 1.0000 1.5900 0.9900
    v 1.0000 1.5900 -1.0400
    v 1.0000 0.0000 -1.0400
    v 1.0000 0.0000 0.9900
    v -1.0200 1.5900 -1.0400
    v -1.0200 1.5900 0.9900
    v -1.0100 0.0000 0.9900
    v -0.9900 0.0000 -1.0400
    v 0.2300 1.5800 -0.2200
    v 0.2300 1.5800 0.1600
    v -0.2400 1.5800 0.1600
    v -0.2400 1.5800 -0.2200
    o shortBox
    usemtl white
    f 1 2 3
    f 3 4 1
    f 5 6 7
    f 7 8 5
    f 1 4 6
    f 6 5 1
    f 4 3 7
    f 7 6 4
    f 3 2 8
    f 8 7 3
    f 2 1 5
    f 5 8 2
    o floor
    usemtl white
    f 9 10 11
    f 11 12 9
    o ceiling
    usemtl white
    f 13 14 15
    f 15 16 13
    o backWall
    usemtl white
    f 17 18 19
    f 19 20 17
    o rightWall
    usemtl green
    f 21 22 23
    f 23 24 21
    o leftWall
    usemtl red
    f 25 26 27
    f 27 28 25
    o light
    usemtl light
    f 29 30 31
    f 31 32 29
";

const MTL: &str = "\
    newmtl white
    Kd 0.725 0.71 0.68
    newmtl red
    Kd 0.63 0.065 0.05
    newmtl green
    Kd 0.3725 0.648 0.3137
    newmtl light
    Kd 0.78 0.78 0.78
    Ke 10 10 10
";

/// The lamp's exitance (`Ke` is radiance) and the largest reflectance.
const EXITANCE: f64 = PI * 10.0;
const MOST_REFLECTANCE: f64 = 0.78;

#[test]
fn a_box_hovering_over_the_floor_converges_and_no_surface_exceeds_what_it_can_receive() {
    let dir = scratch("hovering_box");
    std::fs::write(dir.join("room.obj"), OBJ.replace("    ", "")).unwrap();
    std::fs::write(dir.join("room.mtl"), MTL.replace("    ", "")).unwrap();
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, r#"Scene(meshes: [Obj(file: "room.obj")], camera: Camera(eye: (0.0, 0.8, 3.9), target: (0.0, 0.8, 0.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: 39.3, width: 32, height: 32))"#).unwrap();
    let solved = Solved::new(&dir, &scene, &["--eps", "1e-4"]);
    let most = EXITANCE / (1.0 - MOST_REFLECTANCE);
    for object in ["floor", "shortBox", "ceiling", "backWall"] {
        let largest = solved.leaves_of(object).iter().flat_map(|(e, _)| e.radiosity).map(f64::from).fold(0.0, f64::max);
        assert!(largest <= most, "a leaf of the {object} has radiosity {largest:e}, over the bound {most}");
    }
}
