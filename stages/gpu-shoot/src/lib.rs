//! # gpu-shoot: progressive radiosity on the GPU
//!
//! Paper 004 (chapters 2-4): every triangle gets a region of float
//! lightmap atlases holding radiosity and residual (unshot) radiosity
//! ([`atlas`]); each shot selects on the GPU the triangle with the largest
//! residual power (with ambient overshooting, 004 Sec. 4.3.5, the largest
//! positive `(dB + dB') A`, then the negative remainders it leaves by
//! magnitude), and stops when `sum |dB| A` is small; it renders the scene from each of its substructured
//! samples into visibility maps (a hemicube by rasterization, or the
//! paper's single-pass stereographic projection), and lets every covered
//! texel of the atlas test its depth against them and gather the
//! disc-approximation form factor (Eq. 2.2 / 4.1) times the shot power,
//! scaled by its reflectance (Eq. 4.2-4.3). Goniometric lights
//! ([`Luminaire`]: the manifest's tables, read from EULUMDAT and IES files
//! by mesh-prep) shoot first, as point sources with
//! intensity `I_max LDT(C, gamma)` (Eq. 3.4) over a full cube of faces.
//!
//! Surface detail from `mesh-prep --surface` ([`detail`]): per-texel
//! reflectance from diffuse textures (004 Sec. 4.2), alpha masks that
//! remove texels and discard their fragments in the visibility maps (Sec.
//! 4.3.4), normal maps for the cosines (Sec. 2.3.3). Planar mirrors and
//! thin glass by the reflection tree of virtual shooters built during each
//! shot ([`mirrors`], Sec. 4.3.2-4.3.3). Diffuse transmission
//! through the twin faces of two-sided translucent materials
//! ([`transmission`], Sec. 4.3.1, Eq. 4.4). Adaptive subdivision
//! at shadow boundaries ([`tiling`], Sec. 2.4) splits receivers into tiles
//! before a triangle first shoots.
//!
//! The result is written as the lightmap atlas with its region table
//! (`schemas::lightmap`), and as a `solution.exr` whose leaves average the
//! atlas ([`output`]), so `grid-gather --mode preview`, `tonemap` and
//! `compare` treat it like a hierarchical solution.
//!
//! Its knobs are declared once, in [`Params`] (and [`Adaptive`]); their
//! table with ranges and defaults is `gpu-shoot --print-knobs`, in the
//! README's "Stage knobs".

pub mod atlas;
pub mod convergence;
pub mod detail;
pub mod emitters;
pub mod exposure;
pub mod gpu;
pub mod mirrors;
pub mod output;
pub mod reference;
pub mod report;
pub mod tiling;
pub mod transmission;

use atlas::{Atlas, HIDDEN_CORNERS};
use detail::{Detail, TexelDetail};
use glam::DVec3;
use radiometry::bounds::Aabb;
use radiometry::geometry::frame_with_normal;
pub use radiometry::photometry::Luminaire;
use gpu::{Gpu, GpuGroup, GpuParams, GpuSample, GpuTexel, GpuTri, Setup};
use schemas::header::{Provenance, Schema};
use schemas::lightmap::{Lightmap, Shot};
use schemas::mesh::{Manifest, Mesh};
use schemas::surface::Surface;
use serde::{Deserialize, Serialize};
use std::time::Instant;
use tiling::Tile;
use stage_kit::scene::triangle_corners;

/// How visibility from a shooting sample is found.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Visibility {
    /// Five faces of a cube around the normal, by rasterization (Cohen and
    /// Greenberg; 004 Table 4.1 "hc").
    #[default]
    Hemicube,
    /// The hemisphere in one pass by the stereographic projection of the
    /// vertices (004 Sec. 2.3; edges stay straight, so large triangles near
    /// the horizon are distorted, 004 Fig. 4.4).
    Stereographic,
}

stage_kit::show_by_name!(Visibility);

stage_kit::knobs! {
    /// The stage's parameters.
    pub struct Params {
        /// Covered texels to aim for over the whole scene.
        texels: f64 = 32768.0, "texels", value(at_least(1.0));
        /// Smallest side of a triangle's lightmap region.
        min_size: u32 = 2, "texels", value(2..=4096);
        /// Largest side of a triangle's lightmap region (at least `min_size`).
        max_size: u32 = 512, "texels", value(2..=4096);
        /// Substructuring: shoot from groups of `2^level` x `2^level` texels (a small emitter clear of other surfaces from finer ones).
        shoot_level: u32 = 3, "", value(0..=8);
        /// How visibility from a shooting sample is found: `hemicube` or
        /// `stereographic`.
        visibility: Visibility = Visibility::Hemicube, "", value;
        /// Side of a hemicube face / the stereographic map.
        resolution: u32 = 128, "pixels", value(8..=2048);
        /// Relative depth tolerance of the visibility test.
        tolerance: f64 = 0.02, "", value(custom("in [0, 0.5)", |v: &f64| (0.0..0.5).contains(v)));
        /// Ambient overshooting (004 Eq. 4.9); off by default, because
        /// counted by `sum |dB| A` it converges slower (Cornell box, 8000
        /// texels, to 99%: 1032 shots against 121).
        overshoot: bool = false, "", switch;
        /// Stop when the unshot power, `sum |dB| A` (negative residuals
        /// left by overshooting count by magnitude), is at most 1 - this of
        /// the emitted power.
        convergence_target: f64 = 0.999, "fraction of emitted power", value(custom("in [0, 1]", |v: &f64| (0.0..=1.0).contains(v)));
        /// Stop after this many shots.
        max_shots: usize = 100_000, "shots", value;
        /// Add rho x ambient to the solution's radiosity (004 Eq. 2.4): a
        /// display aid for an unconverged solution; in an open scene it adds
        /// light that is not there.
        // Off by default: the ambient term spreads the unshot power over the
        // scene as if it were closed (paper 002's one-bounce receiver got
        // +6.3% flux, 1.3% without it), so a converged solution would be
        // biased. Ambient overshooting (`overshoot`) is unaffected.
        ambient: bool = false, "", switch;
        /// Texels per solution leaf, about.
        texels_per_leaf: f64 = 4.0, "texels", value(at_least(1.0));
        /// Most windows (planar mirrors and thin panes, 004 Sec.
        /// 4.3.2-4.3.3) on a light path of the reflection tree.
        // Written only where not the default, so the artifacts of a run
        // without it keep their bits (as reflection_threshold, adaptive).
        #[serde(skip_serializing_if = "is_default_depth")]
        reflection_depth: u32 = REFLECTION_DEPTH, "windows", value(1..=16);
        /// Cut a node of the reflection tree whose power bound (004 Eq. 4.6,
        /// made a bound) is under this fraction of the emitted power.
        #[serde(skip_serializing_if = "is_default_threshold")]
        reflection_threshold: f64 = REFLECTION_THRESHOLD, "fraction of emitted power", value(custom("in [0, 1)", |v: &f64| (0.0..1.0).contains(v)));
        /// Adaptive subdivision at shadow boundaries (004 Sec. 2.4; not with
        /// `--lightmap`).
        #[serde(skip_serializing_if = "Option::is_none")]
        adaptive: Option<Adaptive> = None, "", group;
    }
}

stage_kit::knobs! {
    /// Adaptive subdivision at shadow boundaries (004 Sec. 2.4): before a
    /// triangle first shoots, every receiving tile whose visible fraction
    /// `n_v / n_r` (texel-sample pairs the visibility maps see over those
    /// facing each other) lies in `[lower, upper]` is split 1:4, up to
    /// `levels` times per input triangle.
    pub struct Adaptive {
        /// `b_l`: split a receiver whose visible fraction is at least this
        /// (one less is in shadow but for a short boundary).
        lower: f64 = 0.05, "visible fraction", value(custom("in [0, 1]", |v: &f64| (0.0..=1.0).contains(v)));
        /// `b_u`: ... and at most this (one more is lit but for a short
        /// boundary; at least `lower`).
        upper: f64 = 0.95, "visible fraction", value(custom("in [0, 1]", |v: &f64| (0.0..=1.0).contains(v)));
        /// Most 1:4 splits of an input triangle.
        levels: u32 = 3, "splits", value(0..=8);
    }
}

impl Adaptive {
    /// Whether a receiver with visible fraction `ratio` is crossed by a
    /// shadow boundary worth a split: `b_l <= ratio <= b_u`.
    pub fn crossed(&self, ratio: f64) -> bool {
        (self.lower..=self.upper).contains(&ratio)
    }
}

/// The default `reflection_depth`.
const REFLECTION_DEPTH: u32 = 4;
/// The default `reflection_threshold`.
const REFLECTION_THRESHOLD: f64 = 1e-4;

fn is_default_depth(depth: &u32) -> bool {
    *depth == REFLECTION_DEPTH
}

fn is_default_threshold(threshold: &f64) -> bool {
    *threshold == REFLECTION_THRESHOLD
}

impl Params {
    /// What the knobs' ranges do not say, if anything is wrong:
    /// `min_size <= max_size`, and the adaptive bounds `lower <= upper`.
    pub fn conflict(&self) -> Option<String> {
        if self.max_size < self.min_size {
            return Some(format!("max_size must be at least min_size ({}), not {}", self.min_size, self.max_size));
        }
        match &self.adaptive {
            Some(a) if a.lower > a.upper => Some(format!("adaptive.upper must be at least adaptive.lower ({}), not {}", a.lower, a.upper)),
            _ => None,
        }
    }
}

/// The light distribution texture of a luminaire as the shader reads it
/// (004 Sec. 2.3.2): `[nc, ng, C angles, gamma angles, values]`, the values
/// the table's intensities over its largest, so the shot's power carries
/// `I_max` in W/sr ([`Luminaire::i_max`]) and the texture stays in [0, 1].
pub fn light_table(light: &Luminaire) -> Vec<f32> {
    let d = &light.distribution;
    let i_max = d.i_max();
    let norm = if i_max > 0.0 { i_max } else { 1.0 };
    let mut t = vec![d.c_angles.len() as f32, d.gamma_angles.len() as f32];
    t.extend(d.c_angles.iter().map(|&x| x as f32));
    t.extend(d.gamma_angles.iter().map(|&x| x as f32));
    t.extend(d.intensity.iter().map(|&x| (x / norm) as f32));
    t
}

/// The work a solve did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Work {
    /// Shots fired (lights included).
    pub shots: usize,
    /// Shooting samples over all shots.
    pub samples: u64,
    /// Visibility map layers rendered.
    pub layers: u64,
    /// Texel-sample pairs evaluated by the receiver pass.
    pub receiver_evaluations: u64,
    /// Seconds spent before the first shot.
    pub setup_seconds: f64,
    /// Seconds spent shooting.
    pub shoot_seconds: f64,
    /// Texels of the texture atlas uploaded for the visibility maps'
    /// alpha test (0: no alpha mask, nothing allocated).
    pub mask_texels: u64,
    /// Texels buried inside a solid, which do not take part in the
    /// shooting ([`exposure`]), in the last atlas.
    pub buried_texels: u64,
    /// Rays cast to find them, every atlas built.
    pub burial_rays: u64,
    /// Covered texels the adaptive subdivision added.
    pub elements_added: u64,
    /// Tiles it added (3 per split).
    pub tiles_added: u64,
    /// Seconds it took (counting, splitting, copying down, rebuilding).
    pub subdivision_seconds: f64,
    /// Triangles of translucent materials that are not two-sided: they
    /// transmit nothing ([`transmission`]).
    pub one_sided_translucent: u64,
    /// The reflection tree's nodes, depth, power bounds and time
    /// ([`mirrors`]; zero for a scene without specular materials).
    pub reflection: mirrors::TreeWork,
}

/// The result of a solve.
#[derive(Clone, Debug)]
pub struct Solved {
    /// The atlas layout, one region per tile.
    pub atlas: Atlas,
    /// The tiles ([`tiling`]): one per input triangle without adaptive
    /// subdivision.
    pub tiles: Vec<Tile>,
    /// Radiosity per covered texel (order of `atlas.texels`), W/m².
    pub radiosity: Vec<[f32; 3]>,
    /// Residual per covered texel, W/m².
    pub residual: Vec<[f32; 3]>,
    /// Ambient term at the end (004 Eq. 2.4), W/m², RGB.
    pub ambient: [f64; 3],
    /// Total emitted power (surfaces and lights), W, RGB.
    pub emitted_power: [f64; 3],
    /// Unshot fraction before the first shot (magnitudes: 1).
    pub initial_unshot: f64,
    /// Every shot.
    pub shots: Vec<Shot>,
    /// Work counters.
    pub work: Work,
    /// Per triangle, the GPU reduction at the end: `sum dB A` (rgb, w: area)
    /// and `sum |dB| A`, for tests against [`reference::triangle_power`].
    pub triangle_power: Vec<[f32; 4]>,
}

impl Solved {
    /// The mesh of its tiles: the input `mesh` itself without adaptive
    /// subdivision.
    pub fn tile_mesh<'a>(&self, mesh: &'a Mesh) -> std::borrow::Cow<'a, Mesh> {
        if tiling::is_identity(&self.tiles) {
            std::borrow::Cow::Borrowed(mesh)
        } else {
            std::borrow::Cow::Owned(tiling::mesh_of(mesh, &self.tiles))
        }
    }
}

/// The area-weighted mean reflectance of `texels` (0 where none is
/// opaque): a textured triangle's for the ambient term and overshooting.
fn mean_rho(texels: &[GpuTexel]) -> [f32; 4] {
    let area: f64 = texels.iter().map(|x| x.position_area[3] as f64).sum();
    let mean = |c: usize| if area > 0.0 { texels.iter().map(|x| x.rho[c] as f64 * x.position_area[3] as f64).sum::<f64>() / area } else { 0.0 };
    [mean(0) as f32, mean(1) as f32, mean(2) as f32, 0.0]
}

fn f4(v: [f64; 3]) -> [f32; 4] {
    [v[0] as f32, v[1] as f32, v[2] as f32, 0.0]
}

/// What every build of the solver's state shares.
struct Context<'a> {
    device: &'a wgpu::Device,
    mesh: &'a Mesh,
    manifest: &'a Manifest,
    surface: Option<&'a Surface>,
    params: &'a Params,
    /// Region size per object, from the input mesh.
    sizes: Vec<u32>,
    /// Per input triangle: its twin, if any.
    twins: Vec<Option<u32>>,
    layers: u32,
    ldt_capacity: usize,
    /// The specular coefficients, where a material is specular.
    specular: Option<&'a mirrors::Specular>,
    /// Samples per batch (the virtual samples of a level).
    batch: u32,
    /// What finds the texels buried inside solids.
    burial: exposure::Burial,
}

/// The solver's state for one set of tiles.
struct Built {
    atlas: Atlas,
    texels: Vec<GpuTexel>,
    tris: Vec<GpuTri>,
    gpu: Gpu,
    /// Per tile: whether a normal map perturbs its texels' normals.
    normal_mapped: Vec<bool>,
    mask_texels: u64,
    /// Texels buried inside a solid, and the rays that found them.
    buried: (u64, u64),
    /// Translucent input triangles that transmit nothing (not two-sided).
    one_sided: u64,
    /// The first virtual sample of the reflection tree (after the
    /// largest shooter's samples).
    virtual_base: u32,
}

/// Initial radiosity and residual per covered texel of a new atlas.
type Init<'a> = &'a dyn Fn(&Atlas) -> (Vec<[f32; 4]>, Vec<[f32; 4]>);

/// Bakes the atlas of `tiles`, applies the surface detail, and uploads it
/// all; radiosity and residual start as the emission, or as `init` says.
fn build(c: &Context, tiles: &[Tile], init: Option<Init>) -> Built {
    let identity = tiling::is_identity(tiles);
    let tiled;
    let mesh = if identity {
        c.mesh
    } else {
        tiled = tiling::mesh_of(c.mesh, tiles);
        &tiled
    };
    let tiled_surface;
    let surface = match c.surface {
        Some(s) if !identity => {
            tiled_surface = tiling::surface_of(s, tiles);
            Some(&tiled_surface)
        }
        s => s,
    };
    let manifest = c.manifest;
    let levels = emitters::shoot_levels(mesh, manifest, &c.sizes, c.params.shoot_level);
    let mut atlas = atlas::bake_sized(mesh, c.sizes.clone(), &levels);
    let detail = surface.and_then(|s| Detail::new(mesh, s));
    // Per covered texel, what its textures make of it (None: its material has none).
    let details: Vec<Option<TexelDetail>> = match &detail {
        Some(d) => atlas
            .texels
            .iter()
            .map(|x| {
                let t = x.triangle as usize;
                let (i, j) = x.indices(atlas.regions[t]);
                d.texel(mesh, manifest, t, atlas.regions[t], i, j)
            })
            .collect(),
        None => Vec::new(),
    };
    let detail_of = |k: usize| details.get(k).copied().flatten();
    let masks = detail.as_ref().filter(|d| d.masked(mesh));
    let (buried, mut burial_rays) = c.burial.texels(&atlas, tiles);
    if masks.is_some() || buried.contains(&true) {
        let mut has_buried = vec![false; mesh.triangles.len()];
        for (texel, _) in atlas.texels.iter().zip(&buried).filter(|(_, b)| **b) {
            has_buried[texel.triangle as usize] = true;
        }
        let coverage: Vec<f64> = (0..atlas.texels.len()).map(|k| detail_of(k).map_or(1.0, |x| x.coverage)).collect();
        let (exposed, rays) = c.burial.hide(&mut atlas, mesh, tiles, &buried);
        burial_rays += rays;
        for (texel, &e) in atlas.texels.iter_mut().zip(&exposed) {
            texel.buried = e == 0.0;
        }
        atlas.cover(&exposed, &coverage, &|t| has_buried[t] || masks.is_some_and(|d| d.mask(mesh, t).is_some()));
    }
    let material = |t: usize| &manifest.materials[mesh.triangles[t].material as usize];
    let texels: Vec<GpuTexel> = atlas
        .texels
        .iter()
        .enumerate()
        .map(|(k, x)| {
            let tri = &mesh.triangles[x.triangle as usize];
            let here = detail_of(k);
            let normal = here.map_or(tri.normal, |d| d.normal.as_vec3().to_array());
            GpuTexel {
                position_area: [x.position[0], x.position[1], x.position[2], x.area],
                normal_triangle: [tri.normal[0], tri.normal[1], tri.normal[2], f32::from_bits(x.triangle)],
                rho: {
                    let mut rho = f4(here.map_or(material(x.triangle as usize).diffuse, |d| d.rho));
                    // w: 1 on the hypotenuse (half a texel), read by the near-field form factor.
                    rho[3] = if x.on_hypotenuse(atlas.regions[x.triangle as usize]) { 1.0 } else { 0.0 };
                    rho
                },
                shading: [normal[0], normal[1], normal[2], 0.0],
            }
        })
        .collect();
    let emission: Vec<[f32; 4]> = atlas.texels.iter().map(|x| f4(material(x.triangle as usize).emission)).collect();
    let half_edges = |t: usize| {
        let p = triangle_corners(mesh, t);
        let n = 2.0 * atlas.regions[t].size as f64;
        [f4(((p[1] - p[0]) / n).to_array()), f4(((p[2] - p[0]) / n).to_array())]
    };
    let tris: Vec<GpuTri> = atlas
        .triangles
        .iter()
        .enumerate()
        .map(|(t, r)| GpuTri {
            first: r.first,
            count: r.count,
            group_first: r.group_first,
            group_count: r.group_count,
            area: atlas.texels[r.first as usize..(r.first + r.count) as usize].iter().map(|x| x.area).sum(),
            texel_area: atlas.regions[t].texel_area,
            _pad: [0.0; 2],
            rho: if details.is_empty() { f4(material(t).diffuse) } else { mean_rho(&texels[r.first as usize..(r.first + r.count) as usize]) },
            half_u: half_edges(t)[0],
            half_v: half_edges(t)[1],
        })
        .collect();
    let groups: Vec<GpuGroup> = atlas.groups.iter().map(|g| GpuGroup { first: g.first, count: g.count, _pad: [0; 2] }).collect();
    // w: 2 for the corners of a triangle with a twin, whose back face the
    // visibility maps leave out (visibility.wgsl), else 1.
    let vertices: Vec<[f32; 4]> = mesh
        .triangles
        .iter()
        .zip(tiles)
        .flat_map(|(t, tile)| t.vertices.map(|v| {
            let p = mesh.positions[v as usize];
            [p[0], p[1], p[2], if c.twins[tile.root as usize].is_some() { 2.0 } else { 1.0 }]
        }))
        .collect();
    let max_groups = atlas.triangles.iter().map(|t| t.group_count).max().unwrap_or(1).max(1);
    // The alpha masks for the visibility maps (004 Sec. 4.3.4), only where
    // some triangle is masked.
    let masks = detail.as_ref().filter(|d| d.masked(mesh)).map(|d| d.mask_tables(mesh));
    let transmission = transmission::table(&atlas, tiles, c.mesh, manifest, &c.twins);
    let (radiosity, residual) = match init {
        Some(init) => init(&atlas),
        None => (emission.clone(), emission),
    };
    // Per tile, whether its input triangle is specular; the virtual
    // samples follow the shooters' in the samples buffer.
    let specular_flags: Vec<u32> = c.specular.map_or(Vec::new(), |s| {
        let flags = s.flags();
        tiles.iter().map(|t| flags[t.root as usize]).collect()
    });
    let windows_per_level = specular_flags.iter().filter(|&&f| f != 0).count();
    let virtual_base = max_groups.max(1);
    let virtual_samples = if c.specular.is_some() { c.params.reflection_depth * c.batch } else { 0 };
    let gpu = Gpu::new(
        c.device,
        &Setup {
            texels: &texels,
            tris: &tris,
            groups: &groups,
            radiosity: &radiosity,
            residual: &residual,
            vertices: &vertices,
            res: c.params.resolution,
            layers: c.layers,
            sample_capacity: max_groups.max(1) + virtual_samples,
            ldt_capacity: c.ldt_capacity,
            masks: masks.as_ref().map(|(t, m)| (t.as_slice(), m.as_slice())),
            adaptive: c.params.adaptive.is_some(),
            transmission: transmission.as_ref().map(|(table, _)| table.as_slice()),
            mirrors: c.specular.map(|_| gpu::MirrorSetup {
                specular: &specular_flags,
                levels: c.params.reflection_depth as usize,
                windows_per_level,
                views_per_level: c.batch as usize,
            }),
        },
    );
    let normal_mapped = (0..tiles.len()).map(|t| detail.as_ref().is_some_and(|d| d.normal_mapped(mesh, t))).collect();
    let mask_texels = masks.as_ref().map_or(0, |(_, m)| m.len() as u64);
    let one_sided = transmission.map_or(0, |(_, n)| n as u64);
    let buried = (buried.iter().filter(|b| **b).count() as u64, burial_rays);
    Built { atlas, texels, tris, gpu, normal_mapped, mask_texels, buried, one_sided, virtual_base }
}

/// The samples of tile `shooter` (positions, frames, polygons; the GPU
/// fills their powers): one per group, `offset` in front of it, its
/// cosine's normal the group's mean perturbed normal under a normal map.
fn samples_of(b: &Built, mesh: &Mesh, tiles: &[Tile], shooter: usize, offset: f64) -> Vec<GpuSample> {
    let range = b.atlas.triangles[shooter];
    let normal = DVec3::from(mesh.triangles[tiles[shooter].root as usize].normal.map(f64::from));
    let [t, bt, n] = frame_with_normal(normal);
    b.atlas.groups[range.group_first as usize..(range.group_first + range.group_count) as usize]
        .iter()
        .map(|g| {
            let shading = if b.normal_mapped[shooter] {
                let group = &b.texels[g.first as usize..(g.first + g.count) as usize];
                let sum = group.iter().fold(DVec3::ZERO, |acc, x| acc + DVec3::from([0, 1, 2].map(|c| x.shading[c] as f64)) * x.position_area[3] as f64);
                sum.try_normalize().unwrap_or(n)
            } else {
                n
            };
            let c = DVec3::from(g.centroid.map(f64::from)) + n * offset;
            let mut polygon = g.polygon.map(|p| [p[0], p[1], p[2], 0.0]);
            polygon[0][3] = g.corners as f32;
            polygon[1][3] = g.extent;
            let mut hidden = g.hidden.map(|p| [p[0], p[1], p[2], 0.0]);
            hidden[0][3] = g.hidden_corners as f32;
            GpuSample {
                position_area: [c.x as f32, c.y as f32, c.z as f32, g.area],
                t: f4(t.to_array()),
                b: f4(bt.to_array()),
                n: f4(n.to_array()),
                power: [0.0; 4],
                shading: [shading.x as f32, shading.y as f32, shading.z as f32, g.opaque],
                polygon,
                hidden,
                quadrants: [[0.0; 4]; 8],
            }
        })
        .collect()
}

fn sum3(v: [f64; 3]) -> f64 {
    v[0] + v[1] + v[2]
}

/// Runs the progressive solver on `device` / `queue`. `surface` (from
/// `mesh-prep --surface`) gives textures, alpha masks and normal maps
/// ([`detail`]); without it, or where no material has a texture, every
/// texel takes its material's reflectance and its triangle's normal.
/// `on_shot` sees every shot as it completes (for a progress bar).
#[allow(clippy::too_many_arguments)]
pub fn solve(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    mesh: &Mesh,
    manifest: &Manifest,
    surface: Option<&Surface>,
    lights: &[Luminaire],
    params: &Params,
    on_shot: &mut dyn FnMut(&Shot),
) -> Result<Solved, String> {
    let started = Instant::now();
    if mesh.triangles.is_empty() {
        return Err("the mesh has no triangles".into());
    }
    // Scene size: near plane, far distance, and the sample offset.
    let scene = Aabb::around(mesh.positions.iter().map(|p| DVec3::from(p.map(f64::from))).chain(lights.iter().map(|l| l.position)));
    let diagonal = (scene.max - scene.min).length().max(1e-6);
    let hemicube = params.visibility == Visibility::Hemicube;
    let layers_per_sample = if hemicube { 6 } else { 1 };
    // Visibility layers per batch: at most 256 (WebGPU's default array
    // limit) and 256 MiB of maps.
    let per_layer = 4 * (params.resolution as u64).pow(2);
    let layer_budget = (256u64).min((256u64 << 20) / per_layer).max(6) as u32;
    let batch = (layer_budget / 6).max(1);
    let layers = if hemicube { batch * 6 } else { (layer_budget / 6 * 6).max(6) };
    let batch_area = if hemicube { batch } else { layers };
    // With specular materials each sample also needs one frustum map per
    // level of the reflection tree's branch, kept while its children are
    // shot (004 Sec. 4.3.2: one map per recursion depth); lights use 6.
    let specular = mirrors::Specular::of(mesh, manifest);
    let (layers, batch_area) = match &specular {
        None => (layers, batch_area),
        Some(_) => {
            let per_sample = layers_per_sample + params.reflection_depth;
            let batch = (layer_budget / per_sample).max(1);
            ((batch * per_sample).max(6 + params.reflection_depth), batch)
        }
    };
    let context = Context {
        device,
        mesh,
        manifest,
        surface,
        params,
        sizes: atlas::object_sizes(mesh, manifest.objects.len(), params.texels, params.min_size, params.max_size),
        twins: mesh.twins(),
        layers,
        ldt_capacity: lights.iter().map(|l| light_table(l).len()).max().unwrap_or(4),
        specular: specular.as_ref(),
        batch: batch_area,
        burial: exposure::Burial::new(mesh),
    };
    let mut tiles = tiling::identity(mesh);
    let mut built = build(&context, &tiles, None);
    let tris = &built.tris;
    let material = |t: usize| &manifest.materials[mesh.triangles[t].material as usize];
    let total_area: f64 = tris.iter().map(|t| t.area as f64).sum();
    let mut interreflection = [0.0f32; 4];
    for (c, r) in interreflection.iter_mut().take(3).enumerate() {
        let mean_rho: f64 = tris.iter().map(|t| t.rho[c] as f64 * t.area as f64).sum::<f64>() / total_area;
        *r = (1.0 / (1.0 - mean_rho).max(1e-6)) as f32;
    }
    let mut emitted = [0.0f64; 3];
    for (t, tri) in tris.iter().enumerate() {
        for (c, e) in emitted.iter_mut().enumerate() {
            *e += material(t).emission[c] * tri.area as f64;
        }
    }
    let light_flux: Vec<f64> = lights.iter().map(Luminaire::flux).collect();
    for f in &light_flux {
        for e in emitted.iter_mut() {
            *e += f;
        }
    }
    let emitted_total = sum3(emitted).max(f64::MIN_POSITIVE);
    let mut base = GpuParams {
        n_texels: built.texels.len() as u32,
        n_tris: tris.len() as u32,
        shooter: u32::MAX,
        res: params.resolution,
        mode: if hemicube { 0 } else { 1 },
        overshoot: params.overshoot as u32,
        tolerance: params.tolerance as f32,
        near: (1e-5 * diagonal) as f32,
        far: (4.0 * diagonal) as f32,
        total_area: total_area as f32,
        interreflection,
        ..Default::default()
    };
    let mut work = Work { setup_seconds: started.elapsed().as_secs_f64(), mask_texels: built.mask_texels, buried_texels: built.buried.0, burial_rays: built.buried.1, one_sided_translucent: built.one_sided, ..Default::default() };
    let shooting = Instant::now();
    let mut shots = Vec::new();
    let mut unshot_lights: f64 = light_flux.iter().map(|f| 3.0 * f).sum();
    let unshot_of = |sel: &gpu::GpuSelection, lights: f64| {
        (sel.unshot[0] as f64 + sel.unshot[1] as f64 + sel.unshot[2] as f64 + lights).abs() / emitted_total
    };
    // The stop test and the reported convergence: overshooting leaves
    // negative residuals, which cancel positive ones in the net sum (a
    // floor that overshot a lamp's power stopped the run before the lamp
    // shot), so the remaining error is bounded by the magnitudes.
    let magnitude_of = |sel: &gpu::GpuSelection, lights: f64| {
        (sel.unshot_abs[0] as f64 + sel.unshot_abs[1] as f64 + sel.unshot_abs[2] as f64 + lights) / emitted_total
    };
    let mut selection = built.gpu.select(device, queue, &base);
    let initial_unshot = magnitude_of(&selection, unshot_lights);
    let offset = 1e-6 * diagonal;
    // The reflection tree's mesh and coefficients: the tiles' (rebuilt
    // when adaptive subdivision splits them).
    let mut tree_mesh = std::borrow::Cow::Borrowed(mesh);
    let mut tree_specular = specular.clone();
    let cut = params.reflection_threshold * emitted_total;
    let knobs = mirrors::Knobs { depth: params.reflection_depth, cut, diagonal };
    // Lights first: all their power is unshot, and a point source shoots
    // once (6 full cube faces; the stereographic map covers a hemisphere
    // only, so lights always use the cube).
    for (k, light) in lights.iter().enumerate() {
        if shots.len() >= params.max_shots {
            break;
        }
        let [r0, u0, n0] = light.frame;
        let i = light.i_max() as f32;
        let p = light.position.to_array();
        let sample = GpuSample {
            position_area: [p[0] as f32, p[1] as f32, p[2] as f32, 0.0],
            t: f4(r0.to_array()),
            b: f4(u0.to_array()),
            n: f4(n0.to_array()),
            power: [i, i, i, 1.0],
            shading: [0.0; 4],
            polygon: [[0.0; 4]; 5],
            hidden: [[0.0; 4]; HIDDEN_CORNERS],
            quadrants: [[0.0; 4]; 8],
        };
        built.gpu.upload_samples(queue, &[sample], Some(&light_table(light)));
        let p = GpuParams { shooter: u32::MAX, sample_first: 0, sample_count: 1, layers_per_sample: 6, mode: 0, ..base };
        built.gpu.shoot_batch(device, queue, &p, false);
        if let Some(s) = &tree_specular {
            mirrors::Tree { mesh: &tree_mesh, specular: s, knobs, virtual_base: built.virtual_base }.shoot(&built.gpu, device, queue, &p, &[sample], &mut work.reflection);
        }
        work.layers += 6;
        work.samples += 1;
        work.receiver_evaluations += built.texels.len() as u64;
        unshot_lights -= 3.0 * light_flux[k];
        selection = built.gpu.select(device, queue, &base);
        let shot = Shot { shooter: format!("light {k}"), samples: 1, unshot_fraction: unshot_of(&selection, unshot_lights), unshot_magnitude_fraction: magnitude_of(&selection, unshot_lights), seconds: shooting.elapsed().as_secs_f64() };
        on_shot(&shot);
        shots.push(shot);
    }
    // Tiles that have been tested for subdivision as shooters.
    let mut tested = vec![false; tiles.len()];
    while shots.len() < params.max_shots && magnitude_of(&selection, unshot_lights) > 1.0 - params.convergence_target {
        let shooter = selection.shooter[0];
        if shooter as usize >= built.tris.len() || selection.score[0] <= 0.0 {
            break;
        }
        let range = built.atlas.triangles[shooter as usize];
        // Batches of the shooter's samples: (first, count).
        let batches: Vec<(u32, u32)> = (0..range.group_count).step_by(batch_area as usize).map(|first| (first, (range.group_count - first).min(batch_area))).collect();
        let shot_params = GpuParams { shooter, group_count: range.group_count, layers_per_sample, ..base };
        if let Some(adaptive) = params.adaptive.as_ref().filter(|_| !tested[shooter as usize]) {
            // 004 Sec. 2.4: before a triangle first shoots, split the
            // receivers its shadow boundaries cross, again and again.
            let splitting = Instant::now();
            let shooter_tile = tiles[shooter as usize];
            tested[shooter as usize] = true;
            built.gpu.upload_samples(queue, &samples_of(&built, mesh, &tiles, shooter as usize, offset), None);
            for &(first, count) in &batches {
                built.gpu.count_batch(device, queue, &GpuParams { sample_first: first, sample_count: count, ..shot_params }, hemicube);
                work.layers += count as u64 * if hemicube { 5 } else { 1 };
            }
            let counts = built.gpu.counts(device, queue);
            let split: Vec<bool> = counts
                .iter()
                .enumerate()
                .map(|(t, &[n_r, n_v])| t != shooter as usize && tiles[t].level < adaptive.levels && n_r > 0 && adaptive.crossed(n_v as f64 / n_r as f64))
                .collect();
            if split.contains(&true) {
                let (next, origin) = tiling::split(mesh, &tiles, &split);
                let radiosity = built.gpu.read_vec4(device, queue, &built.gpu.radiosity, built.texels.len());
                let residual = built.gpu.read_vec4(device, queue, &built.gpu.residual, built.texels.len());
                let rgb = |v: Vec<[f32; 4]>| v.into_iter().map(|x| [x[0], x[1], x[2]]).collect::<Vec<_>>();
                let old = output::lightmap_of(&built.atlas, &rgb(radiosity), &rgb(residual), &tiling::mesh_of(mesh, &tiles), Lightmap::header(Provenance::in_memory("gpu-shoot")));
                let copied = |atlas: &Atlas| output::copy_down(&old, &tiles, atlas, &next, &origin);
                let texels_before = built.texels.len();
                built = build(&context, &next, Some(&copied));
                work.elements_added += built.texels.len().saturating_sub(texels_before) as u64;
                work.buried_texels = built.buried.0;
                work.burial_rays += built.buried.1;
                work.tiles_added += (next.len() - tiles.len()) as u64;
                // A split tile is new: its children have not shot.
                tested = origin.iter().zip(&next).map(|(&o, tile)| tested[o] && tiles[o] == *tile).collect();
                tiles = next;
                if specular.is_some() {
                    tree_mesh = std::borrow::Cow::Owned(tiling::mesh_of(mesh, &tiles));
                    tree_specular = mirrors::Specular::of(&tree_mesh, manifest);
                }
                // The shooter counts again: the new tiles its boundaries
                // cross split further, up to the level limit.
                if let Some(t) = tiles.iter().position(|x| *x == shooter_tile) {
                    tested[t] = false;
                }
                base.n_texels = built.texels.len() as u32;
                base.n_tris = built.tris.len() as u32;
            }
            work.subdivision_seconds += splitting.elapsed().as_secs_f64();
            // Select again: the tiles (and the shooter's index) changed.
            selection = built.gpu.select(device, queue, &base);
            continue;
        }
        built.gpu.upload_samples(queue, &samples_of(&built, mesh, &tiles, shooter as usize, offset), None);
        built.gpu.prepare(device, queue, &shot_params);
        // The reflection tree mirrors the samples with their powers.
        let root = if tree_specular.is_some() { built.gpu.read_samples(device, queue, range.group_count) } else { Vec::new() };
        for &(first, count) in &batches {
            let batch_params = GpuParams { sample_first: first, sample_count: count, ..shot_params };
            built.gpu.shoot_batch(device, queue, &batch_params, hemicube);
            if let Some(s) = &tree_specular {
                mirrors::Tree { mesh: &tree_mesh, specular: s, knobs, virtual_base: built.virtual_base }.shoot(&built.gpu, device, queue, &batch_params, &root[first as usize..(first + count) as usize], &mut work.reflection);
            }
            work.layers += count as u64 * if hemicube { 5 } else { 1 };
        }
        built.gpu.finish(device, queue, &shot_params, range.count);
        work.samples += range.group_count as u64;
        work.receiver_evaluations += built.texels.len() as u64 * range.group_count as u64;
        selection = built.gpu.select(device, queue, &base);
        let shot = Shot {
            shooter: format!("triangle {shooter}"),
            samples: range.group_count,
            unshot_fraction: unshot_of(&selection, unshot_lights),
            unshot_magnitude_fraction: magnitude_of(&selection, unshot_lights),
            seconds: shooting.elapsed().as_secs_f64(),
        };
        on_shot(&shot);
        shots.push(shot);
    }
    work.shots = shots.len();
    work.shoot_seconds = shooting.elapsed().as_secs_f64();
    let n = built.texels.len();
    let gpu = &built.gpu;
    let radiosity = gpu.read_vec4(device, queue, &gpu.radiosity, n).into_iter().map(|v| [v[0], v[1], v[2]]).collect();
    let residual = gpu.read_vec4(device, queue, &gpu.residual, n).into_iter().map(|v| [v[0], v[1], v[2]]).collect();
    let ambient = [0, 1, 2].map(|c| selection.ambient[c] as f64);
    let triangle_power = gpu.read_vec4(device, queue, &gpu.tri_power, 2 * built.tris.len());
    Ok(Solved { atlas: built.atlas, tiles, radiosity, residual, ambient, emitted_power: emitted, initial_unshot, shots, work, triangle_power })
}
