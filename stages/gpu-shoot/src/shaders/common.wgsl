// Shared by the compute kernels (solver.wgsl) and the visibility render
// (visibility.wgsl): the host-mirrored structs and the projections, so a
// receiver looks up exactly where the rasterizer wrote.

struct Params {
    n_texels: u32,
    n_tris: u32,
    shooter: u32,          // triangle that shoots, 0xffffffff for a light
    sample_first: u32,     // first sample of this batch
    sample_count: u32,     // samples in this batch
    layers_per_sample: u32,// 6 (cube faces) or 1 (stereographic)
    res: u32,              // visibility map side, pixels
    mode: u32,             // 0 cube faces, 1 stereographic
    overshoot: u32,        // 1: ambient overshooting (004 Eq. 4.9)
    group_count: u32,      // groups of the shooter
    level: u32,            // reflection tree: 1 + the level of the node shot (0: the real samples)
    virtual_base: u32,     // reflection tree: the first virtual sample
    tolerance: f32,        // relative depth tolerance of the visibility test
    near: f32,             // near plane of the cube faces, m
    far: f32,              // far distance, m
    total_area: f32,       // sum of triangle areas, m^2
    interreflection: vec4<f32>, // rgb: R of 004 Eq. 2.6, per channel
};

// A shooting sample: a group of texels, or a point light (power.w = 1).
struct Sample {
    position: vec4<f32>, // xyz: m; w: area of the group, m^2
    t: vec4<f32>,        // frame: tangent (light: r0, the C0 direction)
    b: vec4<f32>,        // frame: bitangent (light: u0 = n0 x r0)
    n: vec4<f32>,        // frame: normal (light: n0, the nadir)
    power: vec4<f32>,    // rgb: unshot radiosity dB of the group, W/m^2 (light: I_max, W/sr); w: kind
    shading: vec4<f32>,  // xyz: the group's normal for its cosine (normal map; else n); w: opaque fraction of its polygon
    polygon: array<vec4<f32>, 5>, // xyz: corners of the group's part of the shooter, m; [0].w: their number; [1].w: its area (extent), m^2
    hidden: array<vec4<f32>, 8>,  // xyz: corners of its buried part (HIDDEN_CORNERS), m; [0].w: their number (0: none)
    quadrants: array<vec4<f32>, 8>, // the group's quadrants about its point (prepare_samples): [2q] xyz their centroid, m, w area, m^2; [2q+1] xyz sum A (dB - mean), W
};

// Which cube face looks along which axis of the sample frame, and the
// face's (right, up, forward) coordinates of a local vector. Side faces
// have "up" = the frame normal, so a hemicube needs only their top half.
fn face_coords(face: u32, l: vec3<f32>) -> vec3<f32> {
    switch face {
        case 0u: { return vec3<f32>(l.x, l.y, l.z); }
        case 1u: { return vec3<f32>(l.y, l.z, l.x); }
        case 2u: { return vec3<f32>(-l.y, l.z, -l.x); }
        case 3u: { return vec3<f32>(-l.x, l.z, l.y); }
        case 4u: { return vec3<f32>(l.x, l.z, -l.y); }
        default: { return vec3<f32>(l.x, -l.y, -l.z); }
    }
}

// The face whose forward axis is the largest component of l.
fn face_of(l: vec3<f32>) -> u32 {
    var best = 0u;
    var value = l.z;
    if (l.x > value) { best = 1u; value = l.x; }
    if (-l.x > value) { best = 2u; value = -l.x; }
    if (l.y > value) { best = 3u; value = l.y; }
    if (-l.y > value) { best = 4u; value = -l.y; }
    if (-l.z > value) { best = 5u; }
    return best;
}

// Stereographic projection of the unit direction w onto the unit disc
// (004 Sec. 2.3: the hemisphere above the shooter in one pass).
fn stereographic(w: vec3<f32>) -> vec2<f32> {
    return w.xy / max(1.0 + w.z, 1e-3);
}

// The barycentrics (u, v) of the point p0 + x in the triangle with edges
// e1, e2 from its corner p0 (x = u e1 + v e2 for a point in its plane).
fn barycentric(x: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>) -> vec2<f32> {
    let d11 = dot(e1, e1);
    let d12 = dot(e1, e2);
    let d22 = dot(e2, e2);
    let det = d11 * d22 - d12 * d12;
    return vec2<f32>(d22 * dot(x, e1) - d12 * dot(x, e2), d11 * dot(x, e2) - d12 * dot(x, e1)) / det;
}
