//! grid-gather (skeleton).
