//! Pixel rectangles of the full image, and assembling crops into the whole.
//!
//! A crop must give exactly the pixels of the same rectangle of the whole render. The
//! tile cone march depends on the tile grid (`render::cone`), so the image loop traces
//! the full image's tiles that overlap the crop (grown by one pixel in adaptive mode,
//! whose decisions look at neighbours) and keeps the crop's pixels; the sample pattern
//! is the same for every pixel. Crops are written as PNG with their place in the whole
//! in a `tEXt` chunk ([`CROP_KEY`]), which [`stitch`] reads back.

use std::path::{Path, PathBuf};

/// A rectangle of pixels `x0 .. x1`, `y0 .. y1` (ends exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Rect {
    /// The whole `width x height` image.
    pub fn full(width: u32, height: u32) -> Rect {
        Rect {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }

    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// Pixels in it.
    pub fn area(&self) -> usize {
        self.width() as usize * self.height() as usize
    }

    /// The row-major index of pixel `(x, y)` (full-image coordinates) within it.
    pub fn index(&self, x: u32, y: u32) -> Option<usize> {
        self.contains(x, y)
            .then(|| ((y - self.y0) * self.width() + (x - self.x0)) as usize)
    }

    /// Grown by `by` pixels on every side, within a `width x height` image.
    pub fn grown(&self, by: u32, width: u32, height: u32) -> Rect {
        Rect {
            x0: self.x0.saturating_sub(by),
            y0: self.y0.saturating_sub(by),
            x1: (self.x1 + by).min(width),
            y1: (self.y1 + by).min(height),
        }
    }

    /// Whether it shares a pixel with `other`.
    pub fn overlaps(&self, other: &Rect) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }

    /// Parses `X0,Y0,X1,Y1` (the `--crop` flag) and checks it lies in a `width x
    /// height` image and is not empty.
    pub fn parse(text: &str, width: u32, height: u32) -> Result<Rect, String> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let nums: Option<Vec<u32>> = parts.iter().map(|p| p.parse().ok()).collect();
        let Some([x0, y0, x1, y1]) = nums.and_then(|n| <[u32; 4]>::try_from(n).ok()) else {
            return Err(format!(
                "expected X0,Y0,X1,Y1: four pixel coordinates >= 0, the ends exclusive (got \"{text}\")"
            ));
        };
        if x0 >= x1 || y0 >= y1 {
            return Err(format!(
                "the rectangle {text} is empty: need X0 < X1 and Y0 < Y1 (the ends are exclusive)"
            ));
        }
        if x1 > width || y1 > height {
            return Err(format!(
                "the rectangle {text} does not fit the {width}x{height} image (X1 <= {width}, Y1 <= {height})"
            ));
        }
        Ok(Rect { x0, y0, x1, y1 })
    }
}

impl std::fmt::Display for Rect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

/// The `tEXt` keyword of a crop's place: `X0,Y0,X1,Y1,WIDTH,HEIGHT`.
pub const CROP_KEY: &str = "smoothtrace-crop";

/// Encodes an 8-bit RGB (`channels = 3`) or straight-alpha RGBA (`channels = 4`) crop
/// of a `full_width x full_height` image as PNG, its place recorded for [`stitch`].
pub fn encode_crop_png(
    pixels: &[u8],
    channels: u8,
    rect: Rect,
    full: (u32, u32),
) -> Result<Vec<u8>, png::EncodingError> {
    let mut buf = Vec::new();
    let mut enc = png::Encoder::new(&mut buf, rect.width(), rect.height());
    enc.set_color(if channels == 4 {
        png::ColorType::Rgba
    } else {
        png::ColorType::Rgb
    });
    enc.set_depth(png::BitDepth::Eight);
    enc.add_text_chunk(
        CROP_KEY.to_string(),
        format!("{rect},{},{}", full.0, full.1),
    )?;
    let mut w = enc.write_header()?;
    w.write_image_data(pixels)?;
    w.finish()?;
    Ok(buf)
}

/// Why crops could not be assembled.
#[derive(Debug, thiserror::Error)]
pub enum StitchError {
    #[error("{path}: {message}")]
    Piece { path: PathBuf, message: String },
    #[error("no crops given: pass the PNG files written by `render --crop`")]
    Empty,
    #[error(
        "{missing} of the {width}x{height} pixels are in no crop (the first at x {x}, y {y}); render the missing rectangles too"
    )]
    Missing {
        missing: u64,
        width: u32,
        height: u32,
        x: u32,
        y: u32,
    },
}

/// One crop read back: its pixels (RGB or RGBA), its place and the full size.
struct Piece {
    path: PathBuf,
    channels: usize,
    rect: Rect,
    full: (u32, u32),
    pixels: Vec<u8>,
}

fn read_piece(path: &Path) -> Result<Piece, StitchError> {
    let fail = |message: String| StitchError::Piece {
        path: path.to_path_buf(),
        message,
    };
    let file = std::fs::File::open(path).map_err(|e| fail(format!("cannot open: {e}")))?;
    let mut dec = png::Decoder::new(std::io::BufReader::new(file));
    dec.set_transformations(png::Transformations::IDENTITY);
    let mut reader = dec
        .read_info()
        .map_err(|e| fail(format!("not a PNG image: {e}")))?;
    let place = reader
        .info()
        .uncompressed_latin1_text
        .iter()
        .find(|t| t.keyword == CROP_KEY)
        .map(|t| t.text.clone())
        .ok_or_else(|| {
            fail(format!(
                "no `{CROP_KEY}` text chunk: not a crop written by `smoothtrace render --crop`"
            ))
        })?;
    let nums: Vec<u32> = place
        .split(',')
        .map(|s| s.trim().parse())
        .collect::<Result<_, _>>()
        .map_err(|_| fail(format!("bad `{CROP_KEY}` value \"{place}\"")))?;
    let [x0, y0, x1, y1, w, h] = <[u32; 6]>::try_from(nums).map_err(|_| {
        fail(format!(
            "bad `{CROP_KEY}` value \"{place}\" (expected 6 numbers)"
        ))
    })?;
    let rect = Rect { x0, y0, x1, y1 };
    if x0 >= x1 || y0 >= y1 || x1 > w || y1 > h {
        return Err(fail(format!(
            "`{CROP_KEY}` {place}: the rectangle does not fit the image"
        )));
    }
    let (color, depth) = reader.output_color_type();
    let channels = match (color, depth) {
        (png::ColorType::Rgb, png::BitDepth::Eight) => 3,
        (png::ColorType::Rgba, png::BitDepth::Eight) => 4,
        other => return Err(fail(format!("expected 8-bit RGB or RGBA, got {other:?}"))),
    };
    let info = reader.info();
    if (info.width, info.height) != (rect.width(), rect.height()) {
        return Err(fail(format!(
            "the image is {}x{} but its `{CROP_KEY}` rectangle {rect} is {}x{}",
            info.width,
            info.height,
            rect.width(),
            rect.height()
        )));
    }
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| fail("image too large".to_string()))?;
    let mut pixels = vec![0; size];
    reader
        .next_frame(&mut pixels)
        .map_err(|e| fail(format!("cannot decode: {e}")))?;
    Ok(Piece {
        path: path.to_path_buf(),
        channels,
        rect,
        full: (w, h),
        pixels,
    })
}

/// Assembles crops written by `render --crop` into the full image: they must come from
/// images of one size and one kind (RGB or RGBA), must not overlap, and must cover it.
pub fn stitch(paths: &[PathBuf]) -> Result<image::DynamicImage, StitchError> {
    let pieces: Vec<Piece> = paths
        .iter()
        .map(|p| read_piece(p))
        .collect::<Result<_, _>>()?;
    let first = pieces.first().ok_or(StitchError::Empty)?;
    let (w, h) = first.full;
    let channels = first.channels;
    let mut out = vec![0u8; w as usize * h as usize * channels];
    let mut owner: Vec<Option<usize>> = vec![None; w as usize * h as usize];
    for (k, p) in pieces.iter().enumerate() {
        let fail = |message: String| StitchError::Piece {
            path: p.path.clone(),
            message,
        };
        if p.full != first.full {
            return Err(fail(format!(
                "is a crop of a {}x{} image, but {} is of a {w}x{h} one",
                p.full.0,
                p.full.1,
                first.path.display()
            )));
        }
        if p.channels != channels {
            return Err(fail(format!(
                "has {} channels, but {} has {channels} (mixing transparent and opaque crops)",
                p.channels,
                first.path.display()
            )));
        }
        for y in p.rect.y0..p.rect.y1 {
            for x in p.rect.x0..p.rect.x1 {
                let i = (y * w + x) as usize;
                if let Some(other) = owner[i] {
                    return Err(fail(format!(
                        "overlaps {} at x {x}, y {y}",
                        pieces[other].path.display()
                    )));
                }
                owner[i] = Some(k);
                let src = ((y - p.rect.y0) * p.rect.width() + (x - p.rect.x0)) as usize;
                out[i * channels..(i + 1) * channels]
                    .copy_from_slice(&p.pixels[src * channels..(src + 1) * channels]);
            }
        }
    }
    let missing = owner.iter().filter(|o| o.is_none()).count() as u64;
    if let Some(i) = owner.iter().position(|o| o.is_none()) {
        return Err(StitchError::Missing {
            missing,
            width: w,
            height: h,
            x: i as u32 % w,
            y: i as u32 / w,
        });
    }
    Ok(if channels == 4 {
        image::DynamicImage::ImageRgba8(image::RgbaImage::from_raw(w, h, out).expect("size"))
    } else {
        image::DynamicImage::ImageRgb8(image::RgbImage::from_raw(w, h, out).expect("size"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_checks_the_rectangle() {
        assert_eq!(
            Rect::parse("0, 16,32,48", 64, 48),
            Ok(Rect {
                x0: 0,
                y0: 16,
                x1: 32,
                y1: 48
            })
        );
        for (bad, want) in [
            ("1,2,3", "X0,Y0,X1,Y1"),
            ("a,0,1,1", "X0,Y0,X1,Y1"),
            ("-1,0,4,4", "X0,Y0,X1,Y1"),
            ("4,0,4,4", "empty"),
            ("0,5,4,4", "empty"),
            ("0,0,65,4", "does not fit the 64x48"),
            ("0,0,4,49", "does not fit"),
        ] {
            let e = Rect::parse(bad, 64, 48).unwrap_err();
            assert!(e.contains(want), "{bad}: {e}");
        }
    }

    #[test]
    fn grown_and_overlaps() {
        let r = Rect::parse("0,4,8,8", 10, 10).unwrap();
        assert_eq!(r.grown(1, 10, 10), Rect::parse("0,3,9,9", 10, 10).unwrap());
        assert!(r.overlaps(&Rect::parse("7,7,9,9", 10, 10).unwrap()));
        assert!(!r.overlaps(&Rect::parse("8,0,9,9", 10, 10).unwrap()));
        assert!(r.contains(7, 7) && !r.contains(8, 7) && !r.contains(0, 3));
        assert_eq!(
            (r.area(), r.index(0, 4), r.index(7, 7)),
            (32, Some(0), Some(31))
        );
        assert_eq!(r.index(8, 4), None);
    }
}
