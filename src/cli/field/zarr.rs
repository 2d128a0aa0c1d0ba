//! `smoothtrace field ... -o OUT.zarr`: the field as a chunked Zarr v3 array, computed
//! and written chunk by chunk (`field::zarr`), all of it, some chunks (`--chunks I:J`,
//! one job of a job array) or the missing ones (`--resume`).

use super::FieldArgs;
use crate::cli::console::note;
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use smoothtrace::field::sign::SignedPlan;
use smoothtrace::field::zarr::{
    self as zarr_io, Codec, ZarrArray, ZarrSpec, index_ranges, parse_chunks, write_chunks,
};
use smoothtrace::field::{
    FieldOptions, FieldPlan, FieldSource, Grid, Method, human_bytes, setup_bytes,
};
use smoothtrace::mesh::Mesh;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// Default chunk edge: 8 MiB chunks of f32, a common size for Zarr volumes.
const DEFAULT_CHUNK: usize = 128;

/// Set by Ctrl-C: stop after the chunk being computed (a second Ctrl-C exits at once).
static STOP: AtomicBool = AtomicBool::new(false);

pub fn is_zarr(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("zarr"))
}

/// Flags that make no sense with a `.zarr` output.
pub fn check_flags(a: &FieldArgs) -> Result<()> {
    if a.preview.is_some() {
        bail!(
            "--preview draws slices of a field held in memory; it applies to .npy outputs (read slices of the .zarr array instead)"
        );
    }
    if a.resume && a.force {
        bail!("--resume keeps the existing array and --force replaces it; give one of them");
    }
    Ok(())
}

/// The `.zarr`-only flags are refused for `.npy` outputs.
pub fn refuse_flags(a: &FieldArgs) -> Result<()> {
    for (given, flag) in [
        (a.chunk.is_some(), "--chunk"),
        (a.chunks.is_some(), "--chunks"),
        (a.resume, "--resume"),
        (a.force, "--force"),
        (a.gzip, "--gzip"),
    ] {
        if given {
            bail!(
                "{flag} applies to chunked outputs: give -o OUT.zarr (got {})",
                a.output.display()
            );
        }
    }
    Ok(())
}

/// The chunk shape `(z, y, x)` for `--chunk` on `grid`.
fn chunk_shape(chunk: Option<usize>, grid: &Grid) -> Result<[usize; 3]> {
    let [nz, ny, nx] = grid.shape();
    let longest = nx.max(ny).max(nz);
    let n = match chunk {
        Some(0) => bail!("--chunk must be at least 1 voxel (got 0)"),
        Some(n) if n > longest => bail!(
            "--chunk {n} is larger than the volume ({nx} x {ny} x {nz} voxels); give at most {longest}"
        ),
        Some(n) => n,
        None => DEFAULT_CHUNK.min(longest),
    };
    Ok([n.min(nz), n.min(ny), n.min(nx)])
}

/// What the array's attributes record about the field, so that runs writing into one
/// array must agree.
fn field_attributes(
    a: &FieldArgs,
    mesh: &Mesh,
    method: Method,
    options: &FieldOptions,
) -> serde_json::Value {
    let smooth = match method {
        Method::Smooth {
            alpha,
            max_alpha,
            beta,
        } => json!({"alpha": alpha, "max_alpha": max_alpha, "beta": beta}),
        _ => serde_json::Value::Null,
    };
    let kind = match method {
        Method::Smooth { .. } => "smooth distance",
        _ if a.signed => "signed distance",
        _ => "unsigned distance",
    };
    json!({
        "kind": kind,
        "winding_beta": if a.signed { json!(a.winding_beta) } else { serde_json::Value::Null },
        "method": method.name(),
        "primitive": a.primitive.to_string(),
        "band": options.band,
        "smooth": smooth,
        "mesh": a.mesh.file_name().map(|n| n.to_string_lossy().into_owned()),
        "mesh_vertices": mesh.vertices.len(),
        "mesh_segments": mesh.segments.len(),
        "mesh_triangles": mesh.triangles.len(),
    })
}

pub fn run(
    a: &FieldArgs,
    mesh: &Mesh,
    grid: &Grid,
    method: Method,
    options: &FieldOptions,
) -> Result<()> {
    let chunk = chunk_shape(a.chunk, grid)?;
    let spec = ZarrSpec {
        shape: grid.shape(),
        chunk,
        codec: if a.gzip { Codec::Gzip(1) } else { Codec::Raw },
        attributes: zarr_io::grid_attributes(grid, field_attributes(a, mesh, method, options)),
    };
    let total = spec.chunk_count();
    // The memory of one strip of chunks along x, two chunks and the setup, not of the
    // volume.
    let [cz, cy, cx] = chunk;
    let strip = Grid::new(grid.min, grid.max, [grid.res[0], cy, cz])?;
    strip.check_memory(
        options.memory_limit,
        setup_bytes(mesh) + 8 * (cx * cy * cz) as u64,
    )?;
    // The target is created or checked before the work.
    let out = &a.output;
    let range = a
        .chunks
        .as_deref()
        .map(|t| parse_chunks(t, total).map_err(|e| anyhow::anyhow!("--chunks: {e}")))
        .transpose()?;
    let array = match (&range, a.resume) {
        (None, false) => ZarrArray::create(out, &spec, a.force)?,
        (None, true) => {
            if !out.exists() {
                bail!(
                    "{}: nothing to resume (it does not exist); run without --resume",
                    out.display()
                );
            }
            let array = ZarrArray::open(out)?;
            array.check_matches(&spec)?;
            array
        }
        (Some(_), _) if a.force => ZarrArray::create(out, &spec, true)?,
        (Some(_), _) => ZarrArray::open_or_create(out, &spec)?,
    };
    let mut todo: Vec<usize> = match &range {
        Some(r) => r.clone().collect(),
        None => (0..total).collect(),
    };
    if a.resume {
        let missing = array.missing();
        todo.retain(|i| missing.binary_search(i).is_ok());
    }
    let [gz, gy, gx] = spec.chunk_grid();
    note!(
        "  {}: {total} chunks of {cx} x {cy} x {cz} voxels ({gx} x {gy} x {gz}, {} each), {} to compute",
        out.display(),
        human_bytes(4 * (cx * cy * cz) as u64),
        todo.len()
    );
    if todo.is_empty() {
        return report(&array, total, false);
    }
    let plan = FieldPlan::new(mesh, a.primitive, grid, method, options)?;
    // Signed: the same distances, signed box by box from the winding numbers.
    let (source, setup): (Box<dyn FieldSource>, f64) = if a.signed {
        let s = SignedPlan::new(plan, mesh, a.winding_beta)?;
        let t = s.setup_seconds();
        (Box::new(s), t)
    } else {
        let t = plan.setup_seconds();
        (Box::new(plan), t)
    };
    note!("  setup {setup:.3} s");
    let _ = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        crate::cli::console::note_line(format_args!(
            "smoothtrace: stopping after the chunk being computed (Ctrl-C again to quit at once)"
        ));
    });
    let bar = ProgressBar::new(todo.len() as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} chunks, {elapsed} (eta {eta})")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(method.name());
    let run = write_chunks(source.as_ref(), &array, &todo, &STOP, &|n| {
        bar.set_position(n as u64)
    })
    .context("writing the chunks")?;
    bar.finish_and_clear();
    note!(
        "  {}: {} chunks, {} voxels in {:.3} s ({:.2} M voxels/s; computing {:.3} s)",
        method.name(),
        run.written,
        run.voxels,
        run.seconds,
        run.voxels as f64 / run.seconds.max(1e-12) * 1e-6,
        run.compute_seconds
    );
    report(&array, total, run.interrupted)
}

/// Says whether the array is complete, and which chunks are missing if not; an
/// interrupted run is an error (exit status 2).
fn report(array: &ZarrArray, total: usize, interrupted: bool) -> Result<()> {
    let missing = array.missing();
    let path = array.path().display();
    if missing.is_empty() {
        note!("  {path}: complete, all {total} chunks written");
        return Ok(());
    }
    let mut ranges = index_ranges(&missing);
    if let Some((cut, _)) = ranges.match_indices(' ').nth(9) {
        ranges.truncate(cut);
        ranges += " ...";
    }
    let message = format!(
        "{path} is partial: {} of {total} chunks missing (--chunks {ranges}); they read as NaN. Compute them with the same command and --resume",
        missing.len(),
    );
    if interrupted {
        bail!("interrupted; {message}");
    }
    note!("  {message}");
    Ok(())
}
