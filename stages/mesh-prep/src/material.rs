//! Materials: MTL values, read the way path tracers read them, plus the
//! scene's overrides, checked for physical plausibility.

use crate::mtl::MtlMaterial;
use crate::scene::MaterialOverride;
use schemas::mesh::Material;
use std::f64::consts::PI;

/// The material of an OBJ object without `usemtl`: grey, diffuse.
pub fn default_material() -> Material {
    Material::diffuse("default", [0.5; 3], [0.0; 3])
}

/// The pipeline's material for an MTL entry.
///
/// - `Kd` is the diffuse reflectance (0.5 grey when absent).
/// - `Ke` is read as emitted *radiance* L, as path tracers that read these
///   files do; radiosity needs exitance, `M = pi L` for a Lambertian
///   emitter.
/// - `Ks` is an ideal specular reflectance only for the illumination models
///   that ask for ray-traced reflection (`illum` 3 to 7); under `illum` 2 it
///   is a Phong highlight, which a diffuse radiosity solution ignores.
/// - `Tf` is a specular transmittance for the refracting models (`illum`
///   4, 6, 7, 9); without `Tf` those models transmit `1 - d`.
/// - Under the diffuse models without ray tracing (`illum` 0, 1, 2, and
///   `illum` absent), a partly dissolved material is *translucent*: the
///   light that passes (`1 - d`), filtered by `Tf` (1 when absent), loses
///   its direction in a surface that does not refract (a lamp shade, paper,
///   frosted glass), so its diffuse transmittance is `tau_d = (1 - d) Tf`
///   (paper 004 Sec. 4.3.1). An opaque material (`d 1`, the default, which
///   exporters write beside `Tf 1 1 1`) transmits nothing.
/// - `map_Kd`, `map_d` and `norm`/`bump` name the diffuse texture, alpha mask
///   and normal map.
/// - Ignored: `Ni` (index of refraction: glass is a thin plate whose
///   refraction bending is neglected, as paper 004 Sec. 4.3.2 does, and
///   `Ks`, `Tf` are taken as the plate's reflectance and transmittance,
///   without a Fresnel split), `Ns` (the specular part is ideal, never
///   glossy), `Ka`, `Tr` and the Fresnel variants of `illum` 5 and 7 (read
///   as 3 and 6).
pub fn from_mtl(m: &MtlMaterial) -> Material {
    let illum = m.illumination_model.unwrap_or(2);
    let rgb = |v: Option<[f64; 3]>| v.unwrap_or([0.0; 3]);
    let passed = 1.0 - m.dissolve.unwrap_or(1.0);
    let transmitted = m.transmission_filter.unwrap_or([passed; 3]);
    let name = |t: &Option<crate::mtl::TextureRef>| t.as_ref().map(|t| t.name.clone());
    Material {
        name: m.name.clone(),
        diffuse: m.diffuse.unwrap_or([0.5; 3]),
        emission: rgb(m.emissive).map(|l| PI * l),
        specular_reflectance: if (3..=7).contains(&illum) { rgb(m.specular) } else { [0.0; 3] },
        specular_transmittance: if matches!(illum, 4 | 6 | 7 | 9) { transmitted } else { [0.0; 3] },
        diffuse_transmittance: if illum <= 2 { m.transmission_filter.unwrap_or([1.0; 3]).map(|f| passed * f) } else { [0.0; 3] },
        diffuse_map: name(&m.diffuse_texture),
        alpha_map: name(&m.dissolve_texture),
        normal_map: name(&m.normal_texture),
        two_sided: false,
    }
}

/// Applies the fields an override sets.
pub fn apply(material: &mut Material, o: &MaterialOverride) {
    let set = |target: &mut [f64; 3], value: Option<[f64; 3]>| {
        if let Some(v) = value {
            *target = v;
        }
    };
    set(&mut material.diffuse, o.diffuse);
    set(&mut material.emission, o.emission);
    set(&mut material.specular_reflectance, o.specular_reflectance);
    set(&mut material.specular_transmittance, o.specular_transmittance);
    set(&mut material.diffuse_transmittance, o.diffuse_transmittance);
    if let Some(two_sided) = o.two_sided {
        material.two_sided = two_sided;
    }
    for (target, value) in [
        (&mut material.alpha_map, &o.alpha_map),
        (&mut material.normal_map, &o.normal_map),
        (&mut material.diffuse_map, &o.diffuse_map),
    ] {
        if value.is_some() {
            target.clone_from(value);
        }
    }
}

/// Why a material is not physical, if it is not: every coefficient finite
/// and in [0, 1], energy conserved, `rho_d + tau_d + rho_s + tau_s <= 1`
/// per channel (the scattered total, reflected and transmitted, diffuse and
/// specular; paper 004 Eq. 4.4 splits a translucent surface's light by
/// these fractions), emission finite and non-negative. The message names
/// the material and the fields that add up to more than 1. A diffuse
/// reflectance of exactly 1 is allowed here; the solver's convergence in
/// closed scenes is its own concern.
pub fn check(m: &Material) -> Option<String> {
    let coefficients = [
        ("diffuse", m.diffuse),
        ("specular_reflectance", m.specular_reflectance),
        ("specular_transmittance", m.specular_transmittance),
        ("diffuse_transmittance", m.diffuse_transmittance),
    ];
    for (name, v) in coefficients {
        if let Some(x) = v.iter().find(|x| !(0.0..=1.0).contains(*x)) {
            return Some(format!("material '{}': {name} {x} is outside [0, 1]", m.name));
        }
    }
    for channel in 0..3 {
        let total: f64 = coefficients.iter().map(|(_, v)| v[channel]).sum();
        if total > 1.0 + 1e-9 {
            let fields: Vec<&str> = coefficients.iter().filter(|(_, v)| v[channel] > 0.0).map(|(name, _)| *name).collect();
            return Some(format!(
                "material '{}': {} is {total} in channel {channel}, more than 1 (it would scatter more light than it receives)",
                m.name,
                fields.join(" + ")
            ));
        }
    }
    if let Some(x) = m.emission.iter().find(|x| !x.is_finite() || **x < 0.0) {
        return Some(format!("material '{}': emission {x} is not a finite non-negative number", m.name));
    }
    if m.two_sided && m.emission.iter().any(|&e| e > 0.0) {
        return Some(format!(
            "material '{}': an emitter cannot be two-sided (emission is one-sided, from the front face); model a panel that lights both ways as two emitters",
            m.name
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtl_emission_is_radiance_and_exitance_is_pi_times_it() {
        let mtl = MtlMaterial { name: "light".into(), emissive: Some([17.0, 12.0, 4.0]), ..Default::default() };
        let m = from_mtl(&mtl);
        assert_eq!(m.emission, [17.0 * PI, 12.0 * PI, 4.0 * PI]);
        assert_eq!(m.specular_reflectance, [0.0; 3], "illum 2 highlight is not a mirror");
    }

    #[test]
    fn a_dissolved_diffuse_material_is_translucent_and_a_refracting_one_specular() {
        let sheet = |illum: Option<u32>, tf: Option<[f64; 3]>, d: Option<f64>| {
            from_mtl(&MtlMaterial { name: "shade".into(), diffuse: Some([0.3; 3]), transmission_filter: tf, dissolve: d, illumination_model: illum, ..Default::default() })
        };
        let shade = sheet(Some(2), Some([1.0, 0.5, 0.0]), Some(0.4));
        assert_eq!((shade.diffuse_transmittance, shade.specular_transmittance), ([0.6, 0.3, 0.0], [0.0; 3]));
        assert_eq!(sheet(None, None, Some(0.75)).diffuse_transmittance, [0.25; 3], "Tf absent filters nothing");
        assert_eq!(sheet(Some(0), Some([1.0; 3]), None).diffuse_transmittance, [0.0; 3], "opaque (d 1) with an exporter's Tf 1 1 1");
        let glass = sheet(Some(4), Some([0.5; 3]), Some(0.4));
        assert_eq!((glass.diffuse_transmittance, glass.specular_transmittance), ([0.0; 3], [0.5; 3]));
        assert_eq!(sheet(Some(3), Some([0.5; 3]), Some(0.4)).diffuse_transmittance, [0.0; 3], "a mirror model does not transmit");
    }

    #[test]
    fn mcguires_mirror_and_glass_map_to_ideal_specular_coefficients() {
        let mirror = from_mtl(&MtlMaterial { name: "tallBox".into(), diffuse: Some([0.01; 3]), specular: Some([0.95; 3]), illumination_model: Some(5), ..Default::default() });
        assert_eq!((mirror.diffuse, mirror.specular_reflectance, mirror.specular_transmittance), ([0.01; 3], [0.95; 3], [0.0; 3]));
        let glass = MtlMaterial {
            name: "water".into(),
            diffuse: Some([0.01; 3]),
            specular: Some([0.3; 3]),
            transmission_filter: Some([0.1; 3]),
            illumination_model: Some(7),
            ..Default::default()
        };
        let water = from_mtl(&glass);
        assert_eq!((water.specular_reflectance, water.specular_transmittance, water.diffuse_transmittance), ([0.3; 3], [0.1; 3], [0.0; 3]));
        assert_eq!(check(&water), None);
        // illum 9: glass without reflection; Tf absent, 1 - d passes.
        let pane = from_mtl(&MtlMaterial { illumination_model: Some(9), transmission_filter: None, dissolve: Some(0.25), ..glass });
        assert_eq!((pane.specular_reflectance, pane.specular_transmittance), ([0.0; 3], [0.75; 3]));
    }

    #[test]
    fn implausible_materials_are_refused() {
        let mut m = default_material();
        assert_eq!(check(&m), None);
        m.diffuse = [0.7, 0.7, 0.7];
        m.specular_reflectance = [0.5, 0.0, 0.0];
        assert_eq!(
            check(&m).unwrap(),
            "material 'default': diffuse + specular_reflectance is 1.2 in channel 0, more than 1 (it would scatter more light than it receives)"
        );
        m.specular_reflectance = [0.0; 3];
        m.diffuse[1] = f64::NAN;
        assert!(check(&m).unwrap().contains("outside [0, 1]"));
        let mut lamp = Material { two_sided: true, emission: [1.0, 0.0, 0.0], ..default_material() };
        assert!(check(&lamp).unwrap().contains("cannot be two-sided"));
        lamp.emission = [0.0; 3];
        assert_eq!(check(&lamp), None);
    }
}
