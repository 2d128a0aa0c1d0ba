//! `smoothtrace serve`: a local HTTP server and one embedded page to build a scene in
//! the browser: orbit, zoom and pan with progressive refinement, per-object primitive
//! kinds, alpha, max_alpha and MatCap, beta and epsilon, a probe of any pixel, the
//! depth view, saving the view as scene TOML and a full-resolution PNG.
//!
//! Parts: [`http`] (routes), [`assets`] (the page), [`view`] (what the page sends,
//! checked with the command line's messages), [`jobs`] (the kept build, the generation
//! counter that cancels older passes, the probe), [`paths`] (names from the browser
//! stay inside the scene's folder), [`save`] (scene TOML).
//!
//! Requests are served by one thread each (at most [`MAX_IN_FLIGHT`] at once); each
//! runs inside `catch_unwind`, so a failing or panicking render answers 500 and the
//! server goes on. The server binds to loopback unless told otherwise; [`Server::stop`]
//! (Ctrl-C in the command line) ends [`Server::run`].

pub mod assets;
pub mod http;
pub mod jobs;
pub mod paths;
pub mod save;
pub mod view;

use crate::mesh::Mesh;
use crate::primitives::PrimitiveKind;
use crate::scene::{AlphaSpec, CameraSettings, Geometry, Object, Scene};
use glam::DVec3;
use std::io::Read;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Most requests handled at once; more answer 503.
pub const MAX_IN_FLIGHT: usize = 32;

/// A request's failure, with its HTTP status.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    #[error("{0}")]
    BadRequest(String),
    #[error("{0}")]
    Forbidden(String),
    #[error("{0}")]
    NotFound(String),
    #[error("{0}")]
    Method(String),
    #[error("cancelled: a newer view was requested")]
    Cancelled,
    #[error("request body larger than {0} bytes")]
    TooLarge(usize),
    #[error("busy: {0} requests are being served; try again")]
    Busy(usize),
    #[error("{0}")]
    Internal(String),
}

impl ServeError {
    pub fn status(&self) -> u16 {
        match self {
            ServeError::BadRequest(_) => 400,
            ServeError::Forbidden(_) => 403,
            ServeError::NotFound(_) => 404,
            ServeError::Method(_) => 405,
            ServeError::Cancelled => 409,
            ServeError::TooLarge(_) => 413,
            ServeError::Busy(_) => 503,
            ServeError::Internal(_) => 500,
        }
    }
}

/// What the server serves.
pub struct State {
    /// The served scene (the page's starting view).
    pub scene: Scene,
    pub folder: paths::SceneFolder,
    /// `--save`: server-side saving is on, this is the suggested file.
    pub save: Option<PathBuf>,
    pub jobs: jobs::Jobs,
}

/// Where to listen and what to serve.
pub struct ServeConfig {
    pub scene: Scene,
    pub host: String,
    pub port: u16,
    /// Server-side save target (must be inside the scene's folder).
    pub save: Option<PathBuf>,
    /// Replace the scene's camera by the default framing of its first object (a bare
    /// mesh, see [`scene_for_mesh`]).
    pub frame_camera: bool,
}

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum StartError {
    #[error("{0}")]
    Scene(String),
    #[error("--save {path}: {reason}")]
    Save { path: String, reason: String },
    #[error("cannot listen on {addr}: {reason}")]
    Listen { addr: String, reason: String },
}

/// A running server.
pub struct Server {
    http: Arc<tiny_http::Server>,
    state: Arc<State>,
    addr: SocketAddr,
}

impl Server {
    /// Builds the scene (errors show here, before anything listens), checks `--save`,
    /// and binds.
    pub fn start(config: ServeConfig) -> Result<Server, StartError> {
        let mut scene = config.scene;
        let folder = paths::SceneFolder::new(scene.base_dir()).map_err(|e| {
            StartError::Scene(format!(
                "{}: cannot open the scene's folder: {e}",
                scene.path.display()
            ))
        })?;
        let save = match config.save {
            None => None,
            Some(p) => Some(check_save(&p, &folder)?),
        };
        let jobs = jobs::Jobs::default();
        jobs.warm(&scene)
            .map_err(|e| StartError::Scene(e.to_string()))?;
        if config.frame_camera
            && let Some(c) = jobs.default_camera()
        {
            scene.camera = c;
        }
        let addr = format!("{}:{}", config.host, config.port);
        let http = tiny_http::Server::http(&addr).map_err(|e| StartError::Listen {
            addr: addr.clone(),
            reason: e.to_string(),
        })?;
        let addr = http
            .server_addr()
            .to_ip()
            .ok_or_else(|| StartError::Listen {
                addr,
                reason: "not an IP address".into(),
            })?;
        Ok(Server {
            http: Arc::new(http),
            state: Arc::new(State {
                scene,
                folder,
                save,
                jobs,
            }),
            addr,
        })
    }

    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    pub fn state(&self) -> &State {
        &self.state
    }

    /// A handle that ends [`Server::run`] (for a Ctrl-C handler).
    pub fn stopper(&self) -> impl Fn() + Send + Sync + 'static {
        let http = Arc::clone(&self.http);
        move || http.unblock()
    }

    /// Stops [`Server::run`].
    pub fn stop(&self) {
        self.http.unblock();
    }

    /// Serves until stopped.
    pub fn run(&self) {
        let in_flight = Arc::new(AtomicUsize::new(0));
        for request in self.http.incoming_requests() {
            let n = in_flight.fetch_add(1, Ordering::SeqCst);
            if n >= MAX_IN_FLIGHT {
                in_flight.fetch_sub(1, Ordering::SeqCst);
                respond(request, http::Reply::error(&ServeError::Busy(n)));
                continue;
            }
            let state = Arc::clone(&self.state);
            let counter = Arc::clone(&in_flight);
            let spawned = std::thread::Builder::new()
                .name("serve-request".into())
                .spawn(move || {
                    handle(&state, request);
                    counter.fetch_sub(1, Ordering::SeqCst);
                });
            if spawned.is_err() {
                in_flight.fetch_sub(1, Ordering::SeqCst);
            }
        }
    }
}

/// `--save PATH` must name a `.toml` file inside the scene's folder.
fn check_save(path: &Path, folder: &paths::SceneFolder) -> Result<PathBuf, StartError> {
    let fail = |reason: String| StartError::Save {
        path: path.display().to_string(),
        reason,
    };
    if !path
        .to_string_lossy()
        .to_ascii_lowercase()
        .ends_with(".toml")
    {
        return Err(fail("the saved scene must be a .toml file".into()));
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let real = parent
        .canonicalize()
        .map_err(|e| fail(format!("its folder cannot be opened: {e}")))?;
    let name = path
        .file_name()
        .ok_or_else(|| fail("no file name".into()))?;
    let rel = real
        .join(name)
        .strip_prefix(folder.root())
        .map(Path::to_path_buf)
        .map_err(|_| {
            fail(format!(
                "it must be inside the scene's folder {}",
                folder.root().display()
            ))
        })?;
    folder
        .resolve(&rel.to_string_lossy(), false)
        .map_err(|e| fail(e.to_string()))
}

/// Reads the body (bounded), routes, answers; panics become 500.
fn handle(state: &State, mut request: tiny_http::Request) {
    let method = request.method().as_str().to_string();
    let url = request.url().to_string();
    let reply = match read_body(&mut request) {
        Err(e) => http::Reply::error(&e),
        Ok(body) => guarded(|| http::route(state, &method, &url, &body)),
    };
    respond(request, reply);
}

/// Runs a request's work; an error becomes its status, a panic a 500 (the server goes
/// on).
fn guarded(work: impl FnOnce() -> Result<http::Reply, ServeError>) -> http::Reply {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(work)) {
        Ok(Ok(reply)) => reply,
        Ok(Err(e)) => http::Reply::error(&e),
        Err(panic) => {
            let message = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("unknown panic");
            http::Reply::error(&ServeError::Internal(format!(
                "the request failed (the server goes on): {message}"
            )))
        }
    }
}

fn read_body(request: &mut tiny_http::Request) -> Result<Vec<u8>, ServeError> {
    if request
        .body_length()
        .is_some_and(|n| n > http::MAX_BODY_BYTES)
    {
        return Err(ServeError::TooLarge(http::MAX_BODY_BYTES));
    }
    let mut body = Vec::new();
    request
        .as_reader()
        .take(http::MAX_BODY_BYTES as u64 + 1)
        .read_to_end(&mut body)
        .map_err(|e| ServeError::BadRequest(format!("cannot read the request body: {e}")))?;
    if body.len() > http::MAX_BODY_BYTES {
        return Err(ServeError::TooLarge(http::MAX_BODY_BYTES));
    }
    Ok(body)
}

fn respond(request: tiny_http::Request, reply: http::Reply) {
    let header = |name: &str, value: &str| {
        tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes()).ok()
    };
    // A Content-Length instead of chunks, whatever the size (the body is in memory).
    let mut response = tiny_http::Response::from_data(reply.body)
        .with_status_code(reply.status)
        .with_chunked_threshold(usize::MAX);
    let headers = [
        ("Content-Type", reply.content_type.to_string()),
        ("Cache-Control", "no-store".into()),
    ];
    for (name, value) in headers
        .iter()
        .map(|(n, v)| (*n, v.clone()))
        .chain(reply.headers)
    {
        if let Some(h) = header(name, &value) {
            response.add_header(h);
        }
    }
    // The client may have gone (a cancelled pass): nothing to do then.
    let _ = request.respond(response);
}

/// A scene for a bare mesh file: its richest primitive kind (triangles, else edges,
/// else points), `alpha_rel` 1000 (200 for points, which need a softer surface to
/// close), the default MatCap; the camera is set once built (see [`Server::start`]).
pub fn scene_for_mesh(path: &Path) -> Result<Scene, crate::mesh::MeshError> {
    let (kind, alpha_rel) = if crate::las::is_lidar_path(path) {
        (PrimitiveKind::Points, 200.0)
    } else {
        let mesh = Mesh::load(path)?;
        if !mesh.triangles.is_empty() {
            (PrimitiveKind::Triangles, 1000.0)
        } else if !mesh.segments.is_empty() {
            (PrimitiveKind::Edges, 1000.0)
        } else {
            (PrimitiveKind::Points, 200.0)
        }
    };
    let object = Object {
        geometry: Geometry::Mesh(path.to_path_buf()),
        primitives: vec![kind],
        alpha: AlphaSpec::Relative(alpha_rel),
        max_alpha: None,
        transform: Default::default(),
        matcap: Default::default(),
        las: Default::default(),
        colour: None,
        surface: crate::scene::Surface::Smooth,
    };
    let mut scene = Scene::new(
        CameraSettings::looking_at(DVec3::Z, DVec3::ZERO),
        vec![object],
    );
    scene.path = path.to_path_buf();
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panicking_request_answers_500() {
        let reply = guarded(|| panic!("boom in a render"));
        assert_eq!(reply.status, 500);
        let body = String::from_utf8(reply.body).unwrap();
        assert_eq!(
            body,
            "the request failed (the server goes on): boom in a render"
        );
        let reply = guarded(|| Err(ServeError::Cancelled));
        assert_eq!(reply.status, 409);
    }
}
