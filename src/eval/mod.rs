//! Evaluating the smooth distance (SPEC 2) and the exact nearest primitive over one or
//! more primitive sets.
//!
//! - [`smooth`]: the Barnes-Hut traversal (SPEC 6) feeding an accumulator
//!   ([`accumulate`]) that is either the stable shifted sum or the paper's naive sum.
//! - [`reach`]: how far along a ray the sum provably stays positive, from the terms'
//!   slopes (a second-order sphere-tracing step).
//! - [`nearest`]: the exact nearest primitive on the same BVH.
//! - [`brute`]: f64 brute-force references for tests and reports.

pub mod accumulate;
pub mod brute;
pub mod colour;
pub mod nearest;
pub mod reach;
pub mod smooth;
pub mod walk;

pub use accumulate::Accumulation;
pub use nearest::{Nearest, nearest};
pub use smooth::{
    Along, EvalParams, EvalStats, Sample, evaluate, evaluate_along, evaluate_reach, evaluate_value,
};
