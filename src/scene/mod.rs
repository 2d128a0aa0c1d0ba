//! Scene files (TOML): camera, image, render settings and the objects to draw.
//!
//! The format is documented in the README (section "Scene files"). Loading happens in three steps:
//! 1. `raw`: serde structs that mirror the file, `deny_unknown_fields` everywhere, with
//!    spans on the values checked later; toml errors become `path:line:column: message`.
//! 2. `resolve`: the raw values become a [`Scene`] (paths resolved against the scene
//!    file's directory, `x` / `x_rel` pairs turned into [`AlphaSpec`] / [`Epsilon`]),
//!    remembering where each checked value came from.
//! 3. [`Scene::validate`]: every range and consistency check. It is public and can be
//!    run again after a caller (the command line) changed fields; a value that no longer
//!    equals the one read from the file is reported without a line and column.
//!
//! Mesh and MatCap files are checked to exist but not read: loading belongs to the
//! renderer. Relative parameters follow SPEC 5: `alpha_rel` is `alpha` times the
//! object's bounding-box diagonal (after its transform), `epsilon_rel` is `epsilon`
//! divided by the scene's bounding-box diagonal.

mod error;
mod json;
mod raw;
mod resolve;
mod transform;
mod validate;

pub use crate::matcap::MatCapSpec;
pub use error::{Location, SceneError};
pub use transform::Transform;

pub use crate::camera::CameraSettings;
use crate::camera::{Camera, CameraError};
use crate::film::{AaMode, FilmOptions, Filter};
pub use crate::framing::Framing;
pub use crate::las::LasOptions;
use crate::primitives::PrimitiveKind;
use crate::procedural::Generator;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Largest accepted image width and height, in pixels.
pub const MAX_IMAGE_SIZE: u32 = 16384;

/// A validated scene. Fields are public so a caller can override them; call
/// [`Scene::validate`] after doing so.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene file (named in error messages); empty for a scene built in code.
    pub path: PathBuf,
    pub camera: CameraSettings,
    /// `Some`: the camera is placed by auto-framing when the scene is built (no
    /// `[camera]`, or `fit = true`); `camera.up` and `camera.fov` still apply.
    pub framing: Option<Framing>,
    pub image: ImageSettings,
    pub render: RenderSettings,
    pub objects: Vec<Object>,
    /// Where the checked values were read from, and their values then.
    origins: Origins,
}

/// `[image]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageSettings {
    /// In `1..=MAX_IMAGE_SIZE`; default 960.
    pub width: u32,
    /// In `1..=MAX_IMAGE_SIZE`; default 540.
    pub height: u32,
    /// RGB colour of rays that miss; default white.
    pub background: [u8; 3],
    /// `background = "transparent"`: RGBA output, alpha 0 where rays miss.
    pub transparent: bool,
}

/// `[render]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Barnes-Hut opening parameter in [0, 1] (0 = exact sum); default 0.5.
    pub beta: f64,
    /// Hit threshold; default `Relative(4e-4)`.
    pub epsilon: Epsilon,
    /// Sphere-tracing steps per ray, >= 1; default 1000.
    pub max_steps: u32,
    pub evaluation: Evaluation,
    /// Worker threads; 0 = all cores (default).
    pub threads: usize,
    /// Samples per pixel, in `1..=film::options::MAX_SAMPLES`; default 1.
    pub samples: u32,
    /// `"uniform"` (default) or `"adaptive"`.
    pub aa: AaMode,
    /// `"box"` (default) or `"gaussian"`.
    pub filter: Filter,
    /// Hits certified within one epsilon of the exact sum on edges and triangles
    /// (`render::TracerOptions::certified_hits`, `render --certified-hits`); default off.
    pub certified_hits: bool,
}

/// The sphere-tracing hit threshold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Epsilon {
    /// In world units (`epsilon`).
    Absolute(f64),
    /// Times the scene's bounding-box diagonal (`epsilon_rel`).
    Relative(f64),
}

impl Epsilon {
    /// The threshold in world units for a scene whose bounding box has this diagonal.
    pub fn resolve(self, scene_diagonal: f64) -> f64 {
        match self {
            Epsilon::Absolute(e) => e,
            Epsilon::Relative(r) => r * scene_diagonal,
        }
    }

    /// The key that sets it in a scene file.
    pub fn key(self) -> &'static str {
        match self {
            Epsilon::Absolute(_) => "epsilon",
            Epsilon::Relative(_) => "epsilon_rel",
        }
    }

    /// The number as written in the file.
    pub fn value(self) -> f64 {
        match self {
            Epsilon::Absolute(v) | Epsilon::Relative(v) => v,
        }
    }
}

/// How the smooth distance sum is accumulated (SPEC 2): `"stable"` (shifted sum, never
/// underflows; default) or `"naive"` (the plain sum the paper measured, with alpha
/// falloff). The scene's `evaluation` key is the evaluator's own type.
pub use crate::eval::Accumulation as Evaluation;

/// `[[object]]`: one mesh or generated shape, its primitive sets and parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub geometry: Geometry,
    /// Primitive sets whose smooth distances are summed; non-empty, no duplicates.
    pub primitives: Vec<PrimitiveKind>,
    pub alpha: AlphaSpec,
    /// `None`: the same as `alpha`.
    pub max_alpha: Option<AlphaSpec>,
    pub transform: Transform,
    pub matcap: MatCapSpec,
    /// Lidar filters, origin and colour (`classes`, `crop`, `color_by`, ...); only for
    /// `.las` / `.laz` meshes, the default everywhere else.
    pub las: LasOptions,
    /// `color_by = "vertex" | "height" | "normal"` (any object); lidar attributes are in
    /// `las`.
    pub colour: Option<crate::colour::GeometryColouring>,
    /// Which surface of the object is drawn (`surface = "signed"`, `offset = d`).
    pub surface: Surface,
}

/// The surface an object draws: the zero set of its smooth distance (default), or an
/// offset surface `S = offset` of the signed distance `S` of a closed triangle mesh
/// (exact distance, negative inside where the winding number exceeds 1/2; issue 32).
/// Negative offsets lie inside the solid. A signed surface takes no alpha: its `alpha`
/// is a placeholder the evaluation does not read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Surface {
    #[default]
    Smooth,
    Signed {
        offset: f64,
    },
}

impl Object {
    /// `max_alpha`, or `alpha` when it was not given.
    pub fn max_alpha_or_alpha(&self) -> AlphaSpec {
        self.max_alpha.unwrap_or(self.alpha)
    }
}

/// Where an object's data comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// A mesh file, resolved against the scene file's directory.
    Mesh(PathBuf),
    Generator(Generator),
}

/// An alpha (1/length) given absolutely or relative to the object's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaSpec {
    /// In 1/world units, after the object's transform (`alpha`, `max_alpha`).
    Absolute(f64),
    /// `alpha * diagonal` of the object's bounding box after its transform
    /// (`alpha_rel`, `max_alpha_rel`).
    Relative(f64),
}

impl AlphaSpec {
    /// Alpha in 1/world units for an object whose transformed bounding box has this
    /// diagonal. `None` for a relative alpha and a diagonal that is not positive and
    /// finite (a single point has no size to be relative to).
    pub fn resolve(self, object_diagonal: f64) -> Option<f64> {
        match self {
            AlphaSpec::Absolute(a) => Some(a),
            AlphaSpec::Relative(r) => {
                (object_diagonal > 0.0 && object_diagonal.is_finite()).then(|| r / object_diagonal)
            }
        }
    }

    /// The number as written in the file.
    pub fn value(self) -> f64 {
        match self {
            AlphaSpec::Absolute(v) | AlphaSpec::Relative(v) => v,
        }
    }

    /// `"alpha"` or `"alpha_rel"` (for messages).
    pub fn key(self) -> &'static str {
        match self {
            AlphaSpec::Absolute(_) => "alpha",
            AlphaSpec::Relative(_) => "alpha_rel",
        }
    }
}

impl Default for ImageSettings {
    fn default() -> Self {
        ImageSettings {
            width: 960,
            height: 540,
            background: [255, 255, 255],
            transparent: false,
        }
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            beta: 0.5,
            epsilon: Epsilon::Relative(4e-4),
            max_steps: 1000,
            evaluation: Evaluation::Stable,
            threads: 0,
            samples: 1,
            aa: AaMode::Uniform,
            filter: Filter::Box,
            certified_hits: false,
        }
    }
}

impl Scene {
    /// Reads, parses and validates a scene file: TOML, or a published JSON scene when
    /// the name ends in `.json` (see `json`). A missing or unreadable file is an error
    /// naming it.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let read_err = |source| SceneError::Read {
            path: path.to_path_buf(),
            source,
        };
        let bytes = crate::limits::read_input_file(path).map_err(read_err)?;
        let text = String::from_utf8(bytes).map_err(|e| {
            read_err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "not UTF-8 text (invalid byte at offset {}); a scene file is TOML",
                    e.utf8_error().valid_up_to()
                ),
            ))
        })?;
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
        {
            let scene = json::parse(&text, path)?;
            scene.validate()?;
            return Ok(scene);
        }
        Scene::from_str(&text, path)
    }

    /// Parses and validates scene text; `path` is used in messages and to resolve
    /// relative paths (against its directory). Referenced files must exist.
    pub fn from_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let scene = resolve::parse(text, path)?;
        scene.validate()?;
        Ok(scene)
    }

    /// A scene built in code, with default image and render settings; validate it before use.
    pub fn new(camera: CameraSettings, objects: Vec<Object>) -> Scene {
        Scene {
            path: PathBuf::new(),
            camera,
            framing: None,
            image: ImageSettings::default(),
            render: RenderSettings::default(),
            objects,
            origins: Origins::default(),
        }
    }

    /// Checks every value (see the README (section "Scene files") for the ranges) and that the mesh
    /// and MatCap files exist. Values still equal to those read from the file are
    /// reported with their line and column.
    pub fn validate(&self) -> Result<(), SceneError> {
        validate::validate(self)
    }

    /// The film settings of the scene's `[image]` and `[render]` (whole image, no AOVs).
    pub fn film_options(&self) -> FilmOptions {
        FilmOptions {
            samples: self.render.samples,
            aa: self.render.aa,
            filter: self.render.filter,
            background: self.image.background,
            transparent: self.image.transparent,
            crop: None,
            keep_aovs: false,
            hit_gap: false,
        }
    }

    /// The camera for this scene's image size (as written: for a scene with
    /// [`Scene::framing`] the camera comes from `render::build`, which sees the objects).
    pub fn camera(&self) -> Result<Camera, CameraError> {
        self.camera.build(self.image.width, self.image.height)
    }

    /// The directory relative paths in the file are resolved against.
    pub fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new(""))
    }
}

/// For each checked field (dotted key), where it was read and its value then (`Debug`).
#[derive(Clone, Debug, Default)]
struct Origins(HashMap<String, (Location, String)>);

impl Origins {
    fn record(&mut self, key: String, location: Location, value: &dyn std::fmt::Debug) {
        self.0.insert(key, (location, format!("{value:?}")));
    }

    /// The location of `key` if its value is still `value`.
    fn find(&self, key: &str, value: &dyn std::fmt::Debug) -> Option<Location> {
        let (location, then) = self.0.get(key)?;
        (*then == format!("{value:?}")).then_some(*location)
    }
}
