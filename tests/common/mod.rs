//! Shared test helpers: a deterministic RNG, small meshes, data-file lookup.
#![allow(dead_code)]

use glam::{DVec3, Vec3};
use smoothtrace::mesh::Mesh;
use std::path::PathBuf;

/// A small deterministic generator (PCG-style LCG), fixed seeds for reproducible sweeps.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E3779B97F4A7C15) | 1)
    }
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [-1, 1].
    pub fn sym(&mut self) -> f64 {
        2.0 * self.next_f64() - 1.0
    }
    pub fn vec(&mut self) -> DVec3 {
        DVec3::new(self.sym(), self.sym(), self.sym())
    }
    pub fn unit(&mut self) -> DVec3 {
        loop {
            let v = self.vec();
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// A closed, bumpy UV sphere (triangles, shared vertices) of radius about 1.
pub fn bumpy_sphere(rings: usize, segments: usize) -> Mesh {
    let mut vertices = vec![Vec3::new(0.0, 1.0, 0.0)];
    for i in 1..rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let ph = std::f32::consts::TAU * j as f32 / segments as f32;
            let r = 1.0 + 0.15 * (3.0 * ph).sin() * (2.0 * th).sin();
            vertices.push(r * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin()));
        }
    }
    vertices.push(Vec3::new(0.0, -1.0, 0.0));
    let last = vertices.len() as u32 - 1;
    let idx = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, idx(1, j + 1), idx(1, j)]);
        triangles.push([last, idx(rings - 1, j), idx(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (idx(i, j), idx(i, j + 1), idx(i + 1, j), idx(i + 1, j + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    Mesh {
        vertices,
        segments: Vec::new(),
        triangles,
        name: "bumpy-sphere".into(),
    }
}

/// A wireframe of random polylines plus a few isolated segments.
pub fn random_wire(rng: &mut Rng, polylines: usize, len: usize) -> Mesh {
    let mut vertices = Vec::new();
    let mut segments = Vec::new();
    for _ in 0..polylines {
        let mut p = rng.vec();
        let start = vertices.len() as u32;
        for k in 0..len {
            vertices.push(p.as_vec3());
            if k > 0 {
                segments.push([start + k as u32 - 1, start + k as u32]);
            }
            p += 0.2 * rng.vec();
        }
    }
    Mesh {
        vertices,
        segments,
        triangles: Vec::new(),
        name: "random-wire".into(),
    }
}

/// Path of a shared data file, or `None` (with a printed reason) when `data/` is absent.
pub fn data_file(name: &str) -> Option<PathBuf> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name);
    if p.exists() {
        Some(p)
    } else {
        println!("skipping: data/{name} not found (link ../shared/data to data/ to run this)");
        None
    }
}

/// Relative comparison scale for a smooth distance: near the zero level set relative
/// error is meaningless, so compare against the larger of |s| and the smoothing length.
pub fn s_scale(s: f64, alpha: f64) -> f64 {
    s.abs().max(1.0 / alpha)
}

/// Angle between two vectors in radians (0 if both are zero).
pub fn angle(a: DVec3, b: DVec3) -> f64 {
    let (la, lb) = (a.length(), b.length());
    if la == 0.0 && lb == 0.0 {
        return 0.0;
    }
    (a.dot(b) / (la * lb)).clamp(-1.0, 1.0).acos()
}

/// Runs a command (the built binary) in `dir` with `args`, feeding `stdin` (ignoring a
/// broken pipe: the process may exit before reading bad input), and collects its output.
pub fn run_cli(
    mut cmd: std::process::Command,
    args: &[&str],
    dir: &std::path::Path,
    stdin: Option<&str>,
) -> std::process::Output {
    use std::io::Write;
    use std::process::Stdio;
    let mut child = cmd
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    if let Some(s) = stdin {
        let _ = child.stdin.take().unwrap().write_all(s.as_bytes());
    }
    drop(child.stdin.take());
    child.wait_with_output().unwrap()
}

/// `mesh`'s vertices and triangles as OBJ text.
pub fn obj_text(mesh: &Mesh) -> String {
    let mut obj = String::new();
    for v in &mesh.vertices {
        obj += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in &mesh.triangles {
        obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    obj
}
