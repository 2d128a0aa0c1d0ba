//! A scene file's whole path to an image: build the objects, make the tracer, render,
//! all inside a thread pool of the scene's size (`[render] threads`, 0 = all cores).
//! [`render_built`] renders objects built some other way (the in-memory arrays of
//! [`crate::api`]) the same way.

use super::build::{BuildError, BuiltScene, build_scene};
use super::image::{Rendered, render};
use super::tracer::{Tracer, TracerOptions};
use crate::scene::Scene;

/// Builds and renders `scene`; `options` adjusts the tracer defaults for the scene's
/// epsilon and max_steps; `progress` is called with the number of finished rows.
pub fn render_scene(
    scene: &Scene,
    options: impl Fn(TracerOptions) -> TracerOptions + Send + Sync,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(BuiltScene, Rendered), BuildError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(scene.render.threads)
        .build()
        .map_err(|e| BuildError::Threads(e.to_string()))?;
    pool.install(|| {
        let built = build_scene(scene)?;
        let rendered = render_built(
            &built,
            scene.render.max_steps,
            scene.image.background,
            options,
            progress,
        );
        Ok((built, rendered))
    })
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
    let opts = options(TracerOptions::new(built.epsilon, max_steps));
    let tracer = Tracer::new(&built.objects, opts);
    render(&tracer, &built.camera, &built.shaders, background, progress)
}
