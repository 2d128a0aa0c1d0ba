//! Evaluating the smooth distance (SPEC 2) and the exact nearest primitive over one or
//! more primitive sets.
//!
//! - [`smooth`]: the Barnes-Hut evaluation (SPEC 6): its [`walk`] over the wide BVH
//!   makes the decisions per node and hands the terms to a [`sink`], which feeds an
//!   accumulator ([`accumulate`]): the stable shifted sum or the paper's naive sum.
//!   [`params`] holds what all of them share (parameters, statistics, tolerances).
//! - [`reach`]: how far along a ray the sum provably stays positive, from the terms'
//!   slopes (a second-order sphere-tracing step).
//! - [`nearest`]: the exact nearest primitive on the same BVH.
//! - [`brute`]: f64 brute-force references for tests and reports.

pub mod accumulate;
pub mod brute;
pub mod colour;
pub mod nearest;
pub mod params;
pub mod reach;
pub mod sink;
pub mod smooth;
pub mod walk;

pub use accumulate::Accumulation;
pub use nearest::{Nearest, nearest};
pub use params::{EvalParams, EvalStats, FarShare};
pub use smooth::{Along, Sample, evaluate, evaluate_along, evaluate_reach, evaluate_value};
