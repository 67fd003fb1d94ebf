//! Small artifacts of every kind, made in memory with the `schemas` types
//! and valid by construction: the seeds of the artifact fuzz targets and
//! the fixtures of tests that corrupt them.

use schemas::cluster::{ClusterNode, Clusters};
use schemas::exr_io::{Channel, ExrArtifact, Layer, Samples};
use schemas::header::{Provenance, Schema};
use schemas::image::{HdrImage, PixelSurfaces, EMITTER, NO_SURFACE, SINGLE_SURFACE};
use schemas::lightmap::{Lightmap, Region};
use schemas::mesh::{Camera, Effects, Manifest, Material, Mesh, MeshStatistics, Triangle};
use schemas::solution::{ClusterRadiosity, Element, LeafSlope, Link, Node, Solution, NONE};
use schemas::surface::{self, Surface, Texture, TextureKind};

/// The provenance of every artifact here: one in-memory "run", so that a
/// mesh and a manifest of this module belong together.
fn provenance() -> Provenance {
    Provenance::in_memory("end-to-end fixtures")
}

/// A closed unit box, walls facing in: 12 triangles of material 0
/// (reflectance 0.5), the two of the ceiling of material 1 (emitting 1
/// W/m²), one object per wall pair.
pub fn closed_box() -> (Mesh, Manifest) {
    let positions: Vec<[f32; 3]> = (0..8).map(|i| [(i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32]).collect();
    // Quads (counter-clockwise seen from inside) of the faces x=0, x=1,
    // y=0, y=1 (the ceiling), z=0, z=1.
    let quads = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
    let mut triangles = Vec::new();
    for (face, q) in quads.iter().enumerate() {
        for vertices in [[q[0], q[1], q[2]], [q[0], q[2], q[3]]] {
            let [a, b, c] = vertices.map(|v| positions[v as usize]);
            let (u, w) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
            let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let material = u32::from(face == 3);
            triangles.push(Triangle { vertices, material, object: face as u32 / 2, area: length / 2.0, normal: n.map(|x| x / length) });
        }
    }
    let manifest = Manifest {
        header: Manifest::header(provenance()),
        world_from_mesh_translation: [0.0; 3],
        camera: Camera { eye: [0.5, 0.5, 0.05], target: [0.5, 0.5, 1.0], up: [0.0, 1.0, 0.0], vertical_fov_deg: 60.0, width: 8, height: 6 },
        materials: vec![Material::diffuse("wall", [0.5; 3], [0.0; 3]), Material::diffuse("lamp", [0.0; 3], [1.0; 3])],
        objects: vec!["sides".into(), "floor and ceiling".into(), "ends".into()],
        goniometric_lights: vec![],
        effects: Effects { diffuse_interreflection: true, ..Effects::default() },
        statistics: MeshStatistics { triangles: 12, vertices: 8, total_area: 6.0, emitting_area: 1.0, ..MeshStatistics::default() },
    };
    (Mesh { header: Mesh::header(provenance()), positions, triangles }, manifest)
}

/// A cluster hierarchy over `mesh`'s triangles in input order: each
/// cluster of more than two triangles split into halves, breadth first.
pub fn clusters_over(mesh: &Mesh) -> Clusters {
    let node = |parent: u32, first: u32, count: u32| ClusterNode {
        parent,
        first_child: NONE,
        child_count: 0,
        first_triangle: first,
        triangle_count: count,
        bounds_min: [0.0; 3],
        bounds_max: [1.0; 3],
        area: count as f32 * 0.5,
        reflectance_area: [count as f32 * 0.25; 3],
        normal_axis: [0.0, 0.0, 1.0],
        normal_cos: -1.0,
    };
    let mut nodes = vec![node(NONE, 0, mesh.triangles.len() as u32)];
    let mut next = 0;
    while next < nodes.len() {
        let (first, count) = (nodes[next].first_triangle, nodes[next].triangle_count);
        if count > 2 {
            let half = count / 2;
            nodes[next].first_child = nodes.len() as u32;
            nodes[next].child_count = 2;
            nodes.push(node(next as u32, first, half));
            nodes.push(node(next as u32, first + half, count - half));
        }
        next += 1;
    }
    Clusters { header: Clusters::header(provenance()), nodes, order: (0..mesh.triangles.len() as u32).collect() }
}

/// A solution over `mesh`: one element per triangle, triangle 0 split
/// into four, a link from every root to the next and one from a cluster,
/// and a slope on leaf 1 and on the last child of triangle 0.
pub fn solution(mesh: &Mesh) -> Solution {
    let element = |triangle: u32, parent: u32, level: u32| Element {
        triangle,
        parent,
        first_child: NONE,
        level,
        corners: [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
        area: 0.5 / 4f32.powi(level as i32),
        radiosity: [0.25 + triangle as f32; 3],
    };
    let roots = mesh.triangles.len() as u32;
    let mut elements: Vec<Element> = (0..roots).map(|t| element(t, NONE, 0)).collect();
    elements[0].first_child = roots;
    elements.extend((0..4).map(|_| element(0, 0, 1)));
    let link = |receiver: Node, sender: Node| Link {
        receiver,
        sender,
        form_factor: 0.125,
        visibility: 0.5,
        unoccluded_irradiance: [0.5; 3],
        occluder_distance: if receiver < sender { f32::INFINITY } else { 0.25 },
    };
    let mut links: Vec<Link> = (0..roots).map(|t| link(Node::Element(t), Node::Element((t + 1) % roots))).collect();
    links.push(link(Node::Element(roots), Node::Cluster(0)));
    let clusters = vec![ClusterRadiosity { area: 6.0, radiosity: [0.5; 3] }];
    let slopes = vec![
        LeafSlope { element: 1, gradient: [[0.5, -0.25, 0.0], [0.125, 0.0, -1.0], [0.0, 2.0, 0.75]] },
        LeafSlope { element: roots + 3, gradient: [[-0.5, 0.0, 0.25]; 3] },
    ];
    Solution { header: Solution::header(provenance()), elements, clusters, links, slopes }
}

/// A lightmap of `mesh`: a region of 2 x 2 interior texels per triangle,
/// side by side in a row of the atlas.
pub fn lightmap(mesh: &Mesh) -> Lightmap {
    let (width, height) = (4 * mesh.triangles.len(), 4);
    let n = width * height;
    let regions = (0..mesh.triangles.len() as u32).map(|t| Region { x: 4 * t, y: 0, size: 2, covered: 3, texel_area: 0.25 }).collect();
    Lightmap {
        header: Lightmap::header(provenance()),
        width,
        height,
        radiosity: (0..n).map(|i| [i as f32 * 0.01; 3]).collect(),
        residual: vec![[0.0, 0.125, -0.25]; n],
        coverage: (0..n).map(|i| [0.0, 0.5, 1.0][i % 3]).collect(),
        texel_area: vec![0.25; n],
        position: vec![[0.5, 0.25, 0.0]; n],
        normal: vec![[0.0, 0.0, 1.0]; n],
        regions,
    }
}

/// A 4 x 3 image with its surface channels: a miss, an emitter, edges.
pub fn image() -> HdrImage {
    let n = 12;
    let object = (0..n).map(|i| if i == 0 { NO_SURFACE } else { i as u32 % 3 }).collect();
    let material = (0..n).map(|i| if i == 0 { NO_SURFACE } else { u32::from(i == 5) }).collect();
    let flags = (0..n).map(|i| match i {
        0 => 0,
        5 => SINGLE_SURFACE | EMITTER,
        _ => SINGLE_SURFACE,
    });
    HdrImage {
        header: HdrImage::header(provenance()),
        width: 4,
        height: 3,
        rgb: (0..n).map(|i| [i as f32, 0.5, 2.0]).collect(),
        coverage: (0..n).map(|i| if i == 0 { 0.0 } else { 1.0 }).collect(),
        surfaces: Some(PixelSurfaces { object, material, flags: flags.collect() }),
    }
}

/// Every sample of the table layer `layer`, record after record, each
/// channel's as a little-endian word (`f32` as its bits): what a
/// structural fuzz target mutates.
pub fn table_words(layer: &Layer) -> Vec<u8> {
    (0..layer.len())
        .flat_map(|i| {
            layer.channels.iter().map(move |c| match &c.samples {
                Samples::F32(v) => v[i].to_bits(),
                Samples::U32(v) => v[i],
            })
        })
        .flat_map(u32::to_le_bytes)
        .collect()
}

/// `layer` with its records read from `words` (as [`table_words`] writes
/// them): one record per whole group of words, so a mutant may have more
/// or fewer records than `layer`.
pub fn with_table_words(layer: &Layer, words: &[u8]) -> Layer {
    let width = layer.channels.len().max(1);
    let values: Vec<u32> = words.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect();
    let records = values.len() / width;
    let values = &values;
    let column = |k: usize| (0..records).map(move |i| values[i * width + k]);
    let channels = layer
        .channels
        .iter()
        .enumerate()
        .map(|(k, c)| Channel {
            samples: match c.samples {
                Samples::F32(_) => Samples::F32(column(k).map(f32::from_bits).collect()),
                Samples::U32(_) => Samples::U32(column(k).collect()),
            },
            ..c.clone()
        })
        .collect();
    Layer::table(&layer.name, records, channels)
}

/// `artifact` with its table layer `name` replaced by the records of
/// `words` (see [`with_table_words`]).
pub fn with_layer_words(artifact: &ExrArtifact, name: &str, words: &[u8]) -> ExrArtifact {
    let layers = artifact.layers.iter().map(|l| if l.name == name { with_table_words(l, words) } else { l.clone() }).collect();
    ExrArtifact { layers, ..artifact.clone() }
}

/// World corners of solution element `e`: its barycentric corners mapped
/// onto its mesh triangle, plus the mesh frame's world translation.
pub fn leaf_world_corners(mesh: &Mesh, origin: [f64; 3], e: &Element) -> [[f64; 3]; 3] {
    let t = &mesh.triangles[e.triangle as usize];
    let [p0, p1, p2] = t.vertices.map(|v| mesh.positions[v as usize].map(f64::from));
    e.corners.map(|c| {
        let uv = c.map(f64::from);
        std::array::from_fn(|a| p0[a] + (p1[a] - p0[a]) * uv[0] + (p2[a] - p0[a]) * uv[1] + origin[a])
    })
}

/// A surface artifact for `mesh` with `materials` materials: corner
/// coordinates and a tangent on the first triangle, shading normals on
/// the second, and a 2 x 2 diffuse texture on material 0.
pub fn surface(mesh: &Mesh, materials: usize) -> Surface {
    let n = mesh.triangles[1].normal;
    let texture = Texture {
        kind: TextureKind::Diffuse,
        width: 2,
        height: 2,
        texels: vec![[0.5, 0.25, 0.125, 1.0]; 4],
        scale: [1.0; 2],
        offset: [0.0; 2],
        clamp: false,
        strength: 1.0,
    };
    let mut material_maps = vec![[surface::NONE; 3]; materials];
    material_maps[0][0] = 0;
    Surface {
        header: Surface::header(Provenance::in_memory("end-to-end fixture")),
        uvs: vec![(0, [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])],
        shading_normals: vec![(1, [n; 3])],
        tangents: vec![(0, [1.0, 0.0, 0.0, 1.0])],
        material_maps,
        textures: vec![texture],
    }
}
