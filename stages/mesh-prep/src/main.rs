//! mesh-prep binary (skeleton).
fn main() {}
