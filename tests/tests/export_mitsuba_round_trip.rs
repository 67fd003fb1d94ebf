//! The export round trip: the built-in Cornell box exported, the XML parsed
//! back with a real XML parser and the PLYs read back, has the same
//! triangles, areas, reflectances and emitters (radiance x pi = exitance);
//! a point projected through the exported camera (Mitsuba's `look_at` and
//! perspective projection, as in its sources) lands on the pixel the
//! pipeline's camera sees it in; the CLI writes all or nothing.

use export_mitsuba::{export, ply, Params};
use glam::DVec3;
use quick_xml::events::Event;
use schemas::mesh::{GoniometricLight, Manifest, Mesh};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// An XML element: tag, attributes, children.
#[derive(Debug, Default)]
struct Node {
    tag: String,
    attributes: BTreeMap<String, String>,
    children: Vec<Node>,
}

impl Node {
    fn attribute(&self, key: &str) -> &str {
        self.attributes.get(key).map(String::as_str).unwrap_or_else(|| panic!("<{}> has no {key}", self.tag))
    }
    fn all<'a>(&'a self, tag: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        self.children.iter().filter(move |c| c.tag == tag)
    }
    fn one(&self, tag: &str) -> &Node {
        let found: Vec<&Node> = self.children.iter().filter(|c| c.tag == tag).collect();
        assert_eq!(found.len(), 1, "<{}> has {} <{tag}>", self.tag, found.len());
        found[0]
    }
    /// The `value` of the child `<tag name="name" .../>`, `$x` resolved
    /// through the scene's `<default>`s.
    fn property(&self, tag: &str, name: &str, defaults: &BTreeMap<String, String>) -> String {
        let node = self.all(tag).find(|c| c.attributes.get("name").map(String::as_str) == Some(name));
        let value = node.unwrap_or_else(|| panic!("<{}> has no <{tag} name={name:?}>", self.tag)).attribute("value");
        match value.strip_prefix('$') {
            Some(key) => defaults[key].clone(),
            None => value.to_string(),
        }
    }
}

fn parse_xml(text: &str) -> Node {
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().trim_text(true);
    let mut stack = vec![Node::default()];
    let element = |e: &quick_xml::events::BytesStart| Node {
        tag: String::from_utf8(e.name().as_ref().to_vec()).unwrap(),
        attributes: e
            .attributes()
            .map(|a| {
                let a = a.unwrap();
                (String::from_utf8(a.key.as_ref().to_vec()).unwrap(), a.unescape_value().unwrap().into_owned())
            })
            .collect(),
        children: Vec::new(),
    };
    loop {
        match reader.read_event().expect("well-formed XML") {
            Event::Start(e) => stack.push(element(&e)),
            Event::Empty(e) => stack.last_mut().unwrap().children.push(element(&e)),
            Event::End(_) => {
                let node = stack.pop().unwrap();
                stack.last_mut().unwrap().children.push(node);
            }
            Event::Eof => break,
            Event::Text(t) => panic!("unexpected text {t:?}"),
            _ => {}
        }
    }
    assert_eq!(stack.len(), 1, "unclosed elements");
    let mut root = stack.pop().unwrap();
    assert_eq!(root.children.len(), 1, "one root element");
    let scene = root.children.pop().unwrap();
    assert_eq!(scene.tag, "scene");
    scene
}

fn triple(text: &str) -> [f64; 3] {
    let v: Vec<f64> = text.split(',').map(|s| s.trim().parse().unwrap()).collect();
    assert_eq!(v.len(), 3, "{text}");
    [v[0], v[1], v[2]]
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-30)
}

fn cornell() -> (Mesh, Manifest) {
    mesh_prep::prepare_builtin("cornell-box", "export-mitsuba test").expect("built-in Cornell box")
}

fn defaults(scene: &Node) -> BTreeMap<String, String> {
    scene.all("default").map(|d| (d.attribute("name").to_string(), d.attribute("value").to_string())).collect()
}

#[test]
fn export_round_trip_keeps_triangles_areas_reflectances_and_emitters() {
    let (mesh, manifest) = cornell();
    let exported = export(&mesh, &manifest, &Params::default(), "scene", "test provenance --mesh x");
    let scene = parse_xml(&exported.xml);
    assert_eq!(scene.attribute("version"), "3.0.0");
    let defaults = defaults(&scene);
    assert_eq!(scene.one("integrator").attribute("type"), "path");
    assert_eq!(scene.one("integrator").property("integer", "max_depth", &defaults), "-1");

    let plys: BTreeMap<String, &export_mitsuba::PlyMesh> = exported.meshes.iter().map(|m| (format!("scene/{}", m.file_name), m)).collect();
    let shapes: Vec<&Node> = scene.all("shape").collect();
    assert_eq!(shapes.len(), exported.meshes.len());
    let mut triangles = 0;
    let mut emitters = 0;
    for shape in shapes {
        assert_eq!(shape.attribute("type"), "ply");
        assert_eq!(shape.property("boolean", "face_normals", &defaults), "true");
        let ply = plys[&shape.property("string", "filename", &defaults)];
        let material = &manifest.materials[ply.material];
        let (positions, faces) = ply::decode(&ply.bytes).expect("PLY reads back");
        triangles += faces.len();

        // Triangle count and area per material; the winding keeps the front face.
        let ours: Vec<_> = mesh.triangles.iter().filter(|t| t.material as usize == ply.material).collect();
        assert_eq!(faces.len(), ours.len(), "{}", material.name);
        let mut area = 0.0;
        for (face, t) in faces.iter().zip(&ours) {
            let [p0, p1, p2] = face.map(|v| DVec3::from(positions[v as usize].map(f64::from)));
            let cross = (p1 - p0).cross(p2 - p0);
            area += 0.5 * cross.length();
            assert!(cross.normalize().dot(DVec3::from(t.normal.map(f64::from))) > 0.999, "winding flipped in {}", material.name);
        }
        let expected: f64 = ours.iter().map(|t| f64::from(t.area)).sum();
        assert!(close(area, expected, 1e-6), "{}: area {area} vs {expected}", material.name);

        // Reflectance and emitter.
        let bsdf = shape.one("bsdf");
        assert_eq!(bsdf.attribute("type"), "diffuse");
        let rho = triple(&bsdf.property("rgb", "reflectance", &defaults));
        for k in 0..3 {
            assert!(close(rho[k], material.diffuse[k], 1e-6), "{}: reflectance {rho:?} vs {:?}", material.name, material.diffuse);
        }
        let emitter: Vec<&Node> = shape.all("emitter").collect();
        if material.emission.iter().any(|&e| e > 0.0) {
            assert_eq!(emitter.len(), 1);
            assert_eq!(emitter[0].attribute("type"), "area");
            let radiance = triple(&emitter[0].property("rgb", "radiance", &defaults));
            for k in 0..3 {
                assert!(close(radiance[k] * std::f64::consts::PI, material.emission[k], 1e-6), "radiance x pi {radiance:?} vs {:?}", material.emission);
            }
            emitters += 1;
        } else {
            assert!(emitter.is_empty(), "{} does not emit", material.name);
        }
    }
    assert_eq!(triangles, mesh.triangles.len());
    assert_eq!(emitters, 1, "the Cornell box has one lamp");
    assert!(exported.skipped.is_empty(), "{:?}", exported.skipped);
}

/// A two-sided material (here the Cornell box's first non-emitting one,
/// its triangles given reversed twins as mesh-prep gives them) is exported
/// once per surface, not once per face, with its BSDF inside Mitsuba's
/// `twosided` adapter.
#[test]
fn a_two_sided_material_is_exported_once_inside_a_twosided_bsdf() {
    let (mut mesh, mut manifest) = cornell();
    let m = manifest.materials.iter().position(|m| m.emission == [0.0; 3]).unwrap();
    manifest.materials[m].two_sided = true;
    let fronts: Vec<_> = mesh.triangles.iter().filter(|t| t.material as usize == m).copied().collect();
    let twins = fronts.iter().map(|t| schemas::mesh::Triangle { vertices: schemas::mesh::reversed(t.vertices), normal: t.normal.map(|n| -n), ..*t });
    mesh.triangles.extend(twins.collect::<Vec<_>>());
    manifest.check_mesh(Path::new("mesh.exr"), &mesh).unwrap();
    let exported = export(&mesh, &manifest, &Params::default(), "scene", "");
    let ply = exported.meshes.iter().find(|p| p.material == m).unwrap();
    assert_eq!(ply.triangles, fronts.len(), "each twin pair once");
    let scene = parse_xml(&exported.xml);
    let shape = scene.all("shape").find(|s| s.property("string", "filename", &defaults(&scene)) == format!("scene/{}", ply.file_name)).unwrap();
    let outer = shape.one("bsdf");
    assert_eq!(outer.attribute("type"), "twosided");
    let rho = triple(&outer.one("bsdf").property("rgb", "reflectance", &defaults(&scene)));
    assert_eq!(rho, manifest.materials[m].diffuse);
    let others = scene.all("shape").filter(|s| !std::ptr::eq(*s, shape));
    assert!(others.map(|s| s.one("bsdf").attribute("type").to_string()).all(|t| t != "twosided"));
}

/// Pixel coordinates (continuous, top-left origin) of `point` through the
/// exported sensor, as Mitsuba 3 computes them: `look_at` gives camera
/// axes (left = up x dir, up' = dir x left, dir), the perspective
/// projection maps camera x/z to clip x with cot(fov_x / 2), then
/// `scale(-0.5, -0.5 aspect) * translate(-1, -1 / aspect)` to film [0, 1]^2.
fn mitsuba_pixel(scene: &Node, point: DVec3) -> (f64, f64) {
    let defaults = defaults(scene);
    let sensor = scene.one("sensor");
    assert_eq!(sensor.attribute("type"), "perspective");
    assert_eq!(sensor.property("string", "fov_axis", &defaults), "y");
    let lookat = sensor.one("transform").one("lookat");
    let (origin, target, up) = (triple(lookat.attribute("origin")), triple(lookat.attribute("target")), triple(lookat.attribute("up")));
    let film = sensor.one("film");
    assert_eq!(film.attribute("type"), "hdrfilm");
    assert_eq!(film.one("rfilter").attribute("type"), "box");
    let width: f64 = film.property("integer", "width", &defaults).parse().unwrap();
    let height: f64 = film.property("integer", "height", &defaults).parse().unwrap();
    let fov_y: f64 = sensor.property("float", "fov", &defaults).parse().unwrap();

    let (origin, dir) = (DVec3::from(origin), (DVec3::from(target) - DVec3::from(origin)).normalize());
    let left = DVec3::from(up).cross(dir).normalize();
    let new_up = dir.cross(left);
    let q = point - origin;
    let camera = DVec3::new(q.dot(left), q.dot(new_up), q.dot(dir));
    let aspect = width / height;
    let fov_x = 2.0 * ((0.5 * fov_y.to_radians()).tan() * aspect).atan();
    let cot = 1.0 / (0.5 * fov_x).tan();
    let (clip_x, clip_y) = (cot * camera.x / camera.z, cot * camera.y / camera.z);
    let film_x = -0.5 * (clip_x - 1.0);
    let film_y = -0.5 * aspect * (clip_y - 1.0 / aspect);
    (film_x * width, film_y * height)
}

#[test]
fn a_point_lands_on_the_same_pixel_through_both_cameras() {
    let (mesh, mut manifest) = cornell();
    // An oblique camera with a tilted up vector and a wide film, so that a
    // mirrored axis, a swapped aspect or the wrong fov axis would show.
    manifest.camera.eye = [0.9, 0.4, -0.7];
    manifest.camera.target = [0.1, 0.2, 0.3];
    manifest.camera.up = [0.2, 1.0, 0.1];
    manifest.camera.vertical_fov_deg = 50.0;
    let params = Params { width: Some(320), height: Some(200), ..Params::default() };
    let scene = parse_xml(&export(&mesh, &manifest, &params, "scene", "").xml);
    let pinhole = stage_kit::scene::pinhole(&manifest.camera, 320, 200).unwrap();
    for (x, y) in [(0.5, 0.5), (319.5, 0.5), (0.5, 199.5), (319.5, 199.5), (160.0, 100.0), (40.25, 170.75), (300.0, 12.0)] {
        let point = pinhole.eye + 1.7 * pinhole.direction(x, y);
        let (mx, my) = mitsuba_pixel(&scene, point);
        assert!((mx - x).abs() < 1e-6 && (my - y).abs() < 1e-6, "pixel ({x}, {y}) lands on ({mx}, {my}) in Mitsuba");
    }
}

#[test]
fn what_mitsuba_cannot_render_exactly_is_listed() {
    let (mut mesh, mut manifest) = cornell();
    let base = manifest.materials[0].clone();
    let mut mirror = base.clone();
    (mirror.name, mirror.diffuse, mirror.specular_reflectance) = ("mirror".into(), [0.0; 3], [0.9, 0.8, 0.7]);
    let mut blend = base.clone();
    (blend.name, blend.diffuse, blend.specular_reflectance) = ("glossy".into(), [0.3, 0.2, 0.1], [0.5, 0.5, 0.4]);
    let mut glass = base.clone();
    (glass.name, glass.diffuse, glass.specular_transmittance) = ("glass".into(), [0.1; 3], [0.8; 3]);
    let mut textured = base.clone();
    (textured.name, textured.diffuse_map) = ("poster".into(), Some("poster.png".into()));
    let first = manifest.materials.len() as u32;
    manifest.materials.extend([mirror, blend, glass, textured]);
    for (i, t) in mesh.triangles.iter_mut().take(4).enumerate() {
        t.material = first + i as u32;
    }
    manifest.goniometric_lights.push(GoniometricLight {
        label: "lamp.ies".into(),
        position: [0.0; 3],
        nadir: [0.0, -1.0, 0.0],
        c0: [1.0, 0.0, 0.0],
        scale: 1.0,
        c_angles_deg: vec![0.0],
        gamma_angles_deg: vec![0.0, 180.0],
        intensity_cd: vec![1.0, 1.0],
        flux_lm: 4.0 * std::f64::consts::PI,
    });
    let exported = export(&mesh, &manifest, &Params::default(), "scene", "");
    let skipped = exported.skipped.join("\n");
    assert_eq!(exported.skipped.len(), 2, "{skipped}");
    assert!(skipped.contains("lamp.ies") && skipped.contains("'poster': diffuse texture"), "{skipped}");
    assert!(!skipped.contains("mirror") && !skipped.contains("glossy") && !skipped.contains("glass"), "mirrors and thin glass map exactly: {skipped}");

    let scene = parse_xml(&exported.xml);
    let defaults = defaults(&scene);
    let bsdf_of = |name: &str| scene.all("shape").find(|s| s.attribute("id").ends_with(name)).unwrap().one("bsdf");
    let mirror = bsdf_of("-mirror");
    assert_eq!(mirror.attribute("type"), "conductor");
    assert_eq!(mirror.property("string", "material", &defaults), "none");
    assert_eq!(triple(&mirror.property("rgb", "specular_reflectance", &defaults)), [0.9, 0.8, 0.7]);
    // (1 - w) rho' + w ks' reproduces both parts.
    let blend = bsdf_of("-glossy");
    assert_eq!(blend.attribute("type"), "blendbsdf");
    let w: f64 = blend.property("float", "weight", &defaults).parse().unwrap();
    let parts: Vec<&Node> = blend.all("bsdf").collect();
    assert_eq!((parts[0].attribute("type"), parts[1].attribute("type")), ("diffuse", "conductor"));
    let rho = triple(&parts[0].property("rgb", "reflectance", &defaults));
    let ks = triple(&parts[1].property("rgb", "specular_reflectance", &defaults));
    for k in 0..3 {
        assert!(close((1.0 - w) * rho[k], [0.3, 0.2, 0.1][k], 1e-12) && close(w * ks[k], [0.5, 0.5, 0.4][k], 1e-12));
        assert!(rho[k] <= 1.0 && ks[k] <= 1.0);
    }
}

fn binary() -> PathBuf {
    end_to_end::bin("export-mitsuba")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("export-mitsuba-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write_prepared(dir: &Path) -> (PathBuf, PathBuf) {
    let (mesh, manifest) = cornell();
    let (mesh_path, manifest_path) = (dir.join("mesh.exr"), dir.join("manifest.ron"));
    mesh.write(&mesh_path).unwrap();
    schemas::ron_io::write_ron(&manifest_path, &manifest).unwrap();
    (mesh_path, manifest_path)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn cli_writes_the_scene_and_its_meshes_with_provenance() {
    let dir = temp_dir("cli");
    let (mesh, manifest) = write_prepared(&dir);
    let (xml, report) = (dir.join("scene.xml"), dir.join("export.report.ron"));
    let out = Command::new(binary())
        .args(["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&xml), "--spp", "16", "--max-depth", "-1", "--report", s(&report)])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&xml).unwrap();
    let scene = parse_xml(&text);
    assert_eq!(defaults(&scene)["spp"], "16");
    assert!(text.contains(&schemas::header::sha256_hex(&std::fs::read(&mesh).unwrap())), "the input hashes are in the provenance comment");
    for shape in scene.all("shape") {
        let ply = dir.join(shape.property("string", "filename", &BTreeMap::new()));
        assert!(ply.starts_with(dir.join("scene")), "{}", ply.display());
        ply::decode(&std::fs::read(&ply).unwrap()).unwrap();
    }
    assert!(std::fs::read_to_string(&report).unwrap().contains("triangles"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cli_bad_input_is_one_line_exit_2_and_no_output() {
    let dir = temp_dir("bad");
    let (mesh, manifest) = write_prepared(&dir);
    std::fs::write(dir.join("broken.exr"), b"not an exr").unwrap();
    let xml = dir.join("scene.xml");
    for args in [
        vec!["--mesh", s(&dir.join("broken.exr")), "--manifest", s(&manifest), "-o", s(&xml)],
        vec!["--mesh", s(&mesh), "--manifest", s(&dir.join("missing.ron")), "-o", s(&xml)],
        vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&xml), "--sampler", "sobol"],
        vec!["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&dir.join("no/such/dir/scene.xml"))],
    ] {
        let out = Command::new(binary()).args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "one line: {stderr}");
        assert!(stderr.starts_with("export-mitsuba: error: "), "{stderr}");
        assert!(!xml.exists() && !dir.join("scene").exists(), "no partial output after {args:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
