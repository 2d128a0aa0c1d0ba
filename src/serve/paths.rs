//! Path safety: the browser may only name files inside the served scene's folder.
//!
//! A name from a request must be relative, made of plain components (no `..`, no root,
//! no drive prefix, no empty or hidden-dot tricks), and once joined to the folder and
//! canonicalized (symlinks resolved) it must still lie inside the canonical folder. A
//! file that does not exist yet (a save target) is checked through its parent folder,
//! and a dangling or outside-pointing symlink at the name itself is refused.

use std::path::{Component, Path, PathBuf};

/// Why a name was refused (HTTP 403).
#[derive(Debug, thiserror::Error)]
#[error("{name:?}: {reason} (only files inside the scene's folder {folder} can be named)")]
pub struct PathError {
    pub name: String,
    pub reason: String,
    pub folder: String,
}

/// The served scene's folder, canonical.
#[derive(Clone, Debug)]
pub struct SceneFolder {
    root: PathBuf,
}

impl SceneFolder {
    /// The canonical form of `dir` (which must exist).
    pub fn new(dir: &Path) -> std::io::Result<SceneFolder> {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        Ok(SceneFolder {
            root: dir.canonicalize()?,
        })
    }

    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Whether `path` (canonical) lies inside the folder.
    pub fn contains(&self, path: &Path) -> bool {
        path.starts_with(&self.root)
    }

    /// The file `name` (relative, from a request) inside the folder. With `must_exist`
    /// the file itself is canonicalized and checked; otherwise its parent folder is, and
    /// an existing entry at the name must resolve inside the folder too.
    pub fn resolve(&self, name: &str, must_exist: bool) -> Result<PathBuf, PathError> {
        let fail = |reason: &str| PathError {
            name: name.to_string(),
            reason: reason.to_string(),
            folder: self.root.display().to_string(),
        };
        if name.is_empty() {
            return Err(fail("empty file name"));
        }
        if name.contains('\0') {
            return Err(fail("the name contains a NUL byte"));
        }
        let rel = Path::new(name);
        for c in rel.components() {
            match c {
                Component::Normal(_) => {}
                Component::ParentDir => return Err(fail("`..` is not allowed")),
                Component::RootDir | Component::Prefix(_) => {
                    return Err(fail("absolute paths are not allowed"));
                }
                Component::CurDir => return Err(fail("`.` components are not allowed")),
            }
        }
        let joined = self.root.join(rel);
        if must_exist {
            let real = joined
                .canonicalize()
                .map_err(|e| fail(&format!("cannot open it: {e}")))?;
            if !self.contains(&real) {
                return Err(fail("it resolves (through a symlink) outside the folder"));
            }
            return Ok(real);
        }
        let parent = joined.parent().ok_or_else(|| fail("no parent folder"))?;
        let real_parent = parent
            .canonicalize()
            .map_err(|e| fail(&format!("its folder cannot be opened: {e}")))?;
        if !self.contains(&real_parent) {
            return Err(fail(
                "its folder resolves (through a symlink) outside the folder",
            ));
        }
        let file_name = joined.file_name().ok_or_else(|| fail("no file name"))?;
        let target = real_parent.join(file_name);
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => match target.canonicalize() {
                Ok(real) if self.contains(&real) => Ok(real),
                _ => Err(fail("it is a symlink that leads outside the folder")),
            },
            Ok(m) if m.is_dir() => Err(fail("it is a folder")),
            _ => Ok(target),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_stay_inside_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        std::fs::write(dir.path().join("sub/a.png"), b"x").unwrap();
        std::fs::write(outside.path().join("secret.png"), b"x").unwrap();
        let folder = SceneFolder::new(dir.path()).unwrap();
        let root = folder.root().to_path_buf();
        assert_eq!(
            folder.resolve("sub/a.png", true).unwrap(),
            root.join("sub/a.png")
        );
        assert_eq!(
            folder.resolve("new.toml", false).unwrap(),
            root.join("new.toml")
        );
        for bad in [
            "../x.toml",
            "sub/../../x.toml",
            "/etc/passwd",
            "",
            "./a",
            "sub",
        ] {
            assert!(folder.resolve(bad, false).is_err(), "{bad} was accepted");
        }
        assert!(folder.resolve("missing.png", true).is_err());
        #[cfg(unix)]
        {
            use std::os::unix::fs::symlink;
            symlink(
                outside.path().join("secret.png"),
                dir.path().join("link.png"),
            )
            .unwrap();
            symlink(outside.path(), dir.path().join("out")).unwrap();
            symlink(dir.path().join("sub/a.png"), dir.path().join("inside.png")).unwrap();
            let e = folder.resolve("link.png", true).unwrap_err().to_string();
            assert!(e.contains("outside the folder"), "{e}");
            assert!(folder.resolve("link.png", false).is_err());
            assert!(folder.resolve("out/new.toml", false).is_err());
            assert!(folder.resolve("out/secret.png", true).is_err());
            assert_eq!(
                folder.resolve("inside.png", true).unwrap(),
                root.join("sub/a.png")
            );
        }
    }
}
