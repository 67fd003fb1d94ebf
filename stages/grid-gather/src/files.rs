//! The gather's files beyond the prepared scene: the solution and the
//! optional cluster hierarchy, threshold image and surface detail it reads,
//! each recorded as an input of the run (its provenance), and the image
//! and diagnostics it writes.

use crate::detail::Detail;
use crate::{back_face_warning, Extras, Params, Rendered};
use schemas::cluster::Clusters;
use schemas::diagnostics::{Diagnostics, GatherDiagnostics};
use schemas::header::{Input, Schema};
use schemas::image::HdrImage;
use schemas::lightmap::Lightmap;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use schemas::surface::Surface;
use schemas::threshold::ThresholdImage;
use schemas::{Error, Result};
use stage_kit::run::{read_surface, Outputs, Run};
use stage_kit::stage::Done;
use std::path::Path;

/// The paths given (`None`: an optional input not given).
pub struct Given<'a> {
    /// The mesh the solution is over (named in a surface file's refusal).
    pub mesh: &'a Path,
    /// The radiosity solution.
    pub solution: &'a Path,
    /// The cluster hierarchy of a clustered solution.
    pub clusters: Option<&'a Path>,
    /// The mask stage's threshold image.
    pub threshold: Option<&'a Path>,
    /// mesh-prep's surface artifact.
    pub surface: Option<&'a Path>,
    /// gpu-shoot's lightmap of the run that wrote the solution.
    pub lightmap: Option<&'a Path>,
}

/// The files read.
pub struct Read {
    /// The radiosity solution.
    pub solution: Solution,
    /// The cluster hierarchy, if given.
    pub clusters: Option<Clusters>,
    /// The threshold image, if given.
    pub threshold: Option<ThresholdImage>,
    /// The surface artifact and its input record, if given and the scene
    /// has surface detail (textures, alpha masks, normal maps).
    pub surface: Option<(Surface, Input)>,
    /// The lightmap, if given ([`lightmap`]).
    pub lightmap: Option<Lightmap>,
}

impl Given<'_> {
    /// Reads the files of `mesh` and `manifest`, each recorded in `run`.
    pub fn read(&self, run: &mut Run, mesh: &Mesh, manifest: &Manifest) -> Result<Read> {
        let (solution, input) = Solution::read(self.solution)?;
        run.input(input)?;
        let clusters = self.clusters.map(|path| Clusters::read(path, mesh.triangles.len()).and_then(|(c, input)| run.input(input).map(|_| c))).transpose()?;
        let threshold = self.threshold.map(|path| ThresholdImage::read(path).and_then(|(t, input)| run.input(input).map(|_| t))).transpose()?;
        let surface = match self.surface {
            Some(path) if manifest.effects.surface_detail() => Some(read_surface(path, self.mesh, mesh, manifest)?),
            _ => None,
        };
        // Recorded without the provenance it carries (the mesh's), so that
        // a solution solved without it is not refused as another run's.
        if let Some((_, input)) = &surface {
            run.input(schemas::header::Input { made_by: None, ..input.clone() })?;
        }
        let lightmap = self.lightmap.map(|path| lightmap(path, mesh, &solution, self.solution).and_then(|(l, input)| run.input(input).map(|_| l))).transpose()?;
        Ok(Read { solution, clusters, threshold, surface, lightmap })
    }
}

impl Read {
    /// The surface detail of `mesh` and `manifest`, if read (its textures
    /// in the radiosity where the solution was solved with it:
    /// [`Detail::solved_with`]).
    pub fn detail(&self, mesh: &Mesh, manifest: &Manifest) -> Option<Detail<'_>> {
        self.surface.as_ref().map(|(s, input)| Detail::new(s, mesh, manifest, Detail::solved_with(&self.solution, input)))
    }

    /// The gather's extras: the clusters, the threshold and `detail`.
    pub fn extras<'a>(&'a self, detail: Option<&'a Detail<'a>>) -> Extras<'a> {
        Extras { clusters: self.clusters.as_ref(), threshold: self.threshold.as_ref(), detail, lightmap: self.lightmap.as_ref() }
    }
}

/// Reads the lightmap at `path` for the preview's shading, and checks that
/// it is one of `mesh` (a region per triangle) written by the gpu-shoot
/// run that wrote `solution` (read from `solution_path`): the same
/// provenance. A run that added `rho x ambient` to its solution
/// (`--ambient`, a display aid) is refused, as the lightmap does not hold
/// that term and the preview would lose it.
fn lightmap(path: &Path, mesh: &Mesh, solution: &Solution, solution_path: &Path) -> Result<(Lightmap, Input)> {
    let (lightmap, input) = Lightmap::read(path)?;
    if lightmap.regions.len() != mesh.triangles.len() {
        let message = format!("{} regions for a mesh of {} triangles: not a lightmap of this mesh", lightmap.regions.len(), mesh.triangles.len());
        return Err(Error::invalid(path, None, message));
    }
    let run = &lightmap.header.provenance;
    if *run != solution.header.provenance {
        return Err(Error::invalid(path, None, format!("not written by the run that wrote {} (their provenance differs)", solution_path.display())));
    }
    if ron::from_str::<AmbientAdded>(run.parameters.get_ron()).is_ok_and(|p| p.ambient) {
        return Err(Error::invalid(path, None, "its run added rho x ambient to the solution (--ambient), which the lightmap does not hold: leave out --lightmap or --ambient"));
    }
    Ok((lightmap, input))
}

/// Of a gpu-shoot run's parameters, whether it added `rho x ambient` to
/// its solution (absent: it did not; other fields are ignored).
#[derive(serde::Deserialize)]
struct AmbientAdded {
    #[serde(default)]
    ambient: bool,
}

/// The files the gather writes.
pub struct Written<'a> {
    /// The image.
    pub image: &'a Path,
    /// The diagnostics (full and brute modes), if asked.
    pub diagnostics: Option<&'a Path>,
}

impl Written<'_> {
    /// Writes the image `rendered` and the `diagnostics` (where asked and
    /// made) through `outputs`, stamped with `run`'s provenance with
    /// `params`; returns the report: the gather's counters, what it
    /// skipped, and the back-face warning ([`back_face_warning`], said on
    /// stderr too).
    pub fn write(&self, outputs: &mut Outputs, run: &Run, params: &Params, rendered: Rendered, diagnostics: Option<&Diagnostics>) -> Result<Done> {
        let image = HdrImage { header: HdrImage::header(run.provenance(params)), width: rendered.width, height: rendered.height, rgb: rendered.rgb, coverage: rendered.coverage, surfaces: Some(rendered.surfaces) };
        outputs.write(self.image, |p| image.write(p))?;
        if let (Some(path), Some(d)) = (self.diagnostics, diagnostics) {
            outputs.write(path, |p| d.write(p, GatherDiagnostics::header(run.provenance(params))))?;
        }
        let notes: Vec<String> = back_face_warning(&rendered.counters).into_iter().collect();
        notes.iter().for_each(|note| eprintln!("grid-gather: warning: {note}"));
        Ok(Done { counters: rendered.counters, skipped: rendered.skipped, notes, negative: false })
    }
}
