//! What a run reports: the summary line, the report's counters, the
//! effects the stage does not simulate, and the note when the shooting
//! stopped before its threshold.

use crate::{Params, Structured};
use schemas::mesh::Effects;
use schemas::samples::Reason;
use stage_kit::stage::Done;

impl Structured {
    /// Samples placed for `reason`.
    fn count(&self, reason: Reason) -> usize {
        self.work.samples_by_reason[reason as usize]
    }

    /// The line printed at the end of a run: samples by reason, emitters,
    /// shots.
    pub fn summary(&self) -> String {
        format!(
            "{} samples ({} contour, {} penumbra, {} umbra, {} edge, {} lattice, {} screen), {} secondary emitters, {} shots",
            self.samples.len(),
            self.count(Reason::IsoluxContour),
            self.count(Reason::Penumbra),
            self.count(Reason::Umbra),
            self.count(Reason::SurfaceEdge),
            self.count(Reason::SmoothLattice),
            self.count(Reason::ScreenDensity),
            self.emitters.len(),
            self.work.shooting.shots
        )
    }

    /// The report: the work's counters, what the scene's `effects` ask
    /// that the stage skips, and a note when `max_shots` stopped the
    /// shooting above its threshold.
    pub fn done(&self, params: &Params, effects: &Effects) -> Done {
        let w = &self.work;
        let mut done = Done::counted([
            ("samples", self.samples.len() as f64),
            ("secondary_emitters", self.emitters.len() as f64),
            ("probes", w.probes as f64),
            ("direct_rays", w.direct_rays as f64),
            ("burial_rays", w.burial_rays as f64),
            ("shots", w.shooting.shots as f64),
            ("shooting_rays", w.shooting.rays as f64),
            ("unshot_fraction", w.shooting.remaining),
            ("converged", f64::from(u8::from(w.shooting.converged))),
            ("placement_seconds", w.placement_seconds),
            ("direct_seconds", w.direct_seconds),
            ("shooting_seconds", w.shooting_seconds),
            ("indirect_rays", w.indirect_rays as f64),
            ("indirect_placement_seconds", w.indirect_placement_seconds),
            ("display_seconds", w.display_seconds),
        ]);
        for r in Reason::ALL {
            done.counters.insert(format!("samples_{r:?}"), self.count(r) as f64);
        }
        done.skipped = skipped(effects);
        if !w.shooting.converged {
            done.notes.push(format!(
                "threshold not reached: max_shots = {} stopped the shooting with {:.3e} of the emitted power unshot",
                params.max_shots, w.shooting.remaining
            ));
        }
        done
    }
}

/// What this stage does not simulate, for the effects the scene has.
fn skipped(effects: &Effects) -> Vec<String> {
    Effects::skipped(&[
        (effects.goniometric_lights, "goniometric lights: structured-sample lights the scene by its emitting surfaces only"),
        (effects.specular_reflection, "specular reflection: not simulated; mirrors keep their diffuse part only"),
        (effects.specular_transmission, "specular transmission: not simulated"),
        (effects.diffuse_transmission, "diffuse transmission: not simulated"),
        (effects.textures, "textures: each material's mean diffuse reflectance is used"),
        (effects.alpha_masks, "alpha masks: surfaces are treated as opaque"),
        (effects.normal_maps, "normal maps: geometric normals are used"),
    ])
}
