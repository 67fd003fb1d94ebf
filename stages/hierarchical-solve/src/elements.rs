//! The element hierarchy: input triangles (elements `0..n`, element `t` is
//! triangle `t`) and their 1:4 subdivisions, in one arena. Children are
//! created in a deterministic order, four at a time, so element indices do
//! not depend on threads.

use crate::detail::Detail;
use crate::cluster_tree::ClusterTree;
use crate::transmission::Transmission;
use glam::DVec3;
use radiometry::far_field::{beyond, triangle_factor};
use radiometry::form_factor::{point_to_one_sided_polygon, triangle_to_polygon, Quadrature};
use radiometry::geometry::TriangleGeometry;
use radiometry::subdivision::{children, Corners, ROOT};
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::{Node, NONE};
use schemas::surface::Surface;

/// What the irradiance averaged over a node is divided by to give its
/// exposed part's ([`crate::exposure`]): its exposure, or 1 where it is
/// wholly buried (its links bring it nothing to spread).
pub fn exposed(exposure: f64) -> f64 {
    if exposure > 0.0 {
        exposure
    } else {
        1.0
    }
}

/// Distance, in radii of an element, beyond which its factor from a
/// point is Dunavant's three-point rule of the point kernel over it rather
/// than Lambert's formula where the factor is taken as it is: where a
/// cluster receiver's triangles measure a link's factor
/// ([`crate::receivers`]; [`Hierarchy::factor_beyond`]). The rule is
/// within 0.10% of Lambert's factor at 4 radii in radiometry's test (the
/// point kernel at the centroid alone, used here before, 2.8%; a disc
/// facing the point, 5.9%). Beyond it too the receiver's slopes see a
/// leaf as its centroid ([`crate::slopes`]). 4 instead of 8 for the
/// centroid's kernel (at `EPS` 6e-4, seeds 1-8): relative RMSE 1.551%
/// against 1.547%, 6% less time.
pub const FAR_PART: f64 = 4.0;

/// Distance, in radii of an element, beyond which its weight among its
/// siblings (the parts of a sender or of a receiver, whose weights are
/// normalised to sum to 1; [`Hierarchy::weight_to_element`]) is the
/// three-point rule of [`FAR_PART`]: within 0.97% of Lambert's factor at 2
/// radii, and siblings at about the same distance err alike, which their
/// normalised weights cancel. From [`FAR_PART`] radii, with the centroid's
/// kernel instead of the rule, the built-in Cornell box's preview over
/// seeds 1-8 (against Mitsuba, relative RMSE) was 1.969%, 1.234% and
/// 0.957% at `EPS` 1.5e-3, 1e-3 and 6.5e-4; with the rule from 4 radii
/// 1.962%, 1.230% and 0.949% in the same time (one thread, medians of 11
/// and 7 interleaved); from 2, 1.959%, 1.229% and 0.949%, in 2.2%, 3.5%
/// and 2.5% less time than from 4 (0.130 s, 0.208 s and 0.354 s). The
/// centroid's kernel from 3 and 2 radii had put the relative RMSE at 6e-4
/// at 1.70% and 1.58% against 1.55%; the rule from 2 radii for a cluster
/// link's measured factor put the tests' factors 0.2% to 0.5% off, hence
/// [`FAR_PART`] there.
pub const SIBLING_PART: f64 = 2.0;

/// One element.
#[derive(Clone, Debug)]
pub struct Element {
    /// Input triangle.
    pub triangle: u32,
    /// Parent element or [`NONE`].
    pub parent: u32,
    /// First of four children or [`NONE`].
    pub first_child: u32,
    /// Depth below the input triangle.
    pub level: u32,
    /// Barycentric corners in the input triangle.
    pub corners: Corners,
    /// World corners, mesh frame.
    pub points: [DVec3; 3],
    /// Area, m².
    pub area: f64,
}

impl Element {
    /// Whether the element has no children.
    pub fn is_leaf(&self) -> bool {
        self.first_child == NONE
    }
}

/// The arena plus the per-triangle data every element inherits.
pub struct Hierarchy {
    /// All elements; children of `e` are `first_child .. first_child + 4`.
    pub elements: Vec<Element>,
    /// Geometry of each input triangle.
    pub triangles: Vec<TriangleGeometry>,
    /// Diffuse reflectance of each input triangle (texture-averaged over
    /// the triangle where a texture applies, [`crate::detail`]).
    pub reflectance: Vec<[f64; 3]>,
    /// Emitted radiosity of each input triangle, W/m².
    pub emission: Vec<[f64; 3]>,
    /// The clusters above the input triangles, when solving with them.
    pub clusters: Option<ClusterTree>,
    /// Direct irradiance from the luminaires averaged over each element,
    /// W/m² (the same in R, G, B; [`crate::luminaires`]); elements past its
    /// end have not been lit yet.
    pub direct: Vec<f64>,
    /// Exposed fraction of each element's area ([`crate::exposure`]);
    /// elements past its end count as wholly exposed until measured.
    pub exposure: Vec<f64>,
    /// Textures and alpha masks with each element's averages, where the
    /// scene has them.
    pub detail: Option<Detail>,
    /// Translucent faces and their pairing, where a material transmits.
    pub transmission: Option<Transmission>,
}

impl Hierarchy {
    /// One root element per input triangle, under `clusters` if given,
    /// with the textures and masks of `surface` if given.
    pub fn new(mesh: &Mesh, manifest: &Manifest, clusters: Option<schemas::cluster::Clusters>, surface: Option<Surface>) -> Self {
        let triangles = stage_kit::scene::mesh_triangles(mesh);
        let elements = triangles
            .iter()
            .enumerate()
            .map(|(t, g)| Element {
                triangle: t as u32,
                parent: NONE,
                first_child: NONE,
                level: 0,
                corners: ROOT,
                points: g.corners,
                area: g.area,
            })
            .collect();
        let material = |t: &schemas::mesh::Triangle| &manifest.materials[t.material as usize];
        let mut reflectance: Vec<[f64; 3]> = mesh.triangles.iter().map(|t| material(t).diffuse).collect();
        let mut areas: Vec<f64> = triangles.iter().map(|t| t.area).collect();
        let mut detail = surface.and_then(|s| Detail::new(s, mesh));
        if let Some(detail) = &mut detail {
            for t in 0..triangles.len() as u32 {
                detail.push(t, &ROOT);
                let average = detail.average(t);
                areas[t as usize] *= average.coverage;
                if let Some(rho) = average.reflectance {
                    reflectance[t as usize] = rho;
                }
            }
        }
        let clusters = clusters.map(|c| ClusterTree::new(c, &areas, &reflectance));
        let emission = mesh.triangles.iter().map(|t| material(t).emission).collect();
        let transmission = Transmission::new(mesh, manifest);
        Hierarchy { elements, reflectance, emission, triangles, clusters, direct: Vec::new(), exposure: Vec::new(), detail, transmission }
    }

    /// Opaque fraction of element `e` (1 without an alpha mask).
    pub fn coverage(&self, e: u32) -> f64 {
        self.detail.as_ref().map_or(1.0, |d| d.average(e).coverage)
    }

    /// Lambert's factor from point `x` (normal `n`) to element `e`'s opaque
    /// part: the one-sided point-to-polygon factor (002 Eq. 3) times its
    /// coverage (an alpha-masked element sends through its opaque fraction).
    pub fn factor_to_element(&self, x: DVec3, n: DVec3, e: u32) -> f64 {
        point_to_one_sided_polygon(x, n, &self.elements[e as usize].points, self.normal(e)) * self.coverage(e)
    }

    /// [`Hierarchy::factor_to_element`] where it weighs an element against
    /// its siblings: [`Hierarchy::factor_beyond`] from [`SIBLING_PART`]
    /// radii. Lambert's formula (an `atan2` per edge) was a third of the
    /// time the last solve spent weighing senders' parts on the Cornell
    /// box.
    pub fn weight_to_element(&self, x: DVec3, n: DVec3, e: u32) -> f64 {
        self.factor_beyond(x, n, e, SIBLING_PART)
    }

    /// [`Hierarchy::factor_to_element`], but beyond `radii` times the
    /// element's radius from `x` by Dunavant's three-point rule of the point
    /// kernel over it (radiometry's `far_field::triangle_factor`, exact for
    /// a quadratic kernel) times its coverage.
    pub fn factor_beyond(&self, x: DVec3, n: DVec3, e: u32, radii: f64) -> f64 {
        let el = &self.elements[e as usize];
        if beyond(x, &el.points, radii) {
            triangle_factor(x, n, &el.points, el.area, self.normal(e)) * self.coverage(e)
        } else {
            self.factor_to_element(x, n, e)
        }
    }

    /// Element `r`'s factor to element `e` as a weight among `e`'s
    /// siblings ([`Hierarchy::weight_to_element`]), seen from all of `r`
    /// where the two touch (their bounding boxes meet: a crease, a block's
    /// base): the factor over `r` by Dunavant's degree-5 rule
    /// (radiometry's `triangle_to_polygon` without a split), else from
    /// `r`'s centroid.
    ///
    /// Near a shared edge the kernel over `r` is largest along the edge, and
    /// its centroid sees a touching `e` too weakly: for a unit floor and a
    /// unit wall on its edge the weights from the centroids sum to 3.1%
    /// under the closed form, over the receiver to within 0.01% (test
    /// below). The light of a wall's parts along a crease, darker than the
    /// rest of the wall, then weighed too little: on the built-in Cornell
    /// box at `EPS` 1e-3 (unclustered, seeds 1-3) the links into the
    /// ceiling brought +0.02%, +0.32% and +0.35% against a ray-traced
    /// gather of the solution's own leaves (the green wall's links into
    /// the ceiling leaves along it +7.5% to +10.6%), now -0.23%, +0.07% and
    /// +0.10%: 0.25% less each, the rest the partly occluded links'
    /// visibility noise. Against the `EPS` 2.5e-5 solve (seeds 1-4) the leaves' rms
    /// error went from 3.64-4.04% to 3.38-3.79% at 1e-3 and from
    /// 2.26-2.58% to 2.18-2.51% at 6e-4, every surface's mean as near or
    /// nearer (the ceiling +0.29% -> +0.06% at 1e-3, seed 1), for 4% more
    /// solve time (one thread, medians of 7-9 interleaved; `plants-2k`
    /// the same). Taken over `r` also for the parts within one radius of
    /// `r` but not touching it, the leaves' rms came to 3.77% at 1e-3
    /// (seed 1; 3.79% touching only) for 11% more time.
    pub fn weight_between(&self, r: u32, e: u32) -> f64 {
        if self.touching(r, e) {
            let (er, ee) = (&self.elements[r as usize], &self.elements[e as usize]);
            triangle_to_polygon(&er.points, self.normal(r), &ee.points, self.normal(e), Quadrature::to_depth(0)).mean * self.coverage(e)
        } else {
            self.weight_to_element(self.centroid(r), self.normal(r), e)
        }
    }

    /// Whether the bounding boxes of elements `a` and `b` meet (to a
    /// millionth of the larger box's size).
    pub fn touching(&self, a: u32, b: u32) -> bool {
        let ((lo_a, hi_a), (lo_b, hi_b)) = (self.bounds(Node::Element(a)), self.bounds(Node::Element(b)));
        let tolerance = 1e-6 * (hi_a - lo_a).max(hi_b - lo_b).max_element();
        (lo_a - hi_b).max_element() <= tolerance && (lo_b - hi_a).max_element() <= tolerance
    }

    /// The centroid of element `e`.
    pub fn centroid(&self, e: u32) -> DVec3 {
        let p = &self.elements[e as usize].points;
        (p[0] + p[1] + p[2]) / 3.0
    }

    /// The radius of element `e` about its centroid: its farthest corner's
    /// distance.
    pub fn radius(&self, e: u32) -> f64 {
        let c = self.centroid(e);
        self.elements[e as usize].points.iter().map(|p| p.distance(c)).fold(0.0, f64::max)
    }

    /// Unit front normal of element `e` (its triangle's).
    pub fn normal(&self, e: u32) -> DVec3 {
        self.triangles[self.elements[e as usize].triangle as usize].normal
    }

    /// Diffuse reflectance of element `e` (its texture average where a
    /// texture applies).
    pub fn reflectance_of(&self, e: u32) -> [f64; 3] {
        let own = self.detail.as_ref().and_then(|d| d.average(e).reflectance);
        own.unwrap_or(self.reflectance[self.elements[e as usize].triangle as usize])
    }

    /// The source term of element `e`, W/m²: its emission plus its
    /// reflected direct light from the luminaires, `E + rho D`, plus, on a
    /// translucent face, the direct light its twin transmits, `tau D_twin`;
    /// the direct light, averaged over the whole element, divided by its
    /// exposure, as the links' light is ([`crate::exposure`]).
    pub fn source(&self, e: u32) -> [f64; 3] {
        let t = self.elements[e as usize].triangle as usize;
        let direct = |e: u32| self.direct.get(e as usize).copied().unwrap_or(0.0) / exposed(self.exposure(e));
        let rho = self.reflectance_of(e);
        let mut s = [0, 1, 2].map(|c| self.emission[t][c] + rho[c] * direct(e));
        if let Some((tau, twin)) = self.transmission_of(e) {
            (0..3).for_each(|c| s[c] += tau[c] * direct(twin));
        }
        s
    }

    /// Exposed fraction of element `e`'s area ([`crate::exposure`]).
    pub fn exposure(&self, e: u32) -> f64 {
        self.exposure.get(e as usize).copied().unwrap_or(1.0)
    }

    /// Creates the four children of `e` if it has none; returns the first.
    pub fn subdivide(&mut self, e: u32) -> u32 {
        let parent = self.elements[e as usize].clone();
        if !parent.is_leaf() {
            return parent.first_child;
        }
        let first = self.elements.len() as u32;
        let geometry = self.triangles[parent.triangle as usize];
        for corners in children(&parent.corners) {
            self.elements.push(Element {
                triangle: parent.triangle,
                parent: e,
                first_child: NONE,
                level: parent.level + 1,
                corners,
                points: geometry.element(&corners),
                area: parent.area / 4.0,
            });
            if let Some(detail) = &mut self.detail {
                detail.push(parent.triangle, &corners);
            }
        }
        self.elements[e as usize].first_child = first;
        first
    }
}

#[cfg(test)]
mod tests {
    use crate::test_scenes::FloorAndWall;
    use test_support::closed_form::perpendicular_rectangles;

    /// A unit floor (triangles 0-1) and a unit wall on its edge (2-3): the
    /// floor's factor to the wall summed from the weights between their
    /// triangles, against the closed form for perpendicular squares with
    /// a common edge (0.20004). Every pair touches, so each weight is taken
    /// over its receiver: within 0.1% (it is within 0.01%). From the
    /// receivers' centroids, as before, the sum misses 3.1% of the light
    /// the wall gives the floor, most of it next to the wall.
    #[test]
    fn touching_elements_weigh_each_other_over_the_whole_receiver() {
        let h = FloorAndWall::new(2.0).h;
        let (floor, wall) = ([0u32, 1], [2u32, 3]);
        let area: f64 = floor.iter().map(|&t| h.elements[t as usize].area).sum();
        let summed = |weight: &dyn Fn(u32, u32) -> f64| floor.iter().map(|&t| h.elements[t as usize].area * wall.iter().map(|&u| weight(t, u)).sum::<f64>()).sum::<f64>() / area;
        let exact = perpendicular_rectangles(1.0, 1.0, 1.0);
        let over_receiver = summed(&|t, u| h.weight_between(t, u));
        let from_centroid = summed(&|t, u| h.weight_to_element(h.centroid(t), h.normal(t), u));
        assert!(floor.iter().all(|&t| wall.iter().all(|&u| h.touching(t, u))));
        assert!((over_receiver / exact - 1.0).abs() < 1e-3, "{over_receiver} against {exact}");
        assert!(from_centroid / exact - 1.0 < -0.02, "{from_centroid} against {exact}");
    }
}
