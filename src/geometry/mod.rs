//! Geometry with no knowledge of primitives' weights: exact closest-point queries
//! (SPEC 3, computed in f64 from f32 inputs), the distance between two segments, Morton
//! order for batches of queries, and a grid of directions for tables of convex functions
//! of a direction.

pub mod closest;
pub mod directions;
pub mod morton;
pub mod segments;
