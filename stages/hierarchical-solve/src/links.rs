//! Links and the refinement oracle of hierarchical radiosity (Hanrahan,
//! Salzman, Aupperle, "A rapid hierarchical radiosity algorithm", SIGGRAPH
//! 1991): a link carries light from a sender to a receiver element; a link
//! whose transport is too coarse is replaced by links from or to the
//! children of one of the two.

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
    /// Largest minus smallest point factor over the receiver's quadrature
    /// points: how much the transport varies over the receiver.
    pub spread: f64,
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
    /// Split whichever of the two is larger (oracle's wish only; resolved
    /// to `Sender` or `Receiver` before any link is split).
    Larger,
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
    let f = triangle_to_polygon(&r.points, nr, &s.points);
    (f.mean > 0.0).then_some(Link {
        receiver,
        sender,
        form_factor: f.mean,
        spread: f.max - f.min,
        visibility: None,
        occluder_distance: f32::INFINITY,
    })
}

/// The refinement oracle: HSA's BF criterion, with the "F" replaced by an
/// estimate of the link's error rather than its size. A link makes the
/// receiver's radiosity `rho_r V F_rs B_s` constant over the receiver; it
/// misplaces at most (W/m²)
///
/// - `rho_r B_s (F_max - F_min)` where the kernel varies over the receiver
///   (the spread of the point factors): only splitting the **receiver**
///   reduces it;
/// - `rho_r (B_s_max - B_s_min) F_rs` where the sender's radiosity varies
///   (known from its children, if it has any): splitting the **sender**
///   reduces it;
/// - `2 min(V, 1 - V) rho_r B_s F_rs` where the link is partly occluded (a
///   shadow edge crosses it): splitting the **larger** of the two reduces it.
///
/// Plain BF (`rho_r B_s F_rs`, split the larger) would also split senders
/// whose every part sends the same light: our form factor is exact over
/// the sender, so that buys nothing, and it multiplies links whose small
/// same-signed errors then add up on the receiver. The largest term above
/// `threshold` decides which element is split, unless its children would be
/// smaller than `min_area`: then a shadow edge splits the other element,
/// and the other errors keep the link (splitting the other element would
/// not reduce them).
pub fn decide(h: &Hierarchy, link: &Link, radiosity: &[[f64; 3]], threshold: f64, min_area: f64) -> Split {
    let rho = h.reflectance_of(link.receiver);
    let b = radiosity[link.sender as usize];
    let reflected = (0..3).map(|c| rho[c] * b[c]).fold(0.0, f64::max);
    let sender = &h.elements[link.sender as usize];
    let sender_variation = if sender.is_leaf() {
        0.0
    } else {
        (sender.first_child..sender.first_child + 4)
            .flat_map(|child| (0..3).map(move |c| (child, c)))
            .map(|(child, c)| rho[c] * (radiosity[child as usize][c] - b[c]).abs())
            .fold(0.0, f64::max)
    };
    let v = f64::from(link.visibility.unwrap_or(1.0));
    let errors = [
        (reflected * link.spread, Split::Receiver),
        (sender_variation * link.form_factor, Split::Sender),
        (2.0 * v.min(1.0 - v) * reflected * link.form_factor, Split::Larger),
    ];
    let (error, wanted) = errors.into_iter().fold((0.0, Split::Keep), |best, e| if e.0 > best.0 { e } else { best });
    if error <= threshold {
        return Split::Keep;
    }
    let (ar, as_) = (h.elements[link.receiver as usize].area, sender.area);
    let (can_r, can_s) = (ar / 4.0 >= min_area, as_ / 4.0 >= min_area);
    let larger = if as_ > ar { Split::Sender } else { Split::Receiver };
    match (wanted, can_r, can_s) {
        (Split::Receiver, true, _) | (Split::Sender, _, true) => wanted,
        (Split::Larger, true, true) => larger,
        (Split::Larger, true, false) => Split::Receiver,
        (Split::Larger, false, true) => Split::Sender,
        _ => Split::Keep,
    }
}

/// The links replacing `link` after `split` (children already exist).
pub fn children_links(h: &Hierarchy, link: &Link, split: Split) -> Vec<Link> {
    match split {
        Split::Keep | Split::Larger => vec![*link],
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
