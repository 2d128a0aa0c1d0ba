//! The sphere tracer's settings (SPEC 7): which of the tracer's devices are on and their
//! parameters. Each field's meaning is stated where it is declared; the items cited are
//! those of the `render::tracer` module docs.

/// The default [`TracerOptions::far_share`], in epsilons: a far term by share holds at
/// most `far_share alpha epsilon` of the sum, so it lowers `s` by at most `far_share
/// epsilon`. At 0.075 the soft cells of the speed matrix (`alpha * diag` 100 and 250,
/// edges and triangles, seven meshes) take 11-30% fewer leaves per ray than at the
/// fixed share of 4e-4 before, and every cell keeps its place against the accuracy goals
/// (doc/performance-log.md, rounds twenty-two and thirty-three).
pub const FAR_SHARE: f64 = 0.075;

/// Tracer settings.
#[derive(Clone, Copy, Debug)]
pub struct TracerOptions {
    /// Hit threshold in world units.
    pub epsilon: f64,
    /// Largest number of field evaluations per ray before giving up (a miss).
    pub max_steps: u32,
    /// Opening parameter of the cheapest bound steps, taken far from the surface (0 =
    /// off). Any Barnes-Hut sum coarser than the scene's is a lower bound of it (a
    /// parent's far-field term dominates everything below it), so these steps are as
    /// safe as the scene's own; the hit itself is always decided at the scene's beta.
    pub coarse_beta: f64,
    /// Coarse steps are taken while the coarse value exceeds this many epsilons.
    pub coarse_threshold: f64,
    /// The same where every object is made of points only (their full steps are made at
    /// `step_beta`, so a full step pays off earlier).
    pub coarse_threshold_points: f64,
    /// March primary-ray tiles as cones first (`cone`; needs `coarse_beta > 0`).
    pub cone: bool,
    /// Within a cone-marched tile, start each ray past the empty balls of the rays traced
    /// just before it (`render::neighbours`; needs `cone`).
    pub neighbours: bool,
    /// Over-relaxed steps, each certified by the next sample's value (see `Stepper`).
    pub relax: bool,
    /// Hits on objects with edges or triangles are decided at this share of the scene's
    /// beta (tracer module docs, item 9); 1 decides them at the scene's beta (the paper's).
    /// Soft triangle meshes and edges alone take their own shares (below), except with
    /// certified hits.
    pub hit_beta_scale: f64,
    /// The same for soft fields over triangle meshes (`TraceObject::soft_triangles`):
    /// many triangles within the kernel's width, where a coarser beta keeps the hits as
    /// close to the exact surface (doc/performance-log.md, round twenty-one; 0.7 until
    /// round twenty-nine gave triangles the directional far field). Not with certified
    /// hits, which start from `hit_beta_scale`.
    pub hit_beta_scale_soft_triangles: f64,
    /// The same for objects made of edges alone, at any `alpha`: their far terms split
    /// each edge's weight into its ends' and the bump inside it (`primitives::split`),
    /// and at 0.99 their hits stay closer to the exact surface than they did at 0.8
    /// with the directional tables alone, with fewer leaves (doc/performance-log.md,
    /// round thirty-five; 0.8 from round thirty-two). Just below 1, not 1: the hits stay
    /// decided by the tracer's devices for a hit beta finer than the scene's (`sticky`
    /// evaluations, hits from above the band: `render::tracer`, items 9 and 13). Not
    /// with certified hits, which start from `hit_beta_scale`.
    pub hit_beta_scale_edges: f64,
    /// Evaluations at the hit beta on edges and triangles also take a subtree as one
    /// far-field term when its bound is at most `far_share alpha epsilon` of the sum
    /// (`eval::FarShare`, tracer module docs item 9): each such term lowers `s` by at
    /// most `far_share` epsilons. 0 = off, the paper's.
    pub far_share: f64,
    /// Full evaluations that only take a step (not predicted to hit) are made at this
    /// opening parameter when it is coarser than the scene's (0 = the scene's beta):
    /// still a lower bound, so the step is safe, at a fraction of the terms. Any value in
    /// the hit band or below is taken again at the hit beta before it decides anything.
    pub step_beta: f64,
    /// A tile's later rays step at the hit beta once a refinement of its rays finds the
    /// step value one or more epsilons low (`render::step_beta`).
    pub learn_step_beta: bool,
    /// Steps by the free distance along the ray from the terms' slopes (`eval::reach`;
    /// objects of points only), at least the plain step.
    pub reach_steps: bool,
    /// Over-relaxed steps on point clouds may also be certified by the free distance
    /// behind the next sample (`render::stepper`; needs `reach_steps`), not only by its
    /// ball.
    pub reach_behind: bool,
    /// Clip rays to the grown scene box (misses outside it cost no evaluation). Off,
    /// rays start at the camera's smooth distance and march to the box's far side, as
    /// in the paper's renderer.
    pub clip: bool,
    pub backtrack: Backtrack,
    /// A hit at a positive value `s` is moved on by one more sphere-tracing step that
    /// needs no evaluation (`s`, or the free distance along the ray up to `2 s`): that
    /// stretch is free of the surface, so the hit stays in front of it, closer to it; a
    /// hit at a negative value is moved back to the crossing's first-order estimate
    /// (tracer module docs, item 4). Off, the hit is the sample that came within
    /// epsilon (the paper's).
    pub final_step: bool,
    /// Hits on edges and triangles are decided only where the value's certified gap
    /// (how far the exact value may lie above it) is at most `GAP_MAX` epsilons, halving
    /// the hit beta until it is (`render::tracer` item 11): the surface of the exact sum
    /// at the price of fine evaluations where the far field is loose (soft fields).
    pub certified_hits: bool,
    /// Steps near the surface of soft point clouds are aimed at the crossing of the
    /// field's tangent along the ray (`render::tracer` item 12).
    pub aim: bool,
    /// On soft edge and triangle meshes, a sample a few epsilons above the hit band whose
    /// final step (`final_step`) is predicted, from its gradient, to end in the band is
    /// the hit (`render::tracer` item 13). Off, only a sample in the band is.
    pub band_reach: bool,
}

/// How a step that overshoots into the negative band is resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backtrack {
    /// Safeguarded regula falsi on the bracket (default).
    Illinois,
    /// March back in steps of epsilon until the value is above -epsilon (the paper's).
    FixedStep,
}

impl TracerOptions {
    /// Defaults for a hit threshold `epsilon`.
    pub fn new(epsilon: f64, max_steps: u32) -> TracerOptions {
        TracerOptions {
            epsilon,
            max_steps,
            coarse_beta: 4.0,
            coarse_threshold: 4.0,
            coarse_threshold_points: 8.0,
            cone: true,
            neighbours: true,
            relax: true,
            hit_beta_scale: 0.6,
            hit_beta_scale_soft_triangles: 0.8,
            hit_beta_scale_edges: 0.99,
            far_share: FAR_SHARE,
            step_beta: 1.0,
            learn_step_beta: true,
            reach_steps: true,
            reach_behind: true,
            clip: true,
            backtrack: Backtrack::Illinois,
            final_step: true,
            certified_hits: false,
            aim: true,
            band_reach: true,
        }
    }

    /// The paper's tracer: every step at the scene's beta, no ray clipping, fixed-step
    /// backtracking. (Pair with `EvalParams::prune = false` and the naive sum for the
    /// paper's evaluator.)
    pub fn paper(epsilon: f64, max_steps: u32) -> TracerOptions {
        TracerOptions {
            coarse_beta: 0.0,
            cone: false,
            neighbours: false,
            relax: false,
            hit_beta_scale: 1.0,
            hit_beta_scale_soft_triangles: 1.0,
            hit_beta_scale_edges: 1.0,
            far_share: 0.0,
            step_beta: 0.0,
            learn_step_beta: false,
            reach_steps: false,
            reach_behind: false,
            clip: false,
            backtrack: Backtrack::FixedStep,
            final_step: false,
            aim: false,
            band_reach: false,
            ..TracerOptions::new(epsilon, max_steps)
        }
    }
}
