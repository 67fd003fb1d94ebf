//! Solution comparison: radiosity per leaf element when both hierarchies
//! are the same, else per input triangle.

use crate::metrics::Sample;
use crate::{CompareError, Which};
use schemas::solution::{Element, Solution, NONE};

/// Relative area difference above which two input triangles are taken to
/// come from different meshes.
pub const AREA_TOLERANCE: f64 = 1e-4;

/// How two solutions were matched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Same hierarchy: one sample per leaf element, weighted by its area.
    Leaves,
    /// Different hierarchies on the same mesh: one sample per input
    /// triangle (the area-weighted mean of its leaves), weighted by its area.
    Triangles,
}

impl Mode {
    /// How the report names the mode.
    pub fn describe(self) -> &'static str {
        match self {
            Mode::Leaves => "solution leaves",
            Mode::Triangles => "solution triangles",
        }
    }
}

/// Whether two element tables have the same hierarchy: same length, and
/// per element the same input triangle and first child.
pub fn same_structure(a: &[Element], b: &[Element]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.triangle == y.triangle && x.first_child == y.first_child)
}

/// Number of input triangles: the leading elements without a parent
/// (input triangle `t` is element `t`).
pub fn input_triangles(elements: &[Element]) -> usize {
    elements.iter().take_while(|e| e.parent == NONE).count()
}

/// Checks radiosity and area are finite, naming the first bad element.
fn check(elements: &[Element], which: Which) -> Result<(), CompareError> {
    match elements.iter().position(|e| !(e.area.is_finite() && e.radiosity.iter().all(|v| v.is_finite()))) {
        Some(i) => Err(CompareError::Malformed { which, what: format!("non-finite area or radiosity at element {i}") }),
        None => Ok(()),
    }
}

/// Area-weighted mean radiosity over the leaves below each input triangle:
/// `B̄_t = Σ_leaves A_l B_l / Σ_leaves A_l`, leaves found from element `t`
/// by following `first_child` (children `first_child .. first_child + 4`).
/// Returns `(B̄_t, A_t)` per input triangle, `A_t` the triangle's own area.
/// A triangle whose leaves have no area keeps its own radiosity.
/// A hierarchy that revisits an element (a cycle, or children shared by two
/// parents) is an error.
pub fn triangle_means(elements: &[Element], which: Which) -> Result<Vec<([f64; 3], f64)>, CompareError> {
    let n = elements.len();
    let mut means = Vec::new();
    let mut stack = Vec::new();
    let mut visits = 0usize;
    for (t, triangle) in elements.iter().enumerate().take(input_triangles(elements)) {
        let (mut sum, mut area) = ([0.0f64; 3], 0.0f64);
        stack.push(t);
        while let Some(i) = stack.pop() {
            visits += 1;
            if visits > n {
                return Err(CompareError::Malformed {
                    which,
                    what: format!(
                        "element hierarchy below triangle {t} revisits an element (a cycle or shared children)"
                    ),
                });
            }
            let e = &elements[i];
            if e.is_leaf() {
                let w = f64::from(e.area);
                for (total, &b) in sum.iter_mut().zip(&e.radiosity) {
                    *total += w * f64::from(b);
                }
                area += w;
            } else {
                let first = e.first_child as usize;
                if first + 4 > n {
                    return Err(CompareError::Malformed {
                        which,
                        what: format!("element {i} has children outside the table"),
                    });
                }
                stack.extend((first..first + 4).rev());
            }
        }
        let mean = if area > 0.0 { sum.map(|s| s / area) } else { triangle.radiosity.map(f64::from) };
        means.push((mean, f64::from(triangle.area)));
    }
    Ok(means)
}

/// The mesh a solution was solved on, as its provenance records it: for
/// each of its inputs that mesh-prep made (mesh, manifest, surface),
/// mesh-prep's parameters and the hashes of the files it read (the scene
/// file, OBJ, MTL, ...), sorted. `None` where no input records mesh-prep.
/// Two solutions with the same record were solved on the same mesh,
/// whatever their files' paths: mesh-prep's output is a function of these.
pub fn mesh_record(s: &Solution) -> Option<Vec<(String, Vec<String>)>> {
    let mut record: Vec<(String, Vec<String>)> = s
        .header
        .provenance
        .inputs
        .iter()
        .filter_map(|input| input.made_by.as_deref())
        .filter(|made_by| made_by.stage == "mesh-prep")
        .map(|prep| {
            let mut read: Vec<String> = prep.inputs.iter().map(|i| i.sha256.clone()).collect();
            read.sort();
            (prep.parameters.get_ron().to_string(), read)
        })
        .collect();
    record.sort();
    record.dedup();
    (!record.is_empty()).then_some(record)
}

/// The samples comparing solution `a` with reference `b`, and the mode
/// used: [`Mode::Leaves`] when [`same_structure`], else
/// [`Mode::Triangles`]. Weights are the reference's areas. Different input
/// triangle counts mean different meshes: an error. So do input triangle
/// areas differing by more than [`AREA_TOLERANCE`] (relative), unless both
/// solutions record the same mesh-prep run ([`mesh_record`]): an element's
/// area is the part of it open to the scene, which hierarchical-solve
/// estimates per leaf, so a floor triangle under a block has another area
/// at another EPS on the very same mesh.
pub fn samples(a: &Solution, b: &Solution) -> Result<(Mode, Vec<Sample>), CompareError> {
    check(&a.elements, Which::A)?;
    check(&b.elements, Which::B)?;
    let (ta, tb) = (input_triangles(&a.elements), input_triangles(&b.elements));
    if ta != tb {
        return Err(CompareError::Malformed {
            which: Which::A,
            what: format!("has {ta} input triangles but the reference has {tb}: not the same mesh"),
        });
    }
    let same_mesh = matches!((mesh_record(a), mesh_record(b)), (Some(x), Some(y)) if x == y);
    if !same_mesh {
        for t in 0..ta {
            let (area_a, area_b) = (f64::from(a.elements[t].area), f64::from(b.elements[t].area));
            if (area_a - area_b).abs() > AREA_TOLERANCE * area_a.abs().max(area_b.abs()) {
                return Err(CompareError::Malformed {
                    which: Which::A,
                    what: format!("input triangle {t} has area {area_a} but {area_b} in the reference, and their provenance does not record one mesh-prep run: not the same mesh"),
                });
            }
        }
    }
    if same_structure(&a.elements, &b.elements) {
        let samples = a
            .elements
            .iter()
            .zip(&b.elements)
            .filter(|(_, y)| y.is_leaf())
            .map(|(x, y)| Sample {
                a: x.radiosity.map(f64::from),
                b: y.radiosity.map(f64::from),
                weight: f64::from(y.area),
            })
            .collect();
        return Ok((Mode::Leaves, samples));
    }
    let (ma, mb) = (triangle_means(&a.elements, Which::A)?, triangle_means(&b.elements, Which::B)?);
    let samples = ma.iter().zip(&mb).map(|(x, y)| Sample { a: x.0, b: y.0, weight: y.1 }).collect();
    Ok((Mode::Triangles, samples))
}
