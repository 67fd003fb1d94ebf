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
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::Solution;
use schemas::surface::Surface;
use schemas::threshold::ThresholdImage;
use schemas::Result;
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
        Ok(Read { solution, clusters, threshold, surface })
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
        Extras { clusters: self.clusters.as_ref(), threshold: self.threshold.as_ref(), detail }
    }
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
