//! The `exact` stage end to end (issue 16): its image is read unchanged by
//! `tonemap` and `compare` and carries a per-pixel error bound; a scene of
//! paper 002's one-bounce kind written as files is solved, an occluded one
//! is refused with one line naming why, and nothing is written.

use end_to_end::{assert_refused, run, run_ok, s, scratch};
use schemas::exr_io::read_exr;
use schemas::image::HdrImage;
use test_support::scenes::{one_bounce, straddled_receiver};

/// mesh-prep of the built-in simple environment, then exact at 32 x 32
/// (one bounce): tonemap and compare read the image; compare of it with
/// itself finds no pixel over tau; the bound channels are there, positive
/// on lit pixels and under 1e-5 of them (the tolerance is 1e-6).
#[test]
fn exact_image_reads_in_tonemap_and_compare_with_its_bound() {
    let dir = scratch("exact_simple_environment");
    let (mesh, manifest, image) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("image.exr"));
    run_ok("mesh-prep", &["--builtin", "simple-environment", "--mesh", s(&mesh), "--manifest", s(&manifest)]);
    run_ok("exact", &["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&image), "--width", "32", "--height", "32"]);
    run_ok("tonemap", &[s(&image), "-o", s(&dir.join("image.png"))]);
    let same = run("compare", &[s(&image), s(&image), "--max-pixels-over-tau", "0", "-o", s(&dir.join("compare.ron"))]);
    assert_eq!(same.status.code(), Some(0), "{}", String::from_utf8_lossy(&same.stderr));
    let (hdr, _) = HdrImage::read(&image).unwrap();
    assert_eq!((hdr.width, hdr.height), (32, 32));
    let (artifact, _) = read_exr::<HdrImage>(&image).unwrap();
    let layer = artifact.layer(&image, "").unwrap();
    let mut lit = 0;
    for (k, channel) in ["R", "G", "B"].iter().enumerate() {
        let bound = layer.f32s(&image, &format!("error_bound.{channel}")).unwrap();
        for (i, b) in bound.iter().enumerate() {
            let value = hdr.rgb[i][k];
            assert!(*b >= 0.0 && *b <= 1e-5 * value + 1e-12, "pixel {i} {channel}: bound {b} of {value}");
            lit += usize::from(value > 0.0 && *b > 0.0);
        }
    }
    assert!(lit > 100, "{lit} lit pixel channels with a bound");
}

/// The end-to-end tests' one-bounce scene (a light and B side by side
/// under A) is solved; the straddled receiver (a black box under a lamp
/// that crosses its face's plane) is refused as occluded, one line naming
/// the manifest and why, and no image is written.
#[test]
fn occluded_scene_is_refused_one_bounce_scene_is_solved() {
    for (name, scene, solvable) in [("exact_one_bounce", one_bounce(0.5, 0.5, 1.0), true), ("exact_occluded", straddled_receiver(0.5, 1.0), false)] {
        let dir = scratch(name);
        let path = scene.write(&dir);
        let (mesh, manifest, image) = (dir.join("mesh.exr"), dir.join("manifest.ron"), dir.join("image.exr"));
        run_ok("mesh-prep", &[s(&path), "--mesh", s(&mesh), "--manifest", s(&manifest)]);
        let args = ["--mesh", s(&mesh), "--manifest", s(&manifest), "-o", s(&image), "--width", "8", "--height", "8", "--bounces", "3"];
        if solvable {
            run_ok("exact", &args);
        } else {
            assert_refused("exact", &args, &["manifest.ron", "no exact image: occluders: object '"], &[&image]);
        }
    }
}
