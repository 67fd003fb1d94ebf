// The frustum maps of the reflection tree's nodes (004 Sec. 4.3.2, Fig.
// 4.3), appended to visibility.wgsl only for a scene with specular
// materials. Instance i
// renders the scene from the node's virtual sample i through its window:
// a perspective projection onto face 0's coordinates scaled by k, storing
// the distance in those coordinates (seen_through compares in the same
// ones); only what lies beyond the window's plane is drawn (the paper's
// clipping plane, with its small offset that removes the window itself).
// The structs: mirrors_common.wgsl.

@group(0) @binding(5) var<storage, read> views: array<View>;
@group(0) @binding(6) var<storage, read> levels: array<Level>;

struct VirtualOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec3<f32>,
    @location(1) beyond: f32,
};

@vertex
fn vs_virtual(@builtin(vertex_index) vi: u32, @builtin(instance_index) i: u32) -> VirtualOut {
    let l = params.level - 1u;
    let s = samples[params.virtual_base + l * params.sample_count + i];
    let view = views[l * params.sample_count + i];
    let x = vertices[vi].xyz;
    let v = x - s.position.xyz;
    var out: VirtualOut;
    out.local = vec3<f32>(dot(v, view.right.xyz), dot(v, view.up.xyz), dot(v, view.axis.xyz));
    out.beyond = dot(levels[l].plane.xyz, x) + levels[l].plane.w;
    let z = (out.local.z - params.near) * params.far / (params.far - params.near);
    out.clip = vec4<f32>(out.local.x, out.local.y, z, out.local.z);
    if (hidden_twin(vi / 3u, s.position.xyz)) { out.clip = vec4<f32>(0.0, 0.0, -2.0, 1.0); }
    return out;
}

@fragment
fn fs_virtual(in: VirtualOut) -> @location(0) vec4<f32> {
    if (in.beyond <= plane_offset()) { discard; }
    return vec4<f32>(length(in.local), 0.0, 0.0, 0.0);
}
