//! OBJ reader (being written).
use super::{Mesh, MeshError};
use std::path::Path;

pub(super) fn read_obj(path: &Path) -> Result<Mesh, MeshError> {
    Err(MeshError::Format {
        path: path.to_path_buf(),
        message: "reader not written yet".into(),
    })
}
