//! A scene file's whole path to an image: build the objects, make the tracer, render,
//! all inside a thread pool of the scene's size (`[render] threads`, 0 = all cores).
//! [`render_built`] renders objects built some other way (the in-memory arrays of
//! [`crate::api`]) the same way; [`render_view`] renders built objects from any camera
//! with any film settings (turntable frames, crops, AOVs, a browser's view).

use super::build::{BuildError, BuiltScene, build_scene};
use super::image::{Rendered, render_film};
use super::options::TracerOptions;
use super::tracer::Tracer;
use crate::camera::Camera;
use crate::film::FilmOptions;
use crate::scene::Scene;

/// Builds and renders `scene` with its film settings (`[render] samples`, `aa`,
/// `filter`, `[image] background`); `options` adjusts the tracer defaults for the
/// scene's epsilon and max_steps; `progress` is called with the number of finished rows.
pub fn render_scene(
    scene: &Scene,
    options: impl Fn(TracerOptions) -> TracerOptions + Send + Sync,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(BuiltScene, Rendered), BuildError> {
    let film = scene.film_options();
    in_pool(scene.render.threads, || {
        let built = build_scene(scene)?;
        let rendered = render_view(
            &built,
            &built.camera,
            scene.render.max_steps,
            &film,
            &options,
            progress,
            &|| false,
        )
        .expect("a render that is never cancelled finishes");
        Ok((built, rendered))
    })
}

/// Runs `work` in a rayon pool of `threads` workers (0 = all cores).
pub fn in_pool<T: Send, E: From<BuildError> + Send>(
    threads: usize,
    work: impl FnOnce() -> Result<T, E> + Send,
) -> Result<T, E> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| BuildError::Threads(e.to_string()))?;
    pool.install(work)
}

/// Renders built objects with the tracer defaults for `built.epsilon` and `max_steps`
/// (adjusted by `options`), in the current rayon pool; misses get `background`.
pub fn render_built(
    built: &BuiltScene,
    max_steps: u32,
    background: [u8; 3],
    options: impl Fn(TracerOptions) -> TracerOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Rendered {
    let film = FilmOptions {
        background,
        ..FilmOptions::default()
    };
    render_view(
        built,
        &built.camera,
        max_steps,
        &film,
        options,
        progress,
        &|| false,
    )
    .expect("a render that is never cancelled finishes")
}

/// Renders built objects from `camera` with the film settings `film`, in the current
/// rayon pool; `None` when `cancelled()` turned true.
pub fn render_view(
    built: &BuiltScene,
    camera: &Camera,
    max_steps: u32,
    film: &FilmOptions,
    options: impl Fn(TracerOptions) -> TracerOptions,
    progress: &(dyn Fn(u64) + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Option<Rendered> {
    let opts = options(built.tracer_options(max_steps));
    let tracer = Tracer::new(&built.objects, opts);
    render_film(&tracer, camera, &built.shaders, film, progress, cancelled)
}
