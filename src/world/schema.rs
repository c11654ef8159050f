//! The world file's schema: plain serde structs, one per TOML table, unknown keys rejected.
//!
//! Defaults live here, next to the field they belong to, so that `worlds/README.md` and the
//! code cannot disagree about them for long: every default is a named function below.

use serde::{Deserialize, Serialize};

/// A whole world: the box, its walls, its agents and how long to simulate them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    /// Name of the world, used in the recording and the summary. Default: the file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// The box `[0, W] × [0, H]`, in metres.
    pub size: [f64; 2],
    /// Add four walls of [`OUTER_WALL_THICKNESS`] just inside the box.
    #[serde(default = "default_true")]
    pub walls_around: bool,
    /// Physics step, s.
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// Simulated time, s.
    #[serde(default = "default_duration")]
    pub duration: f64,
    /// Seed for everything random in a run (a run is deterministic for a given file and seed).
    #[serde(default)]
    pub seed: u64,
    /// A constant external acceleration on every agent, m/s² (the paper's drift, eq. 71:
    /// `[-4, -4]`; or gravity). Rapier applies it as gravity, `m·a` on each body. The
    /// controllers do not know it.
    #[serde(default)]
    pub external_acceleration: [f64; 2],
    /// Time at which each agent's distance from its start is reported as `distance_covered`,
    /// s (the paper's corridor: "25 metres in 10 seconds").
    #[serde(default)]
    pub distance_at: Option<f64>,
    /// How the guidance field is built.
    #[serde(default)]
    pub field: FieldSettings,
    /// Static obstacles.
    #[serde(default)]
    pub walls: Vec<Wall>,
    /// The controlled bodies (a world needs at least one agent or pendulum).
    #[serde(default)]
    pub agents: Vec<Agent>,
    /// Controlled pendulums (§VI.8): a mass on a massless rod on a revolute joint, under the
    /// world's `external_acceleration` as gravity.
    #[serde(default)]
    pub pendulums: Vec<Pendulum>,
    /// What every agent's run must show (`nadf run` exits 1 when it does not).
    #[serde(default)]
    pub expect: Option<Expect>,
}

/// An `[expect]` table: assertions on a run's summary, for users' own collision tests. Every
/// key is optional; `nadf run` checks the ones given and exits with status 1, listing what
/// failed, when any does not hold.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// Whether the agent must end within the settling band (`true`) or outside it (`false`).
    pub reached: Option<bool>,
    /// The exact number of contact starts (`contacts = 0`: never touch anything).
    pub contacts: Option<usize>,
    /// At least this many contact starts (for worlds that show a crash).
    pub min_contacts: Option<usize>,
    /// At most this many contact starts.
    pub max_contacts: Option<usize>,
    /// The agent must settle, and no later than this, s.
    pub max_settling_time: Option<f64>,
    /// The smallest clearance to the walls must be at least this, m.
    pub min_clearance: Option<f64>,
    /// The final distance to the target must be at most this, m.
    pub max_final_error: Option<f64>,
    /// `δ_m` must be at most this, m.
    pub max_deviation: Option<f64>,
    /// The peak speed must be at most this, m/s.
    pub max_peak_speed: Option<f64>,
    /// The peak control force must be at most this, N.
    pub max_peak_force: Option<f64>,
    /// The speed at the end must be at most this, m/s (a body that must have stopped).
    pub max_final_speed: Option<f64>,
    /// The distance from the start at the world's `distance_at` time must be at least this, m.
    pub min_distance_covered: Option<f64>,
    /// The distance from the start at the world's `distance_at` time must be at most this, m.
    pub max_distance_covered: Option<f64>,
    /// The sideways reversals (`lateral_reversals`) must be at most this many.
    pub max_lateral_reversals: Option<usize>,
}

/// Thickness of the walls that `walls_around = true` adds, m.
pub const OUTER_WALL_THICKNESS: f64 = 0.1;

/// The `[field]` table: grid and guidance settings shared by all agents.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSettings {
    /// Which potential guides the agents.
    #[serde(default)]
    pub kind: FieldKind,
    /// Grid spacing, m.
    #[serde(default = "default_cell")]
    pub cell: f64,
    /// How the field's gradient becomes a guidance force.
    #[serde(default)]
    pub guidance: GuidanceKind,
    /// Relative residual to which each Laplace solve is taken.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// The largest grid accepted, in cells (about 40 bytes of memory each, per agent).
    #[serde(default = "default_max_cells")]
    pub max_cells: u64,
    /// With several agents: how often each agent's field is rebuilt with the others at their
    /// current positions, Hz (0: only at the start). A harmonic field is re-solved, warm-started
    /// from the last one; an attractive-repulsive one sees the others at every step regardless.
    #[serde(default = "default_replan_hz")]
    pub replan_hz: f64,
    /// `attractive-repulsive`: how the target attracts.
    #[serde(default)]
    pub attraction: Attraction,
    /// `attractive-repulsive`: the FIRAS gain η, m³ (required with that kind).
    #[serde(default)]
    pub eta: Option<f64>,
    /// `attractive-repulsive`: the range ρ0 of the repulsion, m (required with that kind).
    #[serde(default)]
    pub rho0: Option<f64>,
}

/// Which potential guides the agents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FieldKind {
    /// The harmonic potential: Laplace's equation on the free space (eq. 3), no local minima.
    #[default]
    Harmonic,
    /// Khatib's potential: attraction to the target plus FIRAS repulsion
    /// `½η(1/ρ − 1/ρ0)²` from every obstacle within ρ0 (§VI.6). It has local minima.
    AttractiveRepulsive,
}

/// How the target attracts in an attractive-repulsive field (`d` is the distance to it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Attraction {
    /// `U = d`: a pull of constant magnitude (a spring `d²/(2 r_c)` inside the agent's
    /// capture radius `r_c`).
    #[default]
    Conic,
    /// `U = ½ d²`: a spring, pulling harder the farther the target.
    Quadratic,
}

impl Default for FieldSettings {
    fn default() -> Self {
        Self {
            cell: default_cell(),
            guidance: GuidanceKind::default(),
            tolerance: default_tolerance(),
            max_cells: default_max_cells(),
            kind: FieldKind::default(),
            replan_hz: default_replan_hz(),
            attraction: Attraction::default(),
            eta: None,
            rho0: None,
        }
    }
}

/// How the guidance force is derived from the gradient `g = ∇V` (see the design page).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GuidanceKind {
    /// `F_g = -K · g/|g|`, tapered inside the capture radius: constant thrust along the streamline.
    #[default]
    Normalized,
    /// `F_g = -K · g`: the paper's equations, for which Proposition 1's energy argument holds.
    Gradient,
}

/// One static wall: a fixed Rapier collider.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Wall {
    /// A rectangle, possibly rotated.
    Box {
        /// Centre, m.
        center: [f64; 2],
        /// Half width and half height, m.
        half_extents: [f64; 2],
        /// Rotation about the centre, rad (counter-clockwise).
        #[serde(default)]
        angle: f64,
    },
    /// A thick segment from `a` to `b`: a capsule of radius `thickness / 2`.
    Segment {
        /// First end point, m.
        a: [f64; 2],
        /// Second end point, m.
        b: [f64; 2],
        /// Full thickness, m.
        thickness: f64,
    },
    /// A solid disc.
    Disc {
        /// Centre, m.
        center: [f64; 2],
        /// Radius, m.
        radius: f64,
    },
    /// A convex polygon, vertices counter-clockwise.
    Polygon {
        /// Vertices, m.
        points: Vec<[f64; 2]>,
    },
}

/// One agent: a dynamic disc with its own target and controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Agent {
    /// Name, unique in the world; used in entity paths and the summary.
    pub name: String,
    /// Start position, m.
    pub start: [f64; 2],
    /// Target position, m.
    pub target: [f64; 2],
    /// Disc radius, m.
    #[serde(default = "default_radius")]
    pub radius: f64,
    /// Mass, kg.
    #[serde(default = "default_mass")]
    pub mass: f64,
    /// The control law.
    pub controller: ControllerSettings,
    /// Noisy sensing of the walls (default: the agent knows the walls exactly).
    #[serde(default)]
    pub sensor: Option<SensorSettings>,
    /// What this agent's run must show, on top of the world's `[expect]`.
    #[serde(default)]
    pub expect: Option<Expect>,
}

/// One pendulum (`[[pendulums]]`): a point mass `mass` on a massless rod of `length` about a
/// fixed `pivot`, on a Rapier revolute joint, driven by a torque `u = K·e − B·θ̇ (+ β)` with
/// `e = θ_T − θ` (eq. 75 with the target moved off zero, and the bias of eq. 48–50). The angle θ
/// is measured counter-clockwise from hanging straight down.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pendulum {
    /// Name, unique in the world; used in entity paths and the summary.
    pub name: String,
    /// The pivot, m.
    pub pivot: [f64; 2],
    /// Rod length L, m.
    #[serde(default = "default_length")]
    pub length: f64,
    /// The mass M at the end of the rod, kg.
    #[serde(default = "default_mass")]
    pub mass: f64,
    /// Initial angle θ(0), rad.
    #[serde(default)]
    pub start: f64,
    /// Target angle θ_T, rad.
    pub target: f64,
    /// The torque law.
    pub controller: PendulumController,
    /// What this pendulum's run must show.
    #[serde(default)]
    pub expect: Option<PendulumExpect>,
}

/// The `[pendulums.controller]` table: `u = K·e − B·θ̇ (+ β)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PendulumController {
    /// Position gain K, N·m/rad.
    pub k: f64,
    /// Damping B, N·m·s/rad.
    pub b: f64,
    /// The iterative bias (eq. 48–50); α in rad/s.
    #[serde(default)]
    pub bias: Option<BiasSettings>,
}

/// The `[pendulums.expect]` table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PendulumExpect {
    /// The final `|θ_T − θ|` must be at most this, rad.
    pub max_final_error: Option<f64>,
    /// The final `|θ_T − θ|` must be at least this, rad (a steady-state error that must show).
    pub min_final_error: Option<f64>,
    /// At most this many bias updates.
    pub max_bias_updates: Option<usize>,
}

/// The `[agents.controller]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSettings {
    /// Which law turns the guidance into a control force.
    pub kind: ControllerKind,
    /// Guidance gain K: N for `normalized` guidance, N·m for `gradient` guidance
    /// (`nadf` and `viscous`; default [`DEFAULT_K`]).
    #[serde(default)]
    pub k: Option<f64>,
    /// Damping coefficient, N·s/m: `B_d` for NADF, `B` for viscous damping (required by both).
    #[serde(default)]
    pub b: Option<f64>,
    /// Radius around the target inside which normalized guidance (and the sliding-mode
    /// desired speed) tapers linearly to zero, m.
    #[serde(default = "default_capture_radius")]
    pub capture_radius: f64,
    /// Sliding mode: the desired speed `v_d` along the guidance, m/s (eq. 72; required).
    #[serde(default)]
    pub vd: Option<f64>,
    /// Sliding mode: the control magnitude `F_0`, N (eq. 73; required).
    #[serde(default)]
    pub f0: Option<f64>,
    /// Speed limit `v_max`, m/s: at or above it, the part of the control force that would
    /// accelerate the body further along its velocity is dropped (paper §VI.2).
    #[serde(default)]
    pub speed_limit: Option<f64>,
    /// Actuator saturation `F_max`, N: a control force longer than this is scaled down to it
    /// (direction kept), before the speed limit.
    #[serde(default)]
    pub max_force: Option<f64>,
    /// Clamping control near the target (eq. 35–36).
    #[serde(default)]
    pub clamp: Option<ClampSettings>,
    /// Iterative blind error cancellation (eq. 48–50).
    #[serde(default)]
    pub bias: Option<BiasSettings>,
}

/// The guidance gain used when `k` is not given.
pub const DEFAULT_K: f64 = 1.0;

impl ControllerSettings {
    /// The guidance gain K ([`DEFAULT_K`] unless given).
    pub fn k(&self) -> f64 {
        self.k.unwrap_or(DEFAULT_K)
    }
}

/// The `[agents.controller.clamp]` table: `-K_c (x - x_T)` while within `sigma` of the target
/// and moving away from it (eq. 35).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClampSettings {
    /// Clamping gain K_c, N/m.
    pub kc: f64,
    /// Radius σ of the clamping region around the target, m.
    pub sigma: f64,
}

/// The `[agents.controller.bias]` table: a bias β added to the control and reset to the
/// control measured at each settling instant (eq. 48–50).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BiasSettings {
    /// Settling threshold α, m/s: the body is settling while its speed is below α.
    pub alpha: f64,
    /// How long the speed must stay below α before β is updated, s.
    #[serde(default = "default_dwell")]
    pub dwell: f64,
}

/// The `[agents.sensor]` table: the agent senses the walls with noise and rebuilds its field
/// from what it sensed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSettings {
    /// Half-width of the uniform noise on each wall's sensed position, m: every reading moves
    /// each wall's boundary out or in by an independent draw from `[-noise, noise]`.
    pub noise: f64,
    /// Readings per second; the field is rebuilt from each reading, Hz.
    pub rate: f64,
}

/// The control laws.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ControllerKind {
    /// Guidance plus nonlinear anisotropic damping (eq. 9–10).
    Nadf,
    /// Guidance plus linear viscous damping (eq. 1).
    Viscous,
    /// Guldner and Utkin's sliding mode on the guidance (eq. 72–73).
    SlidingMode,
}

impl ControllerKind {
    /// The name used in world files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Nadf => "nadf",
            Self::Viscous => "viscous",
            Self::SlidingMode => "sliding-mode",
        }
    }
}

fn default_true() -> bool {
    true
}
fn default_dt() -> f64 {
    0.01
}
fn default_duration() -> f64 {
    60.0
}
fn default_cell() -> f64 {
    0.05
}
fn default_replan_hz() -> f64 {
    10.0
}
fn default_tolerance() -> f64 {
    1e-12
}
fn default_max_cells() -> u64 {
    super::validate::MAX_CELLS
}
fn default_radius() -> f64 {
    0.2
}
fn default_mass() -> f64 {
    1.0
}
fn default_length() -> f64 {
    1.0
}
fn default_dwell() -> f64 {
    0.5
}
fn default_capture_radius() -> f64 {
    0.25
}
