// The irradiance of a receiver pass in a scene without specular materials:
// the batch's samples' (appended to solver.wgsl in place of mirrors.wgsl).
fn gathered(k: u32) -> vec3<f32> {
    return irradiance(k);
}
