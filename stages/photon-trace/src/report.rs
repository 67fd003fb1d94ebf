//! What a photon-trace run tells: the effects of the scene it does not
//! simulate, a summary line on stderr, and the report's counters (the
//! error against time among them) and notes.

use crate::{Params, Stage, Work};
use schemas::mesh::Effects;
use stage_kit::stage::Done;

/// What this stage does not simulate, for the effects the scene has.
pub fn skipped(effects: &Effects) -> Vec<String> {
    Effects::skipped(&[
        (effects.specular_reflection, "specular reflection: photons reflect off mirrors, but solution.exr holds diffuse radiosity only, so the preview shows a mirror's diffuse part"),
        (effects.specular_transmission, "specular transmission: photons pass through as through a thin sheet (no refraction: materials carry no index); the preview shows the glass's diffuse part"),
        (effects.diffuse_transmission, "diffuse transmission: not simulated by photon-trace"),
        (effects.textures, "textures: photons use each material's mean diffuse reflectance"),
        (effects.alpha_masks, "alpha masks: surfaces are treated as opaque"),
        (effects.normal_maps, "normal maps: photons bounce about geometric normals"),
    ])
}

/// Prints the run's summary (and a warning if it did not converge) on
/// stderr, and returns its report: the work's counters, the curve as
/// `curve.NNN.{stage,photons,seconds,max_error,mean_error}` (stage 1 =
/// stochastic, 3 = indirect), `skipped`, and notes ending with the
/// `snapshots`' own.
pub fn summarise(w: &Work, params: &Params, skipped: Vec<String>, snapshots: Vec<String>) -> Done {
    eprintln!(
        "photon-trace: {} + {} photons, {} splits, {} vertices, {} leaves; first image {:.2} s, direct done {:.2} s, final {:.2} s ({})",
        w.stage1_photons, w.stage3_photons, w.splits, w.vertices, w.leaves, w.first_image_s, w.direct_s, w.final_s, w.stopped_by
    );
    let mut notes = Vec::new();
    if !w.converged {
        let last = w.curve.last().map_or(f64::NAN, |p| p.max_error);
        let note = format!("target_error {} not reached: stopped by {} with a largest vertex error of {last:.3e}", params.target_error, w.stopped_by);
        eprintln!("photon-trace: warning: {note}");
        notes.push(note);
    }
    if w.capped_photons > 0 {
        notes.push(format!("{} photons reached max_bounces = {} and were dropped (their remaining power is lost)", w.capped_photons, params.max_bounces));
    }
    notes.extend(snapshots);
    let mut done = Done::counted([
        ("stage1_photons", w.stage1_photons as f64),
        ("stage3_photons", w.stage3_photons as f64),
        ("photon_rays", w.photon_rays as f64),
        ("direct_rays", w.direct_rays as f64),
        ("exposure_rays", w.exposure_rays as f64),
        ("capped_photons", w.capped_photons as f64),
        ("splits", w.splits as f64),
        ("elements", w.elements as f64),
        ("leaves", w.leaves as f64),
        ("vertices", w.vertices as f64),
        ("converged", f64::from(u8::from(w.converged))),
        ("first_image_s", w.first_image_s),
        ("stage1_s", w.stage1_s),
        ("direct_s", w.direct_s),
        ("final_s", w.final_s),
    ]);
    for (k, p) in w.curve.iter().enumerate() {
        let stage = if p.stage == Stage::Stochastic { 1.0 } else { 3.0 };
        for (field, value) in [("stage", stage), ("photons", p.photons as f64), ("seconds", p.seconds), ("max_error", p.max_error), ("mean_error", p.mean_error)] {
            done.counters.insert(format!("curve.{k:03}.{field}"), value);
        }
    }
    if let Some(p) = w.curve.last() {
        done.counters.insert("max_relative_error".to_string(), p.max_error);
        done.counters.insert("mean_relative_error".to_string(), p.mean_error);
    }
    done.skipped = skipped;
    done.notes = notes;
    done
}
