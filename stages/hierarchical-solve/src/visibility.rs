//! Visibility of a link, estimated by rays between jittered stratified
//! points on receiver and sender, stored as the clear fraction, with the
//! distance from the receiver to the nearest occluder that was hit (the final
//! gather sizes penumbrae from it, paper 000 Section 5.3).

use crate::elements::Hierarchy;
use crate::links::{Link, Linking};
use crate::transfer;
use radiometry::rays::SceneRays;
use radiometry::sampling::{stratified_point, Stream};
use schemas::solution::Node;

/// Visible fraction and nearest occluder of `link`: rays between stratified
/// points for two elements ([`estimate`], `rays` of them), the kernel-weighted
/// pairs of [`transfer::estimate`] where a cluster is at an end. Returns the
/// rays cast too.
pub fn of_link(h: &Hierarchy, scene: &SceneRays, link: &Link, rays: usize, linking: Linking) -> (f32, f32, usize) {
    match (link.receiver, link.sender) {
        (Node::Element(r), Node::Element(s)) => {
            let (v, d) = estimate(h, scene, r, s, rays, linking.seed);
            (v, d, rays)
        }
        (r, s) => {
            let e = transfer::estimate(h, Some(scene), r, s, linking.cluster_samples, linking.seed);
            let (v, d) = e.visibility.unwrap_or((1.0, f32::INFINITY));
            (v, d, linking.cluster_samples)
        }
    }
}

/// Clear fraction and nearest-occluder distance (+inf if no ray was
/// blocked) of the link `receiver <- sender`, with `rays` rays. The random
/// stream is keyed by the two elements, so the estimate does not depend on
/// the order links are processed in.
pub fn estimate(h: &Hierarchy, scene: &SceneRays, receiver: u32, sender: u32, rays: usize, seed: u64) -> (f32, f32) {
    let (r, s) = (&h.elements[receiver as usize], &h.elements[sender as usize]);
    let skip = [r.triangle, s.triangle];
    let mut stream = Stream::new(seed, receiver.into(), sender.into());
    // Pair receiver stratum k with a shuffled sender stratum, so that ray
    // directions are not correlated with position on the receiver.
    let mut order: Vec<usize> = (0..rays).collect();
    for i in (1..rays).rev() {
        let j = (stream.next_f64() * (i + 1) as f64) as usize;
        order.swap(i, j.min(i));
    }
    let mut clear = 0usize;
    let mut nearest = f64::INFINITY;
    for (k, &k_sender) in order.iter().enumerate() {
        let from = stratified_point(&r.points, k, rays, &mut stream);
        let to = stratified_point(&s.points, k_sender, rays, &mut stream);
        match scene.first_blocker(from, to, skip) {
            None => clear += 1,
            Some(distance) => nearest = nearest.min(distance),
        }
    }
    (clear as f32 / rays as f32, nearest as f32)
}
