//! grid-gather binary (skeleton).
fn main() {}
