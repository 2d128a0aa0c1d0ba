//! Arbitrary output variables: per-pixel records of the primary sample (the one nearest
//! the pixel centre, [`super::pattern::primary`]) and of the pixel's work, and the image
//! each AOV is written as.
//!
//! - `depth`: EXR, the hit's ray parameter in all three channels, `+inf` for misses
//!   (`--depth` is its alias).
//! - `normal`: PNG RGBA, the world-space unit normal as `0.5 + 0.5 n`, alpha 0 for misses.
//! - `id`: PNG with a palette (colour type 3): index 0 for misses, `k + 1` for object
//!   `k`, so the file holds the object index itself and shows as distinct colours.
//! - `position`: EXR RGBA, the hit point in world coordinates, alpha 1 (0 and zeros for
//!   misses).
//! - `cost`: a heat map of the smooth-distance evaluations each pixel's rays made (fine
//!   and bound steps, all its samples; the tile cone marches, shared by 256 pixels,
//!   are left out), with a colour bar and its scale ([`super::heatmap`]).

use glam::DVec3;

/// An AOV name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AovKind {
    Depth,
    Normal,
    Id,
    Position,
    Cost,
}

impl AovKind {
    pub const ALL: [AovKind; 5] = [
        AovKind::Depth,
        AovKind::Normal,
        AovKind::Id,
        AovKind::Position,
        AovKind::Cost,
    ];

    pub fn name(self) -> &'static str {
        match self {
            AovKind::Depth => "depth",
            AovKind::Normal => "normal",
            AovKind::Id => "id",
            AovKind::Position => "position",
            AovKind::Cost => "cost",
        }
    }

    pub fn from_name(name: &str) -> Option<AovKind> {
        AovKind::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The file formats it can be written as.
    pub fn formats(self) -> &'static [crate::output::Kind] {
        use crate::output::Kind;
        match self {
            AovKind::Depth | AovKind::Position => &[Kind::Exr],
            AovKind::Normal | AovKind::Id => &[Kind::Png],
            AovKind::Cost => crate::output::IMAGE_8BIT,
        }
    }

    /// Parses `name=path` (the `--aov` flag).
    pub fn parse_request(text: &str) -> Result<(AovKind, std::path::PathBuf), String> {
        let names = AovKind::ALL.map(|k| k.name()).join(", ");
        let Some((name, path)) = text.split_once('=') else {
            return Err(format!(
                "expected NAME=PATH with NAME one of {names} (got \"{text}\")"
            ));
        };
        let kind = AovKind::from_name(name.trim())
            .ok_or_else(|| format!("unknown AOV \"{}\" (expected one of {names})", name.trim()))?;
        if path.is_empty() {
            return Err(format!("{name}= needs a file path"));
        }
        Ok((kind, path.into()))
    }
}

/// "No object": the record of a pixel whose primary sample missed.
pub const NO_OBJECT: u32 = u32::MAX;

/// What the AOVs need of one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelRecord {
    /// Ray parameter of the primary sample's hit (`+inf`: miss).
    pub t: f32,
    pub normal: [f32; 3],
    pub position: [f32; 3],
    /// Index of the object hit, [`NO_OBJECT`] for a miss.
    pub object: u32,
    /// Evaluations (fine and bound) of all the pixel's rays.
    pub cost: u32,
}

impl Default for PixelRecord {
    fn default() -> Self {
        PixelRecord {
            t: f32::INFINITY,
            normal: [0.0; 3],
            position: [0.0; 3],
            object: NO_OBJECT,
            cost: 0,
        }
    }
}

impl PixelRecord {
    /// Records a hit's geometry.
    pub fn set_hit(&mut self, t: f64, normal: DVec3, point: DVec3, object: usize) {
        self.t = t as f32;
        self.normal = normal.as_vec3().to_array();
        self.position = point.as_vec3().to_array();
        self.object = u32::try_from(object).unwrap_or(NO_OBJECT - 1);
    }

    pub fn is_hit(&self) -> bool {
        self.object != NO_OBJECT
    }
}

/// Per-pixel records of an image (or crop), row-major.
#[derive(Clone, Debug)]
pub struct AovBuffers {
    pub width: u32,
    pub height: u32,
    pub records: Vec<PixelRecord>,
}

/// Object colours of the `id` palette (index 0, misses, is black). Tableau 10, then
/// repeated: ids stay exact in the file whatever the colours.
const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// Most objects an `id` PNG can tell apart (index 0 is the background).
pub const MAX_ID_OBJECTS: usize = 255;

impl AovBuffers {
    /// Depth: RGB f32, all channels equal, `+inf` for misses.
    pub fn depth(&self) -> image::DynamicImage {
        let data = self.records.iter().flat_map(|r| [r.t; 3]).collect();
        image::DynamicImage::ImageRgb32F(
            image::Rgb32FImage::from_raw(self.width, self.height, data).expect("size"),
        )
    }

    /// Normals as `0.5 + 0.5 n`, alpha 0 for misses.
    pub fn normal(&self) -> image::DynamicImage {
        let data = self
            .records
            .iter()
            .flat_map(|r| {
                let c = r
                    .normal
                    .map(|v| (255.0 * (0.5 + 0.5 * v)).round().clamp(0.0, 255.0) as u8);
                [c[0], c[1], c[2], if r.is_hit() { 255 } else { 0 }]
            })
            .collect();
        image::DynamicImage::ImageRgba8(
            image::RgbaImage::from_raw(self.width, self.height, data).expect("size"),
        )
    }

    /// World positions, alpha 1 for hits and 0 (with zeros) for misses.
    pub fn position(&self) -> image::DynamicImage {
        let data = self
            .records
            .iter()
            .flat_map(|r| {
                let p = r.position;
                [p[0], p[1], p[2], if r.is_hit() { 1.0 } else { 0.0 }]
            })
            .collect();
        image::DynamicImage::ImageRgba32F(
            image::Rgba32FImage::from_raw(self.width, self.height, data).expect("size"),
        )
    }

    /// The object index image as a palette PNG (index 0 = miss, `k + 1` = object `k`).
    /// Errors when the scene has more objects than a palette holds.
    pub fn id_png(&self, objects: usize) -> Result<Vec<u8>, String> {
        if objects > MAX_ID_OBJECTS {
            return Err(format!(
                "the id AOV is a palette PNG of at most {MAX_ID_OBJECTS} objects; the scene has {objects}"
            ));
        }
        let mut palette = vec![0u8; 3];
        for k in 0..objects {
            palette.extend_from_slice(&PALETTE[k % PALETTE.len()]);
        }
        let data: Vec<u8> = self
            .records
            .iter()
            .map(|r| if r.is_hit() { (r.object + 1) as u8 } else { 0 })
            .collect();
        let mut buf = Vec::new();
        let mut enc = png::Encoder::new(&mut buf, self.width, self.height);
        enc.set_color(png::ColorType::Indexed);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_palette(palette);
        let mut w = enc.write_header().map_err(|e| e.to_string())?;
        w.write_image_data(&data).map_err(|e| e.to_string())?;
        w.finish().map_err(|e| e.to_string())?;
        Ok(buf)
    }

    /// Evaluations per pixel, row-major.
    pub fn costs(&self) -> Vec<u32> {
        self.records.iter().map(|r| r.cost).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_parse_and_bad_names_are_named() {
        let (k, p) = AovKind::parse_request("normal=out/n.png").unwrap();
        assert_eq!((k, p.to_str().unwrap()), (AovKind::Normal, "out/n.png"));
        let e = AovKind::parse_request("albedo=a.png").unwrap_err();
        assert!(
            e.contains("unknown AOV \"albedo\"") && e.contains("cost"),
            "{e}"
        );
        assert!(
            AovKind::parse_request("depth")
                .unwrap_err()
                .contains("NAME=PATH")
        );
        assert!(
            AovKind::parse_request("depth=")
                .unwrap_err()
                .contains("path")
        );
    }

    #[test]
    fn id_png_holds_the_object_index() {
        let mut hit = PixelRecord::default();
        hit.set_hit(1.0, DVec3::Z, DVec3::ONE, 2);
        let b = AovBuffers {
            width: 2,
            height: 1,
            records: vec![PixelRecord::default(), hit],
        };
        let png = b.id_png(3).unwrap();
        let mut dec = png::Decoder::new(std::io::Cursor::new(png));
        dec.set_transformations(png::Transformations::IDENTITY);
        let mut r = dec.read_info().unwrap();
        assert_eq!(r.info().color_type, png::ColorType::Indexed);
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        r.next_frame(&mut buf).unwrap();
        assert_eq!(&buf[..2], &[0, 3]);
        assert!(b.id_png(300).unwrap_err().contains("at most 255"));
    }

    #[test]
    fn normal_png_maps_minus_one_to_zero_and_misses_to_alpha_zero() {
        let mut hit = PixelRecord::default();
        hit.set_hit(1.0, DVec3::new(-1.0, 0.0, 1.0), DVec3::ZERO, 0);
        let b = AovBuffers {
            width: 2,
            height: 1,
            records: vec![hit, PixelRecord::default()],
        };
        let img = b.normal().to_rgba8();
        assert_eq!(img.get_pixel(0, 0).0, [0, 128, 255, 255]);
        assert_eq!(img.get_pixel(1, 0).0[3], 0);
    }
}
