//! # export-mitsuba: the prepared scene as a Mitsuba 3 scene
//!
//! Writes `mesh.exr` + `manifest.ron` as a Mitsuba 3 XML scene
//! (`<scene version="3.0.0">`) with one binary little-endian PLY mesh per
//! material, so that a path tracer renders the same scene, through the same
//! camera, as this pipeline: the reference of `make bench-peer`.
//!
//! ## What maps to what
//!
//! | pipeline | Mitsuba 3 | exact? |
//! |---|---|---|
//! | triangles of one material | `<shape type="ply">`, `face_normals` true | yes: positions as stored (f32), winding kept |
//! | diffuse reflectance rho | `<bsdf type="diffuse">`, `<rgb name="reflectance">` | yes (RGB variants: no spectral upsampling) |
//! | emission (exitance M, W/m², front face) | `<emitter type="area">` nested in the shape, `radiance` = M / pi | yes: Lambertian, one-sided |
//! | ideal mirror ks (no diffuse part) | `<bsdf type="conductor">`, `material` `none`, `specular_reflectance` ks | yes: `none` disables Fresnel |
//! | thin glass pane tau_s (no other part) | `<bsdf type="thindielectric">`, `int_ior` = `ext_ior` = 1, `specular_transmittance` tau_s | yes ([`Bsdf::Pane`]) |
//! | diffuse rho + mirror ks + pane tau_s, two or three of them | nested `<bsdf type="blendbsdf">`: each specular part weighs its largest channel a and is written divided by it, the diffuse part takes the remaining weight 1 - sum a ([`blend`]) | yes where max rho <= 1 - sum a, else the specular parts that do not fit are not exported |
//! | two-sided material (a triangle and its reversed twin) | the triangle once, its BSDF inside `<bsdf type="twosided">` | yes: both faces reflect alike, as the twins do |
//! | two-sided pane | the pane alone, not wrapped (`thindielectric` transmits alike from both faces; Mitsuba's `twosided` refuses a transmitting BSDF) | the pane yes; a diffuse or mirror part beside it is not exported |
//! | diffuse transmission, texture, alpha and normal maps, goniometric lights | nothing | not exported: listed in the report's `skipped` and on stderr |
//! | manifest camera | `perspective`, `fov_axis` y, `<lookat origin target up>`, `hdrfilm` rgb float32, box filter | yes |
//!
//! Frames: the PLY positions and the camera are both in the mesh frame
//! (metres, the world translated by `-world_from_mesh_translation`), so the
//! Mitsuba world frame *is* the mesh frame and no transform is written.
//!
//! Orientation, checked against Mitsuba's sources: a PLY face's normal is
//! `normalize(cross(p1 - p0, p2 - p0))` (`Mesh::face_normal`), so this
//! pipeline's counter-clockwise-from-the-front triangles keep their front
//! face, and Mitsuba's area emitter (radiance only where `cos_theta(wi) > 0`)
//! and `diffuse` BSDF (zero below the surface) are one-sided on that front
//! face as this pipeline's surfaces are. The camera: Mitsuba's `look_at`
//! puts camera-space +x on `cross(up, dir)` (the *left* of the image) and
//! its perspective projection maps camera +x to film x = 0 (scale by -0.5):
//! film x grows to the right and film y downwards, row 0 at the top, as in
//! `radiometry::camera::Pinhole`, so the image is not mirrored.
//!
//! Parameters: [`Params`] (`--params`, flags override; the table is
//! `export-mitsuba --print-knobs`, in the README's "Stage knobs").
//!
//! ```no_run
//! use std::path::Path;
//! // The prepared Cornell box of `make` (mesh-prep's outputs).
//! let (mesh, _) = schemas::mesh::Mesh::read(Path::new("out/cornell/mesh.exr")).unwrap();
//! let manifest = schemas::ron_io::read_ron(Path::new("out/cornell/manifest.ron")).unwrap().value;
//! let export = export_mitsuba::export(&mesh, &manifest, &export_mitsuba::Params::default(), "scene", "");
//! assert!(export.xml.contains(r#"<scene version="3.0.0">"#));
//! assert_eq!(export.meshes.iter().map(|m| m.triangles).sum::<usize>(), mesh.triangles.len());
//! ```

pub mod files;
pub mod ply;
pub mod xml;

use radiometry::color::max_channel;
use schemas::mesh::{Manifest, Material, Mesh, MeshStatistics};
use stage_kit::knobs::{Check, Describe};
use std::fmt::Write as _;
use xml::{attribute, comment};

/// The sampler plugins of Mitsuba 3 that take `sample_count` and `seed`.
pub const SAMPLERS: &[&str] = &["independent", "stratified", "multijitter", "orthogonal", "ldsampler"];

stage_kit::knobs! {
    /// The exporter's parameters.
    pub struct Params {
        /// Samples per pixel (the scene's `spp` default; `-Dspp=N` overrides it).
        spp: u32 = 64, "samples", value(at_least(1));
        /// Longest path of the `path` integrator; -1: unbounded.
        max_depth: i32 = -1, "", value(custom("-1 (unbounded) or at least 1", |d: &i32| *d == -1 || *d >= 1));
        /// Mitsuba sampler plugin.
        sampler: String = "multijitter".into(), "", value(OneOfSamplers);
        /// The sampler's seed.
        seed: u32 = 0, "", value;
        /// Film width (none: the manifest camera's).
        width: Option<u32> = None, "pixels", optional(at_least(1));
        /// Film height (none: the manifest camera's).
        height: Option<u32> = None, "pixels", optional(at_least(1));
    }
}

/// The range of the `sampler` knob: one of [`SAMPLERS`].
pub struct OneOfSamplers;

impl Describe for OneOfSamplers {
    fn text(&self) -> String {
        format!("one of {}", SAMPLERS.join(", "))
    }
}

impl Check<String> for OneOfSamplers {
    fn admits(&self, sampler: &String) -> bool {
        SAMPLERS.contains(&sampler.as_str())
    }
}

/// One PLY file of the export: the triangles of one material.
#[derive(Clone, Debug, PartialEq)]
pub struct PlyMesh {
    /// File name inside the mesh folder, e.g. `m003-white.ply`.
    pub file_name: String,
    /// Index of the material in the manifest.
    pub material: usize,
    /// Triangles in the file.
    pub triangles: usize,
    /// Vertices in the file (welded within the material).
    pub vertices: usize,
    /// The file's bytes (binary little-endian PLY).
    pub bytes: Vec<u8>,
}

/// The exported scene, in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct Export {
    /// The XML scene text.
    pub xml: String,
    /// The PLY meshes it references, relative to the XML's directory as
    /// `<mesh_folder>/<file_name>`.
    pub meshes: Vec<PlyMesh>,
    /// What could not be exported exactly, one line each.
    pub skipped: Vec<String>,
    /// Area emitters written.
    pub emitters: usize,
    /// Film size written.
    pub film: (u32, u32),
}

/// The BSDF a material exports to, or why part of it does not.
#[derive(Clone, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian reflector, reflectance rho.
    Diffuse([f64; 3]),
    /// Ideal mirror (Fresnel off), reflectance ks.
    Mirror([f64; 3]),
    /// Thin glass pane, transmittance tau_s: light goes straight through,
    /// scaled by tau_s, whatever its angle and side, and nothing is
    /// reflected. This pipeline's pane (paper 004 Sec. 4.3.3: a thin plate,
    /// refraction neglected; README "Mirrors and glass") is exactly that,
    /// and so is Mitsuba's `thindielectric` with equal interior and
    /// exterior indices: its Fresnel reflectance is then 0, its
    /// transmission 1 times `specular_transmittance`, and a thin slab does
    /// not bend the ray. A `dielectric` would bend it (and reflect by
    /// Fresnel); `null` cannot scale what it lets through. The pane's
    /// reflectance, if any, is a [`Bsdf::Mirror`] part beside it.
    Pane([f64; 3]),
    /// `(1 - weight) first + weight second`.
    Blend {
        /// Weight of `second`.
        weight: f64,
        /// The part weighted `1 - weight`.
        first: Box<Bsdf>,
        /// The part weighted `weight`.
        second: Box<Bsdf>,
    },
}

fn scaled(v: [f64; 3], s: f64) -> [f64; 3] {
    [v[0] * s, v[1] * s, v[2] * s]
}

/// `sum_i w_i part_i` as nested two-part blends, for parts `(w_i,
/// part_i)` whose weights sum to 1 (the first part's weight is what the
/// others leave): the blend of the first `k` parts takes part `k + 1` with
/// weight `w_{k+1} / (w_1 + ... + w_{k+1})`.
pub fn blend(parts: Vec<(f64, Bsdf)>) -> Bsdf {
    let mut parts = parts.into_iter();
    let (mut total, mut bsdf) = parts.next().expect("a blend of at least one part");
    for (w, part) in parts {
        total += w;
        bsdf = Bsdf::Blend { weight: w / total, first: Box::new(bsdf), second: Box::new(part) };
    }
    bsdf
}

/// The Mitsuba BSDF of `material`, and a line for each part of it that has
/// no exact Mitsuba equivalent (those parts are left out). A specular part
/// of largest channel `a` is written as `a x part(coefficient / a)`, the
/// diffuse part as `(1 - sum a) x diffuse(rho / (1 - sum a))` ([`blend`]);
/// a part alone keeps its coefficients.
pub fn material_bsdf(material: &Material) -> (Bsdf, Vec<String>) {
    let name = &material.name;
    let mut skipped = Vec::new();
    let rho = material.diffuse;
    let (ks, tau) = (material.specular_reflectance, material.specular_transmittance);
    let rho_max = max_channel(rho);
    // A two-sided pane: Mitsuba's `twosided` cannot hold it, and the pane
    // alone is symmetric, so it is written alone.
    let pane_alone = material.two_sided && max_channel(tau) > 0.0;
    let rho_fit = if pane_alone { 0.0 } else { rho_max };
    let mut specular: Vec<(f64, Bsdf)> = Vec::new();
    for (coefficients, what, part) in [(ks, "specular reflectance", Bsdf::Mirror as fn([f64; 3]) -> Bsdf), (tau, "specular transmittance", Bsdf::Pane)] {
        let a = max_channel(coefficients);
        if a <= 0.0 {
            continue;
        }
        let taken: f64 = specular.iter().map(|(w, _)| w).sum();
        if pane_alone && what == "specular reflectance" {
            skipped.push(format!("material '{name}': specular reflectance {ks:?} not exported (a two-sided pane is written alone: Mitsuba's twosided cannot hold a transmitting BSDF)"));
        } else if rho_fit <= 1.0 - taken - a {
            specular.push((a, part(scaled(coefficients, 1.0 / a))));
        } else {
            skipped.push(format!(
                "material '{name}': {what} {coefficients:?} not exported (no blend weight fits beside diffuse {rho:?}); written without it"
            ));
        }
    }
    if pane_alone && rho_max > 0.0 {
        skipped.push(format!("material '{name}': diffuse reflectance {rho:?} not exported (a two-sided pane is written alone: Mitsuba's twosided cannot hold a transmitting BSDF)"));
    }
    let rest = 1.0 - specular.iter().map(|(w, _)| w).sum::<f64>();
    let bsdf = match specular.len() {
        0 => Bsdf::Diffuse(rho),
        1 if pane_alone || rho_max <= 0.0 => match specular.remove(0).1 {
            Bsdf::Mirror(_) => Bsdf::Mirror(ks),
            _ => Bsdf::Pane(tau),
        },
        _ => {
            let diffuse = if rest > 0.0 { vec![(rest, Bsdf::Diffuse(scaled(rho, 1.0 / rest)))] } else { Vec::new() };
            blend(diffuse.into_iter().chain(specular).collect())
        }
    };
    if max_channel(material.diffuse_transmittance) > 0.0 {
        skipped.push(format!(
            "material '{name}': diffuse transmittance {:?} not exported (Mitsuba 3 has no diffuse transmitter); written without it",
            material.diffuse_transmittance
        ));
    }
    for (map, what) in [(&material.diffuse_map, "diffuse texture"), (&material.alpha_map, "alpha mask"), (&material.normal_map, "normal map")] {
        if let Some(file) = map {
            skipped.push(format!("material '{name}': {what} {file:?} not exported (the mesh has no texture coordinates)"));
        }
    }
    (bsdf, skipped)
}

/// A file-name-safe form of `name`: ASCII letters, digits, `-` and `_`.
pub fn safe_name(name: &str) -> String {
    let s: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    if s.is_empty() {
        "unnamed".into()
    } else {
        s
    }
}

/// Three numbers as Mitsuba's `rgb` values and `lookat` points take them.
fn triple(v: [f64; 3]) -> String {
    format!("{}, {}, {}", v[0], v[1], v[2])
}

/// Writes `bsdf` at `indent`, with `name` (a blend's `bsdf_0`, `bsdf_1`)
/// where given.
fn write_bsdf(out: &mut String, bsdf: &Bsdf, indent: &str, name: &str) {
    let open = |kind: &str| format!("{indent}<bsdf type=\"{kind}\"{name}>");
    match bsdf {
        Bsdf::Diffuse(rho) => {
            let _ = writeln!(out, "{}", open("diffuse"));
            let _ = writeln!(out, "{indent}    <rgb name=\"reflectance\" value=\"{}\"/>", triple(*rho));
        }
        Bsdf::Mirror(ks) => {
            let _ = writeln!(out, "{}", open("conductor"));
            let _ = writeln!(out, "{indent}    <string name=\"material\" value=\"none\"/>");
            let _ = writeln!(out, "{indent}    <rgb name=\"specular_reflectance\" value=\"{}\"/>", triple(*ks));
        }
        Bsdf::Pane(tau) => {
            let _ = writeln!(out, "{}", open("thindielectric"));
            let _ = writeln!(out, "{indent}    <float name=\"int_ior\" value=\"1\"/>");
            let _ = writeln!(out, "{indent}    <float name=\"ext_ior\" value=\"1\"/>");
            let _ = writeln!(out, "{indent}    <rgb name=\"specular_transmittance\" value=\"{}\"/>", triple(*tau));
        }
        Bsdf::Blend { weight, first, second } => {
            let _ = writeln!(out, "{}", open("blendbsdf"));
            let _ = writeln!(out, "{indent}    <float name=\"weight\" value=\"{weight}\"/>");
            let inner = format!("{indent}    ");
            write_bsdf(out, first, &inner, " name=\"bsdf_0\"");
            write_bsdf(out, second, &inner, " name=\"bsdf_1\"");
        }
    }
    let _ = writeln!(out, "{indent}</bsdf>");
}

/// Clip distances that keep every point of the scene visible: Mitsuba
/// clips at `near_clip` (default 1 cm) and `far_clip` (default 10 km),
/// this pipeline's camera does not clip.
fn clip_range(statistics: &MeshStatistics, eye: [f64; 3]) -> (f64, f64) {
    let (lo, hi) = (statistics.bounds_min, statistics.bounds_max);
    let far = (0..3).map(|k| (eye[k] - lo[k]).abs().max((eye[k] - hi[k]).abs()).powi(2)).sum::<f64>().sqrt();
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let far_clip = (2.0 * far).max(1e4);
    let near_clip = (1e-5 * diagonal).clamp(1e-7, 1e-2);
    (near_clip, far_clip)
}

/// Exports `mesh` + `manifest`: the XML text (PLY files referenced as
/// `mesh_folder/<file>`, relative to the XML's directory) with
/// `provenance` (any text) in a comment at its top, the PLY files, and
/// what was not exported. `params` must be in their ranges
/// ([`stage_kit::knobs::Knobs::check`]).
pub fn export(mesh: &Mesh, manifest: &Manifest, params: &Params, mesh_folder: &str, provenance: &str) -> Export {
    let camera = &manifest.camera;
    let film = (params.width.unwrap_or(camera.width), params.height.unwrap_or(camera.height));
    let mut skipped = Vec::new();
    for light in &manifest.goniometric_lights {
        skipped.push(format!(
            "goniometric light {:?} at {:?} not exported (Mitsuba 3 has no goniometric emitter)",
            light.label, light.position
        ));
    }

    // Triangles by material, vertices welded within each material.
    let mut by_material: Vec<Vec<usize>> = vec![Vec::new(); manifest.materials.len()];
    for (i, t) in mesh.triangles.iter().enumerate() {
        by_material[t.material as usize].push(i);
    }
    let twins = mesh.twins();
    let mut meshes = Vec::new();
    let mut shapes = String::new();
    let mut emitters = 0;
    for (m, triangles) in by_material.iter().enumerate() {
        if triangles.is_empty() {
            continue;
        }
        let material = &manifest.materials[m];
        let file_name = format!("m{m:03}-{}.ply", safe_name(&material.name));
        let mut local = vec![u32::MAX; mesh.positions.len()];
        let mut positions: Vec<[f32; 3]> = Vec::new();
        let mut faces: Vec<[u32; 3]> = Vec::with_capacity(triangles.len());
        for &t in triangles {
            // A two-sided triangle's twin is the same surface for Mitsuba's
            // `twosided` BSDF; exported twice, the two would z-fight: the
            // earlier of the pair is written.
            if material.two_sided && twins[t].is_some_and(|j| (j as usize) < t && mesh.triangles[j as usize].material == m as u32) {
                continue;
            }
            let face = mesh.triangles[t].vertices.map(|v| {
                let slot = &mut local[v as usize];
                if *slot == u32::MAX {
                    *slot = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                *slot
            });
            faces.push(face);
        }
        let bytes = ply::encode(&positions, &faces, &format!("material {} of the pipeline's manifest", m));
        let (bsdf, material_skipped) = material_bsdf(material);
        skipped.extend(material_skipped);

        let _ = writeln!(shapes, "    <shape type=\"ply\" id={}>", attribute(&format!("m{m:03}-{}", safe_name(&material.name))));
        let _ = writeln!(shapes, "        <string name=\"filename\" value={}/>", attribute(&format!("{mesh_folder}/{file_name}")));
        let _ = writeln!(shapes, "        <boolean name=\"face_normals\" value=\"true\"/>");
        if material.two_sided && !matches!(bsdf, Bsdf::Pane(_)) {
            let _ = writeln!(shapes, "        <bsdf type=\"twosided\">");
            write_bsdf(&mut shapes, &bsdf, "            ", "");
            let _ = writeln!(shapes, "        </bsdf>");
        } else {
            write_bsdf(&mut shapes, &bsdf, "        ", "");
        }
        if max_channel(material.emission) > 0.0 {
            let radiance = scaled(material.emission, 1.0 / std::f64::consts::PI);
            let _ = writeln!(shapes, "        <emitter type=\"area\">");
            let _ = writeln!(shapes, "            <rgb name=\"radiance\" value=\"{}\"/>", triple(radiance));
            let _ = writeln!(shapes, "        </emitter>");
            emitters += 1;
        }
        let _ = writeln!(shapes, "    </shape>");
        meshes.push(PlyMesh { file_name, material: m, triangles: faces.len(), vertices: positions.len(), bytes });
    }

    let (near_clip, far_clip) = clip_range(&manifest.statistics, camera.eye);
    let mut xml = String::new();
    let _ = writeln!(xml, "<?xml version=\"1.0\" encoding=\"utf-8\"?>");
    xml.push_str(&comment(&format!(
        "Exported by export-mitsuba from this radiosity pipeline's prepared scene.\n\
         Frame: the mesh frame (metres) of mesh.exr and manifest.ron, used as Mitsuba's world\n\
         frame as it is: no transform. World position of its origin: {:?}.\n\
         Emitters: radiance = exitance / pi (Lambertian, front face = counter-clockwise).\n\
         Provenance (RON; XML comments cannot hold two hyphens in a row, so each '-' that\n\
         follows a '-' is written as '&#45;'):\n{provenance}",
        manifest.world_from_mesh_translation
    )));
    if !skipped.is_empty() {
        xml.push_str(&comment(&format!("Not exported:\n{}", skipped.join("\n"))));
    }
    let _ = writeln!(xml, "<scene version=\"3.0.0\">");
    let _ = writeln!(xml, "    <default name=\"spp\" value=\"{}\"/>", params.spp);
    let _ = writeln!(xml, "    <default name=\"max_depth\" value=\"{}\"/>", params.max_depth);
    let _ = writeln!(xml, "    <integrator type=\"path\">");
    let _ = writeln!(xml, "        <integer name=\"max_depth\" value=\"$max_depth\"/>");
    let _ = writeln!(xml, "    </integrator>");
    let _ = writeln!(xml, "    <sensor type=\"perspective\">");
    let _ = writeln!(xml, "        <string name=\"fov_axis\" value=\"y\"/>");
    let _ = writeln!(xml, "        <float name=\"fov\" value=\"{}\"/>", camera.vertical_fov_deg);
    let _ = writeln!(xml, "        <float name=\"near_clip\" value=\"{near_clip}\"/>");
    let _ = writeln!(xml, "        <float name=\"far_clip\" value=\"{far_clip}\"/>");
    let _ = writeln!(xml, "        <transform name=\"to_world\">");
    let _ = writeln!(
        xml,
        "            <lookat origin=\"{}\" target=\"{}\" up=\"{}\"/>",
        triple(camera.eye),
        triple(camera.target),
        triple(camera.up)
    );
    let _ = writeln!(xml, "        </transform>");
    let _ = writeln!(xml, "        <sampler type={}>", attribute(&params.sampler));
    let _ = writeln!(xml, "            <integer name=\"sample_count\" value=\"$spp\"/>");
    let _ = writeln!(xml, "            <integer name=\"seed\" value=\"{}\"/>", params.seed);
    let _ = writeln!(xml, "        </sampler>");
    let _ = writeln!(xml, "        <film type=\"hdrfilm\">");
    let _ = writeln!(xml, "            <integer name=\"width\" value=\"{}\"/>", film.0);
    let _ = writeln!(xml, "            <integer name=\"height\" value=\"{}\"/>", film.1);
    let _ = writeln!(xml, "            <string name=\"pixel_format\" value=\"rgb\"/>");
    let _ = writeln!(xml, "            <string name=\"component_format\" value=\"float32\"/>");
    let _ = writeln!(xml, "            <rfilter type=\"box\"/>");
    let _ = writeln!(xml, "        </film>");
    let _ = writeln!(xml, "    </sensor>");
    xml.push_str(&shapes);
    let _ = writeln!(xml, "</scene>");
    Export { xml, meshes, skipped, emitters, film }
}
