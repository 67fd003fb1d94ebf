// The reflection tree's structs, shared by mirrors.wgsl (the receivers)
// and visibility_mirrors.wgsl (the frustum maps); both are appended to
// their modules only for a scene with specular materials.

// One node of the branch: its window's plane, oriented so that the node's
// virtual shooter lies behind it (negative side) and its receivers in
// front; its window entries `windows[window.x .. window.x + window.y]`,
// and its maps' first layer window.z.
struct Level {
    plane: vec4<f32>,
    window: vec4<u32>,
};

// The frustum through a window of one virtual sample (the paper's
// perspective projection towards the mirror's triangles, Fig. 4.3):
// right and up scaled by k = 1 / tan(half the field of view), so face 0's
// projection (visible_face) maps the frustum onto the whole layer; axis.w: k.
struct View {
    right: vec4<f32>,
    up: vec4<f32>,
    axis: vec4<f32>,
};

// What lies within this distance of a window's plane is the window itself
// (the paper's small offset of the clipping plane).
fn plane_offset() -> f32 {
    return 10.0 * params.near;
}

