//! The film: what happens between traced rays and image files (issue 11).
//!
//! As in pbrt-v4 and Mitsuba 3, three small things are kept apart: the sample pattern
//! (where in the pixel a ray goes, [`pattern`]), the reconstruction filter (how much a
//! sample counts, [`filter`]) and the film proper (weighted samples accumulated per
//! pixel in linear light and developed into RGB or straight-alpha RGBA, [`accumulate`]).
//! Beside them: the arbitrary output variables (depth, normal, object id, position and
//! the cost heat map, [`aov`], [`heatmap`]), pixel rectangles and their stitching
//! ([`crop`]) and orbiting cameras for turntables ([`turntable`]).
//!
//! The image loop that traces the samples is `render::image`; everything a caller can
//! choose about the film is one plain struct, [`FilmOptions`].

pub mod accumulate;
pub mod aov;
pub mod crop;
pub mod filter;
pub mod heatmap;
pub mod options;
pub mod pattern;
pub mod turntable;

pub use crop::Rect;
pub use filter::Filter;
pub use options::{AaMode, FilmOptions};
