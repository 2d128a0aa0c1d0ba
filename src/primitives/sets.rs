//! Building a primitive set from a mesh: valences (SPEC 1), the primitives with their
//! weight data, and the BVH over them (SPEC 6). Building one set never builds another.

use super::PrimitiveKind;
use super::kinds::{Edge, Point, Primitive, Triangle};
use crate::bvh::{self, BuildOptions, Bvh};
use crate::mesh::{Aabb, Mesh};
use glam::Vec3;
use rayon::prelude::*;
use std::time::Instant;

/// A mesh cannot provide the requested primitive set.
#[derive(Debug, thiserror::Error)]
#[error("{mesh}: cannot build {kind}: {reason}")]
pub struct PrimitiveError {
    pub mesh: String,
    pub kind: PrimitiveKind,
    pub reason: String,
}

/// Timings of a set's construction, for `--verbose` and the reports.
#[derive(Clone, Copy, Debug, Default)]
pub struct BuildTimes {
    /// Extracting primitives and valences, seconds.
    pub primitives: f64,
    /// Building the BVH and reordering, seconds.
    pub bvh: f64,
}

/// Primitives of one kind in BVH leaf order, with their hierarchy.
#[derive(Clone, Debug)]
pub struct PrimitiveSet<P> {
    /// Primitives in leaf order; `bvh.order[i]` is the source index of `prims[i]`.
    pub prims: Vec<P>,
    pub bvh: Bvh,
    /// Largest valence (SPEC 1); 1 for points.
    pub max_adj: f64,
    pub bounds: Aabb,
    pub times: BuildTimes,
    /// Far-field tables that know directions and weights (`primitives::directional`;
    /// edge and triangle sets of a rendered object, at its `alpha`), read by the walk
    /// where they match its parameters.
    pub directional: Option<std::sync::Arc<super::directional::DirectionalTables>>,
}

impl PrimitiveSet<Point> {
    /// The points of `vertices`, built straight from the vertex array (the points are
    /// made once, in leaf order, from the build's records).
    pub fn from_vertices(vertices: &[Vec3], options: BuildOptions) -> Self {
        let t = Instant::now();
        let (bvh, sorted) = bvh::build_binary_points_with(vertices, options, |p| Point { p });
        Self::finish(bvh, sorted, 1.0, t, 0.0)
    }
}

impl<P: Primitive> PrimitiveSet<P> {
    /// Builds the BVH over `prims` and reorders them into leaf order.
    pub fn new(prims: Vec<P>, max_adj: f64, options: BuildOptions, prim_seconds: f64) -> Self {
        let t = Instant::now();
        // Points (every box is its centroid) build without a copy of their boxes.
        let points = prims.par_iter().all(|p| {
            let (b, c) = (p.bounds(), p.centroid());
            b.min == c && b.max == c
        });
        let centroid = |i: usize| prims[i].centroid();
        let bvh = if points {
            bvh::build_with(prims.len(), centroid, None, options)
        } else {
            let bounds: Vec<Aabb> = prims.par_iter().map(|p| p.bounds()).collect();
            bvh::build_with(prims.len(), centroid, Some(&bounds), options)
        };
        let sorted = bvh.order.par_iter().map(|&i| prims[i as usize]).collect();
        Self::finish(bvh, sorted, max_adj, t, prim_seconds)
    }

    /// Makes the wide form (and, for points, the moments) of `bvh` over the primitives
    /// in leaf order, `sorted`.
    fn finish(mut bvh: Bvh, sorted: Vec<P>, max_adj: f64, t: Instant, prim_seconds: f64) -> Self {
        bvh.make_wide();
        if P::IS_POINT {
            bvh.moments = bvh::moments::build(&bvh.wide, |i| sorted[i].centroid());
        }
        let bounds = bvh
            .nodes
            .first()
            .map(|n| Aabb {
                min: n.min,
                max: n.max,
            })
            .unwrap_or(Aabb::EMPTY);
        PrimitiveSet {
            prims: sorted,
            bvh,
            max_adj,
            bounds,
            times: BuildTimes {
                primitives: prim_seconds,
                bvh: t.elapsed().as_secs_f64(),
            },
            directional: None,
        }
    }

    /// Source index (vertex, edge or triangle index) of the primitive at leaf position `i`.
    pub fn source_index(&self, i: usize) -> u32 {
        self.bvh.order[i]
    }
}

/// A primitive set of any kind.
#[derive(Clone, Debug)]
pub enum AnySet {
    Points(PrimitiveSet<Point>),
    Edges(PrimitiveSet<Edge>),
    Triangles(PrimitiveSet<Triangle>),
}

/// Calls `$body` with `$s` bound to the inner `PrimitiveSet<P>` of an [`AnySet`].
#[macro_export]
macro_rules! with_set {
    ($set:expr, $s:ident => $body:expr) => {
        match $set {
            $crate::primitives::AnySet::Points($s) => $body,
            $crate::primitives::AnySet::Edges($s) => $body,
            $crate::primitives::AnySet::Triangles($s) => $body,
        }
    };
}

/// The leaves of an edge set hold up to this many edges (points and triangles: the
/// default, `bvh::BuildOptions`). A leaf is never a far-field term, and an edge's far
/// term is loose: it charges every edge the weight its middle has, where a query's
/// closest point is mostly an end, of a smaller weight (doc/performance-log.md, round
/// thirty-one; round thirty-five split it, `primitives::split`). With larger leaves the
/// groups near a query are summed exactly, the hits at 0.8 of beta (as then,
/// `TracerOptions::hit_beta_scale_edges`) stayed closer to the exact surface than at
/// 0.6 with leaves of four, and the walk, four edges to an AVX batch, is faster (round
/// thirty-two).
pub const EDGE_LEAF_SIZE: usize = 8;

impl AnySet {
    /// Builds the `kind` set of `mesh` with its kind's leaf size ([`EDGE_LEAF_SIZE`] for
    /// edges, the default otherwise).
    pub fn build(mesh: &Mesh, kind: PrimitiveKind) -> Result<AnySet, PrimitiveError> {
        let options = match kind {
            PrimitiveKind::Edges => BuildOptions {
                leaf_size: EDGE_LEAF_SIZE,
            },
            PrimitiveKind::Points | PrimitiveKind::Triangles => BuildOptions::default(),
        };
        Self::build_with(mesh, kind, options)
    }

    pub fn build_with(
        mesh: &Mesh,
        kind: PrimitiveKind,
        options: BuildOptions,
    ) -> Result<AnySet, PrimitiveError> {
        let t = Instant::now();
        let err = |reason: &str| PrimitiveError {
            mesh: mesh.name.clone(),
            kind,
            reason: reason.to_string(),
        };
        if mesh.vertices.is_empty() {
            return Err(err("the mesh has no vertices"));
        }
        Ok(match kind {
            PrimitiveKind::Points => {
                AnySet::Points(PrimitiveSet::from_vertices(&mesh.vertices, options))
            }
            PrimitiveKind::Edges => {
                let (prims, max_adj) = edges(mesh).ok_or_else(|| {
                    err("it has no edges (no `l` segments and no faces); use points")
                })?;
                AnySet::Edges(PrimitiveSet::new(prims, max_adj, options, secs(t)))
            }
            PrimitiveKind::Triangles => {
                let (prims, max_adj) =
                    triangles(mesh).ok_or_else(|| err("it has no faces; use points or edges"))?;
                AnySet::Triangles(PrimitiveSet::new(prims, max_adj, options, secs(t)))
            }
        })
    }

    pub fn kind(&self) -> PrimitiveKind {
        match self {
            AnySet::Points(_) => PrimitiveKind::Points,
            AnySet::Edges(_) => PrimitiveKind::Edges,
            AnySet::Triangles(_) => PrimitiveKind::Triangles,
        }
    }

    pub fn len(&self) -> usize {
        with_set!(self, s => s.prims.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The median length of the edges of its primitives (each triangle's three, so an
    /// inner edge counts twice); `None` for points or an empty set.
    pub fn median_edge(&self) -> Option<f64> {
        let mut lengths: Vec<f32> = match self {
            AnySet::Points(_) => return None,
            AnySet::Edges(s) => s.prims.iter().map(|e| (e.b - e.a).length()).collect(),
            AnySet::Triangles(s) => s
                .prims
                .iter()
                .flat_map(|t| {
                    [
                        (t.b - t.a).length(),
                        (t.c - t.b).length(),
                        (t.a - t.c).length(),
                    ]
                })
                .collect(),
        };
        if lengths.is_empty() {
            return None;
        }
        let mid = lengths.len() / 2;
        let (_, m, _) = lengths.select_nth_unstable_by(mid, f32::total_cmp);
        Some(*m as f64)
    }

    pub fn max_adj(&self) -> f64 {
        with_set!(self, s => s.max_adj)
    }

    pub fn bounds(&self) -> Aabb {
        with_set!(self, s => s.bounds)
    }

    pub fn bvh(&self) -> &Bvh {
        with_set!(self, s => &s.bvh)
    }

    pub fn times(&self) -> BuildTimes {
        with_set!(self, s => s.times)
    }

    /// Approximate heap memory of the set (primitives and BVH), bytes.
    pub fn memory_bytes(&self) -> usize {
        with_set!(self, s => std::mem::size_of_val(s.prims.as_slice()) + s.bvh.memory_bytes())
    }
}

fn secs(t: Instant) -> f64 {
    t.elapsed().as_secs_f64()
}

/// Edges: the mesh's explicit segments, or else the unique edges of its triangles.
/// `val(v)` counts the edges incident on `v`; `max_adj` is its maximum (SPEC 1).
fn edges(mesh: &Mesh) -> Option<(Vec<Edge>, f64)> {
    let list = if mesh.segments.is_empty() {
        mesh.triangle_edges()
    } else {
        mesh.segments.clone()
    };
    if list.is_empty() {
        return None;
    }
    let mut val = vec![0u32; mesh.vertices.len()];
    for &[a, b] in &list {
        val[a as usize] += 1;
        if a != b {
            val[b as usize] += 1;
        }
    }
    let max_adj = val.iter().copied().max().unwrap_or(1).max(1) as f64;
    let prims = list
        .iter()
        .map(|&[a, b]| Edge {
            a: mesh.vertices[a as usize],
            b: mesh.vertices[b as usize],
            val_a: val[a as usize].max(1) as f32,
            val_b: val[b as usize].max(1) as f32,
        })
        .collect();
    Some((prims, max_adj))
}

/// Triangles with `vmax` (largest incident-triangle count of their vertices) and `emax`
/// (largest incident-triangle count of their edges); `max_adj` is the largest vertex or
/// edge valence (SPEC 1).
fn triangles(mesh: &Mesh) -> Option<(Vec<Triangle>, f64)> {
    if mesh.triangles.is_empty() {
        return None;
    }
    let mut vval = vec![0u32; mesh.vertices.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            // A vertex repeated in a degenerate triangle counts once.
            if !t[..k].contains(&t[k]) {
                vval[t[k] as usize] += 1;
            }
        }
    }
    // Each edge's count of incident triangles, from the runs of equal keys in the sorted
    // (edge, triangle) list; `emax` per triangle is the largest of its edges'.
    let key = |a: u32, b: u32| ((a.min(b) as u64) << 32) | a.max(b) as u64;
    let mut keys: Vec<(u64, u32)> = mesh
        .triangles
        .par_iter()
        .enumerate()
        .flat_map_iter(|(i, t)| {
            [key(t[0], t[1]), key(t[1], t[2]), key(t[2], t[0])].map(|k| (k, i as u32))
        })
        .collect();
    keys.par_sort_unstable_by_key(|&(k, _)| k);
    let mut emax = vec![1u32; mesh.triangles.len()];
    for run in keys.chunk_by(|x, y| x.0 == y.0) {
        for &(_, i) in run {
            emax[i as usize] = emax[i as usize].max(run.len() as u32);
        }
    }
    let max_e = emax.par_iter().copied().max().unwrap_or(1);
    let prims: Vec<Triangle> = mesh
        .triangles
        .par_iter()
        .zip(emax.par_iter())
        .map(|(t, &emax)| {
            let vmax = t
                .iter()
                .map(|&i| vval[i as usize])
                .max()
                .unwrap_or(1)
                .max(1);
            Triangle::new(
                mesh.vertices[t[0] as usize],
                mesh.vertices[t[1] as usize],
                mesh.vertices[t[2] as usize],
                vmax as f32,
                emax as f32,
            )
        })
        .collect();
    let max_v = vval.iter().copied().max().unwrap_or(1);
    Some((prims, max_v.max(max_e).max(1) as f64))
}
