//! Nodes of the link hierarchy: elements (input triangles and their 1:4
//! subdivisions) and, with clustering, the clusters above them. Links join
//! two nodes; this module answers what links need to know of a node
//! whatever its kind: area, bounds, reflectance, children, and random
//! points on its surfaces.

use crate::cluster_tree::ClusterTree;
use crate::elements::Hierarchy;
use glam::DVec3;
use radiometry::sampling::{square_to_triangle, stratified_point, Stream};
use schemas::solution::Node;

/// A point on a node's surfaces with its front normal and input triangle.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Position, mesh frame.
    pub point: DVec3,
    /// Unit front normal.
    pub normal: DVec3,
    /// Input triangle (rays skip it).
    pub triangle: u32,
}

impl Hierarchy {
    /// Dense index of a node: clusters first, then elements.
    pub fn flat(&self, node: Node) -> usize {
        match node {
            Node::Cluster(c) => c as usize,
            Node::Element(e) => self.cluster_count() + e as usize,
        }
    }

    /// The node with dense index `i` (the inverse of [`Hierarchy::flat`]).
    pub fn node(&self, i: usize) -> Node {
        let clusters = self.cluster_count();
        if i < clusters {
            Node::Cluster(i as u32)
        } else {
            Node::Element((i - clusters) as u32)
        }
    }

    /// Number of clusters (0 without clustering).
    pub fn cluster_count(&self) -> usize {
        self.clusters.as_ref().map_or(0, ClusterTree::len)
    }

    /// Surface area of a node, m²: of an element, its opaque area (its
    /// area times its coverage, [`crate::detail`]).
    pub fn area(&self, node: Node) -> f64 {
        match node {
            Node::Element(e) => self.elements[e as usize].area * self.coverage(e),
            Node::Cluster(c) => self.tree().area[c as usize],
        }
    }

    /// Mean diffuse reflectance of a node's surfaces.
    pub fn node_reflectance(&self, node: Node) -> [f64; 3] {
        match node {
            Node::Element(e) => self.reflectance_of(e),
            Node::Cluster(c) => self.tree().reflectance[c as usize],
        }
    }

    /// Axis-aligned bounds of a node.
    pub fn bounds(&self, node: Node) -> (DVec3, DVec3) {
        match node {
            Node::Element(e) => {
                let p = &self.elements[e as usize].points;
                (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
            }
            Node::Cluster(c) => {
                let n = &self.tree().clusters.nodes[c as usize];
                (DVec3::from(n.bounds_min.map(f64::from)), DVec3::from(n.bounds_max.map(f64::from)))
            }
        }
    }

    /// The cluster tree; only called on cluster nodes, which exist only
    /// with one.
    fn tree(&self) -> &ClusterTree {
        self.clusters.as_ref().expect("cluster nodes exist only with a cluster tree")
    }

    /// Whether splitting `node` is allowed: clusters always split (into
    /// clusters or triangles), elements down to `min_area`.
    pub fn can_split(&self, node: Node, min_area: f64) -> bool {
        match node {
            Node::Cluster(_) => true,
            Node::Element(e) => self.elements[e as usize].area / 4.0 >= min_area,
        }
    }

    /// Makes sure `node`'s children exist (subdividing an element).
    pub fn ensure_children(&mut self, node: Node) {
        if let Node::Element(e) = node {
            self.subdivide(e);
        }
    }

    /// The children of a node whose children exist: child clusters, the
    /// input triangles of a leaf cluster, or an element's four children.
    pub fn children(&self, node: Node) -> Vec<Node> {
        match node {
            Node::Element(e) => {
                let first = self.elements[e as usize].first_child;
                (first..first + 4).map(Node::Element).collect()
            }
            Node::Cluster(c) => {
                let tree = self.tree();
                let n = &tree.clusters.nodes[c as usize];
                if n.is_leaf() {
                    tree.clusters.triangles_of(c).iter().map(|&t| Node::Element(t)).collect()
                } else {
                    (n.first_child..n.first_child + n.child_count).map(Node::Cluster).collect()
                }
            }
        }
    }

    /// The children of a node, if they exist (an element not yet
    /// subdivided has none).
    pub fn children_if_any(&self, node: Node) -> Vec<Node> {
        match node {
            Node::Element(e) if self.elements[e as usize].is_leaf() => Vec::new(),
            _ => self.children(node),
        }
    }

    /// The parent of a node in the whole hierarchy: an input triangle's is
    /// its leaf cluster.
    pub fn parent(&self, node: Node) -> Option<Node> {
        match node {
            Node::Element(e) => {
                let element = &self.elements[e as usize];
                if element.parent != schemas::solution::NONE {
                    Some(Node::Element(element.parent))
                } else {
                    self.clusters.as_ref().map(|t| Node::Cluster(t.leaf_of_triangle[element.triangle as usize]))
                }
            }
            Node::Cluster(c) => {
                let parent = self.tree().clusters.nodes[c as usize].parent;
                (parent != schemas::solution::NONE).then_some(Node::Cluster(parent))
            }
        }
    }

    /// The input triangles below a node: a cluster's, or an element's own.
    pub fn triangles_below(&self, node: Node) -> &[u32] {
        match node {
            Node::Element(e) => std::slice::from_ref(&self.elements[e as usize].triangle),
            Node::Cluster(c) => self.tree().clusters.triangles_of(c),
        }
    }

    /// Opens element parts into their four children, those that
    /// `priority` ranks highest first (`None`: not to open; a leaf never
    /// opens), round by round while they number at most `most`; `child`
    /// makes a part of a child element from its parent part.
    pub fn open_parts<P>(&self, parts: &mut Vec<P>, most: usize, element: impl Fn(&P) -> u32, priority: impl Fn(&P) -> Option<f64>, mut child: impl FnMut(u32, &P) -> P) {
        loop {
            let mut open: Vec<(usize, f64)> = parts.iter().enumerate().filter(|(_, p)| !self.elements[element(p) as usize].is_leaf()).filter_map(|(k, p)| Some((k, priority(p)?))).collect();
            if open.is_empty() || parts.len() + 3 > most {
                return;
            }
            open.sort_by(|a, b| b.1.total_cmp(&a.1));
            open.truncate((most - parts.len()) / 3);
            open.sort_unstable_by_key(|o| o.0);
            for &(k, _) in open.iter().rev() {
                let first = self.elements[element(&parts[k]) as usize].first_child;
                let children: Vec<P> = (first..first + 4).map(|c| child(c, &parts[k])).collect();
                parts.splice(k..k + 1, children);
            }
        }
    }

    /// A node opened level by level (clusters down to their input
    /// triangles, elements to their children) while its parts are at most
    /// `most`.
    pub fn parts(&self, node: Node, most: usize) -> Vec<Node> {
        // Two buffers, swapped level by level: this runs for every link of
        // the last solve, and a list per node opened cost a twentieth of
        // the solve.
        let (mut parts, mut next) = (vec![node], Vec::with_capacity(most + 4));
        loop {
            next.clear();
            for &p in &parts {
                match p {
                    Node::Element(e) if !self.elements[e as usize].is_leaf() => {
                        let first = self.elements[e as usize].first_child;
                        next.extend((first..first + 4).map(Node::Element));
                    }
                    Node::Element(_) => next.push(p),
                    Node::Cluster(_) => next.extend(self.children(p)),
                }
                if next.len() > most {
                    return parts;
                }
            }
            if next.len() == parts.len() {
                return parts;
            }
            std::mem::swap(&mut parts, &mut next);
        }
    }

    /// The `k`-th of `n` random points on a node, uniform by area: on an
    /// element stratified over its triangle ([`stratified_point`]); on a
    /// cluster in the `k`-th of `n` equal shares of its area, its triangles
    /// laid end to end in the tree's order ([`ClusterTree::triangle_at`]),
    /// which keeps nearby triangles together, and jittered across.
    ///
    /// Stratified, the `n` points of a cluster visit each part of it in
    /// proportion to its area. Drawn independently, 16 points over the
    /// cluster that holds the Cornell box's floor and short block left the
    /// form factors of the links into it between 0.25 and 1.95 times their
    /// converged values over seeds 1-8 (the kernel is heavy-tailed over a
    /// cluster: a block face near the sender, the floor far).
    pub fn sample(&self, node: Node, k: usize, n: usize, stream: &mut Stream) -> SurfacePoint {
        match node {
            Node::Element(e) => {
                let element = &self.elements[e as usize];
                SurfacePoint {
                    point: stratified_point(&element.points, k, n, stream),
                    normal: self.triangles[element.triangle as usize].normal,
                    triangle: element.triangle,
                }
            }
            Node::Cluster(c) => {
                let (t, along) = self.tree().triangle_at(c, (k as f64 + stream.next_f64()) / n as f64);
                let g = &self.triangles[t as usize];
                let b = square_to_triangle(along, stream.next_f64());
                SurfacePoint { point: g.corners[0] * b[0] + g.corners[1] * b[1] + g.corners[2] * b[2], normal: g.normal, triangle: t }
            }
        }
    }
}

/// A 64-bit key of a node, for seeding random streams.
pub fn key(node: Node) -> u64 {
    match node {
        Node::Element(e) => u64::from(e) << 1,
        Node::Cluster(c) => (u64::from(c) << 1) | 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use test_support::meshes::{manifest, material, quads};

    /// A 1 x 1 quad (triangles 0, 1 of 0.5 m²) and a 2 x 1 quad beside it
    /// (triangles 2, 3 of 1 m²) in one cluster: `n` stratified points give
    /// each triangle exactly `n` times its share of the area, and lie on
    /// the triangle they name.
    #[test]
    fn a_clusters_points_visit_its_triangles_in_proportion_to_their_area() {
        let mesh = quads(&[
            (dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), 0, 0),
            (dvec3(1.0, 0.0, 0.0), dvec3(2.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), 0, 0),
        ]);
        let h = Hierarchy::new(&mesh, &manifest(1, vec![material([0.5; 3], [0.0; 3])]), Some(test_support::artifacts::clusters_over(&mesh)), None);
        for (n, want) in [(6, [1, 1, 2, 2]), (12, [2, 2, 4, 4])] {
            for seed in 0..20 {
                let mut stream = Stream::new(seed, 0, 0);
                let mut count = [0; 4];
                for k in 0..n {
                    let p = h.sample(Node::Cluster(0), k, n, &mut stream);
                    count[p.triangle as usize] += 1;
                    let x0 = if p.triangle < 2 { 0.0 } else { 1.0 };
                    let width = if p.triangle < 2 { 1.0 } else { 2.0 };
                    let (u, v) = ((p.point.x - x0) / width, p.point.y);
                    // Triangle 2t is below the quad's diagonal, 2t + 1 above.
                    let below = u >= v;
                    assert!(p.point.z == 0.0 && (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v), "{p:?}");
                    assert_eq!(below, p.triangle.is_multiple_of(2), "{p:?} is on triangle {}", p.triangle);
                }
                assert_eq!(count, want, "n = {n}, seed {seed}");
            }
        }
    }
}
