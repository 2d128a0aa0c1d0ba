//! Output files that are checked before the long work and never left half-written.
//!
//! [`Output::check`] runs before a render, a field or a report starts: the extension
//! must name a format the caller can write (so `render -o x.tif` fails at once, not
//! after the whole image), the path must not be a directory, and its folder must exist
//! and accept a new file (a temporary file is created and removed to prove it).
//! [`Output::check_as`] is the same for outputs whose format a flag decides (`--csv`,
//! `--json`, `--stats`), whatever their extension.
//!
//! [`Output::write_with`] and [`Output::write_image`] write to a temporary file in the
//! same folder and rename it over the target only when everything was written and
//! flushed: an interrupted or failed write leaves the old file (or no file) in place,
//! never an empty or truncated one. The new file gets the usual permissions (0666 less
//! the umask), not the temporary file's private 0600.
//!
//! Formats: 8-bit images as PNG, JPEG (the `image` crate's default quality, 75) or WebP (lossless; the `image`
//! crate's WebP encoder is lossless only), floating-point images as OpenEXR, text as
//! CSV or JSON, volumes as NumPy `.npy`.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file format, chosen by extension (any case).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Png,
    Jpeg,
    WebP,
    Exr,
    Csv,
    Json,
    Npy,
    /// Animated GIF (turntables), encoded by the caller and written with `write_bytes`.
    Gif,
}

/// The 8-bit image formats (render images, previews, plots).
pub const IMAGE_8BIT: &[Kind] = &[Kind::Png, Kind::Jpeg, Kind::WebP];

impl Kind {
    /// The format named by a path's extension.
    pub fn from_path(path: &Path) -> Option<Kind> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "png" => Kind::Png,
            "jpg" | "jpeg" => Kind::Jpeg,
            "webp" => Kind::WebP,
            "exr" => Kind::Exr,
            "csv" => Kind::Csv,
            "json" => Kind::Json,
            "npy" => Kind::Npy,
            "gif" => Kind::Gif,
            _ => return None,
        })
    }

    /// The extensions that name this format, for messages.
    pub fn extensions(self) -> &'static str {
        match self {
            Kind::Png => ".png",
            Kind::Jpeg => ".jpg/.jpeg",
            Kind::WebP => ".webp",
            Kind::Exr => ".exr",
            Kind::Csv => ".csv",
            Kind::Json => ".json",
            Kind::Npy => ".npy",
            Kind::Gif => ".gif",
        }
    }

    fn image_format(self) -> Option<image::ImageFormat> {
        Some(match self {
            Kind::Png => image::ImageFormat::Png,
            Kind::Jpeg => image::ImageFormat::Jpeg,
            Kind::WebP => image::ImageFormat::WebP,
            Kind::Exr => image::ImageFormat::OpenExr,
            _ => return None,
        })
    }
}

/// What went wrong with an output file; every variant names the path.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{}: unsupported output format{}; {what} can be written as {accepted}", path.display(),
        if extension.is_empty() { " (no extension)".to_string() } else { format!(" '.{extension}'") })]
    UnsupportedFormat {
        path: PathBuf,
        extension: String,
        what: String,
        accepted: String,
    },
    #[error("{}: is a directory; give a file name", path.display())]
    IsDirectory { path: PathBuf },
    #[error("{}: cannot write to the folder {}: {source}", path.display(), folder.display())]
    Folder {
        path: PathBuf,
        folder: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: cannot write: {source}", path.display())]
    Write {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: cannot encode the image: {source}", path.display())]
    Encode {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
}

/// A checked output path and its format.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Output {
    pub path: PathBuf,
    pub kind: Kind,
}

impl Output {
    /// Checks `path` before any work: its extension names one of `accepted` (`what`
    /// describes the output in the message, e.g. "the rendered image"), it is not a
    /// directory, and its folder exists and accepts a new file.
    pub fn check(path: &Path, accepted: &[Kind], what: &str) -> Result<Output, OutputError> {
        let kind = Kind::from_path(path).filter(|k| accepted.contains(k));
        let Some(kind) = kind else {
            return Err(OutputError::UnsupportedFormat {
                path: path.to_path_buf(),
                extension: path
                    .extension()
                    .map(|e| e.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                what: what.to_string(),
                accepted: accepted
                    .iter()
                    .map(|k| k.extensions())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        Output::check_as(path, kind)
    }

    /// [`Output::check`] for an output whose format is `kind` whatever the extension.
    pub fn check_as(path: &Path, kind: Kind) -> Result<Output, OutputError> {
        if path.is_dir() {
            return Err(OutputError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        let out = Output {
            path: path.to_path_buf(),
            kind,
        };
        // Proves the folder exists and is writable; removed when dropped.
        out.temp_file().map_err(|source| OutputError::Folder {
            path: path.to_path_buf(),
            folder: out.folder(),
            source,
        })?;
        Ok(out)
    }

    /// The folder the file goes to (`.` for a bare file name).
    fn folder(&self) -> PathBuf {
        match self.path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        }
    }

    fn temp_file(&self) -> std::io::Result<tempfile::NamedTempFile> {
        let name = self
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let prefix = format!(".{name}.");
        let mut b = tempfile::Builder::new();
        b.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            // The umask applies, as for any new file.
            b.permissions(std::fs::Permissions::from_mode(0o666));
        }
        b.tempfile_in(self.folder())
    }

    /// Writes the file through `write` into a temporary file in the same folder, then
    /// renames it over the target. On any error the target is untouched and the
    /// temporary file is removed.
    pub fn write_with<E>(
        &self,
        write: impl FnOnce(&mut BufWriter<&std::fs::File>) -> Result<(), E>,
    ) -> Result<(), E>
    where
        E: From<OutputError>,
    {
        let io = |source| OutputError::Write {
            path: self.path.clone(),
            source,
        };
        let tmp = self.temp_file().map_err(io)?;
        {
            let mut w = BufWriter::new(tmp.as_file());
            write(&mut w)?;
            w.flush().map_err(io)?;
        }
        tmp.as_file().sync_all().map_err(io)?;
        tmp.persist(&self.path).map_err(|e| io(e.error))?;
        Ok(())
    }

    /// Writes `bytes` (text outputs).
    pub fn write_bytes(&self, bytes: &[u8]) -> Result<(), OutputError> {
        self.write_with(|w| {
            w.write_all(bytes).map_err(|source| OutputError::Write {
                path: self.path.clone(),
                source,
            })
        })
    }

    /// Encodes `img` in the checked format (an 8-bit RGB image for PNG/JPEG/WebP, an f32
    /// RGB image for EXR).
    pub fn write_image(&self, img: &image::DynamicImage) -> Result<(), OutputError> {
        let Some(format) = self.kind.image_format() else {
            return Err(OutputError::UnsupportedFormat {
                path: self.path.clone(),
                extension: self.kind.extensions().into(),
                what: "an image".into(),
                accepted: ".png, .jpg, .webp, .exr".into(),
            });
        };
        // The writer must be seekable for some encoders: encode in memory first.
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, format)
            .map_err(|source| OutputError::Encode {
                path: self.path.clone(),
                source,
            })?;
        self.write_bytes(buf.get_ref())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_by_extension() {
        assert_eq!(Kind::from_path(Path::new("a/b.JPG")), Some(Kind::Jpeg));
        assert_eq!(Kind::from_path(Path::new("b.webp")), Some(Kind::WebP));
        assert_eq!(Kind::from_path(Path::new("b.gif")), Some(Kind::Gif));
        assert_eq!(Kind::from_path(Path::new("b.tif")), None);
        assert_eq!(Kind::from_path(Path::new("b")), None);
    }

    #[test]
    fn unsupported_and_directory_targets_fail_before_work() {
        let dir = tempfile::tempdir().unwrap();
        let e = Output::check(&dir.path().join("x.gif"), IMAGE_8BIT, "the image").unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("x.gif") && msg.contains(".png"), "{msg}");
        let sub = dir.path().join("d.png");
        std::fs::create_dir(&sub).unwrap();
        assert!(matches!(
            Output::check(&sub, IMAGE_8BIT, "the image"),
            Err(OutputError::IsDirectory { .. })
        ));
        let e = Output::check(&dir.path().join("no/such/x.png"), IMAGE_8BIT, "the image");
        assert!(matches!(e, Err(OutputError::Folder { .. })), "{e:?}");
        // Nothing was left behind by the checks.
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1);
    }

    #[test]
    fn failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(&path, "old").unwrap();
        let out = Output::check(&path, &[Kind::Csv], "the table").unwrap();
        let r: Result<(), OutputError> = out.write_with(|w| {
            w.write_all(b"half").unwrap();
            Err(OutputError::IsDirectory { path: path.clone() })
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        out.write_bytes(b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// Every 8-bit format round-trips through the `image` decoders: JPEG within its
    /// lossy tolerance, PNG and (lossless) WebP exactly.
    #[test]
    fn image_formats_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let img =
            image::RgbImage::from_fn(16, 8, |x, y| image::Rgb([x as u8 * 16, y as u8 * 32, 128]));
        for (name, exact) in [("a.png", true), ("a.webp", true), ("a.jpg", false)] {
            let path = dir.path().join(name);
            let out = Output::check(&path, IMAGE_8BIT, "the image").unwrap();
            out.write_image(&image::DynamicImage::ImageRgb8(img.clone()))
                .unwrap();
            let back = image::open(&path).unwrap().to_rgb8();
            assert_eq!(back.dimensions(), img.dimensions());
            let max_diff = back
                .pixels()
                .zip(img.pixels())
                .flat_map(|(a, b)| (0..3).map(move |c| (a[c] as i32 - b[c] as i32).abs()))
                .max()
                .unwrap();
            let tol = if exact { 0 } else { 24 };
            assert!(max_diff <= tol, "{name}: max difference {max_diff} > {tol}");
        }
    }
}
