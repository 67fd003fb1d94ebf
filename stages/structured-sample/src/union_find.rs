//! Union-find over indices `0..n` (a `parent` slice, each root its own
//! parent): the isolux regions a surface's triangles merge into
//! ([`crate::emitters`]) and the curved surfaces facets join
//! ([`crate::surfaces`]).

/// The root of `i`, halving the path on the way.
pub fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Joins the sets of `i` and `j` under the lower of their roots.
pub fn union(parent: &mut [usize], i: usize, j: usize) {
    let (ri, rj) = (find(parent, i), find(parent, j));
    parent[ri.max(rj)] = ri.min(rj);
}
