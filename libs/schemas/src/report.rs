//! Stage reports (`*.report.ron`): the work a run did and its wall time.
//! Reports are the volatile part of the pipeline's output: everything else a
//! stage writes is byte-identical across reruns, reports differ in
//! `wall_time_s` only, and `compare` ignores them.

use crate::header::{Header, Provenance, Schema};
use crate::ron_io::RonArtifact;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What one run of a stage did.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Report {
    /// Header with the run's provenance (parameters, inputs).
    pub header: Header,
    /// Wall-clock time of the run, seconds (volatile).
    pub wall_time_s: f64,
    /// Work counters: rays cast, links, form factors, iterations, ...
    pub counters: BTreeMap<String, f64>,
    /// Code paths not run, each with the reason (effects the scene lacks,
    /// or effects this stage does not simulate).
    pub skipped: Vec<String>,
    /// Anything else worth knowing about the run.
    pub notes: Vec<String>,
}

impl Schema for Report {
    const NAME: &'static str = "report";
    const VERSION: u32 = 1;
}

impl RonArtifact for Report {
    fn provenance(&self) -> &Provenance {
        &self.header.provenance
    }
}
