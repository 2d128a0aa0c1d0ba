//! Loads a mesh or lidar file the way `query` and `field` do and prints the point count
//! and the load time: the lidar load benchmark (issue 12). Peak memory comes from the
//! shell: `/usr/bin/time -f %M cargo run --release --example load_points -- FILE`
//! (better: run the built binary, `target/release/examples/load_points FILE`).

use smoothtrace::load::load_with_origin as load_mesh;
use smoothtrace::primitives::PrimitiveKind;
use std::path::PathBuf;
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let path = PathBuf::from(
        std::env::args()
            .nth(1)
            .ok_or_else(|| anyhow::anyhow!("usage: load_points FILE"))?,
    );
    let t = Instant::now();
    let (mesh, origin) = load_mesh(&path, &[PrimitiveKind::Points])?;
    let seconds = t.elapsed().as_secs_f64();
    println!(
        "{}: {} points in {seconds:.3} s (origin [{}, {}, {}])",
        path.display(),
        mesh.vertices.len(),
        origin.x,
        origin.y,
        origin.z
    );
    Ok(())
}
