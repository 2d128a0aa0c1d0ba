//! A scene file's whole path to an image: build the objects, make the tracer, render,
//! all inside a thread pool of the scene's size (`[render] threads`, 0 = all cores).

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
        let opts = options(TracerOptions::new(built.epsilon, scene.render.max_steps));
        let tracer = Tracer::new(&built.objects, opts);
        let rendered = render(
            &tracer,
            &built.camera,
            &built.shaders,
            scene.image.background,
            progress,
        );
        Ok((built, rendered))
    })
}
