//! compare (skeleton).
