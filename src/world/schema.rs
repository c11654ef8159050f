//! The world file's schema: plain serde structs, one per TOML table, unknown keys rejected.
//!
//! Defaults live here, next to the field they belong to, so that `worlds/README.md` and the
//! code cannot disagree about them for long: every default is a named function below.

use std::collections::BTreeMap;
use std::sync::Arc;

use serde::{Deserialize, Deserializer, Serialize};

use super::map::occupancy::Occupancy;

/// A whole world: the box, its walls, its agents and how long to simulate them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    /// Name of the world, used in the recording and the summary. Default: the file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// The box's width and height, m: `origin + [0, W] × [0, H]`. Required, unless the world
    /// has a `[map]`, whose extent it then is.
    #[serde(default, deserialize_with = "exactly")]
    pub size: [f64; 2],
    /// The box's lower-left corner, m (default `[0, 0]`, or the map's origin with a `[map]`).
    #[serde(default, deserialize_with = "exactly")]
    pub origin: [f64; 2],
    /// A map whose blocked cells are walls (ROS `map_server` or Moving AI).
    #[serde(default)]
    pub map: Option<MapSettings>,
    /// The map as read, once loaded (not part of the file).
    #[serde(skip)]
    pub loaded_map: Option<Arc<LoadedMap>>,
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
    #[serde(default, deserialize_with = "exactly")]
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
    /// Moving obstacles: shapes that follow scripts of their own and plan nothing.
    #[serde(default)]
    pub obstacles: Vec<super::obstacle::Obstacle>,
    /// The controlled bodies (a world needs at least one agent or pendulum).
    #[serde(default)]
    pub agents: Vec<Agent>,
    /// The agents with a shape other than a disc (`[agents.shape]`), planned in (x, y, θ): the
    /// loader moves them here from `agents`, which holds the discs.
    #[serde(skip)]
    pub shaped: Vec<Agent>,
    /// Controlled pendulums (§VI.8): a mass on a massless rod on a revolute joint, under the
    /// world's `external_acceleration` as gravity.
    #[serde(default)]
    pub pendulums: Vec<Pendulum>,
    /// Planar arms: links on revolute joints from a fixed base, planned in joint space, under
    /// the world's `external_acceleration` as gravity (an arm in a vertical plane) or none (on
    /// a table).
    #[serde(default)]
    pub arms: Vec<ArmSettings>,
    /// What every agent's run must show (`nadf run` exits 1 when it does not).
    #[serde(default)]
    pub expect: Option<Expect>,
}

/// An `[expect]` table: assertions on a run's summary, for users' own collision tests. Each
/// key names a metric of the summary (`metrics::Summary`) and how it is bounded:
/// `max_<metric>` (at most), `min_<metric>` (at least), or `<metric>` (exactly, for a yes/no
/// or whole-number metric), e.g. `reached = true`, `contacts = 0`, `max_settling_time = 6.0`.
/// `nadf run` checks them and exits with status 1, listing what failed, when any does not hold;
/// validation rejects a key that names no metric (see `crate::expect`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Expect(pub BTreeMap<String, ExpectValue>);

/// The value of an expectation: `true`/`false`, a whole number or a real number.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum ExpectValue {
    /// `true` or `false`.
    Flag(bool),
    /// A whole number.
    Integer(i64),
    /// A real number.
    Real(f64),
}

impl<'de> Deserialize<'de> for ExpectValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = ExpectValue;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, or true or false")
            }
            fn visit_bool<E>(self, v: bool) -> Result<ExpectValue, E> {
                Ok(ExpectValue::Flag(v))
            }
            fn visit_i64<E>(self, v: i64) -> Result<ExpectValue, E> {
                Ok(ExpectValue::Integer(v))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<ExpectValue, E> {
                i64::try_from(v)
                    .map(ExpectValue::Integer)
                    .map_err(|_| E::custom(format!("{v} is too large")))
            }
            fn visit_f64<E>(self, v: f64) -> Result<ExpectValue, E> {
                Ok(ExpectValue::Real(v))
            }
        }
        d.deserialize_any(Visitor)
    }
}

impl std::fmt::Display for ExpectValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Flag(b) => write!(f, "{b}"),
            Self::Integer(n) => write!(f, "{n}"),
            Self::Real(x) => write!(f, "{x}"),
        }
    }
}

/// The default of `field.max_cells`, the largest grid accepted (4096 × 4096 cells, about 640 MB
/// per agent). A world whose `size` and `field.cell` give more cells is rejected unless it
/// raises `field.max_cells`.
pub const MAX_CELLS: u64 = 4096 * 4096;

/// The `[map]` table: a map whose blocked cells become walls.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSettings {
    /// The map file, relative to the world file: a ROS `map_server` YAML (`.yaml`) or a Moving
    /// AI grid map (`.map`).
    pub file: String,
    /// Moving AI only: metres per map cell (default 1).
    #[serde(default)]
    pub cell: Option<f64>,
    /// ROS only: whether unknown cells are walls (default `blocked`).
    #[serde(default)]
    pub unknown: Option<UnknownCells>,
}

/// What the unknown cells of a ROS map are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum UnknownCells {
    /// Walls: nothing is assumed passable that was not seen to be.
    #[default]
    Blocked,
    /// Free space.
    Free,
}

/// A world's map as loaded: the grid, and its blocked cells merged into boxes.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedMap {
    /// The map's cells.
    pub occupancy: Occupancy,
    /// Its blocked cells as boxes (walls after the outer ones, before the file's own).
    pub walls: Vec<Wall>,
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
    /// With several agents and a harmonic field: what a replan re-solves.
    #[serde(default)]
    pub replan: Replan,
    /// `replan = "local"`: how far the window re-solved around the agent extends from it along
    /// x and y, m (the window is a square of twice this side). Agents farther than this are
    /// not seen until the agent comes nearer.
    #[serde(default = "default_replan_window")]
    pub replan_window: f64,
    /// `replan = "local"`: how far a coarse window (four times the cell) extends around the
    /// agent, m: the other agents up to this far bend its guidance, and the window of
    /// `replan_window` takes its edge from it. At most `replan_window`: no coarse window.
    #[serde(default = "default_replan_reach")]
    pub replan_reach: f64,
    /// How far ahead the agents without a lidar extrapolate a moving obstacle's motion, s: a
    /// harmonic field is solved with each obstacle where it is and where its velocity takes it
    /// over this time, so the way it leaves is behind a crossing obstacle, not ahead of it
    /// (0: where it is only). ORCA extrapolates by itself and sees the obstacles where they are.
    #[serde(default = "default_obstacle_horizon")]
    pub obstacle_horizon: f64,
    /// For an agent with a shape: heading cells over a full turn of the (x, y, θ) grid (an
    /// even number, at least 8).
    #[serde(default = "default_headings")]
    pub headings: i64,
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

/// What a replan of a harmonic field re-solves (`field.replan`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Replan {
    /// The field of the walls is solved once; a replan re-solves only a window around the
    /// agent (`field.replan_window`) with the other agents in it as obstacles, the field of
    /// the walls holding the window's edge (`field::Window`). Costs what the window costs,
    /// whatever the size of the world.
    #[default]
    Local,
    /// Every replan re-solves the whole field with every other agent as an obstacle
    /// (warm-started): the reference the local replan is measured against.
    Full,
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
            replan: Replan::default(),
            replan_window: default_replan_window(),
            replan_reach: default_replan_reach(),
            headings: default_headings(),
            obstacle_horizon: default_obstacle_horizon(),
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
        #[serde(deserialize_with = "wall_center")]
        center: [f64; 2],
        /// Half width and half height, m.
        #[serde(deserialize_with = "wall_half_extents")]
        half_extents: [f64; 2],
        /// Rotation about the centre, rad (counter-clockwise).
        #[serde(default)]
        angle: f64,
    },
    /// A thick segment from `a` to `b`: a capsule of radius `thickness / 2`.
    Segment {
        /// First end point, m.
        #[serde(deserialize_with = "wall_a")]
        a: [f64; 2],
        /// Second end point, m.
        #[serde(deserialize_with = "wall_b")]
        b: [f64; 2],
        /// Full thickness, m.
        thickness: f64,
    },
    /// A solid disc.
    Disc {
        /// Centre, m.
        #[serde(deserialize_with = "wall_center")]
        center: [f64; 2],
        /// Radius, m.
        radius: f64,
    },
    /// A convex polygon, vertices counter-clockwise.
    Polygon {
        /// Vertices, m.
        #[serde(deserialize_with = "wall_points")]
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
    #[serde(deserialize_with = "exactly")]
    pub start: [f64; 2],
    /// Target position, m.
    #[serde(deserialize_with = "exactly")]
    pub target: [f64; 2],
    /// Velocity at the start, m/s (default at rest). The paper's motivation (eq. 2): viscous
    /// damping only works below an admissible initial speed; NADF from any.
    #[serde(default, deserialize_with = "exactly")]
    pub initial_velocity: [f64; 2],
    /// Disc radius, m.
    #[serde(default = "default_radius")]
    pub radius: f64,
    /// Radius of the target disc, m: the harmonic field has `V = 0` on the free cells whose
    /// centres are this close to the target (default: the agent's radius, trimmed to free
    /// space where walls are nearer). A point target has zero capacity in 2-D, so with one
    /// cell at `V = 0` the field depends on the grid (it tends to 1 everywhere as the cell
    /// shrinks); a disc of fixed size makes the continuum problem well posed. Inside the disc
    /// the guidance continues as a bowl that brings the body to the target point itself.
    #[serde(default)]
    pub target_radius: Option<f64>,
    /// Mass, kg.
    #[serde(default = "default_mass")]
    pub mass: f64,
    /// The body's shape (default: a disc of `radius`). A shape other than a disc is planned in
    /// (x, y, θ) and rotates freely; its `start` and `target` are where its centroid is.
    #[serde(default)]
    pub shape: Option<AgentShape>,
    /// The heading at the start, rad (counter-clockwise from the body frame's x axis along the
    /// world's). Only for a shape other than a disc.
    #[serde(default)]
    pub heading: f64,
    /// The heading to reach, rad; without it every heading at the target point is the target.
    /// Only for a shape other than a disc.
    #[serde(default)]
    pub target_heading: Option<f64>,
    /// Moment of inertia about the centroid, kg·m² (default: the shape's, of uniform density
    /// and `mass`). Only for a shape other than a disc.
    #[serde(default)]
    pub inertia: Option<f64>,
    /// The control law.
    pub controller: ControllerSettings,
    /// Noisy sensing of the walls (default: the agent knows the walls exactly).
    #[serde(default)]
    pub sensor: Option<SensorSettings>,
    /// Wheels (default: none, the disc is pushed in any direction). With a drive the disc turns
    /// and is driven by its wheels (`sim::drive`); `start` is its axle's centre at `heading`.
    #[serde(default)]
    pub drive: Option<DriveSettings>,
    /// What this agent's run must show, on top of the world's `[expect]`.
    #[serde(default)]
    pub expect: Option<Expect>,
}

/// An agent's wheels (`[agents.drive]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSettings {
    /// The kind of drive.
    pub kind: DriveKind,
    /// Distance between the two wheels' contact points, m (a TurtleBot3 Burger: 0.160).
    pub wheel_separation: f64,
    /// Each wheel's largest ground speed, m/s (a Burger: 0.22).
    pub max_wheel_speed: f64,
    /// Each wheel's largest traction force, N.
    pub max_wheel_force: f64,
    /// The largest sideways friction before the robot skids, N (default: it never skids).
    #[serde(default)]
    pub lateral_grip: Option<f64>,
    /// How far ahead of the axle the controlled point is, m (default the radius: the front of
    /// the footprint): that point is fully actuated, and the controller steers it as a disc. A
    /// longer look-ahead lets the point go faster ([`DriveSettings::point_speed`]) and plans
    /// for a larger disc.
    #[serde(default)]
    pub lookahead: Option<f64>,
    /// The footprint's radius, m: the agent's `radius` as the world file gives it (the loader
    /// then grows the agent's radius by the look-ahead, the disc its field is planned for).
    #[serde(skip)]
    pub body_radius: f64,
}

impl DriveSettings {
    /// The look-ahead, m, for a footprint of `radius` m.
    pub fn lookahead_for(&self, radius: f64) -> f64 {
        self.lookahead.unwrap_or(radius)
    }

    /// The fastest the look-ahead point `lookahead` m ahead of the axle may move in any
    /// direction with both wheels within `max_wheel_speed`, m/s: its velocity is
    /// `u h + ℓω n`, the wheels' speeds `u ± ωs/2`, and the largest of those over
    /// `u² + (ℓω)² = v²` is `v √(1 + (s/2ℓ)²)`. The loader makes it the controller's speed
    /// limit (or the `speed_limit` given, if lower), so that the wheels always have the speed
    /// left to turn the point: at the wheels' own limit the point could only go straight.
    pub fn point_speed(&self, lookahead: f64) -> f64 {
        let ratio = self.wheel_separation / (2.0 * lookahead);
        self.max_wheel_speed / (1.0 + ratio * ratio).sqrt()
    }
}

/// The kinds of drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DriveKind {
    /// Two wheels on one axle through the disc's centre, no sideways motion: a TurtleBot's.
    Differential,
}

/// An agent's shape (`[agents.shape]`), in the body frame, m. Polygons are convex and
/// counter-clockwise; a compound is a list of such parts (an L, an arrow).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum AgentShape {
    /// A disc of the agent's `radius`: planned in the plane, as without a shape.
    Disc,
    /// A rectangle centred on the body frame's origin.
    Box {
        /// Half length along the body's x axis and half width along its y axis, m.
        #[serde(deserialize_with = "shape_half_extents")]
        half_extents: [f64; 2],
    },
    /// One convex polygon.
    Polygon {
        /// Its vertices, counter-clockwise, m.
        #[serde(deserialize_with = "wall_points")]
        points: Vec<[f64; 2]>,
    },
    /// Several convex polygons, for a body that is not convex.
    Compound {
        /// The parts, each a list of vertices, counter-clockwise, m.
        #[serde(deserialize_with = "shape_parts")]
        parts: Vec<Vec<[f64; 2]>>,
    },
}

impl AgentShape {
    /// The convex parts in the body frame as given (none for a disc).
    pub fn parts(&self) -> Vec<Vec<[f64; 2]>> {
        match self {
            Self::Disc => Vec::new(),
            Self::Box {
                half_extents: [a, b],
            } => {
                vec![vec![[-a, -b], [*a, -b], [*a, *b], [-a, *b]]]
            }
            Self::Polygon { points } => vec![points.clone()],
            Self::Compound { parts } => parts.clone(),
        }
    }
}

impl ArmSettings {
    /// The chain its links make.
    pub fn chain(&self) -> super::arm::Chain {
        super::arm::Chain {
            base: self.base,
            links: (self.links.iter())
                .map(|l| super::arm::Link {
                    com: l.com.unwrap_or(0.5 * l.length),
                    ..super::arm::Link::rod(l.length, l.mass, l.radius)
                })
                .collect(),
        }
    }

    /// Cells per joint of its grid.
    pub fn cells(&self) -> usize {
        let default = if self.links.len() >= 3 { 64 } else { 128 };
        self.cells.map_or(default, |c| c.max(0) as usize)
    }
}

impl Agent {
    /// Whether the agent is a shape planned in (x, y, θ) rather than a disc in the plane.
    pub fn is_shaped(&self) -> bool {
        self.shape.as_ref().is_some_and(|s| *s != AgentShape::Disc)
    }

    /// Whether the agent senses with a lidar (it plans on the map its scans build).
    pub fn has_lidar(&self) -> bool {
        self.sensor.is_some_and(|s| s.kind == SensorKind::Lidar)
    }

    /// The radius of the target disc, m: `target_radius`, or the agent's radius by default
    /// (the field trims the default to free space).
    pub fn target_disc(&self) -> f64 {
        self.target_radius.unwrap_or(self.radius)
    }
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
    #[serde(deserialize_with = "exactly")]
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

/// One arm (`[[arms]]`): two or three links from a fixed `base`, its start and its target in
/// joint space or as a point for its tip.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmSettings {
    /// Name, unique in the world; used in entity paths and the summary.
    pub name: String,
    /// The first joint, m.
    #[serde(deserialize_with = "exactly")]
    pub base: [f64; 2],
    /// The links, from the base out (two or three).
    #[serde(default)]
    pub links: Vec<LinkSettings>,
    /// The joint angles at the start, rad (each relative to the link before; the first to the
    /// world's x axis).
    #[serde(default)]
    pub start: Vec<f64>,
    /// The joint angles to reach, rad (or `target_point`).
    #[serde(default)]
    pub target_joints: Option<Vec<f64>>,
    /// The point the tip must reach, m (or `target_joints`): every configuration with the tip
    /// within `target_radius` of it is the target.
    #[serde(default, deserialize_with = "optional_pair")]
    pub target_point: Option<[f64; 2]>,
    /// The target's radius: rad around `target_joints`, m around `target_point` (default 0.1).
    #[serde(default = "default_arm_target_radius")]
    pub target_radius: f64,
    /// Cells per joint of the joint-space grid (even; default 128 for two links, 64 for three).
    #[serde(default)]
    pub cells: Option<i64>,
    /// The control law, in joint space with the arm's inertia `D(q)`.
    pub controller: ControllerSettings,
    /// What this arm's run must show.
    #[serde(default)]
    pub expect: Option<Expect>,
}

/// One link of an arm (`[[arms.links]]`): a capsule from its joint to the next.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkSettings {
    /// Length, joint to joint (or to the tip), m.
    pub length: f64,
    /// Mass, kg, with the moment of inertia of a uniform rod about its centre of mass.
    #[serde(default = "default_mass")]
    pub mass: f64,
    /// Distance of the centre of mass from the link's joint, m (default: the middle).
    #[serde(default)]
    pub com: Option<f64>,
    /// Radius of the capsule, m.
    #[serde(default = "default_link_radius")]
    pub radius: f64,
    /// The joint's limits `[min, max]`, rad (default none: it turns freely).
    #[serde(default, deserialize_with = "optional_pair")]
    pub limits: Option<[f64; 2]>,
}

/// An optional pair of numbers, checked like [`exactly`].
pub(super) fn optional_pair<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
    Option::<Vec<f64>>::deserialize(d)?
        .map(|v| fixed_length(v, None))
        .transpose()
}

fn default_arm_target_radius() -> f64 {
    0.1
}

fn default_link_radius() -> f64 {
    0.05
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
    /// Braking envelope, m/s²: the speed is also limited to `√(2 a d)` at a distance `d` from
    /// the target, so the body arrives at rest (see `control::SpeedLimit`).
    #[serde(default)]
    pub brake: Option<f64>,
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
    /// How the law's force is handed to the physics each step (default `exact`).
    #[serde(default)]
    pub integration: Integration,
    /// `kind = "orca"`: ORCA's settings (defaults when absent).
    #[serde(default)]
    pub orca: Option<OrcaSettings>,
    /// The unicycle law's turn gain `k`, 1/s (default 2: a heading error of 0.5 rad turns at
    /// 1 rad/s). Only for `kind = "unicycle"`, whose `v_max` is `speed_limit` (default the
    /// wheels' largest speed).
    #[serde(default)]
    pub turn_gain: Option<f64>,
    /// The clearance envelope (`control::Envelope`, on by default): the body never moves
    /// faster than it can stop, braking with `envelope_damping`, in the room it has ahead of
    /// it to the walls and to the other agents' envelopes, so it touches neither. `false`
    /// runs the law bare (the paper's own runs, which have no envelope). Not for robots on
    /// wheels (their wheels limit them instead).
    #[serde(default = "default_true")]
    pub envelope: bool,
    /// The envelope's braking damping `B_e`, N·s/m: it stops the body by damping its whole
    /// velocity with it, within `m·v/B_e`. Default: the controller's damping (`b` for `nadf`
    /// and `viscous`; `m/tracking_time` for `orca`; `f0/vd` for `sliding-mode`).
    #[serde(default)]
    pub envelope_damping: Option<f64>,
}

/// The `[agents.controller.orca]` table: optimal reciprocal collision avoidance's settings
/// (see `control::Orca`). The agent's top speed is the controller's `speed_limit`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrcaSettings {
    /// How far ahead ORCA keeps clear of the other agents, s (RVO2's examples: 2–10 s).
    #[serde(default = "default_orca_time_horizon")]
    pub time_horizon: f64,
    /// Agents within this distance are ORCA's neighbours, m.
    #[serde(default = "default_orca_neighbour_distance")]
    pub neighbour_distance: f64,
    /// Time constant of the force that tracks ORCA's velocity, s (the body's velocity error
    /// decays as `e^{−t/τ}`).
    #[serde(default = "default_orca_tracking_time")]
    pub tracking_time: f64,
}

impl Default for OrcaSettings {
    fn default() -> Self {
        Self {
            time_horizon: default_orca_time_horizon(),
            neighbour_distance: default_orca_neighbour_distance(),
            tracking_time: default_orca_tracking_time(),
        }
    }
}

fn default_orca_time_horizon() -> f64 {
    2.0
}
fn default_orca_neighbour_distance() -> f64 {
    10.0
}
fn default_orca_tracking_time() -> f64 {
    0.1
}

/// How a controller's force is integrated over a physics step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Integration {
    /// The damping and the stiffnesses (clamp, spring, the gradient guidance's curvature) are
    /// integrated exactly over the step, so no gain is unstable (`control::Integrator`).
    #[default]
    Exact,
    /// The continuous law's force at the start of the step, held over it: the textbook
    /// explicit scheme, unstable for `B dt/m > 2`. For comparison with published simulations.
    Explicit,
}

/// The guidance gain used when `k` is not given.
pub const DEFAULT_K: f64 = 1.0;

impl ControllerSettings {
    /// The guidance gain K ([`DEFAULT_K`] unless given).
    pub fn k(&self) -> f64 {
        self.k.unwrap_or(DEFAULT_K)
    }

    /// The clearance envelope's braking damping `B_e` for a body of `mass` (kg), N·s/m: the
    /// one given, else the controller's own damping; `None` when the envelope is off, the
    /// controller is the unicycle law (its wheels limit it), or there is no damping to brake
    /// with (`b = 0`: such a body cannot stop, and is left bare).
    pub fn envelope_damping(&self, mass: f64) -> Option<f64> {
        if !self.envelope {
            return None;
        }
        self.envelope_damping
            .or(match self.kind {
                ControllerKind::Nadf | ControllerKind::Viscous => self.b,
                ControllerKind::Orca => Some(mass / self.orca.unwrap_or_default().tracking_time),
                ControllerKind::SlidingMode => self.f0.zip(self.vd).map(|(f0, vd)| f0 / vd),
                ControllerKind::Unicycle => None,
            })
            .filter(|b| b.is_finite() && *b > 0.0)
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
/// from what it sensed (`kind = "walls"`, the default), or scans with a lidar and plans on the
/// map it builds online (`kind = "lidar"`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSettings {
    /// What the sensor is.
    #[serde(default)]
    pub kind: SensorKind,
    /// Lidar only: the range of each ray, m (required for a lidar).
    #[serde(default)]
    pub range: Option<f64>,
    /// Lidar only: rays per scan, spread evenly over the field of view (default 360).
    #[serde(default)]
    pub rays: Option<u32>,
    /// Lidar only: the field of view, degrees in (0, 360], centred on the direction to the
    /// target (default 360).
    #[serde(default)]
    pub fov: Option<f64>,
    /// Lidar only: the probability that a ray returns nothing (default 0).
    #[serde(default)]
    pub dropout: Option<f64>,
    /// Walls: half-width of the uniform noise on each wall's sensed position, m: every reading
    /// moves each wall's boundary out or in by an independent draw from `[-noise, noise]`.
    /// Lidar: the standard deviation of the Gaussian noise on each range reading, m. Default 0.
    #[serde(default)]
    pub noise: f64,
    /// Half-width of the uniform noise on the agent's estimate of its own position, m: every
    /// reading draws an error in `[-σ, σ]` per axis, which the controller sees (the guidance at
    /// the estimate, the offset from the target) until the next reading (default 0).
    #[serde(default)]
    pub position_noise: f64,
    /// Readings per second; with wall noise the field is rebuilt from each reading, Hz.
    pub rate: f64,
}

/// What an agent's sensor is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SensorKind {
    /// Every wall, each shifted by noise: the field is rebuilt from all of them.
    #[default]
    Walls,
    /// A 2-D lidar of Rapier ray casts: the agent builds an occupancy map online, plans on it
    /// (cells never seen count as free) and finds out online when its target is enclosed.
    Lidar,
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
    /// Not the paper's: the guidance at `speed_limit` as the preferred velocity of ORCA
    /// (optimal reciprocal collision avoidance, van den Berg et al. 2011) among the other
    /// agents, tracked by a force (`control::Orca`). The baseline of crowds.
    Orca,
    /// Not the paper's: the kinematic unicycle law of the peers (navground, ir-sim) on the
    /// same field, for a robot on wheels: forward speed `v_max cos e` and turn rate `k e`, `e`
    /// the angle from the heading to the guidance, tracked by the wheels (`sim::drive`).
    Unicycle,
}

impl ControllerKind {
    /// The name used in world files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Nadf => "nadf",
            Self::Viscous => "viscous",
            Self::SlidingMode => "sliding-mode",
            Self::Orca => "orca",
            Self::Unicycle => "unicycle",
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
fn default_replan_window() -> f64 {
    3.0
}
fn default_replan_reach() -> f64 {
    24.0
}
fn default_obstacle_horizon() -> f64 {
    1.0
}
fn default_headings() -> i64 {
    64
}
fn default_tolerance() -> f64 {
    1e-12
}
fn default_max_cells() -> u64 {
    MAX_CELLS
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

/// A fixed-length array of numbers that rejects any other length. (serde's own `[f64; N]` reads
/// the first N items and silently drops the rest: `start = [8.5, 1.5, 3.0]` would run as
/// `[8.5, 1.5]`.)
fn exactly<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
    fixed_length(Vec::<f64>::deserialize(d)?, None)
}

/// [`exactly`] for the field `name` of a wall. A wall is an internally tagged enum, whose
/// errors serde locates at the wall's table rather than at the field: the message starts with
/// the field's name (`` `center`: … ``), which the loader uses to point at the field's line.
fn exactly_named<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
    name: &str,
) -> Result<[f64; N], D::Error> {
    fixed_length(Vec::<f64>::deserialize(d)?, Some(name))
}

fn wall_center<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    exactly_named(d, "center")
}

fn wall_half_extents<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    exactly_named(d, "half_extents")
}

fn wall_a<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    exactly_named(d, "a")
}

fn wall_b<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    exactly_named(d, "b")
}

fn shape_half_extents<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    exactly_named(d, "half_extents")
}

/// A compound shape's parts, each point checked like [`exactly`].
fn shape_parts<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vec<[f64; 2]>>, D::Error> {
    Vec::<Vec<Vec<f64>>>::deserialize(d)?
        .into_iter()
        .map(|part| {
            part.into_iter()
                .map(|p| fixed_length(p, Some("parts")))
                .collect()
        })
        .collect()
}

/// A wall's list of points, each checked like [`exactly`].
fn wall_points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    Vec::<Vec<f64>>::deserialize(d)?
        .into_iter()
        .map(|p| fixed_length(p, Some("points")))
        .collect()
}

pub(super) fn fixed_length<E: serde::de::Error, const N: usize>(
    items: Vec<f64>,
    name: Option<&str>,
) -> Result<[f64; N], E> {
    let len = items.len();
    items.try_into().map_err(|_| {
        let field = name.map_or_else(String::new, |n| format!("`{n}`: "));
        let dropped = if len > N {
            " (extra numbers are not dropped silently)"
        } else {
            ""
        };
        E::custom(format!(
            "{field}expected an array of exactly {N} numbers, got {len}{dropped}"
        ))
    })
}
