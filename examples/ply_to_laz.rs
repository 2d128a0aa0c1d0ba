//! Converts a point-cloud PLY (the 8-million-point Autzen scan) to LAZ (or LAS, by the
//! output's extension) with the `las` crate, for the lidar load benchmark (issue 12).
//! The PLY's float32 coordinates are local to the EPT origin `(637291, 851210, 511)` ft
//! (see data/README.md); the LAZ gets them back in file coordinates with a scale of
//! 0.01 ft (the source quantisation) and that origin as its offset, point format 0.
//!
//! Run: `cargo run --release --example ply_to_laz -- data/autzen-lidar-8m.ply /tmp/autzen-8m.laz`
//! (the default paths). Then compare the loads with `load_points`.
//!
//! A third argument `morton` writes the points in Morton (Z-curve) order of their
//! 1-foot grid cell instead of the PLY's order. The PLY comes from an EPT octree,
//! coarse levels first, so consecutive points are up to kilometres apart (median 77 ft
//! in the first level); a scanner writes neighbouring pulses one after the other, and
//! LAZ codes each point as the difference from the previous one, so the PLY order is the
//! worst case for decoding speed and the Morton order is close to a real file's.

use las::{Builder, Point, Transform, Vector, Writer};
use smoothtrace::mesh::Mesh;
use std::path::PathBuf;
use std::time::Instant;

/// `world = local + ORIGIN` for data/autzen-lidar-8m.ply.
const ORIGIN: [f64; 3] = [637291.0, 851210.0, 511.0];

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let input = PathBuf::from(
        args.next()
            .unwrap_or_else(|| "data/autzen-lidar-8m.ply".into()),
    );
    let output = PathBuf::from(args.next().unwrap_or_else(|| "/tmp/autzen-8m.laz".into()));
    let morton = args.next().is_some_and(|a| a == "morton");
    let t = Instant::now();
    let mut mesh = Mesh::load(&input)?;
    if morton {
        let lo = mesh.bounds().min;
        mesh.vertices.sort_by_cached_key(|v| {
            let cell = ((*v - lo).max(glam::Vec3::ZERO)).as_uvec3();
            interleave(cell.x) | interleave(cell.y) << 1 | interleave(cell.z) << 2
        });
    }
    eprintln!(
        "read {} points from {} in {:.2} s",
        mesh.vertices.len(),
        input.display(),
        t.elapsed().as_secs_f64()
    );
    let mut builder = Builder::from((1, 2));
    builder.point_format = las::point::Format::new(0)?;
    let t = |offset: f64| Transform {
        scale: 0.01,
        offset,
    };
    builder.transforms = Vector {
        x: t(ORIGIN[0]),
        y: t(ORIGIN[1]),
        z: t(ORIGIN[2]),
    };
    builder.generating_software = "smoothtrace ply_to_laz".into();
    let header = builder.into_header()?;
    let start = Instant::now();
    let mut writer = Writer::from_path(&output, header)?;
    for (i, v) in mesh.vertices.iter().enumerate() {
        writer.write_point(Point {
            x: v.x as f64 + ORIGIN[0],
            y: v.y as f64 + ORIGIN[1],
            z: v.z as f64 + ORIGIN[2],
            ..Default::default()
        })?;
        if i % 1_000_000 == 999_999 {
            eprintln!("  {} points written", i + 1);
        }
    }
    writer.close()?;
    eprintln!(
        "wrote {} in {:.2} s ({} bytes)",
        output.display(),
        start.elapsed().as_secs_f64(),
        std::fs::metadata(&output)?.len()
    );
    Ok(())
}

/// The low 21 bits of `v` spread to every third bit (one axis of a 3D Morton code).
fn interleave(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}
