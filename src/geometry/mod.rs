//! Exact closest-point queries (SPEC 3), computed in f64 from f32 inputs.

pub mod closest;
pub mod morton;
