//! The lightmap artifact (`lightmap.exr`), written by `gpu-shoot`: float
//! atlases of radiosity and residual (unshot) radiosity with their coverage,
//! the area each texel stands for, the baked world position and normal of
//! each texel, and the table that maps every input triangle to its region of
//! the atlas (paper 004, Sec. 2.3 and 4.2). Also the convergence record of a
//! progressive run (`convergence.ron`).
//!
//! # Regions
//!
//! Triangle `t` owns the square region of `size + 2` by `size + 2` texels
//! whose top-left corner is atlas texel `(x, y)`; the outer ring is a gutter
//! for bilinear lookup. Texel `(i, j)` of the region's interior (`0 <= i, j
//! < size`) sits at atlas texel `(x + 1 + i, y + 1 + j)` and stands for the
//! point with barycentric coordinates
//!
//! ```text
//! u = (i + 1/2) / size,   v = (j + 1/2) / size,   P = (1-u-v) P0 + u P1 + v P2
//! ```
//!
//! It is *covered* (takes part in the solution) when `i + j + 1 <= size`,
//! that is when its centre lies inside the triangle or on its edge (the
//! paper renders each triangle filled and outlined for the same reason,
//! 2.3.1). A texel on the hypotenuse (`i + j + 1 = size`) stands for the
//! half of its square inside the triangle, and the solver samples it at
//! that half's centroid `((i + 1/3) / size, (j + 1/3) / size)`, not at its
//! centre on the edge (a point on a concave crease would shoot half its
//! power through the neighbouring surface); the `P` channel keeps the
//! centres, the lookup grid. The texels a bilinear lookup inside the triangle reads but that
//! are not covered hold values filled from covered neighbours (seams,
//! 2.3.1): `coverage` is 1 for covered texels, 0.5 for filled ones and 0
//! elsewhere.
//!
//! Later effects (transmission, specular reflection, alpha masks, normal
//! maps, adaptive subdivision) fit this layout: per-texel data is a channel
//! of the `atlas` layer, per-region data a column of the `region` table, and
//! a refined triangle would get a larger `size`.

use crate::error::{Error, Result};
use crate::exr_io::{check_finite, read_exr, write_exr, Channel, ExrArtifact, Layer, LayerKind};
use crate::header::{Header, Input, Provenance, Schema};
use crate::ron_io::RonArtifact;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Coverage value of a texel that takes part in the solution.
pub const COVERED: f32 = 1.0;
/// Coverage value of a texel filled for lookup only (seams, 004 Sec. 2.3.1).
pub const FILLED: f32 = 0.5;

/// Where one triangle's texels lie in the atlas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Atlas column of the region's top-left gutter texel.
    pub x: u32,
    /// Atlas row of the region's top-left gutter texel.
    pub y: u32,
    /// Interior texels per side (the region is `size + 2` wide with gutter).
    pub size: u32,
    /// Number of covered texels: `size (size + 1) / 2`.
    pub covered: u32,
    /// Area an interior covered texel stands for, m²: `2 A / size²`; a
    /// texel on the hypotenuse (`i + j + 1 = size`, half its square inside
    /// the triangle) stands for half that, so the areas sum to `A`.
    pub texel_area: f32,
}

impl Region {
    /// Atlas texel `(column, row)` of interior texel `(i, j)`.
    pub fn texel(&self, i: u32, j: u32) -> (u32, u32) {
        (self.x + 1 + i, self.y + 1 + j)
    }

    /// Whether interior texel `(i, j)` is covered.
    pub fn is_covered(&self, i: u32, j: u32) -> bool {
        i + j < self.size
    }

    /// Barycentric `(u, v)` of interior texel `(i, j)`'s centre.
    pub fn uv(&self, i: u32, j: u32) -> [f64; 2] {
        let n = self.size as f64;
        [(i as f64 + 0.5) / n, (j as f64 + 0.5) / n]
    }
}

/// The atlas and its region table.
#[derive(Clone, Debug, PartialEq)]
pub struct Lightmap {
    /// Header with provenance.
    pub header: Header,
    /// Atlas width, texels.
    pub width: usize,
    /// Atlas height, texels.
    pub height: usize,
    /// Radiosity B, W/m², RGB, row-major (without the ambient term).
    pub radiosity: Vec<[f32; 3]>,
    /// Residual (unshot) radiosity ΔB, W/m², RGB; negative after ambient
    /// overshooting (004 Sec. 4.3.5).
    pub residual: Vec<[f32; 3]>,
    /// [`COVERED`], [`FILLED`] or 0.
    pub coverage: Vec<f32>,
    /// Area each texel stands for, m² (0 where not covered).
    pub texel_area: Vec<f32>,
    /// Texel centre, mesh frame, m (also for filled texels: the point of the
    /// triangle's plane the texel's centre maps to).
    pub position: Vec<[f32; 3]>,
    /// Unit normal of the texel's triangle (0 where no triangle).
    pub normal: Vec<[f32; 3]>,
    /// One region per input triangle, in triangle order.
    pub regions: Vec<Region>,
}

impl Schema for Lightmap {
    const NAME: &'static str = "lightmap";
    const VERSION: u32 = 1;
}

fn image_channel3(values: &[[f32; 3]], names: [&str; 3], meaning: &str) -> Vec<Channel> {
    (0..3).map(|k| Channel::f32(names[k], meaning, values.iter().map(|v| v[k]).collect())).collect()
}

impl Lightmap {
    /// Bilinear lookup of radiosity at barycentric `uv` of region `t`
    /// (triangle `t` of the mesh the lightmap was made of): the four
    /// texels around the point, in the region's texel grid (interior texel
    /// `i` centred at `u = (i + 1/2) / size`, [`Region::uv`]).
    ///
    /// In region pixels (gutter included) interior texel `i` is pixel `i +
    /// 1`, so `u` lies at pixel coordinate `f = u size + 1/2` measured from
    /// the centre of pixel 0: `u = (i + 1/2) / size` gives `f = i + 1`, that
    /// texel's own value. (The lookup used to subtract another half pixel,
    /// which read every point half a texel down both axes: gpu-shoot's
    /// solution elements were shifted a texel diagonal's half from the
    /// lightmap, 5.4% off Lambert's formula under a tilted emitter where the
    /// texels were within 1.2%; issue 10, item 7.)
    pub fn radiosity_at(&self, t: usize, uv: [f64; 2]) -> [f64; 3] {
        self.lookup(&self.radiosity, t, uv)
    }

    /// [`Lightmap::radiosity_at`] of `values` (the radiosity or the
    /// residual), over the texels that hold a value (covered or filled),
    /// their weights renormalised; 0 where none of the four does.
    ///
    /// A texel buried inside a solid holds none: gpu-shoot's seam fill
    /// extrapolates into it from the exposed texels beside it as it does
    /// beyond a triangle's edge. Read as a covered texel of radiosity 0, it
    /// darkened every lookup within a texel of a block's footprint, and the
    /// floor along the blocks' bases showed a dark band in gpu-shoot's
    /// preview.
    pub fn lookup(&self, values: &[[f32; 3]], t: usize, uv: [f64; 2]) -> [f64; 3] {
        let r = self.regions[t];
        let n = r.size as f64;
        let fx = (uv[0] * n + 0.5).clamp(0.0, n + 1.0);
        let fy = (uv[1] * n + 0.5).clamp(0.0, n + 1.0);
        let (ix, iy) = (fx.floor().min(n), fy.floor().min(n));
        let (tx, ty) = (fx - ix, fy - iy);
        let (mut sum, mut weight) = ([0.0; 3], 0.0);
        for (dx, dy, w) in [(0.0, 0.0, (1.0 - tx) * (1.0 - ty)), (1.0, 0.0, tx * (1.0 - ty)), (0.0, 1.0, (1.0 - tx) * ty), (1.0, 1.0, tx * ty)] {
            let k = (r.y as usize + (iy + dy) as usize) * self.width + r.x as usize + (ix + dx) as usize;
            if self.coverage[k] != 0.0 {
                (0..3).for_each(|c| sum[c] += w * f64::from(values[k][c]));
                weight += w;
            }
        }
        if weight > 0.0 {
            sum.map(|v| v / weight)
        } else {
            [0.0; 3]
        }
    }

    /// Writes `lightmap.exr`: image layer `atlas` and table layer `region`.
    pub fn write(&self, path: &Path) -> Result<()> {
        let n = self.width * self.height;
        let lengths = [self.radiosity.len(), self.residual.len(), self.coverage.len(), self.texel_area.len(), self.position.len(), self.normal.len()];
        if lengths.iter().any(|&l| l != n) {
            return Err(Error::invalid(path, None, "internal: atlas channels do not match the atlas size"));
        }
        let mut channels = Vec::new();
        channels.extend(image_channel3(&self.radiosity, ["B.R", "B.G", "B.B"], "radiosity, W/m^2"));
        channels.extend(image_channel3(&self.residual, ["dB.R", "dB.G", "dB.B"], "residual (unshot) radiosity, W/m^2"));
        channels.push(Channel::f32("coverage", "1 covered, 0.5 filled for lookup, 0 empty", self.coverage.clone()));
        channels.push(Channel::f32("area", "area the texel stands for, m^2", self.texel_area.clone()));
        channels.extend(image_channel3(&self.position, ["P.X", "P.Y", "P.Z"], "texel centre, mesh frame, m"));
        channels.extend(image_channel3(&self.normal, ["N.X", "N.Y", "N.Z"], "unit normal of the texel's triangle"));
        let atlas = Layer { name: "atlas".into(), kind: LayerKind::Image { width: self.width, height: self.height }, channels };
        let r = &self.regions;
        let region = Layer::table(
            "region",
            r.len(),
            vec![
                Channel::u32("x", "atlas column of the region's top-left gutter texel", r.iter().map(|r| r.x).collect()),
                Channel::u32("y", "atlas row of the region's top-left gutter texel", r.iter().map(|r| r.y).collect()),
                Channel::u32("size", "interior texels per side", r.iter().map(|r| r.size).collect()),
                Channel::u32("covered", "covered texels", r.iter().map(|r| r.covered).collect()),
                Channel::f32("texel_area", "area per interior covered texel (half on the hypotenuse), m^2", r.iter().map(|r| r.texel_area).collect()),
            ],
        );
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![atlas, region] })
    }

    /// Reads `lightmap.exr` and checks its structure: every atlas value
    /// finite; every region non-empty (`size` at least 1), inside the
    /// atlas with its gutter, with `covered = size (size + 1) / 2` and a
    /// finite, non-negative `texel_area`. A region that breaks one is
    /// refused with its triangle and field.
    pub fn read(path: &Path) -> Result<(Lightmap, Input)> {
        let (artifact, input) = read_exr::<Lightmap>(path)?;
        let atlas = artifact.layer(path, "atlas")?;
        let LayerKind::Image { width, height } = atlas.kind else {
            return Err(Error::invalid(path, None, "layer 'atlas' is a table"));
        };
        let floats = ["B.R", "B.G", "B.B", "dB.R", "dB.G", "dB.B", "coverage", "area", "P.X", "P.Y", "P.Z", "N.X", "N.Y", "N.Z"];
        check_finite(path, atlas, "texel", &floats)?;
        let three = |names: [&str; 3]| -> Result<Vec<[f32; 3]>> {
            let (a, b, c) = (atlas.f32s(path, names[0])?, atlas.f32s(path, names[1])?, atlas.f32s(path, names[2])?);
            Ok((0..width * height).map(|i| [a[i], b[i], c[i]]).collect())
        };
        let radiosity = three(["B.R", "B.G", "B.B"])?;
        let residual = three(["dB.R", "dB.G", "dB.B"])?;
        let position = three(["P.X", "P.Y", "P.Z"])?;
        let normal = three(["N.X", "N.Y", "N.Z"])?;
        let coverage = atlas.f32s(path, "coverage")?.to_vec();
        let texel_area = atlas.f32s(path, "area")?.to_vec();
        let table = artifact.layer(path, "region")?;
        let (x, y, size, covered, area) =
            (table.u32s(path, "x")?, table.u32s(path, "y")?, table.u32s(path, "size")?, table.u32s(path, "covered")?, table.f32s(path, "texel_area")?);
        let mut regions = Vec::with_capacity(table.len());
        for i in 0..table.len() {
            let r = Region { x: x[i], y: y[i], size: size[i], covered: covered[i], texel_area: area[i] };
            if r.x as usize + r.size as usize + 2 > width || r.y as usize + r.size as usize + 2 > height {
                return Err(Error::invalid(
                    path,
                    None,
                    format!("region {i}: {0}x{0} texels at ({1}, {2}) lie outside the {width}x{height} atlas (fields x, y, size)", r.size as u64 + 2, r.x, r.y),
                ));
            }
            if r.size == 0 || r.covered as u64 != r.size as u64 * (r.size as u64 + 1) / 2 {
                return Err(Error::invalid(path, None, format!("region {i}: size {} with {} covered texels (fields size, covered)", r.size, r.covered)));
            }
            if !r.texel_area.is_finite() || r.texel_area < 0.0 {
                return Err(Error::invalid(path, None, format!("region {i}: field texel_area is {}", r.texel_area)));
            }
            regions.push(r);
        }
        Ok((Lightmap { header: artifact.header, width, height, radiosity, residual, coverage, texel_area, position, normal, regions }, input))
    }
}

/// One shot of a progressive run.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Shot {
    /// The shooter: `"triangle 12"` or `"light 0"`.
    pub shooter: String,
    /// Shooting samples (substructured texel groups, or 1 for a light).
    pub samples: u32,
    /// Fraction of the emitted power still unshot after this shot, net:
    /// `|sum_i ΔB_i A_i| / sum emitted` (channels summed). Overshooting
    /// leaves negative residuals for power already sent ahead, which cancel
    /// positive ones here: this net figure does not bound the remaining
    /// error; gpu-shoot stops on the magnitude sum `sum_i |ΔB_i| A_i`
    /// (its report's `unshot_magnitude_fraction`).
    pub unshot_fraction: f64,
    /// The same with magnitudes, `sum_i |ΔB_i| A_i / sum emitted`: 0 only
    /// when every residual is 0.
    pub unshot_magnitude_fraction: f64,
    /// Seconds since the solver started, after this shot (volatile).
    pub seconds: f64,
}

/// `convergence.ron`: the progress of a progressive run, shot by shot.
/// Like a report, its timings are volatile.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Convergence {
    /// Header with provenance.
    pub header: Header,
    /// The adapter the run used (name, driver, backend).
    pub adapter: String,
    /// Fraction of the emitted power unshot before the first shot (1).
    pub initial_unshot_fraction: f64,
    /// Seconds spent before the first shot (atlas bake, uploads; volatile).
    pub setup_seconds: f64,
    /// Every shot, in order.
    pub shots: Vec<Shot>,
}

impl Schema for Convergence {
    const NAME: &'static str = "convergence";
    const VERSION: u32 = 1;
}

impl RonArtifact for Convergence {
    fn provenance(&self) -> &Provenance {
        &self.header.provenance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lightmap_round_trips_and_refuses_regions_outside_the_atlas() {
        let (width, height) = (6, 5);
        let n = width * height;
        let mut lightmap = Lightmap {
            header: Lightmap::header(Provenance::in_memory("test")),
            width,
            height,
            radiosity: (0..n).map(|i| [i as f32, 0.5, -1.0]).collect(),
            residual: vec![[0.25, -0.5, 0.0]; n],
            coverage: (0..n).map(|i| [0.0, FILLED, COVERED][i % 3]).collect(),
            texel_area: vec![0.125; n],
            position: vec![[1.0, 2.0, 3.0]; n],
            normal: vec![[0.0, 0.0, 1.0]; n],
            regions: vec![Region { x: 1, y: 0, size: 3, covered: 6, texel_area: 0.125 }],
        };
        let path = std::env::temp_dir().join(format!("lightmap-{}.exr", std::process::id()));
        lightmap.write(&path).unwrap();
        let (back, _) = Lightmap::read(&path).unwrap();
        assert_eq!(back, lightmap);
        assert_eq!(back.regions[0].texel(2, 0), (4, 1));
        assert!(back.regions[0].is_covered(2, 0) && !back.regions[0].is_covered(2, 1));
        lightmap.regions[0].x = 2;
        lightmap.write(&path).unwrap();
        let message = Lightmap::read(&path).unwrap_err().to_string();
        assert_eq!(message, format!("{}: region 0: 5x5 texels at (2, 0) lie outside the 6x5 atlas (fields x, y, size)", path.display()));
        lightmap.regions[0] = Region { x: 0, y: 0, size: 3, covered: 5, texel_area: 0.125 };
        lightmap.write(&path).unwrap();
        let message = Lightmap::read(&path).unwrap_err().to_string();
        assert!(message.ends_with("region 0: size 3 with 5 covered texels (fields size, covered)"), "{message}");
        std::fs::remove_file(&path).unwrap();
    }
}
