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
