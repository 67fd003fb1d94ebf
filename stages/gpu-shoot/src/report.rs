//! What a run reports: the summary line, the report's counters (the
//! reflection tree's for scenes with specular materials) and the effects
//! the stage does not simulate.

use crate::Solved;
use schemas::mesh::Effects;
use stage_kit::stage::Done;

impl Solved {
    /// The unshot power at the end over the emitted power: in magnitude,
    /// `sum |dB| A` (what the run stops on), and the net sum.
    pub fn final_unshot(&self) -> (f64, f64) {
        self.shots.last().map_or((self.initial_unshot, self.initial_unshot), |s| (s.unshot_magnitude_fraction, s.unshot_fraction))
    }

    /// The line printed at the end of a run on `adapter`.
    pub fn summary(&self, adapter: &str) -> String {
        format!("{} shots, {} texels, unshot {:.4}, {:.3} s shooting on {adapter}", self.work.shots, self.atlas.texels.len(), self.final_unshot().0, self.work.shoot_seconds)
    }

    /// The report: the work's counters, and what the scene's `effects` ask
    /// that the stage skips (`surface`: whether surface.exr was read); its
    /// notes: the `adapter`, and surface.exr not read though `surface_given`.
    pub fn done(&self, effects: &Effects, surface: bool, surface_given: bool, adapter: &str) -> Done {
        let w = &self.work;
        let (unshot, net) = self.final_unshot();
        let mut done = Done::counted([
            ("shots", w.shots as f64),
            ("samples", w.samples as f64),
            ("visibility_layers", w.layers as f64),
            ("receiver_evaluations", w.receiver_evaluations as f64),
            ("texels", self.atlas.texels.len() as f64),
            ("mask_texels", w.mask_texels as f64),
            ("buried_texels", w.buried_texels as f64),
            ("burial_rays", w.burial_rays as f64),
            ("subdivision_texels_added", w.elements_added as f64),
            ("subdivision_tiles_added", w.tiles_added as f64),
            ("subdivision_seconds", w.subdivision_seconds),
            ("unshot_fraction", net),
            ("unshot_magnitude_fraction", unshot),
            ("setup_seconds", w.setup_seconds),
            ("shoot_seconds", w.shoot_seconds),
            ("seconds_per_shot", w.shoot_seconds / (w.shots.max(1) as f64)),
        ]);
        if effects.specular_reflection || effects.specular_transmission {
            let r = &w.reflection;
            let emitted: f64 = self.emitted_power.iter().sum();
            done.counters.extend([
                ("reflection_nodes".to_string(), r.nodes as f64),
                ("reflection_depth".to_string(), r.depth as f64),
                ("reflection_layers".to_string(), r.layers as f64),
                ("reflection_bound_fraction".to_string(), r.bound / emitted),
                ("reflection_truncated_fraction".to_string(), r.truncated / emitted),
                ("reflection_seconds".to_string(), r.seconds),
            ]);
        }
        done.skipped = skipped(effects, surface, w.one_sided_translucent);
        done.notes.push(format!("adapter: {adapter}"));
        if surface_given && !effects.surface_detail() {
            done.notes.push("surface.exr not read: the scene has no texture, alpha mask or normal map".into());
        }
        done
    }
}

/// The effects of the scene gpu-shoot does not simulate; textures, alpha
/// masks and normal maps are simulated when `surface` (the artifact that
/// holds them) was read, diffuse transmission where its material is
/// two-sided (`one_sided` triangles are not).
fn skipped(effects: &Effects, surface: bool, one_sided: u64) -> Vec<String> {
    let without = !surface;
    let transmits = format!("diffuse transmission: {one_sided} triangles of translucent materials that are not two-sided transmit nothing (their back face has no texels; make the material two_sided)");
    Effects::skipped(&[
        (one_sided > 0, transmits.as_str()),
        (effects.specular_reflection, "specular reflection: planar mirrors by the reflection tree (004 Sec. 4.3.2), up to --reflection-depth windows per path, nodes under --reflection-threshold cut (their bound in reflection_truncated_fraction); no glossy reflection (a curved mirror is its facets), alpha masks opaque in the frustum maps"),
        (effects.specular_transmission, "specular transmission: thin panes in the reflection tree (004 Sec. 4.3.3); no refraction bending by thick glass"),
        (effects.alpha_masks && without, "alpha masks: surfaces are treated as opaque (no --surface given)"),
        (effects.normal_maps && without, "normal maps: texels use the geometric normal (no --surface given)"),
        (effects.textures && without, "textures: radiosity uses each material's diffuse reflectance (no --surface given)"),
        (effects.fine_clustered_geometry, "fine geometry: gpu-shoot does not cluster; every triangle keeps its own region (--adaptive splits receivers only at shadow boundaries)"),
    ])
}
