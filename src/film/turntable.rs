//! Turntables: cameras orbiting the scene's vertical axis, and the looping GIF.
//!
//! Frame `k` of `n` rotates the camera origin by `360 k / n` degrees about the line
//! through the look-at point along the camera's up vector (right-handed: counter-clockwise
//! seen from above); target, up and field of view stay. Frame 0 is the scene's camera.

use crate::camera::{Camera, CameraError};
use glam::{DQuat, DVec3};

/// The camera of frame `k` of an `n`-frame orbit of `base`.
pub fn orbit_camera(base: &Camera, k: u32, n: u32) -> Result<Camera, CameraError> {
    let angle = std::f64::consts::TAU * f64::from(k) / f64::from(n.max(1));
    let axis = base.up().normalize_or(DVec3::Y);
    let target = base.target();
    let origin = target + DQuat::from_axis_angle(axis, angle) * (base.origin() - target);
    Camera::new(
        origin,
        target,
        base.up(),
        base.fov_y_degrees(),
        base.width(),
        base.height(),
    )
}

/// Parses `A:B` (the `--frames` flag: frames `A .. B`, the end exclusive; either side may
/// be left out for the first or last frame) for an `n`-frame turntable.
pub fn parse_frames(text: &str, n: u32) -> Result<std::ops::Range<u32>, String> {
    let Some((a, b)) = text.split_once(':') else {
        return Err(format!(
            "expected A:B, the frames A to B-1 of the turntable (got \"{text}\")"
        ));
    };
    let num = |s: &str, default: u32| -> Result<u32, String> {
        if s.trim().is_empty() {
            Ok(default)
        } else {
            s.trim()
                .parse()
                .map_err(|_| format!("expected A:B with frame numbers >= 0 (got \"{text}\")"))
        }
    };
    let (a, b) = (num(a, 0)?, num(b, n)?);
    if a >= b || b > n {
        return Err(format!(
            "frames {a}:{b} are not a non-empty slice of the {n} frames 0:{n} (the end is exclusive)"
        ));
    }
    Ok(a..b)
}

/// The file name of frame `k`.
pub fn frame_name(k: u32) -> String {
    format!("frame_{k:04}.png")
}

/// Encodes `frames` as an endlessly looping GIF, `delay_ms` per frame.
pub fn encode_gif(frames: Vec<image::RgbaImage>, delay_ms: u32) -> image::ImageResult<Vec<u8>> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let mut buf = Vec::new();
    {
        // Speed 10 of 1..30: good palettes at a fraction of speed 1's time.
        let mut enc = GifEncoder::new_with_speed(&mut buf, 10);
        enc.set_repeat(Repeat::Infinite)?;
        enc.encode_frames(frames.into_iter().map(|f| {
            image::Frame::from_parts(f, 0, 0, image::Delay::from_numer_denom_ms(delay_ms, 1))
        }))?;
    }
    Ok(buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_keeps_distance_and_height_and_comes_round() {
        let base = Camera::new(
            DVec3::new(3.0, 2.0, 4.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::Y,
            40.0,
            8,
            8,
        )
        .unwrap();
        let r0 = base.origin() - base.target();
        for k in 0..8 {
            let c = orbit_camera(&base, k, 8).unwrap();
            let r = c.origin() - c.target();
            assert!((r.length() - r0.length()).abs() < 1e-12);
            assert!((r.y - r0.y).abs() < 1e-12, "height kept");
            assert_eq!(c.target(), base.target());
        }
        let quarter = orbit_camera(&base, 2, 8).unwrap().origin() - base.target();
        // A quarter turn about +y takes +z to +x (and +x to -z).
        assert!(
            (quarter - DVec3::new(4.0, 1.0, -2.0)).length() < 1e-12,
            "{quarter}"
        );
        assert_eq!(orbit_camera(&base, 0, 8).unwrap().origin(), base.origin());
    }

    #[test]
    fn frame_slices() {
        assert_eq!(parse_frames("0:24", 24), Ok(0..24));
        assert_eq!(parse_frames("5:", 24), Ok(5..24));
        assert_eq!(parse_frames(":3", 24), Ok(0..3));
        for bad in ["3", "4:4", "5:2", "0:25", "a:3", "-1:3"] {
            assert!(parse_frames(bad, 24).is_err(), "{bad}");
        }
        assert!(parse_frames("0:25", 24).unwrap_err().contains("24 frames"));
    }

    #[test]
    fn gif_loops_and_holds_every_frame() {
        use image::AnimationDecoder;
        let frames: Vec<_> = (0..3u8)
            .map(|k| image::RgbaImage::from_pixel(4, 4, image::Rgba([80 * k, 0, 0, 255])))
            .collect();
        let bytes = encode_gif(frames, 40).unwrap();
        assert!(
            bytes.windows(11).any(|w| w == b"NETSCAPE2.0"),
            "looping extension"
        );
        let dec = image::codecs::gif::GifDecoder::new(std::io::Cursor::new(bytes)).unwrap();
        let back: Vec<_> = dec.into_frames().collect::<Result<_, _>>().unwrap();
        assert_eq!(back.len(), 3);
        assert_eq!(back[2].buffer().get_pixel(1, 1).0[0], 160);
    }
}
