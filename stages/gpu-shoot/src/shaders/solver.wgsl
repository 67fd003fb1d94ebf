// Progressive radiosity kernels over the compact list of covered texels
// (004 Sec. 2.2-2.3, 4.2, 4.3.5). One thread per texel or per triangle's
// workgroup; every sum runs in a fixed order (per-thread strided loops,
// then a fixed tree), so a rerun on the same device gives the same bits.

struct Texel {
    position: vec4<f32>, // xyz: centre, m; w: area it stands for, m^2
    normal: vec4<f32>,   // xyz: unit normal; w: triangle index (bitcast)
    rho: vec4<f32>,      // rgb: diffuse reflectance (material or texture); w: 1 on the hypotenuse
    shading: vec4<f32>,  // xyz: normal of the cosines (perturbed by a normal map)
};

struct Tri {
    first: u32,
    count: u32,
    group_first: u32,
    group_count: u32,
    area: f32,           // opaque area, m^2
    texel_area: f32,     // area of an interior texel, masks aside, m^2
    _p1: f32,
    _p2: f32,
    rho: vec4<f32>,
    half_u: vec4<f32>,   // xyz: (P1 - P0) / (2 size), half a texel's first edge, m
    half_v: vec4<f32>,   // xyz: (P2 - P0) / (2 size), half its second edge, m
};

struct Group {
    first: u32,
    count: u32,
    _p0: u32,
    _p1: u32,
};

struct Selection {
    shooter: vec4<u32>,     // x: triangle with the largest score
    overshoot: vec4<f32>,   // rgb: dB' of the shooter (004 Eq. 4.9), 0 without overshooting
    ambient: vec4<f32>,     // rgb: ambient term (004 Eq. 2.4-2.6), W/m^2
    unshot: vec4<f32>,      // rgb: sum dB A over covered texels, W
    unshot_abs: vec4<f32>,  // rgb: sum |dB| A, W
    score: vec4<f32>,       // x: the shooter's |dB + dB'| A summed over channels, W
};

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read_write> texels: array<Texel>;
@group(0) @binding(2) var<storage, read_write> radiosity: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> residual: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> tris: array<Tri>;
@group(0) @binding(5) var<storage, read_write> groups: array<Group>;
@group(0) @binding(6) var<storage, read_write> tri_power: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> selection: Selection;
@group(0) @binding(8) var<storage, read_write> samples: array<Sample>;
@group(0) @binding(9) var<storage, read_write> ldt: array<f32>;
@group(0) @binding(10) var visibility: texture_2d_array<f32>;
@group(0) @binding(11) var<storage, read> vertices: array<vec4<f32>>;

const WG: u32 = 256u;
const PI: f32 = 3.14159265358979;

var<workgroup> sum_a: array<vec4<f32>, 256>;
var<workgroup> sum_b: array<vec4<f32>, 256>;
var<workgroup> best_score: array<f32, 256>;
var<workgroup> best_index: array<u32, 256>;
var<workgroup> best_class: array<u32, 256>;

fn group_index(wg: vec3<u32>) -> u32 {
    return wg.x + wg.y * 32768u;
}

// Residual power of each triangle: sum over its covered texels of dB A
// (signed) and |dB| A, in tri_power[2t], tri_power[2t+1] (004 Sec. 2.3:
// only covered texels count).
@compute @workgroup_size(256)
fn reduce(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let t = group_index(wg);
    if (t >= params.n_tris) { return; }
    let tri = tris[t];
    var s = vec4<f32>(0.0);
    var a = vec4<f32>(0.0);
    for (var k = li; k < tri.count; k += WG) {
        let i = tri.first + k;
        let area = texels[i].position.w;
        let r = residual[i];
        s += vec4<f32>(r.xyz * area, area);
        a += vec4<f32>(abs(r.xyz) * area, 0.0);
    }
    sum_a[li] = s;
    sum_b[li] = a;
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride /= 2u) {
        if (li < stride) {
            sum_a[li] += sum_a[li + stride];
            sum_b[li] += sum_b[li + stride];
        }
        workgroupBarrier();
    }
    if (li == 0u) {
        tri_power[2u * t] = sum_a[0];
        tri_power[2u * t + 1u] = sum_b[0];
    }
}

fn overshoot_of(t: u32, total: vec3<f32>, ambient: vec3<f32>) -> vec3<f32> {
    let tri = tris[t];
    // A triangle an alpha mask removes whole has no area to overshoot.
    if (params.overshoot == 0u || tri.area <= 0.0) { return vec3<f32>(0.0); }
    let own = tri_power[2u * t].xyz;
    // 004 Eq. 4.9: dB'_i = min(rho_i ambient, sum_j dB_j A_j / A_i - dB_i),
    // never negative (a negative ambient would not converge).
    let rest = (total - own) / tri.area;
    return max(min(tri.rho.xyz * ambient, rest), vec3<f32>(0.0));
}

// Whether candidate (class ca, key va, index ia) beats (cb, vb, ib): the
// higher class, then the larger key, then the lower index.
fn beats(ca: u32, va: f32, ia: u32, cb: u32, vb: f32, ib: u32) -> bool {
    if (ca != cb) { return ca > cb; }
    if (va != vb) { return va > vb; }
    return ia < ib;
}

// Shooter selection (one workgroup), and the ambient term
// A = R sum_j dB_j A_j / sum_k A_k (004 Eq. 2.4-2.6) in the same pass.
// 004 Sec. 4.3.5 shoots the triangle with the largest (dB + dB') A
// (channels summed, signed): class 1, key that sum, for every triangle
// where it is positive. Overshooting leaves negative residuals (-dB') that
// must be shot back too or the solution keeps light it should not have
// (Feda and Purgathofer); ranking them by magnitude with the rest would let
// a triangle that overshot a lamp's power shoot it back and forth while
// the lamp never shoots. So a negative remainder goes only once nothing
// positive is left: class 0, key |dB + dB'| A. Lowest index on ties.
@compute @workgroup_size(256)
fn select_shooter(@builtin(local_invocation_index) li: u32) {
    var s = vec4<f32>(0.0);
    var a = vec4<f32>(0.0);
    for (var t = li; t < params.n_tris; t += WG) {
        s += tri_power[2u * t];
        a += tri_power[2u * t + 1u];
    }
    sum_a[li] = s;
    sum_b[li] = a;
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride /= 2u) {
        if (li < stride) {
            sum_a[li] += sum_a[li + stride];
            sum_b[li] += sum_b[li + stride];
        }
        workgroupBarrier();
    }
    let total = sum_a[0].xyz;
    let ambient = params.interreflection.xyz * total / params.total_area;
    var rank = 0u;
    var score = -1.0;
    var index = 0xffffffffu;
    for (var t = li; t < params.n_tris; t += WG) {
        let own = tri_power[2u * t].xyz;
        let shot = own + overshoot_of(t, total, ambient) * tris[t].area;
        let net = shot.x + shot.y + shot.z;
        var c = 0u;
        var value = abs(shot.x) + abs(shot.y) + abs(shot.z);
        if (net > 0.0) { c = 1u; value = net; }
        if (beats(c, value, t, rank, score, index)) { rank = c; score = value; index = t; }
    }
    best_class[li] = rank;
    best_score[li] = score;
    best_index[li] = index;
    workgroupBarrier();
    for (var stride = WG / 2u; stride > 0u; stride /= 2u) {
        if (li < stride) {
            let j = li + stride;
            if (beats(best_class[j], best_score[j], best_index[j], best_class[li], best_score[li], best_index[li])) {
                best_class[li] = best_class[j];
                best_score[li] = best_score[j];
                best_index[li] = best_index[j];
            }
        }
        workgroupBarrier();
    }
    if (li == 0u) {
        let shooter = best_index[0];
        selection.shooter = vec4<u32>(shooter, 0u, 0u, 0u);
        var o = vec3<f32>(0.0);
        if (shooter != 0xffffffffu) { o = overshoot_of(shooter, total, ambient); }
        selection.overshoot = vec4<f32>(o, 0.0);
        selection.ambient = vec4<f32>(ambient, 0.0);
        selection.unshot = vec4<f32>(total, 0.0);
        selection.unshot_abs = sum_b[0];
        var magnitude = 0.0;
        if (shooter != 0xffffffffu) {
            let shot = tri_power[2u * shooter].xyz + o * tris[shooter].area;
            magnitude = abs(shot.x) + abs(shot.y) + abs(shot.z);
        }
        selection.score = vec4<f32>(magnitude, 0.0, 0.0, 0.0);
    }
}

// The shooter's samples (substructuring, 004 Sec. 2.3): each group shoots
// its texels' mean residual plus the overshoot dB'.
@compute @workgroup_size(64)
fn prepare_samples(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.group_count) { return; }
    let g = groups[tris[params.shooter].group_first + id.x];
    var sum = vec3<f32>(0.0);
    var area = 0.0;
    for (var k = 0u; k < g.count; k += 1u) {
        let a = texels[g.first + k].position.w;
        sum += residual[g.first + k].xyz * a;
        area += a;
    }
    // A group an alpha mask removes whole has no area and shoots nothing.
    var mean = vec3<f32>(0.0);
    if (area > 0.0) { mean = sum / area; }
    samples[id.x].power = vec4<f32>(mean + selection.overshoot.xyz, 0.0);
    // Its quadrants about its point, along the sample frame's axes, for the
    // variation beyond SQUARES (quadrant_variation).
    let origin = samples[id.x].position.xyz;
    let t = samples[id.x].t.xyz;
    let b = samples[id.x].b.xyz;
    var q_area = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    var q_point = array<vec3<f32>, 4>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    var q_power = array<vec3<f32>, 4>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    for (var k = 0u; k < g.count; k += 1u) {
        let a = texels[g.first + k].position.w;
        if (a <= 0.0) { continue; }
        let x = texels[g.first + k].position.xyz;
        var q = 0u;
        if (dot(x - origin, t) >= 0.0) { q += 1u; }
        if (dot(x - origin, b) >= 0.0) { q += 2u; }
        q_area[q] += a;
        q_point[q] += x * a;
        q_power[q] += (residual[g.first + k].xyz - mean) * a;
    }
    for (var q = 0u; q < 4u; q += 1u) {
        var point = vec3<f32>(0.0);
        if (q_area[q] > 0.0) { point = q_point[q] / q_area[q]; }
        samples[id.x].quadrants[2u * q] = vec4<f32>(point, q_area[q]);
        samples[id.x].quadrants[2u * q + 1u] = vec4<f32>(q_power[q], 0.0);
    }
}

// After the shot the shooter keeps -dB' (0 without overshooting).
@compute @workgroup_size(64)
fn finish_shooter(@builtin(global_invocation_id) id: vec3<u32>) {
    let tri = tris[params.shooter];
    if (id.x >= tri.count) { return; }
    residual[tri.first + id.x] = vec4<f32>(-selection.overshoot.xyz, 0.0);
}

// Whether a receiver at face coordinates q (normal m, same coordinates)
// is visible in cube face `layer` (004 Sec. 2.3 with the neighbour test of
// Fig. 2.3). Each pixel stores the distance to the nearest surface along
// its centre's ray; the receiver is compared not with its own distance
// but with the distance at which that same ray meets the receiver's plane,
// t |dir| with t = (m . q) / (m . dir). A plane seen at a grazing angle
// changes its distance by far more than any fixed tolerance from one pixel
// to the next, so comparing with the receiver's own distance hid the
// texels of a neighbouring wall from a shooter next to it (the closed box
// lost 1-2% of each wall shot that way). Visible when the centre pixel
// holds nothing nearer than the receiver's plane (within the tolerance),
// or one of its 8 neighbours holds the receiver's plane, unless the centre
// pixel holds an occluder well in front of that plane (far_occluder).
fn visible_face(layer: u32, q: vec3<f32>, m: vec3<f32>) -> bool {
    let res = f32(params.res);
    let px = (q.x / q.z * 0.5 + 0.5) * res;
    let py = (0.5 - q.y / q.z * 0.5) * res;
    let x = i32(floor(px));
    let y = i32(floor(py));
    let mq = dot(m, q);
    if (far_occluder(pixel_depths(layer, x, y, mq, m))) { return false; }
    for (var dy = -1; dy <= 1; dy += 1) {
        for (var dx = -1; dx <= 1; dx += 1) {
            let d = pixel_depths(layer, x + dx, y + dy, mq, m);
            if (d.y < 0.0) { continue; }
            let tol = params.tolerance * d.y;
            if (dx == 0 && dy == 0 && d.x >= d.y - tol) { return true; }
            if (abs(d.x - d.y) <= tol) { return true; }
        }
    }
    return false;
}

// Pixel (x, y) of cube face `layer` (clamped to the face) against the
// receiver's plane (normal m, m . q = mq): the distance it stores (x), the
// distance along its centre's ray to the plane (y; -1 where the ray does
// not meet the plane's front), that ray's length in face coordinates (z)
// and its cosine to the plane's normal (w).
fn pixel_depths(layer: u32, x: i32, y: i32, mq: f32, m: vec3<f32>) -> vec4<f32> {
    let res = f32(params.res);
    let cx = clamp(x, 0, i32(params.res) - 1);
    let cy = clamp(y, 0, i32(params.res) - 1);
    let dir = vec3<f32>((f32(cx) + 0.5) / res * 2.0 - 1.0, 1.0 - (f32(cy) + 0.5) / res * 2.0, 1.0);
    let md = dot(m, dir);
    let stored = textureLoad(visibility, vec2<i32>(cx, cy), i32(layer), 0).x;
    if (md >= 0.0 || mq >= 0.0) { return vec4<f32>(stored, -1.0, 0.0, 0.0); }
    let len = length(dir);
    return vec4<f32>(stored, mq / md * len, len, -md / len);
}

// Whether the centre pixel (its pixel_depths d) holds a surface nearer
// than the receiver's plane by more than FAR_PIXELS pixel footprints along
// its ray, measured where the ray meets the plane (the
// footprint grows as 1 / cos at a grazing plane): a real occluder, such as
// a block over its shadow, whose 8 neighbours must not make the receiver
// visible. The neighbour test exists for the surfaces that meet the
// receiver's plane (a wall at the floor), whose rasterized edge covers
// the centre pixels of the receiver's texels beside the crease; counted
// for every occluder, it lit a pixel-wide band inside every shadow
// (Cornell box at 128 pixels: floor +6.4%, short block +9.4% against
// Mitsuba, +0.7% and +3.4% at 512).
fn far_occluder(d: vec4<f32>) -> bool {
    if (d.y < 0.0) { return false; }
    // One pixel's footprint along the ray at the plane: its width there
    // (2 / res of the face's unit distance, times the distance over |dir|)
    // over the cosine of the ray to the plane's normal.
    let footprint = d.y / d.z * (2.0 / f32(params.res)) / max(d.w, 1e-3);
    return d.x < d.y - FAR_PIXELS * footprint - params.tolerance * d.y;
}

// Pixel footprints (far_occluder) beyond which a surface in front of the
// receiver's plane is an occluder, not a rasterized edge of a surface
// meeting the plane.
const FAR_PIXELS: f32 = 2.0;

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// Whether the receiver at p on triangle t is visible in the stereographic
// map `layer` of sample s. Only vertices are projected (004 Sec. 2.3), so
// the rasterizer maps each triangle affinely between its projected
// corners; the receiver is placed the same way (the paper's back
// projection with "the same error", 004 Sec. 2.3): at its barycentric
// combination of its triangle's projected corners. Each pixel stores the
// length of the linearly interpolated local position, so the distance the
// receiver's own triangle would leave at a pixel centre is that of the
// point with the pixel's barycentrics in the projected triangle; the test
// compares with it, as visible_face does with the receiver's plane.
fn visible_stereographic(layer: u32, t: u32, p: vec3<f32>, s: Sample) -> bool {
    var l: array<vec3<f32>, 3>;
    var m: array<vec2<f32>, 3>;
    for (var k = 0u; k < 3u; k += 1u) {
        let v = vertices[3u * t + k].xyz - s.position.xyz;
        l[k] = vec3<f32>(dot(v, s.t.xyz), dot(v, s.b.xyz), dot(v, s.n.xyz));
        m[k] = stereographic(l[k] / max(length(l[k]), 1e-20));
    }
    // Barycentrics of p in its triangle.
    let p0 = vertices[3u * t].xyz;
    let e1 = vertices[3u * t + 1u].xyz - p0;
    let e2 = vertices[3u * t + 2u].xyz - p0;
    let uv = barycentric(p - p0, e1, e2);
    let at = m[0] + uv.x * (m[1] - m[0]) + uv.y * (m[2] - m[0]);
    let res = f32(params.res);
    let x = i32(floor((at.x * 0.5 + 0.5) * res));
    let y = i32(floor((0.5 - at.y * 0.5) * res));
    let a = m[1] - m[0];
    let b = m[2] - m[0];
    let area = cross2(a, b);
    if (abs(area) < 1e-12) { return false; }
    for (var dy = -1; dy <= 1; dy += 1) {
        for (var dx = -1; dx <= 1; dx += 1) {
            let cx = clamp(x + dx, 0, i32(params.res) - 1);
            let cy = clamp(y + dy, 0, i32(params.res) - 1);
            let c = vec2<f32>((f32(cx) + 0.5) / res * 2.0 - 1.0, 1.0 - (f32(cy) + 0.5) / res * 2.0) - m[0];
            let bu = cross2(c, b) / area;
            let bv = cross2(a, c) / area;
            let own = length(l[0] + bu * (l[1] - l[0]) + bv * (l[2] - l[0]));
            let stored = textureLoad(visibility, vec2<i32>(cx, cy), i32(layer), 0).x;
            let tol = params.tolerance * own;
            if (dx == 0 && dy == 0 && stored >= own - tol) { return true; }
            if (abs(stored - own) <= tol) { return true; }
        }
    }
    return false;
}

fn catmull_rom(p0: f32, p1: f32, p2: f32, p3: f32, t: f32) -> f32 {
    let t2 = t * t;
    let t3 = t2 * t;
    return 0.5 * (2.0 * p1 + (p2 - p0) * t + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2 + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3);
}

// ldt layout: [nc, ng, c angles (nc), gamma angles (ng), values (nc x ng)].
fn interval(first: u32, n: u32, x: f32, periodic: bool) -> vec2<f32> {
    // Returns (index, fraction) of x in the angles at ldt[first..first+n].
    if (n == 1u) { return vec2<f32>(0.0, 0.0); }
    var k = 0u;
    for (var i = 1u; i < n; i += 1u) {
        if (ldt[first + i] <= x) { k = i; }
    }
    var lo = ldt[first + k];
    var hi = 0.0;
    if (k + 1u < n) {
        hi = ldt[first + k + 1u];
    } else if (periodic) {
        hi = ldt[first] + 360.0;
    } else {
        return vec2<f32>(f32(n - 2u), 1.0);
    }
    if (x < lo) { return vec2<f32>(0.0, 0.0); }
    return vec2<f32>(f32(k), clamp((x - lo) / (hi - lo), 0.0, 1.0));
}

fn ldt_row(c: u32, g: i32, gt: f32, ng: u32, nc: u32) -> f32 {
    let base = 2u + nc + ng + c * ng;
    let last = i32(ng) - 1;
    let p0 = ldt[base + u32(clamp(g - 1, 0, last))];
    let p1 = ldt[base + u32(clamp(g, 0, last))];
    let p2 = ldt[base + u32(clamp(g + 1, 0, last))];
    let p3 = ldt[base + u32(clamp(g + 2, 0, last))];
    return catmull_rom(p0, p1, p2, p3, gt);
}

// Normalised intensity at (C, gamma) degrees: bicubic Catmull-Rom, clamped
// along gamma, periodic along C (004 Sec. 3.4.1); mirrors Ldt::lookup.
fn ldt_lookup(c_deg: f32, gamma: f32) -> f32 {
    let nc = u32(ldt[0]);
    let ng = u32(ldt[1]);
    let gi = interval(2u + nc, ng, gamma, false);
    let g = i32(gi.x);
    if (nc == 1u) { return max(ldt_row(0u, g, gi.y, ng, nc), 0.0); }
    var c = c_deg - 360.0 * floor(c_deg / 360.0);
    if (c < ldt[2]) { c += 360.0; }
    let ci = interval(2u, nc, c, true);
    let k = i32(ci.x);
    let n = i32(nc);
    let r0 = ldt_row(u32((k - 1 + n) % n), g, gi.y, ng, nc);
    let r1 = ldt_row(u32(k % n), g, gi.y, ng, nc);
    let r2 = ldt_row(u32((k + 1) % n), g, gi.y, ng, nc);
    let r3 = ldt_row(u32((k + 2) % n), g, gi.y, ng, nc);
    return max(catmull_rom(r0, r1, r2, r3, ci.y), 0.0);
}

// Near field: a receiver nearer than sqrt(NEAR_FIELD (A_r + A_s)) gets the
// exact point-to-patch form factor; farther, the disc approximation, whose
// energy loss A_s / (pi d^2 + A_s) is then below 1 / (pi NEAR_FIELD).
const NEAR_FIELD: f32 = 100.0;

// Form factor from a differential area at the origin with normal n to the
// convex polygon corners[0..count] (relative to that area), clipped to its
// hemisphere: Lambert's contour formula, mirrors
// radiometry::form_factor::point_to_polygon.
fn polygon_form_factor(n: vec3<f32>, corners: array<vec3<f32>, 8>, count: u32) -> f32 {
    var clipped: array<vec3<f32>, 9>;
    var m = 0u;
    for (var k = 0u; k < count; k += 1u) {
        let a = corners[k];
        let b = corners[(k + 1u) % count];
        let za = dot(n, a);
        let zb = dot(n, b);
        if (za >= 0.0) { clipped[m] = a; m += 1u; }
        if ((za >= 0.0) != (zb >= 0.0)) { clipped[m] = a + (b - a) * (za / (za - zb)); m += 1u; }
    }
    var sum = 0.0;
    for (var k = 0u; k < m; k += 1u) {
        let a = clipped[k];
        let b = clipped[(k + 1u) % m];
        let c = cross(a, b);
        let s = length(c);
        if (s > 0.0) { sum += atan2(s, dot(a, b)) * dot(n, c) / s; }
    }
    return abs(sum) / (2.0 * PI);
}

// A sample this many times larger than a texel in its near field is
// taken by reciprocity (area_transfer); mirrors reference::RECIPROCAL.
const RECIPROCAL: f32 = 16.0;

// The area of texel k's square (half on the hypotenuse), an alpha mask
// aside: the patch the near field integrates over.
fn patch_area(k: u32) -> f32 {
    let a = tris[bitcast<u32>(texels[k].normal.w)].texel_area;
    if (texels[k].rho.w != 0.0) { return 0.5 * a; }
    return a;
}

// Whether texel k at squared distance d2 is in the near field of area
// sample s (by the sample's extent, area_transfer).
fn near(k: u32, s: Sample, d2: f32) -> bool {
    return d2 < NEAR_FIELD * (patch_area(k) + s.polygon[1].w);
}

// Whether texel k takes area sample s, at squared distance d2, by
// reciprocity.
fn reciprocal(k: u32, s: Sample, d2: f32) -> bool {
    return near(k, s, d2) && s.polygon[1].w > RECIPROCAL * patch_area(k);
}

// The square of texel k (half of it on the hypotenuse) with its point at
// c, relative to the origin of the caller's choice.
struct Patch {
    corners: array<vec3<f32>, 8>,
    count: u32,
};

fn texel_patch(k: u32, c: vec3<f32>) -> Patch {
    let tri = tris[bitcast<u32>(texels[k].normal.w)];
    let a = tri.half_u.xyz;
    let b = tri.half_v.xyz;
    var square: Patch;
    if (texels[k].rho.w != 0.0) {
        // The hypotenuse texel stands for the half square whose centroid is c.
        let h = c + (a + b) / 3.0;
        square.corners[0] = h - a - b;
        square.corners[1] = h + a - b;
        square.corners[2] = h - a + b;
        square.count = 3u;
    } else {
        square.corners[0] = c - a - b;
        square.corners[1] = c + a - b;
        square.corners[2] = c + a + b;
        square.corners[3] = c - a + b;
        square.count = 4u;
    }
    return square;
}

// A receiver nearer to a group than sqrt(VARIATION) times the group's side
// (its extent's root) also takes the group's variation: each texel's
// square by Lambert's formula within sqrt(SQUARES) sides (variation), the
// group's quadrants as points beyond (quadrant_variation).
const VARIATION: f32 = 64.0;
const SQUARES: f32 = 4.0;

// What the receiving texel at p (cosines about ns) gets from the variation
// of the unshot radiosity over the shooter's group g about its mean: each
// texel's square by Lambert's formula, weighted by the texel's exposed,
// opaque fraction,
//   dH = sum_j (dB_j - mean) (A_j / A_j,square) F(p -> square_j).
// A group shoots its texels' mean over its polygon (less its buried
// part), which is right where the receiver is far from it next to the
// group's size; a receiver beside it sees the near texels' own radiosity.
// Only the variation is taken by squares: the squares of the exposed
// texels leave out the strip between the last one and a burying block's
// face, most of what the block's lowest texels see (-14% per texel on the
// cube of tests/tests/gpu_kernels.rs where the texels replaced the
// polygon). The short block's base in the Cornell box sees the floor's
// contact shadow in front of it, which the floor's groups spread over 8
// texels: its lowest rows were 15-100% too bright.
fn variation(p: vec3<f32>, ns: vec3<f32>, g: u32, mean: vec3<f32>) -> vec3<f32> {
    let group = groups[g];
    var h = vec3<f32>(0.0);
    for (var j = group.first; j < group.first + group.count; j += 1u) {
        let area = texels[j].position.w;
        if (area <= 0.0) { continue; }
        let square = texel_patch(j, texels[j].position.xyz - p);
        h += (residual[j].xyz - mean) * (area / patch_area(j)) * polygon_form_factor(ns, square.corners, square.count);
    }
    return h;
}

// The variation farther out, from the group's four quadrants about its
// point, each at its centroid with its unshot power about the mean
// (prepare_samples), point to point:
//   dH = sum_q sum_(j in q) A_j (dB_j - mean) cos_q cos_r / (pi d_q^2).
// The quadrants' powers sum to 0, so it fades with distance as the
// kernel's variation over the group does. A group's mean left the top
// of the wall in tests/tests/gpu_kernels.rs 2.2% bright (2 to 2.5 sides
// from the groups at its foot); taken texel by texel out to 8 sides,
// as points, the default Cornell box shot 3.2 times slower on lavapipe.
fn quadrant_variation(p: vec3<f32>, ns: vec3<f32>, s: Sample) -> vec3<f32> {
    var h = vec3<f32>(0.0);
    for (var q = 0u; q < 4u; q += 1u) {
        let quadrant = s.quadrants[2u * q];
        if (quadrant.w <= 0.0) { continue; }
        let v = quadrant.xyz - p;
        let d2 = dot(v, v);
        h += s.quadrants[2u * q + 1u].xyz * max(-dot(s.n.xyz, v), 0.0) * max(dot(ns, v), 0.0) / (PI * d2 * d2);
    }
    return h;
}

// Irradiance per unit radiosity of the area sample s on the receiving
// texel k at p (normal nr), with the cosines at the sample's point;
// mirrors reference::area_transfer. Far: the disc approximation. Near, the
// larger of the two patches is integrated exactly (Lambert's formula) and
// the smaller one taken as a point:
//   sample over RECIPROCAL texels:  H = F(p -> sample's polygon) - F(p -> its
//                                   buried part)  (reciprocity)
//   otherwise:      H = A_s F(s -> texel's patch) / A_r
// A sample's size here is its polygon's area (atlas::Group::extent), not
// its exposed area A_s: a floor group mostly buried under a block, taken
// as the point of its exposed texels, gave the block's lowest texels up to
// 1.8 times Lambert's value.
// A group of 8 x 8 texels taken as its centroid misplaced the power of its
// near part by half a group, +-90% on the texels next to a shared edge
// (issue 10, item 7), and a texel patch much smaller than its distance
// (a sliver's) lost its solid angle to f32 cancellation. At equal sizes
// the sample's point conserves power exactly, hence the threshold
// RECIPROCAL (see reference.rs). With surface detail (004 Sec. 2.3.3,
// 4.3.4) the receiver's cosines are its perturbed normal ns's (the patch
// factor, whose plane is the triangle's nr, scaled by cos_r over the
// plane's cosine), and a sample's polygon emits its opaque fraction.
fn area_transfer(k: u32, p: vec3<f32>, nr: vec3<f32>, ns: vec3<f32>, s: Sample, d2: f32, cos_s: f32, cos_r: f32) -> f32 {
    let a_r = patch_area(k);
    let a_s = s.position.w;
    if (!near(k, s, d2)) {
        // 004 Eq. 2.2 / 4.1 with one disc per sample.
        return a_s * cos_s * cos_r / (PI * d2 + a_s);
    }
    var corners: array<vec3<f32>, 8>;
    if (reciprocal(k, s, d2)) {
        // The group's polygon less its buried part (atlas::Group::hidden).
        let m = u32(s.polygon[0].w);
        for (var c = 0u; c < m; c += 1u) { corners[c] = s.polygon[c].xyz - p; }
        var f = polygon_form_factor(ns, corners, m);
        let h = u32(s.hidden[0].w);
        if (h > 0u) {
            for (var c = 0u; c < h; c += 1u) { corners[c] = s.hidden[c].xyz - p; }
            f = max(f - polygon_form_factor(ns, corners, h), 0.0);
        }
        return s.shading.w * f;
    }
    let c = p - s.position.xyz;
    let square = texel_patch(k, c);
    // H_r = B_s A_s F_(s -> patch) / A_r: the power the patch receives
    // spread over its area, so the shares of a closed room sum to 1.
    var h = a_s * polygon_form_factor(s.shading.xyz, square.corners, square.count) / a_r;
    let cos_plane = -dot(nr, c) / sqrt(d2);
    if (any(ns != nr) && cos_plane > 0.0) { h *= cos_r / cos_plane; }
    return h;
}

// Whether the receiver at p (triangle tri, plane normal nr, `local` in
// the frame of sample s) is visible in the sample's maps, which start at
// layer `base`.
fn seen_in_maps(base: u32, tri: u32, p: vec3<f32>, nr: vec3<f32>, local: vec3<f32>, s: Sample, light: bool) -> bool {
    if (params.mode == 1u && !light) { return visible_stereographic(base, tri, p, s); }
    let face = face_of(local);
    let normal = vec3<f32>(dot(nr, s.t.xyz), dot(nr, s.b.xyz), dot(nr, s.n.xyz));
    return visible_face(base + face, face_coords(face, local), face_coords(face, normal));
}

// Adaptive subdivision (004 Sec. 2.4), before a triangle first shoots:
// per receiving triangle, the point-sample pairs facing each other (n_r,
// what a rasterization without depth test counts) in counts[2t], and
// those the visibility maps see (n_v) in counts[2t + 1]. The paper counts
// the receiver's fragments in the maps; here each texel tests COUNT_GRID
// x COUNT_GRID points of its square (its own point on the hypotenuse), so
// a boundary between two texel centres is found too. Bound only when the
// subdivision is on.
@group(0) @binding(12) var<storage, read_write> counts: array<atomic<u32>>;

const COUNT_GRID: u32 = 4u;

@compute @workgroup_size(64)
fn count_visible(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let k = id.x + id.y * nw.x * 64u;
    if (k >= params.n_texels) { return; }
    let texel = texels[k];
    let tri = bitcast<u32>(texel.normal.w);
    if (tri == params.shooter || texel.position.w <= 0.0) { return; }
    let nr = texel.normal.xyz;
    var grid = COUNT_GRID;
    if (texel.rho.w != 0.0) { grid = 1u; }
    var n_r = 0u;
    var n_v = 0u;
    for (var g = 0u; g < grid * grid; g += 1u) {
        var p = texel.position.xyz;
        if (grid > 1u) {
            let f = (vec2<f32>(f32(g % grid), f32(g / grid)) * 2.0 + 1.0) / f32(grid) - 1.0;
            p += f.x * tris[tri].half_u.xyz + f.y * tris[tri].half_v.xyz;
        }
        for (var i = 0u; i < params.sample_count; i += 1u) {
            let s = samples[params.sample_first + i];
            let v = p - s.position.xyz;
            if (dot(v, v) <= 0.0 || -dot(nr, v) <= 0.0 || dot(p - s.polygon[0].xyz, s.n.xyz) <= 0.0) { continue; }
            n_r += 1u;
            let local = vec3<f32>(dot(v, s.t.xyz), dot(v, s.b.xyz), dot(v, s.n.xyz));
            if (seen_in_maps(i * params.layers_per_sample, tri, p, nr, local, s, false)) { n_v += 1u; }
        }
    }
    if (n_r > 0u) {
        atomicAdd(&counts[2u * tri], n_r);
        atomicAdd(&counts[2u * tri + 1u], n_v);
    }
}

// Whether texel k receives this shot: not the shooter's, and not removed
// by an alpha mask (a texel it removes does not exist, 004 Sec. 4.3.4).
fn receives(k: u32) -> bool {
    let texel = texels[k];
    return bitcast<u32>(texel.normal.w) != params.shooter && texel.position.w > 0.0;
}

// The receiver pass (004 Sec. 2.3, Eq. 2.2 / 4.1-4.3): every covered texel
// tests its depth against each sample's visibility map and gathers
// (`gathered`: gather.wgsl's `irradiance`, or with specular materials
// mirrors.wgsl's, which also gathers a reflection-tree node's samples)
//   area sample:  H += dB_s A_s cos_s cos_r / (pi d^2 + A_s)
//   point light:  H += I_max LDT(C, gamma) cos_r / d^2      (Eq. 3.4)
// then adds rho H to both its radiosity and its residual.
@compute @workgroup_size(64)
fn receive(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let k = id.x + id.y * nw.x * 64u;
    if (k >= params.n_texels || !receives(k)) { return; }
    let db = texels[k].rho.xyz * gathered(k);
    radiosity[k] += vec4<f32>(db, 0.0);
    residual[k] += vec4<f32>(db, 0.0);
}

// Whether p lies behind the plane of the area sample s's shooter.
fn behind_shooter(s: Sample, p: vec3<f32>) -> bool {
    return dot(p - s.polygon[0].xyz, s.n.xyz) <= 0.0;
}

// The shooter's cosine towards v = p - s.position (d = |v|, local_z its
// component along the frame normal): a light's frame normal's; an area
// sample's its group's perturbed normal's under a normal map, at least 0.
fn shooter_cosine(s: Sample, v: vec3<f32>, d: f32, local_z: f32) -> f32 {
    var cos_s = local_z / d;
    if (s.power.w == 0.0) {
        if (any(s.shading.xyz != s.n.xyz)) { cos_s = dot(v, s.shading.xyz) / d; }
        cos_s = max(cos_s, 0.0);
    }
    return cos_s;
}

// The irradiance H that the texel k (one that `receives`) gathers from
// the batch's samples through the visibility maps.
fn irradiance(k: u32) -> vec3<f32> {
    let texel = texels[k];
    let tri = bitcast<u32>(texel.normal.w);
    let p = texel.position.xyz;
    let nr = texel.normal.xyz;
    let ns = texel.shading.xyz;
    let perturbed = any(ns != nr);
    var h = vec3<f32>(0.0);
    for (var i = 0u; i < params.sample_count; i += 1u) {
        let s = samples[params.sample_first + i];
        let v = p - s.position.xyz;
        let d2 = dot(v, v);
        let d = sqrt(d2);
        if (d <= 0.0) { continue; }
        let cos_plane = -dot(nr, v) / d;
        // The receiver's cosine: its perturbed normal's (004 Sec. 2.3.3).
        var cos_r = cos_plane;
        if (perturbed) { cos_r = max(-dot(ns, v) / d, 0.0); }
        let light = s.power.w != 0.0;
        // A sample that the receiver's plane cuts, near enough to be
        // integrated exactly from the receiver (area_transfer), gives the
        // part in front of that plane even when its centroid lies behind;
        // its visibility from the centroid says nothing about that part, so
        // it is taken as seen (the part of a wall that a sliver touching it
        // faces got nothing).
        var straddles = false;
        if (cos_plane <= 0.0) {
            if (light || !reciprocal(k, s, d2)) { continue; }
            for (var c = 0u; c < u32(s.polygon[0].w); c += 1u) {
                if (dot(nr, s.polygon[c].xyz - p) > 0.0) { straddles = true; }
            }
            if (!straddles) { continue; }
        }
        let local = vec3<f32>(dot(v, s.t.xyz), dot(v, s.b.xyz), dot(v, s.n.xyz));
        // An area sample's point lies a hair (1e-6 of the scene) in front
        // of its shooter so its maps do not see the shooter; which side of
        // the shooter a receiver is on is decided by the shooter's own
        // plane, or a receiver nearer to it than that hair (a sliver
        // touching it) got nothing.
        if (!light && behind_shooter(s, p)) { continue; }
        let cos_s = shooter_cosine(s, v, d, local.z);
        var seen = straddles;
        if (!straddles) { seen = seen_in_maps(i * params.layers_per_sample, tri, p, nr, local, s, light); }
        if (!seen) { continue; }
        if (light) {
            let gamma = degrees(acos(clamp(cos_s, -1.0, 1.0)));
            let c = degrees(atan2(local.y, local.x));
            h += s.power.xyz * ldt_lookup(c, gamma) * cos_r / d2;
        } else {
            h += s.power.xyz * area_transfer(k, p, nr, ns, s, d2, cos_s, cos_r);
            if (reciprocal(k, s, d2)) {
                let extent = s.polygon[1].w;
                if (d2 < SQUARES * extent) {
                    let g = tris[params.shooter].group_first + params.sample_first + i;
                    h += variation(p, ns, g, s.power.xyz - selection.overshoot.xyz);
                } else if (d2 < VARIATION * extent) {
                    h += quadrant_variation(p, ns, s);
                }
            }
        }
    }
    return h;
}

// Diffuse transmission (004 Sec. 4.3.1, Eq. 4.4), bound only where a
// material transmits. A translucent two-sided surface is two faces, each
// with its own texels; per texel, `transmission` holds its tau_d (xyz)
// and the texel of the other face at the same place (w, bits; NONE where
// it has none). The light H reaching one face leaves rho_d H from that
// face and tau_d H from the other: the paper's two shots of what arrives,
// weighted rho_d / (rho_d + tau_d) and tau_d / (rho_d + tau_d) out of
// (rho_d + tau_d) H. So the receiver pass first stores every texel's H
// (`receive_translucent`), then each texel adds
//   dB = rho_d H + tau_d H_twin                      (`transmit`)
// to its radiosity and residual: the same scene means the same as in
// hierarchical-solve (B = E + rho_d H + tau_d H_twin).
@group(0) @binding(13) var<storage, read> transmission: array<vec4<f32>>;
@group(0) @binding(14) var<storage, read_write> received: array<vec4<f32>>;

const NONE: u32 = 0xffffffffu;

@compute @workgroup_size(64)
fn receive_translucent(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let k = id.x + id.y * nw.x * 64u;
    if (k >= params.n_texels) { return; }
    var h = vec3<f32>(0.0);
    if (receives(k)) { h = gathered(k); }
    received[k] = vec4<f32>(h, 0.0);
}

@compute @workgroup_size(64)
fn transmit(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) nw: vec3<u32>) {
    let k = id.x + id.y * nw.x * 64u;
    if (k >= params.n_texels || texels[k].position.w <= 0.0) { return; }
    var db = texels[k].rho.xyz * received[k].xyz;
    let twin = bitcast<u32>(transmission[k].w);
    if (twin != NONE) { db += transmission[k].xyz * received[twin].xyz; }
    radiosity[k] += vec4<f32>(db, 0.0);
    residual[k] += vec4<f32>(db, 0.0);
}
