//! The colours of everything drawn: in the recording and in the pictures `nadf field` writes.

/// An RGB colour.
pub type Rgb = [u8; 3];

/// The box's outline.
pub const BOX: Rgb = [120, 120, 120];
/// The walls' outlines, a pendulum's pivot.
pub const WALL: Rgb = [230, 230, 230];
/// A body, its trail, a pendulum's bob.
pub const BODY: Rgb = [255, 170, 40];
/// A body that touches something.
pub const TOUCHING: Rgb = [255, 40, 40];
/// Where a body touches something.
pub const CONTACT: Rgb = [255, 0, 0];
/// Velocity arrows, the kinematic path.
pub const VELOCITY: Rgb = [80, 200, 255];
/// The kinematic path (the streamline from the start).
pub const KINEMATIC: Rgb = [80, 200, 255];
/// Control force arrows.
pub const FORCE: Rgb = [255, 90, 200];
/// Targets.
pub const TARGET: Rgb = [80, 255, 120];
/// Starts.
pub const START: Rgb = [255, 255, 255];
/// A pendulum's rod.
pub const ROD: Rgb = [200, 200, 200];
/// Guidance arrows and streamlines (translucent in the recording).
pub const GUIDANCE: Rgb = [255, 255, 255];
/// Opacity of the guidance arrows.
pub const GUIDANCE_ALPHA: u8 = 110;
/// Streamlines in a field picture.
pub const STREAMLINE: Rgb = [225, 225, 225];
/// Walls as a sensor saw them (translucent).
pub const SENSED: Rgb = [255, 80, 80];
/// Opacity of the sensed walls.
pub const SENSED_ALPHA: u8 = 160;
/// Blocked cells of a field image.
pub const BLOCKED: Rgb = [70, 70, 70];
/// Free cells of a field image from which the target cannot be reached.
pub const UNREACHABLE: Rgb = [0, 0, 0];

/// A moving obstacle, and (translucent) its path.
pub const OBSTACLE: Rgb = [190, 120, 255];

/// A map's walls (drawn as an image).
pub const MAP_WALL: Rgb = [150, 150, 150];
/// A map's unknown cells.
pub const MAP_UNKNOWN: Rgb = [90, 90, 110];

/// A palette colour with opacity `alpha`, as RGBA bytes.
pub fn rgba(c: Rgb, alpha: u8) -> [u8; 4] {
    [c[0], c[1], c[2], alpha]
}

/// A palette colour for Rerun.
pub fn rerun(c: Rgb) -> rerun::Color {
    rerun::Color::from_rgb(c[0], c[1], c[2])
}

/// A palette colour for Rerun with opacity `alpha`.
pub fn rerun_alpha(c: Rgb, alpha: u8) -> rerun::Color {
    rerun::Color::from_unmultiplied_rgba(c[0], c[1], c[2], alpha)
}

/// Sizes of the marks that show where things are rather than how big they are, in UI points:
/// they keep their size on screen at any zoom, so paths and targets stay visible on a 200 m map
/// and do not cover a 2 m corridor. Bodies and walls keep their sizes in metres.
pub mod size {
    /// The radius of a mark `points` UI points wide.
    pub fn points(points: f32) -> rerun::components::Radius {
        rerun::components::Radius::new_ui_points(points)
    }

    /// Half-width of a path line (the kinematic path, the trail).
    pub const PATH: f32 = 1.5;
    /// Radius of a target or start marker.
    pub const MARKER: f32 = 5.0;
    /// Radius of a contact marker.
    pub const CONTACT: f32 = 4.0;
    /// Radius of a sensed-wall point.
    pub const SENSED: f32 = 1.5;
    /// Half-width of a lidar ray.
    pub const RAY: f32 = 0.5;
}
