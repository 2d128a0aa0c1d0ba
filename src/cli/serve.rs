//! `smoothtrace serve`: the browser scene builder ([`smoothtrace::serve`]). Prints the
//! URL, warns when listening beyond loopback, stops cleanly on Ctrl-C.

use super::console::note;
use anyhow::{Context, Result};
use clap::Args;
use smoothtrace::scene::Scene;
use smoothtrace::serve::{ServeConfig, Server, scene_for_mesh};
use std::io::Write;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ServeArgs {
    /// Scene file (.toml, or a published .json scene), or a mesh file (.obj, .ply, .stl,
    /// .las, .laz) shown with a default camera.
    scene: PathBuf,
    /// Port to listen on (0: any free port; the URL printed tells which).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Address to listen on. Anything but loopback lets other machines use the server
    /// (and read the scene's files through it): a warning is printed.
    #[arg(long, default_value = "127.0.0.1")]
    host: String,
    /// Let the page save scene TOML files on the server, inside the scene's folder
    /// (this file is the one it suggests).
    #[arg(long)]
    save: Option<PathBuf>,
}

fn is_scene_file(path: &std::path::Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("toml") || e.eq_ignore_ascii_case("json"))
}

pub fn run(a: ServeArgs) -> Result<()> {
    let frame_camera = !is_scene_file(&a.scene);
    let scene = if frame_camera {
        let scene = scene_for_mesh(&a.scene)?;
        scene.validate()?;
        scene
    } else {
        Scene::load(&a.scene)?
    };
    let loopback = a
        .host
        .parse::<std::net::IpAddr>()
        .map(|ip| ip.is_loopback())
        .unwrap_or(a.host == "localhost");
    let server = Server::start(ServeConfig {
        scene,
        host: a.host.clone(),
        port: a.port,
        save: a.save,
        frame_camera,
    })?;
    if !loopback {
        note!(
            "warning: listening on {} ({}), not only on this machine: anyone who can reach it can render and probe the scene{}",
            a.host,
            server.addr(),
            if server.state().save.is_some() {
                " and write .toml files into its folder"
            } else {
                ""
            }
        );
    }
    let stop = server.stopper();
    ctrlc::set_handler(stop).context("cannot install the Ctrl-C handler")?;
    let url = format!("http://{}/", server.addr());
    let mut out = std::io::stdout().lock();
    writeln!(out, "smoothtrace serve: {url} (Ctrl-C stops)")?;
    out.flush()?;
    drop(out);
    server.run();
    note!("smoothtrace serve: stopped");
    Ok(())
}
