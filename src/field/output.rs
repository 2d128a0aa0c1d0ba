//! Writing a field: `.npy` (f32, C order, shape `(NZ, NY, NX)`) and a PNG/JPEG/WebP
//! montage of a few z slices with a colour map and isolines.

use super::error::FieldError;
use super::volume::DistanceField;
use crate::output::{IMAGE_8BIT, Kind, Output, OutputError};
use image::{Rgb, RgbImage};
use std::io::Write;
use std::path::Path;

/// The header of a NumPy `.npy` file (format version 1.0) of little-endian f32 in C
/// order with this `shape`: the magic string `\x93NUMPY`, the version `1 0`, the header's
/// length as a little-endian u16, and a Python dict literal naming the dtype, order and
/// shape, padded with spaces and ended by a newline so that the data starts at a
/// multiple of 64 bytes (NumPy's own alignment; the format asks for 16 at least).
fn npy_header_f4(shape: &[usize]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    // A one-dimensional shape is written `(n,)`, as Python spells a 1-tuple.
    let tuple = match dims.as_slice() {
        [one] => format!("({one},)"),
        _ => format!("({})", dims.join(", ")),
    };
    let mut dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {tuple}, }}");
    let unpadded = 10 + dict.len() + 1;
    dict.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    dict.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out
}

/// Number of slices in the preview montage (fewer if the grid has fewer).
pub const PREVIEW_SLICES: usize = 5;

impl DistanceField {
    /// Writes the values as a NumPy `.npy` array of `<f4`, shape `(NZ, NY, NX)`, C order
    /// (`+inf` outside the band), through a temporary file renamed on success
    /// ([`crate::output`]).
    pub fn write_npy(&self, path: &Path) -> Result<(), FieldError> {
        let out = Output::check(path, &[Kind::Npy], "a distance field")?;
        let io = |source: std::io::Error| OutputError::Write {
            path: path.to_path_buf(),
            source,
        };
        let [nz, ny, nx] = self.grid.shape();
        out.write_with(|file| {
            file.write_all(&npy_header_f4(&[nz, ny, nx])).map_err(io)?;
            for chunk in self.values.chunks(1 << 16) {
                let bytes: Vec<u8> = chunk.iter().flat_map(|v| v.to_le_bytes()).collect();
                file.write_all(&bytes).map_err(io)?;
            }
            Ok::<(), FieldError>(())
        })
    }

    /// Renders up to [`PREVIEW_SLICES`] evenly spaced z slices side by side (x to the
    /// right, y up), coloured by distance (viridis-like from 0 to the largest finite
    /// value, red shades below 0 for smooth fields, grey outside the band), with
    /// isolines at a round spacing (the zero isoline in white).
    pub fn preview_image(&self) -> RgbImage {
        let [nx, ny, nz] = self.grid.res;
        let m = PREVIEW_SLICES.min(nz);
        let longest = nx.max(ny) as f64;
        let scale = longest.clamp(192.0, 512.0) / longest;
        let pw = ((nx as f64 * scale).round() as usize).max(1);
        let ph = ((ny as f64 * scale).round() as usize).max(1);
        let gap = 4;
        let width = m * pw + (m + 1) * gap;
        let height = ph + 2 * gap;
        let mut img = RgbImage::from_pixel(width as u32, height as u32, Rgb([30, 30, 30]));
        let vmax = self.max_finite().max(f32::MIN_POSITIVE) as f64;
        let vmin = self
            .values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f32, f32::min) as f64;
        let step = nice_step(vmax / 8.0);
        let mut vals = vec![0.0f64; pw * ph];
        for p in 0..m {
            let k = (((p as f64 + 0.5) * nz as f64 / m as f64) - 0.5)
                .round()
                .clamp(0.0, (nz - 1) as f64) as usize;
            let slice = self.slice(k);
            for py in 0..ph {
                // Image rows go down, y goes up.
                let v = ((ph - 1 - py) as f64 + 0.5) / scale - 0.5;
                for px in 0..pw {
                    let u = (px as f64 + 0.5) / scale - 0.5;
                    vals[py * pw + px] = bilinear(slice, nx, ny, u, v);
                }
            }
            let x0 = gap + p * (pw + gap);
            for py in 0..ph {
                for px in 0..pw {
                    let d = vals[py * pw + px];
                    let mut c = colour(d, vmin, vmax);
                    let level = |d: f64| {
                        if d.is_finite() {
                            (d / step).floor()
                        } else {
                            f64::INFINITY
                        }
                    };
                    let here = level(d);
                    let right = if px + 1 < pw {
                        level(vals[py * pw + px + 1])
                    } else {
                        here
                    };
                    let down = if py + 1 < ph {
                        level(vals[(py + 1) * pw + px])
                    } else {
                        here
                    };
                    if here.is_finite() && (here != right || here != down) {
                        let zero = (here == -1.0 && (right == 0.0 || down == 0.0))
                            || (here == 0.0 && (right == -1.0 || down == -1.0));
                        c = if zero {
                            [255, 255, 255]
                        } else {
                            c.map(|x| (x as f32 * 0.35) as u8)
                        };
                    }
                    img.put_pixel((x0 + px) as u32, (gap + py) as u32, Rgb(c));
                }
            }
        }
        img
    }

    /// Writes [`Self::preview_image`] as PNG, JPEG or WebP (by the extension), through
    /// a temporary file renamed on success.
    pub fn write_preview(&self, path: &Path) -> Result<(), FieldError> {
        let out = Output::check(path, IMAGE_8BIT, "the preview")?;
        out.write_image(&image::DynamicImage::ImageRgb8(self.preview_image()))?;
        Ok(())
    }
}

/// Bilinear interpolation in one slice at continuous pixel coordinates, clamped;
/// `+inf` if a corner with weight is outside the band.
fn bilinear(s: &[f32], nx: usize, ny: usize, u: f64, v: f64) -> f64 {
    let u = u.clamp(0.0, (nx - 1) as f64);
    let v = v.clamp(0.0, (ny - 1) as f64);
    let i0 = (u.floor() as usize).min(nx.saturating_sub(2));
    let j0 = (v.floor() as usize).min(ny.saturating_sub(2));
    let (i1, j1) = ((i0 + 1).min(nx - 1), (j0 + 1).min(ny - 1));
    let (tu, tv) = (
        (u - i0 as f64).clamp(0.0, 1.0),
        (v - j0 as f64).clamp(0.0, 1.0),
    );
    let mut sum = 0.0;
    for (i, wu) in [(i0, 1.0 - tu), (i1, tu)] {
        for (j, wv) in [(j0, 1.0 - tv), (j1, tv)] {
            let w = wu * wv;
            if w <= 1e-12 {
                continue;
            }
            let x = s[j * nx + i] as f64;
            if x.is_infinite() {
                return f64::INFINITY;
            }
            sum += w * x;
        }
    }
    sum
}

/// 1, 2 or 5 times a power of ten, at least `x`.
fn nice_step(x: f64) -> f64 {
    if !(x > 0.0) || !x.is_finite() {
        return 1.0;
    }
    let p = 10f64.powf(x.log10().floor());
    for m in [1.0, 2.0, 5.0, 10.0] {
        if m * p >= x {
            return m * p;
        }
    }
    10.0 * p
}

/// Viridis-like ramp on [0, vmax]; red shades for negative values; grey for `+inf`.
fn colour(d: f64, vmin: f64, vmax: f64) -> [u8; 3] {
    const RAMP: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    if !d.is_finite() {
        return [90, 90, 90];
    }
    if d < 0.0 {
        let t = if vmin < 0.0 {
            (d / vmin).clamp(0.0, 1.0)
        } else {
            1.0
        };
        return [
            (250.0 - 110.0 * t) as u8,
            (190.0 * (1.0 - t)) as u8,
            (190.0 * (1.0 - t)) as u8,
        ];
    }
    let t = (d / vmax).clamp(0.0, 1.0) * (RAMP.len() - 1) as f64;
    let i = (t.floor() as usize).min(RAMP.len() - 2);
    let f = t - i as f64;
    let c = |a: usize| (RAMP[i][a] + f * (RAMP[i + 1][a] - RAMP[i][a])).round() as u8;
    [c(0), c(1), c(2)]
}

#[cfg(test)]
mod tests {
    use super::{nice_step, npy_header_f4};

    #[test]
    fn npy_header_is_numpys_version_1_layout() {
        let h = npy_header_f4(&[7, 6, 5]);
        assert_eq!(&h[..8], b"\x93NUMPY\x01\x00");
        let len = u16::from_le_bytes([h[8], h[9]]) as usize;
        assert_eq!(h.len(), 10 + len);
        assert_eq!(h.len() % 64, 0, "data must start 64-byte aligned");
        let dict = std::str::from_utf8(&h[10..]).unwrap();
        assert!(dict.ends_with('\n'));
        assert_eq!(
            dict.trim_end(),
            "{'descr': '<f4', 'fortran_order': False, 'shape': (7, 6, 5), }"
        );
        let one = npy_header_f4(&[5]);
        assert!(
            std::str::from_utf8(&one[10..])
                .unwrap()
                .contains("'shape': (5,)")
        );
    }

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(0.13), 0.2);
        assert_eq!(nice_step(3.0), 5.0);
        assert!((nice_step(0.01) - 0.01).abs() < 1e-15);
    }
}
