//! MatCap shading (SPEC 8): a colour from a camera-space normal.
//!
//! A MatCap is an image of a lit sphere seen head-on. The normal `n` (camera space: x
//! right, y up, z towards the viewer) picks the texel at
//!
//! ```text
//! u = 0.5 + 0.5 n_x,   v = 0.5 - 0.5 n_y        (image rows go down)
//! ```
//!
//! bilinearly filtered: `u, v` in [0, 1] map to continuous texel coordinates
//! `(u w - 0.5, v h - 0.5)`, clamped to the texel centres at the borders. The `normal`
//! mode shows normals as colours, `(n * 0.5 + 0.5) * 255`.
//!
//! The built-in MatCaps (`clay`, `blue`, `jade`, `gold`, `white`) are not image files:
//! each is a 256 x 256 image of a lit sphere (wrapped-Lambert key and fill lights,
//! hemispherical ambient, Blinn-Phong specular, a rim term and, for the metals, a sky /
//! ground environment band), computed once on first use. Texels outside the sphere's disc
//! repeat the rim colour, so bilinear lookups at grazing normals stay on the material.
//!
//! NaN policy: [`MatCap::shade`] normalizes its input; a zero, infinite or NaN normal
//! gives [`NEUTRAL_GREY`] and never panics.

use glam::DVec3;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Colour of a normal that cannot be normalized (zero, infinite or NaN).
pub const NEUTRAL_GREY: [u8; 3] = [128, 128, 128];

/// Side of the built-in MatCap images, in pixels.
pub const BUILTIN_SIZE: u32 = 256;

/// The built-in MatCap used when a scene names none.
pub const DEFAULT_BUILTIN: &str = "clay";

/// Errors from choosing, loading or saving a MatCap. Each names the MatCap or the file.
#[derive(Debug, thiserror::Error)]
pub enum MatCapError {
    #[error(
        "unknown MatCap '{name}': the built-ins are {}; or use \"normal\" or a path to a PNG image",
        builtin_names().join(", ")
    )]
    UnknownName { name: String },
    #[error("cannot read MatCap image {}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
    #[error("MatCap image {} is {width}x{height}; it must be at least 2x2", path.display())]
    TooSmall {
        path: PathBuf,
        width: u32,
        height: u32,
    },
    #[error("cannot write MatCap image {}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
}

/// Which MatCap an object uses, as a scene file or the command line names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MatCapSpec {
    /// A built-in MatCap by name (see [`builtin_names`]). Not checked on construction.
    Builtin(String),
    /// Normals shown as colours.
    Normal,
    /// An image file (PNG; RGB or RGBA, at least 2x2).
    File(PathBuf),
}

impl Default for MatCapSpec {
    fn default() -> Self {
        MatCapSpec::Builtin(DEFAULT_BUILTIN.to_string())
    }
}

impl MatCapSpec {
    /// Interprets a name: `normal`, a built-in name, else a path when it looks like one
    /// (it has an extension or a path separator), resolved against `base_dir` when
    /// relative. Anything else is kept as a (possibly unknown) built-in name, so that the
    /// error can list the built-ins.
    pub fn parse(text: &str, base_dir: &Path) -> MatCapSpec {
        if text == "normal" {
            return MatCapSpec::Normal;
        }
        if builtin_names().contains(&text) {
            return MatCapSpec::Builtin(text.to_string());
        }
        let looks_like_path =
            text.contains('/') || text.contains('\\') || Path::new(text).extension().is_some();
        if looks_like_path {
            MatCapSpec::File(base_dir.join(text))
        } else {
            MatCapSpec::Builtin(text.to_string())
        }
    }
}

impl std::fmt::Display for MatCapSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MatCapSpec::Builtin(name) => f.write_str(name),
            MatCapSpec::Normal => f.write_str("normal"),
            MatCapSpec::File(path) => write!(f, "{}", path.display()),
        }
    }
}

/// An RGB MatCap image, sampled bilinearly.
#[derive(Clone, Debug, PartialEq)]
pub struct MatCapImage {
    width: u32,
    height: u32,
    texels: Vec<[u8; 3]>,
}

impl MatCapImage {
    /// Wraps an RGB image; `None` when it is smaller than 2x2.
    pub fn from_rgb(image: &image::RgbImage) -> Option<MatCapImage> {
        let (width, height) = image.dimensions();
        if width < 2 || height < 2 {
            return None;
        }
        Some(MatCapImage {
            width,
            height,
            texels: image.pixels().map(|p| p.0).collect(),
        })
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Bilinear lookup at `u, v` in [0, 1] (v downwards), clamped at the borders; each
    /// channel in [0, 255].
    pub fn sample(&self, u: f64, v: f64) -> [f64; 3] {
        let (w, h) = (self.width as usize, self.height as usize);
        let x = (u * w as f64 - 0.5).clamp(0.0, (w - 1) as f64);
        let y = (v * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
        // NaN u or v clamps to NaN; `as usize` turns it into 0 and the weights below
        // would be NaN, so treat it as the first texel.
        let (x, y) = (
            if x.is_nan() { 0.0 } else { x },
            if y.is_nan() { 0.0 } else { y },
        );
        let x0 = (x.floor() as usize).min(w - 1);
        let y0 = (y.floor() as usize).min(h - 1);
        let x1 = (x0 + 1).min(w - 1);
        let y1 = (y0 + 1).min(h - 1);
        let (fx, fy) = (x - x0 as f64, y - y0 as f64);
        let t = |xi: usize, yi: usize| self.texels[yi * w + xi];
        let (a, b, c, d) = (t(x0, y0), t(x1, y0), t(x0, y1), t(x1, y1));
        std::array::from_fn(|k| {
            let top = f64::from(a[k]) * (1.0 - fx) + f64::from(b[k]) * fx;
            let bottom = f64::from(c[k]) * (1.0 - fx) + f64::from(d[k]) * fx;
            top * (1.0 - fy) + bottom * fy
        })
    }

    /// The image, e.g. to save it.
    pub fn to_rgb_image(&self) -> image::RgbImage {
        image::RgbImage::from_fn(self.width, self.height, |x, y| {
            image::Rgb(self.texels[(y * self.width + x) as usize])
        })
    }
}

/// A shading mode: an image MatCap or normals as colours. Cheap to clone (the image is
/// shared), `Send + Sync`.
#[derive(Clone, Debug, PartialEq)]
pub enum MatCap {
    Image(Arc<MatCapImage>),
    Normal,
}

impl MatCap {
    /// Builds the MatCap a spec names: a built-in (computed on first use), the normal
    /// mode, or an image file read now.
    pub fn from_spec(spec: &MatCapSpec) -> Result<MatCap, MatCapError> {
        match spec {
            MatCapSpec::Normal => Ok(MatCap::Normal),
            MatCapSpec::Builtin(name) => {
                MatCap::builtin(name).ok_or_else(|| MatCapError::UnknownName { name: name.clone() })
            }
            MatCapSpec::File(path) => MatCap::load(path),
        }
    }

    /// A built-in MatCap by name, `None` if there is no such built-in.
    pub fn builtin(name: &str) -> Option<MatCap> {
        builtin_image(name).map(MatCap::Image)
    }

    /// Reads an image file (RGB or RGBA; alpha is ignored), at least 2x2.
    pub fn load(path: &Path) -> Result<MatCap, MatCapError> {
        let img = image::open(path).map_err(|source| MatCapError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let rgb = img.to_rgb8();
        let image = MatCapImage::from_rgb(&rgb).ok_or(MatCapError::TooSmall {
            path: path.to_path_buf(),
            width: rgb.width(),
            height: rgb.height(),
        })?;
        Ok(MatCap::Image(Arc::new(image)))
    }

    /// The colour for a camera-space normal (x right, y up, z towards the viewer). The
    /// normal need not be unit length; see the module's NaN policy.
    pub fn shade(&self, n_cam: DVec3) -> [u8; 3] {
        let n = match n_cam.try_normalize() {
            Some(n) => n,
            None => return NEUTRAL_GREY,
        };
        let rgb = match self {
            MatCap::Normal => (n * 0.5 + 0.5).to_array().map(|c| c * 255.0),
            MatCap::Image(image) => image.sample(0.5 + 0.5 * n.x, 0.5 - 0.5 * n.y),
        };
        rgb.map(|c| c.round().clamp(0.0, 255.0) as u8)
    }
}

/// Names of the built-in MatCaps, in the order they are documented.
pub fn builtin_names() -> &'static [&'static str] {
    const NAMES: [&str; BUILTINS.len()] = {
        let mut names = [""; BUILTINS.len()];
        let mut i = 0;
        while i < BUILTINS.len() {
            names[i] = BUILTINS[i].0;
            i += 1;
        }
        names
    };
    &NAMES
}

/// The built-in MatCap image `name` (computed once, then shared), or `None`.
pub fn builtin_image(name: &str) -> Option<Arc<MatCapImage>> {
    static CACHE: [OnceLock<Arc<MatCapImage>>; BUILTINS.len()] =
        [const { OnceLock::new() }; BUILTINS.len()];
    let i = BUILTINS.iter().position(|(n, _)| *n == name)?;
    Some(
        CACHE[i]
            .get_or_init(|| Arc::new(BUILTINS[i].1().render(BUILTIN_SIZE)))
            .clone(),
    )
}

/// Writes built-in MatCap `name` as a PNG file (for the README and for editing).
pub fn save_builtin_png(name: &str, path: &Path) -> Result<(), MatCapError> {
    let image = builtin_image(name).ok_or_else(|| MatCapError::UnknownName {
        name: name.to_string(),
    })?;
    image
        .to_rgb_image()
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|source| MatCapError::Write {
            path: path.to_path_buf(),
            source,
        })
}

/// A built-in's name and the material it renders.
type Builtin = (&'static str, fn() -> LitSphere);

const BUILTINS: [Builtin; 5] = [
    ("clay", clay),
    ("blue", blue),
    ("jade", jade),
    ("gold", gold),
    ("white", white),
];

/// Direction towards the key light of every built-in: upper left, in front.
fn key_light() -> DVec3 {
    DVec3::new(-0.55, 0.65, 0.5).normalize()
}

/// Direction towards the (weaker) fill light: right, slightly below, in front.
fn fill_light() -> DVec3 {
    DVec3::new(0.7, -0.15, 0.7).normalize()
}

/// Parameters of the lit-sphere model; colours are linear RGB.
struct LitSphere {
    base: [f64; 3],
    /// Ambient from above (n_y = 1) and from below (n_y = -1), blended by n_y.
    sky: f64,
    ground: f64,
    key: f64,
    /// Diffuse wrap: `max(0, (n.l + wrap) / (1 + wrap))`; softens the terminator.
    wrap: f64,
    fill: f64,
    specular: [f64; 3],
    shininess: f64,
    /// A second, broad specular lobe (sheen) with its own colour and exponent.
    sheen: [f64; 3],
    sheen_shininess: f64,
    rim: [f64; 3],
    rim_power: f64,
    /// Reflected environment: bright sky above the horizon, dark below (metals).
    environment: [f64; 3],
}

impl LitSphere {
    fn radiance(&self, n: DVec3) -> [f64; 3] {
        let view = DVec3::Z;
        let (l, f) = (key_light(), fill_light());
        let wrapped = |d: f64| ((d + self.wrap) / (1.0 + self.wrap)).max(0.0);
        let ambient = self.ground + (self.sky - self.ground) * (0.5 + 0.5 * n.y);
        let diffuse = ambient + self.key * wrapped(n.dot(l)) + self.fill * n.dot(f).max(0.0);
        let h = (l + view).normalize();
        let nh = n.dot(h).max(0.0);
        let spec = nh.powf(self.shininess);
        let sheen = nh.powf(self.sheen_shininess);
        let rim = (1.0 - n.z.max(0.0)).powf(self.rim_power);
        // Mirror direction of the view ray; its height picks sky or ground.
        let r_y = 2.0 * n.z * n.y;
        let horizon = smoothstep(-0.15, 0.35, r_y);
        let env = 0.15 + 0.85 * horizon;
        std::array::from_fn(|k| {
            self.base[k] * diffuse
                + self.specular[k] * spec
                + self.sheen[k] * sheen
                + self.rim[k] * rim
                + self.environment[k] * env
        })
    }

    /// Renders the sphere filling a `size x size` image; outside the disc the normal is
    /// pushed onto the rim (n_z = 0) so the border repeats the rim colour.
    /// Rows in parallel: six `powf` per texel, about 12 ms a render on one thread.
    fn render(&self, size: u32) -> MatCapImage {
        use rayon::prelude::*;
        let texels = (0..size)
            .into_par_iter()
            .flat_map_iter(|y| {
                (0..size).map(move |x| {
                    let nx = 2.0 * (f64::from(x) + 0.5) / f64::from(size) - 1.0;
                    let ny = 1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(size);
                    let r2 = nx * nx + ny * ny;
                    let n = if r2 >= 1.0 {
                        DVec3::new(nx, ny, 0.0) / r2.sqrt()
                    } else {
                        DVec3::new(nx, ny, (1.0 - r2).sqrt())
                    };
                    self.radiance(n).map(encode_srgb)
                })
            })
            .collect();
        MatCapImage {
            width: size,
            height: size,
            texels,
        }
    }
}

fn smoothstep(a: f64, b: f64, x: f64) -> f64 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Linear radiance to an 8-bit sRGB value, with a soft shoulder above 0.8 so highlights
/// saturate smoothly instead of clipping.
fn encode_srgb(linear: f64) -> u8 {
    let x = linear.max(0.0);
    let x = if x > 0.8 {
        0.8 + 0.2 * (1.0 - (-(x - 0.8) / 0.2).exp())
    } else {
        x
    };
    let s = if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round().clamp(0.0, 255.0) as u8
}

/// Warm matte grey-terracotta: soft wrapped key light, fill, generous ambient, faint sheen.
fn clay() -> LitSphere {
    LitSphere {
        base: [0.40, 0.25, 0.17],
        sky: 0.13,
        ground: 0.04,
        key: 1.15,
        wrap: 0.2,
        fill: 0.08,
        specular: [0.0; 3],
        shininess: 1.0,
        sheen: [0.05, 0.045, 0.04],
        sheen_shininess: 6.0,
        rim: [0.05, 0.035, 0.03],
        rim_power: 2.5,
        environment: [0.0; 3],
    }
}

/// Glossy blue: saturated diffuse, a sharp white highlight, a cool rim light.
fn blue() -> LitSphere {
    LitSphere {
        base: [0.025, 0.10, 0.55],
        sky: 0.12,
        ground: 0.03,
        key: 1.0,
        wrap: 0.1,
        fill: 0.18,
        specular: [1.6, 1.6, 1.6],
        shininess: 140.0,
        sheen: [0.08, 0.1, 0.16],
        sheen_shininess: 12.0,
        rim: [0.12, 0.22, 0.45],
        rim_power: 3.0,
        environment: [0.0; 3],
    }
}

/// Jade: green, soft (strong wrap as if translucent), a glossy highlight, a light rim.
fn jade() -> LitSphere {
    LitSphere {
        base: [0.07, 0.30, 0.14],
        sky: 0.16,
        ground: 0.05,
        key: 1.0,
        wrap: 0.5,
        fill: 0.15,
        specular: [0.9, 0.95, 0.9],
        shininess: 80.0,
        sheen: [0.04, 0.07, 0.05],
        sheen_shininess: 10.0,
        rim: [0.08, 0.22, 0.12],
        rim_power: 2.0,
        environment: [0.0; 3],
    }
}

/// Polished gold: little diffuse, tinted broad and sharp specular, a sky/ground band.
fn gold() -> LitSphere {
    LitSphere {
        base: [0.22, 0.13, 0.03],
        sky: 0.12,
        ground: 0.03,
        key: 0.8,
        wrap: 0.0,
        fill: 0.15,
        specular: [1.4, 1.2, 0.8],
        shininess: 90.0,
        sheen: [0.55, 0.38, 0.10],
        sheen_shininess: 8.0,
        rim: [0.10, 0.06, 0.01],
        rim_power: 3.0,
        environment: [0.40, 0.26, 0.07],
    }
}

/// White porcelain: bright, soft, with a moderate highlight.
fn white() -> LitSphere {
    LitSphere {
        base: [0.62, 0.62, 0.60],
        sky: 0.18,
        ground: 0.06,
        key: 1.0,
        wrap: 0.25,
        fill: 0.2,
        specular: [0.45, 0.45, 0.45],
        shininess: 60.0,
        sheen: [0.03, 0.03, 0.03],
        sheen_shininess: 8.0,
        rim: [0.05, 0.05, 0.06],
        rim_power: 2.5,
        environment: [0.0; 3],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn luminance(c: [u8; 3]) -> f64 {
        0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
    }

    fn tiny() -> MatCapImage {
        // Top row: red, green; bottom row: blue, white.
        let img = image::RgbImage::from_fn(2, 2, |x, y| match (x, y) {
            (0, 0) => image::Rgb([200, 0, 0]),
            (1, 0) => image::Rgb([0, 100, 0]),
            (0, 1) => image::Rgb([0, 0, 40]),
            _ => image::Rgb([255, 255, 255]),
        });
        MatCapImage::from_rgb(&img).unwrap()
    }

    #[test]
    fn normal_mode_colours() {
        let m = MatCap::Normal;
        assert_eq!(m.shade(DVec3::Z), [128, 128, 255]);
        assert_eq!(m.shade(DVec3::new(0.0, 0.0, 7.0)), [128, 128, 255]);
        assert_eq!(m.shade(DVec3::X), [255, 128, 128]);
        assert_eq!(m.shade(-DVec3::Y), [128, 0, 128]);
    }

    #[test]
    fn degenerate_normals_are_neutral_grey() {
        let caps = [MatCap::Normal, MatCap::builtin("clay").unwrap()];
        for m in &caps {
            for n in [
                DVec3::ZERO,
                DVec3::splat(f64::NAN),
                DVec3::new(f64::INFINITY, 0.0, 1.0),
                DVec3::new(1e-320, 0.0, 0.0),
            ] {
                assert_eq!(m.shade(n), NEUTRAL_GREY, "{n:?}");
            }
        }
    }

    #[test]
    fn bilinear_lookup_on_2x2() {
        let t = tiny();
        // Centre: the mean of the four texels.
        let c = t.sample(0.5, 0.5);
        let expected = [
            (200.0 + 255.0) / 4.0,
            (100.0 + 255.0) / 4.0,
            (40.0 + 255.0) / 4.0,
        ];
        for k in 0..3 {
            assert!((c[k] - expected[k]).abs() < 1e-12, "{c:?} vs {expected:?}");
        }
        // Texel centres are at u = 0.25 and 0.75; beyond them the border clamps.
        assert_eq!(t.sample(0.25, 0.25), [200.0, 0.0, 0.0]);
        assert_eq!(t.sample(0.0, 0.0), [200.0, 0.0, 0.0]);
        assert_eq!(t.sample(1.0, 1.0), [255.0, 255.0, 255.0]);
        // Halfway along the top row, a quarter of the way down: x = 0.5, y = 0.
        let s = t.sample(0.5, 0.25);
        assert_eq!(s, [100.0, 50.0, 0.0]);
        // Through `shade`: n = (0.5, 0, z) gives u = 0.75 (right column), v = 0.5.
        let m = MatCap::Image(Arc::new(t));
        let n = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        assert_eq!(m.shade(n), [128, 178, 128]); // (0+255)/2, (100+255)/2, (0+255)/2
        // n = (0, 0.5, z) gives v = 0.25 (top row), u = 0.5.
        let n = DVec3::new(0.0, 0.5, 0.75f64.sqrt());
        assert_eq!(m.shade(n), [100, 50, 0]);
    }

    #[test]
    fn builtins_exist_and_are_lit_towards_their_key_light() {
        let l = key_light();
        let away = DVec3::new(-l.x, -l.y, l.z);
        for name in builtin_names() {
            let m = MatCap::from_spec(&MatCapSpec::Builtin(name.to_string())).unwrap();
            let MatCap::Image(img) = &m else {
                panic!("{name} is not an image")
            };
            assert_eq!((img.width(), img.height()), (BUILTIN_SIZE, BUILTIN_SIZE));
            let (lit, dark) = (luminance(m.shade(l)), luminance(m.shade(away)));
            assert!(lit > dark + 40.0, "{name}: lit {lit} vs away {dark}");
            // The rim colour extends beyond the disc: the corner equals the nearby rim.
            let corner = img.sample(0.0, 0.0);
            let rim = m.shade(DVec3::new(-1.0, 1.0, 0.0));
            for k in 0..3 {
                assert!(
                    (corner[k] - f64::from(rim[k])).abs() <= 8.0,
                    "{name}: {corner:?} vs {rim:?}"
                );
            }
        }
        // Computed once: the same shared image.
        let (a, b) = (
            builtin_image("blue").unwrap(),
            builtin_image("blue").unwrap(),
        );
        assert!(Arc::ptr_eq(&a, &b));
    }

    #[test]
    fn builtin_colours_have_their_character() {
        let clay = MatCap::builtin("clay").unwrap().shade(DVec3::Z);
        assert!(
            clay[0] > clay[1] && clay[1] > clay[2],
            "clay is warm: {clay:?}"
        );
        let blue = MatCap::builtin("blue").unwrap();
        let body = blue.shade(DVec3::new(0.3, -0.3, 0.9));
        assert!(
            body[2] > body[0] + 60 && body[2] > body[1],
            "blue body: {body:?}"
        );
        // The highlight sits at the half vector between the key light and the viewer.
        let h = (key_light() + DVec3::Z).normalize();
        let spot = blue.shade(h);
        assert!(
            spot.iter().all(|&c| c > 200),
            "blue highlight is white: {spot:?}"
        );
    }

    #[test]
    fn unknown_name_error() {
        let e = MatCap::from_spec(&MatCapSpec::Builtin("chalk".into())).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("'chalk'") && msg.contains("clay") && msg.contains("normal"),
            "{msg}"
        );
        assert!(MatCap::builtin("normal").is_none());
    }

    #[test]
    fn parse_spec() {
        let dir = Path::new("/scenes");
        assert_eq!(MatCapSpec::parse("normal", dir), MatCapSpec::Normal);
        assert_eq!(
            MatCapSpec::parse("gold", dir),
            MatCapSpec::Builtin("gold".into())
        );
        assert_eq!(
            MatCapSpec::parse("chalk", dir),
            MatCapSpec::Builtin("chalk".into())
        );
        assert_eq!(
            MatCapSpec::parse("caps/red.png", dir),
            MatCapSpec::File(PathBuf::from("/scenes/caps/red.png"))
        );
        assert_eq!(
            MatCapSpec::parse("/abs/red.png", dir),
            MatCapSpec::File(PathBuf::from("/abs/red.png"))
        );
        assert_eq!(MatCapSpec::default(), MatCapSpec::Builtin("clay".into()));
    }

    #[test]
    fn files_load_save_and_fail_with_their_name() {
        let dir = tempfile::tempdir().unwrap();
        // Round trip through PNG.
        let path = dir.path().join("jade.png");
        save_builtin_png("jade", &path).unwrap();
        let m = MatCap::from_spec(&MatCapSpec::File(path.clone())).unwrap();
        assert_eq!(m, MatCap::builtin("jade").unwrap());

        // RGBA is accepted (alpha ignored).
        let rgba = dir.path().join("rgba.png");
        image::RgbaImage::from_pixel(3, 2, image::Rgba([10, 20, 30, 0]))
            .save(&rgba)
            .unwrap();
        assert_eq!(MatCap::load(&rgba).unwrap().shade(DVec3::Z), [10, 20, 30]);

        let small = dir.path().join("small.png");
        image::RgbImage::from_pixel(1, 5, image::Rgb([0, 0, 0]))
            .save(&small)
            .unwrap();
        let msg = MatCap::load(&small).unwrap_err().to_string();
        assert!(
            msg.contains("small.png") && msg.contains("1x5") && msg.contains("2x2"),
            "{msg}"
        );

        let missing = dir.path().join("missing.png");
        let msg = MatCap::load(&missing).unwrap_err().to_string();
        assert!(msg.contains("missing.png"), "{msg}");

        let garbage = dir.path().join("garbage.png");
        std::fs::write(&garbage, b"not a png").unwrap();
        let msg = MatCap::load(&garbage).unwrap_err().to_string();
        assert!(msg.contains("garbage.png"), "{msg}");

        let msg = save_builtin_png("chalk", &dir.path().join("x.png"))
            .unwrap_err()
            .to_string();
        assert!(msg.contains("chalk"), "{msg}");
    }

    /// Writes every built-in to $SMOOTHTRACE_MATCAP_DIR (to look at them); no-op without it.
    #[test]
    fn dump_builtins_when_asked() {
        if let Some(dir) = std::env::var_os("SMOOTHTRACE_MATCAP_DIR") {
            for name in builtin_names() {
                save_builtin_png(name, &Path::new(&dir).join(format!("{name}.png"))).unwrap();
            }
        }
    }
}
