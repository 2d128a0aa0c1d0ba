//! Routing: one function from a request (method, path, bounded body) to a response.
//!
//! | route | answer |
//! |---|---|
//! | `GET /`, `/app.js`, `/style.css` | the page ([`super::assets`]) |
//! | `GET /api/scene` | the starting view, the objects' diagonals, the MatCap names, limits |
//! | `GET /api/status` | job counters |
//! | `POST /api/render` | one pass as PNG (409 when a newer view cancelled it) |
//! | `POST /api/probe` | the probe of one pixel (JSON) |
//! | `POST /api/save` | the view as scene TOML; with `save_as`, also written in the scene's folder |
//!
//! Bad values answer 400 with the command line's message, a name outside the scene's
//! folder 403, a body over [`MAX_BODY_BYTES`] 413.

use super::view::{MAX_SAMPLES, MAX_SCALE, MAX_VIEW_SIZE, ViewRequest, initial_view};
use super::{ServeError, State, assets, save};
use crate::output::{Kind, Output};

/// Largest accepted request body.
pub const MAX_BODY_BYTES: usize = 64 * 1024;

/// A response before it is sent.
pub struct Reply {
    pub status: u16,
    pub content_type: &'static str,
    pub body: Vec<u8>,
    /// Extra headers (name, value).
    pub headers: Vec<(&'static str, String)>,
}

impl Reply {
    fn ok(content_type: &'static str, body: impl Into<Vec<u8>>) -> Reply {
        Reply {
            status: 200,
            content_type,
            body: body.into(),
            headers: Vec::new(),
        }
    }

    fn json(value: &impl serde::Serialize) -> Reply {
        Reply::ok(
            "application/json",
            serde_json::to_vec(value).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}").into()),
        )
    }

    /// The error as a plain-text answer.
    pub fn error(e: &ServeError) -> Reply {
        Reply {
            status: e.status(),
            content_type: "text/plain; charset=utf-8",
            body: e.to_string().into_bytes(),
            headers: Vec::new(),
        }
    }
}

/// Answers one request.
pub fn route(state: &State, method: &str, path: &str, body: &[u8]) -> Result<Reply, ServeError> {
    let path = path.split(['?', '#']).next().unwrap_or("");
    let get = method == "GET" || method == "HEAD";
    match (path, get, method == "POST") {
        ("/" | "/index.html", true, _) => Ok(Reply::ok("text/html; charset=utf-8", assets::INDEX)),
        ("/app.js", true, _) => Ok(Reply::ok("text/javascript; charset=utf-8", assets::APP_JS)),
        ("/style.css", true, _) => Ok(Reply::ok("text/css; charset=utf-8", assets::STYLE_CSS)),
        ("/api/scene", true, _) => Ok(scene_info(state)),
        ("/api/status", true, _) => Ok(Reply::json(&state.jobs.counters)),
        ("/api/render", _, true) => render(state, body),
        ("/api/probe", _, true) => {
            let view = ViewRequest::parse(body)?;
            let scene = view.apply(&state.scene, &state.folder)?;
            Ok(Reply::json(&state.jobs.probe(&view, &scene)?))
        }
        ("/api/save", _, true) => save(state, body),
        ("/" | "/index.html" | "/app.js" | "/style.css" | "/api/scene" | "/api/status", ..)
        | ("/api/render" | "/api/probe" | "/api/save", ..) => Err(ServeError::Method(format!(
            "{method} is not allowed on {path}"
        ))),
        _ => Err(ServeError::NotFound(format!("no such page: {path}"))),
    }
}

fn scene_info(state: &State) -> Reply {
    #[derive(serde::Serialize)]
    struct Info<'a> {
        scene: String,
        view: ViewRequest,
        diagonals: Vec<f64>,
        objects: Vec<String>,
        matcaps: Vec<&'a str>,
        save_as: Option<String>,
        max_size: u32,
        max_samples: u32,
        max_scale: u32,
    }
    let objects = state
        .scene
        .objects
        .iter()
        .map(|o| match &o.geometry {
            crate::scene::Geometry::Mesh(p) => save::relative_path(p, state.folder.root()),
            crate::scene::Geometry::Generator(g) => {
                let kind = serde_json::to_value(g).ok();
                let kind = kind.as_ref().and_then(|v| v["kind"].as_str());
                format!("generator {}", kind.unwrap_or("?"))
            }
        })
        .collect();
    let mut matcaps = vec!["normal"];
    matcaps.extend(crate::matcap::builtin_names());
    Reply::json(&Info {
        scene: state.scene.path.display().to_string(),
        view: initial_view(&state.scene),
        diagonals: state.jobs.diagonals(),
        objects,
        matcaps,
        save_as: state
            .save
            .as_ref()
            .map(|p| save::relative_path(p, state.folder.root())),
        max_size: MAX_VIEW_SIZE,
        max_samples: MAX_SAMPLES,
        max_scale: MAX_SCALE,
    })
}

fn render(state: &State, body: &[u8]) -> Result<Reply, ServeError> {
    let view = ViewRequest::parse(body)?;
    let scene = view.apply(&state.scene, &state.folder)?;
    let pass = state.jobs.render(&view, &scene)?;
    let s = &pass.stats;
    let mut reply = Reply::ok("image/png", pass.png);
    reply.headers.push((
        "X-Render-Stats",
        format!(
            "{}x{} in {:.0} ms, {:.0} rays/s, {:.1} evaluations per ray{}",
            s.width,
            s.height,
            s.seconds * 1e3,
            s.rays_per_second(),
            s.evals_per_ray() + s.bound_evals_per_ray(),
            if s.camera_inside {
                " (the camera is inside the surface)"
            } else {
                ""
            }
        ),
    ));
    Ok(reply)
}

fn save(state: &State, body: &[u8]) -> Result<Reply, ServeError> {
    let view = ViewRequest::parse(body)?;
    let scene = view.apply(&state.scene, &state.folder)?;
    let Some(name) = &view.save_as else {
        let text = save::scene_toml(&scene, state.folder.root())
            .map_err(|e| ServeError::BadRequest(e.to_string()))?;
        let mut reply = Reply::ok("application/toml; charset=utf-8", text);
        reply.headers.push((
            "Content-Disposition",
            "attachment; filename=\"scene.toml\"".into(),
        ));
        return Ok(reply);
    };
    if state.save.is_none() {
        return Err(ServeError::Forbidden(
            "saving on the server is off: start `smoothtrace serve` with --save NAME.toml".into(),
        ));
    }
    if !name.to_ascii_lowercase().ends_with(".toml") {
        return Err(ServeError::BadRequest(format!(
            "save_as: {name:?} must end in .toml"
        )));
    }
    let path = state
        .folder
        .resolve(name, false)
        .map_err(|e| ServeError::Forbidden(format!("save_as: {e}")))?;
    let folder = path.parent().unwrap_or(state.folder.root());
    let text =
        save::scene_toml(&scene, folder).map_err(|e| ServeError::BadRequest(e.to_string()))?;
    // The output module writes through a temporary file renamed on success; the kind
    // only matters to its image writers.
    Output::check_as(&path, Kind::Json)
        .and_then(|o| o.write_bytes(text.as_bytes()))
        .map_err(|e| ServeError::Internal(e.to_string()))?;
    let mut reply = Reply::ok("application/toml; charset=utf-8", text);
    reply
        .headers
        .push(("X-Saved-To", path.display().to_string()));
    Ok(reply)
}
