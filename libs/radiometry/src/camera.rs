//! A pinhole camera (the manifest's, through the stage kit's
//! `scene::pinhole`), as rays through pixels.

use glam::DVec3;

/// Camera rays: pixel `(x, y)` (continuous, `y` down, `(0, 0)` the top-left
/// corner of the image) to a unit direction in the mesh frame.
#[derive(Clone, Debug)]
pub struct Pinhole {
    /// Eye position, mesh frame.
    pub eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    half_height: f64,
    half_width: f64,
    width: f64,
    height: f64,
}

impl Pinhole {
    /// The camera at `eye` looking at `target`, `up` above (need not be
    /// orthogonal to the view direction), with a full vertical field of
    /// view of `vertical_fov_deg` degrees, rendering a `width` x `height`
    /// image. `None` if the view direction is zero or parallel to `up`, or
    /// the field of view is not in (0, 180) degrees.
    pub fn new(eye: DVec3, target: DVec3, up: DVec3, vertical_fov_deg: f64, width: u32, height: u32) -> Option<Self> {
        let forward = (target - eye).try_normalize()?;
        let right = forward.cross(up).try_normalize()?;
        let up = right.cross(forward);
        if !(vertical_fov_deg > 0.0 && vertical_fov_deg < 180.0) || width == 0 || height == 0 {
            return None;
        }
        let half_height = (0.5 * vertical_fov_deg.to_radians()).tan();
        let half_width = half_height * f64::from(width) / f64::from(height);
        Some(Pinhole { eye, forward, right, up, half_height, half_width, width: width.into(), height: height.into() })
    }

    /// The view axis: unit direction through the image's centre.
    pub fn forward(&self) -> DVec3 {
        self.forward
    }

    /// Unit direction through the image point `(x, y)` in pixels.
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        let sx = (2.0 * x / self.width - 1.0) * self.half_width;
        let sy = (1.0 - 2.0 * y / self.height) * self.half_height;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_at_the_target_and_edges_span_the_fov() {
        let pinhole = Pinhole::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -5.0), DVec3::Y, 90.0, 200, 100).unwrap();
        assert!((pinhole.direction(100.0, 50.0) - DVec3::NEG_Z).length() < 1e-12);
        assert_eq!(pinhole.forward(), DVec3::NEG_Z);
        let top = pinhole.direction(100.0, 0.0);
        assert!((top.y.atan2(-top.z).to_degrees() - 45.0).abs() < 1e-9);
        let right = pinhole.direction(200.0, 50.0);
        assert!(right.x > 0.0, "x grows to the right of the image");
        assert!((right.x / -right.z - 2.0).abs() < 1e-12, "aspect 2:1 widens the horizontal extent");
    }
}
