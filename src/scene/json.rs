//! The published scene builder's JSON scenes (the paper's `scenes/*.json`):
//!
//! ```json
//! {"camera": {"origin": [x, y, z], "dest": [x, y, z], "up": [x, y, z]},
//!  "objects": [{"path": "mesh.obj", "alpha": 100.0, "max_alpha": 200.0,
//!               "bvh_type": "faces", "matcap": ""}]}
//! ```
//!
//! read into the same [`Scene`] a TOML file gives: `dest` is the camera target, `path`
//! a mesh file resolved against the JSON file's folder, `bvh_type` `"points"`, `"edges"`
//! or `"faces"` (triangles), `matcap` a MatCap name or file (empty: the default),
//! `max_alpha` optional (the published reader falls back to alpha too). The published
//! files give no image size, field of view or render settings, so the TOML defaults
//! apply. Unknown keys are errors, as in TOML scenes.

use super::{
    AlphaSpec, CameraSettings, Geometry, LasOptions, MatCapSpec, Object, Scene, SceneError,
    Surface, Transform,
};
use crate::primitives::PrimitiveKind;
use glam::DVec3;
use serde::Deserialize;
use std::path::Path;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonScene {
    camera: JsonCamera,
    objects: Vec<JsonObject>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonCamera {
    origin: [f64; 3],
    dest: [f64; 3],
    #[serde(default = "y_up")]
    up: [f64; 3],
}

fn y_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonObject {
    path: String,
    alpha: f64,
    max_alpha: Option<f64>,
    bvh_type: BvhType,
    #[serde(default)]
    matcap: String,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "snake_case")]
enum BvhType {
    Points,
    Edges,
    Faces,
}

impl BvhType {
    fn kind(self) -> PrimitiveKind {
        match self {
            BvhType::Points => PrimitiveKind::Points,
            BvhType::Edges => PrimitiveKind::Edges,
            BvhType::Faces => PrimitiveKind::Triangles,
        }
    }
}

/// Parses a JSON scene (`text`, the contents of `path`) into an unvalidated [`Scene`].
pub(super) fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let raw: JsonScene = serde_json::from_str(text).map_err(|e| SceneError::Syntax {
        path: path.to_path_buf(),
        location: (e.line() > 0).then_some(super::Location {
            line: e.line(),
            column: e.column(),
        }),
        message: format!(
            "{} (a published JSON scene: {{\"camera\": {{\"origin\", \"dest\", \"up\"}}, \
             \"objects\": [{{\"path\", \"alpha\", \"max_alpha\", \"bvh_type\", \"matcap\"}}]}})",
            strip_position(&e.to_string())
        ),
    })?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let camera = CameraSettings {
        up: DVec3::from_array(raw.camera.up),
        ..CameraSettings::looking_at(
            DVec3::from_array(raw.camera.origin),
            DVec3::from_array(raw.camera.dest),
        )
    };
    let objects = raw
        .objects
        .into_iter()
        .map(|o| Object {
            geometry: Geometry::Mesh(dir.join(&o.path)),
            primitives: vec![o.bvh_type.kind()],
            alpha: AlphaSpec::Absolute(o.alpha),
            max_alpha: o.max_alpha.map(AlphaSpec::Absolute),
            transform: Transform::IDENTITY,
            matcap: if o.matcap.is_empty() {
                MatCapSpec::default()
            } else {
                MatCapSpec::parse(&o.matcap, dir)
            },
            las: LasOptions::default(),
            colour: None,
            surface: Surface::Smooth,
        })
        .collect();
    let mut scene = Scene::new(camera, objects);
    scene.path = path.to_path_buf();
    Ok(scene)
}

/// serde_json ends its messages with " at line L column C"; the location is printed
/// in front instead.
fn strip_position(message: &str) -> &str {
    match message.rfind(" at line ") {
        Some(i) => &message[..i],
        None => message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_bunny_scene() {
        let text = r#"{"camera":{"dest":[-0.1,1.1,0.0],"origin":[-0.1,1.0,3.0],"up":[0.0,1.0,0.0]},"objects":[{"alpha":100.0,"bvh_type":"faces","matcap":"","max_alpha":200.0,"path":"../data/bunny10.obj"}]}"#;
        let s = parse(text, Path::new("scenes/bunny.json")).unwrap();
        assert_eq!(s.camera.origin, DVec3::new(-0.1, 1.0, 3.0));
        assert_eq!(s.camera.target, DVec3::new(-0.1, 1.1, 0.0));
        let o = &s.objects[0];
        assert_eq!(
            o.geometry,
            Geometry::Mesh(Path::new("scenes/../data/bunny10.obj").to_path_buf())
        );
        assert_eq!(o.primitives, vec![PrimitiveKind::Triangles]);
        assert_eq!(o.alpha, AlphaSpec::Absolute(100.0));
        assert_eq!(o.max_alpha, Some(AlphaSpec::Absolute(200.0)));
        assert_eq!(o.matcap, MatCapSpec::default());
    }

    #[test]
    fn errors_name_the_file_line_and_key() {
        let text = "{\"camera\":{\"dest\":[0,0,0],\"origin\":[0,0,1]},\n\"objects\":[{\"alpha\":1,\"bvh_type\":\"cubes\",\"path\":\"a.obj\"}]}";
        let e = parse(text, Path::new("s.json")).unwrap_err().to_string();
        assert!(e.starts_with("s.json:2:"), "{e}");
        assert!(e.contains("unknown variant `cubes`"), "{e}");
        let e = parse("{\"camera\":{}}", Path::new("s.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing field `origin`"), "{e}");
    }
}
