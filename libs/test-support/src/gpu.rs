//! What a GPU test does without a GPU.

/// The device and queue of the stage's own adapter request `acquire`
/// (e.g. `gpu_shoot::gpu::acquire`), after `quiet` (the stage's set-up
/// before any device, e.g. `gpu_shoot::gpu::quiet_device_select_layer`);
/// `None` where it finds no adapter: the test then skips, loudly, except
/// under CI (the variable `CI` set), where a missing adapter fails it.
pub fn device_or_skip<D, Q, I>(quiet: fn(), acquire: fn() -> Result<(D, Q, I), String>) -> Option<(D, Q)> {
    quiet();
    match acquire() {
        Ok((d, q, _)) => Some((d, q)),
        Err(e) if std::env::var_os("CI").is_some() => panic!("CI has no GPU adapter: {e}"),
        Err(e) => {
            eprintln!("\n*** SKIPPED: gpu-shoot GPU test: {e} ***\n");
            None
        }
    }
}
