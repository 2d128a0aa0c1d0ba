//! The film (issue 11): anti-aliasing, transparency, crops and stitching, auto-framing,
//! AOVs and turntables, through the library and the command line.

use smoothtrace::film::aov::AovKind;
use smoothtrace::film::{AaMode, FilmOptions, Rect};
use smoothtrace::render::TracerOptions;
use smoothtrace::render::build::{BuiltScene, build_scene};
use smoothtrace::render::image::Rendered;
use smoothtrace::render::pipeline::{in_pool, render_view};
use smoothtrace::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scene from `scenes/`, at `w x h`, built.
fn built(scene: &str, w: u32, h: u32) -> (Scene, BuiltScene) {
    let mut s = Scene::load(&root().join("scenes").join(scene)).unwrap();
    s.image.width = w;
    s.image.height = h;
    s.render.threads = 2;
    s.validate().unwrap();
    let b = in_pool(2, || build_scene(&s)).unwrap();
    (s, b)
}

fn render(s: &Scene, b: &BuiltScene, film: &FilmOptions) -> Rendered {
    render_opts(s, b, film, |o| o)
}

fn render_opts(
    s: &Scene,
    b: &BuiltScene,
    film: &FilmOptions,
    options: impl Fn(TracerOptions) -> TracerOptions + Send + Sync,
) -> Rendered {
    in_pool(2, || {
        Ok::<_, smoothtrace::render::build::BuildError>(
            render_view(
                b,
                &b.camera,
                s.render.max_steps,
                film,
                &options,
                &|_| {},
                &|| false,
            )
            .unwrap(),
        )
    })
    .unwrap()
}

fn film(samples: u32, aa: AaMode) -> FilmOptions {
    FilmOptions {
        samples,
        aa,
        ..FilmOptions::default()
    }
}

/// The pixels of `r` (RGBA, alpha 255 for opaque renders).
fn rgba(r: &Rendered) -> image::RgbaImage {
    r.to_dynamic().to_rgba8()
}

#[test]
fn crops_are_the_same_pixels_as_the_whole_render() {
    // Odd sizes and crop edges that cut tiles (16 px) in the middle.
    let (s, b) = built("showcase.toml", 101, 67);
    for (samples, aa, transparent) in [
        (1, AaMode::Uniform, false),
        (4, AaMode::Uniform, true),
        (5, AaMode::Adaptive, false),
        (4, AaMode::Adaptive, true),
    ] {
        let mut f = film(samples, aa);
        f.transparent = transparent;
        f.keep_aovs = true;
        let whole = render(&s, &b, &f);
        let whole_px = rgba(&whole);
        let crops = [
            Rect {
                x0: 0,
                y0: 0,
                x1: 37,
                y1: 67,
            },
            Rect {
                x0: 37,
                y0: 0,
                x1: 101,
                y1: 23,
            },
            Rect {
                x0: 37,
                y0: 23,
                x1: 90,
                y1: 67,
            },
            Rect {
                x0: 90,
                y0: 23,
                x1: 101,
                y1: 67,
            },
        ];
        let mut covered = 0;
        for rect in crops {
            let c = render(
                &s,
                &b,
                &FilmOptions {
                    crop: Some(rect),
                    ..f
                },
            );
            let px = rgba(&c);
            assert_eq!(px.dimensions(), (rect.width(), rect.height()));
            let aovs = c.aovs.as_ref().unwrap();
            let whole_aovs = whole.aovs.as_ref().unwrap();
            for (x, y, p) in px.enumerate_pixels() {
                let (gx, gy) = (rect.x0 + x, rect.y0 + y);
                assert_eq!(
                    p,
                    whole_px.get_pixel(gx, gy),
                    "{samples} samples {aa:?}: crop {rect} pixel ({gx}, {gy})"
                );
                // Depths bit for bit: a different tile grid would march differently.
                let i = (y * rect.width() + x) as usize;
                let j = (gy * 101 + gx) as usize;
                assert_eq!(
                    c.depth[i].to_bits(),
                    whole.depth[j].to_bits(),
                    "({gx}, {gy})"
                );
                assert_eq!(aovs.records[i], whole_aovs.records[j], "({gx}, {gy})");
            }
            covered += px.len() / 4;
        }
        assert_eq!(covered, 101 * 67);
    }
}

#[test]
fn transparent_render_has_clear_corners_and_soft_silhouettes() {
    let (s, b) = built("torus.toml", 96, 64);
    let mut f = film(4, AaMode::Uniform);
    f.transparent = true;
    let r = render(&s, &b, &f);
    let img = rgba(&r);
    for (x, y) in [(0, 0), (95, 0), (0, 63), (95, 63)] {
        assert_eq!(img.get_pixel(x, y).0[3], 0, "corner ({x}, {y})");
    }
    let alphas: Vec<u8> = img.pixels().map(|p| p.0[3]).collect();
    let opaque = alphas.iter().filter(|&&a| a == 255).count();
    let partial: Vec<(u32, u32)> = img
        .enumerate_pixels()
        .filter(|(_, _, p)| p.0[3] > 0 && p.0[3] < 255)
        .map(|(x, y, _)| (x, y))
        .collect();
    assert!(opaque > 500, "{opaque} opaque pixels");
    assert!(
        partial.len() > 50,
        "{} partly covered pixels",
        partial.len()
    );
    // 4 box-filtered samples: alpha is a multiple of a quarter.
    for &(x, y) in &partial {
        let a = img.get_pixel(x, y).0[3];
        assert!([64, 128, 191].contains(&a), "alpha {a} at ({x}, {y})");
    }
    // Partial pixels lie on the silhouette: each has a clear or an opaque pixel within
    // one pixel.
    for &(x, y) in &partial {
        let near = (x.saturating_sub(1)..=(x + 1).min(95))
            .flat_map(|nx| (y.saturating_sub(1)..=(y + 1).min(63)).map(move |ny| (nx, ny)))
            .any(|(nx, ny)| [0, 255].contains(&img.get_pixel(nx, ny).0[3]));
        assert!(near, "({x}, {y}) is not on a silhouette");
    }
    // Straight alpha: a fully covered pixel has the opaque render's colour, whatever the
    // background.
    let opaque_img = rgba(&render(
        &s,
        &b,
        &FilmOptions {
            transparent: false,
            ..f
        },
    ));
    for (x, y, p) in img.enumerate_pixels() {
        if p.0[3] == 255 {
            assert_eq!(p.0, opaque_img.get_pixel(x, y).0, "({x}, {y})");
        }
    }
}

#[test]
fn adaptive_sampling_traces_far_fewer_rays_and_keeps_the_uniform_pixels() {
    let (s, b) = built("torus.toml", 160, 96);
    // Without tile cone marches every sample is traced ray by ray, as adaptive sampling
    // traces its extra samples: then the pixels can be compared exactly.
    let per_ray = |o: TracerOptions| TracerOptions { cone: false, ..o };
    let one = render_opts(&s, &b, &film(1, AaMode::Uniform), per_ray);
    let uniform = render_opts(&s, &b, &film(4, AaMode::Uniform), per_ray);
    let adaptive = render_opts(&s, &b, &film(4, AaMode::Adaptive), per_ray);
    let pixels = 160 * 96;
    assert_eq!(uniform.stats.rays, 4 * pixels);
    let flagged = adaptive.stats.adaptive_pixels;
    assert!(flagged > 100, "{flagged} flagged pixels");
    // A centre ray per pixel, then 4 per flagged pixel.
    assert_eq!(adaptive.stats.rays, pixels + 4 * flagged);
    assert!(
        adaptive.stats.rays * 2 < uniform.stats.rays,
        "adaptive {} rays, uniform {}",
        adaptive.stats.rays,
        uniform.stats.rays
    );
    // Every pixel is exactly the one-sample pixel or the uniform 4-sample one, and
    // `flagged` of them (those where the two differ, at least) are the uniform one.
    let (o, u, a) = (&one.image, &uniform.image, &adaptive.image);
    let mut as_uniform = 0;
    for (x, y, p) in a.enumerate_pixels() {
        let (po, pu) = (o.get_pixel(x, y), u.get_pixel(x, y));
        assert!(p == po || p == pu, "({x}, {y}): {p:?} vs {po:?} / {pu:?}");
        as_uniform += (p == pu && p != po) as u64;
    }
    assert!(
        as_uniform > 50 && as_uniform <= flagged,
        "{as_uniform} of {flagged}"
    );
    // A pixel whose centre ray hits while a 4-neighbour's misses (or the other way) is
    // anti-aliased.
    let hit = |x: u32, y: u32| one.depth[(y * 160 + x) as usize].is_finite();
    for (x, y, pu) in u.enumerate_pixels() {
        let edge = [(-1i32, 0i32), (1, 0), (0, -1), (0, 1)]
            .iter()
            .any(|&(dx, dy)| {
                let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                (0..160).contains(&nx)
                    && (0..96).contains(&ny)
                    && hit(nx as u32, ny as u32) != hit(x, y)
            });
        if edge {
            assert_eq!(a.get_pixel(x, y), pu, "({x}, {y}) not anti-aliased");
        }
    }
    // Most partly covered pixels (the silhouette; thin sub-pixel slivers can slip
    // between centre rays) get the 4-sample colour.
    let mut transparent = film(4, AaMode::Uniform);
    transparent.transparent = true;
    let cover = render_opts(&s, &b, &transparent, per_ray).alpha.unwrap();
    let partial: Vec<(u32, u32)> = cover
        .enumerate_pixels()
        .filter(|(_, _, p)| p.0[0] > 0 && p.0[0] < 255)
        .map(|(x, y, _)| (x, y))
        .collect();
    let smoothed = partial
        .iter()
        .filter(|&&(x, y)| a.get_pixel(x, y) == u.get_pixel(x, y))
        .count();
    assert!(
        smoothed as f64 >= 0.9 * partial.len() as f64,
        "{smoothed} of {} silhouette pixels anti-aliased",
        partial.len()
    );
    // With cone marching (the default) the counts are the same.
    let adaptive_cone = render(&s, &b, &film(4, AaMode::Adaptive));
    assert_eq!(
        adaptive_cone.stats.rays,
        pixels + 4 * adaptive_cone.stats.adaptive_pixels
    );
    assert!(adaptive_cone.stats.rays * 2 < uniform.stats.rays);
}

#[test]
fn one_sample_is_todays_image() {
    // The default film is one ray per pixel centre: the goldens stay (tests/golden.rs);
    // here the one-sample film equals the 1-sample render through `render_built`.
    let (s, b) = built("spiky_sphere.toml", 64, 48);
    let r = render(&s, &b, &film(1, AaMode::Adaptive));
    let old = in_pool(2, || {
        Ok::<_, smoothtrace::render::build::BuildError>(
            smoothtrace::render::pipeline::render_built(
                &b,
                s.render.max_steps,
                s.image.background,
                |o| o,
                &|_| {},
            ),
        )
    })
    .unwrap();
    assert_eq!(r.image, old.image);
    assert_eq!(r.stats.rays, 64 * 48);
}

#[test]
fn auto_framing_shows_the_whole_scene_and_its_camera_pastes_back() {
    let (s, b) = built("auto_framed.toml", 120, 80);
    assert!(s.framing.is_some());
    let r = render(&s, &b, &s.film_options());
    let img = rgba(&r);
    // Nothing touches the border, and the objects are not lost in the frame.
    let bg = s.image.background;
    let hit = |x: u32, y: u32| img.get_pixel(x, y).0[..3] != bg;
    for x in 0..120 {
        assert!(!hit(x, 0) && !hit(x, 79), "column {x} touches the border");
    }
    for y in 0..80 {
        assert!(!hit(0, y) && !hit(119, y), "row {y} touches the border");
    }
    let rows: Vec<u32> = (0..80).filter(|&y| (0..120).any(|x| hit(x, y))).collect();
    let span = rows.last().unwrap() - rows.first().unwrap();
    assert!(span > 30, "the scene spans {span} of 80 rows");
    // The camera centre looks at the reach box's centre.
    let (min, max) =
        smoothtrace::framing::reach_box(b.objects.iter().map(|o| o.reach_bounds())).unwrap();
    assert!((b.camera.target() - 0.5 * (min + max)).length() < 1e-9);
}

// ---- the command line ----

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_smoothtrace"))
}

fn run(dir: &Path, args: &[&str]) -> Output {
    bin().current_dir(dir).args(args).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: &Output) {
    assert!(o.status.success(), "{}", stderr(o));
}

fn scene(name: &str) -> String {
    root().join("scenes").join(name).display().to_string()
}

#[test]
fn cli_crops_stitch_into_the_whole_render() {
    let dir = tempfile::tempdir().unwrap();
    let torus = scene("torus.toml");
    let common = [
        "--width",
        "75",
        "--height",
        "50",
        "--samples",
        "4",
        "--aa",
        "adaptive",
    ];
    let render = |out: &str, extra: &[&str]| {
        let mut args = vec!["render", torus.as_str(), "-o", out];
        args.extend(common);
        args.extend(extra);
        ok(&run(dir.path(), &args));
    };
    render("whole.png", &[]);
    render("a.png", &["--crop", "0,0,30,50"]);
    render("b.png", &["--crop", "30,0,75,21"]);
    render("c.png", &["--crop", "30,21,75,50"]);
    ok(&run(
        dir.path(),
        &["stitch", "c.png", "a.png", "b.png", "-o", "st.png"],
    ));
    let whole = image::open(dir.path().join("whole.png")).unwrap().to_rgb8();
    let st = image::open(dir.path().join("st.png")).unwrap().to_rgb8();
    assert!(whole == st, "stitched crops differ from the whole render");
    // Missing and overlapping crops are errors naming the problem.
    let o = run(dir.path(), &["stitch", "a.png", "b.png", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("in no crop (the first at x 30, y 21)"),
        "{}",
        stderr(&o)
    );
    let o = run(
        dir.path(),
        &["stitch", "a.png", "a.png", "b.png", "c.png", "-o", "x.png"],
    );
    assert!(stderr(&o).contains("overlaps"), "{}", stderr(&o));
    let o = run(dir.path(), &["stitch", "whole.png", "-o", "x.png"]);
    assert!(
        stderr(&o).contains("whole.png") && stderr(&o).contains("not a crop"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("x.png").exists());
}

#[test]
fn cli_turntable_frames_and_gif() {
    let dir = tempfile::tempdir().unwrap();
    let torus = scene("torus.toml");
    let size = ["--width", "48", "--height", "32"];
    let mut args = vec!["render", torus.as_str(), "-o", "frames", "--turntable", "6"];
    args.extend(size);
    args.extend(["--gif", "spin.gif", "--stats", "s.json"]);
    ok(&run(dir.path(), &args));
    let names: Vec<String> = (0..6).map(|k| format!("frame_{k:04}.png")).collect();
    for n in &names {
        assert!(dir.path().join("frames").join(n).exists(), "{n}");
    }
    // Frame 0 is the scene's own view; the others differ (the camera moved).
    let mut single = vec!["render", torus.as_str(), "-o", "one.png"];
    single.extend(size);
    ok(&run(dir.path(), &single));
    let one = image::open(dir.path().join("one.png")).unwrap().to_rgb8();
    let f0 = image::open(dir.path().join("frames/frame_0000.png"))
        .unwrap()
        .to_rgb8();
    let f1 = image::open(dir.path().join("frames/frame_0001.png"))
        .unwrap()
        .to_rgb8();
    assert!(one == f0);
    assert!(f0 != f1);
    // The GIF loops over all six frames.
    use image::AnimationDecoder;
    let bytes = std::fs::read(dir.path().join("spin.gif")).unwrap();
    assert!(bytes.windows(11).any(|w| w == b"NETSCAPE2.0"));
    let gif = image::codecs::gif::GifDecoder::new(std::io::Cursor::new(bytes)).unwrap();
    assert_eq!(gif.into_frames().count(), 6);
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap();
    assert_eq!(stats["frames"].as_array().unwrap().len(), 6);
    // A slice renders only its frames, identical to the same frames of the whole.
    let mut args = vec!["render", torus.as_str(), "-o", "part", "--turntable", "6"];
    args.extend(size);
    args.extend(["--frames", "4:6"]);
    ok(&run(dir.path(), &args));
    let listed: Vec<String> = std::fs::read_dir(dir.path().join("part"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(listed.len(), 2, "{listed:?}");
    for n in &names[4..] {
        let a = std::fs::read(dir.path().join("part").join(n)).unwrap();
        let b = std::fs::read(dir.path().join("frames").join(n)).unwrap();
        assert!(a == b, "{n}");
    }
}

#[test]
fn cli_aovs_agree_with_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let showcase = scene("showcase.toml");
    let o = run(
        dir.path(),
        &[
            "render",
            &showcase,
            "-o",
            "img.png",
            "--width",
            "64",
            "--height",
            "40",
            "--aov",
            "depth=d.exr",
            "--depth",
            "d2.exr",
            "--aov",
            "normal=n.png",
            "--aov",
            "id=id.png",
            "--aov",
            "position=p.exr",
            "--aov",
            "cost=cost.png",
        ],
    );
    ok(&o);
    let d = image::open(dir.path().join("d.exr")).unwrap().to_rgb32f();
    let d2 = image::open(dir.path().join("d2.exr")).unwrap().to_rgb32f();
    assert!(d == d2, "--depth is the depth AOV");
    let p = image::open(dir.path().join("p.exr")).unwrap().to_rgba32f();
    let n = image::open(dir.path().join("n.png")).unwrap().to_rgba8();
    let cost = image::open(dir.path().join("cost.png")).unwrap();
    assert_eq!(
        (cost.width(), cost.height()),
        (64 + smoothtrace::film::heatmap::PANEL, 40)
    );
    // The id PNG is a palette image: 0 for misses, object + 1 for hits.
    let mut dec = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.path().join("id.png")).unwrap(),
    ));
    dec.set_transformations(png::Transformations::IDENTITY);
    let mut reader = dec.read_info().unwrap();
    assert_eq!(reader.info().color_type, png::ColorType::Indexed);
    let mut ids = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut ids).unwrap();
    let s = Scene::load(Path::new(&showcase)).unwrap();
    let mut s64 = s.clone();
    s64.image.width = 64;
    s64.image.height = 40;
    let cam = s64.camera().unwrap();
    let mut seen = [false; 4];
    for y in 0..40 {
        for x in 0..64 {
            let i = (y * 64 + x) as usize;
            let depth = d.get_pixel(x, y).0[0];
            let hit = depth.is_finite();
            assert_eq!(hit, ids[i] != 0, "({x}, {y})");
            assert_eq!(hit, p.get_pixel(x, y).0[3] == 1.0);
            assert_eq!(hit, n.get_pixel(x, y).0[3] == 255);
            seen[ids[i] as usize] = true;
            if hit {
                // position = origin + depth * direction of the pixel's centre ray.
                let (o, dir) = cam.ray(x, y);
                let want = o + f64::from(depth) * dir;
                let got = p.get_pixel(x, y).0;
                let err = (0..3)
                    .map(|k| (f64::from(got[k]) - want[k]).abs())
                    .fold(0.0, f64::max);
                assert!(err < 1e-4 * (1.0 + f64::from(depth)), "({x}, {y}): {err}");
                // The normal faces the camera.
                let nn: Vec<f64> = (0..3)
                    .map(|k| f64::from(n.get_pixel(x, y).0[k]) / 127.5 - 1.0)
                    .collect();
                let facing = nn[0] * dir.x + nn[1] * dir.y + nn[2] * dir.z;
                assert!(
                    facing < 0.05,
                    "({x}, {y}): normal {nn:?} along the ray {facing}"
                );
            }
        }
    }
    assert_eq!(
        seen, [true; 4],
        "misses and all three objects appear in the id image"
    );
}

#[test]
fn cli_verbose_prints_a_camera_that_pastes_back() {
    let dir = tempfile::tempdir().unwrap();
    let auto = scene("auto_framed.toml");
    let size = ["--width", "64", "--height", "40", "--samples", "1"];
    let mut args = vec!["render", auto.as_str(), "-o", "a.png", "--verbose"];
    args.extend(size);
    let o = run(dir.path(), &args);
    ok(&o);
    let err = stderr(&o);
    let toml_start = err.find("[camera]").expect("camera printed");
    let camera: String = err[toml_start..]
        .lines()
        .take(5)
        .collect::<Vec<_>>()
        .join("\n");
    let text = std::fs::read_to_string(&auto).unwrap();
    let pasted = format!("{camera}\n{text}");
    std::fs::write(dir.path().join("pasted.toml"), pasted).unwrap();
    let mut args = vec!["render", "pasted.toml", "-o", "b.png"];
    args.extend(size);
    ok(&run(dir.path(), &args));
    let a = image::open(dir.path().join("a.png")).unwrap().to_rgb8();
    let b = image::open(dir.path().join("b.png")).unwrap().to_rgb8();
    assert!(a == b, "the pasted camera gives another image");
}

#[test]
fn cli_bad_film_values_name_the_flag_or_field() {
    let dir = tempfile::tempdir().unwrap();
    let torus = scene("torus.toml");
    for (extra, needle) in [
        (vec!["--samples", "0"], "--samples must be in 1..=1024"),
        (vec!["--samples", "-3"], "--samples must be in 1..=1024"),
        (
            vec!["--aa", "smart"],
            "--aa must be \"uniform\" or \"adaptive\" (got \"smart\")",
        ),
        (
            vec!["--filter", "lanczos"],
            "--filter must be \"box\" or \"gaussian\"",
        ),
        (
            vec!["--aov", "albedo=a.png"],
            "--aov: unknown AOV \"albedo\"",
        ),
        (
            vec!["--aov", "normal=n.exr"],
            "the normal AOV can be written as .png",
        ),
        (vec!["--aov", "depth"], "NAME=PATH"),
        (vec!["--crop", "0,0,10"], "--crop: expected X0,Y0,X1,Y1"),
        (
            vec!["--crop", "0,0,961,10"],
            "does not fit the 960x540 image",
        ),
        (vec!["--crop", "5,0,5,10"], "is empty"),
        (
            vec!["--turntable", "0"],
            "--turntable must be in 1..=100000",
        ),
        (vec!["--frames", "0:2"], "--frames needs --turntable N"),
        (vec!["--gif", "a.gif"], "--gif needs --turntable N"),
        (
            vec!["--turntable", "8", "--frames", "6:9"],
            "--frames: frames 6:9 are not a non-empty slice of the 8 frames",
        ),
        (vec!["--turntable", "8", "--gif", "a.png"], "a.png"),
        (
            vec!["--turntable", "8", "--aov", "depth=d.exr"],
            "--turntable writes whole frames",
        ),
    ] {
        let out = if extra.contains(&"--turntable") {
            "frames"
        } else {
            "x.png"
        };
        let mut args = vec!["render", torus.as_str(), "-o", out];
        args.extend(extra.iter().copied());
        let o = run(dir.path(), &args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(needle), "{extra:?}: {}", stderr(&o));
        assert!(
            !stderr(&o).contains("rays/s"),
            "{extra:?} rendered before failing"
        );
    }
    let o = run(
        dir.path(),
        &["render", &torus, "-o", "x.jpg", "--transparent"],
    );
    assert!(stderr(&o).contains("JPEG has no alpha"), "{}", stderr(&o));
    let o = run(
        dir.path(),
        &["render", &torus, "-o", "x.jpg", "--crop", "0,0,4,4"],
    );
    assert!(
        stderr(&o).contains("x.jpg") && stderr(&o).contains(".png"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("x.png").exists());
}

#[test]
fn scene_keys_for_the_film_are_checked_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.toml");
    let body =
        "[[object]]\ngenerator = { kind = \"torus\" }\nprimitives = \"triangles\"\nalpha = 300\n";
    let parse = |head: &str| Scene::from_str(&format!("{head}{body}"), &path);
    let s = parse("[render]\nsamples = 9\naa = \"adaptive\"\nfilter = \"gaussian\"\n[image]\nbackground = \"transparent\"\n").unwrap();
    assert_eq!(s.render.samples, 9);
    assert_eq!(s.render.aa, AaMode::Adaptive);
    assert_eq!(s.render.filter, smoothtrace::film::Filter::Gaussian);
    assert!(s.image.transparent && s.framing.is_some());
    let s = parse("[camera]\nfit = true\ndirection = [0, 0, 1]\nfov = 30\n").unwrap();
    let f = s.framing.unwrap();
    assert_eq!((f.direction.z, f.fov), (1.0, 30.0));
    for (head, needle) in [
        (
            "[render]\nsamples = 0\n",
            ":2:11: render.samples must be in 1..=1024",
        ),
        (
            "[render]\naa = \"fast\"\n",
            ":2:6: render.aa must be \"uniform\" or \"adaptive\"",
        ),
        (
            "[render]\nfilter = \"sinc\"\n",
            ":2:10: render.filter must be \"box\" or \"gaussian\"",
        ),
        ("[image]\nbackground = \"clear\"\n", "or \"transparent\""),
        (
            "[camera]\nfit = true\ndirection = [0, 0, 0]\n",
            "camera.direction must be a finite, non-zero vector",
        ),
        (
            "[camera]\ndirection = [0, 1, 0]\n",
            "camera.up [0, 1, 0] is zero or parallel to camera.direction",
        ),
    ] {
        let e = parse(head).unwrap_err().to_string();
        assert!(e.contains(needle), "{head}: {e}");
    }
}

#[test]
fn every_scene_still_renders() {
    // Small, one thread pool, the scene's own film settings; data scenes skip without
    // data/.
    for entry in std::fs::read_dir(root().join("scenes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let mut s = match Scene::load(&path) {
            Ok(s) => s,
            Err(e) if e.to_string().contains("data/") => {
                println!("skip {}: {e}", path.display());
                continue;
            }
            Err(e) => panic!("{}: {e}", path.display()),
        };
        s.image.width = 24;
        s.image.height = 16;
        s.validate().unwrap();
        let (_, r) = smoothtrace::render::pipeline::render_scene(&s, |o| o, &|_| {})
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(!r.stats.camera_inside, "{}", path.display());
        assert!(r.stats.hits > 0, "{}: nothing visible", path.display());
    }
}

#[test]
fn aov_names_round_trip() {
    for k in AovKind::ALL {
        assert_eq!(AovKind::from_name(k.name()), Some(k));
    }
}
