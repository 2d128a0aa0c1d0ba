//! Render jobs of the interactive view: the built scene is kept between requests and
//! rebuilt only when what the BVHs depend on changes (the primitive kinds of an object;
//! meshes and transforms are fixed by the served scene). Alpha, max_alpha and beta are
//! evaluation parameters (the weights are scaled at evaluation time, `WeightScale`), so
//! they are written into the built objects; a new MatCap is loaded on its own.
//!
//! Every interactive render takes a number from a generation counter; its tiles check,
//! before each starts, that no newer request has taken one since, and give up
//! otherwise ([`render_cancellable`]): dragging cancels the passes of older views. A
//! "keep" render (the full-resolution PNG download) takes no number and is never
//! cancelled. Jobs run one at a time on the built scene (a mutex), each inside
//! `catch_unwind` in the HTTP layer; a panic drops the built scene, which the next job
//! rebuilds.

use super::ServeError;
use super::view::{Aov, ViewRequest, probe_pixel};
use crate::eval;
use crate::film::aov::AovBuffers;
use crate::film::{FilmOptions, heatmap};
use crate::matcap::{MatCap, MatCapSpec};
use crate::primitives::PrimitiveKind;
use crate::render::Tracer;
use crate::render::build::{BuiltScene, build_scene, object_alphas};
use crate::render::image::{ImageStats, Rendered, render_film};
use crate::scene::Scene;
use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// A built scene and what it was built for.
struct Cached {
    kinds: Vec<Vec<PrimitiveKind>>,
    matcaps: Vec<MatCapSpec>,
    built: BuiltScene,
}

/// How many jobs started, were cancelled, finished (for the page and the tests).
#[derive(Debug, Default, Serialize)]
pub struct Counters {
    pub renders_started: AtomicU64,
    pub renders_cancelled: AtomicU64,
    pub renders_finished: AtomicU64,
    pub builds: AtomicU64,
}

/// The render state shared by all requests.
#[derive(Default)]
pub struct Jobs {
    newest: AtomicU64,
    cache: Mutex<Option<Cached>>,
    pub counters: Counters,
}

/// A finished pass.
pub struct PassImage {
    pub png: Vec<u8>,
    pub stats: ImageStats,
}

/// What a probe reports about one pixel's ray (names as in `smoothtrace query`).
#[derive(Debug, Serialize)]
pub struct Probe {
    pub hit: bool,
    /// Hit point (world units).
    pub point: Option<[f64; 3]>,
    pub t: Option<f64>,
    /// Object whose smooth distance is smallest at the hit.
    pub object: Option<usize>,
    /// Smooth distance and its gradient at the hit point (`eval::evaluate`).
    pub s: Option<f64>,
    pub gradient: Option<[f64; 3]>,
    /// Smooth-distance evaluation's leaves at the hit point (as `query` prints).
    pub query_leaves: Option<u32>,
    /// Exact distance to the nearest primitive and which one (`eval::nearest`).
    pub distance: Option<f64>,
    pub nearest_kind: Option<&'static str>,
    pub nearest_index: Option<u32>,
    pub nearest_point: Option<[f64; 3]>,
    /// The object's parameters.
    pub alpha: Option<f64>,
    pub max_alpha: Option<f64>,
    pub beta: f64,
    /// Work spent tracing this ray alone (full-accuracy and bound evaluations, leaves).
    pub evals: u32,
    pub coarse_evals: u32,
    pub leaves: u32,
}

fn lock(m: &Mutex<Option<Cached>>) -> MutexGuard<'_, Option<Cached>> {
    m.lock().unwrap_or_else(|poisoned| {
        // A job panicked while holding the scene: it may be half updated.
        let mut guard = poisoned.into_inner();
        *guard = None;
        m.clear_poison();
        guard
    })
}

impl Jobs {
    /// Builds `scene` now, so that the first view renders at once and build errors
    /// show before the server starts.
    pub fn warm(&self, scene: &Scene) -> Result<(), ServeError> {
        let mut guard = lock(&self.cache);
        self.prepare(&mut guard, scene)?;
        Ok(())
    }

    /// The camera the Python API would frame the first built object with
    /// ([`crate::api::view::default_camera`]).
    pub fn default_camera(&self) -> Option<crate::scene::CameraSettings> {
        let guard = lock(&self.cache);
        let object = guard.as_ref()?.built.objects.first()?;
        Some(crate::api::view::default_camera(object))
    }

    /// Each object's bounding-box diagonal (what alpha_rel is relative to).
    pub fn diagonals(&self) -> Vec<f64> {
        lock(&self.cache)
            .as_ref()
            .map_or_else(Vec::new, |c| c.built.diagonals.clone())
    }

    /// Runs `f` on the served scene's built form, prepared for `scene`.
    fn with_built<T>(
        &self,
        scene: &Scene,
        cancelled: &dyn Fn() -> bool,
        f: impl FnOnce(&BuiltScene) -> Result<T, ServeError>,
    ) -> Result<T, ServeError> {
        let mut guard = lock(&self.cache);
        if cancelled() {
            self.counters
                .renders_cancelled
                .fetch_add(1, Ordering::Relaxed);
            return Err(ServeError::Cancelled);
        }
        let built = self.prepare(&mut guard, scene)?;
        f(built)
    }

    /// Makes the cached build match `scene`: rebuilds when the primitive kinds changed,
    /// else updates parameters and MatCaps in place.
    fn prepare<'g>(
        &self,
        guard: &'g mut MutexGuard<'_, Option<Cached>>,
        scene: &Scene,
    ) -> Result<&'g BuiltScene, ServeError> {
        let kinds: Vec<Vec<PrimitiveKind>> =
            scene.objects.iter().map(|o| o.primitives.clone()).collect();
        let matcaps: Vec<MatCapSpec> = scene.objects.iter().map(|o| o.matcap.clone()).collect();
        let bad = |e: crate::render::build::BuildError| ServeError::BadRequest(e.to_string());
        if guard.as_ref().is_none_or(|c| c.kinds != kinds) {
            **guard = None;
            let built = build_scene(scene).map_err(bad)?;
            self.counters.builds.fetch_add(1, Ordering::Relaxed);
            **guard = Some(Cached {
                kinds,
                matcaps,
                built,
            });
        } else if let Some(c) = guard.as_mut() {
            let name = scene.path.display().to_string();
            for (k, o) in scene.objects.iter().enumerate() {
                let (alpha, max_alpha) =
                    object_alphas(&name, k, o, c.built.diagonals[k]).map_err(bad)?;
                let p = &mut c.built.objects[k].params;
                p.alpha = alpha;
                p.max_alpha = max_alpha;
                p.beta = scene.render.beta;
                p.accumulation = scene.render.evaluation;
                c.built.objects[k].update_far_tables();
                if c.matcaps[k] != o.matcap {
                    c.built.shaders[k] = MatCap::from_spec(&o.matcap).map_err(|e| {
                        ServeError::BadRequest(format!("{name}: object[{k}].matcap: {e}"))
                    })?;
                    c.matcaps[k] = o.matcap.clone();
                }
            }
            c.built.epsilon = scene.render.epsilon.resolve(c.built.bounds.diagonal());
        }
        Ok(&guard.as_ref().expect("built above").built)
    }

    /// Renders one pass of `view` (already applied to the scene as `scene`).
    pub fn render(&self, view: &ViewRequest, scene: &Scene) -> Result<PassImage, ServeError> {
        let generation = (!view.keep).then(|| self.newest.fetch_add(1, Ordering::SeqCst) + 1);
        let cancelled = || generation.is_some_and(|g| self.newest.load(Ordering::SeqCst) != g);
        let (w, h) = view.pass_size(scene);
        let camera = scene
            .camera
            .build(w, h)
            .map_err(|e| ServeError::BadRequest(format!("camera: {e}")))?;
        self.with_built(scene, &cancelled, |built| {
            let tracer = Tracer::new(&built.objects, built.tracer_options(scene.render.max_steps));
            self.counters
                .renders_started
                .fetch_add(1, Ordering::Relaxed);
            let film = FilmOptions {
                samples: view.samples,
                aa: scene.render.aa,
                filter: scene.render.filter,
                background: scene.image.background,
                transparent: false,
                crop: None,
                keep_aovs: !matches!(view.aov, Aov::Shaded | Aov::Depth),
                hit_gap: false,
            };
            let rendered =
                render_film(&tracer, &camera, &built.shaders, &film, &|_| {}, &cancelled);
            let Some(rendered) = rendered else {
                self.counters
                    .renders_cancelled
                    .fetch_add(1, Ordering::Relaxed);
                return Err(ServeError::Cancelled);
            };
            self.counters
                .renders_finished
                .fetch_add(1, Ordering::Relaxed);
            let png = encode(
                &rendered,
                view.aov,
                scene.image.background,
                built.objects.len(),
            )?;
            Ok(PassImage {
                png,
                stats: rendered.stats,
            })
        })
    }

    /// Traces the ray through the pixel `(view.x, view.y)` of the full-resolution image
    /// and evaluates the field at its hit.
    pub fn probe(&self, view: &ViewRequest, scene: &Scene) -> Result<Probe, ServeError> {
        let (w, h) = (scene.image.width, scene.image.height);
        let x = probe_pixel(view.x, "x", w)?;
        let y = probe_pixel(view.y, "y", h)?;
        let camera = scene
            .camera
            .build(w, h)
            .map_err(|e| ServeError::BadRequest(format!("camera: {e}")))?;
        self.with_built(scene, &|| false, |built| {
            let tracer = Tracer::new(&built.objects, built.tracer_options(scene.render.max_steps));
            let (o, d) = camera.ray_through(x, y);
            let r = tracer.trace(o, d, 0.0);
            let mut probe = Probe {
                hit: r.hit.is_some(),
                point: None,
                t: None,
                object: None,
                s: None,
                gradient: None,
                query_leaves: None,
                distance: None,
                nearest_kind: None,
                nearest_index: None,
                nearest_point: None,
                alpha: None,
                max_alpha: None,
                beta: scene.render.beta,
                evals: r.stats.evals,
                coarse_evals: r.stats.coarse_evals,
                leaves: r.stats.eval.leaves(),
            };
            if let Some(hit) = r.hit {
                let object = &built.objects[hit.object];
                let sets = object.set_refs();
                let sample = eval::evaluate(&sets, hit.point, &object.params);
                let nearest = eval::nearest(&sets, hit.point);
                probe.point = Some(hit.point.to_array());
                probe.t = Some(hit.t);
                probe.object = Some(hit.object);
                probe.s = Some(sample.s);
                probe.gradient = Some(sample.grad.to_array());
                probe.query_leaves = Some(sample.stats.leaves());
                probe.distance = Some(nearest.d);
                probe.nearest_kind = sets.get(nearest.set).map(|s| s.kind().name());
                probe.nearest_index = Some(nearest.index);
                probe.nearest_point = Some(nearest.point.to_array());
                probe.alpha = Some(object.params.alpha);
                probe.max_alpha = Some(object.params.max_alpha);
            }
            Ok(probe)
        })
    }
}

/// The pass as PNG bytes: the shaded image, or one of the AOV views (depth as grey,
/// normals as colours, object ids as a palette, positions scaled to the hits' box, the
/// cost heat map with its scale).
fn encode(
    r: &Rendered,
    aov: Aov,
    background: [u8; 3],
    objects: usize,
) -> Result<Vec<u8>, ServeError> {
    let internal = |e: String| ServeError::Internal(e);
    let aovs = || {
        r.aovs
            .as_ref()
            .ok_or_else(|| internal("the render kept no AOV records".into()))
    };
    let image = match aov {
        Aov::Shaded => r.to_dynamic(),
        Aov::Depth => image::DynamicImage::ImageRgb8(depth_image(r, background)),
        Aov::Normal => aovs()?.normal(),
        Aov::Id => return aovs()?.id_png(objects).map_err(ServeError::BadRequest),
        Aov::Position => image::DynamicImage::ImageRgba8(position_image(aovs()?)),
        Aov::Cost => {
            let b = aovs()?;
            image::DynamicImage::ImageRgb8(
                heatmap::heat_map(&b.costs(), b.width, b.height).map_err(internal)?,
            )
        }
    };
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| ServeError::Internal(format!("cannot encode the PNG: {e}")))?;
    Ok(png)
}

/// World positions as colours: each coordinate scaled over the box of the hits, alpha 0
/// for misses.
fn position_image(b: &AovBuffers) -> image::RgbaImage {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for r in b.records.iter().filter(|r| r.is_hit()) {
        for a in 0..3 {
            lo[a] = lo[a].min(r.position[a]);
            hi[a] = hi[a].max(r.position[a]);
        }
    }
    let data = b
        .records
        .iter()
        .flat_map(|r| {
            if !r.is_hit() {
                return [0; 4];
            }
            let c = |a: usize| {
                let span = hi[a] - lo[a];
                let v = if span > 0.0 {
                    (r.position[a] - lo[a]) / span
                } else {
                    0.5
                };
                (255.0 * v).round().clamp(0.0, 255.0) as u8
            };
            [c(0), c(1), c(2), 255]
        })
        .collect();
    image::RgbaImage::from_raw(b.width, b.height, data).expect("size")
}

/// Hit distance as grey: the nearest hit white, the farthest dark grey, misses in the
/// background colour.
fn depth_image(r: &Rendered, background: [u8; 3]) -> image::RgbImage {
    let (lo, hi) = r
        .depth
        .iter()
        .filter(|d| d.is_finite())
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &d| {
            (lo.min(d), hi.max(d))
        });
    let span = (hi - lo).max(f32::MIN_POSITIVE);
    let (w, h) = r.image.dimensions();
    image::RgbImage::from_fn(w, h, |x, y| {
        let d = r.depth[(y * w + x) as usize];
        if d.is_finite() {
            let g = (255.0 - 200.0 * (d - lo) / span).round() as u8;
            image::Rgb([g, g, g])
        } else {
            image::Rgb(background)
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::image::ImageStats;

    #[test]
    fn a_panic_while_holding_the_build_drops_it() {
        let scene = crate::scene::Scene::from_str(
            "[camera]\norigin = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\n[[object]]\ngenerator = { kind = \"hex_torus\" }\nprimitives = \"edges\"\nalpha = 20.0\n",
            std::path::Path::new("t.toml"),
        )
        .unwrap();
        let jobs = Jobs::default();
        jobs.warm(&scene).unwrap();
        assert_eq!(jobs.diagonals().len(), 1);
        let poisoned = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let _guard = jobs.cache.lock().unwrap();
            panic!("a render panicked");
        }));
        assert!(poisoned.is_err() && jobs.cache.is_poisoned());
        // The next job finds no build (it may be half updated) and builds again.
        assert!(jobs.diagonals().is_empty());
        jobs.warm(&scene).unwrap();
        assert_eq!(jobs.counters.builds.load(Ordering::Relaxed), 2);
        // Once, not at every job after.
        assert!(!jobs.cache.is_poisoned());
        jobs.warm(&scene).unwrap();
        assert_eq!(jobs.diagonals().len(), 1);
        assert_eq!(jobs.counters.builds.load(Ordering::Relaxed), 2);
    }

    #[test]
    fn depth_view_orders_near_to_far() {
        let r = Rendered {
            image: image::RgbImage::new(3, 1),
            alpha: None,
            depth: vec![1.0, 3.0, f32::INFINITY],
            aovs: None,
            region: crate::film::crop::Rect::full(3, 1),
            stats: ImageStats::default(),
        };
        let img = depth_image(&r, [1, 2, 3]);
        assert_eq!(img.get_pixel(0, 0).0, [255; 3]);
        assert_eq!(img.get_pixel(1, 0).0, [55; 3]);
        assert_eq!(img.get_pixel(2, 0).0, [1, 2, 3]);
    }
}
