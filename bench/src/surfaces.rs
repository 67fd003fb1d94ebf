//! Each surface's mean radiosity in several solutions of one scene, against
//! a reference solve: `bench-surfaces`, with which `make bench-renderpark`
//! measures both programs' accuracy alike.
//!
//! A surface is an object of the manifest, or each of its input triangles
//! ([`Unit`]; emitters left out). Its mean is the luminance of its
//! radiosity averaged over its area open to the scene,
//!
//! ```text
//! B_o = sum_k a_k Y(B_k) / sum_k a_k
//! ```
//!
//! over the pieces `k` of the object a solution holds, `a_k` their open
//! area: a hierarchical-solve leaf's own (the part of it not buried in a
//! solid). RenderPark knows no burial: an element along a block's base is
//! dark where it runs under the block, and its linear basis carries that
//! into its open part. So each of its elements is taken as
//! [`FACE_PIECES`] pieces, the centroids of its corners' barycentric
//! subdivision, each with `pi` times the radiance its linear basis has
//! there (interpolated between its corners, a quadrilateral split into
//! two triangles) and weighed by the open fraction of the reference's leaf
//! there: its radiosity over its open part as it would show. Both solvers
//! are judged by the same measure against the same reference, a solve at
//! a much finer `EPS` (the README's RenderPark section).
//!
//! A RenderPark model also converts into a solution on the mesh
//! ([`Surfaces::solution_of_faces`]), which grid-gather's preview renders
//! like any other: its images are then measured like hierarchical-solve's.

use glam::DVec3;
use radiometry::color::luminance;
use radiometry::geometry::TriangleGeometry;
use radiometry::subdivision::{children, Corners, ROOT};
use schemas::header::Header;
use schemas::mesh::{Manifest, Mesh};
use schemas::solution::{Element, Solution, NONE};
use stage_kit::scene::mesh_triangles;
use std::f64::consts::PI;

/// A polygon of a RenderPark VRML model with its corners' RGB radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// Corners, in the file's order.
    pub corners: Vec<DVec3>,
    /// Radiance at each corner, W/(m² sr).
    pub radiance: Vec<[f64; 3]>,
}

impl Face {
    /// Its [`FACE_PIECES`] pieces per triangle of its fan: `(centroid,
    /// area, radiosity)`, the radiosity `pi` times the radiance
    /// interpolated linearly between the triangle's corners.
    fn pieces(&self) -> Vec<(DVec3, f64, [f64; 3])> {
        let (c, r) = (&self.corners, &self.radiance);
        let mut pieces = Vec::new();
        for i in 1..c.len() - 1 {
            let area = 0.5 * (c[i] - c[0]).cross(c[i + 1] - c[0]).length() / FACE_PIECES as f64;
            for (a, b, d) in sub_centroids() {
                let at = a * c[0] + b * c[i] + d * c[i + 1];
                pieces.push((at, area, std::array::from_fn(|k| PI * (a * r[0][k] + b * r[i][k] + d * r[i + 1][k]))));
            }
        }
        pieces
    }
}

/// Pieces a RenderPark triangle is taken as ([`Face::pieces`]): `n²` for
/// `n` = [`FACE_SPLIT`].
pub const FACE_PIECES: usize = FACE_SPLIT * FACE_SPLIT;

/// Parts each edge of a RenderPark triangle is cut into.
const FACE_SPLIT: usize = 4;

/// Barycentric coordinates of the centroids of a triangle's `n²` equal
/// sub-triangles (`n` = [`FACE_SPLIT`]), upward and downward.
fn sub_centroids() -> impl Iterator<Item = (f64, f64, f64)> {
    let n = FACE_SPLIT as f64;
    let up = (0..FACE_SPLIT).flat_map(move |i| (0..FACE_SPLIT - i).map(move |j| ((i as f64 + 1.0 / 3.0) / n, (j as f64 + 1.0 / 3.0) / n)));
    let down = (0..FACE_SPLIT).flat_map(move |i| (0..FACE_SPLIT - i - 1).map(move |j| ((i as f64 + 2.0 / 3.0) / n, (j as f64 + 2.0 / 3.0) / n)));
    up.chain(down).map(|(b, d)| (1.0 - b - d, b, d))
}

/// The numbers of the first `[ ... ]` list after `key` in `text`, from
/// `from` on, and where the list ends.
fn list_after(text: &str, key: &str, from: usize) -> Result<(Vec<f64>, usize), String> {
    let at = text[from..].find(key).ok_or(format!("no '{key}' list"))? + from;
    let open = text[at..].find('[').ok_or(format!("'{key}' is not followed by a list"))? + at + 1;
    let close = text[open..].find(']').ok_or(format!("the '{key}' list is not closed"))? + open;
    let numbers = text[open..close]
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| !w.is_empty())
        .map(|w| w.parse::<f64>().map_err(|_| format!("'{w}' in the '{key}' list is not a number")))
        .collect::<Result<_, _>>()?;
    Ok((numbers, close))
}

/// The faces of the indexed face sets of a VRML 2 model as RenderPark's
/// Galerkin radiosity writes it (`-radiance-model-savefile`): `point`,
/// then `color` per vertex (`colorPerVertex TRUE`), then `coordIndex`,
/// faces ended by -1 (the last one perhaps not). The colours must be radiance, not display values:
/// `make bench-renderpark` builds rpk with its tone mapping taken out of
/// that writer (pipelines/renderpark.mk).
pub fn vrml_faces(text: &str) -> Result<Vec<Face>, String> {
    let mut faces = Vec::new();
    let mut from = 0;
    while let Some(at) = text[from..].find("IndexedFaceSet").map(|a| a + from) {
        let (points, end) = list_after(text, "point", at)?;
        let (colours, end) = list_after(text, "color [", end).map_err(|_| "a face set without per-vertex colours".to_string())?;
        let (indices, end) = list_after(text, "coordIndex", end)?;
        if points.len() % 3 != 0 || colours.len() != points.len() {
            return Err(format!("{} point coordinates and {} colour values: not one RGB colour per point", points.len(), colours.len()));
        }
        let vertex = |i: f64| -> Result<usize, String> {
            let k = i as usize;
            (i >= 0.0 && i.fract() == 0.0 && 3 * k < points.len()).then_some(k).ok_or(format!("coordIndex {i} is not a point of the set ({})", points.len() / 3))
        };
        // Faces end at -1, the last one also at the list's end (VRML 2
        // lets it go without).
        for face in indices.split(|&i| i == -1.0).filter(|f| !f.is_empty()) {
            let corners = face.iter().map(|&i| vertex(i)).collect::<Result<Vec<_>, _>>()?;
            if corners.len() < 3 {
                return Err(format!("a face of {} corners", corners.len()));
            }
            faces.push(Face {
                corners: corners.iter().map(|&k| DVec3::new(points[3 * k], points[3 * k + 1], points[3 * k + 2])).collect(),
                radiance: corners.iter().map(|&k| [colours[3 * k], colours[3 * k + 1], colours[3 * k + 2]]).collect(),
            });
        }
        from = end;
    }
    if faces.is_empty() {
        return Err("no IndexedFaceSet with faces".into());
    }
    Ok(faces)
}

/// What a surface is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Unit {
    /// An object of the manifest (the issue's surfaces: floor, blocks).
    Object,
    /// An input triangle of the mesh (a block's face is two): where an
    /// object's mean hides errors of opposite sign on its faces.
    Triangle,
}

impl Unit {
    /// The surface (its index) that input triangle `t` of `mesh` belongs to.
    pub fn of(self, mesh: &Mesh, t: u32) -> usize {
        match self {
            Unit::Object => mesh.triangles[t as usize].object as usize,
            Unit::Triangle => t as usize,
        }
    }

    /// Every surface's name, by index: an object's, or an object's and a
    /// triangle's index.
    pub fn names(self, mesh: &Mesh, manifest: &Manifest) -> Vec<String> {
        match self {
            Unit::Object => manifest.objects.clone(),
            Unit::Triangle => mesh.triangles.iter().enumerate().map(|(i, t)| format!("{} {i}", manifest.objects[t.object as usize])).collect(),
        }
    }
}

/// The scene's surfaces and a reference solution on its mesh.
pub struct Surfaces<'a> {
    mesh: &'a Mesh,
    /// Each mesh triangle's geometry, f64.
    geometry: Vec<TriangleGeometry>,
    unit: Unit,
    /// Surface names, and whether each is measured (not an emitter).
    surfaces: Vec<(String, bool)>,
    reference: &'a Solution,
    /// Largest distance of a point from a triangle's plane that still lies
    /// on it, m.
    on_plane: f64,
}

/// How far outside a triangle, in barycentric terms, a point may be and
/// still be taken as on it (the VRML's coordinates have six digits).
const INSIDE: f64 = 1e-5;

impl<'a> Surfaces<'a> {
    /// The surfaces (`unit`) of `mesh` and `manifest`, against `reference`
    /// (a solution on that mesh).
    pub fn new(mesh: &'a Mesh, manifest: &Manifest, reference: &'a Solution, unit: Unit) -> Result<Self, String> {
        check_mesh(mesh, reference, "the reference")?;
        let emits = |t: &schemas::mesh::Triangle| luminance(manifest.materials[t.material as usize].emission) > 0.0;
        // A surface is measured unless all its triangles emit.
        let names = unit.names(mesh, manifest);
        let mut measured = vec![false; names.len()];
        for (t, triangle) in mesh.triangles.iter().enumerate() {
            measured[unit.of(mesh, t as u32)] |= !emits(triangle);
        }
        let surfaces = names.into_iter().zip(measured).collect();
        let geometry = mesh_triangles(mesh);
        let (lo, hi) = geometry.iter().flat_map(|g| g.corners).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        Ok(Surfaces { mesh, geometry, unit, surfaces, reference, on_plane: 1e-5 * (hi - lo).length() })
    }

    /// The measured surfaces' names (an object's, or an object's and a
    /// triangle's index).
    pub fn names(&self) -> Vec<&str> {
        self.surfaces.iter().filter(|o| o.1).map(|o| o.0.as_str()).collect()
    }

    /// Each measured surface's mean ([`Self::names`]' order) in `solution`,
    /// a solution on the same mesh; `None` where it has no open area.
    pub fn of_solution(&self, solution: &Solution) -> Result<Vec<Option<f64>>, String> {
        check_mesh(self.mesh, solution, "a solution")?;
        let pieces = solution.elements.iter().filter(|e| e.first_child == NONE).map(|e| (self.surface_of(e.triangle), f64::from(e.area), e.radiosity.map(f64::from)));
        Ok(self.means(pieces))
    }

    /// Each measured surface's mean in the faces of a RenderPark model
    /// ([`Face::pieces`]). A piece that lies on no triangle of the mesh is
    /// an error.
    pub fn of_faces(&self, faces: &[Face]) -> Result<Vec<Option<f64>>, String> {
        let pieces = faces
            .iter()
            .flat_map(Face::pieces)
            .map(|(c, area, radiosity)| {
                let (t, uv) = self.locate(c).ok_or(format!("a face's point ({:.6}, {:.6}, {:.6}) lies on no triangle of the mesh", c.x, c.y, c.z))?;
                Ok((self.surface_of(t), area * self.open_fraction(t, uv), radiosity))
            })
            .collect::<Result<Vec<_>, String>>()?;
        Ok(self.means(pieces.into_iter()))
    }

    /// A RenderPark model as a solution on the mesh (no links, no
    /// clusters): each input triangle subdivided as hierarchical-solve
    /// subdivides it, down to [`BELOW_FACE`] levels below the model's
    /// element (triangle of its fan) that holds the leaf, each leaf with
    /// the radiosity of that element's linear basis at its centroid (its
    /// mean there) and the reference's open fraction of its area
    /// ([`Self::of_faces`]). The model's elements must be such
    /// subdivisions too (RenderPark's quadtree of a triangle is): a leaf
    /// that no element holds, or that still straddles two at
    /// [`MOST_LEVELS`], is an error.
    pub fn solution_of_faces(&self, faces: &[Face], header: Header) -> Result<Solution, String> {
        let mut on: Vec<Vec<Piece>> = vec![Vec::new(); self.mesh.triangles.len()];
        for f in faces {
            for i in 1..f.corners.len() - 1 {
                let k = [0, i, i + 1];
                let centroid = k.iter().map(|&j| f.corners[j]).sum::<DVec3>() / 3.0;
                let (t, _) = self.locate(centroid).ok_or(format!("a face centred at ({:.6}, {:.6}, {:.6}) lies on no triangle of the mesh", centroid.x, centroid.y, centroid.z))?;
                let uv = uv_triangle(&k.map(|j| self.geometry[t as usize].uv_of(f.corners[j])));
                on[t as usize].push(Piece { uv, radiosity: k.map(|j| f.radiance[j].map(|r| PI * r)) });
            }
        }
        let triangles = self.mesh.triangles.len();
        let mut elements: Vec<Element> = (0..triangles as u32).map(|t| Element::root(t, 0.0, [0.0; 3])).collect();
        let mut corners: Vec<Corners> = vec![ROOT; triangles];
        let mut e = 0;
        while e < elements.len() {
            let (t, level) = (elements[e].triangle, elements[e].level);
            let c = corners[e];
            let centroid = [(c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0];
            let holding = on[t as usize].iter().find(|p| p.holds(centroid));
            let cell = uv_triangle(&c);
            let leaf = holding.filter(|p| c.iter().all(|&x| p.holds(x)) && cell.area * 4f64.powi(BELOW_FACE as i32) <= p.uv.area * (1.0 + 1e-9));
            if let Some(p) = leaf {
                elements[e].radiosity = p.at(centroid).map(|x| x as f32);
                elements[e].area = (self.geometry[t as usize].area * 2.0 * cell.area * self.open_fraction(t, centroid)) as f32;
            } else if level >= MOST_LEVELS {
                return Err(format!("triangle {t}: a leaf at ({:.6}, {:.6}) {} after {MOST_LEVELS} levels", centroid[0], centroid[1], if holding.is_some() { "still straddles two of the model's elements" } else { "lies in none of the model's elements" }));
            } else {
                elements[e].first_child = elements.len() as u32;
                for child in children(&c) {
                    elements.push(Element { triangle: t, parent: e as u32, first_child: NONE, level: level + 1, corners: child.map(|x| x.map(|v| v as f32)), area: 0.0, radiosity: [0.0; 3] });
                    corners.push(child);
                }
            }
            e += 1;
        }
        // Inner elements: their children's open area and its mean radiosity
        // (children follow their parents, so one backward sweep finds an
        // element's sums complete when it reaches it).
        for e in (0..elements.len()).rev() {
            let element = &mut elements[e];
            if element.first_child != NONE {
                let area = element.area;
                element.radiosity = element.radiosity.map(|x| if area > 0.0 { x / area } else { 0.0 });
            }
            let (parent, area, b) = (element.parent, element.area, element.radiosity);
            if parent != NONE {
                let p = &mut elements[parent as usize];
                for (sum, x) in p.radiosity.iter_mut().zip(b) {
                    *sum += area * x;
                }
                p.area += area;
            }
        }
        Ok(Solution { header, elements, clusters: Vec::new(), links: Vec::new(), slopes: Vec::new() })
    }

    /// The surface input triangle `triangle` belongs to.
    fn surface_of(&self, triangle: u32) -> usize {
        self.unit.of(self.mesh, triangle)
    }

    /// Open-area-weighted mean luminance per measured surface of
    /// `(surface, open area, radiosity)` pieces.
    fn means(&self, pieces: impl Iterator<Item = (usize, f64, [f64; 3])>) -> Vec<Option<f64>> {
        let mut sums = vec![(0.0, 0.0); self.surfaces.len()];
        for (o, a, b) in pieces {
            sums[o].0 += a * luminance(b);
            sums[o].1 += a;
        }
        sums.iter().zip(&self.surfaces).filter(|(_, o)| o.1).map(|(&(s, a), _)| (a > 0.0).then(|| s / a)).collect()
    }

    /// The triangle `p` lies on and its barycentric `(u, v)` there (`p =
    /// (1-u-v) P0 + u P1 + v P2`): the nearest plane among the triangles
    /// that hold it.
    fn locate(&self, p: DVec3) -> Option<(u32, [f64; 2])> {
        let mut best: Option<(f64, u32, [f64; 2])> = None;
        for (t, g) in self.geometry.iter().enumerate().filter(|(_, g)| g.area > 0.0) {
            let distance = (p - g.corners[0]).dot(g.normal).abs();
            if distance > self.on_plane || best.is_some_and(|b| b.0 <= distance) {
                continue;
            }
            let uv = g.uv_of(p);
            if uv[0] >= -INSIDE && uv[1] >= -INSIDE && uv[0] + uv[1] <= 1.0 + INSIDE {
                best = Some((distance, t as u32, uv));
            }
        }
        best.map(|(_, t, uv)| (t, uv))
    }

    /// The open fraction of the reference's leaf at `uv` of triangle `t`:
    /// its open area over its geometric area.
    fn open_fraction(&self, t: u32, uv: [f64; 2]) -> f64 {
        let elements = &self.reference.elements;
        let mut e = &elements[t as usize];
        while e.first_child != NONE {
            let children = &elements[e.first_child as usize..e.first_child as usize + 4];
            e = children.iter().max_by(|a, b| inside_by(a, uv).total_cmp(&inside_by(b, uv))).expect("four children");
        }
        let geometric = self.geometry[t as usize].area * 2.0 * uv_triangle(&corners_of(e)).area;
        if geometric > 0.0 {
            (f64::from(e.area) / geometric).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }
}

/// Levels below a RenderPark element that [`Surfaces::solution_of_faces`]
/// subdivides to: 16 leaves carry its linear basis, each its mean over it.
pub const BELOW_FACE: u32 = 2;

/// Most levels [`Surfaces::solution_of_faces`] subdivides an input
/// triangle to.
pub const MOST_LEVELS: u32 = 16;

/// A triangle of a RenderPark element on an input triangle: its corners'
/// `(u, v)` there ([`uv_triangle`]) and radiosity.
#[derive(Clone, Debug)]
struct Piece {
    uv: TriangleGeometry,
    radiosity: [[f64; 3]; 3],
}

/// How far outside a RenderPark element, in its own barycentric terms, a
/// corner of a leaf may lie and be taken as in it: its corners carry the
/// VRML's six digits; a leaf that straddles two elements has a corner
/// outside one by a good fraction of it.
const IN_PIECE: f64 = 1e-3;

impl Piece {
    /// Whether it holds `uv` (within [`IN_PIECE`]).
    fn holds(&self, uv: [f64; 2]) -> bool {
        local(&self.uv, uv).iter().all(|&l| l >= -IN_PIECE)
    }

    /// Its linear radiosity at `uv`.
    fn at(&self, uv: [f64; 2]) -> [f64; 3] {
        let l = local(&self.uv, uv);
        std::array::from_fn(|c| (0..3).map(|k| l[k] * self.radiosity[k][c]).sum())
    }
}

/// The triangle of `(u, v)` corners `c` in the plane `z = 0`: its area is
/// its `(u, v)` area.
fn uv_triangle(c: &Corners) -> TriangleGeometry {
    TriangleGeometry::new(c.map(|c| DVec3::new(c[0], c[1], 0.0)))
}

/// The barycentric coordinates of `uv` in `triangle` (a [`uv_triangle`]).
fn local(triangle: &TriangleGeometry, uv: [f64; 2]) -> [f64; 3] {
    let [s, t] = triangle.uv_of(DVec3::new(uv[0], uv[1], 0.0));
    [1.0 - s - t, s, t]
}

/// Element `e`'s `(u, v)` corners.
fn corners_of(e: &Element) -> Corners {
    e.corners.map(|c| [f64::from(c[0]), f64::from(c[1])])
}

/// The least of `uv`'s barycentric coordinates in element `e`: at least 0
/// where `e` holds it.
fn inside_by(e: &Element, uv: [f64; 2]) -> f64 {
    local(&uv_triangle(&corners_of(e)), uv).into_iter().fold(f64::INFINITY, f64::min)
}

/// That `solution` (`which`) lies on `mesh`: one root element per triangle.
/// Whether `solution` (named `which` in the error) is a solution of
/// `mesh`: one root element per input triangle, no element of another.
pub fn check_mesh(mesh: &Mesh, solution: &Solution, which: &str) -> Result<(), String> {
    let roots = solution.elements.iter().take_while(|e| e.parent == NONE).count();
    if roots != mesh.triangles.len() || solution.elements.iter().any(|e| e.triangle as usize >= mesh.triangles.len()) {
        return Err(format!("{which} has {roots} input triangles but the mesh {}: not its solution", mesh.triangles.len()));
    }
    Ok(())
}

/// A Markdown table: per surface the reference's mean and each series'
/// signed error against it, then each series' largest error in magnitude.
pub fn table(names: &[&str], reference: &[Option<f64>], series: &[(String, Vec<Option<f64>>)]) -> String {
    let error = |x: Option<f64>, r: Option<f64>| match (x, r) {
        (Some(x), Some(r)) if r > 0.0 => Some(x / r - 1.0),
        _ => None,
    };
    let mut rows = vec![
        format!("| surface | reference | {} |", series.iter().map(|s| s.0.as_str()).collect::<Vec<_>>().join(" | ")),
        format!("|---|---|{}", "---|".repeat(series.len())),
    ];
    for (o, name) in names.iter().enumerate() {
        let cells: Vec<String> = series.iter().map(|s| error(s.1[o], reference[o]).map_or("-".into(), |e| format!("{:+.2}%", 100.0 * e))).collect();
        rows.push(format!("| {name} | {} | {} |", reference[o].map_or("-".into(), |r| format!("{r:.4}")), cells.join(" | ")));
    }
    let worst: Vec<String> = series
        .iter()
        .map(|s| {
            let w = (0..names.len()).filter_map(|o| error(s.1[o], reference[o])).map(f64::abs).fold(0.0, f64::max);
            format!("{:.2}%", 100.0 * w)
        })
        .collect();
    rows.push(format!("| worst surface | | {} |", worst.join(" | ")));
    rows.join("\n") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::dvec3;
    use schemas::header::{Provenance, Schema};
    use test_support::meshes::{manifest, material, triangles};

    /// A floor triangle (object 0) and an emitting one above it (object 1).
    fn scene() -> (Mesh, Manifest) {
        let floor = [dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)];
        let lamp = [dvec3(0.0, 0.0, 1.0), dvec3(0.0, 1.0, 1.0), dvec3(1.0, 0.0, 1.0)];
        let mesh = triangles(&[(floor, 0, 0), (lamp, 1, 1)]);
        (mesh, manifest(2, vec![material([0.5; 3], [0.0; 3]), material([0.0; 3], [10.0; 3])]))
    }

    /// The floor split into four, its corner child at (0, 0) wholly
    /// buried (no open area), the others open, radiosity `b` each.
    fn reference(b: [f32; 4]) -> Solution {
        let corners = radiometry::subdivision::children(&radiometry::subdivision::ROOT);
        let root = |t: u32| Element::root(t, 0.5, [1.0; 3]);
        let mut elements = vec![root(0), root(1)];
        elements[0].first_child = 2;
        elements.extend((0..4).map(|k| Element {
            triangle: 0,
            parent: 0,
            first_child: NONE,
            level: 1,
            corners: corners[k].map(|c| c.map(|x| x as f32)),
            area: if k == 0 { 0.0 } else { 0.125 },
            radiosity: [b[k]; 3],
        }));
        Solution { header: Solution::header(Provenance::in_memory("bench-surfaces test")), elements, clusters: Vec::new(), links: Vec::new(), slopes: Vec::new() }
    }

    /// A triangle's pieces and a quadrilateral's (two triangles) cover it
    /// and average a linear radiance to `pi` times its mean there.
    #[test]
    fn a_faces_pieces_cover_it_and_average_its_linear_radiance() {
        let r = |p: DVec3| [p.x + 2.0 * p.y, 1.0, 3.0 * p.x];
        for corners in [vec![dvec3(0.0, 0.0, 0.0), dvec3(2.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)], vec![dvec3(0.0, 0.0, 0.0), dvec3(2.0, 0.0, 0.0), dvec3(2.0, 1.0, 0.0), dvec3(0.0, 1.0, 0.0)]] {
            let face = Face { radiance: corners.iter().map(|&p| r(p)).collect(), corners: corners.clone() };
            let pieces = face.pieces();
            let area: f64 = pieces.iter().map(|p| p.1).sum();
            let expected = if corners.len() == 3 { 1.0 } else { 2.0 };
            assert!((area - expected).abs() < 1e-12, "{area}");
            // The mean of a linear function over a polygon is its value at
            // the centroid: (2/3, 1/3) for the triangle, (1, 1/2) for the
            // rectangle.
            let centroid = if corners.len() == 3 { dvec3(2.0 / 3.0, 1.0 / 3.0, 0.0) } else { dvec3(1.0, 0.5, 0.0) };
            for c in 0..3 {
                let mean = pieces.iter().map(|p| p.1 * p.2[c]).sum::<f64>() / area;
                assert!((mean - PI * r(centroid)[c]).abs() < 1e-12, "channel {c}: {mean}");
            }
        }
    }

    /// The faces, corners and colours of a small VRML file; a colour list
    /// of another length and an index past the points are refused.
    #[test]
    fn a_vrml_face_set_reads_into_faces() {
        let vrml = |points: &str, colours: &str, indices: &str| {
            format!("#VRML V2.0 utf8\nShape {{ geometry IndexedFaceSet {{\n coord Coordinate {{ point [ {points} ] }}\n colorPerVertex TRUE\n color Color {{ color [ {colours} ] }}\n coordIndex [ {indices} ] }} }}\n")
        };
        let points = "0 0 0, 1 0 0, 0 1 0, 1 1 0";
        let faces = vrml_faces(&vrml(points, "0.1 0.2 0.3, 1 1 1, 2 2 2, 3 3 3", "0 1 2 -1 1 3 2 -1")).expect("two faces");
        assert_eq!(faces.len(), 2);
        assert_eq!(vrml_faces(&vrml(points, "0.1 0.2 0.3, 1 1 1, 2 2 2, 3 3 3", "0 1 2 -1 1 3 2")).expect("the last face unended"), faces);
        assert!(vrml_faces(&vrml(points, "0.1 0.2 0.3, 1 1 1, 2 2 2, 3 3 3", "0 1 2 -1 1 3")).unwrap_err().contains("a face of 2 corners"));
        assert_eq!(faces[1].corners, vec![dvec3(1.0, 0.0, 0.0), dvec3(1.0, 1.0, 0.0), dvec3(0.0, 1.0, 0.0)]);
        assert_eq!(faces[0].radiance[0], [0.1, 0.2, 0.3]);
        assert!(vrml_faces(&vrml(points, "1 1 1", "0 1 2 -1")).unwrap_err().contains("not one RGB colour per point"));
        assert!(vrml_faces(&vrml(points, "0 0 0, 1 1 1, 2 2 2, 3 3 3", "0 1 4 -1")).unwrap_err().contains("coordIndex 4"));
        assert!(vrml_faces("no model").is_err());
    }

    /// A solution's surface mean is its leaves' open-area mean; a
    /// RenderPark face over the whole floor, its radiance `u + v` at
    /// barycentric `(u, v)`, counts only where the reference's leaves are
    /// open: the mean of `u + v` over the three open children, 7/9 (2/3
    /// over the floor, 1/3 over the buried child), times `pi`. The emitter
    /// is left out; a face off the mesh is refused.
    #[test]
    fn surfaces_are_open_area_means_against_the_reference() {
        let (mesh, manifest) = scene();
        let reference = reference([9.0, 1.0, 2.0, 3.0]);
        let surfaces = Surfaces::new(&mesh, &manifest, &reference, Unit::Object).expect("the reference lies on the mesh");
        assert_eq!(surfaces.names(), ["object_0"]);
        assert_eq!(Surfaces::new(&mesh, &manifest, &reference, Unit::Triangle).unwrap().names(), ["object_0 0"]);
        let means = surfaces.of_solution(&reference).unwrap();
        assert!((means[0].unwrap() - 2.0).abs() < 1e-6, "{means:?}");
        let floor = vec![dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)];
        let face = Face { radiance: vec![[0.0; 3], [1.0; 3], [1.0; 3]], corners: floor };
        let means = surfaces.of_faces(std::slice::from_ref(&face)).unwrap();
        assert!((means[0].unwrap() - PI * 7.0 / 9.0).abs() < 1e-9, "{means:?}");
        let off = Face { corners: face.corners.iter().map(|p| *p + dvec3(0.0, 0.0, 0.5)).collect(), ..face };
        assert!(surfaces.of_faces(&[off]).unwrap_err().contains("lies on no triangle"));
    }

    /// A model converted into a solution: each triangle subdivided
    /// [`BELOW_FACE`] levels below the model's element (16 leaves for a
    /// face over the whole triangle), each leaf with the element's linear
    /// radiosity at its centroid and the reference's open part of its
    /// area, the inner elements their leaves' open area and mean: the
    /// floor's root the mean of `pi (u + v)` over its open part, `pi` 7/9.
    /// An element that is not a quadtree cell of its triangle is refused.
    #[test]
    fn a_model_converts_into_a_solution_on_the_mesh() {
        let (mesh, manifest) = scene();
        let reference = reference([9.0, 1.0, 2.0, 3.0]);
        let surfaces = Surfaces::new(&mesh, &manifest, &reference, Unit::Object).unwrap();
        let floor = Face { corners: vec![dvec3(0.0, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)], radiance: vec![[0.0; 3], [1.0; 3], [1.0; 3]] };
        let lamp = Face { corners: vec![dvec3(0.0, 0.0, 1.0), dvec3(0.0, 1.0, 1.0), dvec3(1.0, 0.0, 1.0)], radiance: vec![[2.0; 3]; 3] };
        let header = Solution::header(Provenance::in_memory("bench-surfaces test"));
        let solution = surfaces.solution_of_faces(&[floor.clone(), lamp.clone()], header.clone()).expect("quadtree cells");
        let leaves: Vec<&Element> = solution.elements.iter().filter(|e| e.first_child == NONE && e.triangle == 0).collect();
        assert_eq!(leaves.len(), 16);
        assert!(leaves.iter().all(|e| e.level == 2));
        for e in &leaves {
            let c = corners_of(e);
            let (u, v) = ((c[0][0] + c[1][0] + c[2][0]) / 3.0, (c[0][1] + c[1][1] + c[2][1]) / 3.0);
            assert!((f64::from(e.radiosity[0]) - PI * (u + v)).abs() < 1e-6, "{e:?}");
            let open = if 1.0 - u - v > 0.5 { 0.0 } else { 0.5 / 16.0 };
            assert!((f64::from(e.area) - open).abs() < 1e-7, "{e:?}");
        }
        let root = &solution.elements[0];
        assert!((f64::from(root.area) - 0.375).abs() < 1e-7 && (f64::from(root.radiosity[0]) - PI * 7.0 / 9.0).abs() < 1e-5, "{root:?}");
        assert!((f64::from(solution.elements[1].radiosity[1]) - 2.0 * PI).abs() < 1e-5);
        let halves = [[dvec3(0.0, 0.0, 0.0), dvec3(0.7, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)], [dvec3(0.7, 0.0, 0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0)]];
        let mut split: Vec<Face> = halves.iter().map(|c| Face { corners: c.to_vec(), radiance: vec![[1.0; 3]; 3] }).collect();
        split.push(lamp);
        assert!(surfaces.solution_of_faces(&split, header).unwrap_err().contains("straddles"));
    }

    /// The table: the reference's mean, each series' signed error, the
    /// worst surface per series.
    #[test]
    fn the_table_gives_signed_errors_and_the_worst_surface() {
        let text = table(&["floor", "wall"], &[Some(2.0), Some(1.0)], &[("a".into(), vec![Some(2.02), Some(0.99)])]);
        assert!(text.contains("| floor | 2.0000 | +1.00% |"), "{text}");
        assert!(text.contains("| wall | 1.0000 | -1.00% |"), "{text}");
        assert!(text.contains("| worst surface | | 1.00% |"), "{text}");
    }
}
