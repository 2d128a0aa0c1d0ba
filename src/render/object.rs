//! A traceable object: one or more primitive sets summed into one smooth distance
//! (SPEC 2), with its evaluation parameters and the bound of where its surface can be.

use super::signed::SignedSurface;
use crate::bvh::Node4;
use crate::colour::ObjectColours;
use crate::eval::{self, Along, EvalParams, FarShare, Sample};
use crate::mesh::Aabb;
use crate::primitives::directional::DirectionalTables;
use crate::primitives::{AnySet, Primitive, PrimitiveKind, PrimitiveSet, WeightScale};
use glam::DVec3;
use std::sync::Arc;

/// The largest `alpha` times median edge length at which an object of triangles counts
/// as soft (`TraceObject::soft_triangles`): there the tracer decides hits at a coarser
/// beta (`TracerOptions::hit_beta_scale_soft_triangles`; doc/performance-log.md, round
/// twenty-one).
pub const SOFT_MAX_ALPHA_EDGE: f64 = 3.0;

/// Gives `set` directional tables at `alpha` and `max_alpha` by `build`, unless it has
/// them already.
fn refresh<P: Primitive>(
    set: &mut PrimitiveSet<P>,
    alpha: f64,
    max_alpha: f64,
    build: impl Fn(&[P], &[Node4], f64, &WeightScale) -> DirectionalTables,
) {
    let scale = WeightScale::new(set.max_adj, alpha, max_alpha);
    let current = set
        .directional
        .as_ref()
        .is_some_and(|t| t.alpha == alpha && t.q == scale.q);
    if !current {
        set.directional = Some(Arc::new(build(&set.prims, &set.bvh.wide, alpha, &scale)));
    }
}

/// Primitive sets summed into one smooth distance, evaluated with `params`.
pub struct TraceObject {
    pub sets: Vec<AnySet>,
    pub params: EvalParams,
    /// Union of the sets' bounding boxes.
    pub bounds: Aabb,
    /// Colours from the data, one [`crate::colour::SetColours`] per set; `None` shades
    /// with the MatCap alone.
    pub colours: Option<ObjectColours>,
    /// `surface = "signed"`: the object draws this offset surface of its triangles'
    /// signed distance instead of its smooth distance's zero set (`render::signed`).
    pub signed: Option<SignedSurface>,
    /// The largest median edge length of its sets when all are triangles (`None`
    /// otherwise), measured once: what [`TraceObject::soft_triangles`] compares with
    /// `alpha` (the scene builder's server changes `alpha`, not the sets).
    triangle_edge: Option<f64>,
    /// Seconds spent building its edge and triangle sets' directional far-field tables
    /// (0 for points), for the build report.
    pub tables_seconds: f64,
}

impl TraceObject {
    pub fn new(sets: Vec<AnySet>, params: EvalParams) -> TraceObject {
        let bounds = sets.iter().fold(Aabb::EMPTY, |b, s| b.union(s.bounds()));
        let triangle_edge = sets
            .iter()
            .map(|s| match s {
                AnySet::Triangles(_) => s.median_edge(),
                _ => None,
            })
            .try_fold(0.0f64, |longest, e| e.map(|e| longest.max(e)))
            .filter(|_| !sets.is_empty());
        let mut object = TraceObject {
            sets,
            params,
            bounds,
            colours: None,
            signed: None,
            triangle_edge,
            tables_seconds: 0.0,
        };
        object.tables_seconds = object.update_far_tables();
        object
    }

    /// Gives its edge and triangle sets directional far-field tables at its own `alpha`
    /// and `max_alpha` (`primitives::directional`; the walk takes them where its
    /// parameters match), building only those that do not match yet: call it after
    /// changing `params` (the scene builder's server does). Returns the seconds spent.
    pub fn update_far_tables(&mut self) -> f64 {
        let t = std::time::Instant::now();
        let (alpha, max_alpha) = (self.params.alpha, self.params.max_alpha);
        for s in &mut self.sets {
            match s {
                AnySet::Edges(e) => refresh(e, alpha, max_alpha, DirectionalTables::for_edges),
                AnySet::Triangles(t) => {
                    refresh(t, alpha, max_alpha, DirectionalTables::for_triangles)
                }
                AnySet::Points(_) => {}
            }
        }
        t.elapsed().as_secs_f64()
    }

    pub fn set_refs(&self) -> Vec<&AnySet> {
        self.sets.iter().collect()
    }

    /// Every set of the object holds primitives of `kind`.
    pub fn only(&self, kind: PrimitiveKind) -> bool {
        self.sets.iter().all(|s| s.kind() == kind)
    }

    /// Whether the object is made of triangles alone and its `alpha` times their median
    /// edge length is at most [`SOFT_MAX_ALPHA_EDGE`]: a soft field over a dense mesh,
    /// where many triangles lie within the kernel's width.
    pub fn soft_triangles(&self) -> bool {
        self.signed.is_none()
            && self
                .triangle_edge
                .is_some_and(|e| self.params.alpha * e <= SOFT_MAX_ALPHA_EDGE)
    }

    /// How far outside the data's bounding box the zero set can reach at sharpness
    /// `alpha` (a signed surface: its offset, `render::signed`): every evaluation (at any beta) satisfies `s(x) >= r(x) - ln(N w_max) /
    /// alpha` with `r` the distance to the box, because the sum is at most `N w_max
    /// exp(-alpha r)`.
    pub fn reach(&self, alpha: f64) -> f64 {
        if let Some(signed) = &self.signed {
            return signed.reach();
        }
        let n: usize = self.sets.iter().map(|s| s.len()).sum();
        let w_max = self
            .sets
            .iter()
            .map(|s| WeightScale::new(s.max_adj(), alpha, self.params.max_alpha).max_weight())
            .fold(1.0, f64::max);
        (n.max(1) as f64 * w_max).ln() / alpha
    }

    /// The object's box grown by its [`reach`](Self::reach) at its own alpha, as
    /// `(min, max)`: where its surface can be (what auto-framing fits).
    pub fn reach_bounds(&self) -> (DVec3, DVec3) {
        let r = self.reach(self.params.alpha).max(0.0);
        (
            self.bounds.min.as_dvec3() - r,
            self.bounds.max.as_dvec3() + r,
        )
    }

    /// A lower bound of the smooth distance at `x` that costs no traversal.
    pub fn lower_bound(&self, x: DVec3, reach: f64) -> f64 {
        let (r, _) = crate::geometry::closest::closest_on_box(
            x,
            self.bounds.min.as_dvec3(),
            self.bounds.max.as_dvec3(),
        );
        r - reach
    }

    /// Evaluates the smooth distance with the object's parameters, alpha possibly
    /// replaced (the naive mode's falloff), at opening parameter `beta` (the tracer's
    /// bound steps take a coarser one, a lower bound of the scene's sum; its hit
    /// decisions a finer one) and the pruning tolerance possibly raised (a lower bound
    /// too, see `eval::smooth`), with the gradient if `grad`, and with the free distances
    /// along a ray if `along` is given (`eval::reach`); with closest-box
    /// far fields if `bound` (a bound step); with `Sample::s_upper` if `upper`; with far
    /// terms by share as well as by beta where `far_share` says so (hit decisions).
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        sets: &[&AnySet],
        x: DVec3,
        alpha: f64,
        beta: f64,
        prune_tolerance: f64,
        grad: bool,
        along: Option<Along>,
        bound: bool,
        upper: bool,
        far_share: FarShare,
    ) -> Sample {
        if let Some(signed) = &self.signed {
            return signed.sample(x, grad);
        }
        let mut p = self.params;
        p.upper_bound = upper;
        p.alpha = alpha;
        p.beta = beta;
        p.prune_tolerance = p.prune_tolerance.max(prune_tolerance);
        // Bound steps take closest-box far fields: both are lower bounds of the sum, so
        // either keeps a bound step safe, and the tighter moment terms buy no longer steps
        // there for their extra cost (performance log, round four). Soft triangle meshes
        // are the exception: there the directional terms (`primitives::directional`)
        // bring the bound steps nearer the surface, and fewer full values follow, each
        // of hundreds of leaves (the published full bunny's far view: the first full
        // value 12-24 epsilons out on 76% of the hit rays, 12-48 on 72% before;
        // doc/performance-log.md, round thirty).
        p.moments &= !bound || self.soft_triangles();
        p.far_share = far_share;
        eval::evaluate_along(sets, x, along, &p, grad)
    }
}
