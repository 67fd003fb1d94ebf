//! compare binary (skeleton).
fn main() {}
