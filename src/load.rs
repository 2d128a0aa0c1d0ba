//! The loader room: reads any supported file into a [`Mesh`], picking the reader by the
//! file's extension. It sits above the readers it chooses between, so they never call
//! each other: [`crate::mesh`] reads OBJ, PLY and STL ([`Mesh::load`]), [`crate::las`]
//! reads LAS and LAZ point clouds (recentred on an origin in f64, as explained there),
//! and only this module knows both.
//!
//! Three entry points, by what the caller needs back:
//! - [`load_mesh`]: the mesh of any file (a lidar file with the default filters, noise
//!   classes dropped, recentred on the header's box centre).
//! - [`load_with_origin`]: the mesh and the file coordinates of its origin
//!   (`file = origin + mesh`), for `query` and `field`, whose inputs are in file
//!   coordinates; a lidar file asked for edges or triangles is an error naming the file.
//! - [`load_scene_mesh`]: a scene object's mesh, a lidar file read with the object's
//!   filters and origin.

use crate::las::{LasOptions, is_lidar_path};
use crate::mesh::{Mesh, MeshError};
use crate::primitives::PrimitiveKind;
use glam::DVec3;
use std::path::Path;

/// Reads a mesh or lidar file (`.obj`, `.ply`, `.stl`, `.las`, `.laz`, any case); see the
/// module docs. Errors name the file; a file without vertices (or without kept points)
/// is an error.
pub fn load_mesh(path: &Path) -> Result<Mesh, MeshError> {
    if !is_lidar_path(path) {
        return Mesh::load(path);
    }
    let mesh = crate::las::read(path, &LasOptions::default())?.mesh;
    mesh.validate(path)?;
    Ok(mesh)
}

/// Reads any mesh file for the command line's `query` and `field`: a lidar file with the
/// default filters (asking it for anything but points is an error naming the file),
/// other files through [`Mesh::load`]. Returns the mesh and the origin its coordinates
/// are relative to (zero for non-lidar files): `file = origin + mesh`.
pub fn load_with_origin(path: &Path, kinds: &[PrimitiveKind]) -> Result<(Mesh, DVec3), MeshError> {
    if !is_lidar_path(path) {
        return Ok((Mesh::load(path)?, DVec3::ZERO));
    }
    if let Some(kind) = kinds.iter().find(|k| **k != PrimitiveKind::Points) {
        return Err(MeshError::Format {
            path: path.to_path_buf(),
            message: format!(
                "a LAS/LAZ file holds points only, so it cannot give {kind}; use points"
            ),
        });
    }
    let cloud = crate::las::read(path, &LasOptions::default())?;
    Ok((cloud.mesh, cloud.origin))
}

/// A scene object's mesh file: a lidar file read with the object's `options` (filters,
/// origin), any other file through [`Mesh::load`]. For callers that need the points
/// only (the renderer calls [`crate::las::read`] itself to keep the colours and counts).
pub fn load_scene_mesh(path: &Path, options: &LasOptions) -> Result<Mesh, MeshError> {
    if is_lidar_path(path) {
        Ok(crate::las::read(path, options)?.mesh)
    } else {
        Mesh::load(path)
    }
}
