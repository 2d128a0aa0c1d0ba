//! Meshes and query points from flat arrays (row-major `(n, 3)` coordinates, `(m, 3)`
//! triangle and `(k, 2)` segment indices), checked like the mesh readers check files:
//! finite coordinates, indices in range, at least one vertex.

use super::InputError;
use crate::mesh::Mesh;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// A mesh from `vertices` (flat `(n, 3)`), `triangles` (flat `(m, 3)`) and `segments`
/// (flat `(k, 2)`). `names` are the arrays' names for messages (vertices, triangles,
/// segments). Coordinates are stored in f32 like every mesh: values beyond the f32 range
/// are refused rather than turned into infinities.
pub fn mesh_from_arrays(
    vertices: &[f64],
    triangles: &[i64],
    segments: &[i64],
    names: [&str; 3],
) -> Result<Mesh, InputError> {
    let [vname, tname, sname] = names;
    let points = finite_points(vertices, vname)?;
    if points.is_empty() {
        return Err(InputError::Empty(vname.to_string()));
    }
    let mut verts = Vec::with_capacity(points.len());
    for (row, p) in points.iter().enumerate() {
        let v = p.as_vec3();
        if !v.is_finite() {
            return Err(InputError::OutOfF32Range {
                array: vname.to_string(),
                row,
                value: p.to_array(),
            });
        }
        verts.push(v);
    }
    Ok(Mesh {
        triangles: indices::<3>(triangles, tname, verts.len())?,
        segments: indices::<2>(segments, sname, verts.len())?,
        vertices: verts,
        name: vname.to_string(),
    })
}

/// Query points from a flat `(n, 3)` array; every coordinate must be finite and within
/// the command line's query limit ([`crate::limits::MAX_QUERY_COORD`]): beyond it the
/// f64 squared distances overflow (issue 32: `[1e200, 0, 0]` gave `inf`, a zero gradient
/// and a NaN closest point).
///
/// The checks and the conversion run in parallel (in the current rayon pool); the error
/// names the first bad row, non-finite values first, as one pass in order would.
pub fn points_from_array(values: &[f64], name: &str) -> Result<Vec<DVec3>, InputError> {
    if !values.len().is_multiple_of(3) {
        return Err(InputError::Shape {
            array: name.to_string(),
            len: values.len(),
            width: 3,
        });
    }
    let rows = values.par_chunks_exact(3);
    let row_value = |row: usize| [values[3 * row], values[3 * row + 1], values[3 * row + 2]];
    // `None` for a good row (the limits' check also refuses NaN and infinities).
    let problem = |c: &[f64]| {
        c.iter()
            .find_map(|&v| crate::limits::query_coordinate_problem(v))
    };
    if let Some(row) = rows.clone().position_first(|c| problem(c).is_some()) {
        if let Some(row) = rows.position_first(|c| !c.iter().all(|v| v.is_finite())) {
            return Err(InputError::NonFinite {
                array: name.to_string(),
                row,
                value: row_value(row),
            });
        }
        return Err(InputError::QueryOutOfRange {
            array: name.to_string(),
            row,
            value: row_value(row),
            problem: problem(&row_value(row)).unwrap_or_default(),
        });
    }
    Ok(rows.map(|c| DVec3::new(c[0], c[1], c[2])).collect())
}

/// Points from a flat `(n, 3)` array with finite coordinates (vertices: their own
/// range check is the f32 one of [`mesh_from_arrays`]).
fn finite_points(values: &[f64], name: &str) -> Result<Vec<DVec3>, InputError> {
    if !values.len().is_multiple_of(3) {
        return Err(InputError::Shape {
            array: name.to_string(),
            len: values.len(),
            width: 3,
        });
    }
    values
        .chunks_exact(3)
        .enumerate()
        .map(|(row, c)| {
            let p = DVec3::new(c[0], c[1], c[2]);
            if p.is_finite() {
                Ok(p)
            } else {
                Err(InputError::NonFinite {
                    array: name.to_string(),
                    row,
                    value: p.to_array(),
                })
            }
        })
        .collect()
}

/// Rows of `N` vertex indices, each in `0..count`.
fn indices<const N: usize>(
    values: &[i64],
    name: &str,
    count: usize,
) -> Result<Vec<[u32; N]>, InputError> {
    if !values.len().is_multiple_of(N) {
        return Err(InputError::Shape {
            array: name.to_string(),
            len: values.len(),
            width: N,
        });
    }
    values
        .chunks_exact(N)
        .enumerate()
        .map(|(row, c)| {
            let mut out = [0u32; N];
            for (o, &i) in out.iter_mut().zip(c) {
                if i < 0 || i as u64 >= count as u64 {
                    return Err(InputError::IndexOutOfRange {
                        array: name.to_string(),
                        row,
                        index: i,
                        count,
                    });
                }
                *o = i as u32;
            }
            Ok(out)
        })
        .collect()
}

/// The vertices of a mesh as a flat f64 array (exact: f32 widens without rounding).
pub fn flat_vertices(vertices: &[Vec3]) -> Vec<f64> {
    vertices
        .iter()
        .flat_map(|v| v.as_dvec3().to_array())
        .collect()
}

/// Index rows as a flat i64 array.
pub fn flat_indices<const N: usize>(rows: &[[u32; N]]) -> Vec<i64> {
    rows.iter().flatten().map(|&i| i64::from(i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAMES: [&str; 3] = ["V", "faces", "edges"];

    #[test]
    fn a_triangle_round_trips() {
        let v = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.5];
        let m = mesh_from_arrays(&v, &[0, 1, 2], &[], NAMES).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
        assert_eq!(flat_vertices(&m.vertices), v.to_vec());
        assert_eq!(flat_indices(&m.triangles), vec![0, 1, 2]);
    }

    #[test]
    fn errors_name_the_array_and_row() {
        let v = [0.0, 0.0, 0.0, 1.0, f64::NAN, 0.0];
        let e = mesh_from_arrays(&v, &[], &[], NAMES).unwrap_err();
        assert!(e.to_string().starts_with("V[1] has a non-finite"), "{e}");
        let v = [0.0, 0.0, 0.0, 1e39, 0.0, 0.0];
        let e = mesh_from_arrays(&v, &[], &[], NAMES).unwrap_err();
        assert!(e.to_string().starts_with("V[1] = "), "{e}");
        let v = [0.0; 9];
        let e = mesh_from_arrays(&v, &[0, 1, 2, 0, 3, 1], &[], NAMES).unwrap_err();
        assert!(
            e.to_string().starts_with("faces[1] holds vertex index 3"),
            "{e}"
        );
        let e = mesh_from_arrays(&v, &[], &[0, -1], NAMES).unwrap_err();
        assert!(
            e.to_string().starts_with("edges[0] holds vertex index -1"),
            "{e}"
        );
        let e = mesh_from_arrays(&[], &[], &[], NAMES).unwrap_err();
        assert_eq!(e.to_string(), "V has no vertices");
    }

    #[test]
    fn query_points_beyond_the_command_lines_limit_are_refused() {
        // Issue 32: [1e200, 0, 0] gave inf, a zero gradient, a NaN closest point.
        let e = points_from_array(&[0.0, 0.0, 0.0, 1e200, 0.0, 0.0], "P").unwrap_err();
        let m = e.to_string();
        assert!(
            m.starts_with("P[1] = [1e200, 0.0, 0.0]: query coordinate 1e200 is beyond"),
            "{m}"
        );
        assert!(points_from_array(&[-1e31, 5e30, 0.0], "P").is_ok());
        assert!(points_from_array(&[0.0, 2e31, 0.0], "P").is_err());
    }

    #[test]
    fn query_point_errors_name_the_first_bad_row_non_finite_first() {
        let mut v = vec![0.5; 3 * 5000];
        v[3 * 4000 + 1] = f64::INFINITY;
        v[3 * 3000] = 1e200;
        v[3 * 4500 + 2] = f64::NAN;
        let e = points_from_array(&v, "P").unwrap_err().to_string();
        assert!(e.starts_with("P[4000] has a non-finite"), "{e}");
        v[3 * 4000 + 1] = 0.0;
        v[3 * 4500 + 2] = 0.0;
        v[3 * 3500] = -1e100;
        let e = points_from_array(&v, "P").unwrap_err().to_string();
        assert!(e.starts_with("P[3000]"), "{e}");
        v[3 * 3000] = 0.0;
        v[3 * 3500] = 0.0;
        let p = points_from_array(&v, "P").unwrap();
        assert_eq!(p.len(), 5000);
        assert_eq!(p[4999], DVec3::splat(0.5));
        assert!(points_from_array(&v[..7], "P").is_err());
    }
}
