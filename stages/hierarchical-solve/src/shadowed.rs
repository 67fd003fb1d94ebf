//! Leaves a shadow edge crosses, opened in the last solve.
//!
//! Refinement keeps a link whose shadow term, `2 min(V, 1 - V) rho_r B_s
//! F_rs` (what a shadow edge across it may misplace over its receiver,
//! [`crate::links::decide`]), is within its share of the receiver's
//! allowance: the receiver's *mean* is then right, but a leaf shows that
//! mean all over, the bright side of the edge and the dark side alike.
//! Where such a leaf lies next to another surface, that surface sees its
//! near side, and the kernel weighs the near side most: along a block's
//! base the floor's contact shadow is a strip a centimetre wide, which a
//! floor leaf of 2.5 cm holds with the lit floor beside it. On the
//! built-in Cornell box at `EPS` 4e-4 (seed 1) one such leaf in front of
//! the short block's camera face has the mean 0.434, where the leaves of
//! the `EPS` 5e-5 solve in it range from 0.02 at the face to 0.65, and the
//! face's leaf above it came out 41% over the fine solve's; the face as a
//! whole +1.75%, and the short block, the worst surface of the preview,
//! +0.61% against Mitsuba (mean over seeds 1-5).
//!
//! So the last solve opens every leaf whose partly occluded links together
//! may misplace at least [`SHADOWED_LEAF`] (a thirty-second) of its
//! radiosity into its four children, down to the shadow floor (`--shadow-levels` below the area
//! floor): no link is added or refined. The links into the leaf now have
//! a receiver with children, and bring each child the light its own
//! visibility of the sender lets through ([`crate::receivers`], with as
//! many rays as a link's own visibility takes); a solve with the senders'
//! means, distributing only those links by weight
//! ([`crate::receivers::Build::Opened`]), gives the children their
//! radiosity; and the links out of the leaf, resolved into parts next
//! ([`crate::gather`]), weigh its near child most. Without that solve
//! the children share their parent's radiosity when the links out of it
//! are weighed, and the short block kept +0.53%.
//!
//! Preview against Mitsuba, `EPS` 4e-4, opening at a quarter of the
//! radiosity: the short block +0.60% -> +0.41% (mean over seeds 1-5), the
//! worst surface per seed 0.29-0.72% -> 0.29-0.55% over seeds 1-8,
//! relative RMSE 1.352% -> 1.252% (seeds 1-5), with 27-38 leaves opened,
//! for 4% more solve time on one thread. In
//! `tests/tests/contact_shadow.rs` at 4e-4 the floor within 2 cm of the
//! wall's base went from +7.4% to +3.1% over the reference, and the wall's
//! base, which that floor lights, from +2.9% to +2.1% (means of per-leaf
//! errors); the penumbra of `tests/tests/receiver_parts.rs`, where
//! refinement had already placed the leaves, from 0.35% to 0.31% (L2 over
//! the leaves).
//!
//! **A sixteenth** opens about eight times the leaves (290 against 34 at
//! 4e-4, seed 1) for 8% more solve time at the same `EPS` (one thread,
//! medians of 9 interleaved; 14% at 2.5e-4), and buys more accuracy than
//! that time buys by tightening `EPS`: the errors it removes are one-signed
//! (a dim face lit by the floor's contact shadow next to it), not the
//! refinement's. Over seeds 1-8 of the built-in Cornell box (against a
//! Mitsuba reference of 0.2% noise) every surface of every seed is within
//! 0.7% from `EPS` 6e-4 (worst 0.30-0.63%, 19.4k links), where a quarter
//! needed 4.75e-4 (0.23-0.62%, 26.8k links): 0.83 times the solve time
//! (medians of 11 interleaved, one thread). At 6e-4 a quarter left
//! 0.55-0.96% (short block +0.70% on average, now +0.37%), at 5e-4
//! 0.36-0.78% (now 0.31-0.54%); relative RMSE over seeds 1-5 at 4e-4
//! 1.166% -> 1.046%, at 2.5e-4 0.897% -> 0.852%. In `contact_shadow.rs`
//! at 4e-4 the crease's floor +3.3% -> +2.5%, its wall +2.0% -> +1.9%.
//! An eighth left seed 3 at 0.73% at 6e-4; opening two levels at once
//! (the children that may split again) changed the short block by 0.07%.
//!
//! **A thirty-second**, now: judged by the worst surface alone it was
//! about as accurate as a sixteenth (0.21-0.65% at 6e-4) for more time,
//! but the preview's relative RMSE over seeds 1-8 (the measure)
//! goes from 2.145% to 2.016% at `EPS` 1e-3, 1.522% to 1.391% at 6e-4 and
//! 3.519% to 3.454% at 1.5e-3 (the worst surface per seed 0.59-1.28% ->
//! 0.54-1.05%, 0.28-0.46% -> 0.28-0.47%, 1.04-3.06% -> 1.49-2.92%), for
//! 4% and 6% more solve time at 1e-3 and 6e-4 (one thread, medians of
//! 9 and 7 interleaved; `plants-2k` the same, 30 leaves opened against
//! 18): the floor's shadows along the blocks show at the children's
//! resolution. A tighter `EPS` buys about 6% for that time there.
//! Against the `EPS` 2.5e-5 solve (seeds 1-2) the worst surface went
//! 0.29-0.34% -> 0.20-0.28% at 1e-3 and 0.14-0.15% -> 0.13-0.18% at
//! 6e-4, the worst input triangle 4.89-5.05% -> 3.90-4.10% and
//! 1.22-1.35% -> 1.24-1.42%; the leaves' rms error at 6e-4 rose by 1-3%
//! (seeds 1-4), the smaller children each lit through fewer rays. A
//! sixty-fourth gave 1.986% and 1.359% for 6% and 8% more time.
//!
//! **Also a leaf a solid stands on** (exposure under 1,
//! [`crate::exposure`]), but not one wholly buried. Such a leaf lies along
//! a block's base, where the contact shadow is, and the block's own faces
//! see it nearest. Left whole (as before: its children's light, each
//! divided by its own exposure, came out worse than the leaf's in
//! `tests/tests/buried_parts.rs` when that opening was first tried), on
//! the built-in Cornell box at `EPS` 1e-3 (seed 3) a floor leaf of 6.6 cm
//! at the short block's front corner, half in the block's penumbra from
//! the lamp, had the mean 0.286, where the `EPS` 2.5e-5 solve's leaves in
//! it range from 0.04 at the corner to 0.42. The face's leaves at that
//! corner, which see it nearest, took the kernel-weighted 0.29 where the
//! fine leaves give 0.18, and came out 20% to 62% over the fine solve; the
//! face's lower triangle +7.0%. Opened as well, over seeds 1-8 of the
//! Cornell box (preview against Mitsuba, worst surface per seed): `EPS`
//! 1e-3 0.65-1.71% -> 0.57-1.11% (relative RMSE 2.37% -> 2.18%), 7e-4
//! 0.45-0.84% -> 0.37-0.75%, 6e-4 0.31-0.54% -> 0.31-0.41%, 5e-4
//! 0.19-0.48% -> 0.17-0.42%, for about 5% more solve time at 1e-3 and
//! none measurable at 6e-4. In `buried_parts.rs` the leaves crossing the
//! slab's footprint now come out better, not worse (bias and L2: +2.76%,
//! 7.93% -> -1.00%, 7.17% at 4e-4; +0.10%, 2.03% -> -0.39%, 1.81% at
//! 1.5e-5), since links into inner elements take the visibility their
//! parts measure ([`crate::receivers`]).
//!
//! Not where mirrors or panes couple elements (their couplings hold the
//! pass's elements) nor on translucent surfaces (whose two faces refine
//! together): there the leaves stay as refinement left them.

use crate::elements::Hierarchy;
use crate::links::Link;
use schemas::solution::Node;

/// Fraction of a leaf's radiosity (brightest channel) that its partly
/// occluded links' shadow terms must reach together for the last solve to
/// open it (module docs).
pub const SHADOWED_LEAF: f64 = 1.0 / 32.0;

/// The leaves (element indices, ascending) that `links` may light with a
/// shadow edge across by at least [`SHADOWED_LEAF`] of their radiosity in
/// `radiosity` (dense index), that may split above `floor` (m²) and that
/// are not wholly buried.
pub fn shadowed_leaves(h: &Hierarchy, links: &[Link], radiosity: &[[f64; 3]], floor: f64) -> Vec<u32> {
    let mut misplaced = vec![0.0; h.elements.len()];
    for l in links.iter().filter(|l| l.partly_occluded()) {
        if let Node::Element(r) = l.receiver {
            if h.elements[r as usize].is_leaf() {
                misplaced[r as usize] += l.shadow_term(h, r, radiosity);
            }
        }
    }
    (0..h.elements.len() as u32)
        .filter(|&e| {
            let m = misplaced[e as usize];
            let brightest = radiosity[h.flat(Node::Element(e))].iter().copied().fold(0.0, f64::max);
            m > 0.0 && m >= SHADOWED_LEAF * brightest && h.can_split(Node::Element(e), floor) && h.exposure(e) > 0.0
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::links::{link, Linking};
    use crate::test_scenes::FloorAndWall;
    use radiometry::form_factor::Quadrature;

    /// The floor's first triangle under the lamp with a partly occluded
    /// link: opened where the link's shadow term reaches [`SHADOWED_LEAF`]
    /// of its radiosity, also where a solid stands on part of it; not where
    /// it falls short, nor where the link is clear or wholly hidden, nor
    /// below the floor, nor where the leaf is wholly buried.
    #[test]
    fn a_leaf_opens_where_its_shadow_term_reaches_its_share_of_its_radiosity() {
        let mut h = FloorAndWall::new(1.0).h;
        h.exposure = vec![1.0; h.elements.len()];
        let linking = Linking { cluster_samples: 16, seed: 1, quadrature: Quadrature::to_depth(3) };
        let mut lamp = link(&h, Node::Element(0), Node::Element(4), linking).expect("the lamp faces the floor");
        lamp.visibility = Some(0.5);
        let mut b = vec![[1.0; 3]; h.cluster_count() + h.elements.len()];
        // 2 min(V, 1 - V) rho_r B_s F: the floor's reflectance 0.5, the
        // lamp's radiosity 1.
        let term = lamp.shadow_term(&h, 0, &b);
        assert!((term - 0.5 * lamp.form_factor).abs() < 1e-12, "{term}");
        let floor = h.flat(Node::Element(0));
        let area = h.area(Node::Element(0));
        // The leaf's radiosity as a multiple of the term: just under the
        // threshold's, and just over.
        let (under, over) = (1.0 / SHADOWED_LEAF - 0.1, 1.0 / SHADOWED_LEAF + 0.1);
        for (radiosity, v, floor_area, opened) in [(under, 0.5, 0.0, true), (over, 0.5, 0.0, false), (under, 1.0, 0.0, false), (under, 0.0, 0.0, false), (under, 0.5, area, false)] {
            let x = radiosity * term;
            b[floor] = [0.5 * x, x, 0.25 * x];
            lamp.visibility = Some(v);
            let leaves = shadowed_leaves(&h, &[lamp], &b, floor_area);
            assert_eq!(leaves == [0], opened, "B_r = {radiosity} x the term, V = {v}, floor {floor_area}: {leaves:?}");
        }
        // Half buried, with the same shadow term on its exposed part: it
        // opens; wholly buried, it does not.
        h.exposure[0] = 0.5;
        lamp.visibility = Some(0.25);
        assert!((lamp.shadow_term(&h, 0, &b) - term).abs() < 1e-12);
        b[floor] = [under * term; 3];
        assert_eq!(shadowed_leaves(&h, &[lamp], &b, 0.0), [0]);
        h.exposure[0] = 0.0;
        assert!(shadowed_leaves(&h, &[lamp], &b, 0.0).is_empty());
    }
}
