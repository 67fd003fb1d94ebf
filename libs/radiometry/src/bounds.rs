//! Axis-aligned bounding boxes in f64, mesh frame.

use glam::DVec3;

/// An axis-aligned box, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The box around `points` (`min` +inf and `max` -inf for none).
    pub fn around(points: impl IntoIterator<Item = DVec3>) -> Aabb {
        points.into_iter().fold(Aabb { min: DVec3::INFINITY, max: DVec3::NEG_INFINITY }, |b, p| Aabb { min: b.min.min(p), max: b.max.max(p) })
    }

    /// Its centre, halfway between its corners.
    pub fn centre(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Whether the two boxes share a point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// The heights over the plane through `point` (along `normal`) of the
    /// box's lowest and highest corners: `(centre - point) . normal -+
    /// half . |normal|`, `half` the box's half extents.
    pub fn heights(&self, point: DVec3, normal: DVec3) -> (f64, f64) {
        let (height, span) = ((self.centre() - point).dot(normal), (0.5 * (self.max - self.min)).dot(normal.abs()));
        (height - span, height + span)
    }

    /// Whether the whole box lies strictly on the side of the plane through
    /// `point` that `normal` points to: its lowest corner above the plane
    /// ([`Aabb::heights`]).
    pub fn above(&self, point: DVec3, normal: DVec3) -> bool {
        self.heights(point, normal).0 > 0.0
    }

    /// The distance from `p` to the box (0 inside it).
    pub fn distance(&self, p: DVec3) -> f64 {
        (self.min - p).max(p - self.max).max(DVec3::ZERO).length()
    }

    /// Whether `p` is inside (the faces included).
    pub fn contains(&self, p: DVec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;

    #[test]
    fn the_box_around_points_holds_them_and_touching_boxes_overlap() {
        let b = Aabb::around([dvec3(1.0, -2.0, 0.5), dvec3(-1.0, 3.0, 0.0), dvec3(0.0, 0.0, 2.0)]);
        assert_eq!((b.min, b.max), (dvec3(-1.0, -2.0, 0.0), dvec3(1.0, 3.0, 2.0)));
        assert!(b.contains(dvec3(1.0, 3.0, 2.0)) && !b.contains(dvec3(1.0 + 1e-12, 0.0, 1.0)));
        assert_eq!(b.centre(), dvec3(0.0, 0.5, 1.0));
        let touching = Aabb { min: dvec3(1.0, 3.0, 2.0), max: dvec3(5.0, 5.0, 5.0) };
        let apart = Aabb { min: dvec3(1.0, 3.0, 2.0 + 1e-9), max: dvec3(5.0, 5.0, 5.0) };
        assert!(b.overlaps(&touching) && touching.overlaps(&b));
        assert!(!b.overlaps(&apart) && !apart.overlaps(&b));
        // Above a plane: every corner, not only the centre.
        let n = dvec3(1.0, 1.0, 0.0).normalize();
        let corner = |p: DVec3| (p - dvec3(-3.0, -2.0, 0.0)).dot(n);
        assert!(b.above(dvec3(-3.0, -2.0, 0.0), n) && corner(b.min) > 0.0);
        assert!(!b.above(dvec3(-1.0, -2.0, 0.0), n) && b.above(dvec3(-1.0 - 1e-9, -2.0, 0.0), n));
        assert!(!b.above(dvec3(0.0, 0.5, 1.0), DVec3::Z) && !b.above(dvec3(0.0, 0.0, 1.5), -DVec3::Z) && b.above(dvec3(0.0, 0.0, 2.0 + 1e-9), -DVec3::Z));
        // Heights of the lowest and highest corners (the box spans 0..2 in z).
        assert_eq!(b.heights(dvec3(5.0, 5.0, -1.0), DVec3::Z), (1.0, 3.0));
        // Distance: inside 0, beside a face, off a corner.
        assert_eq!(b.distance(dvec3(0.0, 0.0, 1.0)), 0.0);
        assert_eq!(b.distance(dvec3(0.0, 0.0, 4.0)), 2.0);
        assert_eq!(b.distance(dvec3(4.0, 7.0, 1.0)), 5.0);
        let empty = Aabb::around(std::iter::empty());
        assert!(!empty.contains(DVec3::ZERO) && !empty.overlaps(&b));
    }
}
