//! What the benchmark reads back from a run: per surface, structured
//! sampling's samples and secondary emitters (its samples artifact) or
//! hierarchical-solve's leaf elements and their distinct corners (its
//! solution), the share of pixels over each tau (compare's report, per
//! object), and the time split its stages' reports allow.

use super::table::{OverTau, Phase};
use crate::sweep::knobs::Solver;
use schemas::mesh::{Manifest, Mesh};
use schemas::report::Report;
use schemas::samples::Samples;
use schemas::solution::Solution;
use std::collections::{BTreeMap, HashSet};

/// A surface the table reports on: one or more objects of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceGroup {
    /// Its name in the table.
    pub name: String,
    /// The objects (indices into the manifest's `objects`).
    pub objects: Vec<u32>,
}

/// The surfaces `given` as `(name, object names)`, or, when none is given,
/// every object with a triangle that does not emit, each its own surface.
/// An error naming the object for a name the scene does not have.
pub fn surface_groups(mesh: &Mesh, manifest: &Manifest, given: &[(String, Vec<String>)]) -> Result<Vec<SurfaceGroup>, String> {
    if given.is_empty() {
        let emits = |m: u32| manifest.materials[m as usize].emission.iter().any(|&e| e > 0.0);
        let lit: Vec<u32> = (0..manifest.objects.len() as u32).filter(|&o| mesh.triangles.iter().any(|t| t.object == o && !emits(t.material))).collect();
        return Ok(lit.into_iter().map(|o| SurfaceGroup { name: manifest.objects[o as usize].clone(), objects: vec![o] }).collect());
    }
    given
        .iter()
        .map(|(name, objects)| {
            let objects = objects
                .iter()
                .map(|o| manifest.objects.iter().position(|n| n == o).map(|i| i as u32).ok_or_else(|| format!("--surface {name}: the scene has no object {o:?} (objects: {})", manifest.objects.join(", "))))
                .collect::<Result<Vec<u32>, String>>()?;
            Ok(SurfaceGroup { name: name.clone(), objects })
        })
        .collect()
}

/// Per surface, structured sampling's samples and secondary emitters.
pub fn structured_counts(samples: &Samples, groups: &[SurfaceGroup]) -> Vec<(usize, usize)> {
    let object = |surface: u32| samples.surfaces[surface as usize].object;
    groups
        .iter()
        .map(|g| {
            let on = |surface: u32| g.objects.contains(&object(surface));
            (samples.samples.iter().filter(|s| on(s.surface)).count(), samples.emitters.iter().filter(|e| on(e.surface)).count())
        })
        .collect()
}

/// Per surface, hierarchical-solve's leaf elements and their distinct
/// corners. Corners are placed in the scene (`(1-u-v) P0 + u P1 + v P2`
/// of their input triangle) and merged when they agree to 1e-6 of the
/// scene's extent, so a corner shared by elements of neighbouring input
/// triangles counts once.
pub fn hierarchical_counts(solution: &Solution, mesh: &Mesh, groups: &[SurfaceGroup]) -> Vec<(usize, usize)> {
    let extent = mesh.positions.iter().fold(0f64, |m, p| p.iter().fold(m, |m, &c| m.max(f64::from(c).abs())));
    let quantum = 1e-6 * extent.max(f64::MIN_POSITIVE);
    let point = |triangle: u32, [u, v]: [f32; 2]| -> [i64; 3] {
        let corners = mesh.triangles[triangle as usize].vertices.map(|i| mesh.positions[i as usize]);
        let (u, v) = (f64::from(u), f64::from(v));
        [0, 1, 2].map(|k| {
            let p = (1.0 - u - v) * f64::from(corners[0][k]) + u * f64::from(corners[1][k]) + v * f64::from(corners[2][k]);
            (p / quantum).round() as i64
        })
    };
    groups
        .iter()
        .map(|g| {
            let leaves: Vec<_> = solution.elements.iter().filter(|e| e.is_leaf() && g.objects.contains(&mesh.triangles[e.triangle as usize].object)).collect();
            let corners: HashSet<[i64; 3]> = leaves.iter().flat_map(|e| e.corners.map(|c| point(e.triangle, c))).collect();
            (leaves.len(), corners.len())
        })
        .collect()
}

/// compare's percent of the image's pixels over each tau.
pub fn image_over_tau(counters: &BTreeMap<String, f64>, taus: &[f64]) -> Vec<OverTau> {
    taus.iter().filter_map(|&tau| counters.get(&format!("percent_over_tau_{tau}")).map(|&percent| OverTau { tau, percent })).collect()
}

/// A surface's pixels and its percent over each tau, from compare's per
/// object counters (`object[NAME].samples`,
/// `object[NAME].percent_over_tau_T`): the pixel-weighted mean over the
/// surface's objects (`objects`: the manifest's object names). A tau no object of the surface has a pixel for is
/// left out.
pub fn surface_over_tau(counters: &BTreeMap<String, f64>, objects: &[String], group: &SurfaceGroup, taus: &[f64]) -> (usize, Vec<OverTau>) {
    let counter = |o: u32, name: &str| counters.get(&format!("object[{}].{name}", objects[o as usize])).copied();
    let pixels: f64 = group.objects.iter().filter_map(|&o| counter(o, "samples")).sum();
    let over = taus
        .iter()
        .filter(|_| pixels > 0.0)
        .map(|&tau| {
            let over: f64 = group.objects.iter().filter_map(|&o| Some(counter(o, "samples")? * counter(o, &format!("percent_over_tau_{tau}"))?)).sum();
            OverTau { tau, percent: over / pixels }
        })
        .collect();
    (pixels as usize, over)
}

/// The phases a solver's report times: (phase, counter, part of the
/// light's transfer from the sources to the first receivers (`A`) or
/// between surfaces (`B`), or neither).
fn timed_phases(solver: Solver) -> &'static [(&'static str, &'static str, Option<char>)] {
    match solver {
        // Exact direct light at every sample is the sources' transfer;
        // shooting the secondary emitters and gathering their light at the
        // display samples of surfaces lit only by interreflection are the
        // transfer between surfaces.
        Solver::Structured => &[
            ("placement", "placement_seconds", None),
            ("direct", "direct_seconds", Some('A')),
            ("shooting", "shooting_seconds", Some('B')),
            ("indirect_display", "indirect_placement_seconds", Some('B')),
            ("display", "display_seconds", None),
        ],
        // Every link is refined, tested and gathered in the same passes,
        // whatever its sender: no split by transfer.
        Solver::Hierarchical => &[("refine", "refine_seconds", None), ("visibility", "visibility_seconds", None), ("gather", "gather_seconds", None)],
        Solver::Gpu | Solver::Photon => &[],
    }
}

/// A run's times: each stage's (`stage_times`, pipeline order), the
/// phases the solver's report times (`solver stage/phase`), and the
/// light-to-A and A-to-B times where the report separates them.
pub fn time_split(solver: Solver, stage_times: &[(String, f64)], solve_report: &Report) -> (Vec<Phase>, Option<f64>, Option<f64>) {
    let mut phases = Vec::new();
    let (mut to_a, mut to_b) = (None::<f64>, None::<f64>);
    for (stage, seconds) in stage_times {
        phases.push(Phase { name: stage.clone(), seconds: *seconds });
        if stage != solver.stage() {
            continue;
        }
        for &(name, counter, part) in timed_phases(solver) {
            let Some(&seconds) = solve_report.counters.get(counter) else { continue };
            phases.push(Phase { name: format!("{stage}/{name}"), seconds });
            match part {
                Some('A') => to_a = Some(to_a.unwrap_or(0.0) + seconds),
                Some(_) => to_b = Some(to_b.unwrap_or(0.0) + seconds),
                None => {}
            }
        }
    }
    (phases, to_a, to_b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use schemas::header::{Provenance, Schema};

    #[test]
    fn a_surface_is_the_pixel_weighted_mean_of_its_objects() {
        let counters: BTreeMap<String, f64> = [
            ("object[left].samples", 300.0),
            ("object[left].percent_over_tau_0.1", 10.0),
            ("object[right].samples", 100.0),
            ("object[right].percent_over_tau_0.1", 2.0),
            ("percent_over_tau_0.1", 7.0),
        ]
        .map(|(k, v)| (k.to_string(), v))
        .into();
        let objects = ["left", "right", "dark"].map(String::from);
        let group = SurfaceGroup { name: "walls".into(), objects: vec![0, 1] };
        let (pixels, over) = surface_over_tau(&counters, &objects, &group, &[0.1, 0.15]);
        assert_eq!(pixels, 400);
        assert_eq!(over, [OverTau { tau: 0.1, percent: 8.0 }, OverTau { tau: 0.15, percent: 0.0 }], "(300 x 10 + 100 x 2) / 400; 0.15 not measured counts nothing");
        let (pixels, over) = surface_over_tau(&counters, &objects, &SurfaceGroup { name: "dark".into(), objects: vec![2] }, &[0.1]);
        assert_eq!((pixels, over.len()), (0, 0), "no pixel: no figure");
        assert_eq!(image_over_tau(&counters, &[0.1, 0.15]), [OverTau { tau: 0.1, percent: 7.0 }]);
    }

    /// A unit square of two triangles (object 0) and a far triangle
    /// (object 1).
    fn mesh() -> Mesh {
        let triangle = |vertices: [u32; 3], object: u32| schemas::mesh::Triangle { vertices, material: 0, object, area: 0.5, normal: [0.0, 0.0, 1.0] };
        Mesh {
            header: Mesh::header(Provenance::in_memory("test")),
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, 1.0, 0.0]],
            triangles: vec![triangle([0, 1, 2], 0), triangle([0, 2, 3], 0), triangle([4, 5, 6], 1)],
        }
    }

    #[test]
    fn element_vertices_shared_by_neighbouring_input_triangles_count_once() {
        use schemas::solution::{Element, NONE};
        let mut elements: Vec<Element> = (0..3).map(|t| Element::root(t, 0.5, [0.0; 3])).collect();
        // Triangle 0 split 1:4: corner children, then the middle one.
        elements[0].first_child = 3;
        for corners in [[[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]], [[0.5, 0.0], [1.0, 0.0], [0.5, 0.5]], [[0.0, 0.5], [0.5, 0.5], [0.0, 1.0]], [[0.5, 0.5], [0.0, 0.5], [0.5, 0.0]]] {
            elements.push(Element { triangle: 0, parent: 0, first_child: NONE, level: 1, corners, area: 0.125, radiosity: [0.0; 3] });
        }
        let solution = Solution { header: Solution::header(Provenance::in_memory("test")), elements, clusters: Vec::new(), links: Vec::new(), slopes: Vec::new() };
        let groups = [SurfaceGroup { name: "square".into(), objects: vec![0] }, SurfaceGroup { name: "both".into(), objects: vec![0, 1] }];
        // Square: 4 leaves of triangle 0 and triangle 1's root; corners: the
        // square's 4 and triangle 0's 3 edge midpoints (triangle 1 shares
        // the diagonal's ends, not its midpoint).
        assert_eq!(hierarchical_counts(&solution, &mesh(), &groups), [(5, 7), (6, 10)]);
    }

    #[test]
    fn samples_and_emitters_are_counted_on_the_surface_of_their_object() {
        use schemas::samples::{Reason, SampledSurface, Sample, SecondaryEmitter, NO_EMITTER, NO_LEVEL};
        let sample = |surface: u32| Sample { position: [0.0; 3], surface, triangle: 0, reason: Reason::SmoothLattice, level: NO_LEVEL, direct: [0.0; 3], luminance: [0.0; 3], emitter: NO_EMITTER };
        let on = |object: u32| SampledSurface { object, material: 0, normal: [0.0, 0.0, 1.0] };
        let emitter = |surface: u32| SecondaryEmitter { surface, area: 1.0, shot: [0.0; 3], triangles: vec![[0, 1, 2]] };
        let samples = Samples {
            header: Samples::header(Provenance::in_memory("test")),
            samples: [0, 0, 1, 1, 1, 2].map(sample).to_vec(),
            // Sampled surfaces 0 and 2 lie on object 1, surface 1 on object 0.
            surfaces: vec![on(1), on(0), on(1)],
            emitters: vec![emitter(0), emitter(1), emitter(2)],
        };
        let groups = [SurfaceGroup { name: "A".into(), objects: vec![0] }, SurfaceGroup { name: "B".into(), objects: vec![1] }];
        assert_eq!(structured_counts(&samples, &groups), [(3, 1), (3, 2)]);
    }

    #[test]
    fn the_time_split_is_what_the_report_times_and_nothing_for_a_solver_that_does_not_split() {
        let report = |counters: &[(&str, f64)]| Report {
            header: Report::header(Provenance::in_memory("test")),
            wall_time_s: 10.0,
            counters: counters.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            skipped: Vec::new(),
            notes: Vec::new(),
        };
        let structured = report(&[("placement_seconds", 1.0), ("direct_seconds", 2.0), ("shooting_seconds", 3.0), ("indirect_placement_seconds", 0.5), ("display_seconds", 0.25)]);
        let (phases, to_a, to_b) = time_split(Solver::Structured, &[("structured-sample".into(), 7.0)], &structured);
        assert_eq!((to_a, to_b), (Some(2.0), Some(3.5)));
        let names: Vec<&str> = phases.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["structured-sample", "structured-sample/placement", "structured-sample/direct", "structured-sample/shooting", "structured-sample/indirect_display", "structured-sample/display"]);
        let hierarchical = report(&[("refine_seconds", 1.0), ("visibility_seconds", 2.0), ("gather_seconds", 3.0)]);
        let (phases, to_a, to_b) = time_split(Solver::Hierarchical, &[("cluster".into(), 0.5), ("hierarchical-solve".into(), 6.0), ("grid-gather".into(), 1.0)], &hierarchical);
        assert_eq!((to_a, to_b), (None, None));
        assert_eq!(phases.iter().map(|p| p.seconds).collect::<Vec<_>>(), [0.5, 6.0, 1.0, 2.0, 3.0, 1.0]);
    }
}
