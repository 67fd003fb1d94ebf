// Planar mirrors and thin glass (004 Sec. 4.3.2-4.3.3): the receiver side
// of the reflection tree, appended to solver.wgsl only for a scene with
// specular materials. The host walks the tree depth first; `levels` holds
// the branch to the node being shot (level 0 the root's first child), and
// a virtual sample of level l for the batch's sample i is
// samples[virtual_base + l sample_count + i] (the sample mirrored in every
// mirror of the branch, kept where a pane transmits), seen through the
// frustum views[l sample_count + i] into layer levels[l].window.z + i.

@group(0) @binding(15) var<storage, read> levels: array<Level>;
// Window entries: rgb the coefficient (rho_s of a mirror, tau_s of a
// pane), w the triangle's bits.
@group(0) @binding(16) var<storage, read> windows: array<vec4<f32>>;
@group(0) @binding(17) var<storage, read> views: array<View>;
// Per triangle: bit 0 it is specular, bit 1 the last mark pass found it lit.
@group(0) @binding(18) var<storage, read_write> hits: array<atomic<u32>>;

// Signed distance of x from level l's plane.
fn beyond(l: u32, x: vec3<f32>) -> f32 {
    return dot(levels[l].plane.xyz, x) + levels[l].plane.w;
}

fn virtual_sample(l: u32, i: u32) -> Sample {
    return samples[params.virtual_base + l * params.sample_count + i];
}

// Whether p (plane normal nr) is the nearest surface beyond level l's
// window along the ray from its virtual sample i (the frustum map).
fn seen_through(l: u32, i: u32, p: vec3<f32>, nr: vec3<f32>) -> bool {
    let view = views[l * params.sample_count + i];
    let v = p - virtual_sample(l, i).position.xyz;
    let q = vec3<f32>(dot(v, view.right.xyz), dot(v, view.up.xyz), dot(v, view.axis.xyz));
    if (q.z <= 0.0 || abs(q.x) > q.z || abs(q.y) > q.z) { return false; }
    // The plane's normal in the scaled coordinates: the inverse transpose.
    let k2 = view.axis.w * view.axis.w;
    let m = vec3<f32>(dot(nr, view.right.xyz) / k2, dot(nr, view.up.xyz) / k2, dot(nr, view.axis.xyz));
    return visible_face(levels[l].window.z + i, q, m);
}

// Where a segment crosses a window: the point, and the window entry of
// the triangle crossed there (NONE outside the window).
struct Crossing {
    point: vec3<f32>,
    entry: u32,
};

// Where the segment from `src` (behind level l's plane) to `dst` (in
// front) crosses the window.
fn crossing(l: u32, src: vec3<f32>, dst: vec3<f32>) -> Crossing {
    let a = beyond(l, src);
    let c = beyond(l, dst);
    if (!(a < 0.0 && c > 0.0)) { return Crossing(dst, NONE); }
    let b = src + (dst - src) * (a / (a - c));
    let w = levels[l].window;
    for (var e = w.x; e < w.x + w.y; e += 1u) {
        let t = bitcast<u32>(windows[e].w);
        let p0 = vertices[3u * t].xyz;
        let uv = barycentric(b - p0, vertices[3u * t + 1u].xyz - p0, vertices[3u * t + 2u].xyz - p0);
        if (uv.x >= 0.0 && uv.y >= 0.0 && uv.x + uv.y <= 1.0) { return Crossing(b, e); }
    }
    return Crossing(b, NONE);
}

// The product of the specular coefficients (Eq. 4.5, 4.7: rho_s^*) along
// the path from the batch's sample i through the windows of levels
// top, ..., 0 to p on the plane with normal nr: each leg must be seen in
// its level's map (the receiver beyond the window, then each window
// through its parent's, which holds the parent's possible occluders:
// mirror-object-mirror occlusion) and cross its window inside (partial
// visibility through the parents' windows); 0 where one is not.
fn through_windows(i: u32, p: vec3<f32>, nr: vec3<f32>, top: u32) -> vec3<f32> {
    var coef = vec3<f32>(1.0);
    var x = p;
    var n = nr;
    for (var l = top + 1u; l > 0u; l -= 1u) {
        if (!seen_through(l - 1u, i, x, n)) { return vec3<f32>(0.0); }
        let c = crossing(l - 1u, virtual_sample(l - 1u, i).position.xyz, x);
        let e = c.entry;
        if (e == NONE) { return vec3<f32>(0.0); }
        coef *= windows[e].xyz;
        x = c.point;
        let t = bitcast<u32>(windows[e].w);
        n = normalize(cross(vertices[3u * t + 1u].xyz - vertices[3u * t].xyz, vertices[3u * t + 2u].xyz - vertices[3u * t].xyz));
        if (l == 1u) {
            // The first window seen from the real sample, in its own maps.
            let s = samples[params.sample_first + i];
            let v = x - s.position.xyz;
            let local = vec3<f32>(dot(v, s.t.xyz), dot(v, s.b.xyz), dot(v, s.n.xyz));
            if (!seen_in_maps(i * params.layers_per_sample, t, x, n, local, s, s.power.w != 0.0)) { return vec3<f32>(0.0); }
        }
    }
    return coef;
}

// The irradiance the texel k (one that `receives`) gathers from the
// batch's virtual samples of the node at level params.level - 1: Eq.
// 4.7's F V rho_s^* per sample, with the form factors of the mirrored
// samples (area_transfer, or the mirrored light's intensity, whose frame
// is mirrored too so the table is read in the light's own angles).
fn irradiance_mirrored(k: u32) -> vec3<f32> {
    let texel = texels[k];
    let p = texel.position.xyz;
    let nr = texel.normal.xyz;
    let ns = texel.shading.xyz;
    let top = params.level - 1u;
    var h = vec3<f32>(0.0);
    if (beyond(top, p) <= plane_offset()) { return h; }
    for (var i = 0u; i < params.sample_count; i += 1u) {
        let s = virtual_sample(top, i);
        let v = p - s.position.xyz;
        let d2 = dot(v, v);
        let d = sqrt(d2);
        let cos_plane = -dot(nr, v) / d;
        if (d <= 0.0 || cos_plane <= 0.0) { continue; }
        var cos_r = cos_plane;
        if (any(ns != nr)) { cos_r = max(-dot(ns, v) / d, 0.0); }
        let light = s.power.w != 0.0;
        let local = vec3<f32>(dot(v, s.t.xyz), dot(v, s.b.xyz), dot(v, s.n.xyz));
        if (!light && behind_shooter(s, p)) { continue; }
        let cos_s = shooter_cosine(s, v, d, local.z);
        let coef = through_windows(i, p, nr, top);
        if (all(coef == vec3<f32>(0.0))) { continue; }
        if (light) {
            let gamma = degrees(acos(clamp(cos_s, -1.0, 1.0)));
            h += coef * s.power.xyz * ldt_lookup(degrees(atan2(local.y, local.x)), gamma) * cos_r / d2;
        } else {
            h += coef * s.power.xyz * area_transfer(k, p, nr, ns, s, d2, cos_s, cos_r);
        }
    }
    return h;
}

// The irradiance of a receiver pass (receive, receive_translucent): the
// real samples' at level 0, the node's virtual samples' below (Eq.
// 4.7-4.8: rho_d H into the radiosity and the residual, as for any shot).
fn gathered(k: u32) -> vec3<f32> {
    if (params.level == 0u) { return irradiance(k); }
    return irradiance_mirrored(k);
}

// The specular triangles the pass lit (004 Sec. 4.3.2: "if specular
// surfaces are encountered" they become the node's children): a texel of
// one that gathers light marks its triangle.
@compute @workgroup_size(64)
fn mark_specular(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let k = id.x + id.y * nw.x * 64u;
    if (k >= params.n_texels || !receives(k)) { return; }
    let t = bitcast<u32>(texels[k].normal.w);
    if ((atomicLoad(&hits[t]) & 1u) == 0u) { return; }
    if (any(gathered(k) > vec3<f32>(0.0))) { atomicOr(&hits[t], 2u); }
}
