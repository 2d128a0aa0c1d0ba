//! A leaf's edges, four at a time: their terms and values (`Edge::term`, `Edge::value`;
//! SPEC 3, 4) computed in the four lanes of AVX registers (`avx`: the lane types;
//! `edges`: the kernels), with the same arithmetic in the same order as the scalar code,
//! so every result is the same to the last bit (`primitives::kinds`' tests compare the
//! bits) and so is every image.
//!
//! The scalar closest point on a segment (`geometry::closest::closest_on_segment`)
//! branches on where the query projects (before, past or inside the edge), which near a
//! soft surface changes from one edge to the next, and each scalar edge term divides
//! three times in a row (the two valences' reciprocals, then the projection); here the
//! lanes compute every case and keep the first that holds, in the scalar code's order,
//! and four terms share each division. The weight's quartic is the scalar one
//! (`weights::edge_w`, generic over `weights::Real`). Without AVX (detected once per
//! process), off x86-64, or with [`SCALAR_ENV`] set, the scalar path does everything
//! (the functions below return `None`). `Edge` gathers a leaf into lanes and calls these
//! (`Primitive::terms`, `values`), and the evaluator asks for a leaf's terms at once
//! (`eval::sink`, `Primitive::BATCHED`). What they bought, and why triangles and points
//! are not among them: doc/performance-log.md, round twenty.

use super::weights::WeightScale;
use glam::DVec3;

#[cfg(target_arch = "x86_64")]
mod avx;
#[cfg(target_arch = "x86_64")]
mod edges;
#[cfg(target_arch = "x86_64")]
mod slabs;

/// Setting this environment variable (to anything) keeps every term on the scalar
/// path: for profilers that cannot decode AVX (valgrind 3.19), and for comparisons.
pub const SCALAR_ENV: &str = "SMOOTHTRACE_SCALAR_TERMS";

/// True when the lanes run on AVX here (checked once per process).
pub fn available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        static AVX: std::sync::LazyLock<bool> = std::sync::LazyLock::new(|| {
            std::arch::is_x86_feature_detected!("avx") && std::env::var_os(SCALAR_ENV).is_none()
        });
        *AVX
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// True when the lanes run on AVX here and the CPU has AVX2 too (its integer lanes:
/// `directional`'s branch-free `exp` builds `2^k` in them; checked once per process).
pub fn available_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        static AVX2: std::sync::LazyLock<bool> =
            std::sync::LazyLock::new(|| available() && std::arch::is_x86_feature_detected!("avx2"));
        *AVX2
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Four doubles, one per lane.
pub type Lanes = [f64; 4];
/// Four 3-vectors, coordinate by coordinate (`[x, y, z]`, each a lane array).
pub type Lanes3 = [Lanes; 3];

/// Up to four edges: their ends and their ends' valences, lane by lane (unused lanes
/// repeat a used one).
#[derive(Clone, Copy, Debug, Default)]
pub struct EdgeLanes {
    pub a: Lanes3,
    pub b: Lanes3,
    pub val_a: Lanes,
    pub val_b: Lanes,
}

/// Four terms (`primitives::Term`), lane by lane.
#[derive(Clone, Copy, Debug, Default)]
pub struct TermLanes {
    pub d: Lanes,
    pub dir: Lanes3,
    pub w: Lanes,
    pub grad_w: Lanes3,
}

/// `Edge::term` of four edges, or `None` without AVX.
#[inline]
pub fn edge_terms(e: &EdgeLanes, x: DVec3, scale: &WeightScale) -> Option<TermLanes> {
    #[cfg(target_arch = "x86_64")]
    if available() {
        // SAFETY: AVX was detected.
        return Some(unsafe { edges::terms(e, x, scale) });
    }
    let _ = (e, x, scale);
    None
}

/// `Edge::value` of four edges (`(d, w)`), or `None` without AVX.
#[inline]
pub fn edge_values(e: &EdgeLanes, x: DVec3, scale: &WeightScale) -> Option<(Lanes, Lanes)> {
    #[cfg(target_arch = "x86_64")]
    if available() {
        // SAFETY: AVX was detected.
        return Some(unsafe { edges::values(e, x, scale) });
    }
    let _ = (e, x, scale);
    None
}

/// Edges' slabs in structure-of-arrays form (`primitives::split`): per edge its midpoint
/// `m` and `n = (b - a) / |b - a|^2` (0 for an empty edge), coordinate by coordinate, so
/// that `n . (x - m)` lies in `(-1/2, 1/2)` exactly where `x` projects inside the edge.
#[derive(Clone, Debug, Default)]
pub struct Slabs {
    pub m: [Vec<f64>; 3],
    pub n: [Vec<f64>; 3],
}

impl Slabs {
    /// `n . (x - m)` of edge `k`, in the order the lanes compute it.
    #[inline(always)]
    pub fn projection(&self, k: usize, x: DVec3) -> f64 {
        let (m, n) = (&self.m, &self.n);
        n[0][k] * (x.x - m[0][k]) + n[1][k] * (x.y - m[1][k]) + n[2][k] * (x.z - m[2][k])
    }

    /// Calls `inside(k)` for each edge `k` of `range`, in order, whose projection
    /// ([`Slabs::projection`]) is below `lim` in size, until it returns `false`; returns
    /// whether every call returned `true`. Four edges at a time on AVX, with the same
    /// arithmetic.
    #[inline]
    pub fn scan(
        &self,
        range: std::ops::Range<usize>,
        x: DVec3,
        lim: f64,
        inside: impl FnMut(usize) -> bool,
    ) -> bool {
        #[cfg(target_arch = "x86_64")]
        if available() {
            // SAFETY: AVX was detected.
            return unsafe { slabs::scan(self, range, x, lim, inside) };
        }
        self.scan_scalar(range, x, lim, inside)
    }

    /// [`Slabs::scan`] one edge at a time.
    #[inline]
    pub fn scan_scalar(
        &self,
        range: std::ops::Range<usize>,
        x: DVec3,
        lim: f64,
        inside: impl FnMut(usize) -> bool,
    ) -> bool {
        range
            .filter(|&k| self.projection(k, x).abs() < lim)
            .all(inside)
    }
}
