//! One Zarr v3 float32 array on the file system: its metadata (`zarr.json`), creating,
//! opening and checking it, and its chunk files (module docs of `field::zarr`).

use crate::field::plan::VoxelBox;
use serde_json::{Value, json};
use std::io::Write;
use std::path::{Path, PathBuf};

/// How chunk bytes are stored after the `bytes` codec (little-endian float32).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Codec {
    /// The raw bytes: 4 per voxel, the fastest to write and read.
    Raw,
    /// The `gzip` codec at this level (1-9): small for banded fields (`+inf` runs),
    /// about 11% smaller and much slower for dense ones (measured, `doc/zarr.md`).
    Gzip(u32),
}

/// What an array holds: shape and chunk shape `(z, y, x)`, codec, attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct ZarrSpec {
    pub shape: [usize; 3],
    pub chunk: [usize; 3],
    pub codec: Codec,
    pub attributes: Value,
}

/// What went wrong with a Zarr array; every variant names the path.
#[derive(Debug, thiserror::Error)]
pub enum ZarrError {
    #[error(
        "{}: already exists; add --force to replace it, --resume to compute only its missing chunks, or --chunks I:J to (re)compute some of its chunks",
        path.display()
    )]
    Exists { path: PathBuf },
    #[error("{}: {reason}; not replacing it (give another output)", path.display())]
    NotReplaceable { path: PathBuf, reason: String },
    #[error("{}: cannot create the array: {source}", path.display())]
    Create {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error(
        "{}: not an array this program can write into: {reason}; remove it or add --force to replace it",
        path.display()
    )]
    Corrupt { path: PathBuf, reason: String },
    #[error(
        "{}: the array was written for another field: {what} is {existing} there but {wanted} in this run; repeat the original parameters, write another output, or add --force to replace it",
        path.display()
    )]
    Mismatch {
        path: PathBuf,
        what: String,
        existing: String,
        wanted: String,
    },
    #[error("{}: cannot write chunk {index}: {source}", path.display())]
    WriteChunk {
        path: PathBuf,
        index: usize,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: cannot read: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl ZarrSpec {
    /// The `zarr.json` document.
    pub fn metadata(&self) -> Value {
        let mut codecs = vec![json!({"name": "bytes", "configuration": {"endian": "little"}})];
        if let Codec::Gzip(level) = self.codec {
            codecs.push(json!({"name": "gzip", "configuration": {"level": level}}));
        }
        json!({
            "zarr_format": 3,
            "node_type": "array",
            "shape": self.shape,
            "data_type": "float32",
            "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": self.chunk}},
            "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
            "fill_value": "NaN",
            "codecs": codecs,
            "attributes": self.attributes,
            "dimension_names": ["z", "y", "x"],
        })
    }

    /// Reads a `zarr.json` document back; refuses anything this module would not write.
    fn from_metadata(m: &Value) -> Result<ZarrSpec, String> {
        let field = |k: &str| m.get(k).ok_or_else(|| format!("no \"{k}\""));
        let triple = |v: &Value, what: &str| -> Result<[usize; 3], String> {
            let a = v
                .as_array()
                .filter(|a| a.len() == 3)
                .ok_or_else(|| format!("{what} is not three integers"))?;
            let mut out = [0usize; 3];
            for (o, x) in out.iter_mut().zip(a) {
                *o = x
                    .as_u64()
                    .filter(|&x| x > 0)
                    .ok_or_else(|| format!("{what} is not three positive integers"))?
                    as usize;
            }
            Ok(out)
        };
        let expect = |k: &str, want: Value| -> Result<(), String> {
            let got = field(k)?;
            if *got == want {
                Ok(())
            } else {
                Err(format!("\"{k}\" is {got}, expected {want}"))
            }
        };
        expect("zarr_format", json!(3))?;
        expect("node_type", json!("array"))?;
        expect("data_type", json!("float32"))?;
        expect(
            "chunk_key_encoding",
            json!({"name": "default", "configuration": {"separator": "/"}}),
        )?;
        expect("fill_value", json!("NaN"))?;
        let shape = triple(field("shape")?, "\"shape\"")?;
        let grid = field("chunk_grid")?;
        if grid.get("name") != Some(&json!("regular")) {
            return Err(format!("\"chunk_grid\" is {grid}, expected a regular grid"));
        }
        let chunk = triple(
            grid.pointer("/configuration/chunk_shape")
                .ok_or("no chunk_grid.configuration.chunk_shape")?,
            "the chunk shape",
        )?;
        let codecs = field("codecs")?
            .as_array()
            .ok_or("\"codecs\" is not a list")?;
        let bytes = json!({"name": "bytes", "configuration": {"endian": "little"}});
        let codec = match codecs.as_slice() {
            [b] if *b == bytes => Codec::Raw,
            [b, g] if *b == bytes && g.get("name") == Some(&json!("gzip")) => Codec::Gzip(
                g.pointer("/configuration/level")
                    .and_then(Value::as_u64)
                    .filter(|&l| l <= 9)
                    .ok_or("the gzip codec has no level 0-9")? as u32,
            ),
            _ => {
                return Err(format!(
                    "\"codecs\" are {}, expected bytes (little endian) and optionally gzip",
                    field("codecs")?
                ));
            }
        };
        Ok(ZarrSpec {
            shape,
            chunk,
            codec,
            attributes: m.get("attributes").cloned().unwrap_or(json!({})),
        })
    }

    /// Chunks along z, y, x.
    pub fn chunk_grid(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| self.shape[a].div_ceil(self.chunk[a]))
    }

    /// Number of chunks.
    pub fn chunk_count(&self) -> usize {
        self.chunk_grid().iter().product()
    }

    /// The voxels of chunk `index` (C order over the chunk grid), as a box of the grid
    /// (x, y, z order), cut at the array's far edges.
    pub fn chunk_box(&self, index: usize) -> VoxelBox {
        let [_, gy, gx] = self.chunk_grid();
        let k = [index / (gy * gx), (index / gx) % gy, index % gx];
        let start = [0, 1, 2].map(|a| k[a] * self.chunk[a]);
        let size = [0, 1, 2].map(|a| self.chunk[a].min(self.shape[a] - start[a]));
        VoxelBox {
            start: [start[2], start[1], start[0]],
            size: [size[2], size[1], size[0]],
        }
    }

    /// Bytes of one stored chunk before compression.
    fn chunk_bytes(&self) -> u64 {
        4 * self.chunk.iter().map(|&c| c as u64).product::<u64>()
    }
}

/// The first key (as a path) where two JSON values differ, with both values. Numbers
/// equal to 1e-15 relative are equal: serde_json's default parser may round the last
/// digit of a written f64 differently.
fn first_difference(path: &str, a: &Value, b: &Value) -> Option<(String, String, String)> {
    if a == b {
        return None;
    }
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            for k in x.keys().chain(y.keys()) {
                let (va, vb) = (
                    x.get(k).unwrap_or(&Value::Null),
                    y.get(k).unwrap_or(&Value::Null),
                );
                if let Some(d) = first_difference(&format!("{path}.{k}"), va, vb) {
                    return Some(d);
                }
            }
            return None;
        }
        (Value::Array(x), Value::Array(y))
            if x.len() == y.len()
                && x.iter()
                    .zip(y)
                    .all(|(p, q)| first_difference(path, p, q).is_none()) =>
        {
            return None;
        }
        (Value::Number(x), Value::Number(y)) => {
            if let (Some(p), Some(q)) = (x.as_f64(), y.as_f64())
                && (p - q).abs() <= 1e-15 * p.abs().max(q.abs())
            {
                return None;
            }
        }
        _ => {}
    }
    Some((path.to_string(), a.to_string(), b.to_string()))
}

/// An array on disk whose metadata has been written or checked.
#[derive(Clone, Debug)]
pub struct ZarrArray {
    path: PathBuf,
    spec: ZarrSpec,
}

impl ZarrArray {
    /// Creates a new array at `path`, which must not exist unless `force` (then an
    /// existing Zarr array or empty folder there is removed first; anything else is
    /// refused).
    pub fn create(path: &Path, spec: &ZarrSpec, force: bool) -> Result<ZarrArray, ZarrError> {
        if path.symlink_metadata().is_ok() {
            if !force {
                return Err(ZarrError::Exists { path: path.into() });
            }
            remove_array(path)?;
        }
        std::fs::create_dir(path).map_err(|source| ZarrError::Create {
            path: path.into(),
            source,
        })?;
        write_metadata(path, spec)?;
        Ok(ZarrArray {
            path: path.into(),
            spec: spec.clone(),
        })
    }

    /// Opens the array at `path` and checks that it is what `spec` describes (shape,
    /// chunks, codec and attributes); creates it when `path` does not exist or is an
    /// empty folder. Safe when several processes start at once (each writes the same
    /// metadata through a rename, then checks what is there).
    pub fn open_or_create(path: &Path, spec: &ZarrSpec) -> Result<ZarrArray, ZarrError> {
        if !path.join("zarr.json").exists() {
            match std::fs::create_dir(path) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && path.is_dir() => {
                    if !is_empty_dir(path)? && !path.join("zarr.json").exists() {
                        return Err(ZarrError::Corrupt {
                            path: path.into(),
                            reason: "a non-empty folder without zarr.json".into(),
                        });
                    }
                }
                Err(source) => {
                    return Err(ZarrError::Create {
                        path: path.into(),
                        source,
                    });
                }
            }
            if !path.join("zarr.json").exists() {
                write_metadata(path, spec)?;
            }
        }
        let a = ZarrArray::open(path)?;
        a.check_matches(spec)?;
        Ok(a)
    }

    /// Opens an existing array written by this module.
    pub fn open(path: &Path) -> Result<ZarrArray, ZarrError> {
        if !path.is_dir() {
            let reason = if path.exists() {
                "a file, not a Zarr array folder".to_string()
            } else {
                "does not exist".to_string()
            };
            return Err(ZarrError::Corrupt {
                path: path.into(),
                reason,
            });
        }
        let meta = path.join("zarr.json");
        let text = std::fs::read_to_string(&meta).map_err(|e| ZarrError::Corrupt {
            path: path.into(),
            reason: format!("cannot read zarr.json ({e})"),
        })?;
        let value: Value = serde_json::from_str(&text).map_err(|e| ZarrError::Corrupt {
            path: path.into(),
            reason: format!("zarr.json is not valid JSON ({e})"),
        })?;
        let spec = ZarrSpec::from_metadata(&value).map_err(|reason| ZarrError::Corrupt {
            path: path.into(),
            reason: format!("zarr.json: {reason}"),
        })?;
        Ok(ZarrArray {
            path: path.into(),
            spec,
        })
    }

    /// Refuses an array whose shape, chunks, codec or attributes differ from `spec`.
    pub fn check_matches(&self, spec: &ZarrSpec) -> Result<(), ZarrError> {
        let mismatch = |what: &str, existing: String, wanted: String| ZarrError::Mismatch {
            path: self.path.clone(),
            what: what.into(),
            existing,
            wanted,
        };
        let s = &self.spec;
        if s.shape != spec.shape {
            return Err(mismatch(
                "the shape (z, y, x)",
                format!("{:?}", s.shape),
                format!("{:?}", spec.shape),
            ));
        }
        if s.chunk != spec.chunk {
            return Err(mismatch(
                "the chunk shape (z, y, x)",
                format!("{:?}", s.chunk),
                format!("{:?}", spec.chunk),
            ));
        }
        if s.codec != spec.codec {
            return Err(mismatch(
                "the codec",
                format!("{:?}", s.codec),
                format!("{:?}", spec.codec),
            ));
        }
        if let Some((key, a, b)) = first_difference("attributes", &s.attributes, &spec.attributes) {
            return Err(mismatch(&key, a, b));
        }
        Ok(())
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn spec(&self) -> &ZarrSpec {
        &self.spec
    }

    /// The file of chunk `index`: `c/kz/ky/kx`.
    pub fn chunk_path(&self, index: usize) -> PathBuf {
        let [_, gy, gx] = self.spec.chunk_grid();
        self.path
            .join("c")
            .join((index / (gy * gx)).to_string())
            .join(((index / gx) % gy).to_string())
            .join((index % gx).to_string())
    }

    /// Chunks not (validly) on disk, in index order: absent files, and with the raw
    /// codec files of the wrong size (not written by this module).
    pub fn missing(&self) -> Vec<usize> {
        let want = self.spec.chunk_bytes();
        (0..self.spec.chunk_count())
            .filter(|&i| match std::fs::metadata(self.chunk_path(i)) {
                Ok(m) => !m.is_file() || (self.spec.codec == Codec::Raw && m.len() != want),
                Err(_) => true,
            })
            .collect()
    }

    /// Writes chunk `index` from the values of its box (C order, `(size_z, size_y,
    /// size_x)`), padded with NaN to the chunk shape, through a temporary file renamed
    /// when complete.
    pub fn write_chunk(&self, index: usize, values: &[f32]) -> Result<(), ZarrError> {
        let b = self.spec.chunk_box(index);
        assert_eq!(values.len(), b.len(), "values of chunk {index}");
        let [cz, cy, cx] = self.spec.chunk;
        let [sx, sy, sz] = b.size;
        let mut bytes = vec![0u8; 4 * cz * cy * cx];
        let nan = f32::NAN.to_le_bytes();
        let full = sx == cx && sy == cy && sz == cz;
        if !full {
            for c in bytes.chunks_exact_mut(4) {
                c.copy_from_slice(&nan);
            }
        }
        for k in 0..sz {
            for j in 0..sy {
                let src = &values[(k * sy + j) * sx..][..sx];
                let dst = &mut bytes[4 * (k * cy + j) * cx..][..4 * sx];
                for (d, v) in dst.chunks_exact_mut(4).zip(src) {
                    d.copy_from_slice(&v.to_le_bytes());
                }
            }
        }
        let path = self.chunk_path(index);
        let err = |source: std::io::Error| ZarrError::WriteChunk {
            path: path.clone(),
            index,
            source,
        };
        let dir = path.parent().expect("chunk paths have a folder");
        std::fs::create_dir_all(dir).map_err(err)?;
        let mut tmp = temp_in(dir, ".chunk.").map_err(err)?;
        match self.spec.codec {
            Codec::Raw => tmp.write_all(&bytes).map_err(err)?,
            Codec::Gzip(level) => {
                let mut gz = flate2::write::GzEncoder::new(
                    std::io::BufWriter::new(tmp.as_file_mut()),
                    flate2::Compression::new(level),
                );
                gz.write_all(&bytes).map_err(err)?;
                gz.finish().map_err(err)?.flush().map_err(err)?;
            }
        }
        tmp.persist(&path).map_err(|e| err(e.error))?;
        Ok(())
    }

    /// The whole array, `(z, y, x)` C order, NaN where chunks are missing (tests and
    /// small arrays; a large one is read with zarr-python, zarrs or tensorstore).
    pub fn read_all(&self) -> Result<Vec<f32>, ZarrError> {
        let [nz, ny, nx] = self.spec.shape;
        let [_, cy, cx] = self.spec.chunk;
        let mut out = vec![f32::NAN; nz * ny * nx];
        for index in 0..self.spec.chunk_count() {
            let path = self.chunk_path(index);
            let raw = match std::fs::read(&path) {
                Ok(r) => r,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                Err(source) => return Err(ZarrError::Read { path, source }),
            };
            let bytes = match self.spec.codec {
                Codec::Raw => raw,
                Codec::Gzip(_) => {
                    let mut v = Vec::new();
                    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&raw[..]), &mut v)
                        .map_err(|source| ZarrError::Read {
                            path: path.clone(),
                            source,
                        })?;
                    v
                }
            };
            if bytes.len() as u64 != self.spec.chunk_bytes() {
                return Err(ZarrError::Corrupt {
                    path,
                    reason: format!(
                        "{} bytes, expected {}",
                        bytes.len(),
                        self.spec.chunk_bytes()
                    ),
                });
            }
            let b = self.spec.chunk_box(index);
            let [x0, y0, z0] = b.start;
            let [sx, sy, sz] = b.size;
            for k in 0..sz {
                for j in 0..sy {
                    let src = &bytes[4 * (k * cy + j) * cx..][..4 * sx];
                    let dst = &mut out[((z0 + k) * ny + y0 + j) * nx + x0..][..sx];
                    for (d, s) in dst.iter_mut().zip(src.chunks_exact(4)) {
                        *d = f32::from_le_bytes([s[0], s[1], s[2], s[3]]);
                    }
                }
            }
        }
        Ok(out)
    }
}

/// A temporary file in `dir` with the usual permissions (0666 less the umask).
fn temp_in(dir: &Path, prefix: &str) -> std::io::Result<tempfile::NamedTempFile> {
    let mut b = tempfile::Builder::new();
    b.prefix(prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(dir)
}

/// Writes `zarr.json` through a temporary file renamed into place.
fn write_metadata(path: &Path, spec: &ZarrSpec) -> Result<(), ZarrError> {
    let err = |source: std::io::Error| ZarrError::Create {
        path: path.into(),
        source,
    };
    let text = serde_json::to_string_pretty(&spec.metadata()).expect("JSON values serialize");
    let mut tmp = temp_in(path, ".zarr.json.").map_err(err)?;
    tmp.write_all(text.as_bytes()).map_err(err)?;
    tmp.write_all(b"\n").map_err(err)?;
    tmp.persist(path.join("zarr.json"))
        .map_err(|e| err(e.error))?;
    Ok(())
}

/// Whether the folder `path` has no entries.
fn is_empty_dir(path: &Path) -> Result<bool, ZarrError> {
    let mut entries = std::fs::read_dir(path).map_err(|source| ZarrError::Read {
        path: path.into(),
        source,
    })?;
    Ok(entries.next().is_none())
}

/// Removes an existing Zarr array (a folder with `zarr.json`) or an empty folder for
/// `--force`; refuses files and other folders.
fn remove_array(path: &Path) -> Result<(), ZarrError> {
    let refuse = |reason: &str| ZarrError::NotReplaceable {
        path: path.into(),
        reason: reason.into(),
    };
    if !path.is_dir()
        || path
            .symlink_metadata()
            .is_ok_and(|m| m.file_type().is_symlink())
    {
        return Err(refuse("exists and is not a folder"));
    }
    if !is_empty_dir(path)? && !path.join("zarr.json").is_file() {
        return Err(refuse("is a folder without zarr.json, not a Zarr array"));
    }
    std::fs::remove_dir_all(path).map_err(|source| ZarrError::Create {
        path: path.into(),
        source,
    })
}
