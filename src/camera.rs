//! Pinhole camera (SPEC 7): origin, target, up vector and vertical field of view.
//!
//! Rays go through pixel centres; image row 0 is the top row, column 0 the left one.
//! With `f = normalize(target - origin)`, `r = normalize(f x up)` and `u = r x f`, the ray
//! through pixel `(px, py)` of a `w x h` image has direction
//!
//! ```text
//! d = normalize(f + sx * tan(fov/2) * (w/h) * r + sy * tan(fov/2) * u),
//! sx = 2 (px + 0.5) / w - 1,   sy = 1 - 2 (py + 0.5) / h.
//! ```
//!
//! Camera space (used by MatCap shading, SPEC 8) has x along `r` (right), y along `u`
//! (up) and z along `-f` (towards the viewer); it is right-handed because `r x u = -f`.

use glam::DVec3;

/// Relative tolerance for "origin equals target": `|target - origin| <= this * max(|origin|, |target|)`.
const SAME_POINT_REL: f64 = 1e-12;

/// Smallest accepted sine of the angle between `up` and the view direction.
const PARALLEL_SIN: f64 = 1e-6;

/// The settings of a pinhole camera (a scene's `[camera]`, SPEC 7), before the image
/// size makes it a [`Camera`]. Scenes, auto-framing and the API all give one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSettings {
    pub origin: DVec3,
    pub target: DVec3,
    /// Default `[0, 1, 0]`.
    pub up: DVec3,
    /// Vertical field of view in degrees, in (0, 180). Default 53.13.
    pub fov: f64,
}

impl CameraSettings {
    /// A camera with the default up vector and field of view.
    pub fn looking_at(origin: DVec3, target: DVec3) -> CameraSettings {
        CameraSettings {
            origin,
            target,
            up: DVec3::Y,
            fov: Camera::DEFAULT_FOV_Y,
        }
    }

    /// The camera for an image of this size.
    pub fn build(&self, width: u32, height: u32) -> Result<Camera, CameraError> {
        Camera::new(self.origin, self.target, self.up, self.fov, width, height)
    }
}

/// Why a camera cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CameraError {
    #[error("camera {what} is not finite ({value:?})")]
    NonFinite { what: &'static str, value: [f64; 3] },
    #[error(
        "camera origin and target are the same point ({origin:?}); the view direction is undefined: move the target away from the origin"
    )]
    OriginIsTarget { origin: [f64; 3] },
    #[error(
        "camera up vector {up:?} is zero or parallel to the view direction {view:?}; choose an up vector across the view, e.g. [0, 1, 0] or [0, 0, 1]"
    )]
    UpParallel { up: [f64; 3], view: [f64; 3] },
    #[error("camera field of view must be in (0, 180) degrees (got {0})")]
    FieldOfView(f64),
    #[error("image size must be at least 1x1 pixel (got {width}x{height})")]
    EmptyImage { width: u32, height: u32 },
}

/// Checks the view parameters a [`Camera`] needs, without an image size: finite origin,
/// target and up; origin != target (relative test); up not parallel to the view (sine of
/// the angle at least 1e-6); fov in (0, 180) degrees. Scene validation reuses it.
pub fn check_view(
    origin: DVec3,
    target: DVec3,
    up: DVec3,
    fov_y_degrees: f64,
) -> Result<(), CameraError> {
    for (what, v) in [("origin", origin), ("target", target), ("up", up)] {
        if !v.is_finite() {
            return Err(CameraError::NonFinite {
                what,
                value: v.to_array(),
            });
        }
    }
    let view = target - origin;
    let scale = origin.length().max(target.length());
    // `<=` so that origin == target == 0 is caught too.
    if view.length() <= SAME_POINT_REL * scale {
        return Err(CameraError::OriginIsTarget {
            origin: origin.to_array(),
        });
    }
    let f = view.normalize();
    let parallel = match up.try_normalize() {
        Some(u) => f.cross(u).length() < PARALLEL_SIN,
        None => true,
    };
    if parallel {
        return Err(CameraError::UpParallel {
            up: up.to_array(),
            view: f.to_array(),
        });
    }
    if !(fov_y_degrees > 0.0 && fov_y_degrees < 180.0) {
        return Err(CameraError::FieldOfView(fov_y_degrees));
    }
    Ok(())
}

/// A pinhole camera with its image size. Build it with [`Camera::new`].
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    origin: DVec3,
    target: DVec3,
    up: DVec3,
    fov_y_degrees: f64,
    width: u32,
    height: u32,
    /// Unit view direction `f`.
    forward: DVec3,
    /// Unit right vector `r`.
    right: DVec3,
    /// Unit camera up `u` (orthogonal to `f` and `r`).
    up_cam: DVec3,
    /// `tan(fov/2)`: half the image plane height at distance 1.
    half_height: f64,
}

impl Camera {
    /// The paper's default vertical field of view, in degrees.
    pub const DEFAULT_FOV_Y: f64 = 53.13;

    /// Builds a camera at `origin` looking at `target`; `up` only needs to be roughly up
    /// (it is orthogonalised). `fov_y_degrees` is the vertical field of view.
    pub fn new(
        origin: DVec3,
        target: DVec3,
        up: DVec3,
        fov_y_degrees: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        check_view(origin, target, up, fov_y_degrees)?;
        if width == 0 || height == 0 {
            return Err(CameraError::EmptyImage { width, height });
        }
        let forward = (target - origin).normalize();
        let right = forward.cross(up).normalize();
        let up_cam = right.cross(forward);
        Ok(Camera {
            origin,
            target,
            up,
            fov_y_degrees,
            width,
            height,
            forward,
            right,
            up_cam,
            half_height: (0.5 * fov_y_degrees.to_radians()).tan(),
        })
    }

    /// The ray through the centre of pixel `(px, py)` (row 0 at the top): origin and unit
    /// direction. Pixels outside the image give rays outside the field of view; no panic.
    pub fn ray(&self, px: u32, py: u32) -> (DVec3, DVec3) {
        self.ray_through(f64::from(px) + 0.5, f64::from(py) + 0.5)
    }

    /// The ray through the image-plane position `(x, y)` in pixel units (`(0, 0)` is the
    /// top-left corner of the image, `(px + 0.5, py + 0.5)` the centre of pixel `(px, py)`):
    /// sub-pixel samples for anti-aliasing.
    pub fn ray_through(&self, x: f64, y: f64) -> (DVec3, DVec3) {
        let sx = 2.0 * x / f64::from(self.width) - 1.0;
        let sy = 1.0 - 2.0 * y / f64::from(self.height);
        let x = sx * self.half_height * self.aspect();
        let y = sy * self.half_height;
        let d = self.forward + x * self.right + y * self.up_cam;
        (self.origin, d.normalize())
    }

    /// Where the ray towards `p` crosses the image plane, in the pixel units of
    /// [`Camera::ray_through`] (its inverse), or `None` when `p` is not in front of the
    /// camera (on or behind the plane through the origin facing `forward`). Points
    /// outside the field of view give positions outside `[0, width] x [0, height]`.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let v = p - self.origin;
        let z = v.dot(self.forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        let sx = v.dot(self.right) / (z * self.half_height * self.aspect());
        let sy = v.dot(self.up_cam) / (z * self.half_height);
        Some((
            0.5 * (sx + 1.0) * f64::from(self.width),
            0.5 * (1.0 - sy) * f64::from(self.height),
        ))
    }

    /// A world-space vector in camera coordinates: x right, y up, z towards the viewer.
    pub fn to_camera_space(&self, n: DVec3) -> DVec3 {
        DVec3::new(n.dot(self.right), n.dot(self.up_cam), -n.dot(self.forward))
    }

    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    pub fn target(&self) -> DVec3 {
        self.target
    }

    /// The up vector as given (not orthogonalised); see [`Camera::camera_up`].
    pub fn up(&self) -> DVec3 {
        self.up
    }

    pub fn fov_y_degrees(&self) -> f64 {
        self.fov_y_degrees
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Width over height.
    pub fn aspect(&self) -> f64 {
        f64::from(self.width) / f64::from(self.height)
    }

    /// Unit view direction (origin towards target).
    pub fn forward(&self) -> DVec3 {
        self.forward
    }

    /// Unit right vector of the image plane.
    pub fn right(&self) -> DVec3 {
        self.right
    }

    /// Unit up vector of the image plane (orthogonal to [`Camera::forward`]).
    pub fn camera_up(&self) -> DVec3 {
        self.up_cam
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) {
        assert!(
            (a - b).abs() <= tol,
            "expected {b}, got {a} (tolerance {tol}, difference {})",
            (a - b).abs()
        );
    }

    fn cam(w: u32, h: u32) -> Camera {
        Camera::new(
            DVec3::new(1.0, 2.0, 5.0),
            DVec3::new(0.5, 0.0, -1.0),
            DVec3::Y,
            53.13,
            w,
            h,
        )
        .unwrap()
    }

    #[test]
    fn project_inverts_ray_through_and_rejects_points_behind() {
        let c = cam(64, 36);
        for &(x, y) in &[(0.0, 0.0), (32.0, 18.0), (63.5, 0.25), (-10.0, 50.0)] {
            let (o, d) = c.ray_through(x, y);
            for t in [0.1, 3.0, 40.0] {
                let (px, py) = c.project(o + t * d).expect("in front");
                close(px, x, 1e-9);
                close(py, y, 1e-9);
            }
        }
        assert_eq!(c.project(c.origin() - c.forward()), None);
        assert_eq!(c.project(c.origin()), None);
    }

    fn angle_deg(a: DVec3, b: DVec3) -> f64 {
        a.normalize()
            .dot(b.normalize())
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
    }

    #[test]
    fn centre_ray_of_odd_image_hits_target() {
        let c = cam(101, 51);
        let (o, d) = c.ray(50, 25);
        assert_eq!(o, c.origin());
        close(d.length(), 1.0, 1e-12);
        let to_target = (c.target() - o).normalize();
        close(d.dot(to_target), 1.0, 1e-12);
    }

    #[test]
    fn vertical_field_of_view_between_edge_rows() {
        // Rays through the top and bottom pixel centres span fov * (h-1)/h approximately;
        // the exact half angle at pixel centre row 0 is atan((1 - 1/h) tan(fov/2)).
        let h = 200;
        let c = cam(300, h);
        let (_, top) = c.ray(150, 0);
        let expected = ((1.0 - 1.0 / f64::from(h)) * (0.5 * 53.13f64.to_radians()).tan())
            .atan()
            .to_degrees();
        let axis = c.forward();
        // Column 150 of 300 is half a pixel right of centre; compare in the vertical plane.
        let top_v = top - top.dot(c.right()) * c.right();
        close(angle_deg(top_v, axis), expected, 1e-9);
        assert!(top.dot(c.camera_up()) > 0.0, "row 0 must be at the top");
    }

    #[test]
    fn corner_rays_make_the_right_angle_with_the_axis() {
        let (w, h) = (64, 48);
        let c = cam(w, h);
        let t = (0.5 * 53.13f64.to_radians()).tan();
        let sx = 1.0 - 1.0 / f64::from(w);
        let sy = 1.0 - 1.0 / f64::from(h);
        let expected = (((sx * t * c.aspect()).powi(2) + (sy * t).powi(2)).sqrt())
            .atan()
            .to_degrees();
        for (px, py) in [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)] {
            let (_, d) = c.ray(px, py);
            close(angle_deg(d, c.forward()), expected, 1e-9);
            let cs = c.to_camera_space(d);
            assert_eq!(cs.x > 0.0, px == w - 1, "pixel ({px},{py}) x side");
            assert_eq!(cs.y > 0.0, py == 0, "pixel ({px},{py}) y side");
        }
    }

    #[test]
    fn aspect_ratio_scales_horizontal_extent() {
        let c = cam(200, 100);
        close(c.aspect(), 2.0, 0.0);
        // Pixel centres on the middle row/column of a wide image: the horizontal tangent
        // at the left edge is aspect times the vertical one at the top edge.
        let c = cam(201, 101);
        let (_, left) = c.ray(0, 50);
        let (_, top) = c.ray(100, 0);
        let tl = c.to_camera_space(left);
        let tt = c.to_camera_space(top);
        let tan_h = -tl.x / -tl.z;
        let tan_v = tt.y / -tt.z;
        let expected = (1.0 - 1.0 / 201.0) / (1.0 - 1.0 / 101.0) * (201.0 / 101.0);
        close(tan_h / tan_v, expected, 1e-12);
    }

    #[test]
    fn camera_space_basis_is_right_handed() {
        let c = cam(10, 10);
        let x = c.to_camera_space(c.right());
        let y = c.to_camera_space(c.camera_up());
        let z = c.to_camera_space(-c.forward());
        close(x.distance(DVec3::X), 0.0, 1e-12);
        close(y.distance(DVec3::Y), 0.0, 1e-12);
        close(z.distance(DVec3::Z), 0.0, 1e-12);
        close(
            c.right().cross(c.camera_up()).distance(-c.forward()),
            0.0,
            1e-12,
        );
        // A vector pointing back at the camera has positive camera-space z.
        assert!(c.to_camera_space(c.origin() - c.target()).z > 0.0);
    }

    #[test]
    fn default_camera_looks_down_minus_z() {
        let c = Camera::new(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 60.0, 3, 3).unwrap();
        close(c.right().distance(DVec3::X), 0.0, 1e-15);
        close(c.camera_up().distance(DVec3::Y), 0.0, 1e-15);
        let n = DVec3::new(0.3, -0.2, 0.9);
        close(c.to_camera_space(n).distance(n), 0.0, 1e-15);
    }

    #[test]
    fn errors() {
        let o = DVec3::new(0.0, 0.0, 5.0);
        let new = |o, t, up, fov, w, h| Camera::new(o, t, up, fov, w, h).unwrap_err();

        let e = new(o, o, DVec3::Y, 50.0, 4, 4);
        assert!(matches!(e, CameraError::OriginIsTarget { .. }), "{e}");
        assert!(e.to_string().contains("same point"), "{e}");
        // Relative test: a tiny but real offset at a tiny scale is fine...
        assert!(
            Camera::new(
                DVec3::new(0.0, 0.0, 1e-9),
                DVec3::ZERO,
                DVec3::Y,
                50.0,
                4,
                4
            )
            .is_ok()
        );
        // ...and an offset below rounding at a large scale is not.
        let far = DVec3::splat(1e9);
        let e = new(far, far + DVec3::splat(1e-5), DVec3::Y, 50.0, 4, 4);
        assert!(matches!(e, CameraError::OriginIsTarget { .. }), "{e}");
        let e = new(DVec3::ZERO, DVec3::ZERO, DVec3::Y, 50.0, 4, 4);
        assert!(matches!(e, CameraError::OriginIsTarget { .. }), "{e}");

        let e = new(o, DVec3::ZERO, DVec3::Z, 50.0, 4, 4);
        assert!(matches!(e, CameraError::UpParallel { .. }), "{e}");
        assert!(e.to_string().contains("parallel"), "{e}");
        let e = new(o, DVec3::ZERO, DVec3::new(1e-9, 0.0, -3.0), 50.0, 4, 4);
        assert!(matches!(e, CameraError::UpParallel { .. }), "{e}");
        let e = new(o, DVec3::ZERO, DVec3::ZERO, 50.0, 4, 4);
        assert!(matches!(e, CameraError::UpParallel { .. }), "{e}");
        // A large but slanted up vector is fine (relative test).
        assert!(Camera::new(o, DVec3::ZERO, DVec3::new(0.0, 1e-2, 1e3), 50.0, 4, 4).is_ok());

        for fov in [0.0, -10.0, 180.0, 200.0, f64::NAN] {
            let e = new(o, DVec3::ZERO, DVec3::Y, fov, 4, 4);
            assert!(matches!(e, CameraError::FieldOfView(_)), "fov {fov}: {e}");
            assert!(e.to_string().contains("(0, 180)"), "{e}");
        }

        for (w, h) in [(0, 4), (4, 0), (0, 0)] {
            let e = new(o, DVec3::ZERO, DVec3::Y, 50.0, w, h);
            assert!(matches!(e, CameraError::EmptyImage { .. }), "{e}");
            assert!(e.to_string().contains(&format!("{w}x{h}")), "{e}");
        }

        let e = new(
            DVec3::new(f64::NAN, 0.0, 0.0),
            DVec3::ZERO,
            DVec3::Y,
            50.0,
            4,
            4,
        );
        assert!(
            matches!(e, CameraError::NonFinite { what: "origin", .. }),
            "{e}"
        );
        assert!(e.to_string().contains("origin is not finite"), "{e}");
        let e = new(o, DVec3::splat(f64::INFINITY), DVec3::Y, 50.0, 4, 4);
        assert!(e.to_string().contains("target is not finite"), "{e}");
        let e = new(o, DVec3::ZERO, DVec3::new(0.0, f64::NAN, 0.0), 50.0, 4, 4);
        assert!(e.to_string().contains("up is not finite"), "{e}");
    }
}
