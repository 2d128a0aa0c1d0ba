//! Depth error of renders against a reference render of the same rays:
//! `cargo run --release --example depth_error -- REF DIAG FILE...`
//!
//! Each depth is either an EXR of `smoothtrace render --depth` (the hit's ray parameter,
//! `+inf` for misses) or the raw depth of the published renderer's harness (`.bin`:
//! float32, row-major from the image's top row, `+inf` for misses), whose size is taken
//! from the first EXR among the arguments or from `--size WxH` before them. For each FILE
//! it prints, relative to `DIAG` (the scene's diagonal), the median and 99th percentile
//! of `|t - t_ref|` over rays that hit in both, the signed median of `t - t_ref` (below
//! zero: in front of the reference), and the pixels whose hit or miss differs from the
//! reference's (`reports::compare::compare_depths`, whose tests hold the counts). The
//! measurement of doc/measurements.md, "At equal error".
use smoothtrace::reports::compare::compare_depths;
use smoothtrace::reports::quantile;
use std::path::Path;

/// A depth image: width, height and the depths row by row.
struct Depth {
    width: usize,
    height: usize,
    t: Vec<f32>,
}

fn read_exr(path: &str) -> Result<Depth, String> {
    let image = image::open(Path::new(path)).map_err(|e| format!("{path}: {e}"))?;
    let rgb = image.to_rgb32f();
    Ok(Depth {
        width: rgb.width() as usize,
        height: rgb.height() as usize,
        t: rgb.pixels().map(|p| p.0[0]).collect(),
    })
}

fn read_bin(path: &str, (width, height): (usize, usize)) -> Result<Depth, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    if bytes.len() != width * height * 4 {
        return Err(format!(
            "{path}: {} bytes, expected {width} x {height} float32 values ({} bytes); give --size WxH",
            bytes.len(),
            width * height * 4
        ));
    }
    let t = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    Ok(Depth { width, height, t })
}

fn run(args: &[String]) -> Result<(), String> {
    let usage = "usage: depth_error [--size WxH] REF DIAG FILE...";
    let mut args = args.to_vec();
    let mut size: Option<(usize, usize)> = None;
    if args.first().map(String::as_str) == Some("--size") {
        let text = args.get(1).ok_or(usage)?.clone();
        let (w, h) = text
            .split_once('x')
            .ok_or("--size: expected WxH, e.g. 480x270")?;
        let parse = |v: &str| {
            v.parse::<usize>()
                .map_err(|_| format!("--size: bad number {v}"))
        };
        size = Some((parse(w)?, parse(h)?));
        args.drain(..2);
    }
    if args.len() < 3 {
        return Err(usage.into());
    }
    let diag: f64 = args[1]
        .parse()
        .ok()
        .filter(|d: &f64| *d > 0.0 && d.is_finite())
        .ok_or_else(|| format!("DIAG: expected a positive number, got {}", args[1]))?;
    let is_exr = |p: &str| p.to_ascii_lowercase().ends_with(".exr");
    // The EXR read for the size is kept for its own turn below.
    let mut probed = None;
    if size.is_none()
        && let Some(p) = args.iter().find(|p| is_exr(p))
    {
        let d = read_exr(p)?;
        size = Some((d.width, d.height));
        probed = Some((p.clone(), d));
    }
    let probed = std::cell::RefCell::new(probed);
    let read = |p: &str| match (is_exr(p), size) {
        (true, _) if probed.borrow().as_ref().is_some_and(|(q, _)| q == p) => {
            Ok(probed.borrow_mut().take().expect("checked above").1)
        }
        (true, _) => read_exr(p),
        (false, Some(s)) => read_bin(p, s),
        (false, None) => Err(format!(
            "{p}: raw depth needs --size WxH or an EXR argument"
        )),
    };
    let reference = read(&args[0])?;
    println!("reference {}: {} hits", args[0], hits(&reference));
    for path in &args[2..] {
        let d = read(path)?;
        if (d.width, d.height) != (reference.width, reference.height) {
            return Err(format!(
                "{path}: {}x{}, the reference is {}x{}",
                d.width, d.height, reference.width, reference.height
            ));
        }
        let diff = compare_depths(&d.t, &reference.t, 1.0, diag);
        // Signed: below zero where the render stands in front of the reference.
        let mut signed: Vec<f64> = (d.t.iter().zip(&reference.t))
            .filter(|(a, r)| a.is_finite() && r.is_finite())
            .map(|(&a, &r)| (f64::from(a) - f64::from(r)) / diag)
            .collect();
        let sci = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2e}"));
        println!(
            "{path}: {} hits, {} in both, hit or miss differs at {}; |t - t_ref| / diag median {} p99 {}, signed median {}",
            hits(&d),
            diff.both,
            diff.only_one,
            sci(diff.p50),
            sci(diff.p99),
            sci(quantile(&mut signed, 0.5)),
        );
    }
    Ok(())
}

fn hits(d: &Depth) -> usize {
    d.t.iter().filter(|t| t.is_finite()).count()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Err(e) = run(&args) {
        eprintln!("depth_error: {e}");
        std::process::exit(2);
    }
}
