//! The structured samples (`samples.exr`, written by `structured-sample`):
//! the illumination samples of paper 002 Section 3.2, each with the reason
//! it was placed ("tagged samples"), its luminance, and the secondary
//! emitter polygon it is a vertex of.
//!
//! Layers (tables):
//! - `sample`: position (mesh frame, m), surface, triangle, tag, reason,
//!   isolux level, direct and total luminance, secondary emitter;
//! - `surface`: the planar surfaces samples lie on (object, material,
//!   front normal);
//! - `emitter`: the secondary emitters (surface, area, the vertex-averaged
//!   radiosity they shot in all);
//! - `emitter_triangle`: the triangles of sample indices each emitter
//!   polygon is made of.
//!
//! "Luminance" is paper 002's: radiance, W/(m² sr), linear RGB, the
//! quantity its Eq. 1-5 are written in (`l = B / pi` for a diffuse surface
//! of radiosity `B`).
//!
//! f64 where f32 loses the answer: positions and luminances are stored as
//! an f32 `hi` channel (`P.X`, what a viewer shows) and an f32 residual
//! `lo` channel (`P.X.lo`), `value = hi + lo`, which keeps 48 bits of the
//! mantissa: a sample's direct luminance can then be checked against the
//! exact formula at its stored position to 1e-9 (paper 002's exact values).

use crate::error::{Error, Result};
use crate::exr_io::{check_finite, read_exr, write_exr, Channel, ExrArtifact, Layer};
use crate::header::{Header, Input, Schema};
use std::path::Path;

/// `emitter` of a sample that is no secondary emitter's vertex (a display
/// sample).
pub const NO_EMITTER: u32 = u32::MAX;
/// `level` of a sample not placed on an isolux contour.
pub const NO_LEVEL: u32 = u32::MAX;

/// What a sample is for (paper 002 Section 3.1, "tagged samples").
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Tag {
    /// In a region of smoothly varying illumination.
    Smooth = 0,
    /// Across a shadow's umbra or penumbra.
    ShadowBoundary = 1,
    /// Placed for the view: denser where the surface is larger on screen.
    ViewDependent = 2,
}

/// Why a sample was placed where it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Reason {
    /// On a corner or boundary edge of its surface.
    SurfaceEdge = 0,
    /// In the penumbra (the light source partly visible).
    Penumbra = 1,
    /// On an isolux contour, spaced by the contour's curvature.
    IsoluxContour = 2,
    /// In the umbra (no light source visible), sparsely.
    Umbra = 3,
    /// On the coarse lattice that covers smooth regions.
    SmoothLattice = 4,
    /// On the screen-space lattice (a display sample).
    ScreenDensity = 5,
}

impl Reason {
    /// Every reason, in code order.
    pub const ALL: [Reason; 6] =
        [Reason::SurfaceEdge, Reason::Penumbra, Reason::IsoluxContour, Reason::Umbra, Reason::SmoothLattice, Reason::ScreenDensity];

    /// The tag a sample placed for this reason carries.
    pub fn tag(self) -> Tag {
        match self {
            Reason::Penumbra | Reason::Umbra => Tag::ShadowBoundary,
            Reason::ScreenDensity => Tag::ViewDependent,
            Reason::SurfaceEdge | Reason::IsoluxContour | Reason::SmoothLattice => Tag::Smooth,
        }
    }

    fn from_code(code: u32) -> Option<Reason> {
        Reason::ALL.get(code as usize).copied()
    }
}

/// One illumination sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Position, mesh frame, m.
    pub position: [f64; 3],
    /// Index into [`Samples::surfaces`].
    pub surface: u32,
    /// The mesh triangle it lies on.
    pub triangle: u32,
    /// Why it was placed; its tag is `reason.tag()`.
    pub reason: Reason,
    /// Index of the isolux level it was placed on, or [`NO_LEVEL`].
    pub level: u32,
    /// Luminance reflected from the primary light sources (exact, 002 Eq.
    /// 2-3, with ray-cast visibility), W/(m² sr), RGB.
    pub direct: [f64; 3],
    /// Total luminance leaving it: emitted, direct and interreflected.
    pub luminance: [f64; 3],
    /// The secondary emitter it is a vertex of (a light-transfer sample),
    /// or [`NO_EMITTER`] (a display sample).
    pub emitter: u32,
}

/// A planar surface samples lie on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledSurface {
    /// Index into the manifest's objects.
    pub object: u32,
    /// Index into the manifest's materials.
    pub material: u32,
    /// Front-face unit normal.
    pub normal: [f64; 3],
}

/// A secondary emitter: a polygon of light-transfer samples approximating
/// an isolux region (002 Section 3.2, "Light-transfer reconstruction").
#[derive(Clone, Debug, PartialEq)]
pub struct SecondaryEmitter {
    /// Index into [`Samples::surfaces`].
    pub surface: u32,
    /// Area, m².
    pub area: f64,
    /// Radiosity it shot in all, W/m², RGB: the sum over its shots of its
    /// unshot radiosity (the mean over its area of what it received).
    pub shot: [f64; 3],
    /// Its triangles, as sample indices (counter-clockwise seen from the
    /// front).
    pub triangles: Vec<[u32; 3]>,
}

/// The `samples` artifact.
#[derive(Clone, Debug, PartialEq)]
pub struct Samples {
    /// Header with provenance.
    pub header: Header,
    /// The samples.
    pub samples: Vec<Sample>,
    /// The surfaces they lie on.
    pub surfaces: Vec<SampledSurface>,
    /// The secondary emitters.
    pub emitters: Vec<SecondaryEmitter>,
}

impl Schema for Samples {
    const NAME: &'static str = "samples";
    const VERSION: u32 = 1;
}

/// f64 as `(hi, lo)`: `hi` the nearest f32, `lo` the f32 nearest to the
/// rest.
fn split(values: impl Iterator<Item = f64>) -> (Vec<f32>, Vec<f32>) {
    values.map(|v| (v as f32, (v - f64::from(v as f32)) as f32)).unzip()
}

/// Channels `name` and `name.lo` holding the f64 `values`.
fn f64_channels(name: &str, meaning: &str, values: impl Iterator<Item = f64>) -> [Channel; 2] {
    let (hi, lo) = split(values);
    [Channel::f32(name, meaning, hi), Channel::f32(&format!("{name}.lo"), &format!("residual of {name}: value = {name} + {name}.lo"), lo)]
}

/// Three f64 channels `prefix.X|R ...` of `vectors`, each as hi and lo.
fn vector_channels(prefix: &str, axes: [&str; 3], meaning: &str, vectors: &[[f64; 3]]) -> Vec<Channel> {
    (0..3).flat_map(|k| f64_channels(&format!("{prefix}.{}", axes[k]), meaning, vectors.iter().map(move |v| v[k]))).collect()
}

/// Reads back what [`vector_channels`] wrote, refusing non-finite values.
fn read_vectors(path: &Path, layer: &Layer, record: &str, prefix: &str, axes: [&str; 3]) -> Result<Vec<[f64; 3]>> {
    let mut out = vec![[0.0; 3]; layer.len()];
    for (k, axis) in axes.iter().enumerate() {
        let name = format!("{prefix}.{axis}");
        let lo_name = format!("{name}.lo");
        check_finite(path, layer, record, &[&name, &lo_name])?;
        let (hi, lo) = (layer.f32s(path, &name)?, layer.f32s(path, &lo_name)?);
        for (i, v) in out.iter_mut().enumerate() {
            v[k] = f64::from(hi[i]) + f64::from(lo[i]);
        }
    }
    Ok(out)
}

const XYZ: [&str; 3] = ["X", "Y", "Z"];
const RGB: [&str; 3] = ["R", "G", "B"];

impl Samples {
    /// Writes `samples.exr`.
    pub fn write(&self, path: &Path) -> Result<()> {
        let s = &self.samples;
        let mut channels = vector_channels("P", XYZ, "position, mesh frame, m", &s.iter().map(|s| s.position).collect::<Vec<_>>());
        channels.extend([
            Channel::u32("surface", "index into layer surface", s.iter().map(|s| s.surface).collect()),
            Channel::u32("triangle", "mesh triangle the sample lies on", s.iter().map(|s| s.triangle).collect()),
            Channel::u32("tag", "0 smooth, 1 shadow boundary, 2 view-dependent", s.iter().map(|s| s.reason.tag() as u32).collect()),
            Channel::u32(
                "reason",
                "0 surface edge, 1 penumbra, 2 isolux contour, 3 umbra, 4 smooth lattice, 5 screen density",
                s.iter().map(|s| s.reason as u32).collect(),
            ),
            Channel::u32("level", "isolux level index; 4294967295: not on a contour", s.iter().map(|s| s.level).collect()),
            Channel::u32("emitter", "secondary emitter it is a vertex of; 4294967295: display sample", s.iter().map(|s| s.emitter).collect()),
        ]);
        channels.extend(vector_channels("direct", RGB, "luminance from the light sources, W/(m^2 sr)", &s.iter().map(|s| s.direct).collect::<Vec<_>>()));
        channels.extend(vector_channels("L", RGB, "total luminance, W/(m^2 sr)", &s.iter().map(|s| s.luminance).collect::<Vec<_>>()));
        let sample = Layer::table("sample", s.len(), channels);
        let f = &self.surfaces;
        let mut surface_channels = vec![
            Channel::u32("object", "index into manifest objects", f.iter().map(|f| f.object).collect()),
            Channel::u32("material", "index into manifest materials", f.iter().map(|f| f.material).collect()),
        ];
        surface_channels.extend(vector_channels("N", XYZ, "front-face unit normal", &f.iter().map(|f| f.normal).collect::<Vec<_>>()));
        let surface = Layer::table("surface", f.len(), surface_channels);
        let e = &self.emitters;
        let mut emitter_channels = vec![Channel::u32("surface", "index into layer surface", e.iter().map(|e| e.surface).collect())];
        emitter_channels.extend(f64_channels("area", "area, m^2", e.iter().map(|e| e.area)));
        emitter_channels.extend(vector_channels("shot", RGB, "radiosity shot in all, W/m^2", &e.iter().map(|e| e.shot).collect::<Vec<_>>()));
        let emitter = Layer::table("emitter", e.len(), emitter_channels);
        let triangles: Vec<(u32, [u32; 3])> = e.iter().enumerate().flat_map(|(i, e)| e.triangles.iter().map(move |t| (i as u32, *t))).collect();
        let mut triangle_channels = vec![Channel::u32("emitter", "index into layer emitter", triangles.iter().map(|t| t.0).collect())];
        for k in 0..3 {
            triangle_channels.push(Channel::u32(&format!("s{k}"), "sample index of a corner", triangles.iter().map(|t| t.1[k]).collect()));
        }
        let emitter_triangle = Layer::table("emitter_triangle", triangles.len(), triangle_channels);
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![sample, surface, emitter, emitter_triangle] })
    }

    /// Reads and validates `samples.exr`: values finite, every index in
    /// range (surface, emitter, triangle corners), tags and reasons known
    /// and agreeing, every emitter with at least one triangle. The mesh
    /// triangle indices are checked against the mesh by
    /// [`Samples::check_mesh`].
    pub fn read(path: &Path) -> Result<(Samples, Input)> {
        let (artifact, input) = read_exr::<Samples>(path)?;
        let invalid = |message: String| Err(Error::invalid(path, None, message));
        let surface = artifact.layer(path, "surface")?;
        let normals = read_vectors(path, surface, "surface", "N", XYZ)?;
        let (object, material) = (surface.u32s(path, "object")?, surface.u32s(path, "material")?);
        let surfaces: Vec<SampledSurface> =
            (0..surface.len()).map(|i| SampledSurface { object: object[i], material: material[i], normal: normals[i] }).collect();
        let emitter = artifact.layer(path, "emitter")?;
        check_finite(path, emitter, "emitter", &["area", "area.lo"])?;
        let (area_hi, area_lo) = (emitter.f32s(path, "area")?, emitter.f32s(path, "area.lo")?);
        let shot = read_vectors(path, emitter, "emitter", "shot", RGB)?;
        let emitter_surface = emitter.u32s(path, "surface")?;
        let mut emitters = Vec::with_capacity(emitter.len());
        for i in 0..emitter.len() {
            if emitter_surface[i] as usize >= surfaces.len() {
                return invalid(format!("emitter {i}: field surface is {}, but the file has {} surfaces", emitter_surface[i], surfaces.len()));
            }
            let area = f64::from(area_hi[i]) + f64::from(area_lo[i]);
            emitters.push(SecondaryEmitter { surface: emitter_surface[i], area, shot: shot[i], triangles: Vec::new() });
        }
        let sample = artifact.layer(path, "sample")?;
        let positions = read_vectors(path, sample, "sample", "P", XYZ)?;
        let direct = read_vectors(path, sample, "sample", "direct", RGB)?;
        let luminance = read_vectors(path, sample, "sample", "L", RGB)?;
        let [s_surface, s_triangle, s_tag, s_reason, s_level, s_emitter] =
            ["surface", "triangle", "tag", "reason", "level", "emitter"].map(|name| sample.u32s(path, name));
        let (s_surface, s_triangle, s_tag, s_reason, s_level, s_emitter) = (s_surface?, s_triangle?, s_tag?, s_reason?, s_level?, s_emitter?);
        let mut samples = Vec::with_capacity(sample.len());
        for i in 0..sample.len() {
            if s_surface[i] as usize >= surfaces.len() {
                return invalid(format!("sample {i}: field surface is {}, but the file has {} surfaces", s_surface[i], surfaces.len()));
            }
            if s_emitter[i] != NO_EMITTER && s_emitter[i] as usize >= emitters.len() {
                return invalid(format!("sample {i}: field emitter is {}, but the file has {} emitters", s_emitter[i], emitters.len()));
            }
            let Some(reason) = Reason::from_code(s_reason[i]) else {
                return invalid(format!("sample {i}: field reason is {}, not a known reason (0 to 5)", s_reason[i]));
            };
            if reason.tag() as u32 != s_tag[i] {
                return invalid(format!("sample {i}: field tag is {}, but reason {} gives tag {}", s_tag[i], s_reason[i], reason.tag() as u32));
            }
            samples.push(Sample {
                position: positions[i],
                surface: s_surface[i],
                triangle: s_triangle[i],
                reason,
                level: s_level[i],
                direct: direct[i],
                luminance: luminance[i],
                emitter: s_emitter[i],
            });
        }
        let triangle = artifact.layer(path, "emitter_triangle")?;
        let owner = triangle.u32s(path, "emitter")?;
        let corners = [triangle.u32s(path, "s0")?, triangle.u32s(path, "s1")?, triangle.u32s(path, "s2")?];
        let emitter_count = emitters.len();
        for i in 0..triangle.len() {
            let Some(e) = emitters.get_mut(owner[i] as usize) else {
                return invalid(format!("emitter_triangle {i}: field emitter is {}, but the file has {emitter_count} emitters", owner[i]));
            };
            let t = [corners[0][i], corners[1][i], corners[2][i]];
            if let Some(k) = t.iter().position(|&s| s as usize >= samples.len()) {
                return invalid(format!("emitter_triangle {i}: field s{k} is {}, but the file has {} samples", t[k], samples.len()));
            }
            e.triangles.push(t);
        }
        if let Some(i) = emitters.iter().position(|e| e.triangles.is_empty()) {
            return invalid(format!("emitter {i}: has no triangle in layer emitter_triangle"));
        }
        Ok((Samples { header: artifact.header, samples, surfaces, emitters }, input))
    }

    /// Checks the samples against the mesh they were placed on: every
    /// sample's triangle is one of its `triangles` triangles.
    pub fn check_mesh(&self, path: &Path, triangles: usize) -> Result<()> {
        match self.samples.iter().position(|s| s.triangle as usize >= triangles) {
            Some(i) => Err(Error::invalid(path, None, format!("sample {i}: field triangle is {}, but the mesh has {triangles}", self.samples[i].triangle))),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::Provenance;

    fn example() -> Samples {
        let sample = |x: f64, reason: Reason, emitter: u32| Sample {
            position: [x, 1.0 / 3.0, -2.0],
            surface: 0,
            triangle: 1,
            reason,
            level: if reason == Reason::IsoluxContour { 2 } else { NO_LEVEL },
            direct: [0.1 + x, std::f64::consts::PI, 1e-7],
            luminance: [0.2 + x, 4.0, 1e-7],
            emitter,
        };
        Samples {
            header: Samples::header(Provenance::in_memory("test")),
            samples: vec![sample(0.1, Reason::SurfaceEdge, 0), sample(0.7, Reason::IsoluxContour, 0), sample(1.3, Reason::Penumbra, 0), sample(2.9, Reason::ScreenDensity, NO_EMITTER)],
            surfaces: vec![SampledSurface { object: 2, material: 1, normal: [0.0, 0.6, 0.8] }],
            emitters: vec![SecondaryEmitter { surface: 0, area: 0.123456789, shot: [1.0, 2.0, 3.0], triangles: vec![[0, 1, 2]] }],
        }
    }

    fn temp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("samples-{name}-{}.exr", std::process::id()))
    }

    #[test]
    fn round_trip_keeps_f64_values_to_48_bits() {
        let samples = example();
        let path = temp("round");
        samples.write(&path).unwrap();
        let (back, _) = Samples::read(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!((back.surfaces.len(), back.emitters[0].triangles.clone()), (1, vec![[0, 1, 2]]));
        for (a, b) in samples.samples.iter().zip(&back.samples) {
            assert_eq!((a.surface, a.triangle, a.reason, a.level, a.emitter), (b.surface, b.triangle, b.reason, b.level, b.emitter));
            for k in 0..3 {
                for (x, y) in [(a.position[k], b.position[k]), (a.direct[k], b.direct[k]), (a.luminance[k], b.luminance[k])] {
                    assert!((x - y).abs() <= 4e-15 * x.abs(), "{x} read back as {y}");
                }
            }
        }
        assert!((back.emitters[0].area - 0.123456789).abs() < 1e-15);
    }

    fn refusal(name: &str, edit: impl FnOnce(&mut Samples)) -> String {
        let mut samples = example();
        edit(&mut samples);
        let path = temp(name);
        samples.write(&path).unwrap();
        let message = Samples::read(&path).unwrap_err().to_string();
        std::fs::remove_file(&path).unwrap();
        message.strip_prefix(&format!("{}: ", path.display())).unwrap_or(&message).to_string()
    }

    #[test]
    fn indices_out_of_range_and_nan_are_refused() {
        assert_eq!(refusal("surface", |s| s.samples[1].surface = 1), "sample 1: field surface is 1, but the file has 1 surfaces");
        assert_eq!(refusal("emitter", |s| s.samples[0].emitter = 3), "sample 0: field emitter is 3, but the file has 1 emitters");
        assert_eq!(refusal("corner", |s| s.emitters[0].triangles[0][2] = 9), "emitter_triangle 0: field s2 is 9, but the file has 4 samples");
        assert_eq!(refusal("nan", |s| s.samples[2].direct[1] = f64::NAN), "sample 2: field direct.G is NaN");
        assert_eq!(refusal("empty", |s| s.emitters[0].triangles.clear()), "emitter 0: has no triangle in layer emitter_triangle");
        let samples = example();
        let e = samples.check_mesh(Path::new("s.exr"), 1).unwrap_err().to_string();
        assert_eq!(e, "s.exr: sample 0: field triangle is 1, but the mesh has 1");
    }
}
