//! `smoothtrace render`: a scene file to a PNG, with a progress bar, a one-line summary
//! (scene, size, time, rays/s, output; the counters with `--verbose`), and optional
//! statistics (JSON) and AOV outputs; anti-aliasing, transparency, crops
//! (`--crop`, assembled by `stitch`) and turntables (`--turntable`, `--frames`, `--gif`).

use super::console::note;
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use smoothtrace::api::params::{Naming, SceneOverrides};
use smoothtrace::film::aov::AovKind;
use smoothtrace::film::{AaMode, FilmOptions, Filter, Rect, crop, heatmap, turntable};
use smoothtrace::output::{IMAGE_8BIT, Kind, Output};
use smoothtrace::render::TracerOptions;
use smoothtrace::render::build::BuiltScene;
use smoothtrace::render::image::{ImageStats, Rendered};
use smoothtrace::render::pipeline;
use smoothtrace::scene::{AlphaSpec, CameraSettings, Evaluation, Scene};
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
    /// Write the hit distance along each ray as an EXR (RGB all equal; misses +inf); the
    /// same as `--aov depth=PATH`.
    #[arg(long)]
    depth: Option<PathBuf>,
    /// Samples per pixel (overrides `[render] samples`; 1 = one ray per pixel centre).
    #[arg(long, allow_negative_numbers = true)]
    samples: Option<i64>,
    /// Anti-aliasing: `uniform` (every pixel gets the samples) or `adaptive` (only pixels
    /// whose neighbours disagree).
    #[arg(long)]
    aa: Option<String>,
    /// Pixel filter: `box` or `gaussian`.
    #[arg(long)]
    filter: Option<String>,
    /// Transparent background: RGBA PNG/WebP, alpha 0 where rays miss.
    #[arg(long)]
    transparent: bool,
    /// Write an AOV: NAME=PATH with NAME one of depth (EXR), normal (PNG), id (palette
    /// PNG), position (EXR), cost (heat map PNG/JPEG/WebP). Repeatable.
    #[arg(long = "aov", value_name = "NAME=PATH")]
    aovs: Vec<String>,
    /// Render only the pixels X0..X1, Y0..Y1 (ends exclusive) of the full image, as a
    /// PNG that `smoothtrace stitch` assembles.
    #[arg(long, value_name = "X0,Y0,X1,Y1")]
    crop: Option<String>,
    /// Render N frames orbiting the scene's up axis into the folder given by -o
    /// (frame_0000.png, ...).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    turntable: Option<i64>,
    /// With --turntable: only frames A..B (end exclusive), e.g. for a job array.
    #[arg(long, value_name = "A:B")]
    frames: Option<String>,
    /// With --turntable: also write the frames as a looping animated GIF.
    #[arg(long)]
    gif: Option<PathBuf>,
    /// Frames per second of the GIF.
    #[arg(long, default_value_t = 25, allow_negative_numbers = true)]
    fps: i64,
    /// Opening parameter of the cheap steps taken far from the surface (0 = off: every
    /// step at the scene's beta).
    #[arg(long, default_value_t = 4.0)]
    coarse_beta: f64,
    /// Edges and triangles: decide hits only where the value is certified within one
    /// epsilon of the exact sum, refining the far field where it is not (soft fields over
    /// dense meshes: the exact surface, at many times the cost there).
    #[arg(long)]
    certified_hits: bool,
    /// List what was built (meshes, primitive sets, BVHs, MatCaps) and its times, and
    /// print the render's counters (evaluations, bound steps, leaves per ray) after it.
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

/// The checked outputs of one render.
struct Outputs {
    /// The image, or (turntables) the first frame's path, whose folder is checked.
    image: Output,
    stats: Option<Output>,
    aovs: Vec<(AovKind, Output)>,
    gif: Option<Output>,
}

/// The film options the flags ask for, over the scene's.
fn film_options(a: &RenderArgs, scene: &mut Scene) -> Result<FilmOptions> {
    if let Some(n) = a.samples {
        if let Some(message) = smoothtrace::film::options::samples_error("--samples", n) {
            bail!(message);
        }
        scene.render.samples = n as u32;
    }
    if let Some(name) = &a.aa {
        scene.render.aa = AaMode::from_name(name)
            .with_context(|| format!("--aa must be {} (got \"{name}\")", AaMode::NAMES))?;
    }
    if let Some(name) = &a.filter {
        scene.render.filter = Filter::from_name(name)
            .with_context(|| format!("--filter must be {} (got \"{name}\")", Filter::NAMES))?;
    }
    if a.transparent {
        scene.image.transparent = true;
    }
    let mut film = scene.film_options();
    if let Some(text) = &a.crop {
        let rect = Rect::parse(text, scene.image.width, scene.image.height)
            .map_err(|e| anyhow::anyhow!("--crop: {e}"))?;
        film.crop = Some(rect);
    }
    Ok(film)
}

/// The AOV requests: `--aov` and the `--depth` alias.
fn aov_requests(a: &RenderArgs) -> Result<Vec<(AovKind, PathBuf)>> {
    let mut out: Vec<(AovKind, PathBuf)> = a
        .aovs
        .iter()
        .map(|t| AovKind::parse_request(t).map_err(|e| anyhow::anyhow!("--aov: {e}")))
        .collect::<Result<_>>()?;
    if let Some(d) = &a.depth {
        out.push((AovKind::Depth, d.clone()));
    }
    Ok(out)
}

/// Checks the combination of flags and every output before the work.
fn check_outputs(a: &RenderArgs, film: &FilmOptions) -> Result<Outputs> {
    let turntable = a.turntable.is_some();
    if !turntable {
        for (set, flag) in [(a.frames.is_some(), "--frames"), (a.gif.is_some(), "--gif")] {
            if set {
                bail!("{flag} needs --turntable N (it selects or assembles turntable frames)");
            }
        }
    }
    let aovs = aov_requests(a)?;
    if turntable && (!aovs.is_empty() || film.crop.is_some()) {
        bail!(
            "--turntable writes whole frames: --aov, --depth and --crop apply to single images \
             (split a turntable with --frames instead)"
        );
    }
    let image = if turntable {
        std::fs::create_dir_all(&a.output)
            .with_context(|| format!("{}: cannot create the frames folder", a.output.display()))?;
        Output::check(
            &a.output.join(turntable::frame_name(0)),
            &[Kind::Png],
            "a turntable frame",
        )?
    } else {
        let accepted: &[Kind] = if film.crop.is_some() {
            &[Kind::Png]
        } else if film.transparent {
            &[Kind::Png, Kind::WebP]
        } else {
            IMAGE_8BIT
        };
        let what = if film.crop.is_some() {
            "a crop (its place is stored in the PNG for `stitch`)"
        } else if film.transparent {
            "a transparent image (JPEG has no alpha)"
        } else {
            "the rendered image"
        };
        Output::check(&a.output, accepted, what)?
    };
    let stats = a
        .stats
        .as_deref()
        .map(|p| Output::check_as(p, Kind::Json))
        .transpose()?;
    let aovs = aovs
        .into_iter()
        .map(|(kind, path)| {
            let what = format!("the {} AOV", kind.name());
            Ok((kind, Output::check(&path, kind.formats(), &what)?))
        })
        .collect::<Result<_>>()?;
    let gif = a
        .gif
        .as_deref()
        .map(|p| Output::check(p, &[Kind::Gif], "the turntable animation"))
        .transpose()?;
    if !(1..=100).contains(&a.fps) {
        bail!("--fps must be in 1..=100 (got {})", a.fps);
    }
    Ok(Outputs {
        image,
        stats,
        aovs,
        gif,
    })
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
    let mut film = film_options(&a, &mut scene)?;
    let frames = match a.turntable {
        None => None,
        Some(n) => {
            let n = u32::try_from(n)
                .ok()
                .filter(|&n| (1..=100_000).contains(&n))
                .with_context(|| format!("--turntable must be in 1..=100000 frames (got {n})"))?;
            let range = match &a.frames {
                Some(t) => {
                    turntable::parse_frames(t, n).map_err(|e| anyhow::anyhow!("--frames: {e}"))?
                }
                None => 0..n,
            };
            Some((n, range))
        }
    };
    // Every output is checked before the render (issue 10, defect 5).
    let outputs = check_outputs(&a, &film)?;
    film.keep_aovs = !outputs.aovs.is_empty();
    film.hit_gap = true;
    let (coarse_beta, certified_hits) = (a.coarse_beta, a.certified_hits);
    let tracer_options = |o: TracerOptions| TracerOptions {
        coarse_beta,
        certified_hits: certified_hits || o.certified_hits,
        ..o
    };
    let label = a.scene.display().to_string();
    let (built, rendered) = pipeline::in_pool(scene.render.threads, || -> Result<_> {
        let built = smoothtrace::render::build::build_scene(&scene)?;
        let rows = scene.image.height as u64;
        let rendered = match &frames {
            None => {
                let rows = film.crop.map_or(rows, |c| c.height() as u64);
                let bar = row_progress(rows, &label);
                let r = pipeline::render_view(
                    &built,
                    &built.camera,
                    scene.render.max_steps,
                    &film,
                    tracer_options,
                    &|n| bar.set_position(n),
                    &|| false,
                );
                bar.finish_and_clear();
                vec![r.expect("never cancelled")]
            }
            Some((n, range)) => render_turntable(
                &built,
                &scene,
                &film,
                *n,
                range,
                &label,
                &tracer_options,
                &outputs.image,
                outputs.gif.is_some(),
            )?,
        };
        Ok((built, rendered))
    })?;
    if a.verbose {
        for s in &built.steps {
            note!("object[{}] {} ({:.3} s)", s.object, s.what, s.seconds);
        }
        note!(
            "epsilon {} (scene diagonal {})",
            built.epsilon,
            built.bounds.diagonal()
        );
        let c = &built.camera;
        let settings = CameraSettings {
            origin: c.origin(),
            target: c.target(),
            up: c.up(),
            fov: c.fov_y_degrees(),
        };
        let how = if scene.framing.is_some() {
            "auto-framed"
        } else {
            "as given"
        };
        note!(
            "camera ({how}; paste into the scene file to keep it):\n{}",
            smoothtrace::framing::camera_toml(&settings)
        );
    }
    if rendered.iter().any(|r| r.stats.camera_inside) {
        bail!(
            "{}: the camera at {} is inside the surface (the smooth distance there is <= 0): move it out, or raise alpha",
            a.scene.display(),
            built.camera.origin()
        );
    }
    if frames.is_none() {
        let r = &rendered[0];
        write_image(&outputs.image, r, &film, &scene)?;
        for (kind, out) in &outputs.aovs {
            write_aov(*kind, out, r, built.objects.len())?;
        }
    }
    if let Some(out) = &outputs.gif {
        let delay = (1000 / a.fps) as u32;
        let images = rendered.iter().map(|r| r.to_dynamic().to_rgba8()).collect();
        let bytes = turntable::encode_gif(images, delay).context("encoding the GIF")?;
        out.write_bytes(&bytes)?;
    }
    let stats: Vec<&ImageStats> = rendered.iter().map(|r| &r.stats).collect();
    if let Some(out) = &outputs.stats {
        write_stats_json(out, &a.scene, &stats, &built, frames.is_some())?;
    }
    let shown = match &frames {
        Some((_, range)) => a.output.join(format!(
            "frame_{:04}.png .. {}",
            range.start,
            turntable::frame_name(range.end - 1)
        )),
        None => a.output.clone(),
    };
    match stats.as_slice() {
        [st] => {
            note!("{}", summary(&a.scene, st, &shown));
            if a.verbose {
                note!("{}", counters(st));
            }
        }
        all => {
            let seconds: f64 = all.iter().map(|s| s.seconds).sum();
            let rays: u64 = all.iter().map(|s| s.rays).sum();
            note!(
                "{}: {} frames of {}x{} in {seconds:.3} s ({:.3} s per frame, {:.0} rays/s) -> {}",
                a.scene.display(),
                all.len(),
                all[0].width,
                all[0].height,
                seconds / all.len() as f64,
                rays as f64 / seconds.max(1e-12),
                shown.display()
            )
        }
    }
    let exhausted: u64 = stats.iter().map(|s| s.exhausted).sum();
    if exhausted > 0 {
        note!(
            "warning: {} rays ran out of steps (max_steps = {}) and were drawn as misses",
            exhausted,
            scene.render.max_steps
        );
    }
    if let Some(gap) = stats.iter().filter_map(|s| s.hit_gap).find(|g| g.loose()) {
        note!(
            "note: at the hits the exact smooth distance may lie up to {:.0} epsilons above the value they were decided on (median {:.1}, certified bounds at {} hits): the far field is loose where the kernel is wide against the mesh's detail, and the surface is drawn outside the exact one. --certified-hits decides hits within one epsilon of the exact sum (slower)",
            gap.max,
            gap.median,
            gap.samples
        );
    }
    let falloffs: u64 = stats.iter().map(|s| s.falloffs).sum();
    if falloffs > 0 {
        note!(
            "note: alpha falloff fired {} times (the naive sum underflowed)",
            falloffs
        );
    }
    Ok(())
}

/// Renders and writes the turntable frames `range` of `n` (one progress bar over all
/// of them), returning them for the GIF and the statistics.
#[allow(clippy::too_many_arguments)]
fn render_turntable(
    built: &BuiltScene,
    scene: &Scene,
    film: &FilmOptions,
    n: u32,
    range: &std::ops::Range<u32>,
    label: &str,
    tracer_options: &(dyn Fn(TracerOptions) -> TracerOptions + Sync),
    first: &Output,
    keep_images: bool,
) -> Result<Vec<Rendered>> {
    let rows = scene.image.height as u64;
    let bar = row_progress(rows * range.len() as u64, label);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent}%, {elapsed} (eta {eta})")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let folder = first.path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut out = Vec::new();
    for (i, k) in range.clone().enumerate() {
        bar.set_message(format!("{label} frame {k}/{n}"));
        let camera = turntable::orbit_camera(&built.camera, k, n)
            .with_context(|| format!("{label}: the camera of frame {k}"))?;
        let done = i as u64 * rows;
        let mut r = pipeline::render_view(
            built,
            &camera,
            scene.render.max_steps,
            film,
            tracer_options,
            &|n| bar.set_position(done + n),
            &|| false,
        )
        .expect("never cancelled");
        if r.stats.camera_inside {
            bar.finish_and_clear();
            return Ok(vec![r]);
        }
        let path = folder.join(turntable::frame_name(k));
        let written = Output::check(&path, &[Kind::Png], "a turntable frame")
            .and_then(|o| o.write_image(&r.to_dynamic()));
        if let Err(e) = written {
            bar.finish_and_clear();
            return Err(e.into());
        }
        if !keep_images {
            // Only the statistics are needed: a long turntable must not pile up frames.
            r.image = image::RgbImage::new(0, 0);
            r.alpha = None;
            r.depth = Vec::new();
        }
        out.push(r);
    }
    bar.finish_and_clear();
    Ok(out)
}

/// Writes the image: a crop as PNG with its place for `stitch`, else by the extension.
fn write_image(out: &Output, r: &Rendered, film: &FilmOptions, scene: &Scene) -> Result<()> {
    let img = r.to_dynamic();
    match film.crop {
        Some(rect) => {
            let channels = if r.alpha.is_some() { 4 } else { 3 };
            let bytes = crop::encode_crop_png(
                img.as_bytes(),
                channels,
                rect,
                (scene.image.width, scene.image.height),
            )
            .with_context(|| format!("{}: encoding the crop", out.path.display()))?;
            Ok(out.write_bytes(&bytes)?)
        }
        None => Ok(out.write_image(&img)?),
    }
}

/// Writes one AOV of a render made with `keep_aovs`.
fn write_aov(kind: AovKind, out: &Output, r: &Rendered, objects: usize) -> Result<()> {
    let b = r.aovs.as_ref().context("the render kept no AOV records")?;
    match kind {
        AovKind::Depth => out.write_image(&b.depth())?,
        AovKind::Normal => out.write_image(&b.normal())?,
        AovKind::Position => out.write_image(&b.position())?,
        AovKind::Id => {
            let bytes = b
                .id_png(objects)
                .map_err(|e| anyhow::anyhow!("{}: {e}", out.path.display()))?;
            out.write_bytes(&bytes)?
        }
        AovKind::Cost => {
            let img = heatmap::heat_map(&b.costs(), b.width, b.height).map_err(|e| {
                anyhow::anyhow!("{}: drawing the heat map: {e}", out.path.display())
            })?;
            out.write_image(&image::DynamicImage::ImageRgb8(img))?
        }
    }
    Ok(())
}

/// The one-line summary printed after every render: scene, size, time, rays per second
/// and where the image went. The counters are [`counters`] (`--verbose`) and `--stats`.
pub fn summary(scene: &Path, st: &ImageStats, output: &Path) -> String {
    format!(
        "{}: {}x{} in {:.3} s, {:.0} rays/s -> {}",
        scene.display(),
        st.width,
        st.height,
        st.seconds,
        st.rays_per_second(),
        output.display()
    )
}

/// The render's counters, one line (`--verbose`; `--stats` writes all of them as JSON):
/// threads, rays per pixel, full evaluations and bound steps per ray and per hit ray,
/// leaves per evaluation and per ray, and the share of rays that hit.
pub fn counters(st: &ImageStats) -> String {
    format!(
        "{} threads, {:.2} rays/pixel{}; {:.2} evaluations/ray ({:.2} per hit ray, max {}) + {:.2} bound steps ({:.2} per hit ray + {:.2} per ray on tiles), {:.1} leaves/evaluation, {:.0} leaves/ray, {:.1}% hits",
        st.threads,
        st.samples_per_pixel(),
        aa_note(st),
        st.evals_per_ray(),
        st.evals_per_hit(),
        st.max_evals_per_ray,
        st.bound_evals_per_ray(),
        st.bound_evals_per_hit(),
        st.tile_evals_per_ray(),
        st.leaves_per_eval(),
        st.leaves_per_ray(),
        100.0 * st.hits as f64 / st.rays.max(1) as f64,
    )
}

/// `, 4 samples adaptive on 1234 pixels` and the like, for the summary.
fn aa_note(st: &ImageStats) -> String {
    match (st.samples, st.aa) {
        (0 | 1, _) => String::new(),
        (n, AaMode::Uniform) => format!(", {n} samples uniform"),
        (n, AaMode::Adaptive) => format!(", {n} samples adaptive on {} pixels", st.adaptive_pixels),
    }
}

/// The statistics of one image as JSON.
fn image_json(st: &ImageStats, built: &BuiltScene) -> serde_json::Value {
    serde_json::json!({
        "image": st,
        "evals_per_ray": st.evals_per_ray(),
        "evals_per_hit_ray": st.evals_per_hit(),
        "step_evals_per_hit_ray": st.step_evals_per_hit(),
        "bound_evals_per_ray": st.bound_evals_per_ray(),
        "bound_evals_per_hit_ray": st.bound_evals_per_hit(),
        "tile_evals_per_ray": st.tile_evals_per_ray(),
        "leaves_per_eval": st.leaves_per_eval(),
        "leaves_per_ray": st.leaves_per_ray(),
        "leaves_per_hit_ray": st.leaves_per_hit(),
        "samples_per_pixel": st.samples_per_pixel(),
        "phases": phases(st, built),
        "rays_per_second": st.rays_per_second(),
    })
}

/// The statistics JSON: one image's fields at the top level, or (turntables) one entry
/// per frame under `frames`.
fn write_stats_json(
    out: &Output,
    scene: &Path,
    stats: &[&ImageStats],
    built: &BuiltScene,
    turntable: bool,
) -> Result<()> {
    let mut json = if turntable {
        serde_json::json!({
            "frames": stats.iter().map(|st| image_json(st, built)).collect::<Vec<_>>(),
        })
    } else {
        image_json(stats[0], built)
    };
    let map = json.as_object_mut().expect("an object");
    map.insert("scene".into(), scene.display().to_string().into());
    map.insert("epsilon".into(), built.epsilon.into());
    map.insert("build".into(), serde_json::to_value(&built.steps)?);
    Ok(out.write_bytes(serde_json::to_string_pretty(&json)?.as_bytes())?)
}

/// Seconds per phase: loading meshes (the build log's `mesh` steps), building the rest
/// (primitive sets, BVHs, far-field tables, colours, MatCaps), tracing (wall clock of the
/// image loop, shading included) and shading alone (CPU seconds summed over the threads).
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
