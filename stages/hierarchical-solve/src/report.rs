//! What a solve's report says: its work counters, the note of a solve the
//! iteration cap stopped, and what the stage does not simulate of the
//! scene's effects.

use crate::transmission::Transmission;
use crate::{Params, Work};
use schemas::mesh::{Effects, Manifest, Mesh};
use stage_kit::stage::Done;

/// The report of a solve that did `work` on `mesh` and `manifest` with
/// `params`; `surface`: whether surface.exr was given, `clustered`: whether
/// a cluster hierarchy was.
pub fn done(work: &Work, params: &Params, mesh: &Mesh, manifest: &Manifest, surface: bool, clustered: bool) -> Done {
    let w = work;
    let mut done = Done::counted([
        ("passes", w.passes as f64),
        ("links", w.links as f64),
        ("resolved_links", w.resolved_links as f64),
        ("opened_leaves", w.opened_leaves as f64),
        ("part_visibility_rays", w.part_rays as f64),
        ("cluster_links", w.cluster_links as f64),
        ("elements", w.elements as f64),
        ("leaves", w.leaves as f64),
        ("form_factors", w.form_factors as f64),
        ("rays", w.rays as f64),
        ("iterations", w.iterations as f64),
        ("relative_change", w.relative_change),
        ("converged", f64::from(u8::from(w.converged))),
        ("capped_passes", w.capped_passes as f64),
        ("extrapolations", w.extrapolations as f64),
        ("refine_seconds", w.refine_seconds),
        ("visibility_seconds", w.visibility_seconds),
        ("gather_seconds", w.gather_seconds),
        ("luminaires", manifest.goniometric_lights.len() as f64),
        ("luminaire_rays", w.luminaire_rays as f64),
        ("exposure_rays", w.exposure_rays as f64),
        ("luminaire_seconds", w.luminaire_seconds),
        ("visibility_rays_per_second", w.rays as f64 / w.visibility_seconds.max(1e-9)),
    ]);
    let mut count = |name: &str, value: f64| done.counters.insert(name.to_string(), value);
    // Only where the scene has mirrors or panes; the bound where finite.
    if manifest.effects.specular_reflection || manifest.effects.specular_transmission {
        count("specular_couplings", w.specular_couplings as f64);
        count("specular_rays", w.specular_rays as f64);
        count("specular_seconds", w.specular_seconds);
        if w.specular_truncation.is_finite() {
            count("specular_truncation_bound", w.specular_truncation);
        }
    }
    if w.links_capped {
        done.notes.push(format!(
            "refinement stopped at max_links = {} ({} links kept): links the error bound would split were kept, so the solution errs by more than eps = {:e} allows; raise --max-links (about 600 bytes a link) or eps",
            params.max_links, w.links, params.eps
        ));
    }
    if w.specular_windows_left_out > 0 {
        done.notes.push(format!(
            "specular light not simulated: the mirrors and panes lie in {} planes, more than the {} whose couplings a solve traces (a curved mirror or pane is one plane per facet); they reflect diffusely only",
            w.specular_windows_left_out,
            crate::mirrors::MAX_WINDOWS
        ));
    }
    // Left out where unknown (no contraction below 1 was known).
    for (name, value) in [("error_bound", w.error_bound), ("contraction", w.contraction)] {
        if value.is_finite() {
            count(name, value);
        }
    }
    if !w.converged {
        done.notes.push(format!(
            "tolerance not reached: the last pass stopped at max_iterations = {} with a remaining-error bound of {:.3e} of the largest radiosity (tolerance {:.1e}, contraction {:.6}); raise --max-iterations",
            params.max_iterations, w.error_bound, params.tolerance, w.contraction
        ));
    }
    let one_sided = Transmission::new(mesh, manifest).map_or(0, |t| t.one_sided);
    done.skipped = skipped(&manifest.effects, surface, one_sided, w.specular_windows_left_out == 0);
    if !clustered && manifest.effects.fine_clustered_geometry {
        done.skipped.push("clustering: no --clusters given; every pair of input triangles starts linked".to_string());
    }
    done
}

/// What this stage does not simulate, for the effects the scene has;
/// `surface`: whether surface.exr was given (textures, alpha masks and
/// normal maps are simulated from it); `one_sided`: triangles of
/// translucent materials that are not two-sided (they cannot transmit);
/// `specular`: whether the mirrors and panes were traced (the limits of
/// that tracing are listed only then; where they were left out, the note
/// says so).
fn skipped(effects: &Effects, surface: bool, one_sided: usize, specular: bool) -> Vec<String> {
    let transmits = format!("diffuse transmission: {one_sided} triangles of translucent materials that are not two-sided transmit nothing (their back face has no elements; make the material two_sided)");
    Effects::skipped(&[
        (!effects.diffuse_interreflection, "interreflection passes: no surface both receives light and reflects it; direct light only"),
        (specular && effects.specular_reflection, "specular reflection: planar mirrors by virtual senders, up to --specular-depth mirrors and panes per path (light meeting one more stops there), senders at their elements' mean radiosity --specular-sender-level levels down; no glossy reflection (a curved mirror is its facets), goniometric lights not mirrored"),
        (specular && effects.specular_transmission, "specular transmission: thin panes by transmitted senders, in the chains of up to --specular-depth mirrors and panes per path; no refraction bending by thick glass (a pane is a thin plate: light goes straight through)"),
        (effects.diffuse_transmission && one_sided > 0, &transmits),
        (effects.textures && !surface, "textures: no --surface given; radiosity uses each material's diffuse reflectance"),
        (effects.alpha_masks && !surface, "alpha masks: no --surface given; surfaces are treated as opaque"),
        (effects.normal_maps && !surface, "normal maps: no --surface given; radiosity uses geometric normals"),
    ])
}
