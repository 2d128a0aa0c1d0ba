//! smoothtrace: sphere tracing of smooth (weighted LogSumExp) distance fields of point
//! clouds, edge meshes and triangle meshes. See `ARCHITECTURE.md` for the data flow and
//! `SPEC.md` (shared) for the math.

pub mod mesh;
pub mod procedural;
pub mod primitives;
pub mod bvh;
pub mod eval;
pub mod geometry;
pub mod field;
