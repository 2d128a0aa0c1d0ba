//! Fixed-seed query points shared by the benchmarks (`engine_bench`, `api_bench`).

use glam::DVec3;
use smoothtrace::mesh::Mesh;

/// Fixed-seed queries: half near the surface (a vertex plus a small offset), half
/// uniform in the bounding box grown by 10%.
pub fn queries(mesh: &Mesh, n: usize) -> Vec<DVec3> {
    let b = mesh.bounds();
    let diag = b.diagonal();
    let mut seed = 0x5EEDu64;
    let mut rnd = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|i| {
            if i % 2 == 0 {
                let v = mesh.vertices
                    [(rnd() * mesh.vertices.len() as f64) as usize % mesh.vertices.len()];
                v.as_dvec3() + 0.01 * diag * DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5)
            } else {
                let lo = b.min.as_dvec3() - 0.1 * diag;
                let hi = b.max.as_dvec3() + 0.1 * diag;
                lo + (hi - lo) * DVec3::new(rnd(), rnd(), rnd())
            }
        })
        .collect()
}
