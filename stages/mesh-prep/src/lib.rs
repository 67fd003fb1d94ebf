//! # mesh-prep: from a scene file to the prepared mesh
//!
//! Reads `scene.ron` ([`scene::Scene`]: OBJ/MTL files, camera, lights,
//! material overrides) or a built-in scene ([`builtin::Builtin`]),
//! reads and validates the photometric files of its luminaires
//! ([`photometry`]), triangulates, places and recentres the geometry, welds duplicate
//! vertices, drops degenerate and duplicate triangles, checks that every
//! emitter lights the scene ([`lighting`]), and lists the effects the scene
//! calls for. The OBJ and MTL readers ([`obj`], [`mtl`], [`text`]) take
//! files as exporters write them. The binary writes the result as
//! `mesh.exr` and `manifest.ron` (see the `schemas` crate), and a make
//! dependency file of every file it read ([`depfile`]); [`report`] says
//! what the run did.

pub mod builtin;
pub mod depfile;
pub mod lighting;
pub mod material;
pub mod mtl;
pub mod obj;
pub mod photometry;
pub mod prepare;
pub mod procedural;
pub mod report;
pub mod scene;
pub mod surface;
pub mod text;

pub use prepare::{prepare, Params, Prepared};

use text::TextSource;
use schemas::header::Input;
use schemas::Error;
use std::cell::RefCell;
use std::path::Path;

/// Prepares the built-in scene `name` (see [`builtin`]) in memory with
/// default parameters, as `mesh-prep --builtin name` would write it.
pub fn prepare_builtin(name: &str, made_by: &str) -> Result<(schemas::mesh::Mesh, schemas::mesh::Manifest), Error> {
    let source: builtin::Builtin = name.parse().map_err(|e: String| Error::invalid(Path::new(name), None, e))?;
    let path = source.scene_path();
    let scene = read_scene(&source, &path)?;
    let prepared = prepare(&scene, &path, &source, &Params::default())?;
    Ok(prepared.into_artifacts(schemas::header::Provenance::in_memory(made_by)))
}

/// Reads and parses the scene file at `path` through `source` (UTF-8,
/// strictly).
pub fn read_scene(source: &dyn TextSource, path: &Path) -> Result<scene::Scene, Error> {
    let text = text::read_utf8(source, path)?;
    schemas::ron_io::parse_ron(path, &text)
}

/// A [`TextSource`] that records every file read through it (path and
/// content hash), for the outputs' provenance.
pub struct Recording<'a> {
    inner: &'a dyn TextSource,
    inputs: RefCell<Vec<Input>>,
}

impl<'a> Recording<'a> {
    /// Records reads from `inner`.
    pub fn new(inner: &'a dyn TextSource) -> Self {
        Recording { inner, inputs: RefCell::new(Vec::new()) }
    }

    /// The files read so far, in order.
    pub fn into_inputs(self) -> Vec<Input> {
        self.inputs.into_inner()
    }
}

impl TextSource for Recording<'_> {
    fn read_bytes(&self, path: &Path) -> Result<Vec<u8>, Error> {
        let bytes = self.inner.read_bytes(path)?;
        self.inputs.borrow_mut().push(Input::new(path, &bytes, None));
        Ok(bytes)
    }

    fn exists(&self, path: &Path) -> bool {
        self.inner.exists(path)
    }
}
