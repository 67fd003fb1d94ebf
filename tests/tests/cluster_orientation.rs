//! Light a cluster receives reaches each of its surfaces by that surface's
//! own orientation to the sender (issue 10): the built-in Cornell box solved
//! with clusters at a coarse `EPS` has every face of every object within a
//! few percent of the unclustered solve at a fine `EPS`, per face (object
//! and normal), from the solution's leaves, area-weighted. Before the fix a
//! cluster's irradiance was pushed to all its triangles alike, faces turned
//! away from the light included: the short block's mean was +85% in the
//! preview at `EPS` 1e-2.

use end_to_end::{run_ok, s, scratch, solve_prepared};
use schemas::mesh::{Manifest, Mesh};
use schemas::ron_io::read_ron;
use schemas::solution::Solution;
use std::collections::BTreeMap;
use std::path::Path;

/// Per face, its mean radiosity and area.
type Faces = BTreeMap<(String, [i32; 3]), ([f64; 3], f64)>;

/// Area-weighted mean radiosity of the solution's leaves per face: (object
/// name, normal's components in hundredths).
fn face_means(dir: &Path, solution: &Path) -> Faces {
    let manifest = read_ron::<Manifest>(&dir.join("manifest.ron")).unwrap().value;
    let (mesh, _) = Mesh::read(&dir.join("mesh.exr")).unwrap();
    let (solution, _) = Solution::read(solution).unwrap();
    let mut sums: BTreeMap<(String, [i32; 3]), ([f64; 3], f64)> = BTreeMap::new();
    for e in solution.elements.iter().filter(|e| e.is_leaf()) {
        let t = &mesh.triangles[e.triangle as usize];
        let key = (manifest.objects[t.object as usize].clone(), t.normal.map(|x| (x * 100.0).round() as i32));
        let entry = sums.entry(key).or_insert(([0.0; 3], 0.0));
        for c in 0..3 {
            entry.0[c] += f64::from(e.area) * f64::from(e.radiosity[c]);
        }
        entry.1 += f64::from(e.area);
    }
    sums.into_iter().map(|(k, (b, a))| (k, (b.map(|x| x / a), a))).collect()
}

/// The largest relative error over the channels of `got` against `want`,
/// signed.
fn worst_channel(got: [f64; 3], want: [f64; 3]) -> f64 {
    (0..3).map(|c| (got[c] - want[c]) / want[c]).fold(0.0f64, |m, x| if x.abs() > m.abs() { x } else { m })
}

/// The largest relative error of a face and of a surface (an object's
/// faces together, area-weighted) of `got` against `want`, emitters left
/// out.
fn worst(label: &str, got: &Faces, want: &Faces) -> (f64, f64) {
    assert_eq!(got.len(), want.len(), "{label}: the same faces");
    let (mut face, mut objects) = (0.0f64, BTreeMap::<&str, ([f64; 3], [f64; 3])>::new());
    for ((key, (b, area)), (_, (reference, _))) in got.iter().zip(want) {
        if key.0 == "light" {
            continue;
        }
        let error = worst_channel(*b, *reference);
        eprintln!("{label} {key:?} area {area:.4}: {b:.4?} vs {reference:.4?}: {:+.2}%", 100.0 * error);
        face = face.max(error.abs());
        let sums = objects.entry(&key.0).or_insert(([0.0; 3], [0.0; 3]));
        for c in 0..3 {
            sums.0[c] += area * b[c];
            sums.1[c] += area * reference[c];
        }
    }
    let mut object = 0.0f64;
    for (name, (b, reference)) in objects {
        let error = worst_channel(b, reference);
        eprintln!("{label} surface {name}: {:+.2}%", 100.0 * error);
        object = object.max(error.abs());
    }
    eprintln!("{label}: worst face {:.2}%, worst surface {:.2}%", 100.0 * face, 100.0 * object);
    (face, object)
}

#[test]
fn a_coarse_clustered_solve_lights_every_face_by_its_own_orientation() {
    let dir = scratch("cluster_orientation");
    run_ok("mesh-prep", &["--builtin", "cornell-box", "--mesh", s(&dir.join("mesh.exr")), "--manifest", s(&dir.join("manifest.ron"))]);
    let reference = solve_prepared(&dir, &["--eps", "1.5e-5"], None);
    let kept = dir.join("reference.exr");
    std::fs::rename(&reference, &kept).unwrap();
    let expected = face_means(&dir, &kept);
    // Measured: unclustered at EPS 1e-2 the worst face is 9.9% off, the
    // worst surface 2.6%; clustered with the isotropic push the worst face
    // was 235% off at 1e-2 and 91% at 1e-3 (surfaces kept their flux: 3.5%
    // at 1e-2); with each triangle's own factor to each part of the sender 11.1%
    // and 3.3% (surfaces 4.6% and 2.3%); with the sender's parts weighted by
    // their visibility too 9.8% and 3.1% (surfaces 4.0% and 2.2%, the short
    // block); and with each face of a partly occluded link's receiver
    // weighted by its visibility (receivers.rs) 7.1% and 2.5% (surfaces 2.8%
    // and 1.1%); with the links into inner elements lighting each part by
    // its own factor (both solves) 5.5% and 2.4% (surfaces 2.4% and 1.1%).
    // Those EPS were 24 times the ones below, which have the same relative
    // threshold since hierarchical-solve's RELATIVE_AT went from 3 to 1/8
    // with the absolute threshold as a cap: 5.4% and 0.24% (surfaces 1.3%
    // and 0.05%); 5.2% at 4e-4 (the short block's face turned from the lamp,
    // lit by the floor in its umbra, which links from the ceiling into the
    // clusters holding floor and block lit as if the block hid none of it)
    // until partly occluded cluster links were split by their shadow term:
    // 1.74% (surfaces 0.65%). That face's error at 4e-4 swings with the
    // seed (the visibility noise of the few large links that light it: over
    // seeds 1-5 its leaves are 3.0-9.4% over the fine solve's before the
    // split, 1.7-6.1% after), so the tolerance stays above what any seed
    // gives.
    for (eps, face_tolerance, surface_tolerance) in [("4e-4", 0.07, 0.03), ("4e-5", 0.03, 0.016)] {
        let clustered = solve_prepared(&dir, &["--eps", eps], Some(8));
        let (face, surface) = worst(&format!("EPS {eps}"), &face_means(&dir, &clustered), &expected);
        assert!(face < face_tolerance, "EPS {eps}: a face's mean radiosity {:.1}% off the unclustered solve", 100.0 * face);
        assert!(surface < surface_tolerance, "EPS {eps}: a surface's mean radiosity {:.1}% off the unclustered solve", 100.0 * surface);
    }
}
