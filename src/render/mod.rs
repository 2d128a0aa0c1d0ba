//! Rendering: objects ready to trace, the sphere tracer (SPEC 7), the image loop.

mod backtrack;
pub mod cone;
pub mod hit_gap;
pub mod neighbours;
pub mod object;
pub mod options;
pub mod schedule;
pub mod signed;
pub mod step_beta;
mod stepper;
pub mod tracer;

pub use object::TraceObject;
pub use options::{Backtrack, TracerOptions};
pub use tracer::{Hit, RayResult, RayStats, Tracer};
pub mod albedo;
pub mod build;
pub mod image;
mod image_stats;
pub mod pipeline;
