//! Fuzz target for the cluster hierarchy as the solver walks it (issue
//! 11): the records of the `cluster` table (parent, children, triangle
//! range, bounds, area, reflectance, normal cone) mutated as words,
//! written with the `schemas` writer, read back, and, where the reader
//! accepts them, solved. Once a cycle hung the solver and an empty cluster
//! panicked it; now the reader refuses both, and every hierarchy it
//! accepts must solve without a panic or a hang.

use end_to_end::fuzz::{fuzz, Kind};
use hierarchical_solve::{solve, Criterion, Params};
use schemas::cluster::Clusters;
use schemas::exr_io::{read_exr, write_exr};
use std::sync::atomic::{AtomicUsize, Ordering};
use test_support::artifacts::{closed_box, clusters_over, table_words, with_layer_words};

#[test]
fn fuzz_cluster_hierarchy_walk() {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let path = |case: usize| std::env::temp_dir().join(format!("fuzz-hierarchy-{}-{case}.exr", std::process::id()));
    let (mesh, _) = closed_box();
    let seed = path(NEXT.fetch_add(1, Ordering::Relaxed));
    clusters_over(&mesh).write(&seed).unwrap();
    let (artifact, _) = read_exr::<Clusters>(&seed).unwrap();
    std::fs::remove_file(&seed).unwrap();
    let words = table_words(artifact.layer(&seed, "cluster").unwrap());
    // A coarse solve: the walk is what is tested, not the accuracy.
    let params = Params { criterion: Criterion::Absolute, eps: 0.5, min_area: 0.05, visibility_rays: 1, cluster_samples: 1, max_passes: 2, max_iterations: 4, ..Params::default() };
    fuzz("clusters-hierarchy", &[&words], Kind::Binary, move |bytes| {
        let (mesh, manifest) = closed_box();
        let file = path(NEXT.fetch_add(1, Ordering::Relaxed));
        write_exr(&file, &with_layer_words(&artifact, "cluster", bytes)).unwrap();
        let read = Clusters::read(&file, mesh.triangles.len());
        std::fs::remove_file(&file).unwrap();
        if let Ok((clusters, _)) = read {
            let _ = solve(&mesh, &manifest, Some(clusters), &params, &|_| {});
        }
    });
}
