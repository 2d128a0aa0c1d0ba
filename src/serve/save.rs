//! Saving the current view as a scene TOML (the format of the README's "Scene files"):
//! camera, image, render settings and every object, with file paths written relative to
//! the folder the TOML goes to, so `smoothtrace render` reads back the same scene.

use crate::matcap::MatCapSpec;
use crate::scene::{AlphaSpec, Epsilon, Geometry, LasOptions, Scene};
use glam::DVec3;
use std::path::{Component, Path, PathBuf};
use toml::{Table, Value};

/// Why a scene could not be written as TOML.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SaveError(pub String);

fn vec3(v: DVec3) -> Value {
    Value::Array(vec![v.x.into(), v.y.into(), v.z.into()])
}

fn alpha_into(t: &mut Table, key: &str, a: AlphaSpec) {
    match a {
        AlphaSpec::Absolute(v) => t.insert(key.into(), v.into()),
        AlphaSpec::Relative(v) => t.insert(format!("{key}_rel"), v.into()),
    };
}

/// `path` written relative to the folder `from` when both resolve (`../data/x.obj`),
/// else absolute.
pub fn relative_path(path: &Path, from: &Path) -> String {
    // A file not written yet resolves through its folder.
    let real = path
        .canonicalize()
        .or_else(|e| match (path.parent(), path.file_name()) {
            (Some(dir), Some(name)) => dir.canonicalize().map(|d| d.join(name)),
            _ => Err(e),
        });
    let (Ok(path), Ok(from)) = (real, from.canonicalize()) else {
        return path.display().to_string();
    };
    let a: Vec<Component> = path.components().collect();
    let b: Vec<Component> = from.components().collect();
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    if common == 0 {
        return path.display().to_string();
    }
    let mut rel = PathBuf::new();
    for _ in common..b.len() {
        rel.push("..");
    }
    for c in &a[common..] {
        rel.push(c.as_os_str());
    }
    // Forward slashes read back on every platform.
    rel.to_string_lossy().replace('\\', "/")
}

/// The scene as TOML text, paths relative to `folder` (where the file will be).
pub fn scene_toml(scene: &Scene, folder: &Path) -> Result<String, SaveError> {
    let mut root = Table::new();
    let c = &scene.camera;
    let mut camera = Table::new();
    camera.insert("origin".into(), vec3(c.origin));
    camera.insert("target".into(), vec3(c.target));
    camera.insert("up".into(), vec3(c.up));
    camera.insert("fov".into(), c.fov.into());
    root.insert("camera".into(), camera.into());
    let mut image = Table::new();
    image.insert("width".into(), i64::from(scene.image.width).into());
    image.insert("height".into(), i64::from(scene.image.height).into());
    let [r, g, b] = scene.image.background;
    image.insert(
        "background".into(),
        format!("#{r:02x}{g:02x}{b:02x}").into(),
    );
    root.insert("image".into(), image.into());
    let mut render = Table::new();
    render.insert("beta".into(), scene.render.beta.into());
    match scene.render.epsilon {
        Epsilon::Absolute(e) => render.insert("epsilon".into(), e.into()),
        Epsilon::Relative(e) => render.insert("epsilon_rel".into(), e.into()),
    };
    render.insert("max_steps".into(), i64::from(scene.render.max_steps).into());
    let evaluation = serde_json::to_value(scene.render.evaluation)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| "stable".into());
    render.insert("evaluation".into(), evaluation.into());
    if scene.render.threads != 0 {
        render.insert("threads".into(), (scene.render.threads as i64).into());
    }
    if scene.render.certified_hits {
        render.insert("certified_hits".into(), true.into());
    }
    root.insert("render".into(), render.into());
    let mut objects = Vec::new();
    for (k, o) in scene.objects.iter().enumerate() {
        if o.las != LasOptions::default() {
            return Err(SaveError(format!(
                "object[{k}]: saving lidar filters and colours (classes, crop, thin, origin, color_by) is not supported yet; copy them from the original scene file"
            )));
        }
        let mut t = Table::new();
        match &o.geometry {
            Geometry::Mesh(p) => {
                t.insert("mesh".into(), relative_path(p, folder).into());
            }
            Geometry::Generator(g) => {
                let v = Value::try_from(g)
                    .map_err(|e| SaveError(format!("object[{k}].generator: {e}")))?;
                t.insert("generator".into(), v);
            }
        }
        let kinds: Vec<Value> = o.primitives.iter().map(|p| p.name().into()).collect();
        t.insert("primitives".into(), Value::Array(kinds));
        alpha_into(&mut t, "alpha", o.alpha);
        if let Some(m) = o.max_alpha {
            alpha_into(&mut t, "max_alpha", m);
        }
        let matcap = match &o.matcap {
            MatCapSpec::File(p) => relative_path(p, folder),
            other => other.to_string(),
        };
        t.insert("matcap".into(), matcap.into());
        if let Some(c) = &o.colour {
            t.insert("color_by".into(), c.by.name().into());
            if c.by == crate::colour::GeometryColorBy::Height {
                t.insert("colormap".into(), c.colormap.name().into());
            }
        }
        if !o.transform.is_identity() {
            let mut tr = Table::new();
            tr.insert("scale".into(), vec3(o.transform.scale));
            tr.insert("rotate".into(), vec3(o.transform.rotate));
            tr.insert("translate".into(), vec3(o.transform.translate));
            t.insert("transform".into(), tr.into());
        }
        objects.push(Value::Table(t));
    }
    root.insert("object".into(), Value::Array(objects));
    let text = toml::to_string(&root).map_err(|e| SaveError(format!("cannot write TOML: {e}")))?;
    Ok(format!(
        "# Saved by `smoothtrace serve` from {}.\n{text}",
        scene.path.display()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_climb_out_of_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("scenes")).unwrap();
        std::fs::create_dir_all(dir.path().join("data")).unwrap();
        std::fs::write(dir.path().join("data/m.obj"), b"v 0 0 0\n").unwrap();
        assert_eq!(
            relative_path(&dir.path().join("data/m.obj"), &dir.path().join("scenes")),
            "../data/m.obj"
        );
        assert_eq!(
            relative_path(
                &dir.path().join("scenes/../data/m.obj"),
                &dir.path().join("data")
            ),
            "m.obj"
        );
    }

    #[test]
    fn a_saved_scene_reads_back_equal() {
        let dir = tempfile::tempdir().unwrap();
        let text = r##"
[camera]
origin = [0.0, 2.0, 2.6]
target = [0.0, -0.05, 0.0]
fov = 40.0
[image]
width = 64
height = 48
background = "#102030"
[render]
beta = 0.25
epsilon_rel = 0.001
[[object]]
generator = { kind = "torus", minor_radius = 0.3 }
primitives = ["triangles", "edges"]
alpha_rel = 500.0
max_alpha = 600.0
matcap = "gold"
transform = { scale = 2.0, rotate = [0.0, 30.0, 0.0], translate = [1.0, 0.0, 0.0] }
color_by = "height"
colormap = "magma"
[[object]]
generator = { kind = "torus" }
primitives = ["points"]
alpha_rel = 50.0
color_by = "normal"
"##;
        let a = Scene::from_str(text, &dir.path().join("a.toml")).unwrap();
        let saved = scene_toml(&a, dir.path()).unwrap();
        let b = Scene::from_str(&saved, &dir.path().join("b.toml")).unwrap();
        assert_eq!(a.camera, b.camera);
        assert_eq!(a.image, b.image);
        assert_eq!(a.render, b.render);
        assert_eq!(a.objects, b.objects, "saved:\n{saved}");
    }
}
