//! From a validated [`Scene`] to what the tracer needs: each object's mesh (loaded or
//! generated, then transformed), the primitive sets it names and nothing else, its
//! resolved alpha and max_alpha, and its MatCap. Every step is logged with its time so
//! `--verbose` can show what was built.

use super::object::TraceObject;
use super::options::TracerOptions;
use super::signed::SignedSurface;
use crate::camera::{Camera, CameraError};
use crate::colour::by_geometry::height_colours;
use crate::colour::{GeometryColorBy, ObjectColours, SetColours};
use crate::eval::EvalParams;
use crate::matcap::{MatCap, MatCapError};
use crate::mesh::{Aabb, Mesh, MeshError};
use crate::primitives::{AnySet, PrimitiveError};
use crate::procedural::GeneratorError;
use crate::scene::{Geometry, Scene, Surface};
use crate::winding::boundary::Boundary;
use std::time::Instant;

/// Why a scene could not be built.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    #[error("{scene}: object[{object}]: {source}")]
    Mesh {
        scene: String,
        object: usize,
        #[source]
        source: MeshError,
    },
    #[error("{scene}: object[{object}]: {source}")]
    Generator {
        scene: String,
        object: usize,
        #[source]
        source: GeneratorError,
    },
    #[error("{scene}: object[{object}]: {source}")]
    Primitives {
        scene: String,
        object: usize,
        #[source]
        source: PrimitiveError,
    },
    #[error("{scene}: object[{object}]: {message}")]
    Invalid {
        scene: String,
        object: usize,
        message: String,
    },
    #[error("{scene}: object[{object}].matcap: {source}")]
    MatCap {
        scene: String,
        object: usize,
        #[source]
        source: Box<MatCapError>,
    },
    #[error("cannot start the worker threads: {0}")]
    Threads(String),
    #[error("{scene}: camera: {source}")]
    Camera {
        scene: String,
        #[source]
        source: CameraError,
    },
}

/// One step of the build, for `--verbose`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BuildStep {
    pub object: usize,
    pub what: String,
    pub seconds: f64,
}

/// A scene ready to render.
pub struct BuiltScene {
    pub objects: Vec<TraceObject>,
    /// One shader per object.
    pub shaders: Vec<MatCap>,
    pub camera: Camera,
    /// Hit threshold in world units.
    pub epsilon: f64,
    /// Union of the objects' bounding boxes.
    pub bounds: Aabb,
    pub steps: Vec<BuildStep>,
    /// Each object's bounding-box diagonal after its transform (what `alpha_rel` is
    /// relative to).
    pub diagonals: Vec<f64>,
    /// The scene's `certified_hits` (`[render]`).
    pub certified_hits: bool,
}

impl BuiltScene {
    /// The tracer's defaults for this scene: its epsilon, `max_steps` and
    /// `certified_hits`.
    pub fn tracer_options(&self, max_steps: u32) -> TracerOptions {
        TracerOptions {
            certified_hits: self.certified_hits,
            ..TracerOptions::new(self.epsilon, max_steps)
        }
    }
}

/// Builds every object of `scene`.
pub fn build_scene(scene: &Scene) -> Result<BuiltScene, BuildError> {
    let name = scene.path.display().to_string();
    let mut steps = Vec::new();
    let mut objects = Vec::new();
    let mut shaders: Vec<MatCap> = Vec::new();
    let mut loaded_matcaps: Vec<(crate::matcap::MatCapSpec, MatCap)> = Vec::new();
    let mut diagonals = Vec::new();
    for (k, obj) in scene.objects.iter().enumerate() {
        let t = Instant::now();
        let mesh_error = |source| BuildError::Mesh {
            scene: name.clone(),
            object: k,
            source,
        };
        let mut vertex_colours = None;
        let mut mesh = match &obj.geometry {
            Geometry::Mesh(path) if crate::las::is_lidar_path(path) => {
                let cloud = crate::las::read(path, &obj.las).map_err(mesh_error)?;
                steps.extend(lidar_steps(k, &cloud, t.elapsed().as_secs_f64()));
                vertex_colours = cloud.colours;
                cloud.mesh
            }
            Geometry::Mesh(path) if obj.colour.is_some_and(|c| c.by == GeometryColorBy::Vertex) => {
                let (mesh, colours) = Mesh::load_with_vertex_colours(path).map_err(mesh_error)?;
                vertex_colours = Some(colours.ok_or_else(|| BuildError::Invalid {
                    scene: name.clone(),
                    object: k,
                    message: format!(
                        "object[{k}].color_by = \"vertex\", but {} has no vertex colours (PLY: \
                         red, green, blue vertex properties; OBJ: 'v x y z r g b')",
                        path.display()
                    ),
                })?);
                mesh
            }
            Geometry::Mesh(path) => Mesh::load(path).map_err(mesh_error)?,
            Geometry::Generator(g) => g.build().map_err(|source| BuildError::Generator {
                scene: name.clone(),
                object: k,
                source,
            })?,
        };
        if !obj.transform.is_identity() {
            obj.transform.apply_to_mesh(&mut mesh);
            // The transform may carry coordinates past the limits (crate::limits).
            mesh.validate(std::path::Path::new(&mesh.name))
                .map_err(|source| BuildError::Mesh {
                    scene: name.clone(),
                    object: k,
                    source,
                })?;
        }
        steps.push(BuildStep {
            object: k,
            what: format!(
                "mesh {}: {} vertices, {} segments, {} triangles",
                mesh.name,
                mesh.vertices.len(),
                mesh.segments.len(),
                mesh.triangles.len()
            ),
            seconds: t.elapsed().as_secs_f64(),
        });
        let diag = mesh.bounds().diagonal();
        let (alpha, max_alpha) = object_alphas(&name, k, obj, diag)?;
        diagonals.push(diag);
        let mut sets = Vec::new();
        for &kind in &obj.primitives {
            let t = Instant::now();
            let set = AnySet::build(&mesh, kind).map_err(|source| BuildError::Primitives {
                scene: name.clone(),
                object: k,
                source,
            })?;
            let times = set.times();
            steps.push(BuildStep {
                object: k,
                what: format!(
                    "{kind}: {} primitives, max_adj {}, primitives+valences {:.3} s, BVH {:.3} s ({} nodes)",
                    set.len(),
                    set.max_adj(),
                    times.primitives,
                    times.bvh,
                    set.bvh().nodes.len()
                ),
                seconds: t.elapsed().as_secs_f64(),
            });
            sets.push(set);
        }
        if let Some(c) = obj.colour.filter(|c| c.by == GeometryColorBy::Height) {
            vertex_colours = Some(height_colours(&mesh, c.colormap));
        }
        let colours = vertex_colours.map(|vc| {
            let t = Instant::now();
            let c = ObjectColours {
                sets: sets
                    .iter()
                    .map(|s| SetColours::build(s, &mesh, &vc))
                    .collect(),
                from_normal: false,
            };
            steps.push(BuildStep {
                object: k,
                what: "colours per primitive and per BVH node".to_string(),
                seconds: t.elapsed().as_secs_f64(),
            });
            c
        });
        let signed = match obj.surface {
            Surface::Smooth => None,
            Surface::Signed { offset } => {
                Some(signed_surface(&name, k, &mesh, offset, &mut steps)?)
            }
        };
        drop(mesh);
        let params = EvalParams {
            accumulation: scene.render.evaluation,
            ..EvalParams::new(alpha, max_alpha, scene.render.beta)
        };
        steps.push(BuildStep {
            object: k,
            what: format!(
                "parameters: alpha {alpha} (alpha * diagonal {:.4}), max_alpha {max_alpha}, beta {}",
                alpha * diag,
                scene.render.beta
            ),
            seconds: 0.0,
        });
        let mut object = TraceObject::new(sets, params);
        if object.sets.iter().any(|s| !matches!(s, AnySet::Points(_))) {
            steps.push(BuildStep {
                object: k,
                what: "directional far-field tables".to_string(),
                seconds: object.tables_seconds,
            });
        }
        object.signed = signed;
        object.colours = match obj.colour {
            Some(c) if c.by == GeometryColorBy::Normal => Some(ObjectColours {
                sets: Vec::new(),
                from_normal: true,
            }),
            _ => colours,
        };
        objects.push(object);
        // Each distinct MatCap is built or loaded once.
        let shader = match loaded_matcaps.iter().find(|(s, _)| *s == obj.matcap) {
            Some((_, m)) => m.clone(),
            None => {
                let t = Instant::now();
                let m = MatCap::from_spec(&obj.matcap).map_err(|source| BuildError::MatCap {
                    scene: name.clone(),
                    object: k,
                    source: Box::new(source),
                })?;
                steps.push(BuildStep {
                    object: k,
                    what: format!("matcap {}", obj.matcap),
                    seconds: t.elapsed().as_secs_f64(),
                });
                loaded_matcaps.push((obj.matcap.clone(), m.clone()));
                m
            }
        };
        shaders.push(shader);
    }
    let bounds = objects.iter().fold(Aabb::EMPTY, |b, o| b.union(o.bounds));
    // Auto-framing needs the objects' reach, known only now.
    let settings = match &scene.framing {
        Some(f) => {
            let aspect = f64::from(scene.image.width) / f64::from(scene.image.height);
            crate::framing::fit_boxes(objects.iter().map(TraceObject::reach_bounds), aspect, f)
                .unwrap_or(scene.camera)
        }
        None => scene.camera,
    };
    let camera = settings
        .build(scene.image.width, scene.image.height)
        .map_err(|source| BuildError::Camera {
            scene: name.clone(),
            source,
        })?;
    Ok(BuiltScene {
        objects,
        shaders,
        camera,
        epsilon: scene.render.epsilon.resolve(bounds.diagonal()),
        bounds,
        steps,
        diagonals,
        certified_hits: scene.render.certified_hits,
    })
}

/// The signed offset surface of object `k` (`surface = "signed"`): its mesh must be
/// closed (no boundary edges), else the winding number's crossing of 1/2 away from the
/// mesh would draw a false sheet (`render::signed`).
fn signed_surface(
    scene: &str,
    k: usize,
    mesh: &Mesh,
    offset: f64,
    steps: &mut Vec<BuildStep>,
) -> Result<SignedSurface, BuildError> {
    let t = Instant::now();
    let boundary = Boundary::of(mesh);
    if boundary.edges > 0 {
        return Err(BuildError::Invalid {
            scene: scene.to_string(),
            object: k,
            message: format!(
                "surface = \"signed\" needs a closed triangle mesh, and {} has {} boundary \
                 edges (holes or open borders); close them, or draw the smooth surface",
                mesh.name, boundary.edges
            ),
        });
    }
    let surface = SignedSurface::new(mesh, offset).map_err(|source| BuildError::Primitives {
        scene: scene.to_string(),
        object: k,
        source,
    })?;
    steps.push(BuildStep {
        object: k,
        what: format!("signed surface at offset {offset}: winding-number far fields"),
        seconds: t.elapsed().as_secs_f64(),
    });
    Ok(surface)
}

/// Object `k`'s alpha and max_alpha in 1/world units, resolved against `diag` (its
/// bounding-box diagonal after its transform) and checked against the alpha limits.
/// `scene` names the scene in messages. An interactive view that changes alpha calls it
/// again with [`BuiltScene::diagonals`] instead of rebuilding.
pub fn object_alphas(
    scene: &str,
    k: usize,
    obj: &crate::scene::Object,
    diag: f64,
) -> Result<(f64, f64), BuildError> {
    let invalid = |message: String| BuildError::Invalid {
        scene: scene.to_string(),
        object: k,
        message,
    };
    let alpha = obj.alpha.resolve(diag).ok_or_else(|| {
        invalid(format!(
            "{} needs an object with a non-zero bounding box (its diagonal is {diag}); give an absolute alpha",
            obj.alpha.key()
        ))
    })?;
    let max_alpha = obj.max_alpha_or_alpha().resolve(diag).ok_or_else(|| {
        invalid(format!(
            "max_alpha_rel needs a non-zero bounding box (diagonal {diag})"
        ))
    })?;
    for (key, v) in [("alpha", alpha), ("max_alpha", max_alpha)] {
        if let Some(problem) = crate::limits::alpha_problem(v) {
            return Err(invalid(format!(
                "{key} {problem} (resolved from {} = {} over the diagonal {diag})",
                obj.alpha.key(),
                obj.alpha.value()
            )));
        }
    }
    Ok((alpha, max_alpha))
}

/// `--verbose` lines of a lidar file: what was read, each filter's count, the origin.
fn lidar_steps(k: usize, cloud: &crate::las::LasCloud, seconds: f64) -> Vec<BuildStep> {
    let step = |what: String, seconds: f64| BuildStep {
        object: k,
        what,
        seconds,
    };
    let [lo, hi] = cloud.bounds;
    let mut out = vec![step(
        format!(
            "lidar {}: LAS {} point format {}, {} points in the header",
            cloud.mesh.name, cloud.version, cloud.point_format, cloud.header_points
        ),
        seconds,
    )];
    out.extend(
        cloud
            .counts
            .iter()
            .map(|c| step(format!("filter {}: {} points kept", c.filter, c.kept), 0.0)),
    );
    out.push(step(
        format!(
            "origin [{}, {}, {}] (scene = file - origin); kept points span [{}, {}, {}] .. [{}, {}, {}] in file coordinates",
            cloud.origin.x, cloud.origin.y, cloud.origin.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
        ),
        0.0,
    ));
    out
}
