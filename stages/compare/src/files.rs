//! The comparison the binary makes: reads two files (images of this
//! pipeline or foreign EXRs, or two solutions), compares them with
//! [`crate::compare_images`] or [`crate::compare_solutions`], and gathers
//! the report's counters and notes, the difference picture and the
//! per-surface table.

use crate::{CompareError, Params, Which};
use schemas::header::Schema;
use schemas::image::HdrImage;
use schemas::mesh::Manifest;
use schemas::solution::Solution;
use schemas::Error;
use stage_kit::run::{bad_parameter, Run};
use std::collections::BTreeMap;
use std::path::Path;

/// Everything computed, nothing written yet.
pub struct Outcome {
    /// The report's counters.
    pub counters: BTreeMap<String, f64>,
    /// What was compared: images, or solutions per element or triangle.
    pub mode: &'static str,
    /// The metrics over every sample.
    pub metrics: crate::metrics::Metrics,
    /// Notes for the report.
    pub notes: Vec<String>,
    /// The difference picture (PNG), where asked.
    pub diff_png: Option<Vec<u8>>,
    /// Per-surface lines for stderr.
    pub table: Vec<String>,
}

/// `error` as a contract error naming the input it concerns.
fn named(error: CompareError, a: &Path, b: &Path) -> Error {
    let path = match error.which() {
        Which::A => a,
        Which::B => b,
    };
    Error::invalid(path, None, error.to_string())
}

/// Reads an image of this pipeline or a foreign EXR; a foreign one gets a
/// note (here and on stderr) that it carries no provenance.
fn read_image(path: &Path, run: &mut Run, notes: &mut Vec<String>) -> schemas::Result<HdrImage> {
    let (image, record, origin) = HdrImage::read_any(path)?;
    if let Some(note) = origin.foreign_note(path, &record) {
        eprintln!("compare: note: {note}");
        notes.push(note);
    }
    run.input(record)?;
    Ok(image)
}

/// Labels of object or material indices: the manifest's names where one
/// is given, else `#<index>`; [`schemas::image::NO_SURFACE`] never appears
/// (such pixels are not compared).
fn labeller(names: Option<Vec<String>>) -> impl Fn(u32) -> String {
    move |i| names.as_ref().and_then(|n| n.get(i as usize).cloned()).unwrap_or_else(|| format!("#{i}"))
}

/// What the binary was asked to compare.
pub struct Request<'a> {
    /// The approximation.
    pub a: &'a Path,
    /// The reference.
    pub b: &'a Path,
    /// The scene's manifest, naming objects and materials (images only).
    pub manifest: Option<&'a Path>,
    /// Where the difference picture goes, if drawn (images only).
    pub diff: Option<&'a Path>,
}

/// Reads the two inputs (recorded in `run`) and compares them: images, or
/// solutions where A is no image.
pub fn compare_files(request: &Request, params: &Params, run: &mut Run) -> schemas::Result<Outcome> {
    let (a, b) = (request.a, request.b);
    // The kind is decided by A: an image, or else (when A's schema says it
    // is no image) a solution; B must then be of the same kind.
    let mut notes = Vec::new();
    let image_a = match read_image(a, run, &mut notes) {
        Ok(image) => image,
        Err(image_error @ Error::Schema { .. }) => return compare_solution_files(request, params, run, image_error),
        Err(other) => return Err(other),
    };
    let image_b = read_image(b, run, &mut notes)?;
    let manifest = match request.manifest {
        Some(path) => {
            let loaded = schemas::ron_io::read_ron::<Manifest>(path)?;
            run.input(loaded.input)?;
            Some(loaded.value)
        }
        None => None,
    };
    let result = crate::compare_images(&image_a, &image_b, params).map_err(|e| named(e, a, b))?;
    if let (Some(m), Some((s, which))) = (&manifest, crate::images::surfaces(&image_a, &image_b)) {
        let out_of_range = |list: &[u32], len: usize| list.iter().any(|&i| i != schemas::image::NO_SURFACE && i as usize >= len);
        if out_of_range(&s.object, m.objects.len()) || out_of_range(&s.material, m.materials.len()) {
            let path = if which == Which::A { a } else { b };
            return Err(Error::invalid(path, None, "surface layer names objects or materials the manifest does not have: is it this image's scene?"));
        }
    }
    let diff_png = match request.diff {
        Some(path) => {
            let picture = crate::images::difference_picture(&image_a, &image_b, &result.compared, params.tau_max());
            let (w, h, pixels) = crate::scale_bar::with_scale_bar(image_b.width, image_b.height, &picture, params.tau_max());
            Some(stage_kit::png::encode_png(w, h, &pixels).map_err(|e| Error::invalid(path, None, e))?)
        }
        None => None,
    };
    if result.coverage_mismatches > 0 {
        notes.push(format!("{} pixels are covered in one image only", result.coverage_mismatches));
    }
    if let Some(which) = result.surfaces_from {
        notes.push(format!("surfaces (objects, materials, edges) from {}", if which == Which::A { "A" } else { "B" }));
    }
    let object_label = labeller(manifest.as_ref().map(|m| m.objects.clone()));
    let material_label = labeller(manifest.as_ref().map(|m| m.materials.iter().map(|m| m.name.clone()).collect()));
    let table = surface_table(&result, params.tau_max(), &object_label, &material_label);
    Ok(Outcome { counters: result.counters(&object_label, &material_label), mode: "images", metrics: result.metrics, notes, diff_png, table })
}

/// The per-object and per-material lines printed on stderr.
fn surface_table(result: &crate::ImageComparison, tau_max: f64, object: &dyn Fn(u32) -> String, material: &dyn Fn(u32) -> String) -> Vec<String> {
    let mut lines = Vec::new();
    for (group, list, label) in [("object", &result.by_object, object), ("material", &result.by_material, material)] {
        if list.is_empty() {
            continue;
        }
        let over_tau = format!("over {}", crate::scale_bar::percent(tau_max));
        lines.push(format!("  {group:<24} {:>8} {:>13} {:>12} {over_tau:>10}", "pixels", "relative_rmse", "mean_signed"));
        for (index, m) in list {
            let over = m.percent_over(tau_max);
            lines.push(format!("  {:<24} {:>8} {:>13.5} {:>+11.3}% {:>9.2}%", label(*index), m.samples, m.relative_rmse, 100.0 * m.mean_signed_error, over));
        }
    }
    lines
}

fn compare_solution_files(request: &Request, params: &Params, run: &mut Run, image_error: Error) -> schemas::Result<Outcome> {
    let (a, b) = (request.a, request.b);
    let (solution_a, record_a) = match Solution::read(a) {
        Ok(read) => read,
        Err(Error::Schema { .. }) => {
            let what =
                format!("is neither an '{}' nor a '{}' artifact ({image_error})", HdrImage::NAME, Solution::NAME);
            return Err(Error::schema(a, what));
        }
        Err(other) => return Err(other),
    };
    if request.diff.is_some() {
        return Err(bad_parameter("--diff applies to images only; the inputs are solutions"));
    }
    if params.exclusions().any() || request.manifest.is_some() {
        return Err(bad_parameter("--exclude-emitters, --exclude-edges and --manifest apply to images only; the inputs are solutions"));
    }
    run.input(record_a)?;
    let (solution_b, record_b) = Solution::read(b)?;
    run.input(record_b)?;
    let result = crate::compare_solutions(&solution_a, &solution_b, params).map_err(|e| named(e, a, b))?;
    Ok(Outcome {
        counters: result.counters(),
        mode: result.mode.describe(),
        metrics: result.metrics,
        notes: Vec::new(),
        diff_png: None,
        table: Vec::new(),
    })
}

