//! Golden images: small renders of procedural scenes compared with committed PNGs by
//! statistics. A pixel "differs" when a channel differs by more than 16 levels; a test
//! fails when more than 0.5% of the pixels differ or the mean absolute channel
//! difference exceeds 1.0 level. On failure the render and a diff image are written to
//! `target/golden-diff/`. `SMOOTHTRACE_BLESS=1 cargo test --release --test golden`
//! rewrites the goldens.

use smoothtrace::render::pipeline::render_scene;
use smoothtrace::scene::Scene;
use std::path::{Path, PathBuf};

const WIDTH: u32 = 128;
const HEIGHT: u32 = 96;
const CHANNEL_THRESHOLD: u8 = 16;
const MAX_DIFFERING_SHARE: f64 = 0.005;
const MAX_MEAN_DIFF: f64 = 1.0;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn render_small(scene: &str, threads: usize) -> image::RgbImage {
    render_with(scene, threads, |_| {}).to_rgb8()
}

/// A small render of `scene` after `adjust` changed its settings (samples, background):
/// RGB, or RGBA for a transparent render.
fn render_with(scene: &str, threads: usize, adjust: impl Fn(&mut Scene)) -> image::DynamicImage {
    let mut s = Scene::load(&root().join("scenes").join(scene)).unwrap();
    s.image.width = WIDTH;
    s.image.height = HEIGHT;
    s.render.threads = threads;
    adjust(&mut s);
    s.validate().unwrap();
    render_scene(&s, |o| o, &|_| {}).unwrap().1.to_dynamic()
}

struct Diff {
    differing_share: f64,
    mean: f64,
    max: u8,
    image: image::RgbImage,
}

/// Compares RGB(A) images channel by channel (alpha too: 255 for RGB images).
fn diff(a: &image::RgbImage, b: &image::RgbImage) -> Diff {
    diff_rgba(
        &image::DynamicImage::ImageRgb8(a.clone()).to_rgba8(),
        &image::DynamicImage::ImageRgb8(b.clone()).to_rgba8(),
        3,
    )
}

/// Compares the first `channels` channels (3: colour only, 4: with alpha).
fn diff_rgba(a: &image::RgbaImage, b: &image::RgbaImage, channels: usize) -> Diff {
    assert_eq!(a.dimensions(), b.dimensions());
    let mut image = image::RgbImage::new(a.width(), a.height());
    let (mut differing, mut sum, mut max) = (0usize, 0u64, 0u8);
    for (x, y, pa) in a.enumerate_pixels() {
        let pb = b.get_pixel(x, y);
        let d: Vec<u8> = (0..channels).map(|k| pa[k].abs_diff(pb[k])).collect();
        let m = d.iter().copied().max().unwrap();
        differing += (m > CHANNEL_THRESHOLD) as usize;
        sum += d.iter().map(|&v| v as u64).sum::<u64>();
        max = max.max(m);
        image.put_pixel(x, y, image::Rgb([m.saturating_mul(4), 0, 0]));
    }
    let n = (a.width() * a.height()) as f64;
    Diff {
        differing_share: differing as f64 / n,
        mean: sum as f64 / (channels as f64 * n),
        max,
        image,
    }
}

fn check(scene: &str) {
    let name = Path::new(scene)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .into_owned();
    check_image(scene, &name, render_with(scene, 2, |_| {}));
}

/// Compares `got` (a render of `scene`) with the golden `tests/golden/{name}.png`.
fn check_image(scene: &str, name: &str, got: image::DynamicImage) {
    let golden = root().join("tests/golden").join(format!("{name}.png"));
    if std::env::var_os("SMOOTHTRACE_BLESS").is_some() {
        got.save(&golden).unwrap();
        println!("blessed {}", golden.display());
        return;
    }
    let want = image::open(&golden)
        .unwrap_or_else(|e| panic!("{}: {e} (bless with SMOOTHTRACE_BLESS=1)", golden.display()));
    assert_eq!(got.color(), want.color(), "{name}: RGB against RGBA");
    let channels = if got.color().has_alpha() { 4 } else { 3 };
    let d = diff_rgba(&got.to_rgba8(), &want.to_rgba8(), channels);
    if d.differing_share > MAX_DIFFERING_SHARE || d.mean > MAX_MEAN_DIFF {
        let out = root().join("target/golden-diff");
        std::fs::create_dir_all(&out).unwrap();
        got.save(out.join(format!("{name}.png"))).unwrap();
        d.image.save(out.join(format!("{name}-diff.png"))).unwrap();
        panic!(
            "{scene}: {:.3}% of pixels differ by more than {CHANNEL_THRESHOLD} (limit {:.1}%), mean difference {:.3} (limit {MAX_MEAN_DIFF}), max {}; render and diff written to {}",
            100.0 * d.differing_share,
            100.0 * MAX_DIFFERING_SHARE,
            d.mean,
            d.max,
            out.display()
        );
    }
}

#[test]
fn golden_torus_triangles() {
    check("torus.toml");
}

#[test]
fn golden_hex_torus_edges() {
    check("hex_torus.toml");
}

#[test]
fn golden_bowl_edges() {
    check("bowl.toml");
}

#[test]
fn golden_net_edges() {
    check("net.toml");
}

#[test]
fn golden_sphere_points() {
    check("sphere_points.toml");
}

#[test]
fn golden_spiky_sphere_mixed_primitives() {
    check("spiky_sphere.toml");
}

#[test]
fn golden_showcase_several_objects_and_matcap_file() {
    check("showcase.toml");
}

#[test]
fn golden_bucky_ball() {
    check("bucky_ball.toml");
}

/// Signed offset surfaces of a closed triangle mesh (issue 32): one inside the solid,
/// one outside.
#[test]
fn golden_signed_torus_offsets() {
    check("signed_torus.toml");
}

/// Colour from the data (issue 11 item 6): per-vertex PLY colours through the smooth
/// colour field, shaded by the MatCap.
#[test]
fn golden_colour_vertex() {
    check("colour_vertex.toml");
}

// Issue 11: the film. Each golden changes one setting of a scene above.

#[test]
fn golden_uniform_4x_anti_aliasing() {
    let img = render_with("bucky_ball.toml", 2, |s| s.render.samples = 4);
    check_image("bucky_ball.toml, 4 samples", "bucky_ball_aa4", img);
}

#[test]
fn golden_adaptive_anti_aliasing() {
    let img = render_with("showcase.toml", 2, |s| {
        s.render.samples = 9;
        s.render.aa = smoothtrace::film::AaMode::Adaptive;
    });
    check_image(
        "showcase.toml, 9 samples adaptive",
        "showcase_adaptive9",
        img,
    );
}

#[test]
fn golden_transparent_background() {
    let img = render_with("spiky_sphere.toml", 2, |s| {
        s.render.samples = 4;
        s.image.transparent = true;
    });
    assert!(matches!(img, image::DynamicImage::ImageRgba8(_)));
    check_image(
        "spiky_sphere.toml, transparent",
        "spiky_sphere_transparent",
        img,
    );
}

#[test]
fn golden_auto_framed_scene() {
    check("auto_framed.toml");
}

#[test]
fn renders_do_not_depend_on_the_thread_count() {
    for scene in ["showcase.toml", "spiky_sphere.toml"] {
        let one = render_small(scene, 1);
        let two = render_small(scene, 2);
        let four = render_small(scene, 4);
        assert!(
            one == two && two == four,
            "{scene}: images differ across thread counts"
        );
    }
}

#[test]
fn the_comparison_detects_a_changed_image() {
    // The statistics must flag a real change: shift the torus by a few pixels.
    let a = render_small("torus.toml", 2);
    let mut b = a.clone();
    for (x, y, p) in b.enumerate_pixels_mut() {
        *p = *a.get_pixel((x + 3).min(WIDTH - 1), y);
    }
    let d = diff(&a, &b);
    assert!(
        d.differing_share > MAX_DIFFERING_SHARE,
        "{}",
        d.differing_share
    );
}
