//! smoothtrace: sphere tracing of smooth (weighted LogSumExp) distance fields of point
//! clouds, edge meshes and triangle meshes. See `ARCHITECTURE.md` for the data flow and
//! `SPEC.md` (shared) for the math.
//!
//! Data flows one way: [`mesh`] and [`las`] files (read through [`load`]), [`procedural`]
//! shapes -> [`bvh`] -> [`primitives`] (sets with valences, weights and their BVH) ->
//! [`eval`] (smooth distance, nearest) ->
//! [`render`] (tracer, image loop, with [`camera`] and [`matcap`]), configured by
//! [`scene`] files. The [`reports`] (bench, sweep, stability) and the exact distance
//! volumes of [`field`] (SPEC 9) call the same library; [`api`] serves callers that hold
//! their data in memory (the Python bindings in `python/`).

pub mod api;
pub mod bvh;
pub mod camera;
pub mod colour;
pub mod eval;
pub mod field;
pub mod film;
pub mod font;
pub mod framing;
pub mod geometry;
pub mod las;
pub mod limits;
pub mod load;
pub mod matcap;
pub mod mesh;
pub mod output;
pub mod primitives;
pub mod procedural;
pub mod render;
pub mod reports;
pub mod rgb;
pub mod scene;
pub mod serve;
#[cfg(test)]
pub(crate) mod testing;
pub mod winding;
