//! Converts a point-cloud PLY (the 8-million-point Autzen scan) to LAZ (or LAS, by the
//! output's extension) with the `las` crate, for the lidar load benchmark (issue 12).
//! The PLY's float32 coordinates are local to the EPT origin `(637291, 851210, 511)` ft
//! (see data/README.md); the LAZ gets them back in file coordinates with a scale of
//! 0.01 ft (the source quantisation) and that origin as its offset, point format 0.
//!
//! Run: `cargo run --release --example ply_to_laz -- data/autzen-lidar-8m.ply /tmp/autzen-8m.laz`
//! (the default paths). Then compare the loads with `load_points`.

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
    let t = Instant::now();
    let mesh = Mesh::load(&input)?;
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
