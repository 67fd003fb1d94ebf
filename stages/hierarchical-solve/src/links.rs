//! Links and the refinement oracle of hierarchical radiosity (Hanrahan,
//! Salzman, Aupperle, "A rapid hierarchical radiosity algorithm", SIGGRAPH
//! 1991): a link carries light from a sender to a receiver element; a link
//! whose transport is too coarse is replaced by links from or to the
//! children of the larger element.

use crate::elements::Hierarchy;
use radiometry::form_factor::triangle_to_polygon;

/// A link: `receiver` gathers from `sender`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    /// Receiving element.
    pub receiver: u32,
    /// Sending element.
    pub sender: u32,
    /// Unoccluded form factor F_rs: receiver-area mean of Lambert's
    /// point-to-polygon factor to the sender (002 Eq. 3).
    pub form_factor: f64,
    /// Largest point factor over the receiver's quadrature points: the
    /// oracle's bound on the transport's variation.
    pub bound: f64,
    /// Visible fraction, `None` until rays were cast.
    pub visibility: Option<f32>,
    /// Distance from the receiver to the nearest occluder, +inf if none.
    pub occluder_distance: f32,
}

/// What to do with a link.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// Accurate enough, or too small to split.
    Keep,
    /// Replace by links from the sender's children.
    Sender,
    /// Replace by links to the receiver's children.
    Receiver,
}

/// The link from `sender` to `receiver`, or `None` where no light can pass:
/// the sender lies wholly behind the receiver's plane or the receiver wholly
/// behind the sender's (both are one-sided), which includes coplanar
/// elements and an element with itself.
pub fn link(h: &Hierarchy, receiver: u32, sender: u32) -> Option<Link> {
    let (r, s) = (&h.elements[receiver as usize], &h.elements[sender as usize]);
    let (nr, ns) = (h.normal(receiver), h.normal(sender));
    // Heights above the other's plane, against a tolerance scaled to the
    // elements, so round-off on coplanar elements does not count as "in front".
    let size = (r.area + s.area).sqrt();
    let tolerance = 1e-9 * size;
    let in_front = |points: &[glam::DVec3; 3], origin: glam::DVec3, normal: glam::DVec3| {
        points.iter().any(|p| (*p - origin).dot(normal) > tolerance)
    };
    if receiver == sender || !in_front(&s.points, r.points[0], nr) || !in_front(&r.points, s.points[0], ns) {
        return None;
    }
    let (form_factor, bound) = triangle_to_polygon(&r.points, nr, &s.points);
    (form_factor > 0.0).then_some(Link { receiver, sender, form_factor, bound, visibility: None, occluder_distance: f32::INFINITY })
}

/// BF refinement oracle: the radiosity a link may misplace on its receiver
/// is bounded by `rho_r B_s F_max` (reflectance of the receiver, radiosity
/// of the sender, largest point form factor). Above `threshold` (W/m²) the
/// larger of the two elements is split, unless a child would be smaller than
/// `min_area`; then the other one, if it can be.
pub fn decide(h: &Hierarchy, link: &Link, radiosity: &[[f64; 3]], threshold: f64, min_area: f64) -> Split {
    let rho = h.reflectance_of(link.receiver);
    let b = radiosity[link.sender as usize];
    let transported = (0..3).map(|c| rho[c] * b[c]).fold(0.0, f64::max) * link.bound;
    if transported <= threshold {
        return Split::Keep;
    }
    let (ar, as_) = (h.elements[link.receiver as usize].area, h.elements[link.sender as usize].area);
    let (can_r, can_s) = (ar / 4.0 >= min_area, as_ / 4.0 >= min_area);
    match (as_ >= ar, can_s, can_r) {
        (true, true, _) => Split::Sender,
        (_, _, true) => Split::Receiver,
        (_, true, false) => Split::Sender,
        _ => Split::Keep,
    }
}

/// The links replacing `link` after `split` (children already exist).
pub fn children_links(h: &Hierarchy, link: &Link, split: Split) -> Vec<Link> {
    match split {
        Split::Keep => vec![*link],
        Split::Sender => {
            let first = h.elements[link.sender as usize].first_child;
            (first..first + 4).filter_map(|s| self::link(h, link.receiver, s)).collect()
        }
        Split::Receiver => {
            let first = h.elements[link.receiver as usize].first_child;
            (first..first + 4).filter_map(|r| self::link(h, r, link.sender)).collect()
        }
    }
}
