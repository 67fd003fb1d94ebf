//! The radiosity solution artifact (`solution.exr`), written by
//! `hierarchical-solve`: the element hierarchy with radiosity per element,
//! the radiosity of every cluster (when solved with the cluster hierarchy
//! of `clusters.exr`), and every link of every level, between elements or
//! clusters (the final gather reads them), and the slope of the radiosity
//! across the leaves where the solve measured one. Other solvers
//! (`gpu-shoot`, `photon-trace`) write the same schema with no clusters,
//! links or slopes.

use crate::error::{Error, Result};
use crate::exr_io::{check_finite, check_forest, read_exr, write_exr, Channel, ExrArtifact, Layer};
use crate::header::{Header, Input, Schema};
use std::path::Path;

/// Marks "no element" in `parent` and `first_child`.
pub const NONE: u32 = u32::MAX;

/// One element: an input triangle, or a sub-triangle of it from regular
/// 1:4 subdivision (children: three corner triangles, then the middle one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// The input triangle this element lies on.
    pub triangle: u32,
    /// Parent element, or [`NONE`] for an input triangle.
    pub parent: u32,
    /// First of four consecutive children, or [`NONE`] for a leaf.
    pub first_child: u32,
    /// Subdivision depth, 0 for input triangles.
    pub level: u32,
    /// Barycentric `(u, v)` of each corner in the input triangle: the point
    /// is `(1-u-v) P0 + u P1 + v P2`. Dyadic fractions, exact in f32.
    pub corners: [[f32; 2]; 3],
    /// Area, m², of the element's surface open to the scene: hierarchical-
    /// solve leaves out the part buried inside a solid (a floor under a
    /// block), so a leaf crossing the block's footprint has less than its
    /// geometric area and one wholly under it none; inner elements the sum
    /// of their children's.
    pub area: f32,
    /// Radiosity B (exitance: emitted plus reflected), W/m², RGB, of the
    /// element's open part; for inner elements the area-weighted mean of
    /// their children.
    pub radiosity: [f32; 3],
}

impl Element {
    /// The root element of input triangle `triangle` (area `area`, m²):
    /// the whole triangle, no parent, no children yet, radiosity
    /// `radiosity`.
    pub fn root(triangle: u32, area: f32, radiosity: [f32; 3]) -> Self {
        Element { triangle, parent: NONE, first_child: NONE, level: 0, corners: [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], area, radiosity }
    }

    /// Whether the element has no children.
    pub fn is_leaf(&self) -> bool {
        self.first_child == NONE
    }
}

/// One end of a link: an element of the solution, or a cluster of the
/// cluster hierarchy it was solved with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Node {
    /// Index into [`Solution::elements`].
    Element(u32),
    /// Index into the cluster hierarchy (and [`Solution::clusters`]).
    Cluster(u32),
}

impl Node {
    fn index(self) -> u32 {
        match self {
            Node::Element(i) | Node::Cluster(i) => i,
        }
    }

    fn is_cluster(self) -> u32 {
        matches!(self, Node::Cluster(_)) as u32
    }

    /// The `end` (`receiver` or `sender`) of link `link` as stored: its
    /// index and its `_is_cluster` flag, which must be 0 or 1.
    fn read(path: &Path, link: usize, end: &str, index: u32, is_cluster: u32) -> Result<Self> {
        match is_cluster {
            0 => Ok(Node::Element(index)),
            1 => Ok(Node::Cluster(index)),
            other => Err(Error::invalid(path, None, format!("link {link}: field {end}_is_cluster is {other}, not 0 or 1"))),
        }
    }
}

/// The radiosity of one cluster, as the solve used it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClusterRadiosity {
    /// Total surface area in the cluster, m².
    pub area: f32,
    /// Area-weighted mean radiosity of the cluster's surfaces, W/m², RGB.
    pub radiosity: [f32; 3],
}

/// One link: light gathered by `receiver` from `sender`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Link {
    /// Receiving element or cluster.
    pub receiver: Node,
    /// Sending element or cluster.
    pub sender: Node,
    /// Unoccluded form factor F_rs (fraction of the energy leaving the
    /// receiver that would reach the sender; by reciprocity the receiver's
    /// irradiance is F_rs B_s).
    pub form_factor: f32,
    /// Fraction of receiver-sender rays not blocked, in [0, 1].
    pub visibility: f32,
    /// Unoccluded irradiance F_rs B_s at the receiver, W/m², RGB, where B_s
    /// is what the last solve sent through the link: the sender's leaves
    /// weighted by the kernel seen from the receiver, not their area mean
    /// (so `E_u / F` is that kernel-weighted radiosity, which the full
    /// gather resamples).
    pub unoccluded_irradiance: [f32; 3],
    /// Distance from the receiver to the nearest occluder found by the
    /// visibility rays, m; +inf when no ray was blocked.
    pub occluder_distance: f32,
}

/// The slope of a leaf's radiosity along its surface, where the solve
/// measured one (hierarchical-solve: the direct light of emitters across a
/// leaf in a penumbra). Readers draw the leaf as a plane through its mean
/// with this gradient (blended as they document).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeafSlope {
    /// The leaf element it belongs to.
    pub element: u32,
    /// Gradient of the radiosity along the surface, W/m² per m, world
    /// space: `gradient[c]` is channel c's (R, G, B) gradient vector (x, y, z).
    pub gradient: [[f32; 3]; 3],
}

/// Names of the `slope` layer's gradient channels: `[c][axis]` is channel
/// c's (R, G, B) derivative along axis x, y, z.
const SLOPE_CHANNELS: [[&str; 3]; 3] = [
    ["dB.R/dx", "dB.R/dy", "dB.R/dz"],
    ["dB.G/dx", "dB.G/dy", "dB.G/dz"],
    ["dB.B/dx", "dB.B/dy", "dB.B/dz"],
];

/// The solution: element hierarchy, cluster radiosities, links and leaf
/// slopes.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Header with provenance.
    pub header: Header,
    /// Elements; input triangle `t` is element `t`, children follow.
    pub elements: Vec<Element>,
    /// Per cluster of the hierarchy the solve used; empty without
    /// clustering.
    pub clusters: Vec<ClusterRadiosity>,
    /// Links, sorted by receiver then sender.
    pub links: Vec<Link>,
    /// Per-leaf slopes, ascending by element, at most one per leaf; empty
    /// where the producer measured none (every producer but
    /// hierarchical-solve).
    pub slopes: Vec<LeafSlope>,
}

impl Schema for Solution {
    const NAME: &'static str = "solution";
    const VERSION: u32 = 1;
}

fn column<T: Copy, U>(rows: &[T], f: impl Fn(&T) -> U) -> Vec<U> {
    rows.iter().map(f).collect()
}

impl Solution {
    /// Writes `solution.exr`: layers `element`, `cluster`, `link` and
    /// `slope` (tables; `cluster`, `link` and `slope` may hold no record).
    pub fn write(&self, path: &Path) -> Result<()> {
        let e = &self.elements;
        let corner = |k: usize, axis: usize| column(e, move |x: &Element| x.corners[k][axis]);
        let element = Layer::table(
            "element",
            e.len(),
            vec![
                Channel::u32("triangle", "input triangle index", column(e, |x| x.triangle)),
                Channel::u32("parent", "parent element, 4294967295 = none", column(e, |x| x.parent)),
                Channel::u32("first_child", "first of 4 children, 4294967295 = leaf", column(e, |x| x.first_child)),
                Channel::u32("level", "subdivision depth", column(e, |x| x.level)),
                Channel::f32("c0.u", "corner 0 barycentric u", corner(0, 0)),
                Channel::f32("c0.v", "corner 0 barycentric v", corner(0, 1)),
                Channel::f32("c1.u", "corner 1 barycentric u", corner(1, 0)),
                Channel::f32("c1.v", "corner 1 barycentric v", corner(1, 1)),
                Channel::f32("c2.u", "corner 2 barycentric u", corner(2, 0)),
                Channel::f32("c2.v", "corner 2 barycentric v", corner(2, 1)),
                Channel::f32("area", "area, m^2", column(e, |x| x.area)),
                Channel::f32("B.R", "radiosity, W/m^2", column(e, |x| x.radiosity[0])),
                Channel::f32("B.G", "radiosity, W/m^2", column(e, |x| x.radiosity[1])),
                Channel::f32("B.B", "radiosity, W/m^2", column(e, |x| x.radiosity[2])),
            ],
        );
        let l = &self.links;
        let link = Layer::table(
            "link",
            l.len(),
            vec![
                Channel::u32("receiver", "receiving element or cluster", column(l, |x| x.receiver.index())),
                Channel::u32("receiver_is_cluster", "1: receiver indexes the clusters", column(l, |x| x.receiver.is_cluster())),
                Channel::u32("sender", "sending element or cluster", column(l, |x| x.sender.index())),
                Channel::u32("sender_is_cluster", "1: sender indexes the clusters", column(l, |x| x.sender.is_cluster())),
                Channel::f32("F", "unoccluded form factor receiver->sender", column(l, |x| x.form_factor)),
                Channel::f32("V", "visible fraction of rays", column(l, |x| x.visibility)),
                Channel::f32("Eu.R", "unoccluded irradiance F*B_sender, W/m^2", column(l, |x| x.unoccluded_irradiance[0])),
                Channel::f32("Eu.G", "unoccluded irradiance F*B_sender, W/m^2", column(l, |x| x.unoccluded_irradiance[1])),
                Channel::f32("Eu.B", "unoccluded irradiance F*B_sender, W/m^2", column(l, |x| x.unoccluded_irradiance[2])),
                Channel::f32("occluder_distance", "receiver to nearest occluder, m (inf = none)", column(l, |x| x.occluder_distance)),
            ],
        );
        let c = &self.clusters;
        let cluster = Layer::table(
            "cluster",
            c.len(),
            vec![
                Channel::f32("area", "surface area in the cluster, m^2", column(c, |x| x.area)),
                Channel::f32("B.R", "area-weighted mean radiosity, W/m^2", column(c, |x| x.radiosity[0])),
                Channel::f32("B.G", "area-weighted mean radiosity, W/m^2", column(c, |x| x.radiosity[1])),
                Channel::f32("B.B", "area-weighted mean radiosity, W/m^2", column(c, |x| x.radiosity[2])),
            ],
        );
        let sl = &self.slopes;
        let mut slope_channels = vec![Channel::u32("element", "leaf element index", column(sl, |x| x.element))];
        for (c, (names, colour)) in SLOPE_CHANNELS.iter().zip(["R", "G", "B"]).enumerate() {
            for (axis, (name, along)) in names.iter().zip(["x", "y", "z"]).enumerate() {
                let meaning = format!("d(radiosity {colour})/d{along} along the surface, W/m^2 per m");
                slope_channels.push(Channel::f32(name, &meaning, column(sl, |x| x.gradient[c][axis])));
            }
        }
        let slope = Layer::table("slope", sl.len(), slope_channels);
        write_exr(path, &ExrArtifact { header: self.header.clone(), layers: vec![element, cluster, link, slope] })
    }

    /// Reads `solution.exr` and checks its structure (see
    /// [`Solution::check_elements`], [`Solution::check_link`] and
    /// [`Solution::check_slope`]), so that a stage may walk and index it
    /// without further checks. A file with no `slope` layer (written before
    /// there was one) reads with no slopes.
    pub fn read(path: &Path) -> Result<(Solution, Input)> {
        let (artifact, input) = read_exr::<Solution>(path)?;
        let el = artifact.layer(path, "element")?;
        check_finite(path, el, "element", &["c0.u", "c0.v", "c1.u", "c1.v", "c2.u", "c2.v", "area", "B.R", "B.G", "B.B"])?;
        let u = |name: &str| el.u32s(path, name);
        let f = |name: &str| el.f32s(path, name);
        let (triangle, parent, first_child, level) = (u("triangle")?, u("parent")?, u("first_child")?, u("level")?);
        let c = [f("c0.u")?, f("c0.v")?, f("c1.u")?, f("c1.v")?, f("c2.u")?, f("c2.v")?];
        let (area, b) = (f("area")?, [f("B.R")?, f("B.G")?, f("B.B")?]);
        let n = el.len();
        let elements: Vec<Element> = (0..n)
            .map(|i| Element {
                triangle: triangle[i],
                parent: parent[i],
                first_child: first_child[i],
                level: level[i],
                corners: [[c[0][i], c[1][i]], [c[2][i], c[3][i]], [c[4][i], c[5][i]]],
                area: area[i],
                radiosity: [b[0][i], b[1][i], b[2][i]],
            })
            .collect();
        Solution::check_elements(path, &elements)?;
        let cl = artifact.layer(path, "cluster")?;
        check_finite(path, cl, "cluster", &["area", "B.R", "B.G", "B.B"])?;
        let (cluster_area, cb) = (cl.f32s(path, "area")?, [cl.f32s(path, "B.R")?, cl.f32s(path, "B.G")?, cl.f32s(path, "B.B")?]);
        let clusters: Vec<ClusterRadiosity> =
            (0..cl.len()).map(|i| ClusterRadiosity { area: cluster_area[i], radiosity: [cb[0][i], cb[1][i], cb[2][i]] }).collect();
        let li = artifact.layer(path, "link")?;
        check_finite(path, li, "link", &["F", "V", "Eu.R", "Eu.G", "Eu.B"])?;
        let (receiver, sender) = (li.u32s(path, "receiver")?, li.u32s(path, "sender")?);
        let (receiver_kind, sender_kind) = (li.u32s(path, "receiver_is_cluster")?, li.u32s(path, "sender_is_cluster")?);
        let (ff, vis, dist) = (li.f32s(path, "F")?, li.f32s(path, "V")?, li.f32s(path, "occluder_distance")?);
        let eu = [li.f32s(path, "Eu.R")?, li.f32s(path, "Eu.G")?, li.f32s(path, "Eu.B")?];
        let mut links = Vec::with_capacity(li.len());
        for i in 0..li.len() {
            let (r, s) = (Node::read(path, i, "receiver", receiver[i], receiver_kind[i])?, Node::read(path, i, "sender", sender[i], sender_kind[i])?);
            let link = Link {
                receiver: r,
                sender: s,
                form_factor: ff[i],
                visibility: vis[i],
                unoccluded_irradiance: [eu[0][i], eu[1][i], eu[2][i]],
                occluder_distance: dist[i],
            };
            Solution::check_link(path, i, &link, n, clusters.len())?;
            links.push(link);
        }
        let slopes = match artifact.optional_layer("slope") {
            Some(layer) => Solution::read_slopes(path, layer, &elements)?,
            None => Vec::new(),
        };
        Ok((Solution { header: artifact.header, elements, clusters, links, slopes }, input))
    }

    /// The rows of the `slope` layer, each checked (finite gradients, then
    /// [`Solution::check_slope`]) against `elements`.
    fn read_slopes(path: &Path, layer: &Layer, elements: &[Element]) -> Result<Vec<LeafSlope>> {
        check_finite(path, layer, "slope", SLOPE_CHANNELS.as_flattened())?;
        let element = layer.u32s(path, "element")?;
        let mut g = Vec::with_capacity(9);
        for name in SLOPE_CHANNELS.as_flattened() {
            g.push(layer.f32s(path, name)?);
        }
        let mut slopes: Vec<LeafSlope> = Vec::with_capacity(layer.len());
        for i in 0..layer.len() {
            let slope = LeafSlope { element: element[i], gradient: std::array::from_fn(|c| std::array::from_fn(|axis| g[3 * c + axis][i])) };
            Solution::check_slope(path, i, &slope, slopes.last(), elements)?;
            slopes.push(slope);
        }
        Ok(slopes)
    }

    /// The invariants of the element table, checked on read; a file that
    /// breaks one is refused with the element and the field it concerns:
    ///
    /// - the input triangles' elements come first: element `t < roots` has
    ///   `parent` [`NONE`], `triangle` `t` and `level` 0, and no later
    ///   element is a root;
    /// - the elements form a forest below them: each inner element's four
    ///   children lie inside the table, no cycle, every element reached
    ///   exactly once, each child naming its parent (see [`check_forest`]);
    /// - a child lies on its parent's triangle, one level deeper;
    /// - corners, areas and radiosities are finite (checked with the
    ///   channels), areas not negative.
    fn check_elements(path: &Path, elements: &[Element]) -> Result<()> {
        let invalid = |message: String| Err(Error::invalid(path, None, message));
        let roots = elements.iter().position(|e| e.parent != NONE).unwrap_or(elements.len());
        for (i, e) in elements.iter().enumerate() {
            if i < roots && (e.triangle as usize != i || e.level != 0) {
                return invalid(format!("element {i}: a root must lie on triangle {i} at level 0, not triangle {} level {}", e.triangle, e.level));
            }
            if e.area < 0.0 {
                return invalid(format!("element {i}: field area is {}", e.area));
            }
        }
        let children = |i: usize| if elements[i].is_leaf() { (NONE, 0) } else { (elements[i].first_child, 4) };
        check_forest(path, "element", elements.len(), 0..roots, children, |i| elements[i].parent)?;
        for (i, e) in elements.iter().enumerate().skip(roots) {
            let parent = &elements[e.parent as usize];
            if e.triangle != parent.triangle || parent.level.checked_add(1) != Some(e.level) {
                return invalid(format!(
                    "element {i}: on triangle {} at level {}, but its parent element {} is on triangle {} at level {} (fields triangle, level)",
                    e.triangle, e.level, e.parent, parent.triangle, parent.level
                ));
            }
        }
        Ok(())
    }

    /// The invariants of link `i`, checked on read: both ends name an
    /// element (of `elements`) or a cluster (of `clusters`) that exists,
    /// and the occluder distance is not NaN (+inf: no occluder; the other
    /// numbers are checked finite with their channels).
    fn check_link(path: &Path, i: usize, link: &Link, elements: usize, clusters: usize) -> Result<()> {
        for (end, node) in [("receiver", link.receiver), ("sender", link.sender)] {
            let (kind, index, count) = match node {
                Node::Element(e) => ("element", e, elements),
                Node::Cluster(c) => ("cluster", c, clusters),
            };
            if index as usize >= count {
                return Err(Error::invalid(path, None, format!("link {i}: field {end} names {kind} {index}, but the solution has {count}")));
            }
        }
        match link.occluder_distance.is_nan() {
            true => Err(Error::invalid(path, None, format!("link {i}: field occluder_distance is NaN"))),
            false => Ok(()),
        }
    }

    /// The invariants of slope row `i`, checked on read: it names an
    /// element of `elements` that is a leaf, and a later one than the row
    /// before (`previous`), so rows ascend by element, at most one per
    /// leaf (the gradients are checked finite with their channels).
    fn check_slope(path: &Path, i: usize, slope: &LeafSlope, previous: Option<&LeafSlope>, elements: &[Element]) -> Result<()> {
        let invalid = |message: String| Err(Error::invalid(path, None, message));
        let e = slope.element;
        let Some(element) = elements.get(e as usize) else {
            return invalid(format!("slope {i}: field element names element {e}, but the solution has {}", elements.len()));
        };
        if !element.is_leaf() {
            return invalid(format!("slope {i}: field element names element {e}, which is not a leaf (its first_child is {})", element.first_child));
        }
        match previous {
            Some(p) if p.element >= e => invalid(format!(
                "slope {i}: field element is {e}, but slope {} names element {} (rows must ascend by element, one per leaf)",
                i - 1,
                p.element
            )),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::header::Provenance;

    fn element(triangle: u32, parent: u32, first_child: u32, level: u32) -> Element {
        Element { triangle, parent, first_child, level, corners: [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], area: 0.5, radiosity: [1.0; 3] }
    }

    /// Two input triangles; the second split into elements 2..6; slopes on
    /// leaves 0 and 3.
    fn solution() -> Solution {
        let mut elements = vec![element(0, NONE, NONE, 0), element(1, NONE, 2, 0)];
        elements.extend((0..4).map(|_| element(1, 1, NONE, 1)));
        let link = Link {
            receiver: Node::Element(2),
            sender: Node::Cluster(0),
            form_factor: 0.25,
            visibility: 1.0,
            unoccluded_irradiance: [0.5; 3],
            occluder_distance: f32::INFINITY,
        };
        Solution {
            header: Solution::header(Provenance::in_memory("test")),
            elements,
            clusters: vec![ClusterRadiosity { area: 1.0, radiosity: [2.0; 3] }],
            links: vec![link],
            slopes: vec![
                LeafSlope { element: 0, gradient: [[0.5, -0.25, 0.0], [1e-7, 3.0e5, -0.0], [-2.5, 0.125, 7.0]] },
                LeafSlope { element: 3, gradient: [[-1.0, 0.0, 2.0], [0.0, 0.0, 0.0], [1.5, -1.5, 1.0 / 3.0]] },
            ],
        }
    }

    /// The outcome of writing `solution` with the writer and reading it
    /// back; an error message must name the file.
    fn round_trip(name: &str, solution: &Solution) -> Result<Solution, String> {
        let path = std::env::temp_dir().join(format!("solution-{name}-{}.exr", std::process::id()));
        solution.write(&path).unwrap();
        let back = Solution::read(&path).map(|(s, _)| s).map_err(|e| e.to_string());
        std::fs::remove_file(&path).unwrap();
        if let Err(message) = &back {
            assert!(message.starts_with(&path.display().to_string()), "{message}");
        }
        back
    }

    #[test]
    fn a_valid_solution_round_trips() {
        assert_eq!(round_trip("valid", &solution()).unwrap(), solution());
    }

    #[test]
    fn slopes_round_trip_exactly_and_an_empty_slope_table_reads_empty() {
        let solution = solution();
        assert_eq!(solution.slopes.len(), 2);
        assert_eq!(round_trip("slopes", &solution).unwrap().slopes, solution.slopes);
        let none = Solution { slopes: Vec::new(), ..solution };
        assert_eq!(round_trip("no-slopes", &none).unwrap(), none);
    }

    #[test]
    fn a_file_without_a_slope_layer_reads_with_no_slopes() {
        let path = std::env::temp_dir().join(format!("solution-old-{}.exr", std::process::id()));
        solution().write(&path).unwrap();
        let (mut artifact, _) = read_exr::<Solution>(&path).unwrap();
        artifact.layers.retain(|l| l.name != "slope");
        assert_eq!(artifact.layers.len(), 3);
        write_exr(&path, &artifact).unwrap();
        let back = Solution::read(&path).map(|(s, _)| s);
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back.unwrap(), Solution { slopes: Vec::new(), ..solution() });
    }

    /// Asserts that `solution` after `edit` is refused with a message
    /// naming the file (checked by [`round_trip`]) and ending in `expected`.
    fn assert_refused(name: &str, edit: impl FnOnce(&mut Solution), expected: &str) {
        let mut edited = solution();
        edit(&mut edited);
        let message = round_trip(name, &edited).unwrap_err();
        assert!(message.ends_with(&format!(": {expected}")), "{message}");
    }

    #[test]
    fn a_cyclic_element_tree_is_refused() {
        let cycle = "element 0: reached twice from the root, through element 3 (a cycle or a shared child; field first_child)";
        assert_refused("cycle", |s| s.elements[3].first_child = 0, cycle);
    }

    #[test]
    fn children_past_the_end_and_children_on_another_triangle_are_refused() {
        let past = "element 1: children 4..8 run past the end of the table of 6 (field first_child)";
        assert_refused("past", |s| s.elements[1].first_child = 4, past);
        let moved = "element 4: on triangle 0 at level 1, but its parent element 1 is on triangle 1 at level 0 (fields triangle, level)";
        assert_refused("moved", |s| s.elements[4].triangle = 0, moved);
    }

    #[test]
    fn a_link_to_a_missing_element_or_cluster_is_refused() {
        let element = "link 0: field receiver names element 6, but the solution has 6";
        assert_refused("element", |s| s.links[0].receiver = Node::Element(6), element);
        assert_refused("cluster", |s| s.links[0].sender = Node::Cluster(1), "link 0: field sender names cluster 1, but the solution has 1");
    }

    #[test]
    fn a_slope_on_a_missing_or_inner_element_is_refused() {
        assert_refused("slope-past", |s| s.slopes[1].element = 6, "slope 1: field element names element 6, but the solution has 6");
        let inner = "slope 1: field element names element 1, which is not a leaf (its first_child is 2)";
        assert_refused("slope-inner", |s| s.slopes[1].element = 1, inner);
    }

    #[test]
    fn slopes_out_of_order_or_twice_for_one_leaf_are_refused() {
        let twice = "slope 1: field element is 0, but slope 0 names element 0 (rows must ascend by element, one per leaf)";
        assert_refused("slope-twice", |s| s.slopes[1].element = 0, twice);
        let descending = "slope 1: field element is 3, but slope 0 names element 4 (rows must ascend by element, one per leaf)";
        assert_refused("slope-descending", |s| s.slopes[0].element = 4, descending);
    }

    #[test]
    fn a_non_finite_slope_is_refused() {
        assert_refused("slope-nan", |s| s.slopes[1].gradient[2][1] = f32::NAN, "slope 1: field dB.B/dy is NaN");
        assert_refused("slope-inf", |s| s.slopes[0].gradient[0][2] = f32::NEG_INFINITY, "slope 0: field dB.R/dz is -inf");
    }
}
