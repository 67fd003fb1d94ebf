//! export-mitsuba's materials as Mitsuba reads them: the built-in Cornell
//! box with its first triangles given panes, mirrors and their blends,
//! exported and parsed back; each BSDF's coefficients are the material's,
//! and what a blend cannot hold is skipped and said.

use export_mitsuba::{export, Params};
use quick_xml::events::Event;
use schemas::mesh::Material;

/// An XML element: its tag, attributes and children.
#[derive(Clone)]
struct Element {
    tag: String,
    attributes: Vec<(String, String)>,
    children: Vec<Element>,
}

impl Element {
    fn attribute(&self, name: &str) -> &str {
        self.attributes.iter().find(|(k, _)| k == name).map_or("", |(_, v)| v)
    }
    /// The numbers of child `<kind name="name" value="...">`.
    fn numbers(&self, kind: &str, name: &str) -> Vec<f64> {
        let child = self.children.iter().find(|c| c.tag == kind && c.attribute("name") == name).unwrap_or_else(|| panic!("no {kind} {name} in {}", self.tag));
        child.attribute("value").split(',').map(|x| x.trim().parse().unwrap()).collect()
    }
}

fn parse(xml: &str) -> Element {
    let mut reader = quick_xml::Reader::from_str(xml);
    let mut stack = vec![Element { tag: "root".into(), attributes: Vec::new(), children: Vec::new() }];
    let element = |e: &quick_xml::events::BytesStart| Element {
        tag: String::from_utf8(e.name().as_ref().to_vec()).unwrap(),
        attributes: e.attributes().map(|a| a.unwrap()).map(|a| (String::from_utf8(a.key.as_ref().to_vec()).unwrap(), a.unescape_value().unwrap().into_owned())).collect(),
        children: Vec::new(),
    };
    loop {
        match reader.read_event().unwrap() {
            Event::Start(e) => stack.push(element(&e)),
            Event::Empty(e) => stack.last_mut().unwrap().children.push(element(&e)),
            Event::End(_) => {
                let done = stack.pop().unwrap();
                stack.last_mut().unwrap().children.push(done);
            }
            Event::Eof => return stack.pop().unwrap(),
            _ => {}
        }
    }
}

/// What a written BSDF does, as the pipeline's coefficients: `[rho_d,
/// rho_s, tau_s]`, each part's own coefficients checked to be at most
/// 1 (Mitsuba clamps nothing, but a part over 1 would create energy).
fn coefficients(bsdf: &Element) -> [[f64; 3]; 3] {
    let rgb = |name: &str| {
        let v = bsdf.numbers("rgb", name);
        assert!(v.iter().all(|&x| (0.0..=1.0).contains(&x)), "{} {name} {v:?}", bsdf.attribute("type"));
        [v[0], v[1], v[2]]
    };
    let bsdfs: Vec<&Element> = bsdf.children.iter().filter(|c| c.tag == "bsdf").collect();
    match bsdf.attribute("type") {
        "diffuse" => [rgb("reflectance"), [0.0; 3], [0.0; 3]],
        "conductor" => {
            assert_eq!(bsdf.children.iter().find(|c| c.attribute("name") == "material").unwrap().attribute("value"), "none", "Fresnel must be off");
            [[0.0; 3], rgb("specular_reflectance"), [0.0; 3]]
        }
        "thindielectric" => {
            assert_eq!(bsdf.numbers("float", "int_ior"), bsdf.numbers("float", "ext_ior"), "equal indices: no Fresnel reflection");
            [[0.0; 3], [0.0; 3], rgb("specular_transmittance")]
        }
        "blendbsdf" => {
            let w = bsdf.numbers("float", "weight")[0];
            assert!((0.0..=1.0).contains(&w) && bsdfs.len() == 2);
            let (a, b) = (coefficients(bsdfs[0]), coefficients(bsdfs[1]));
            std::array::from_fn(|k| std::array::from_fn(|c| (1.0 - w) * a[k][c] + w * b[k][c]))
        }
        "twosided" => coefficients(bsdfs[0]),
        other => panic!("unexpected bsdf {other}"),
    }
}

fn material(name: &str, diffuse: [f64; 3], specular_reflectance: [f64; 3], specular_transmittance: [f64; 3], two_sided: bool) -> Material {
    Material { specular_reflectance, specular_transmittance, two_sided, ..Material::diffuse(name, diffuse, [0.0; 3]) }
}

/// The Cornell box with its first triangles given `materials`, exported
/// and parsed: each material's BSDF element and what it does, and what
/// was skipped.
fn exported(materials: &[Material]) -> (Vec<Element>, Vec<[[f64; 3]; 3]>, Vec<String>) {
    let (mut mesh, mut manifest) = mesh_prep::prepare_builtin("cornell-box", "test").unwrap();
    let first = manifest.materials.len();
    manifest.materials.extend(materials.iter().cloned());
    for (i, t) in mesh.triangles.iter_mut().take(materials.len()).enumerate() {
        t.material = (first + i) as u32;
    }
    let export = export(&mesh, &manifest, &Params::default(), "scene", "");
    let root = parse(&export.xml);
    let scene = root.children.iter().find(|c| c.tag == "scene").unwrap();
    let bsdfs: Vec<Element> = (first..first + materials.len())
        .map(|m| {
            let shape = scene.children.iter().find(|s| s.tag == "shape" && s.attribute("id").starts_with(&format!("m{m:03}-"))).unwrap();
            shape.children.iter().find(|c| c.tag == "bsdf").unwrap().clone()
        })
        .collect();
    let found = bsdfs.iter().map(coefficients).collect();
    (bsdfs, found, export.skipped)
}

fn assert_close(found: [[f64; 3]; 3], expected: [[f64; 3]; 3], what: &str) {
    for k in 0..3 {
        for c in 0..3 {
            assert!((found[k][c] - expected[k][c]).abs() <= 1e-12, "{what}: part {k} channel {c}: {} written, {} wanted ({found:?})", found[k][c], expected[k][c]);
        }
    }
}

#[test]
fn a_pane_and_a_mirror_keep_their_coefficients() {
    let (pane, mirror) = ([0.6, 0.5, 0.4], [0.9, 0.8, 0.7]);
    let materials = [material("pane", [0.0; 3], [0.0; 3], pane, false), material("mirror", [0.0; 3], mirror, [0.0; 3], false)];
    let (bsdfs, found, skipped) = exported(&materials);
    assert!(skipped.is_empty(), "{skipped:?}");
    assert_close(found[0], [[0.0; 3], [0.0; 3], pane], "pane");
    assert_close(found[1], [[0.0; 3], mirror, [0.0; 3]], "mirror");
    // The pane alone is a thindielectric of equal indices (tau_s straight
    // through), the mirror a Fresnel-free conductor, both unscaled.
    assert_eq!(bsdfs[0].attribute("type"), "thindielectric");
    assert_eq!((bsdfs[0].numbers("float", "int_ior"), bsdfs[0].numbers("float", "ext_ior")), (vec![1.0], vec![1.0]));
    assert_eq!(bsdfs[0].numbers("rgb", "specular_transmittance"), pane.to_vec());
    assert_eq!((bsdfs[1].attribute("type"), bsdfs[1].numbers("rgb", "specular_reflectance")), ("conductor", mirror.to_vec()));
}

#[test]
fn diffuse_mirror_and_pane_blend_to_the_same_coefficients() {
    // rho 0.2 + rho_s 0.3 + tau_s 0.4 (largest channels) fit in 1; the
    // channels differ so that each part is scaled, not copied.
    let (rho, ks, tau) = ([0.2, 0.1, 0.05], [0.3, 0.25, 0.2], [0.4, 0.35, 0.1]);
    let materials = [
        material("window", rho, ks, tau, false),
        material("tinted", [0.0; 3], ks, tau, false),
        material("frosted", rho, [0.0; 3], tau, false),
        material("two-sided pane", [0.0; 3], [0.0; 3], tau, true),
    ];
    let (bsdfs, found, skipped) = exported(&materials);
    assert!(skipped.is_empty(), "{skipped:?}");
    assert_eq!((bsdfs[0].attribute("type"), bsdfs[3].attribute("type")), ("blendbsdf", "thindielectric"), "a two-sided pane is not wrapped in twosided");
    assert_close(found[0], [rho, ks, tau], "diffuse + mirror + pane");
    assert_close(found[1], [[0.0; 3], ks, tau], "mirror + pane");
    assert_close(found[2], [rho, [0.0; 3], tau], "diffuse + pane");
    assert_close(found[3], [[0.0; 3], [0.0; 3], tau], "two-sided pane");
}

#[test]
fn what_a_blend_cannot_hold_is_skipped_and_the_rest_kept() {
    // Red diffuse 0.7 beside a blue mirror 0.5: per channel they conserve
    // energy, but no convex blend holds both (0.7 + 0.5 > 1).
    let (rho, ks, tau) = ([0.7, 0.1, 0.1], [0.1, 0.1, 0.5], [0.2; 3]);
    let materials = [material("odd", rho, ks, [0.0; 3], false), material("sheet", [0.3; 3], ks, tau, true)];
    let (_, found, skipped) = exported(&materials);
    assert_close(found[0], [rho, [0.0; 3], [0.0; 3]], "diffuse kept");
    assert_close(found[1], [[0.0; 3], [0.0; 3], tau], "two-sided pane written alone");
    assert_eq!(skipped.len(), 3, "{skipped:?}");
    assert!(skipped[0].contains("'odd': specular reflectance") && skipped[1].contains("'sheet': specular reflectance") && skipped[2].contains("'sheet': diffuse reflectance"), "{skipped:?}");
}
