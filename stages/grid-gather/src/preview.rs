//! The preview: the solution's radiosity made continuous over the leaf
//! elements ([`crate::gouraud`]), or gpu-shoot's lightmap where given
//! (bilinear between texel centres, [`Lightmap::radiosity_at`]; the
//! leaves average the lightmap over a few texels, and a step inside
//! coarse leaves rings in their interpolation), and seen through the
//! camera. A front-face
//! hit shows `L = B / pi` (Lambertian exitance to radiance, W/(m² sr));
//! with textures `B(x) = E + rho(x) H(x)` ([`crate::detail`]); a back-face
//! hit is black, since radiosity is one-sided; mirrors and glass are
//! followed ([`crate::specular`]; a specular surface seen from behind is
//! not black when it transmits).

use crate::detail::Detail;
use crate::film::{expose, CameraHit, Lens, Sampling, Shader};
use crate::gouraud::Gouraud;
use crate::specular::{self, Followed, Seen, Specular};
use crate::{pixel_surfaces, scene_rays, skipped, Extras, Frame, Mode, Params, Rendered, Scene};
use glam::DVec3;
use radiometry::camera::Pinhole;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::{Hit, SceneRays};
use schemas::lightmap::Lightmap;
use schemas::Result;
use std::collections::BTreeMap;
use std::f64::consts::PI;

/// What the display of a textured scene adds: at a hit on a textured
/// triangle, `B(x) = E + rho(x) H(x)` with the texture's `rho(x)` and `H`
/// interpolated like the radiosity.
#[derive(Clone, Copy)]
pub struct Textured<'a> {
    /// The texture lookups.
    pub detail: &'a Detail<'a>,
    /// Irradiance `H` over the surfaces (Gouraud over the elements' `H_e`).
    pub irradiance: &'a Gouraud,
    /// Emitted radiosity of each triangle's material, W/m².
    pub emission: &'a [[f64; 3]],
}

/// The preview's shader.
pub struct Preview<'a> {
    /// The camera.
    pub camera: &'a Pinhole,
    /// Triangle geometry, mesh frame.
    pub triangles: &'a [TriangleGeometry],
    /// BVH over `triangles`.
    pub rays: Option<&'a SceneRays>,
    /// Radiosity over the surfaces.
    pub shading: &'a Gouraud,
    /// gpu-shoot's lightmap, shown instead of `shading` where given.
    pub lightmap: Option<&'a Lightmap>,
    /// Textures, in a scene that has them.
    pub textured: Option<Textured<'a>>,
    /// The mirrors and glass camera rays continue through, in a scene
    /// that has some.
    pub specular: Option<&'a Specular>,
}

impl Shader for Preview<'_> {
    type Pixel = ();

    fn pixel(&self, _: u64) {}

    /// A front face's radiance, or what the ray sees through a specular
    /// surface (from either side, then counted as a front-face hit); a back
    /// face adds nothing.
    fn shade(&self, _: &mut (), camera: &CameraHit, sum: &mut [f64; 3], followed: &mut Followed) -> bool {
        let (eye, hit) = (self.camera.eye, camera.hit);
        let Some(specular) = self.specular.filter(|s| s.is_specular(hit.triangle)) else {
            let Some(radiance) = self.radiance(eye, camera.direction, hit) else { return false };
            sum.iter_mut().zip(radiance).for_each(|(s, r)| *s += r);
            return true;
        };
        let mut seen = [0.0; 3];
        let visit = &mut |s: &Seen| {
            if let Some(radiance) = self.radiance(s.origin, s.direction, s.hit) {
                (0..3).for_each(|c| seen[c] += s.weight[c] * radiance[c]);
            }
        };
        if let Some(rays) = self.rays {
            followed.add(specular.follow(rays, self.triangles, eye, camera.direction, hit, visit));
        }
        sum.iter_mut().zip(seen).for_each(|(s, r)| *s += r);
        true
    }
}

impl Preview<'_> {
    /// The diffuse radiance `B / pi` the ray `origin + t direction` sees at
    /// `hit`: `None` on a back face (radiosity is one-sided).
    fn radiance(&self, origin: DVec3, direction: DVec3, hit: Hit) -> Option<[f64; 3]> {
        let triangle = &self.triangles[hit.triangle as usize];
        if direction.dot(triangle.normal) > 0.0 {
            return None;
        }
        let point = origin + direction * f64::from(hit.t);
        let uv = triangle.uv_of(point);
        let textured = self.textured.and_then(|t| Some((t, t.detail.reflectance(hit.triangle, uv)?)));
        let radiosity = match textured {
            Some((t, rho)) => {
                let (e, h) = (t.emission[hit.triangle as usize], t.irradiance.radiosity(hit.triangle, uv));
                std::array::from_fn(|c| e[c] + rho[c] * h[c])
            }
            None => match self.lightmap {
                Some(lightmap) => lightmap.radiosity_at(hit.triangle as usize, uv),
                None => self.shading.radiosity(hit.triangle, uv),
            },
        };
        Some(radiosity.map(|b| b / PI))
    }
}

/// Renders the preview of `scene` in `frame`, shading the element radiosity
/// with `shading`.
pub fn render(params: &Params, scene: &Scene, extras: Extras, frame: &Frame, shading: &Gouraud, rows_done: &(dyn Fn(u64) + Sync)) -> Result<Rendered> {
    let Frame { camera, width, height, triangles, materials, smoothing } = *frame;
    let rays = (!triangles.is_empty()).then(|| scene_rays(triangles, extras.detail));
    let textures = extras.detail.filter(|_| scene.manifest.effects.textures);
    let emission: Vec<[f64; 3]> = match textures {
        Some(_) => scene.mesh.triangles.iter().map(|t| scene.manifest.materials[t.material as usize].emission).collect(),
        None => Vec::new(),
    };
    let irradiance = match textures {
        Some(detail) => Some(Gouraud::of(triangles, materials, scene.solution, scene.solution_path, smoothing, &|corners, e| {
            let m = &scene.manifest.materials[scene.mesh.triangles[e.triangle as usize].material as usize];
            detail.irradiance(e.triangle, corners, e.radiosity.map(f64::from), m.emission, m.diffuse)
        }, &[])?),
        None => None,
    };
    let textured = textures.zip(irradiance.as_ref()).map(|(detail, irradiance)| Textured { detail, irradiance, emission: &emission });
    let ids = pixel_surfaces::surface_ids(scene.mesh, scene.manifest);
    let specular = Specular::new(scene.mesh, scene.manifest, triangles, params.specular_depth, params.specular_min_weight);
    let preview = Preview { camera, triangles, rays: rays.as_ref(), shading, lightmap: extras.lightmap, textured, specular: specular.as_ref() };
    let lens = Lens { camera, triangles, rays: rays.as_ref(), surfaces: &ids, crease_angle_deg: params.crease_angle_deg };
    let film = expose(&lens, Sampling { width, height, spp: params.spp, seed: params.seed }, &preview, rows_done);

    let pixels = f64::from(width) * f64::from(height);
    let mut counters = BTreeMap::from([
        ("pixels".to_string(), pixels),
        ("samples_per_pixel".to_string(), f64::from(params.spp)),
        ("rays_cast".to_string(), pixels * f64::from(params.spp)),
        ("ray_hits".to_string(), film.hits as f64),
        ("back_face_hits".to_string(), film.back_face_hits as f64),
        ("triangles".to_string(), triangles.len() as f64),
        ("elements".to_string(), scene.solution.elements.len() as f64),
        ("leaf_elements".to_string(), shading.leaves() as f64),
        ("vertices".to_string(), shading.vertices() as f64),
    ]);
    if let Some(lightmap) = extras.lightmap {
        counters.insert("lightmap_texels".to_string(), lightmap.regions.iter().map(|r| f64::from(r.covered)).sum());
    }
    if specular.is_some() {
        specular::count(&mut counters, film.specular);
    }
    Ok(Rendered {
        width: width as usize,
        height: height as usize,
        rgb: film.rgb,
        coverage: film.coverage,
        surfaces: film.surfaces,
        counters,
        skipped: skipped(scene.manifest, Mode::Preview, extras.detail.is_some()),
    })
}
