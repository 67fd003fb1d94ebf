// Visibility maps: the scene rendered from a shooting sample into one layer
// per cube face (hemicube: 5 faces, light: 6) or one stereographic layer;
// each pixel keeps the distance to the nearest surface, m (004 Sec. 2.3:
// depth values instead of polygon ids, so the test can have a tolerance).

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> samples: array<Sample>;
@group(0) @binding(2) var<storage, read> vertices: array<vec4<f32>>;

// Alpha masks (fs_masked only): per triangle (u0, v0, u1, v1), (u2, v2,
// record, 0), record the bits of the offset of its mask's record in
// `masks` or 0xffffffff; a record is [width, height, clamp, S.U, S.V, O.U,
// O.V] then the alpha values, row 0 at the top (detail::mask_tables).
@group(0) @binding(3) var<storage, read> mask_uvs: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> masks: array<f32>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec3<f32>,
    @location(1) bary: vec2<f32>,
    @location(2) @interpolate(flat) triangle: u32,
    @location(3) @interpolate(flat) sample: u32,
};

@vertex
fn vs(@builtin(vertex_index) vi: u32, @builtin(instance_index) layer: u32) -> VertexOut {
    let s = samples[params.sample_first + layer / params.layers_per_sample];
    let face = layer % params.layers_per_sample;
    let v = vertices[vi].xyz - s.position.xyz;
    let local = vec3<f32>(dot(v, s.t.xyz), dot(v, s.b.xyz), dot(v, s.n.xyz));
    var out: VertexOut;
    out.local = local;
    let corner = vi % 3u;
    out.bary = vec2<f32>(f32(corner == 1u), f32(corner == 2u));
    out.triangle = vi / 3u;
    out.sample = params.sample_first + layer / params.layers_per_sample;
    if (params.mode == 1u && s.power.w == 0.0) {
        let d = length(local);
        out.clip = vec4<f32>(stereographic(local / max(d, 1e-20)), d / params.far, 1.0);
        // Cull triangles on or behind the shooter's plane (004 Sec. 2.3):
        // the shooter's own and coplanar triangles project onto the rim and,
        // filled across the disc, hid every receiver.
        let t = vi / 3u;
        var above = false;
        for (var k = 0u; k < 3u; k += 1u) {
            if (dot(vertices[3u * t + k].xyz - s.position.xyz, s.n.xyz) > 0.0) { above = true; }
        }
        if (!above) { out.clip = vec4<f32>(0.0, 0.0, -2.0, 1.0); }
    } else {
        let f = face_coords(face, local);
        let z = (f.z - params.near) * params.far / (params.far - params.near);
        out.clip = vec4<f32>(f.x, f.y, z, f.z);
    }
    if (hidden_twin(vi / 3u, s.position.xyz)) { out.clip = vec4<f32>(0.0, 0.0, -2.0, 1.0); }
    return out;
}

// Whether triangle t has a twin (w = 2: a two-sided surface's other face,
// over the same corners) and `eye` sees its back: it shows only its front,
// for seen from behind the twin's front is there at the same depth, and
// the two would z-fight.
fn hidden_twin(t: u32, eye: vec3<f32>) -> bool {
    if (vertices[3u * t].w <= 1.5) { return false; }
    let p0 = vertices[3u * t].xyz;
    let front = cross(vertices[3u * t + 1u].xyz - p0, vertices[3u * t + 2u].xyz - p0);
    return dot(eye - p0, front) <= 0.0;
}

fn distance_of(in: VertexOut) -> vec4<f32> {
    return vec4<f32>(length(in.local), 0.0, 0.0, 0.0);
}

@fragment
fn fs(in: VertexOut) -> @location(0) vec4<f32> {
    return distance_of(in);
}

// Whether the point at barycentrics `bary` of triangle t is opaque: the
// mask's texel holding it (MTL -s, -o, -clamp) is above 0; mirrors
// radiometry::texture::opaque.
fn opaque(t: u32, bary: vec2<f32>) -> bool {
    let a = mask_uvs[2u * t];
    let b = mask_uvs[2u * t + 1u];
    let at = bitcast<u32>(b.z);
    if (at == 0xffffffffu) { return true; }
    let uv = a.xy + bary.x * (a.zw - a.xy) + bary.y * (b.xy - a.xy);
    let size = vec2<f32>(masks[at], masks[at + 1u]);
    var st = vec2<f32>(masks[at + 3u], masks[at + 4u]) * uv + vec2<f32>(masks[at + 5u], masks[at + 6u]);
    if (masks[at + 2u] != 0.0) { st = clamp(st, vec2<f32>(0.0), vec2<f32>(1.0)); } else { st = st - floor(st); }
    let x = min(u32(floor(st.x * size.x)), u32(size.x) - 1u);
    let y = min(u32(floor((1.0 - st.y) * size.y)), u32(size.y) - 1u);
    return masks[at + 7u + y * u32(size.x) + x] > 0.0;
}

// The barycentrics of the point a fragment shows. Cube faces interpolate
// them perspective-correctly; the stereographic map interpolates affinely
// between projected corners, which misplaces a large triangle's interior
// (004 Fig. 4.4; a masked hole moved by 40% of its light), so there the
// pixel's ray (the inverse projection of its centre) meets the triangle's
// plane.
fn fragment_bary(in: VertexOut) -> vec2<f32> {
    let s = samples[in.sample];
    if (params.mode != 1u || s.power.w != 0.0) { return in.bary; }
    let res = f32(params.res);
    let m = vec2<f32>(in.clip.x / res * 2.0 - 1.0, 1.0 - in.clip.y / res * 2.0);
    let q = dot(m, m);
    let w = vec3<f32>(2.0 * m.x, 2.0 * m.y, 1.0 - q) / (1.0 + q);
    let dir = w.x * s.t.xyz + w.y * s.b.xyz + w.z * s.n.xyz;
    let p0 = vertices[3u * in.triangle].xyz;
    let e1 = vertices[3u * in.triangle + 1u].xyz - p0;
    let e2 = vertices[3u * in.triangle + 2u].xyz - p0;
    let normal = cross(e1, e2);
    let denom = dot(normal, dir);
    if (denom == 0.0) { return in.bary; }
    let x = s.position.xyz + dir * (dot(normal, p0 - s.position.xyz) / denom) - p0;
    return barycentric(x, e1, e2);
}

// The visibility maps of a scene with alpha masks: texels with alpha 0 do
// not exist, so their fragments are discarded and light passes (004 Sec.
// 4.3.4).
@fragment
fn fs_masked(in: VertexOut) -> @location(0) vec4<f32> {
    if (!opaque(in.triangle, fragment_bary(in))) { discard; }
    return distance_of(in);
}
