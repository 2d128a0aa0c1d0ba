//! Rendering: objects ready to trace, the sphere tracer (SPEC 7), the image loop.

pub mod cone;
pub mod neighbours;
pub mod object;
mod stepper;
pub mod tracer;

pub use object::TraceObject;
pub use tracer::{Backtrack, Hit, RayResult, RayStats, Tracer, TracerOptions};
pub mod albedo;
pub mod build;
pub mod image;
pub mod pipeline;
