//! The one table of entity paths and time series, read both when the recording is set up
//! (labels, static data, the layout) and at every step (the values), so the two can never
//! disagree on a name.

use crate::sim::AgentState;
use crate::sim::pendulum::PendulumState;
use crate::world::{Agent, Pendulum};

/// The root of the static geometry.
pub const WORLD: &str = "world";
/// The box's outline.
pub const BOX: &str = "world/box";
/// The walls' outlines.
pub const WALLS: &str = "world/walls";
/// A map's cells, as an image.
pub const MAP: &str = "world/map";
/// The root of everything agents draw.
pub const AGENTS: &str = "agents";

/// The run's verdict as a text document: the summary table and the expectations' results.
pub const SUMMARY: &str = "summary";

/// The time series of `owner` (an agent or a pendulum) called `series`.
pub fn plot(owner: &str, series: &str) -> String {
    format!("plots/{owner}/{series}")
}

/// One agent's entities.
pub struct AgentPaths {
    /// `log10(1 − V)` of its field, as an image.
    pub potential: String,
    /// The unit guidance arrows.
    pub guidance: String,
    /// Its kinematic path.
    pub kinematic_path: String,
    /// Its target.
    pub target: String,
    /// Its start.
    pub start: String,
    /// Its body, per step.
    pub body: String,
    /// Its trail.
    pub trail: String,
    /// Its velocity arrow.
    pub velocity: String,
    /// Its control force arrow.
    pub force: String,
    /// Where it touches something.
    pub contacts: String,
    /// Faults (WARN) and control notes (INFO).
    pub events: String,
    /// The walls as its sensor last saw them.
    pub sensed_walls: String,
    /// The rays of its lidar's latest scan.
    pub scan: String,
    /// The map its lidar has built: occupied, free, unknown.
    pub known_map: String,
}

impl AgentPaths {
    /// The entities of the agent called `name`.
    pub fn of(name: &str) -> Self {
        let path = |part: &str| format!("{AGENTS}/{name}/{part}");
        Self {
            potential: path("field/potential"),
            guidance: path("field/guidance"),
            kinematic_path: path("kinematic_path"),
            target: path("target"),
            start: path("start"),
            body: path("body"),
            trail: path("trail"),
            velocity: path("velocity"),
            force: path("force"),
            contacts: path("contacts"),
            events: path("events"),
            sensed_walls: path("sensed_walls"),
            scan: path("lidar/scan"),
            known_map: path("lidar/map"),
        }
    }

    /// What the layout hides of every agent but the first: its field (they overlap).
    pub fn field_of(name: &str) -> String {
        format!("/{AGENTS}/{name}/field/**")
    }
}

/// One pendulum's entities.
pub struct PendulumPaths {
    /// Its pivot.
    pub pivot: String,
    /// The rod at the target angle.
    pub target: String,
    /// Its rod, per step.
    pub rod: String,
    /// Its bob, per step.
    pub bob: String,
    /// Its bias updates (INFO).
    pub events: String,
}

impl PendulumPaths {
    /// The entities of the pendulum called `name`.
    pub fn of(name: &str) -> Self {
        let path = |part: &str| format!("{WORLD}/pendulums/{name}/{part}");
        Self {
            pivot: path("pivot"),
            target: path("target"),
            rod: path("rod"),
            bob: path("bob"),
            events: path("events"),
        }
    }
}

/// A time series: its name under `plots/OWNER/`, its label, the view it is shown in, whether
/// an owner has it, and its value after a step.
pub struct Series<Owner, State> {
    /// The entity name under `plots/OWNER/`.
    pub key: &'static str,
    /// Its label in the viewer.
    pub label: &'static str,
    /// The title of the time-series view it is shown in.
    pub view: &'static str,
    /// Whether an owner (from its settings) has this series.
    pub shown: fn(&Owner) -> bool,
    /// Its value after a step.
    pub value: fn(&Owner, &State) -> f64,
}

fn always<T>(_: &T) -> bool {
    true
}

fn flag(on: bool) -> f64 {
    if on { 1.0 } else { 0.0 }
}

/// Every agent's time series, in the order of the views.
pub const AGENT_SERIES: &[Series<Agent, AgentState>] = &[
    Series {
        key: "distance",
        label: "distance to target (m)",
        view: "distance to target (m)",
        shown: always,
        value: |_, s| s.distance,
    },
    Series {
        key: "speed",
        label: "speed (m/s)",
        view: "speed (m/s)",
        shown: always,
        value: |_, s| s.velocity.norm(),
    },
    Series {
        key: "radial_speed",
        label: "speed along the guidance (m/s)",
        view: "speed (m/s)",
        shown: always,
        value: |_, s| s.radial_speed,
    },
    Series {
        key: "force",
        label: "|F| (N)",
        view: "control force (N)",
        shown: always,
        value: |_, s| s.force.norm(),
    },
    Series {
        key: "force_x",
        label: "Fx (N)",
        view: "control force (N)",
        shown: always,
        value: |_, s| s.force.x,
    },
    Series {
        key: "force_y",
        label: "Fy (N)",
        view: "control force (N)",
        shown: always,
        value: |_, s| s.force.y,
    },
    Series {
        key: "potential",
        label: "V",
        view: "potential V",
        shown: always,
        value: |_, s| s.potential,
    },
    Series {
        key: "clamping",
        label: "clamping active",
        view: "limits active (0/1)",
        shown: |a| a.controller.clamp.is_some(),
        value: |_, s| flag(s.clamping),
    },
    Series {
        key: "speed_limited",
        label: "speed limit active",
        view: "limits active (0/1)",
        shown: |a| a.controller.speed_limit.is_some() || a.controller.brake.is_some(),
        value: |_, s| flag(s.speed_limited),
    },
    Series {
        key: "beta_x",
        label: "β x (N)",
        view: "bias β (N)",
        shown: |a| a.controller.bias.is_some(),
        value: |_, s| s.beta.map_or(0.0, |b| b.x),
    },
    Series {
        key: "beta_y",
        label: "β y (N)",
        view: "bias β (N)",
        shown: |a| a.controller.bias.is_some(),
        value: |_, s| s.beta.map_or(0.0, |b| b.y),
    },
];

/// Every pendulum's time series, in the order of the views.
pub const PENDULUM_SERIES: &[Series<Pendulum, PendulumState>] = &[
    Series {
        key: "theta",
        label: "θ (rad)",
        view: "pendulum angle θ (rad)",
        shown: always,
        value: |_, s| s.theta,
    },
    Series {
        key: "target",
        label: "θ_T (rad)",
        view: "pendulum angle θ (rad)",
        shown: always,
        value: |p, _| p.target,
    },
    Series {
        key: "torque",
        label: "u (N·m)",
        view: "torque u (N·m)",
        shown: always,
        value: |_, s| s.torque,
    },
    Series {
        key: "beta",
        label: "β (N·m)",
        view: "bias β (N·m)",
        shown: always,
        value: |_, s| s.beta,
    },
];
