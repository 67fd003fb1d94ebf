//! The pinhole camera of the manifest, as rays through pixels.

use glam::DVec3;
use schemas::mesh::Camera;

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
    /// The camera of `camera` rendering a `width` x `height` image. `None`
    /// if the view direction is zero or parallel to `up`, or the field of
    /// view is not in (0, 180) degrees.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Option<Self> {
        let eye = DVec3::from(camera.eye);
        let forward = (DVec3::from(camera.target) - eye).try_normalize()?;
        let right = forward.cross(DVec3::from(camera.up)).try_normalize()?;
        let up = right.cross(forward);
        if !(camera.vertical_fov_deg > 0.0 && camera.vertical_fov_deg < 180.0) || width == 0 || height == 0 {
            return None;
        }
        let half_height = (0.5 * camera.vertical_fov_deg.to_radians()).tan();
        let half_width = half_height * f64::from(width) / f64::from(height);
        Some(Pinhole { eye, forward, right, up, half_height, half_width, width: width.into(), height: height.into() })
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
        let camera = Camera { eye: [0.0, 0.0, 0.0], target: [0.0, 0.0, -5.0], up: [0.0, 1.0, 0.0], vertical_fov_deg: 90.0, width: 4, height: 2 };
        let pinhole = Pinhole::new(&camera, 200, 100).unwrap();
        assert!((pinhole.direction(100.0, 50.0) - DVec3::NEG_Z).length() < 1e-12);
        let top = pinhole.direction(100.0, 0.0);
        assert!((top.y.atan2(-top.z).to_degrees() - 45.0).abs() < 1e-9);
        let right = pinhole.direction(200.0, 50.0);
        assert!(right.x > 0.0, "x grows to the right of the image");
        assert!((right.x / -right.z - 2.0).abs() < 1e-12, "aspect 2:1 widens the horizontal extent");
    }
}
