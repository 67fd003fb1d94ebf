//! mesh-prep on files as they are found in the wild, the dependency file
//! `make` includes, and the word it gives on lighting mistakes (issue 11,
//! items 4, 7 and 8).

use end_to_end::{refused, run_ok, s, scratch};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

/// The inside of a closed unit box (walls facing in), material `wall`
/// from `library`.
fn room_obj(library: &str) -> String {
    format!(
        "mtllib {library}\nusemtl wall\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n"
    )
}

/// An Area light 5 mm under the box's ceiling, emitting down (or up, into
/// the ceiling, wound the wrong way).
fn ceiling_light(down: bool) -> &'static str {
    if down {
        "Area(corner: (0.4, 0.995, 0.4), edge_u: (0.2, 0.0, 0.0), edge_v: (0.0, 0.0, 0.2), emission: (10.0, 10.0, 10.0))"
    } else {
        "Area(corner: (0.4, 0.995, 0.4), edge_u: (0.0, 0.0, 0.2), edge_v: (0.2, 0.0, 0.0), emission: (10.0, 10.0, 10.0))"
    }
}

/// Writes `files` (path relative to `dir`, bytes) and a scene.ron in
/// `dir/scene` naming `obj` (relative to it) with `lights`; returns the
/// scene's path.
fn write_scene(dir: &Path, obj: &str, lights: &str, files: &[(&str, &[u8])]) -> PathBuf {
    for (path, bytes) in files {
        let path = dir.join(path);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    let scene = dir.join("scene/scene.ron");
    std::fs::create_dir_all(scene.parent().unwrap()).unwrap();
    let text = format!(
        "Scene(meshes: [Obj(file: \"{obj}\")], camera: Camera(eye: (0.5, 0.5, 0.05), target: (0.5, 0.5, 1.0), up: (0.0, 1.0, 0.0), vertical_fov_deg: 60.0, width: 16, height: 16), lights: [{lights}])"
    );
    std::fs::write(&scene, text).unwrap();
    scene
}

/// The room of [`room_obj`] in `dir/scene`, its library `walls.mtl` in
/// `dir/<library>` naming the texture `texture` beside it (after a texture
/// option, as exporters write them), lit by the ceiling light and a
/// luminaire whose EULUMDAT file is `dir/<library>/lamp.ldt`.
fn scene_with_library_elsewhere(dir: &Path, library: &str, texture: &str) -> PathBuf {
    let obj = room_obj(&format!("../{library}/walls.mtl"));
    let (mtl_path, texture_path, ldt_path) = (format!("{library}/walls.mtl"), format!("{library}/{texture}"), format!("{library}/lamp.ldt"));
    let mtl = format!("newmtl wall\nKd 0.5\nmap_Kd -bm 1 {texture}\n");
    let ldt = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../stages/mesh-prep/tests/data/photometry/lidrs_example_prolicht_E30-0019.ldt")).unwrap();
    let lights = format!("{}, Goniometric(file: \"../{library}/lamp.ldt\", position: (0.5, 0.8, 0.5))", ceiling_light(true));
    let png = stage_kit::png::encode_png(1, 1, &[[128, 128, 128]]).unwrap();
    write_scene(dir, "room.obj", &lights, &[("scene/room.obj", obj.as_bytes()), (&mtl_path, mtl.as_bytes()), (&texture_path, &png), (&ldt_path, &ldt)])
}

/// mesh-prep's arguments for `scene` with every output in `dir/out`.
fn prep_args(dir: &Path, scene: &Path) -> Vec<String> {
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    [s(scene), "--mesh", s(&out.join("mesh.exr")), "--manifest", s(&out.join("manifest.ron")), "--depfile", s(&out.join("mesh.d")), "--report", s(&out.join("report.ron"))]
        .map(String::from)
        .to_vec()
}

fn as_strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

/// Runs mesh-prep on `scene` expecting success; returns its warnings.
fn warnings_of(dir: &Path, scene: &Path) -> Vec<String> {
    let out = run_ok("mesh-prep", &as_strs(&prep_args(dir, scene)));
    String::from_utf8_lossy(&out.stderr).lines().filter(|l| l.starts_with("mesh-prep: warning: ")).map(|l| l["mesh-prep: warning: ".len()..].to_string()).collect()
}

/// Issue 11: `Kd 0.5` and `Ks 0` made tobj panic (exit 101).
#[test]
fn one_value_colours_are_grey() {
    let dir = scratch("wild_one_value");
    let scene = write_scene(&dir, "room.obj", ceiling_light(true), &[("scene/room.obj", room_obj("room.mtl").as_bytes()), ("scene/room.mtl", b"newmtl wall\nKd 0.5\nKs 0\n")]);
    assert_eq!(warnings_of(&dir, &scene), Vec::<String>::new());
    let manifest = std::fs::read_to_string(dir.join("out/manifest.ron")).unwrap();
    assert!(manifest.contains("diffuse: (0.5, 0.5, 0.5)"), "{manifest}");
}

/// Issue 11: a Latin-1 comment made the OBJ unreadable, and a library
/// name with spaces was not found.
#[test]
fn latin1_comments_and_library_names_with_spaces() {
    let dir = scratch("wild_latin1");
    let obj: Vec<u8> = [b"# export\xe9 par Blender\n".as_slice(), room_obj("base.mtl my walls.mtl").as_bytes()].concat();
    let scene = write_scene(
        &dir,
        "room.obj",
        ceiling_light(true),
        &[("scene/room.obj", &obj), ("scene/base.mtl my walls.mtl", b"newmtl wall\nKd 0.25\n")],
    );
    let warnings = warnings_of(&dir, &scene);
    assert_eq!(warnings, [format!("{}: not UTF-8; read as Latin-1", s(&dir.join("scene/room.obj:1")))]);
    let manifest = std::fs::read_to_string(dir.join("out/manifest.ron")).unwrap();
    assert!(manifest.contains("diffuse: (0.25, 0.25, 0.25)"), "the library with a space in its name was read: {manifest}");
}

/// Runs mesh-prep on the room with `lights`, `obj` and `mtl` (as
/// `scene/room.obj` and `scene/room.mtl`) in a fresh directory `test`;
/// expects exit 2 and one stderr line, which it returns with `DIR` for the
/// directory, and checks that no output was written.
fn refusal(test: &str, lights: &str, obj: &str, mtl: &str) -> String {
    let dir = scratch(test);
    let scene = write_scene(&dir, "room.obj", lights, &[("scene/room.obj", obj.as_bytes()), ("scene/room.mtl", mtl.as_bytes())]);
    let line = refused("mesh-prep", &as_strs(&prep_args(&dir, &scene)));
    for output in ["mesh.exr", "manifest.ron", "mesh.d", "report.ron"] {
        assert!(!dir.join("out").join(output).exists(), "{output} written despite the error");
    }
    line.replace(s(&dir), "DIR")
}

/// Wild input that cannot be read, and lights without a sensible shape,
/// are one error naming the file, line or light (issue 11: a NaN light
/// corner was reported as a camera error; a zero-area one was dropped).
#[test]
fn bad_wild_input_and_bad_lights_are_one_line_naming_file_line_or_light() {
    let (room, wall) = (room_obj("room.mtl"), "newmtl wall\nKd 0.5\n");
    let light = ceiling_light(true);
    let cases = [
        ("wild_bad_mtl", light, room.clone(), "newmtl wall\n\nKd 0.5 0.5\n", "DIR/scene/room.mtl:3: Kd needs one value (grey) or three (r g b), found 2"),
        ("wild_bad_illum", light, room.clone(), "newmtl wall\nillum x\n", "DIR/scene/room.mtl:2: illum 'x' is not an illumination model (0 to 10)"),
        ("wild_missing_mtl", light, room_obj("gone.mtl"), wall, "DIR/scene/room.obj:1: material library 'DIR/scene/gone.mtl' does not exist"),
        (
            "wild_nan_light",
            "Area(corner: (0.4, NaN, 0.4), edge_u: (0.2, 0.0, 0.0), edge_v: (0.0, 0.0, 0.2), emission: (10.0, 10.0, 10.0))",
            room.clone(),
            wall,
            "DIR/scene/scene.ron: light 0 (Area, 'area_light_0'): corner [0.4, NaN, 0.4] is not finite",
        ),
        (
            "wild_flat_light",
            "Area(corner: (0.4, 0.9, 0.4), edge_u: (0.2, 0.0, 0.0), edge_v: (0.0, 0.0, 0.0), emission: (10.0, 10.0, 10.0))",
            room.clone(),
            wall,
            "DIR/scene/scene.ron: light 0 (Area, 'area_light_0'): edge_u and edge_v span no area (zero or parallel edges)",
        ),
        (
            "wild_flat_emitter",
            "",
            format!("{room}o lamp\nusemtl glow\nv 0.2 0.5 0.5\nv 0.4 0.5 0.5\nv 0.6 0.5 0.5\nf -3 -2 -1\n"),
            "newmtl wall\nKd 0.5\nnewmtl glow\nKe 5\n",
            "DIR/scene/room.obj:22: emitter 'lamp' (material 'glow', DIR/scene/room.obj:22) has zero area: all 1 of its triangles are degenerate",
        ),
    ];
    for (test, lights, obj, mtl, expected) in cases {
        assert_eq!(refusal(test, lights, &obj, mtl), format!("mesh-prep: error: {expected}"), "{test}");
    }
}

/// The depfile names every file read, wherever it lies, escaped for make.
#[test]
fn the_depfile_names_the_scene_obj_mtl_elsewhere_texture_and_luminaire() {
    let dir = scratch("wild_depfile");
    let scene = scene_with_library_elsewhere(&dir, "shared lib", "tex$1.png");
    assert_eq!(warnings_of(&dir, &scene), Vec::<String>::new());
    let esc = |p: &Path| s(p).replace(' ', "\\ ").replace('$', "$$");
    let (scene_dir, out) = (dir.join("scene"), dir.join("out"));
    let read = ["room.obj", "../shared lib/walls.mtl", "../shared lib/lamp.ldt", "../shared lib/tex$1.png"].map(|p| scene_dir.join(p));
    let read: Vec<PathBuf> = std::iter::once(scene.clone()).chain(read).collect();
    let mut expected = format!("# Written by mesh-prep: the files its outputs were made from.\n{} {}:", esc(&out.join("mesh.exr")), esc(&out.join("manifest.ron")));
    for p in &read {
        expected += &format!(" \\\n  {}", esc(p));
    }
    expected += "\n";
    for p in &read {
        expected += &format!("\n{}:\n", esc(p));
    }
    assert_eq!(std::fs::read_to_string(out.join("mesh.d")).unwrap(), expected);
}

/// `make` reruns mesh-prep when, and only when, a file it read changed:
/// the MTL in another folder, its texture, or a luminaire's EULUMDAT file.
#[test]
fn make_reruns_mesh_prep_exactly_when_a_file_it_read_changes() {
    let dir = scratch("wild_make");
    let scene = scene_with_library_elsewhere(&dir, "lib", "tex.png");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let out = dir.join("out");
    let make = || {
        // -o: the stage binaries count as old and are not rebuilt (the
        // tests run on the ones `make test` built).
        // Under `make test` the parent make's flags and variables would
        // reach this one through the environment.
        let result = std::process::Command::new("make")
            .current_dir(root)
            .env_remove("MAKEFLAGS")
            .env_remove("MFLAGS")
            .env_remove("MAKELEVEL")
            .args(["--no-print-directory", "-o", "target/release/mesh-prep", &format!("OUT={}", s(&out)), &format!("SCENE={}", s(&scene)), s(&out.join("mesh.exr"))])
            .output()
            .expect("make runs");
        assert!(result.status.success(), "make failed: {}", String::from_utf8_lossy(&result.stderr));
        String::from_utf8_lossy(&result.stdout).contains("--depfile")
    };
    // "Touch" without waiting for the clock: every file of the test goes
    // two minutes back, then the touched one one minute forward of that.
    let touch = |path: &str| {
        let now = SystemTime::now();
        set_times(&dir, now - Duration::from_secs(120));
        std::fs::File::options().write(true).open(dir.join(path)).unwrap().set_modified(now - Duration::from_secs(60)).unwrap();
    };
    assert!(make(), "the first make runs mesh-prep");
    assert!(!make(), "nothing changed: nothing reruns");
    touch("lib/walls.mtl");
    assert!(make(), "the MTL in another folder changed: mesh-prep reruns");
    assert!(!make(), "nothing changed since");
    touch("lib/tex.png");
    assert!(make(), "the texture changed: mesh-prep reruns");
    touch("lib/lamp.ldt");
    assert!(make(), "the photometric file changed: mesh-prep reruns");
    assert!(!make(), "nothing changed since");
}

/// Sets the modification time of every file under `dir` to `time`.
fn set_times(dir: &Path, time: SystemTime) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            set_times(&path, time);
        } else {
            std::fs::File::options().write(true).open(&path).unwrap().set_modified(time).unwrap();
        }
    }
}

/// Issue 11: a light wound into the ceiling gave a dark image with no
/// word; now a warning names it, on stderr and in the report.
#[test]
fn a_light_wound_the_wrong_way_is_named_on_stderr_and_in_the_report() {
    let dir = scratch("wild_wound");
    let obj = room_obj("room.mtl");
    let files: [(&str, &[u8]); 2] = [("scene/room.obj", obj.as_bytes()), ("scene/room.mtl", b"newmtl wall\nKd 0.5\n")];
    let scene = write_scene(&dir, "room.obj", ceiling_light(true), &files);
    assert_eq!(warnings_of(&dir, &scene), Vec::<String>::new(), "a light facing down into the room gets no word");
    let scene = write_scene(&dir, "room.obj", ceiling_light(false), &files);
    let warnings = warnings_of(&dir, &scene);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].starts_with(&format!("emitter 'area_light_0' (material 'area_light_0', {}): half the rays from its front hit a surface within 0.0", s(&scene))), "{}", warnings[0]);
    assert!(warnings[0].ends_with("is it wound the wrong way? (it emits on the side its corners turn counter-clockwise around)"), "{}", warnings[0]);
    let report = std::fs::read_to_string(dir.join("out/report.ron")).unwrap();
    assert!(report.contains("is it wound the wrong way?"), "{report}");
}
