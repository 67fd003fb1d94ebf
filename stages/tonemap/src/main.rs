//! tonemap binary (skeleton).
fn main() {}
