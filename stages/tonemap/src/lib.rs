//! tonemap (skeleton).
