//! Data meshes: vertices plus optional explicit segments and triangles (SPEC 1).
//!
//! A [`Mesh`] is what a file or a procedural generator yields. It holds positions in
//! `f32` and the simplices the source stated: OBJ `l` polylines become `segments`,
//! faces of any size become fan-triangulated `triangles`. Which primitive set is built
//! from it (points, edges, triangles) is decided later, by [`crate::primitives`]; a
//! mesh never builds what nobody asked for.

mod error;
mod obj;
mod ply;
mod ply_binary;
mod ply_check;
mod stl;
mod vertex_colours;

pub use error::MeshError;

use crate::rgb::Linear;
use glam::Vec3;
use rayon::prelude::*;
use std::path::Path;

/// Vertices and the simplices a source provides.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<Vec3>,
    /// Explicit line segments (OBJ `l` polylines split into consecutive pairs, PLY `edge`
    /// elements). Empty when the source has none.
    pub segments: Vec<[u32; 2]>,
    /// Triangles (polygons are fan-triangulated on load). Empty when the source has none.
    pub triangles: Vec<[u32; 3]>,
    /// A short human-readable name (file name or generator name) for messages.
    pub name: String,
}

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (min = +inf, max = -inf); growing it by a point gives that point.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Aabb {
        points.into_iter().fold(Aabb::EMPTY, |b, p| b.grow(p))
    }

    pub fn grow(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Length of the diagonal, in f64 (0 for a single point, 0 for the empty box).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        self.extent().as_dvec3().length()
    }
}

/// A path's extension in lower case (empty when it has none).
fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default()
}

impl Mesh {
    /// Reads a mesh file, choosing the reader by extension (`.obj`, `.ply`, `.stl`, any
    /// case). Lidar files are read by [`crate::las`]; [`crate::load::load_mesh`] reads
    /// either kind. The path must be a regular file of at most
    /// [`crate::limits::MAX_INPUT_BYTES`].
    ///
    /// Errors name the file and what was wrong; a mesh with no vertices is an error.
    pub fn load(path: &Path) -> Result<Mesh, MeshError> {
        let ext = extension(path);
        if !matches!(ext.as_str(), "obj" | "ply" | "stl") {
            return Err(MeshError::UnknownExtension {
                path: path.to_path_buf(),
                extension: ext,
            });
        }
        let bytes = crate::limits::read_input_file(path).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Mesh::from_bytes(bytes, path)
    }

    /// Reads a mesh and its per-vertex colours (see [`vertex_colours`]): `Ok((mesh, None))`
    /// when the file has none. Errors name the file, and the property, vertex or line
    /// of a colour that cannot be used.
    pub fn load_with_vertex_colours(path: &Path) -> Result<(Mesh, Option<Vec<Linear>>), MeshError> {
        let ext = extension(path);
        if !matches!(ext.as_str(), "obj" | "ply") {
            return Ok((Mesh::load(path)?, None));
        }
        let bytes = crate::limits::read_input_file(path).map_err(|source| MeshError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let (mut mesh, colours) = if ext == "ply" {
            ply::parse_ply_coloured(&bytes, path, true)?
        } else {
            obj::parse_obj_coloured(&bytes, path, true)?
        };
        mesh.name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        mesh.validate(path)?;
        Ok((mesh, colours))
    }

    /// Parses a whole mesh file held in memory, choosing the reader by the extension of
    /// `path` (which is otherwise only used in messages and for the mesh's name), and
    /// validates it as [`Mesh::load`] does. The fuzz tests feed the readers through this.
    pub fn from_bytes(bytes: Vec<u8>, path: &Path) -> Result<Mesh, MeshError> {
        let ext = extension(path);
        let mut mesh = match ext.as_str() {
            "obj" => obj::parse_obj(&bytes, path)?,
            "ply" => ply::parse_ply(&bytes, path)?,
            "stl" => stl::parse_stl(bytes, path)?,
            _ => {
                return Err(MeshError::UnknownExtension {
                    path: path.to_path_buf(),
                    extension: ext,
                });
            }
        };
        if mesh.name.is_empty() {
            mesh.name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
        }
        mesh.validate(path)?;
        Ok(mesh)
    }

    /// Checks the invariants every reader and generator must meet: at least one vertex,
    /// finite coordinates within [`crate::limits::MAX_COORD`], indices in range.
    pub fn validate(&self, path: &Path) -> Result<(), MeshError> {
        if self.vertices.is_empty() {
            return Err(MeshError::Empty {
                path: path.to_path_buf(),
            });
        }
        // One vectorised pass accepts valid input (NaN fails the comparison too); the
        // loops below find the first offending vertex and say why.
        let limit = Vec3::splat(crate::limits::MAX_COORD as f32);
        let accepted = |v: &[Vec3]| v.iter().all(|v| v.abs().cmple(limit).all());
        if self.vertices.par_chunks(1 << 16).all(accepted) {
            return self.validate_indices(path);
        }
        if let Some(i) = self.vertices.iter().position(|v| !v.is_finite()) {
            return Err(MeshError::NonFinite {
                path: path.to_path_buf(),
                vertex: i,
            });
        }
        for (i, v) in self.vertices.iter().enumerate() {
            for c in v.to_array() {
                if let Some(problem) = crate::limits::coordinate_problem(f64::from(c)) {
                    return Err(MeshError::CoordinateOutOfRange {
                        path: path.to_path_buf(),
                        vertex: i,
                        problem,
                    });
                }
            }
        }
        self.validate_indices(path)
    }

    /// Every segment and triangle index names a vertex.
    fn validate_indices(&self, path: &Path) -> Result<(), MeshError> {
        let n = self.vertices.len();
        let bad = self
            .segments
            .iter()
            .flat_map(|s| s.iter())
            .chain(self.triangles.iter().flat_map(|t| t.iter()))
            .find(|&&i| i as usize >= n);
        if let Some(&i) = bad {
            return Err(MeshError::IndexOutOfRange {
                path: path.to_path_buf(),
                line: None,
                index: i as i64,
                count: n,
            });
        }
        Ok(())
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.vertices.iter().copied())
    }

    /// Applies `p -> rotation * (scale * p) + translation` to every vertex.
    pub fn transform(&mut self, scale: Vec3, rotation: glam::Quat, translation: Vec3) {
        self.vertices
            .par_iter_mut()
            .for_each(|v| *v = rotation * (scale * *v) + translation);
    }

    /// Unique undirected edges of the triangles, each as `[min, max]`, sorted.
    pub fn triangle_edges(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = self
            .triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|[a, b]| [a.min(b), a.max(b)])
            .filter(|[a, b]| a != b)
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }
}
