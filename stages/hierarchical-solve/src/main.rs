//! hierarchical-solve binary (skeleton).
fn main() {}
