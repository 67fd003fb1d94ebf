//! radiometry (skeleton).
