//! smoothtrace: sphere tracing of smooth (weighted LogSumExp) distance fields of point
//! clouds, edge meshes and triangle meshes. See `ARCHITECTURE.md` for the data flow and
//! `SPEC.md` (shared) for the math.

pub mod camera;
pub mod matcap;
pub mod mesh;
pub mod primitives;
pub mod procedural;
pub mod scene;
