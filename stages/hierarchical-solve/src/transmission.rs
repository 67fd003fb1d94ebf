//! Diffuse transmission (paper 004 Sec. 4.3.1, Eq. 4.4) between the two
//! faces of a translucent two-sided surface.
//!
//! A two-sided material's triangles come with *twins* from `mesh-prep`
//! (the same corners wound the other way), each face an input triangle
//! with its own elements, links and radiosity. Each face gathers the light
//! arriving on its side through its own links, which is the backward form
//! factor `T_nm` of Eq. 4.4 for the other face: the light reaching the
//! back of a face is what reaches the front of its twin. A face then
//! leaves
//!
//! ```text
//! B_front = E + rho_d H_front + tau_d H_back,    H_back = its twin's H
//! ```
//!
//! per point. So that every leaf has a twin leaf over the same part of the
//! surface, the two faces' hierarchies are refined alike: after each round
//! of refinement [`Hierarchy::pair_faces`] splits the leaf of any pair
//! whose other element was split, and pairs the children by position. A
//! new leaf starts from its parent's radiosity and receives its
//! ancestors' links through push-pull.
//!
//! A translucent material that is not two-sided has no element for its
//! back face, which would have to leave the transmitted light: it is
//! reported and transmits nothing.

use crate::elements::Hierarchy;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::NONE;

/// The translucent faces: transmittances and the pairing of elements.
pub struct Transmission {
    /// Diffuse transmittance of each input triangle (0 for opaque ones).
    pub tau: Vec<[f64; 3]>,
    /// Per element, the element over the same part of the twin face, or
    /// [`NONE`]; elements past the end are not paired yet.
    pub counterpart: Vec<u32>,
    /// Triangles of translucent materials that are not two-sided.
    pub one_sided: usize,
}

impl Transmission {
    /// The pairing of the input triangles of translucent two-sided
    /// materials with their twins; `None` where no material transmits.
    pub fn new(mesh: &Mesh, manifest: &Manifest) -> Option<Self> {
        if !manifest.effects.diffuse_transmission {
            return None;
        }
        let material = |t: usize| &manifest.materials[mesh.triangles[t].material as usize];
        let tau: Vec<[f64; 3]> = (0..mesh.triangles.len()).map(|t| material(t).diffuse_transmittance).collect();
        let twins = mesh.twins();
        let translucent = |t: usize| tau[t].iter().any(|&x| x > 0.0);
        let mut counterpart = vec![NONE; mesh.triangles.len()];
        let mut one_sided = 0;
        for t in (0..mesh.triangles.len()).filter(|&t| translucent(t)) {
            match twins[t].filter(|&u| material(u as usize).two_sided && material(t).two_sided) {
                Some(u) => counterpart[t] = u,
                None => one_sided += 1,
            }
        }
        Some(Transmission { tau, counterpart, one_sided })
    }

    /// Element `e`'s twin element, if paired.
    pub fn twin(&self, e: u32) -> Option<u32> {
        self.counterpart.get(e as usize).copied().filter(|&c| c != NONE)
    }
}

impl Hierarchy {
    /// Diffuse transmittance of element `e`'s triangle and its twin
    /// element, where it transmits into a paired face.
    pub fn transmission_of(&self, e: u32) -> Option<([f64; 3], u32)> {
        let t = self.transmission.as_ref()?;
        t.twin(e).map(|c| (t.tau[self.elements[e as usize].triangle as usize], c))
    }

    /// Splits leaves until every paired element's twin has children where
    /// it has, and pairs the children by position (module docs). Returns
    /// whether it added elements.
    pub fn pair_faces(&mut self) -> bool {
        let Some(mut t) = self.transmission.take() else { return false };
        let before = self.elements.len();
        let mut e = 0;
        while e < self.elements.len() {
            t.counterpart.resize(self.elements.len(), NONE);
            let c = t.counterpart[e];
            if c != NONE && (e as u32) < c {
                let (first, other) = (self.subdivide_if(e as u32, c), self.subdivide_if(c, e as u32));
                t.counterpart.resize(self.elements.len(), NONE);
                if let (Some(first), Some(other)) = (first, other) {
                    if t.counterpart[first as usize] == NONE {
                        self.pair_children(&mut t, first, other);
                    }
                }
            }
            e += 1;
        }
        t.counterpart.resize(self.elements.len(), NONE);
        self.transmission = Some(t);
        self.elements.len() > before
    }

    /// Pairs the four children from `first` with the four from `other`,
    /// each with the one whose centroid is nearest to its own.
    fn pair_children(&self, t: &mut Transmission, first: u32, other: u32) {
        for k in first..first + 4 {
            let centre = self.centroid(k);
            let distance = |x: u32| self.centroid(x).distance_squared(centre);
            let twin = (other..other + 4).min_by(|&a, &b| distance(a).total_cmp(&distance(b))).unwrap_or(other);
            t.counterpart[k as usize] = twin;
            t.counterpart[twin as usize] = k;
        }
    }

    /// The first child of `e`, subdividing it if `other` has children;
    /// `None` where neither has.
    fn subdivide_if(&mut self, e: u32, other: u32) -> Option<u32> {
        let has = |h: &Hierarchy, x: u32| !h.elements[x as usize].is_leaf();
        (has(self, e) || has(self, other)).then(|| self.subdivide(e))
    }
}
