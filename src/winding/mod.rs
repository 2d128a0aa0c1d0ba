//! Generalized winding numbers and signed distances of triangle soups (issue 32).
//!
//! The winding number `w(q) = sum_t Omega_t(q) / (4 pi)` sums the signed solid angles of
//! the triangles (Jacobson, Kavan and Sorkine-Hornung 2013): 1 inside and 0 outside a
//! closed, outward-oriented mesh, and a harmonic function that still separates inside
//! from outside (`w > 1/2`) on open, non-manifold soups such as a scan with holes. Its
//! fast evaluation is the Barnes-Hut sum of Barill, Dickson, Schmidt, Levin and
//! Jacobson, "Fast Winding Numbers for Soups and Clouds" (SIGGRAPH 2018), on the same
//! BVH the exact nearest query walks.
//!
//! - [`exact`]: the solid angle of a triangle (Van Oosterom and Strackee 1983) and the
//!   brute-force references.
//! - [`expansion`]: a cluster's moments and its second-order far field.
//! - [`batch`] and [`lanes`]: many queries at once, in groups of neighbours that share
//!   one walk, with the arithmetic written over the group's lanes for the vectorizer.
//! - [`tree`]: the far fields of a triangle set's BVH nodes and the query walk, with the
//!   accuracy parameter `beta` (far field when a node's radius is below `beta` times the
//!   distance to its centre; 0 = exact).
//! - [`signed`]: [`Solid`] (triangles + far fields): winding numbers and signed distances
//!   (exact distance, negative where `w > 1/2`).
//! - [`boundary`]: the soup's boundary curve, which bounds how fast `w` can change away
//!   from the surface (used to sign distance volumes block by block).

pub mod batch;
pub mod boundary;
pub mod exact;
pub mod expansion;
pub mod lanes;
pub mod signed;
pub mod tree;

pub use signed::{DEFAULT_BETA, Signed, Solid, sign};
pub use tree::WindingTree;
