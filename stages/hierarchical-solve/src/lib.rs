//! hierarchical-solve (skeleton).
