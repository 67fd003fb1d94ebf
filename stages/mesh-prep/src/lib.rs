//! mesh-prep (skeleton).
