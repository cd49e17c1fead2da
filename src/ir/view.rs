//! What a scene is seen and lit by: its camera, its render settings and its lights.

use glam::DVec3;

use crate::span::Span;

/// A camera: a pinhole, or under light transport a thin lens when it has an aperture.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: DVec3,
    /// A point the camera looks at (never equal to `position`).
    pub look_at: DVec3,
    /// Up hint (never parallel to the view direction).
    pub up: DVec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov: f64,
    /// Diameter of the thin lens (0: a pinhole, everything sharp); light transport only.
    pub aperture: f64,
    /// Distance along the view at which the lens focuses (`None`: at `look_at`).
    pub focus_distance: Option<f64>,
    /// The `camera` statement, if any.
    pub span: Option<Span>,
}

/// The study's vertical field of view: a 1×1 viewport at distance 1, `2·atan(0.5)` in degrees.
pub const SEED_FOV: f64 = 53.13010235415598;

impl Default for Camera {
    fn default() -> Camera {
        Camera {
            position: DVec3::ZERO,
            look_at: DVec3::Z,
            up: DVec3::Y,
            fov: SEED_FOV,
            aperture: 0.0,
            focus_distance: None,
            span: None,
        }
    }
}

/// Image size and tracer knobs from `render(…)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Reflection recursion depth (0 = no reflection rays).
    pub depth: u32,
    /// Background colour, 0–255 per channel.
    pub background: DVec3,
    /// Sphere-tracing hit threshold, relative to the distance travelled (see `sdf`).
    pub epsilon: f64,
    /// Sphere-tracing step budget per ray.
    pub max_steps: u32,
    /// Far limit of every ray.
    pub max_distance: f64,
    /// Samples per pixel (antialiasing), a perfect square is not required.
    pub samples: u32,
    /// Reach of ambient occlusion in world units (0 = off).
    pub ambient_occlusion: f64,
    /// How colours are read and pixels written.
    pub color: ColorSpace,
    /// Frames of the animation (1: a still).
    pub frames: u32,
    /// Frames per second, for encoding an animation.
    pub fps: f64,
    /// Whether the animation loops: then `clock` stops one frame short of 1, so the frame
    /// after the last would be the first again.
    pub cyclic: bool,
    /// Surface interactions of a light-transport path after the camera ray (`None`: not
    /// given; a scene lit by light transport then takes [`DEFAULT_BOUNCES`]).
    pub bounces: Option<u32>,
    /// Exposure in stops: light-transport pixels are scaled by `2^exposure` before the
    /// tone map.
    pub exposure: f64,
    /// Adaptive sampling under light transport: each pixel takes samples until its
    /// estimated relative error is below this (`samples` is then the most it takes).
    pub noise: Option<f64>,
    /// Under light transport, the most radiance one sample may bring in any channel: a
    /// brighter sample is scaled down to it, its hue kept (biased; `None`: unclamped).
    pub clamp: Option<f64>,
    /// The `render` statement, if any.
    pub span: Option<Span>,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            width: 500,
            height: 500,
            depth: 5,
            background: DVec3::splat(245.0),
            epsilon: 1e-4,
            max_steps: 512,
            max_distance: 1000.0,
            samples: 1,
            ambient_occlusion: 0.0,
            color: ColorSpace::Linear,
            frames: 1,
            fps: 24.0,
            cyclic: false,
            bounces: None,
            exposure: 0.0,
            noise: None,
            clamp: None,
            span: None,
        }
    }
}

/// Bounces of a scene lit by light transport that does not give `render(bounces = …)`.
pub const DEFAULT_BOUNCES: u32 = 8;

/// How colours are read and pixels written (`render(color = …)`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorSpace {
    /// The study's: colours are shaded as written and pixels are those numbers, 0–255.
    Linear,
    /// Colours are sRGB-encoded (as colour pickers give them): decoded to linear light
    /// for shading, and pixels are encoded back to sRGB.
    Srgb,
}

impl ColorSpace {
    /// The name `render(color = …)` takes.
    pub fn name(self) -> &'static str {
        match self {
            ColorSpace::Linear => "linear",
            ColorSpace::Srgb => "srgb",
        }
    }
}

/// What kind of light.
#[derive(Clone, Debug, PartialEq)]
pub enum LightKind {
    /// Lights every point equally.
    Ambient,
    /// A point light.
    Point {
        /// Where it is.
        position: DVec3,
    },
    /// A light at infinity.
    Directional {
        /// Direction *towards* the light (non-zero, not normalised, as written).
        towards: DVec3,
    },
    /// A rectangle of light `centre ± u ± v`, emitting from its front, the side
    /// `u × v` points to (−y before `rotate`).
    Area {
        /// Its centre.
        centre: DVec3,
        /// Half its width, as a vector along the rectangle.
        u: DVec3,
        /// Half its height, as a vector along the rectangle.
        v: DVec3,
    },
    /// Light arriving equally from every direction, seen where rays escape.
    Environment,
}

/// A light.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// Its kind and placement.
    pub kind: LightKind,
    /// Intensity, ≥ 0.
    pub intensity: f64,
    /// Whether it casts shadows (`shadows = false` opts out).
    pub shadows: bool,
    /// Radius for soft shadows (0 = hard).
    pub radius: f64,
    /// The light's expression.
    pub span: Span,
}
