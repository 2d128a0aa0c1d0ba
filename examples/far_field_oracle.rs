//! Far-field oracle: how far below the exact smooth distance a Barnes-Hut sum over an
//! edge or triangle mesh lies at the hits, for the engine's far-field term and for
//! tighter ones that could replace it (doc/performance-log.md, round twenty-eight).
//!
//! At the hits of the scene's own tracer (every `STEP`-th pixel of every `STEP`-th row,
//! 480x270), a plain Barnes-Hut walk over the binary BVH (no pruning) takes a subtree
//! as one far term where its box diagonal is below `beta` times its distance, and
//! sums it by each of these bounds (all of them at least the subtree's exact sum):
//! - `box, max weight`: `n w_max exp(-alpha r)`, `r` the distance to the box (the
//!   engine's far term for edges and triangles, SPEC 6);
//! - `box, actual weights`: the primitives' weights at their closest points (an
//!   oracle: a walk does not know them);
//! - `box, cone weights`: each primitive's largest weight at a point that can be its
//!   closest from the directions in which the query sees the box (a vertex always; an
//!   edge's interior only where some such direction is perpendicular to it; a face's
//!   interior only where one is along its normal), the cone widened by `WIDEN` degrees
//!   as a table over direction bins would widen it;
//! - `directional`: `|x - p| >= u . (x - p)` for `u` the unit direction from the box
//!   centre `c` to `x`, so a primitive's term is at most `w exp(-alpha (u . (x - c) -
//!   s(u)))`, `s(u)` its largest `u . (p - c)` over its vertices; with the largest
//!   weight, cone weights or actual weights (the exact direction: a table over
//!   directions loses some of it);
//! - `directional, weighted support`: the largest `u . (p - c) + ln w(p) / alpha` over
//!   the primitive (no knowledge of the closest point needed);
//! - `weighted support, 25-direction grid`: the same summed per subtree in the log
//!   domain, `D(v) = ln sum exp(alpha s(v))`, tabulated at an octahedral grid of 25
//!   directions scaled out by `S` and at `v = 0`, and bounded between them by its
//!   convexity (`geometry::directions`; the bound the round proposes). Each such term is checked
//!   against its subtree's exact sum, and the count below it printed;
//! - `centroid moments`: Bennett's bound on the centroids, each primitive within `rho`
//!   of its centroid (`exp(alpha rho_max)` more), the largest weight (the bound of
//!   point clouds, `eval::smooth`, carried over to primitives with extent).
//!
//! On edges, four more (doc/performance-log.md, round thirty-one): an edge's weight split
//! into its ends' weight `w_E` (the larger of the two, everywhere along the edge) and the
//! bump above it inside the edge (at most `b`, both from `primitives::support`'s
//! pieces, certain). The bump counts only where the closest point is inside the edge,
//! which needs the query to see the edge at nearly a right angle: `|e . u| <= h / l` for
//! the box's half diagonal `h` at distance `l` from its centre.
//! - `split, exact bump`: `w_E` with the directional distance, plus each edge's actual
//!   rise above `w_E` where its closest point is inside it (an oracle);
//! - `split, right-angle bumps`: the same with `b` for every edge that passes the test
//!   (certain, with the exact direction);
//! - `grid, ends' weight alone`: `w_E`'s weighted support on the 25-direction grid, no
//!   bump (not a bound: the floor of what the grid can reach);
//! - `grid, ends' weight + axis-bin bumps`: that plus, per bin of edge directions (one
//!   per pair of opposite points of a 9 x 9 grid, 33 axes), the bumps' weighted support
//!   on the grid where the bin's axis passes the test widened by its edges' largest
//!   angle to it (certain; the tables a walk could read);
//! - `grid, ends' weight + bumps where inside`: the ends' weight's grid table plus `b`
//!   for each edge that the query projects inside (`0 < t < 1`, one dot product per
//!   edge; elsewhere the closest point is an end, whose weight the table holds):
//!   certain, at the cost of a test per edge of the far subtree (doc/performance-log.md,
//!   round thirty-four);
//! - `directional, closest feature's weight`: the directional distance with the largest
//!   weight of the feature (corner, edge or face; an edge's end or inside) that holds the
//!   primitive's closest point, as a test of where the query projects would know it
//!   (sampled maxima, as the cone weights).
//!
//! The weights' maxima over an edge or a face are sampled (17 points per edge, 66 per
//! face, 91 per primitive for the weighted support), not bounded: these are
//! measurements of what a bound could reach, not bounds. Except in the grid's tables
//! on edges: there the weighted support is certain (`primitives::support`, 32 pieces per
//! edge, the weight quartic's maximum on each from its critical points).
//! Printed per beta: leaves (exact terms plus far terms) per point, the primitives
//! below the far terms within reach of the nearest distance (`alpha (r - d_min) <= 2 +
//! ln(n w_max)`, as the walk reads the tables: what a far term that tests each primitive
//! would read), and the median and
//! 90th percentile of each sum's deficit below the exact value, in epsilons.
//!
//! `cargo run --release --example far_field_oracle -- SCENE [STEP] [WIDEN] [BETAS]`
//! (defaults 7, 0, `0.35,0.5,0.7,1`).
use glam::DVec3;
use smoothtrace::bvh::Node;
use smoothtrace::geometry::closest::{TriFeature, closest_on_triangle};
use smoothtrace::geometry::directions::DirectionGrid;
use smoothtrace::primitives::directional::lse;
use smoothtrace::primitives::support::{edge_piece_log_weights, edge_weighted_support};
use smoothtrace::primitives::{AnySet, Edge, Primitive, PrimitiveSet, Triangle, WeightScale};
use smoothtrace::render::TracerOptions;
use smoothtrace::render::build::build_scene;
use smoothtrace::render::tracer::Tracer;
use smoothtrace::reports::quantile;
use smoothtrace::scene::Scene;
use std::path::Path;

const NAMES: [&str; 15] = [
    "box, max weight",
    "box, actual weights",
    "box, cone weights",
    "directional, max weight",
    "directional, cone weights",
    "directional, actual weights",
    "directional, weighted support",
    "centroid moments",
    "weighted support, 25-direction grid",
    "split, exact bump (edges)",
    "split, right-angle bumps (edges)",
    "grid, ends' weight alone (edges)",
    "grid, ends' weight + axis-bin bumps (edges)",
    "grid, ends' weight + bumps where inside (edges)",
    "directional, closest feature's weight",
];

/// The side of the grid whose points give the bump bins' axes (33 axes).
const BUMP_AXES: usize = 9;

/// A node's bins of edge directions that hold a bump: axis, largest chord, grid table.
type BumpBins = Vec<(DVec3, f64, Vec<f64>)>;

/// What a far term needs to know of one primitive: its vertices (an edge's second
/// repeated), the largest weight at a vertex, along each edge and over the face, the
/// edges' unit directions and the face's unit normal (zero for an edge).
struct Shape {
    v: [DVec3; 3],
    w_vertex: f64,
    w_edge: [f64; 3],
    dir_edge: [DVec3; 3],
    w_face: f64,
    normal: DVec3,
}

trait Vertices: Primitive {
    fn vertices(&self) -> [DVec3; 3];

    /// The largest weight of the feature (vertex, edge or face) holding the closest
    /// point to `x`, from the shape's sampled maxima: what a test of where `x` projects
    /// can know without the weight itself.
    fn feature_weight(&self, s: &Shape, x: DVec3) -> f64;

    /// Certain upper bounds of `max over p of alpha g . p + ln w(p)`, one per direction
    /// `g` of `dirs` (`None`: only sampled for this kind).
    fn certain_supports(
        &self,
        _dirs: &[DVec3],
        _alpha: f64,
        _scale: &WeightScale,
    ) -> Option<Vec<f64>> {
        None
    }

    /// Edges: `(w_E, b)`, the ends' weight and the bound of the bump above it (module
    /// docs), certain.
    fn bump_split(&self, _scale: &WeightScale) -> Option<(f64, f64)> {
        None
    }
}

impl Vertices for Triangle {
    fn vertices(&self) -> [DVec3; 3] {
        [self.a.as_dvec3(), self.b.as_dvec3(), self.c.as_dvec3()]
    }

    fn feature_weight(&self, s: &Shape, x: DVec3) -> f64 {
        let [a, b, c] = self.vertices();
        match closest_on_triangle(x, a, b, c).feature {
            TriFeature::VertexA | TriFeature::VertexB | TriFeature::VertexC => s.w_vertex,
            TriFeature::EdgeAB => s.w_edge[0],
            TriFeature::EdgeBC => s.w_edge[1],
            TriFeature::EdgeAC => s.w_edge[2],
            TriFeature::Face => s.w_face,
            TriFeature::Degenerate => s.w_face.max(s.w_edge[0]).max(s.w_edge[1]).max(s.w_edge[2]),
        }
    }
}

impl Vertices for Edge {
    fn vertices(&self) -> [DVec3; 3] {
        [self.a.as_dvec3(), self.b.as_dvec3(), self.b.as_dvec3()]
    }

    fn feature_weight(&self, s: &Shape, x: DVec3) -> f64 {
        let (a, e) = (self.a.as_dvec3(), (self.b - self.a).as_dvec3());
        let t = (x - a).dot(e) / e.length_squared();
        if t > 0.0 && t < 1.0 {
            s.w_edge[0]
        } else {
            s.w_vertex
        }
    }

    /// `primitives::support`: certain, from 32 pieces of the edge (their weights once).
    fn certain_supports(
        &self,
        dirs: &[DVec3],
        alpha: f64,
        scale: &WeightScale,
    ) -> Option<Vec<f64>> {
        let lw = edge_piece_log_weights(self, scale);
        Some(
            dirs.iter()
                .map(|&g| edge_weighted_support(self, g, alpha, &lw))
                .collect(),
        )
    }

    fn bump_split(&self, scale: &WeightScale) -> Option<(f64, f64)> {
        let lw = edge_piece_log_weights(self, scale);
        let end = lw[0].max(lw[lw.len() - 1]);
        let peak = lw.iter().fold(end, |m, &v| m.max(v));
        Some((end.exp(), (peak.exp() - end.exp()).max(0.0)))
    }
}

fn shape<P: Vertices>(p: &P, scale: &WeightScale) -> Shape {
    let v = p.vertices();
    let w = |q: DVec3| p.value(q, scale).1;
    let w_vertex = v.iter().map(|&q| w(q)).fold(0.0, f64::max);
    let mut w_edge = [0.0; 3];
    let mut dir_edge = [DVec3::ZERO; 3];
    for e in 0..3 {
        let (a, b) = (v[e], v[(e + 1) % 3]);
        dir_edge[e] = (b - a).normalize_or_zero();
        w_edge[e] = (0..=16)
            .map(|j| w(a + (b - a) * (j as f64 / 16.0)))
            .fold(0.0, f64::max);
    }
    let mut w_face = w_vertex;
    for i in 0..=10 {
        for j in 0..=(10 - i) {
            let q = v[0] + (v[1] - v[0]) * (i as f64 / 10.0) + (v[2] - v[0]) * (j as f64 / 10.0);
            w_face = w_face.max(w(q));
        }
    }
    Shape {
        v,
        w_vertex,
        w_edge,
        dir_edge,
        w_face,
        normal: (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero(),
    }
}

impl Shape {
    /// The largest weight of a point that can be closest to a query seen in directions
    /// within `sin_t` (sine of the half-angle) of `u`.
    fn cone_weight(&self, u: DVec3, sin_t: f64) -> f64 {
        let mut w = self.w_vertex;
        for e in 0..3 {
            if self.dir_edge[e] != DVec3::ZERO && u.dot(self.dir_edge[e]).abs() <= sin_t {
                w = w.max(self.w_edge[e]);
            }
        }
        let cos_t = (1.0 - sin_t * sin_t).max(0.0).sqrt();
        if self.normal != DVec3::ZERO && u.dot(self.normal).abs() >= cos_t {
            w = w.max(self.w_face);
        }
        w
    }

    /// `max u . (p - c)` over the vertices.
    fn support(&self, u: DVec3, c: DVec3) -> f64 {
        self.v
            .iter()
            .map(|&p| u.dot(p - c))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// An edge's two ends (the shape repeats the second).
fn edge_ends(s: &Shape) -> [DVec3; 2] {
    [s.v[0], s.v[1]]
}

/// The grid's size: 5 x 5 directions (round twenty-one's).
const G: usize = 5;

/// The first primitive (in leaf order) below each node of a binary BVH.
fn starts(nodes: &[Node]) -> Vec<usize> {
    fn fill(nodes: &[Node], i: usize, start: &mut [usize]) -> usize {
        let n = &nodes[i];
        start[i] = if n.is_leaf() {
            n.index as usize
        } else {
            let s = fill(nodes, i + 1, start);
            fill(nodes, n.index as usize, start);
            s
        };
        start[i]
    }
    let mut start = vec![0; nodes.len()];
    if !nodes.is_empty() {
        fill(nodes, 0, &mut start);
    }
    start
}

struct Oracle<'s, P> {
    set: &'s PrimitiveSet<P>,
    scale: WeightScale,
    alpha: f64,
    shapes: Vec<Shape>,
    start: Vec<usize>,
    widen: f64,
    grid: DirectionGrid,
    /// Per node: `alpha` times its weighted support at each scaled grid direction,
    /// about the origin, summed over its primitives in the log domain, and (last) at
    /// the zero direction (`ln sum w_max`).
    tables: Vec<Vec<f64>>,
    /// Edges: per primitive `(w_E, b)` (module docs); empty for triangles.
    split: Vec<(f64, f64)>,
    /// Edges: per node, the ends' weight's grid table (as `tables`), and per bin of
    /// edge directions that holds a bump its axis, largest chord and grid table.
    end_tables: Vec<Vec<f64>>,
    bump_bins: Vec<BumpBins>,
    /// Edges of far terms, and those whose closest point lies inside them.
    far_edges: std::cell::Cell<usize>,
    inside: std::cell::Cell<usize>,
    /// Primitives below far terms (what a test per primitive would read).
    far_prims: std::cell::Cell<usize>,
    /// Far terms whose grid bound fell below their exact sum, and the worst ratio.
    violations: std::cell::Cell<usize>,
    worst: std::cell::Cell<f64>,
}

impl<P: Vertices> Oracle<'_, P> {
    /// A node's grid table `t` (about the origin) at the unit `u` from its centre `c`.
    fn on_grid(&self, t: &[f64], u: DVec3, c: DVec3) -> f64 {
        let (idx, mu) = self.grid.cone(u);
        let m: f64 = mu.iter().sum();
        let sc = self.grid.scale();
        let mut d = (1.0 - m / sc) * t[self.grid.len()];
        for k in 0..3 {
            // About the centre c: the support shifts by -g . c.
            let g = sc * self.grid.direction(idx[k]);
            d += mu[k] / sc * (t[idx[k]] - self.alpha * g.dot(c));
        }
        d
    }

    /// Each bound's sum at `x` for `beta` (NaN for rows that do not apply), the exact
    /// sum, and the leaves.
    fn sums(&self, x: DVec3, beta: f64) -> ([f64; 15], f64, usize) {
        let (nodes, prims, alpha) = (&self.set.bvh.nodes, &self.set.prims, self.alpha);
        let w_max = self.scale.max_weight();
        let mut sums = [0.0; 15];
        if self.split.is_empty() {
            sums[9..14].fill(f64::NAN);
        }
        let (mut exact, mut leaves) = (0.0, 0);
        // The nearest distance, for the far terms within reach of it (those a walk reads
        // the tables for, `eval::walk`'s `SIGNIFICANT`).
        let d_min = prims
            .iter()
            .map(|p| p.value(x, &self.scale).0)
            .fold(f64::INFINITY, f64::min);
        let mut stack = vec![0usize];
        while let Some(i) = stack.pop() {
            let n = &nodes[i];
            let r = n.distance_squared(x).sqrt();
            let range = self.start[i]..self.start[i] + n.size as usize;
            if r > 0.0 && (n.diam as f64) < beta * r {
                leaves += 1;
                let ln_w = (n.size as f64 * w_max).ln().max(0.0);
                if alpha * (r - d_min) <= 2.0 + ln_w {
                    self.far_prims.set(self.far_prims.get() + n.size as usize);
                }
                let count = n.size as f64;
                let boxed = (-alpha * r).exp();
                let c = 0.5 * (n.min.as_dvec3() + n.max.as_dvec3());
                let l = (x - c).length();
                let u = (x - c) / l;
                let half_angle =
                    (0.5 * n.diam as f64 / l).min(1.0).asin() + self.widen.to_radians();
                let sin_t = half_angle.min(std::f64::consts::FRAC_PI_2).sin();
                let mut part = [0.0; 8];
                let node_exact: f64 = range
                    .clone()
                    .map(|k| {
                        let (d, w) = prims[k].value(x, &self.scale);
                        w * (-alpha * d).exp()
                    })
                    .sum();
                // Round twenty-eight's proposal: the weighted support tabulated at the
                // grid and bounded between them by convexity.
                {
                    let d = self.on_grid(&self.tables[i], u, c);
                    let bound = (-alpha * u.dot(x - c) + d).exp();
                    if bound < node_exact * (1.0 - 1e-9) {
                        self.violations.set(self.violations.get() + 1);
                        let r = node_exact / bound;
                        if r > self.worst.get() {
                            self.worst.set(r);
                        }
                    }
                    sums[8] += bound.min(count * w_max * boxed);
                }
                if !self.split.is_empty() {
                    // The bump counts where the edge is seen at nearly a right angle.
                    let right = 0.5 * n.diam as f64 / l;
                    let (mut oracle, mut certain, mut inside_bumps) = (0.0, 0.0, 0.0);
                    for k in range.clone() {
                        let (w_e, b) = self.split[k];
                        let v = edge_ends(&self.shapes[k]);
                        let dir = (-alpha
                            * (l - v
                                .iter()
                                .map(|&p| u.dot(p - c))
                                .fold(f64::NEG_INFINITY, f64::max)))
                        .exp();
                        oracle += w_e * dir;
                        certain += w_e * dir;
                        let (a, e) = (v[0], v[1] - v[0]);
                        let t = (x - a).dot(e) / e.length_squared();
                        self.far_edges.set(self.far_edges.get() + 1);
                        if t > 0.0 && t < 1.0 {
                            inside_bumps += b * dir;
                            self.inside.set(self.inside.get() + 1);
                            let (d, w) = prims[k].value(x, &self.scale);
                            oracle += (w - w_e).max(0.0) * (-alpha * d).exp();
                        }
                        if u.dot(e.normalize_or_zero()).abs() <= right {
                            certain += b * dir;
                        }
                    }
                    let box_term = count * w_max * boxed;
                    sums[9] += oracle.min(box_term);
                    sums[10] += certain.min(box_term);
                    let ends = (-alpha * l + self.on_grid(&self.end_tables[i], u, c)).exp();
                    sums[11] += ends.min(box_term);
                    let bumps: f64 = self.bump_bins[i]
                        .iter()
                        .filter(|(axis, chord, _)| axis.dot(u).abs() <= right + chord)
                        .map(|(_, _, t)| (-alpha * l + self.on_grid(t, u, c)).exp())
                        .sum();
                    sums[12] += (ends + bumps).min(box_term);
                    // Where the query projects inside an edge (a test per edge, certain),
                    // its bump above the ends' weight; elsewhere the closest point is an
                    // end, whose weight the ends' table holds.
                    sums[13] += (ends + inside_bumps).min(box_term);
                }
                let (mut moment_var, mut moment_z, mut rho_max) = (0.0, 0.0f64, 0.0f64);
                let mean: DVec3 = range
                    .clone()
                    .map(|k| prims[k].centroid().as_dvec3())
                    .sum::<DVec3>()
                    / count;
                for k in range.clone() {
                    let (d, w) = prims[k].value(x, &self.scale);
                    let s = &self.shapes[k];
                    let term = w * (-alpha * d).exp();
                    exact += term;
                    let wc = s.cone_weight(u, sin_t);
                    part[1] += w;
                    part[2] += wc;
                    let dir = (-alpha * (l - s.support(u, c))).exp();
                    part[3] += w_max * dir;
                    part[4] += wc * dir;
                    part[5] += w * dir;
                    part[7] += prims[k].feature_weight(s, x) * dir;
                    let weighted = (0..=12)
                        .flat_map(|i| (0..=(12 - i)).map(move |j| (i, j)))
                        .map(|(i, j)| {
                            let q = s.v[0]
                                + (s.v[1] - s.v[0]) * (i as f64 / 12.0)
                                + (s.v[2] - s.v[0]) * (j as f64 / 12.0);
                            u.dot(q - c) + prims[k].value(q, &self.scale).1.ln() / alpha
                        })
                        .fold(f64::NEG_INFINITY, f64::max);
                    part[6] += (-alpha * (l - weighted)).exp();
                    let cm = prims[k].centroid().as_dvec3();
                    let a = u.dot(cm - mean);
                    moment_var += a * a / count;
                    moment_z = moment_z.max(alpha * a);
                    rho_max =
                        rho_max.max(s.v.iter().map(|&p| (p - cm).length()).fold(0.0, f64::max));
                }
                let box_term = count * w_max * boxed;
                sums[0] += box_term;
                sums[1] += part[1] * boxed;
                sums[2] += part[2] * boxed;
                // A directional term is a bound as well: the smaller of the two is.
                sums[3] += part[3].min(box_term);
                sums[4] += part[4].min(part[2] * boxed);
                sums[5] += part[5].min(part[1] * boxed);
                sums[6] += part[6].min(box_term);
                sums[14] += part[7].min(box_term);
                let g = if moment_z < 1e-9 {
                    0.5
                } else {
                    (moment_z.exp() - 1.0 - moment_z) / (moment_z * moment_z)
                };
                let lm = (x - mean).length();
                let moments = count
                    * w_max
                    * (alpha * rho_max).exp()
                    * (1.0 + alpha * alpha * moment_var * g)
                    * (-alpha * lm).exp();
                sums[7] += moments.min(box_term);
            } else if n.is_leaf() {
                for k in range {
                    leaves += 1;
                    let (d, w) = prims[k].value(x, &self.scale);
                    let term = w * (-alpha * d).exp();
                    exact += term;
                    for s in sums.iter_mut() {
                        *s += term;
                    }
                }
            } else {
                stack.push(i + 1);
                stack.push(n.index as usize);
            }
        }
        (sums, exact, leaves)
    }
}

/// Per node of an edge set: the ends' weight's grid table and the bins' bump tables
/// (module docs), about the origin.
fn split_tables<P: Vertices>(
    set: &PrimitiveSet<P>,
    split: &[(f64, f64)],
    start: &[usize],
    grid: &DirectionGrid,
    alpha: f64,
) -> (Vec<Vec<f64>>, Vec<BumpBins>) {
    let dirs: Vec<DVec3> = (0..grid.len())
        .map(|k| grid.scale() * grid.direction(k))
        .chain([DVec3::ZERO])
        .collect();
    let axis_grid = DirectionGrid::new(BUMP_AXES);
    let axes: Vec<DVec3> = (0..axis_grid.len())
        .map(|k| axis_grid.direction(k))
        .filter(|a| {
            let first = if a.z != 0.0 {
                a.z
            } else if a.y != 0.0 {
                a.y
            } else {
                a.x
            };
            first > 0.0
        })
        .collect();
    let supports = |p: &P, w: f64| -> Vec<f64> {
        let v = p.vertices();
        dirs.iter()
            .map(|g| alpha * g.dot(v[0]).max(g.dot(v[1])) + w.ln())
            .collect()
    };
    // Per edge: its bin's index and chord (the nearer of the axis' two directions).
    let bins: Vec<(usize, f64)> = set
        .prims
        .iter()
        .map(|p| {
            let v = p.vertices();
            let e = (v[1] - v[0]).normalize_or_zero();
            axes.iter()
                .map(|a| (e - *a).length().min((e + *a).length()))
                .enumerate()
                .fold((0, f64::INFINITY), |b, c| if c.1 < b.1 { c } else { b })
        })
        .collect();
    let mut end_tables = Vec::new();
    let mut bump_bins = Vec::new();
    for (i, n) in set.bvh.nodes.iter().enumerate() {
        let mut ends = vec![f64::NEG_INFINITY; dirs.len()];
        let mut node_bins: BumpBins = Vec::new();
        let mut bin_of: std::collections::HashMap<usize, usize> = Default::default();
        for k in start[i]..start[i] + n.size as usize {
            let (w_e, b) = split[k];
            for (t, v) in ends.iter_mut().zip(supports(&set.prims[k], w_e)) {
                *t = lse(*t, v);
            }
            if b > 0.0 {
                let (axis, chord) = bins[k];
                let j = *bin_of.entry(axis).or_insert_with(|| {
                    node_bins.push((axes[axis], 0.0, vec![f64::NEG_INFINITY; dirs.len()]));
                    node_bins.len() - 1
                });
                let bin = &mut node_bins[j];
                bin.1 = bin.1.max(chord);
                for (t, v) in bin.2.iter_mut().zip(supports(&set.prims[k], b)) {
                    *t = lse(*t, v);
                }
            }
        }
        end_tables.push(ends);
        bump_bins.push(node_bins);
    }
    (end_tables, bump_bins)
}

fn run<P: Vertices>(
    set: &PrimitiveSet<P>,
    points: &[DVec3],
    alpha: f64,
    max_alpha: f64,
    eps: f64,
    widen: f64,
    betas: &[f64],
) {
    let scale = WeightScale::new(set.max_adj, alpha, max_alpha);
    let grid = DirectionGrid::new(G);
    println!(
        "grid: {} directions, scaled by {:.4}",
        grid.len(),
        grid.scale()
    );
    // The grid's scaled directions, then the zero direction.
    let dirs: Vec<DVec3> = (0..grid.len())
        .map(|k| grid.scale() * grid.direction(k))
        .chain([DVec3::ZERO])
        .collect();
    // Per primitive, sampled: max over p of alpha (g . p) + ln w(p), for each g.
    let prim_tables: Vec<Vec<f64>> = set
        .prims
        .iter()
        .map(|p| {
            let v = p.vertices();
            let samples: Vec<(DVec3, f64)> = (0..=12)
                .flat_map(|i| (0..=(12 - i)).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let q = v[0]
                        + (v[1] - v[0]) * (i as f64 / 12.0)
                        + (v[2] - v[0]) * (j as f64 / 12.0);
                    (q, p.value(q, &scale).1.ln())
                })
                .collect();
            p.certain_supports(&dirs, alpha, &scale).unwrap_or_else(|| {
                dirs.iter()
                    .map(|&g| {
                        samples
                            .iter()
                            .map(|&(q, lw)| alpha * g.dot(q) + lw)
                            .fold(f64::NEG_INFINITY, f64::max)
                    })
                    .collect()
            })
        })
        .collect();
    let start = starts(&set.bvh.nodes);
    let tables: Vec<Vec<f64>> = set
        .bvh
        .nodes
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let mut t = vec![f64::NEG_INFINITY; grid.len() + 1];
            for prim in &prim_tables[start[i]..start[i] + n.size as usize] {
                for (a, b) in t.iter_mut().zip(prim) {
                    *a = lse(*a, *b);
                }
            }
            t
        })
        .collect();
    let split: Vec<(f64, f64)> = set
        .prims
        .iter()
        .map_while(|p| p.bump_split(&scale))
        .collect();
    let (end_tables, bump_bins) = if split.is_empty() {
        (Vec::new(), Vec::new())
    } else {
        split_tables(set, &split, &start, &grid, alpha)
    };
    let oracle = Oracle {
        split,
        end_tables,
        bump_bins,
        far_edges: Default::default(),
        inside: Default::default(),
        far_prims: Default::default(),
        violations: Default::default(),
        worst: std::cell::Cell::new(1.0),
        grid,
        tables,
        set,
        shapes: set.prims.iter().map(|p| shape(p, &scale)).collect(),
        scale,
        alpha,
        start,
        widen,
    };
    for &beta in betas {
        oracle.far_edges.set(0);
        oracle.inside.set(0);
        oracle.far_prims.set(0);
        let mut deficits: Vec<Vec<f64>> = vec![Vec::new(); NAMES.len()];
        let mut leaves = 0;
        for &x in points {
            let (sums, exact, n) = oracle.sums(x, beta);
            leaves += n;
            for (d, s) in deficits.iter_mut().zip(sums) {
                // s_exact - s_bound = ln(sum_bound / sum_exact) / alpha.
                d.push((s / exact).ln() / alpha / eps);
            }
        }
        println!(
            "beta {beta}: {:.0} leaves per point ({:.0} primitives below far terms within reach); grid bound below the exact sum: {} far terms (worst by {:.3e})",
            leaves as f64 / points.len() as f64,
            oracle.far_prims.get() as f64 / points.len() as f64,
            oracle.violations.get(),
            oracle.worst.get() - 1.0
        );
        if oracle.far_edges.get() > 0 {
            println!(
                "  far terms' edges whose closest point lies inside them: {:.1}%",
                100.0 * oracle.inside.get() as f64 / oracle.far_edges.get() as f64
            );
        }
        for (name, d) in NAMES.iter().zip(&mut deficits) {
            if d.iter().all(|v| v.is_nan()) {
                continue;
            }
            println!(
                "  {name:30} deficit p50 {:.3}, p90 {:.3} epsilons",
                quantile(d, 0.5).unwrap_or(f64::NAN),
                quantile(d, 0.9).unwrap_or(f64::NAN)
            );
        }
    }
}

fn main() -> anyhow::Result<()> {
    use anyhow::{Context, bail};
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else {
        bail!("usage: far_field_oracle SCENE [STEP] [WIDEN] [BETAS]");
    };
    let step: usize =
        match args.get(2) {
            Some(s) => s.parse().ok().filter(|&n| n > 0).with_context(|| {
                format!("STEP: expected a pixel stride of 1 or more, got `{s}`")
            })?,
            None => 7,
        };
    let widen: f64 = match args.get(3) {
        Some(s) => s
            .parse()
            .ok()
            .filter(|w: &f64| (0.0..=90.0).contains(w))
            .with_context(|| format!("WIDEN: expected degrees from 0 to 90, got `{s}`"))?,
        None => 0.0,
    };
    let betas: Vec<f64> = match args.get(4) {
        Some(s) => s
            .split(',')
            .map(|b| b.parse().ok().filter(|b: &f64| *b > 0.0))
            .collect::<Option<_>>()
            .with_context(|| {
                format!("BETAS: expected positive numbers like 0.35,0.5, got `{s}`")
            })?,
        None => vec![0.35, 0.5, 0.7, 1.0],
    };
    let mut scene = Scene::load(Path::new(path))?;
    scene.image.width = 480;
    scene.image.height = 270;
    let built = build_scene(&scene).with_context(|| format!("building {path}"))?;
    let tracer = Tracer::new(
        &built.objects,
        TracerOptions::new(built.epsilon, scene.render.max_steps),
    );
    let mut points = Vec::new();
    for py in (0..270).step_by(step) {
        for px in (0..480).step_by(step) {
            let (o, d) = built.camera.ray(px, py);
            if let Some(hit) = tracer.trace(o, d, 0.0).hit {
                points.push(hit.point);
            }
        }
    }
    let obj = &built.objects[0];
    let (alpha, max_alpha) = (obj.params.alpha, obj.params.max_alpha);
    println!(
        "{} hit points, alpha {alpha}, widened by {widen} degrees",
        points.len()
    );
    match obj.set_refs()[0] {
        AnySet::Triangles(set) => run(set, &points, alpha, max_alpha, built.epsilon, widen, &betas),
        AnySet::Edges(set) => run(set, &points, alpha, max_alpha, built.epsilon, widen, &betas),
        AnySet::Points(_) => {
            bail!("{path}: a point cloud; its far terms are moment bounds already")
        }
    }
    Ok(())
}
