//! # structured-sample: paper 002's structured sampling (Section 3)
//!
//! Drettakis and Fiume's "structured sampling" places illumination samples
//! where the light's structure asks for them (isolux contours, shadow
//! boundaries, the view) instead of where the mesh has vertices, computes
//! the direct light at them exactly, transfers light between surfaces with
//! polygons approximating isolux regions, and resamples the sparse
//! samples onto a grid per surface for display. The paper placed its
//! samples by hand; this stage places them by its stated guidelines:
//!
//! 1. [`probes`]: exact direct illumination (Eq. 2-3, ray-cast visibility,
//!    [`direct`]) on a fine probe grid per planar surface ([`surfaces`]);
//! 2. [`placement`]: tagged samples along the isolux contours by their
//!    curvature, across penumbrae densely and umbrae sparsely, a coarse
//!    lattice in smooth regions, and view-dependent display samples one per
//!    block of screen pixels ([`render::screen_candidates`]);
//! 3. exact direct light at every sample, and whether it lies buried
//!    inside a solid ([`burial`]: the floor under a block);
//! 4. [`emitters`]: secondary emitter polygons of light-transfer samples,
//!    one per isolux region (Delaunay triangles merged by band,
//!    [`delaunay`]); on surfaces lit only by reflection, with vertices
//!    along the outline of what hides the room from them, as the first
//!    reflection off the other polygons shows it;
//! 5. [`shooting`]: progressive shooting from the polygon of highest unshot
//!    power, each of its triangles sending the mean of its corners', with
//!    the paper's ray occlusion (from points over the polygon); then,
//!    on surfaces the direct light leaves without contours (lit only by
//!    interreflection, like the paper's B), display samples along the
//!    contours of the indirect light, each gathering what the emitters
//!    shot;
//! 6. [`display`]: the indirect light's grid resampling with the conical
//!    filter, tag-aware at shadow boundaries, and [`render`]: the image
//!    through the camera, each hit's direct light from the probe grid
//!    ([`probes::ProbeGrid::irradiance_at`], or evaluated at the hit along
//!    a surface's border and a solid's footprint) plus its indirect light
//!    from the display grid.
//!
//! Why an image and not a `solution.exr` for grid-gather: the paper's
//! display is part of the method (its grid resampling and conical filter
//! are what it measures in Table 2), and a solution's elements would have
//! to be a mesh of the samples, which grid-gather would interpolate by
//! Gouraud shading instead of the paper's filter. So the stage writes the
//! samples artifact and the image of its own display, in the `image`
//! format every later stage (tonemap, compare) reads.
//!
//! f64 throughout; every step is in a fixed order or keyed by its work
//! item, so a rerun is bit-identical whatever the thread count.

#![warn(missing_docs)]

pub mod burial;
pub mod delaunay;
pub mod direct;
pub mod display;
pub mod emitters;
pub mod placement;
pub mod probes;
pub mod render;
pub mod report;
pub mod shooting;
pub mod surfaces;
mod union_find;

use direct::{DirectLight, PrimaryEmitter};
use display::{DisplayGrid, FilterSample};
use glam::{DVec2, DVec3};
use placement::{contour_levels, isolux_levels, light_candidates, Candidate, Thinning};
use probes::ProbeGrid;
use radiometry::bounds::Aabb;
use radiometry::color::luminance;
use stage_kit::scene::{mesh_triangles, pinhole};
use radiometry::rays::SceneRays;
use render::Film;
use schemas::mesh::{Manifest, Mesh};
use schemas::samples::{Reason, SampledSurface, Sample, SecondaryEmitter, NO_EMITTER};
use shooting::{shoot, Collector, ShootingParams, ShootingWork};
use std::f64::consts::PI;

stage_kit::knobs! {
    /// The stage's parameters. Spacings and radii are fractions of each
    /// surface's extent (the longer side of its bounding rectangle, or of
    /// the curved surface it is a facet of: [`surfaces::Surface::extent`]).
    pub struct Params {
        /// Probe grid cells along a surface's extent.
        probe_resolution: usize = 96, "cells", value(4..=4096);
        /// Isolux bands per surface (`levels - 1` contours).
        levels: usize = 8, "bands", value(1..=256);
        /// Sample spacing along a straight isolux contour.
        contour_spacing: f64 = 0.12, "fraction of extent", value(left_open(0.0, 10.0));
        /// Turning of a curved contour between two of its samples.
        turn_angle_deg: f64 = 25.0, "degrees", value(left_open(0.0, 180.0));
        /// Spacing of the lattice in smooth regions and of the samples along
        /// a surface's edges.
        lattice_spacing: f64 = 0.25, "fraction of extent", value(left_open(0.0, 10.0));
        /// Spacing of samples in a penumbra.
        shadow_spacing: f64 = 0.04, "fraction of extent", value(left_open(0.0, 10.0));
        /// Spacing of samples in an umbra.
        umbra_spacing: f64 = 0.3, "fraction of extent", value(left_open(0.0, 10.0));
        /// One view-dependent display sample per this many pixels squared.
        screen_spacing: u32 = 8, "pixels", value(1..=16384);
        /// Rays per light-source triangle for the direct light's visibility.
        visibility_rays: usize = 16, "rays", value(1..=4096);
        /// Least area of a secondary emitter, as a fraction of its surface's:
        /// smaller isolux regions are merged into a neighbour.
        emitter_min_area: f64 = 0.02, "fraction of surface area", value(custom("in [0, 1]", |v: &f64| (0.0..=1.0).contains(v)));
        /// Largest side of the grid cells that also cut secondary emitters
        /// (each sends its mean radiosity from all of it), as a fraction of
        /// the scene's bounding-box diagonal (at 1 or more, no surface is
        /// cut: by isolux band alone).
        emitter_cell: f64 = 0.15, "fraction of the scene's diagonal", value(left_open(0.0, 10.0));
        /// Points spread over a secondary emitter's area that cast its
        /// occlusion rays (as many as it has vertices where it has fewer).
        occlusion_points: usize = 16, "points", value(1..=4096);
        /// Stop shooting when the unshot power (all polygons together) is
        /// under this fraction of the emitted power.
        threshold: f64 = 1e-4, "fraction of emitted power", value(open(0.0, 1.0));
        /// Most shots.
        max_shots: usize = 10_000, "shots", value;
        /// Reflections off secondary emitters (0: all, until `threshold`).
        bounces: u32 = 0, "", value;
        /// Display grid cells along a surface's extent.
        display_resolution: usize = 64, "cells", value(1..=4096);
        /// The display filter of the indirect light: `conical` (paper
        /// 002's cone), `conical-linear` or `conical-quadratic` (the cone
        /// with a first- or second-order correction).
        filter: display::Filter = display::Filter::ConicalQuadratic, "", value;
        /// Radius `r` of the conical filter.
        filter_radius: f64 = 0.2, "fraction of extent", value(left_open(0.0, 10.0));
        /// Radius of the cone near shadow-boundary samples.
        shadow_filter_radius: f64 = 0.04, "fraction of extent", value(left_open(0.0, 10.0));
        /// Image width (none: the camera's).
        width: Option<u32> = None, "pixels", optional(1..=16384);
        /// Image height (none: the camera's).
        height: Option<u32> = None, "pixels", optional(1..=16384);
        /// Rays per pixel along each side (`spp_side`² per pixel).
        spp_side: u32 = 2, "rays", value(1..=16);
        /// Seed of the visibility rays.
        seed: u64 = 1, "", value;
    }
}

stage_kit::show_by_name!(display::Filter);

/// What the run did, for the report.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Work {
    /// Probes evaluated.
    pub probes: usize,
    /// Rays cast for the direct light's visibility (probes and samples).
    pub direct_rays: u64,
    /// Rays cast testing the samples for burial ([`burial`]).
    pub burial_rays: u64,
    /// Samples per reason, in [`Reason::ALL`] order.
    pub samples_by_reason: [usize; 6],
    /// The shooting.
    pub shooting: ShootingWork,
    /// Seconds placing samples (probes included).
    pub placement_seconds: f64,
    /// Seconds computing the direct light at the samples.
    pub direct_seconds: f64,
    /// Seconds cutting the secondary emitters (the outline of surfaces lit
    /// only indirectly included) and shooting.
    pub shooting_seconds: f64,
    /// Rays cast probing surfaces lit only indirectly: for their outline
    /// before the shooting, and placing and gathering their display
    /// samples after it.
    pub indirect_rays: u64,
    /// Seconds placing and gathering them.
    pub indirect_placement_seconds: f64,
    /// Seconds resampling and rendering.
    pub display_seconds: f64,
}

/// The result: the samples artifact's content, the image, the work.
pub struct Structured {
    /// Samples.
    pub samples: Vec<Sample>,
    /// Their surfaces.
    pub surfaces: Vec<SampledSurface>,
    /// Secondary emitters.
    pub emitters: Vec<SecondaryEmitter>,
    /// The rendered image.
    pub film: Film,
    /// Image size.
    pub size: (u32, u32),
    /// Work done.
    pub work: Work,
}

/// Progress callbacks: `phase` names a phase with its step count; `step`
/// advances it.
pub struct Progress<'a> {
    /// A phase starts: its name and steps.
    pub phase: &'a dyn Fn(&str, u64),
    /// One step done.
    pub step: &'a (dyn Fn() + Sync),
}

/// Runs structured sampling on a prepared scene (see the crate
/// documentation). Errors are messages about the scene (no triangle, a
/// camera that cannot be built).
pub fn structured(mesh: &Mesh, manifest: &Manifest, params: &Params, progress: &Progress) -> Result<Structured, String> {
    let geometry = mesh_triangles(mesh);
    let corners: Vec<[DVec3; 3]> = geometry.iter().map(|g| g.corners).collect();
    let rays = SceneRays::new(&corners);
    let (surfaces, surface_of) = surfaces::planar_surfaces(mesh, manifest, &geometry);
    let emitters: Vec<PrimaryEmitter> = mesh
        .triangles
        .iter()
        .enumerate()
        .filter_map(|(i, t)| {
            let exitance = manifest.materials[t.material as usize].emission;
            (exitance.iter().any(|&e| e > 0.0) && geometry[i].area > 0.0).then_some(PrimaryEmitter { triangle: i as u32, geometry: geometry[i], exitance })
        })
        .collect();
    let emitted_power: f64 = emitters.iter().map(|e| e.geometry.area * luminance(e.exitance)).sum();
    let direct = DirectLight { emitters, rays: &rays, visibility_rays: params.visibility_rays, seed: params.seed };
    let camera = &manifest.camera;
    let size = (params.width.unwrap_or(camera.width), params.height.unwrap_or(camera.height));
    let pinhole = pinhole(camera, size.0, size.1).ok_or("the manifest's camera has a zero view direction, one parallel to up, or a field of view outside (0, 180) degrees")?;
    let mut work = Work::default();
    let scene = Aabb::around(mesh.positions.iter().map(|p| DVec3::from(p.map(f64::from))));
    let diagonal = (scene.max - scene.min).length();
    let normals: Vec<DVec3> = geometry.iter().map(|g| g.normal).collect();
    let t_min = (1e-6 * diagonal) as f32;

    // 1-2. Probes, candidates, thinning.
    let clock = std::time::Instant::now();
    (progress.phase)("probing", surfaces.len() as u64);
    let mut grids = Vec::with_capacity(surfaces.len());
    let mut thinnings = Vec::with_capacity(surfaces.len());
    for (s, surface) in surfaces.iter().enumerate() {
        let mut grid = ProbeGrid::new(surface, &direct, params.probe_resolution, (s as u64) << 32);
        work.probes += grid.probes.len();
        work.direct_rays += grid.rays;
        work.burial_rays += burial::mark_probes(&mut grid, s, surface, &rays, &normals, t_min, params.seed, 2);
        let mut thinning = Thinning::new(params.contour_spacing * surface.extent());
        for c in light_candidates(surface, &surface.boundary(mesh), &grid, params) {
            thinning.offer(c);
        }
        grids.push(grid);
        thinnings.push(thinning);
        (progress.step)();
    }
    let view = render::View { camera: &pinhole, rays: &rays, surfaces: &surfaces, surface_of: &surface_of };
    for (s, uv, spacing) in render::screen_candidates(&view, size, camera.vertical_fov_deg, params.screen_spacing) {
        thinnings[s as usize].offer(Candidate { uv, reason: Reason::ScreenDensity, level: schemas::samples::NO_LEVEL, spacing, priority: 0.0 });
    }
    work.placement_seconds = clock.elapsed().as_secs_f64();

    // 3. Exact direct light at every sample.
    let clock = std::time::Instant::now();
    let placed: Vec<(u32, Candidate)> = thinnings.iter().enumerate().flat_map(|(s, t)| t.kept().iter().map(move |c| (s as u32, *c))).collect();
    (progress.phase)("direct light", placed.len() as u64);
    // A sample on surface `s` at `uv` with its exact direct light (random
    // stream `key`), nothing reflected yet; and the rays cast.
    let sample_at = |s: u32, uv: DVec2, key: u64| -> (Collector, u64) {
        let surface = &surfaces[s as usize];
        let (triangle, position) = (triangle_of(surface, uv), surface.point(uv));
        let e = direct.at(position, surface.normal, triangle, key);
        let direct = [0, 1, 2].map(|k| surface.reflectance[k] * e.rgb[k]);
        (Collector { position, normal: surface.normal, surface: s, triangle, reflectance: surface.reflectance, direct, indirect: [0.0; 3], buried: false }, e.rays)
    };
    let evaluated: Vec<(Collector, u64)> = {
        use rayon::prelude::*;
        placed
            .par_iter()
            .enumerate()
            .map(|(i, (s, c))| {
                let sample = sample_at(*s, c.uv, (1u64 << 62) + i as u64);
                (progress.step)();
                sample
            })
            .collect()
    };
    work.direct_rays += evaluated.iter().map(|e| e.1).sum::<u64>();
    let mut collectors: Vec<Collector> = evaluated.into_iter().map(|e| e.0).collect();
    work.burial_rays += burial::mark(&mut collectors, &rays, &normals, t_min, params.seed, 0);
    work.direct_seconds = clock.elapsed().as_secs_f64();

    // 4. Secondary emitter polygons per reflecting surface: first of the
    // surfaces the direct light gives isolux contours; then of those lit
    // only by reflection, whose vertices include the outline of what
    // hides the room from them (where a probe receives under [`SHADOWED`]
    // of its unoccluded first reflection, from the first polygons' direct
    // light): a lamp hung a centimetre under a ceiling leaves a pocket
    // over it that sees nothing of the room. Cut from lattice samples
    // alone, the ceiling's triangles straddled the pocket's outline
    // wherever the lattice happened to fall, their corners' visibility
    // stood for the pocket or for the open ceiling round it, and what the
    // ceiling received moved by 3% from one lattice spacing to the next
    // (McGuire's white box against hierarchical-solve: -1.0% to -3.9%;
    // README, Structured sampling).
    let clock = std::time::Instant::now();
    let reflecting: Vec<bool> = surfaces.iter().map(|s| luminance(s.reflectance) > 0.0).collect();
    let by_reflection: Vec<bool> = (0..surfaces.len()).map(|s| reflecting[s] && isolux_levels(&grids[s], params.levels).is_empty()).collect();
    let mut polygons = Vec::new();
    let cut = |s: usize, placed: &[(u32, Candidate)], collectors: &[Collector], polygons: &mut Vec<emitters::Polygon>| {
        let (surface, grid) = (&surfaces[s], &grids[s]);
        let members: Vec<u32> = (0..placed.len() as u32).filter(|&i| placed[i as usize].0 == s as u32 && placed[i as usize].1.reason != Reason::ScreenDensity).collect();
        let uv: Vec<DVec2> = members.iter().map(|&i| placed[i as usize].1.uv).collect();
        let min_area = params.emitter_min_area * surface.area;
        let cells = (surface.extent() / (params.emitter_cell * diagonal)).ceil().clamp(1.0, 256.0) as usize;
        polygons.extend(emitters::isolux_polygons(s as u32, surface, &members, &uv, |p| grid.illuminance_at(p), &contour_levels(surface, grid, params.levels), min_area, cells, &|i| collectors[i as usize].buried));
    };
    for s in (0..surfaces.len()).filter(|&s| reflecting[s] && !by_reflection[s]) {
        cut(s, &placed, &collectors, &mut polygons);
    }
    // The direct light at each polygon triangle's centroid, for the power
    // each polygon shoots first (shooting::direct_emission), `key` the
    // random stream of the first one's first triangle.
    let direct_first = |polygons: &[emitters::Polygon], placed: &[(u32, Candidate)], collectors: &[Collector], key: u64| -> (Vec<Vec<[f64; 3]>>, u64) {
        let first: Vec<usize> = polygons.iter().scan(0, |n, p| Some(std::mem::replace(n, *n + p.triangles.len()))).collect();
        let centroid_rays = std::sync::atomic::AtomicU64::new(0);
        let at_centroid = |p: usize, t: usize| -> [f64; 3] {
            let (polygon, surface) = (&polygons[p], &surfaces[polygons[p].surface as usize]);
            let uv = polygon.triangles[t].iter().map(|&v| placed[v as usize].1.uv).sum::<DVec2>() / 3.0;
            let triangle = triangle_of(surface, uv);
            let e = direct.at(surface.point(uv), surface.normal, triangle, key + (first[p] + t) as u64);
            centroid_rays.fetch_add(e.rays, std::sync::atomic::Ordering::Relaxed);
            [0, 1, 2].map(|k| surface.reflectance[k] * e.rgb[k])
        };
        let emission = shooting::direct_emission(polygons, collectors, &at_centroid);
        (emission, centroid_rays.into_inner())
    };
    let (mut emission, centroid_rays) = direct_first(&polygons, &placed, &collectors, 1u64 << 60);
    work.direct_rays += centroid_rays;
    let mut placed = placed;
    if by_reflection.iter().any(|&b| b) && !polygons.is_empty() {
        let senders: Vec<shooting::Sender> = polygons.iter().map(|p| shooting::Sender::new(p, &collectors, params.occlusion_points)).collect();
        let totals: Vec<Vec<[f64; 3]>> = senders.iter().zip(&emission).map(|(sender, u)| sender.totals(u)).collect();
        let before = placed.len();
        for s in (0..surfaces.len()).filter(|&s| by_reflection[s]) {
            let grid = indirect_probes(&surfaces[s], s as u32, params.probe_resolution / OUTLINE_COARSENING, &senders, &totals, &rays);
            work.indirect_rays += grid.rays;
            let offered = thinnings[s].kept().len();
            for c in light_candidates(&surfaces[s], &[], &grid, params).into_iter().filter(|c| matches!(c.reason, Reason::Penumbra | Reason::Umbra)) {
                thinnings[s].offer(c);
            }
            placed.extend(thinnings[s].kept()[offered..].iter().map(|c| (s as u32, *c)));
        }
        for (i, &(s, c)) in placed.iter().enumerate().skip(before) {
            let (x, rays_cast) = sample_at(s, c.uv, (1u64 << 62) + i as u64);
            work.direct_rays += rays_cast;
            collectors.push(x);
        }
        work.burial_rays += burial::mark(&mut collectors[before..], &rays, &normals, t_min, params.seed, 3);
    }
    let lit = polygons.len();
    for s in (0..surfaces.len()).filter(|&s| by_reflection[s]) {
        cut(s, &placed, &collectors, &mut polygons);
    }
    let lit_triangles: usize = polygons[..lit].iter().map(|p| p.triangles.len()).sum();
    let (rest, centroid_rays) = direct_first(&polygons[lit..], &placed, &collectors, (1u64 << 60) + lit_triangles as u64);
    work.direct_rays += centroid_rays;
    emission.extend(rest);
    // 5. Progressive shooting.
    (progress.phase)("shooting", params.max_shots as u64);
    let shooting_params = ShootingParams { threshold: params.threshold, max_shots: params.max_shots, bounces: params.bounces, occlusion_points: params.occlusion_points };
    work.shooting = shoot(&polygons, emission, &mut collectors, &rays, emitted_power, shooting_params, &|_| (progress.step)());
    // Each shot passes on at most the reflectance times what it sends, so
    // the unshot power never grows past what the surfaces first reflect,
    // less than the emitted power: more is light made from nothing
    // (overlapping emitters: a Delaunay triangulation that covered a
    // panel's face 144 times ended 47 times over), and the samples'
    // light means nothing.
    if work.shooting.remaining > 1.0 {
        return Err(format!(
            "the shooting diverges: after {} shots the unshot power is {:.3e} times the emitted power, which light reflected once cannot exceed (secondary emitters that overlap?); no output written",
            work.shooting.shots, work.shooting.remaining
        ));
    }
    work.shooting_seconds = clock.elapsed().as_secs_f64();

    // 5b. Surfaces the direct light leaves without isolux structure (lit
    // only by interreflection, like paper 002's B, whose contours its
    // Figure 3(b) shows): their indirect light is probed from the shot
    // emitters (on a grid a quarter as fine as the direct light's: the
    // indirect light is smooth, and each probe gathers from every
    // emitter), display samples go along its contours and across the
    // outline of what hides most of the room from it ([`SHADOWED`]), and
    // each gathers what the emitters shot.
    let clock = std::time::Instant::now();
    let before_display = placed.len();
    // Each such surface's indirect probes, whose outline of what hides the
    // room from it parts the display's filter (`DisplayGrid::new`).
    let mut indirect_grids: Vec<Option<ProbeGrid>> = vec![None; surfaces.len()];
    let senders: Vec<shooting::Sender> = polygons.iter().map(|p| shooting::Sender::new(p, &collectors, params.occlusion_points)).collect();
    let totals: Vec<Vec<[f64; 3]>> = senders.iter().zip(&work.shooting.shot_triangles).map(|(sender, shot)| sender.totals(shot)).collect();
    for (s, surface) in surfaces.iter().enumerate() {
        if !by_reflection[s] || senders.is_empty() {
            continue;
        }
        let grid = indirect_grids[s].insert(indirect_probes(surface, s as u32, params.probe_resolution / 4, &senders, &totals, &rays));
        work.indirect_rays += grid.rays;
        let before = thinnings[s].kept().len();
        for c in light_candidates(surface, &[], grid, params).into_iter().filter(|c| matches!(c.reason, Reason::IsoluxContour | Reason::Penumbra | Reason::Umbra)) {
            thinnings[s].offer(c);
        }
        for c in &thinnings[s].kept()[before..] {
            let (mut x, direct_rays) = sample_at(s as u32, c.uv, (1u64 << 61) + placed.len() as u64);
            let (indirect, _, indirect_rays) = gather(&senders, &totals, &rays, x.position, surface.normal, s as u32, x.triangle);
            x.indirect = [0, 1, 2].map(|k| surface.reflectance[k] * indirect[k]);
            work.direct_rays += direct_rays;
            work.indirect_rays += indirect_rays;
            collectors.push(x);
            placed.push((s as u32, *c));
        }
    }
    work.burial_rays += burial::mark(&mut collectors[before_display..], &rays, &normals, t_min, params.seed, 1);
    work.indirect_placement_seconds = clock.elapsed().as_secs_f64();

    let mut emitter_of = vec![NO_EMITTER; placed.len()];
    for (p, polygon) in polygons.iter().enumerate() {
        for &v in &polygon.vertices {
            // A sample on the border of two regions belongs to the first.
            if emitter_of[v as usize] == NO_EMITTER {
                emitter_of[v as usize] = p as u32;
            }
        }
    }
    let samples: Vec<Sample> = placed
        .iter()
        .zip(&collectors)
        .enumerate()
        .map(|(i, ((s, c), x))| {
            let surface = &surfaces[*s as usize];
            work.samples_by_reason[c.reason as usize] += 1;
            Sample {
                position: x.position.to_array(),
                surface: *s,
                triangle: x.triangle,
                reason: c.reason,
                level: c.level,
                direct: x.direct.map(|b| b / PI),
                luminance: [0, 1, 2].map(|k| (surface.emission[k] + x.direct[k] + x.indirect[k]) / PI),
                emitter: emitter_of[i],
            }
        })
        .collect();

    // 6. Display: the direct light from the probes, grids of the
    // indirect light filtered from the samples, then the image.
    let clock = std::time::Instant::now();
    (progress.phase)("display", u64::from(size.1));
    let display: Vec<DisplayGrid> = surfaces
        .iter()
        .enumerate()
        .map(|(s, surface)| {
            let filter: Vec<FilterSample> = placed
                .iter()
                .zip(&collectors)
                .filter(|((owner, _), x)| *owner == s as u32 && !x.buried)
                .map(|((_, c), x)| FilterSample { uv: c.uv, luminance: x.indirect.map(|b| b / PI), tag: c.reason.tag() })
                .collect();
            let extent = surface.extent();
            let open = |uv: DVec2| indirect_grids[s].as_ref().is_none_or(|g| g.open_at(uv));
            DisplayGrid::new(params.filter, surface.lo, surface.hi, extent / params.display_resolution as f64, &filter, params.filter_radius * extent, params.shadow_filter_radius * extent, open)
        })
        .collect();
    let shown_rays = std::sync::atomic::AtomicU64::new(0);
    let reflected = |s: u32, uv: DVec2, triangle: u32, key: u64| -> [f64; 3] {
        let surface = &surfaces[s as usize];
        let e = grids[s as usize].irradiance_at(uv).unwrap_or_else(|| {
            let e = direct.at(surface.point(uv), surface.normal, triangle, (1u64 << 59) + key);
            shown_rays.fetch_add(e.rays, std::sync::atomic::Ordering::Relaxed);
            e.rgb
        });
        let indirect = display[s as usize].at(uv);
        [0, 1, 2].map(|k| surface.reflectance[k] * e[k] / PI + indirect[k])
    };
    let film = render::render(&view, &reflected, size, params.spp_side, progress.step);
    work.direct_rays += shown_rays.into_inner();
    work.display_seconds = clock.elapsed().as_secs_f64();

    let sampled_surfaces = surfaces.iter().map(|s| SampledSurface { object: s.object, material: s.material, normal: s.normal.to_array() }).collect();
    let secondary = polygons
        .iter()
        .enumerate()
        .map(|(i, p)| SecondaryEmitter { surface: p.surface, area: p.area, shot: work.shooting.shot(i, p, &collectors), triangles: p.triangles.clone() })
        .collect();
    Ok(Structured { samples, surfaces: sampled_surfaces, emitters: secondary, film, size, work })
}

/// On a surface lit only by reflection, a probe of its indirect light
/// counts as shadowed (visibility 0 for the placement, else 1) where it
/// receives less than this fraction of what it would with nothing in the
/// way, so that the outline of what hides the room from it is sampled as
/// a shadow boundary ([`placement::light_candidates`]'s penumbra) and the
/// display's filter takes the small cone there. A fraction, not any
/// occlusion at all: nearly every point of a room has some of its senders
/// partly hidden, and the placement's penumbra test marks every
/// visibility strictly between 0 and 1. Half marks the outline of what
/// hides most of the room (a lamp hung under a ceiling) and not the soft
/// shade of a block seen from the ceiling.
pub const SHADOWED: f64 = 0.5;

/// How much coarser than the direct light's probes (`probe_resolution`)
/// the grid is that finds, before the shooting, the outline of what hides
/// the room from a surface lit only by reflection ([`SHADOWED`]); the
/// indirect light's probes after the shooting are a quarter as fine. Each
/// probe gathers from every polygon: at a quarter, this probing took 0.9
/// s of the built-in Cornell box's 10.2 s (whose ceiling has no such
/// outline). An eighth (a twelfth of the white box's ceiling, 17 cm)
/// takes about a quarter of that, and against Mitsuba McGuire's `Original` went
/// 2.10% -> 1.68% (its ceiling round the lamp 5.9% -> 4.1%), its white
/// box against hierarchical-solve 1.16-1.29% -> 1.11-1.36% over four
/// lattice spacings: the outline's place to a cell matters less than
/// having one.
pub const OUTLINE_COARSENING: usize = 8;

/// What `senders` bring to `point` (unit `normal`, on `surface` and mesh
/// `triangle`), each shooting the radiosities whose groups' totals are
/// `totals` ([`shooting::Sender::irradiance`]): the irradiance, the same
/// unoccluded, and the rays cast.
#[allow(clippy::too_many_arguments)]
fn gather(senders: &[shooting::Sender], totals: &[Vec<[f64; 3]>], rays: &SceneRays, point: DVec3, normal: DVec3, surface: u32, triangle: u32) -> ([f64; 3], [f64; 3], u64) {
    let (mut e, mut unoccluded, mut rays_cast) = ([0.0; 3], [0.0; 3], 0);
    for (sender, totals) in senders.iter().zip(totals) {
        let (de, du, r) = sender.irradiance(rays, point, normal, surface, triangle, totals);
        rays_cast += r;
        e.iter_mut().zip(de).for_each(|(e, de)| *e += de);
        unoccluded.iter_mut().zip(du).for_each(|(u, du)| *u += du);
    }
    (e, unoccluded, rays_cast)
}

/// Probes of the reflected light on `surface` (number `s`) with
/// `resolution` cells along its extent, each gathering what `senders`
/// bring ([`gather`]); each probe's visibility 0 where it is
/// [`SHADOWED`], else 1.
fn indirect_probes(surface: &surfaces::Surface, s: u32, resolution: usize, senders: &[shooting::Sender], totals: &[Vec<[f64; 3]>], rays: &SceneRays) -> ProbeGrid {
    ProbeGrid::of(surface, resolution.max(8), |point, triangle, _| {
        let (e, unoccluded, rays_cast) = gather(senders, totals, rays, point, surface.normal, s, triangle);
        (e, if luminance(e) < SHADOWED * luminance(unoccluded) { 0.0 } else { 1.0 }, rays_cast)
    })
}

/// The mesh triangle of `surface` at `uv`, or the one whose centroid is
/// nearest to it: for a sample that rounding put just outside every
/// triangle.
fn triangle_of(surface: &surfaces::Surface, uv: DVec2) -> u32 {
    surface.triangle_at(uv).unwrap_or_else(|| {
        let distance = |c: &[DVec2; 3]| ((c[0] + c[1] + c[2]) / 3.0 - uv).length_squared();
        let best = surface.corners_uv.iter().enumerate().min_by(|a, b| distance(a.1).total_cmp(&distance(b.1))).map_or(0, |(k, _)| k);
        surface.triangles[best]
    })
}
