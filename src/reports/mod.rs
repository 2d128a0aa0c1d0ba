//! The three reports: [`bench`] (Table 1 of the paper on this machine), [`sweep`]
//! (render time against isosurface error over the Barnes-Hut parameter beta, and the
//! Thingi10K-style grid of queries) and [`stability`] (a fixed suite of hard inputs for
//! the stable and the naive evaluators). They sit beside the renderer and call the same
//! library (`render::build`, `render::Tracer`, `render::image::render`, `eval`); they
//! return [`table::Table`]s, which the command line prints and writes as CSV and JSON,
//! and [`plot`] draws the sweep's PNGs. Columns and units: `doc/reports.md`.
//!
//! The library knows nothing of the terminal: long loops report through [`Progress`].

pub mod bench;
pub mod compare;
pub mod matrix;
pub mod plot;
pub mod stability;
pub mod sweep;
pub mod table;

use crate::camera::Camera;
use crate::matcap::MatCap;
use crate::render::image::{Rendered, render};
use crate::render::{TraceObject, Tracer, TracerOptions};

/// Progress of a long loop (a render's rows, a grid's slices), one bar at a time.
pub trait Progress: Sync {
    /// A new bar with this label and total.
    fn start(&self, label: &str, total: u64);
    /// Units done so far on the current bar.
    fn set(&self, done: u64);
    /// The current bar is done.
    fn finish(&self);
}

/// Reports nothing.
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _: &str, _: u64) {}
    fn set(&self, _: u64) {}
    fn finish(&self) {}
}

/// A rayon pool of `threads` workers (0 = all cores).
pub fn pool(threads: usize) -> Result<rayon::ThreadPool, rayon::ThreadPoolBuildError> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build()
}

/// Renders `objects` through `camera` with `options` in the current rayon pool, with a
/// progress bar over the rows.
pub fn render_objects(
    objects: &[TraceObject],
    options: TracerOptions,
    camera: &Camera,
    shaders: &[MatCap],
    background: [u8; 3],
    label: &str,
    progress: &dyn Progress,
) -> Rendered {
    let tracer = Tracer::new(objects, options);
    progress.start(label, camera.height() as u64);
    let r = render(&tracer, camera, shaders, background, &|n| progress.set(n));
    progress.finish();
    r
}

/// Peak resident memory of this process (VmHWM), MiB; `None` where /proc is missing.
pub fn peak_rss_mib() -> Option<f64> {
    proc_status_kib("VmHWM:").map(|k| k / 1024.0)
}

/// Current resident memory (VmRSS), MiB.
pub fn rss_mib() -> Option<f64> {
    proc_status_kib("VmRSS:").map(|k| k / 1024.0)
}

/// Resets the peak resident memory to the current one (Linux >= 4.0, `clear_refs` 5), so
/// the next [`peak_rss_mib`] is the peak since now. Returns whether it worked.
pub fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

fn proc_status_kib(key: &str) -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    s.lines()
        .find(|l| l.starts_with(key))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()
}

/// The `q`-quantile (0..=1, nearest rank) of `v`, which it sorts; `None` when empty.
pub fn quantile(v: &mut [f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_unstable_by(f64::total_cmp);
    let k = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    Some(v[k])
}

/// Parses a comma-separated list of numbers (`"0,0.25,0.5"`).
pub fn parse_list(text: &str) -> Result<Vec<f64>, String> {
    let v: Result<Vec<f64>, String> = text
        .split(',')
        .map(|s| {
            let s = s.trim();
            s.parse::<f64>()
                .map_err(|_| format!("'{s}' is not a number"))
        })
        .collect();
    let v = v?;
    if v.is_empty() {
        return Err("the list is empty".into());
    }
    Ok(v)
}
