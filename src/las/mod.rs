//! Airborne lidar in LAS 1.0-1.4 and LAZ (point formats 0-10), read with the `las` crate
//! (`laz` feature for the compressed files).
//!
//! Records stream in batches: each one's coordinates are computed in f64 with the
//! header's scale and offset, tested by the [`filter`]s in those exact file coordinates,
//! then **recentred in f64** on [`LasCloud::origin`] before being stored in f32 (at
//! 8.5e5 an f32 has a step of 0.06; relative to an origin inside the data the step is
//! below 1e-3 for any tile a few km wide). Only the kept points are stored, once: the
//! f32 positions, plus one attribute per point when a colour is asked for. Bounds are
//! reported in file coordinates, exactly (tracked in f64 while reading).
//!
//! A lidar file gives points only: asking for edges or triangles fails when the set is
//! built ("it has no edges").

pub mod attributes;
pub mod filter;
pub mod layout_check;

pub use attributes::ColorBy;
pub use filter::{FilterCount, LasFilters, NOISE_CLASSES, Returns, Thin};

use crate::mesh::{Mesh, MeshError};
use crate::rgb::{Colormap, Linear};
use attributes::AttributeColumn;
use filter::{Record, Stream, VoxelThin};
use glam::{DVec3, Vec3};
use std::path::Path;

/// Points per batch read from the file.
const BATCH: u64 = 1 << 19;

/// What to read from a lidar file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LasOptions {
    pub filters: LasFilters,
    /// Colour the points by an attribute (`None`: no colours are built).
    pub color_by: Option<ColorBy>,
    /// The colormap of scalar attributes (intensity, elevation); default viridis.
    pub colormap: Option<Colormap>,
    /// The recentring origin in file coordinates; `None`: the centre of the header's
    /// bounding box.
    pub origin: Option<DVec3>,
}

/// The kept points of a lidar file, recentred.
#[derive(Clone, Debug)]
pub struct LasCloud {
    /// The kept points (no segments, no triangles), in `file - origin` coordinates.
    pub mesh: Mesh,
    /// File coordinates of the local origin: `file = origin + local` (in f64).
    pub origin: DVec3,
    /// Exact bounds of the kept points in file coordinates.
    pub bounds: [DVec3; 2],
    /// One linear colour per kept point when `color_by` was given.
    pub colours: Option<Vec<Linear>>,
    /// Points kept after each filter, starting with the records read.
    pub counts: Vec<FilterCount>,
    /// `"1.2"`, `"1.4"`...
    pub version: String,
    pub point_format: u8,
    /// The point count the header announces.
    pub header_points: u64,
    /// The header's bounding box (file coordinates).
    pub header_bounds: [DVec3; 2],
}

/// Whether `path` names a lidar file (`.las` or `.laz`, any case).
pub fn is_lidar_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("las") || e.eq_ignore_ascii_case("laz"))
}

fn format_error(path: &Path, message: String) -> MeshError {
    MeshError::Format {
        path: path.to_path_buf(),
        message,
    }
}

/// Reads, filters, recentres and (if asked) colours the points of a LAS/LAZ file.
/// Errors name the file: unreadable, not a LAS file, a corrupt or truncated point
/// stream, an attribute the point format does not have, no point left after filtering.
pub fn read(path: &Path, options: &LasOptions) -> Result<LasCloud, MeshError> {
    let file = crate::limits::open_input_file(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    // Before the crates size any buffer from the header: see `layout_check`.
    layout_check::check_layout(&file).map_err(|m| format_error(path, m))?;
    let mut file = file;
    std::io::Seek::rewind(&mut file).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut reader = las::Reader::new(std::io::BufReader::new(file)).map_err(|e| {
        format_error(
            path,
            format!(
                "cannot read the LAS/LAZ header and point layout (corrupt or truncated \
                     file?): {e}"
            ),
        )
    })?;
    let header = reader.header().clone();
    let format = *header.point_format();
    let point_format = format
        .to_u8()
        .map_err(|e| format_error(path, format!("bad point format: {e}")))?;
    let version = format!("{}.{}", header.version().major, header.version().minor);
    let hb = header.bounds();
    let header_bounds = [
        DVec3::new(hb.min.x, hb.min.y, hb.min.z),
        DVec3::new(hb.max.x, hb.max.y, hb.max.z),
    ];
    let origin = match options.origin {
        Some(o) => o,
        None if header_bounds[0].is_finite() && header_bounds[1].is_finite() => {
            0.5 * (header_bounds[0] + header_bounds[1])
        }
        None => {
            return Err(format_error(
                path,
                format!(
                    "the header's bounding box is not finite ({:?}); cannot choose an origin",
                    header_bounds
                ),
            ));
        }
    };
    let total = header.number_of_points();
    if let Some(by) = options.color_by {
        by.check_format(&format)
            .map_err(|m| format_error(path, format!("color_by = \"{}\": {m}", by.name())))?;
    }
    let mut column = options.color_by.map(AttributeColumn::new);
    let mut stream = Stream::new(&options.filters);
    let mut voxel = match options.filters.thin {
        Some(Thin::Voxel(v)) => Some(VoxelThin::new(v)),
        _ => None,
    };
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut bounds = [DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)];
    let mut data = las::PointDataBuilder::new().for_header(&header).build();
    let mut read = 0u64;
    while read < total {
        let want = BATCH.min(total - read);
        let n = reader.fill_points(want, &mut data).map_err(|e| {
            format_error(
                path,
                format!(
                    "cannot read points {read}..{} of the {total} the header announces \
                     (truncated or corrupt file?): {e}",
                    read + want
                ),
            )
        })?;
        if n == 0 {
            return Err(format_error(
                path,
                format!(
                    "the file ends after {read} of the {total} points its header announces \
                     (truncated?)"
                ),
            ));
        }
        if let Some(c) = &mut column {
            c.begin_batch(&data);
        }
        let xyz = data.x().zip(data.y()).zip(data.z());
        let flags = data
            .classification()
            .zip(data.return_number())
            .zip(data.number_of_returns());
        for (k, (((x, y), z), ((class, rn), nr))) in xyz.zip(flags).enumerate() {
            let r = Record {
                p: DVec3::new(x, y, z),
                class,
                return_number: rn,
                number_of_returns: nr,
            };
            if !r.p.is_finite() {
                return Err(format_error(
                    path,
                    format!("point {} has a non-finite coordinate", read + k as u64),
                ));
            }
            if !stream.keeps(&r) {
                continue;
            }
            if let Some(v) = &mut voxel {
                v.add(vertices.len() as u32, r.p);
            } else {
                bounds = [bounds[0].min(r.p), bounds[1].max(r.p)];
            }
            vertices.push((r.p - origin).as_vec3());
            if let Some(c) = &mut column {
                c.push(k, &r);
            }
        }
        read += n;
    }
    let mut voxel_kept = None;
    if let Some(v) = voxel {
        let (keep, b) = v.finish(vertices.len());
        retain(&mut vertices, &keep);
        if let Some(c) = &mut column {
            c.retain(&keep);
        }
        voxel_kept = Some(vertices.len() as u64);
        if let Some(b) = b {
            bounds = b;
        }
    }
    let counts = stream.counts(voxel_kept);
    if vertices.is_empty() {
        let list: Vec<String> = counts
            .iter()
            .map(|c| format!("{}: {}", c.filter, c.kept))
            .collect();
        return Err(format_error(
            path,
            format!("no point is left after filtering ({})", list.join("; ")),
        ));
    }
    if vertices.len() > u32::MAX as usize {
        return Err(format_error(
            path,
            format!(
                "{} points is more than the 2^32 - 1 supported",
                vertices.len()
            ),
        ));
    }
    let colours = column.map(|c| c.into_colours(options.colormap.unwrap_or(Colormap::Viridis)));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(LasCloud {
        mesh: Mesh {
            vertices,
            segments: Vec::new(),
            triangles: Vec::new(),
            name,
        },
        origin,
        bounds,
        colours,
        counts,
        version,
        point_format,
        header_points: total,
        header_bounds,
    })
}

/// Keeps the items whose flag is set, in order.
fn retain<T>(items: &mut Vec<T>, keep: &[bool]) {
    let mut flags = keep.iter();
    items.retain(|_| *flags.next().unwrap_or(&false));
}
