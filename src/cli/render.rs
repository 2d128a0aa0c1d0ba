//! `smoothtrace render`: a scene file to a PNG, with a progress bar, a one-line summary,
//! and optional statistics (JSON) and depth (EXR) outputs.

use super::console::note;
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use smoothtrace::api::params::{Naming, SceneOverrides};
use smoothtrace::output::{IMAGE_8BIT, Kind, Output};
use smoothtrace::render::TracerOptions;
use smoothtrace::render::build::BuiltScene;
use smoothtrace::render::image::{ImageStats, Rendered};
use smoothtrace::render::pipeline;
use smoothtrace::scene::{AlphaSpec, Evaluation, Scene};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file (TOML; see the README for the format).
    scene: PathBuf,
    /// Output image (.png, .jpg/.jpeg or .webp, by the extension).
    #[arg(short, long)]
    output: PathBuf,
    /// Override the image width.
    #[arg(long, allow_negative_numbers = true)]
    width: Option<i64>,
    /// Override the image height.
    #[arg(long, allow_negative_numbers = true)]
    height: Option<i64>,
    /// Override the Barnes-Hut parameter (0 = exact sum).
    #[arg(long, allow_negative_numbers = true)]
    beta: Option<f64>,
    /// Override every object's alpha (absolute, 1/length).
    #[arg(long, conflicts_with = "alpha_rel", allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Override every object's alpha relative to its bounding-box diagonal.
    #[arg(long, allow_negative_numbers = true)]
    alpha_rel: Option<f64>,
    /// Use the naive (unshifted) sum with alpha falloff, as the paper did.
    #[arg(long)]
    naive: bool,
    /// Worker threads (0 = all cores).
    #[arg(long, allow_negative_numbers = true)]
    threads: Option<i64>,
    /// Write the render statistics as JSON.
    #[arg(long)]
    stats: Option<PathBuf>,
    /// Write the hit distance along each ray as an EXR (RGB all equal; misses +inf).
    #[arg(long)]
    depth: Option<PathBuf>,
    /// Opening parameter of the cheap steps taken far from the surface (0 = off: every
    /// step at the scene's beta).
    #[arg(long, default_value_t = 4.0)]
    coarse_beta: f64,
    /// List what was built (meshes, primitive sets, BVHs, MatCaps) and its times.
    #[arg(short, long)]
    verbose: bool,
}

/// Loads the scene and applies the command-line overrides, then validates again.
pub fn load_scene(
    path: &Path,
    width: Option<i64>,
    height: Option<i64>,
    beta: Option<f64>,
    alpha: Option<AlphaSpec>,
    threads: Option<i64>,
) -> Result<Scene> {
    let mut scene = Scene::load(path)?;
    SceneOverrides {
        width,
        height,
        beta,
        alpha,
        threads,
    }
    .apply(&mut scene, Naming::Flag)?;
    scene.validate()?;
    Ok(scene)
}

/// A progress bar over image rows on standard error (hidden when it is not a terminal).
pub fn row_progress(rows: u64, label: &str) -> ProgressBar {
    let bar = ProgressBar::new(rows);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} rows, {elapsed} (eta {eta})")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(label.to_string());
    bar
}

/// Builds and renders a loaded scene with a progress bar over its rows.
pub fn render_scene(
    scene: &Scene,
    label: &str,
    coarse_beta: f64,
) -> Result<(BuiltScene, Rendered)> {
    let bar = row_progress(scene.image.height as u64, label);
    let out = pipeline::render_scene(scene, |o| TracerOptions { coarse_beta, ..o }, &|n| {
        bar.set_position(n)
    })?;
    bar.finish_and_clear();
    Ok(out)
}

pub fn run(a: RenderArgs) -> Result<()> {
    let alpha = match (a.alpha, a.alpha_rel) {
        (Some(v), _) => Some(AlphaSpec::Absolute(v)),
        (None, Some(v)) => Some(AlphaSpec::Relative(v)),
        _ => None,
    };
    let mut scene = load_scene(&a.scene, a.width, a.height, a.beta, alpha, a.threads)?;
    if a.naive {
        scene.render.evaluation = Evaluation::Naive;
    }
    if !(a.coarse_beta >= 0.0 && a.coarse_beta.is_finite()) {
        bail!("--coarse-beta must be >= 0 (got {})", a.coarse_beta);
    }
    // Every output is checked before the render (issue 10, defect 5).
    let output = Output::check(&a.output, IMAGE_8BIT, "the rendered image")?;
    let stats = a
        .stats
        .as_deref()
        .map(|p| Output::check_as(p, Kind::Json))
        .transpose()?;
    let depth = a
        .depth
        .as_deref()
        .map(|p| Output::check(p, &[Kind::Exr], "the depth image"))
        .transpose()?;
    let (built, rendered) = render_scene(&scene, &a.scene.display().to_string(), a.coarse_beta)?;
    if a.verbose {
        for s in &built.steps {
            note!("object[{}] {} ({:.3} s)", s.object, s.what, s.seconds);
        }
        note!(
            "epsilon {} (scene diagonal {})",
            built.epsilon,
            built.bounds.diagonal()
        );
    }
    let st = &rendered.stats;
    if st.camera_inside {
        bail!(
            "{}: the camera at {} is inside the surface (the smooth distance there is <= 0): move it out, or raise alpha",
            a.scene.display(),
            scene.camera.origin
        );
    }
    output.write_image(&image::DynamicImage::ImageRgb8(rendered.image.clone()))?;
    if let Some(out) = &stats {
        write_stats_json(out, &a.scene, st, &built)?;
    }
    if let Some(out) = &depth {
        write_depth_exr(out, &rendered)?;
    }
    note!("{}", summary(&a.scene, st, &a.output));
    if st.exhausted > 0 {
        note!(
            "warning: {} rays ran out of steps (max_steps = {}) and were drawn as misses",
            st.exhausted,
            scene.render.max_steps
        );
    }
    if st.falloffs > 0 {
        note!(
            "note: alpha falloff fired {} times (the naive sum underflowed)",
            st.falloffs
        );
    }
    Ok(())
}

/// The one-line summary printed after a render.
pub fn summary(scene: &Path, st: &ImageStats, output: &Path) -> String {
    format!(
        "{}: {}x{} in {:.3} s on {} threads ({:.0} rays/s), {:.2} evaluations/ray ({:.2} per hit ray, max {}) + {:.2} bound steps ({:.2} per hit ray + {:.2} per ray on tiles), {:.1} leaves/evaluation, {:.0} leaves/ray, {:.1}% hits -> {}",
        scene.display(),
        st.width,
        st.height,
        st.seconds,
        st.threads,
        st.rays_per_second(),
        st.evals_per_ray(),
        st.evals_per_hit(),
        st.max_evals_per_ray,
        st.bound_evals_per_ray(),
        st.bound_evals_per_hit(),
        st.tile_evals_per_ray(),
        st.leaves_per_eval(),
        st.leaves_per_ray(),
        100.0 * st.hits as f64 / st.rays.max(1) as f64,
        output.display()
    )
}

fn write_stats_json(out: &Output, scene: &Path, st: &ImageStats, built: &BuiltScene) -> Result<()> {
    let json = serde_json::json!({
        "scene": scene.display().to_string(),
        "image": st,
        "evals_per_ray": st.evals_per_ray(),
        "evals_per_hit_ray": st.evals_per_hit(),
        "bound_evals_per_ray": st.bound_evals_per_ray(),
        "bound_evals_per_hit_ray": st.bound_evals_per_hit(),
        "tile_evals_per_ray": st.tile_evals_per_ray(),
        "leaves_per_eval": st.leaves_per_eval(),
        "leaves_per_ray": st.leaves_per_ray(),
        "leaves_per_hit_ray": st.leaves_per_hit(),
        "phases": phases(st, built),
        "rays_per_second": st.rays_per_second(),
        "epsilon": built.epsilon,
        "build": built.steps,
    });
    Ok(out.write_bytes(serde_json::to_string_pretty(&json)?.as_bytes())?)
}

/// Seconds per phase: loading meshes (the build log's `mesh` steps), building the rest
/// (primitive sets, BVHs, colours, MatCaps), tracing (wall clock of the image loop,
/// shading included) and shading alone (CPU seconds summed over the threads).
fn phases(st: &ImageStats, built: &BuiltScene) -> serde_json::Value {
    let load: f64 = built
        .steps
        .iter()
        .filter(|s| s.what.starts_with("mesh "))
        .map(|s| s.seconds)
        .sum();
    let all: f64 = built.steps.iter().map(|s| s.seconds).sum();
    serde_json::json!({
        "load": load,
        "build": all - load,
        "trace": st.seconds,
        "shade_cpu": st.shade_cpu_seconds,
    })
}

fn write_depth_exr(out: &Output, r: &Rendered) -> Result<()> {
    let (w, h) = (r.image.width(), r.image.height());
    let data: Vec<f32> = r.depth.iter().flat_map(|&d| [d, d, d]).collect();
    let img = image::Rgb32FImage::from_raw(w, h, data).context("depth buffer size")?;
    Ok(out.write_image(&image::DynamicImage::ImageRgb32F(img))?)
}
