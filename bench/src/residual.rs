//! A solution against one bounce of a radiosity field, ray-traced apart
//! from the solvers: what `bench-residual` measures.
//!
//! Each leaf `i` of the solution that does not emit gets
//!
//! ```text
//! B_i' = rho_i H_i,   H_i = mean over points x of the leaf of
//!        integral over the hemisphere of B(y(x, w)) cos(w) / pi dw       (cosine-distributed rays)
//!      + sum over emitting triangles e of integral over e of B(y) G(x, y) v(x, y) dA_y   (points on e, shadow rays)
//! ```
//!
//! with `B` the field's radiosity at the point `y` a ray meets (the leaf of
//! the field holding it; 0 on a back face), `G = cos cos / (pi d^2)` and
//! `v` the visibility; a ray meeting an emitter is left to the second
//! term, which samples the emitters directly (small and bright, they make
//! the first term's noise). A point whose rays mostly meet back faces
//! lies inside a solid (a floor under a block) and is left out, as the
//! solvers leave out buried area.
//!
//! With the solution as its own field, `B_i / B_i' - 1` is the residual of
//! the radiosity equation over the solution's own leaves, the transport
//! computed here, not by the solver's quadratures, part weights and
//! visibility estimates: how far what its links bring a leaf is from what
//! the leaves they join send it. With a finer solve as the field, it is
//! the leaf's error against one bounce of that solve.
//!
//! Per link ([`Gather::link_fluxes`]): each ray's light is credited to the link
//! that carries it, the one between an ancestor of the receiving leaf
//! (itself included, then its input triangle's clusters) and an ancestor
//! of the leaf the ray meets, against the link's own flux, `A_r V F B_sent`
//! (links into clusters, whose light the solver spreads over their
//! triangles by weights it does not write, are left out). On the built-in
//! Cornell box this found the crease bias of the sender parts' weights
//! (README, hierarchical-solve).
//!
//! Plain scenes only: a material with a texture, alpha or normal map,
//! specular or transmitting, or two-sided, and goniometric lights are
//! refused, since the gather here models none of them.

use glam::DVec3;
use radiometry::color::luminance;
use radiometry::geometry::TriangleGeometry;
use radiometry::rays::SceneRays;
use radiometry::sampling::{strata, Strata, Stream};
use radiometry::subdivision::leaf_holding;
use rayon::prelude::*;
use schemas::cluster::Clusters;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::{Node, Solution, NONE};
use stage_kit::scene::mesh_triangles;
use std::collections::HashMap;
use std::f64::consts::PI;

/// How densely [`Gather::leaf`] samples.
#[derive(Clone, Copy, Debug)]
pub struct Sampling {
    /// Stratified points per leaf.
    pub points: usize,
    /// Cosine-distributed rays per point.
    pub rays: usize,
    /// Stratified points on each emitting triangle per point.
    pub emitter_points: usize,
}

/// The scene as the gather traces it, and the field it gathers.
pub struct Gather<'a> {
    geometry: Vec<TriangleGeometry>,
    scene: SceneRays,
    /// Per triangle: diffuse reflectance and emission.
    reflectance: Vec<[f64; 3]>,
    emits: Vec<bool>,
    field: &'a Solution,
}

/// One leaf's gathered radiosity, and the light of each link into it
/// (luminance of irradiance, W/m², per link index).
pub struct Gathered {
    /// `B'` of the leaf, RGB.
    pub radiosity: [f64; 3],
    /// Per link carrying its rays' light, the luminance of that light.
    pub links: Vec<(usize, f64)>,
}

/// Where a solution's nodes sit: each element's chain of ancestors and
/// each input triangle's chain of clusters, and its links by their ends.
pub struct Attribution<'a> {
    solution: &'a Solution,
    clusters_of: Vec<Vec<u32>>,
    link_of: HashMap<(Node, Node), usize>,
}

impl<'a> Attribution<'a> {
    /// `solution`'s links by their ends; `clusters` the hierarchy it was
    /// solved with, if any (for links with a cluster at an end).
    pub fn new(solution: &'a Solution, clusters: Option<&Clusters>, triangles: usize) -> Self {
        let mut clusters_of = vec![Vec::new(); triangles];
        if let Some(c) = clusters {
            for (i, node) in c.nodes.iter().enumerate().filter(|(_, n)| n.child_count == 0) {
                let mut chain = vec![i as u32];
                let mut parent = node.parent;
                while parent != NONE {
                    chain.push(parent);
                    parent = c.nodes[parent as usize].parent;
                }
                for k in node.first_triangle..node.first_triangle + node.triangle_count {
                    clusters_of[c.order[k as usize] as usize] = chain.clone();
                }
            }
        }
        let link_of = solution.links.iter().enumerate().map(|(i, l)| ((l.receiver, l.sender), i)).collect();
        Attribution { solution, clusters_of, link_of }
    }

    /// Element `leaf`, its ancestors, then its triangle's clusters.
    fn nodes(&self, leaf: usize) -> Vec<Node> {
        let elements = &self.solution.elements;
        let mut nodes = vec![Node::Element(leaf as u32)];
        let mut e = leaf;
        while elements[e].parent != NONE {
            e = elements[e].parent as usize;
            nodes.push(Node::Element(e as u32));
        }
        nodes.extend(self.clusters_of[elements[leaf].triangle as usize].iter().map(|&c| Node::Cluster(c)));
        nodes
    }

    /// The link between an ancestor of leaf `receiver` and one of leaf
    /// `sender`, if there is one.
    fn link(&self, receiver: usize, sender: usize) -> Option<usize> {
        let senders = self.nodes(sender);
        self.nodes(receiver).into_iter().find_map(|r| senders.iter().find_map(|&s| self.link_of.get(&(r, s)).copied()))
    }
}

impl<'a> Gather<'a> {
    /// The gather of `field` over `mesh` (its materials from `manifest`);
    /// an error naming what it cannot model.
    pub fn new(mesh: &'a Mesh, manifest: &Manifest, field: &'a Solution) -> Result<Self, String> {
        if !manifest.goniometric_lights.is_empty() {
            return Err("the scene has goniometric lights, which this gather does not model".into());
        }
        for m in &manifest.materials {
            let why = if m.diffuse_map.is_some() || m.alpha_map.is_some() || m.normal_map.is_some() {
                "a texture, alpha or normal map"
            } else if m.specular_reflectance.iter().chain(&m.specular_transmittance).chain(&m.diffuse_transmittance).any(|&x| x > 0.0) {
                "specular reflection or transmission"
            } else if m.two_sided {
                "two sides"
            } else {
                continue;
            };
            return Err(format!("material '{}' has {why}, which this gather does not model", m.name));
        }
        if field.elements.len() < mesh.triangles.len() {
            return Err(format!("the field has {} elements for {} triangles", field.elements.len(), mesh.triangles.len()));
        }
        let geometry = mesh_triangles(mesh);
        let scene = SceneRays::new(&geometry.iter().map(|g| g.corners).collect::<Vec<_>>());
        let material = |t: &schemas::mesh::Triangle| &manifest.materials[t.material as usize];
        Ok(Gather {
            reflectance: mesh.triangles.iter().map(|t| material(t).diffuse).collect(),
            emits: mesh.triangles.iter().map(|t| luminance(material(t).emission) > 0.0).collect(),
            geometry,
            scene,
            field,
        })
    }

    /// The world centroid of element `e` of a solution of this mesh.
    fn centroid(&self, e: &schemas::solution::Element) -> DVec3 {
        let g = &self.geometry[e.triangle as usize];
        e.corners.iter().map(|c| g.point([f64::from(c[0]), f64::from(c[1])])).sum::<DVec3>() / 3.0
    }

    /// `gathered` (of `solution`'s leaves) as CSV, a row per leaf: its
    /// element, surface (`surface` names a triangle's), input triangle,
    /// level, open area (m²), world centroid, and the luminance of its
    /// radiosity in the solution and in the gather (W/m²).
    pub fn leaves_csv(&self, solution: &Solution, gathered: &[(usize, Gathered)], surface: &dyn Fn(u32) -> String) -> String {
        let mut csv = String::from("element,surface,triangle,level,area_m2,x,y,z,solution,gathered\n");
        for (leaf, g) in gathered {
            let e = &solution.elements[*leaf];
            let c = self.centroid(e);
            let b = luminance(e.radiosity.map(f64::from));
            csv += &format!("{leaf},{},{},{},{:e},{},{},{},{b:e},{:e}\n", surface(e.triangle), e.triangle, e.level, e.area, c.x, c.y, c.z, luminance(g.radiosity));
        }
        csv
    }

    /// Whether triangle `t` emits.
    pub fn emits(&self, t: u32) -> bool {
        self.emits[t as usize]
    }

    /// The leaf of `solution` on triangle `t` holding point `p`.
    fn leaf_at(&self, solution: &Solution, t: u32, p: DVec3) -> usize {
        let first_child = |e: usize| Some(solution.elements[e].first_child).filter(|&c| c != NONE).map(|c| c as usize);
        leaf_holding(t as usize, self.geometry[t as usize].uv_of(p), first_child).0
    }

    /// The field's radiosity at point `p` of triangle `t`.
    fn field_at(&self, t: u32, p: DVec3) -> [f64; 3] {
        self.field.elements[self.leaf_at(self.field, t, p)].radiosity.map(f64::from)
    }

    /// `B'` of leaf `leaf` of `solution` (module docs), sampled by
    /// `sampling`, and the light of each link of `attribution` into it;
    /// `None` where every point is buried. The random streams are keyed by
    /// the leaf.
    pub fn leaf(&self, solution: &Solution, leaf: usize, sampling: Sampling, attribution: Option<&Attribution>) -> Option<Gathered> {
        let Sampling { points, rays, emitter_points } = sampling;
        let e = &solution.elements[leaf];
        let g = &self.geometry[e.triangle as usize];
        let corners = e.corners.map(|c| g.point([f64::from(c[0]), f64::from(c[1])]));
        let n = g.normal;
        let tangent = n.cross(if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y }).normalize();
        let bitangent = n.cross(tangent);
        let mut stream = Stream::new(0x9a7e_4e5d, leaf as u64, 1);
        let (points_strata, emitter_strata) = (Strata::of(points), Strata::of(emitter_points));
        let (columns, _) = strata(rays);
        let rows = rays.div_ceil(columns);
        let skip = [e.triangle, u32::MAX];
        let offset = 1e-7 * corners.iter().map(|p| p.abs().max_element()).fold(1.0, f64::max);
        let (mut sum, mut used) = ([0.0; 3], 0usize);
        let mut credited: HashMap<usize, f64> = HashMap::new();
        for k in 0..points {
            let x = points_strata.point(&corners, k, &mut stream) + n * offset;
            let (mut h, mut back) = ([0.0; 3], 0);
            let mut links: Vec<(usize, f64)> = Vec::new();
            for r in 0..rays {
                let u1 = ((r % columns) as f64 + stream.next_f64()) / columns as f64;
                let u2 = ((r / columns) as f64 + stream.next_f64()) / rows as f64;
                let (radius, phi) = (u1.sqrt(), 2.0 * PI * u2);
                let w = tangent * (radius * phi.cos()) + bitangent * (radius * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt();
                let Some(hit) = self.scene.closest_hit(x, w, 0.0, f32::INFINITY, skip) else { continue };
                let facing = self.geometry[hit.triangle as usize].normal.dot(w) < 0.0;
                if !facing {
                    back += 1;
                    continue;
                }
                if self.emits(hit.triangle) {
                    continue;
                }
                let y = x + w * f64::from(hit.t);
                let b = self.field_at(hit.triangle, y);
                for c in 0..3 {
                    h[c] += b[c] / rays as f64;
                }
                if let Some(a) = attribution {
                    if let Some(l) = a.link(leaf, self.leaf_at(solution, hit.triangle, y)) {
                        links.push((l, luminance(b) / rays as f64));
                    }
                }
            }
            if 2 * back > rays {
                continue;
            }
            for (t, emitter) in self.geometry.iter().enumerate().filter(|(t, _)| self.emits[*t]) {
                for j in 0..emitter_points {
                    let y = emitter_strata.point(&emitter.corners, j, &mut stream);
                    let d = y - x;
                    let d2 = d.length_squared();
                    let (cos_r, cos_s) = (n.dot(d), -emitter.normal.dot(d));
                    if cos_r <= 0.0 || cos_s <= 0.0 || !self.scene.segment_clear(x, y, [e.triangle, t as u32]) {
                        continue;
                    }
                    let weight = cos_r * cos_s / (PI * d2 * d2) * emitter.area / emitter_points as f64;
                    let b = self.field_at(t as u32, y);
                    for c in 0..3 {
                        h[c] += weight * b[c];
                    }
                    if let Some(a) = attribution {
                        if let Some(l) = a.link(leaf, self.leaf_at(solution, t as u32, y)) {
                            links.push((l, weight * luminance(b)));
                        }
                    }
                }
            }
            for c in 0..3 {
                sum[c] += h[c];
            }
            for (l, v) in links {
                *credited.entry(l).or_default() += v;
            }
            used += 1;
        }
        (used > 0).then(|| {
            let rho = self.reflectance[e.triangle as usize];
            let mut links: Vec<(usize, f64)> = credited.into_iter().map(|(l, v)| (l, v / used as f64)).collect();
            links.sort_unstable_by_key(|l| l.0);
            Gathered { radiosity: std::array::from_fn(|c| rho[c] * sum[c] / used as f64), links }
        })
    }

    /// Every non-emitting leaf of `solution` with open area whose triangle
    /// `keep` accepts, gathered ([`Self::leaf`]), in leaf order.
    pub fn leaves(&self, solution: &Solution, keep: &(dyn Fn(u32) -> bool + Sync), sampling: Sampling, attribution: Option<&Attribution>) -> Vec<(usize, Gathered)> {
        let leaves: Vec<usize> = (0..solution.elements.len())
            .filter(|&i| {
                let e = &solution.elements[i];
                e.first_child == NONE && e.area > 0.0 && !self.emits(e.triangle) && keep(e.triangle)
            })
            .collect();
        leaves.par_iter().filter_map(|&i| self.leaf(solution, i, sampling, attribution).map(|g| (i, g))).collect()
    }
}

impl Gather<'_> {
    /// Per link of `solution` credited in `gathered` ([`Self::leaves`]
    /// with an [`Attribution`]): (link, its flux as the gather credits
    /// it, its own flux `A_r V F B_sent`), luminance in W, `A_r` the
    /// receiver's whole area (its links' visibility counts a buried part
    /// as hidden); links into clusters left out (module docs). `B_sent` is
    /// what the link sends its receiver's centroid: where the last solve
    /// has each part of the receiver see the sender for itself (a receiver
    /// next to its sender, hierarchical-solve's `near_sender_terms`), the
    /// leaves got those parts' views instead, and the link's own flux is
    /// not what they got.
    pub fn link_fluxes(&self, solution: &Solution, gathered: &[(usize, Gathered)]) -> Vec<(usize, f64, f64)> {
        let mut credited: HashMap<usize, f64> = HashMap::new();
        for (leaf, g) in gathered {
            let area = f64::from(solution.elements[*leaf].area);
            for &(l, v) in &g.links {
                *credited.entry(l).or_default() += area * v;
            }
        }
        let mut out: Vec<(usize, f64, f64)> = credited
            .into_iter()
            .filter_map(|(l, gathered)| {
                let link = &solution.links[l];
                let Node::Element(r) = link.receiver else { return None };
                let e = &solution.elements[r as usize];
                let g = &self.geometry[e.triangle as usize];
                let p = e.corners.map(|c| g.point([f64::from(c[0]), f64::from(c[1])]));
                let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                Some((l, gathered, area * f64::from(link.visibility) * luminance(link.unoccluded_irradiance.map(f64::from))))
            })
            .collect();
        out.sort_unstable_by_key(|l| l.0);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use schemas::header::{Provenance, Schema};
    use schemas::solution::{Element, Link};
    use test_support::closed_form::{lambert_polygon, mean_over_triangle};
    use test_support::meshes::{manifest, material, triangles};

    const LAMP: [DVec3; 3] = [dvec3(0.0, 0.0, 1.0), dvec3(0.0, 1.0, 1.0), dvec3(1.0, 0.0, 1.0)];

    /// A floor triangle (reflectance 0.5) under a lamp triangle (emitting
    /// 10) a metre above it, facing it; the solution their two roots, the
    /// lamp at 10, and one link between them of factor `f`, visibility
    /// `v` and the lamp's light.
    fn scene(f: f64, v: f32) -> (Mesh, Manifest, Solution) {
        let floor = [dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)];
        let mesh = triangles(&[(floor, 0, 0), (LAMP, 1, 1)]);
        let manifest = manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [10.0; 3])]);
        let elements = vec![Element::root(0, 0.5, [0.0; 3]), Element::root(1, 0.5, [10.0; 3])];
        let link = Link { receiver: Node::Element(0), sender: Node::Element(1), form_factor: f as f32, visibility: v, unoccluded_irradiance: [(10.0 * f) as f32; 3], occluder_distance: f32::INFINITY };
        let solution = Solution { header: Solution::header(Provenance::in_memory("bench-residual test")), elements, clusters: Vec::new(), links: vec![link], slopes: Vec::new() };
        (mesh, manifest, solution)
    }

    /// The floor's factor to the lamp: Lambert's point-to-polygon factor
    /// (002 Eq. 3) averaged over 4^6 points of the floor, by the test
    /// support's closed forms, apart from the gather.
    fn factor() -> f64 {
        let floor = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        mean_over_triangle(&floor, 6, &|x| lambert_polygon(x, [0.0, 0.0, 1.0], &LAMP.map(|p| p.to_array())))
    }

    /// The floor gathers `rho F E` from 64 points of 1,024 lamp points
    /// each (within 0.5%: it is within 0.05%; from 16 points, 1.2%), and
    /// the link is credited with that light; the link's own flux agrees
    /// where it is right and is half the gathered where it says half the
    /// lamp is hidden.
    #[test]
    fn the_floor_under_a_lamp_gathers_its_closed_form_and_credits_the_link() {
        let f = factor();
        for (v, ratio) in [(1.0, 1.0), (0.5, 0.5)] {
            let (mesh, manifest, solution) = scene(f, v);
            let gather = Gather::new(&mesh, &manifest, &solution).expect("a plain scene");
            let attribution = Attribution::new(&solution, None, mesh.triangles.len());
            let gathered = gather.leaves(&solution, &|_| true, Sampling { points: 64, rays: 64, emitter_points: 1024 }, Some(&attribution));
            assert_eq!(gathered.len(), 1, "the lamp is not gathered");
            let b = gathered[0].1.radiosity[0];
            assert!((b / (0.5 * f * 10.0) - 1.0).abs() < 5e-3, "{b} against {}", 0.5 * f * 10.0);
            let fluxes = gather.link_fluxes(&solution, &gathered);
            let [(0, credited, own)] = fluxes[..] else { panic!("{fluxes:?}") };
            assert!((credited / (0.5 * f * 10.0) - 1.0).abs() < 5e-3 && (own / credited - ratio).abs() < 5e-3, "{credited} {own}");
        }
    }

    /// `--leaves`: a row per gathered leaf whose columns say what its
    /// header says: the floor's element, surface, triangle, level, area,
    /// centroid `(1/3, 1/3, 0)`, its radiosity in the solution (0) and
    /// gathered (`rho F E`).
    #[test]
    fn the_leaves_table_has_a_row_per_gathered_leaf() {
        let f = factor();
        let (mesh, manifest, solution) = scene(f, 1.0);
        let gather = Gather::new(&mesh, &manifest, &solution).expect("a plain scene");
        let gathered = gather.leaves(&solution, &|_| true, Sampling { points: 16, rays: 16, emitter_points: 256 }, None);
        let csv = gather.leaves_csv(&solution, &gathered, &|t| format!("surface {t}"));
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 2, "{csv}");
        let row: Vec<&str> = lines[1].split(',').collect();
        let header: Vec<&str> = lines[0].split(',').collect();
        let column = |name: &str| row[header.iter().position(|&h| h == name).expect(name)];
        assert_eq!((column("element"), column("surface"), column("triangle"), column("level")), ("0", "surface 0", "0", "0"));
        let number = |name: &str| column(name).parse::<f64>().expect(name);
        assert!((number("area_m2") - 0.5).abs() < 1e-6 && (number("x") - 1.0 / 3.0).abs() < 1e-6 && (number("y") - 1.0 / 3.0).abs() < 1e-6 && number("z").abs() < 1e-12, "{csv}");
        assert_eq!(number("solution"), 0.0);
        assert!((number("gathered") / (0.5 * f * 10.0) - 1.0).abs() < 0.02, "{csv}");
    }

    /// A material the gather does not model is refused by name.
    #[test]
    fn a_textured_material_is_refused() {
        let (mesh, mut manifest, solution) = scene(0.1, 1.0);
        manifest.materials[0].diffuse_map = Some("wood.png".into());
        let why = Gather::new(&mesh, &manifest, &solution).err().expect("refused");
        assert!(why.contains("material 'm'") && why.contains("map"), "{why}");
    }
}
