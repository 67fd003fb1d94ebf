//! Fuzz target for the cluster hierarchy as the solver walks it (issue
//! 11): every field of every cluster (parent, children, triangle range,
//! bounds, area, reflectance, normal cone) mutated as words, written with the `schemas` writer, read back,
//! and, where the reader accepts them, solved. Once a cycle hung the solver
//! and an empty cluster panicked it; now the reader refuses both, and every
//! hierarchy it accepts must solve without a panic or a hang.

use end_to_end::artifacts::{closed_box, cluster_words, clusters_over, with_cluster_words};
use end_to_end::fuzz::{fuzz, Kind};
use hierarchical_solve::{solve, Criterion, Params};
use schemas::cluster::Clusters;
use std::sync::atomic::{AtomicUsize, Ordering};

#[test]
fn fuzz_cluster_hierarchy_walk() {
    let (mesh, _) = closed_box();
    let words = cluster_words(&clusters_over(&mesh));
    // A coarse solve: the walk is what is tested, not the accuracy.
    let params = Params { criterion: Criterion::Absolute, eps: 0.5, min_area: 0.05, visibility_rays: 1, cluster_samples: 1, max_passes: 2, max_iterations: 4, ..Params::default() };
    fuzz("clusters-hierarchy", &[&words], Kind::Binary, move |bytes| {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let (mesh, manifest) = closed_box();
        let path = std::env::temp_dir().join(format!("fuzz-hierarchy-{}-{}.exr", std::process::id(), NEXT.fetch_add(1, Ordering::Relaxed)));
        with_cluster_words(&clusters_over(&mesh), bytes).write(&path).unwrap();
        let read = Clusters::read(&path, mesh.triangles.len());
        std::fs::remove_file(&path).unwrap();
        if let Ok((clusters, _)) = read {
            let _ = solve(&mesh, &manifest, Some(clusters), &params, &|_| {});
        }
    });
}
