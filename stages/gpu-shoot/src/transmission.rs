//! Diffuse transmission (paper 004 Sec. 4.3.1, Eq. 4.4): the pairing of
//! the texels of a translucent surface's two faces.
//!
//! A two-sided material's triangles come with twins from `mesh-prep` (the
//! same corners wound the other way), each with its own region of texels.
//! The light reaching one face leaves `rho_d H` from it and `tau_d H` from
//! its twin (the GPU side is in `solver.wgsl`, `transmit`), so each texel
//! of a translucent face needs the texel of the twin over the same place:
//! the one whose centre is nearest to its own (a twin's texel grid mirrors
//! its triangle's, so without adaptive subdivision the centres coincide
//! and the pairing is one to one). Adaptive subdivision may split the two
//! faces differently; the nearest texel is then a point sample of the
//! other face's irradiance, and power is conserved only as far as it
//! stands for its texel. The search is brute force over the twin's
//! texels: `n^2` for a face of `n` texels.
//! As in `hierarchical-solve`, a translucent material that is not
//! two-sided has no back face to leave the transmitted light from: it
//! transmits nothing, and the report counts its triangles.

use crate::atlas::Atlas;
use crate::tiling::Tile;
use glam::DVec3;
use schemas::mesh::{Manifest, Mesh};
use std::collections::HashMap;

/// Per covered texel: its diffuse transmittance (xyz) and its twin
/// texel's index bits (w; `u32::MAX` for none), as the GPU reads them.
pub type Table = Vec<[f32; 4]>;

/// The table for the texels of `atlas` (tiles `tiles` of `mesh`, whose
/// input triangles have `twins`), or `None` where no material transmits;
/// with it, the number of translucent input triangles that are not
/// two-sided and so transmit nothing.
pub fn table(atlas: &Atlas, tiles: &[Tile], mesh: &Mesh, manifest: &Manifest, twins: &[Option<u32>]) -> Option<(Table, usize)> {
    if !manifest.effects.diffuse_transmission {
        return None;
    }
    let material = |t: u32| &manifest.materials[mesh.triangles[t as usize].material as usize];
    let translucent = |t: u32| material(t).diffuse_transmittance.iter().any(|&x| x > 0.0);
    // The input triangle whose back each translucent input triangle is.
    let twin_of = |t: u32| twins[t as usize].filter(|&u| translucent(t) && material(t).two_sided && material(u).two_sided);
    let one_sided = (0..mesh.triangles.len() as u32).filter(|&t| translucent(t) && twin_of(t).is_none()).count();
    let root = |k: usize| tiles[atlas.texels[k].triangle as usize].root;
    let centre = |k: usize| DVec3::from(atlas.texels[k].position.map(f64::from));
    // The texels of every input triangle that is some translucent face's twin.
    let mut backs: HashMap<u32, Vec<usize>> = HashMap::new();
    for k in 0..atlas.texels.len() {
        if twin_of(root(k)).is_some() {
            backs.entry(root(k)).or_default().push(k);
        }
    }
    let table = (0..atlas.texels.len())
        .map(|k| {
            let t = root(k);
            let tau = material(t).diffuse_transmittance;
            let twin = twin_of(t)
                .and_then(|u| backs.get(&u))
                .and_then(|candidates| candidates.iter().copied().min_by(|&a, &b| centre(a).distance_squared(centre(k)).total_cmp(&centre(b).distance_squared(centre(k)))));
            match twin {
                Some(twin) => [tau[0] as f32, tau[1] as f32, tau[2] as f32, f32::from_bits(twin as u32)],
                None => [0.0, 0.0, 0.0, f32::from_bits(u32::MAX)],
            }
        })
        .collect();
    Some((table, one_sided))
}

#[cfg(test)]
mod tests {
    use super::*;
    use test_support::meshes::{manifest, material};
    use schemas::mesh::{Material, Triangle};

    /// A translucent two-sided quad (triangles 0, 1 and their twins 2, 3),
    /// a translucent one-sided triangle (4) and an opaque one (5): every
    /// texel of the quad's faces is paired with the twin's texel at the
    /// same centre, one to one (the pair of its pair is itself), carrying
    /// its material's tau_d; the others have no twin, and the one-sided
    /// translucent triangle is counted.
    #[test]
    fn the_texels_of_twin_faces_pair_one_to_one_at_the_same_place() {
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let triangle = |vertices: [u32; 3], material: u32, z: f32| Triangle { vertices, material, object: 0, area: 0.5, normal: [0.0, 0.0, z] };
        let triangles = vec![
            triangle([0, 1, 2], 0, 1.0),
            triangle([0, 2, 3], 0, 1.0),
            triangle([0, 2, 1], 0, -1.0),
            triangle([0, 3, 2], 0, -1.0),
            triangle([4, 5, 6], 1, 1.0),
            triangle([4, 6, 5], 2, -1.0),
        ];
        let mut mesh = test_support::meshes::triangles(&[]);
        mesh.positions = positions;
        mesh.triangles = triangles;
        let tau = [0.5, 0.4, 0.3];
        let sheet = Material { two_sided: true, diffuse_transmittance: tau, ..material([0.2; 3], [0.0; 3]) };
        let one_sided = Material { diffuse_transmittance: tau, ..material([0.2; 3], [0.0; 3]) };
        let mut m = manifest(1, vec![sheet, one_sided, material([0.5; 3], [0.0; 3])]);
        m.effects.diffuse_transmission = true;
        let atlas = crate::atlas::bake_sized(&mesh, vec![16], &vec![2; mesh.triangles.len()]);
        let tiles = crate::tiling::identity(&mesh);
        let (table, one_sided) = table(&atlas, &tiles, &mesh, &m, &mesh.twins()).unwrap();
        assert_eq!(one_sided, 1);
        let mut paired = 0;
        for (k, texel) in atlas.texels.iter().enumerate() {
            let twin = table[k][3].to_bits();
            if texel.triangle >= 4 {
                assert_eq!((twin, [table[k][0], table[k][1], table[k][2]]), (u32::MAX, [0.0; 3]), "texel {k}");
                continue;
            }
            let other = &atlas.texels[twin as usize];
            assert_eq!(table[twin as usize][3].to_bits(), k as u32, "texel {k}: not one to one");
            assert_eq!((texel.triangle + 2) % 4, other.triangle, "texel {k}");
            let distance = DVec3::from(texel.position.map(f64::from)).distance(DVec3::from(other.position.map(f64::from)));
            assert!(distance < 1e-6, "texel {k}: {distance}");
            assert_eq!([table[k][0], table[k][1], table[k][2]], tau.map(|x| x as f32));
            paired += 1;
        }
        assert!(paired > 200, "{paired}");
        m.effects.diffuse_transmission = false;
        assert!(super::table(&atlas, &tiles, &mesh, &m, &mesh.twins()).is_none(), "no table without the effect");
    }
}
