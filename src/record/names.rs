//! The one table of entity paths and time series, read both when the recording is set up
//! (labels, static data, the layout) and at every step (the values), so the two can never
//! disagree on a name.

use crate::sim::AgentState;
use crate::sim::arm_run::ArmState;
use crate::sim::pendulum::PendulumState;
use crate::sim::shaped::ShapedState;
use crate::world::{Agent, ArmSettings, Pendulum};

/// The timeline of the simulation's time, s.
pub const SIM_TIME: &str = "sim_time";

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

/// The plot `key` of `owner` (an agent or a pendulum).
pub fn plot(owner: &str, key: &str) -> String {
    format!("plots/{owner}/{key}")
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
    /// Its body: a frame that moves with it (a translation per step, flipped to y-down so that
    /// a view rooted there, which follows the agent, shows the world upright) with its disc at
    /// the frame's origin.
    pub body: String,
    /// Its trail.
    pub trail: String,
    /// Its velocity arrow, in the body's frame.
    pub velocity: String,
    /// Its control force arrow, in the body's frame.
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
    /// A robot on wheels: its footprint at its axle, turned by its heading, with its wheels.
    pub footprint: String,
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
            velocity: path("body/velocity"),
            force: path("body/force"),
            contacts: path("contacts"),
            events: path("events"),
            sensed_walls: path("sensed_walls"),
            scan: path("lidar/scan"),
            known_map: path("lidar/map"),
            footprint: path("footprint"),
        }
    }

    /// What the layout hides of every agent but the first: its field (they overlap).
    pub fn field_of(name: &str) -> String {
        format!("/{AGENTS}/{name}/field/**")
    }
}

/// One moving obstacle's entities, under `world/obstacles/NAME/`.
pub struct ObstaclePaths {
    /// Its frame: the pose per step (translation and rotation).
    pub body: String,
    /// Its shape's outline in that frame (static).
    pub shape: String,
    /// Its path, or the region a wanderer stays in (static).
    pub path: String,
}

impl ObstaclePaths {
    /// The entities of the obstacle called `name`.
    pub fn of(name: &str) -> Self {
        let path = |part: &str| format!("{WORLD}/obstacles/{name}/{part}");
        Self {
            body: path("body"),
            shape: path("body/shape"),
            path: path("path"),
        }
    }
}

/// One shaped agent's entities (under `agents/NAME/`, as a disc's).
pub struct ShapedPaths {
    /// `log10(1 − V)` of the slice of its field at its current heading, as an image.
    pub potential: String,
    /// Its kinematic path.
    pub kinematic_path: String,
    /// The shape at poses along its kinematic path: the heading marks.
    pub kinematic_poses: String,
    /// Its target (the shape at the target heading, if it has one).
    pub target: String,
    /// Its start (the shape at its start pose).
    pub start: String,
    /// Its body: a frame with its pose per step (translation and rotation).
    pub body: String,
    /// The shape's outline in the body's frame.
    pub shape: String,
    /// Its trail.
    pub trail: String,
    /// Where it touches something.
    pub contacts: String,
    /// Contacts and faults (WARN).
    pub events: String,
}

impl ShapedPaths {
    /// The entities of the shaped agent called `name`.
    pub fn of(name: &str) -> Self {
        let path = |part: &str| format!("{AGENTS}/{name}/{part}");
        Self {
            potential: path("field/potential"),
            kinematic_path: path("kinematic_path"),
            kinematic_poses: path("kinematic_poses"),
            target: path("target"),
            start: path("start"),
            body: path("body"),
            shape: path("body/shape"),
            trail: path("trail"),
            contacts: path("contacts"),
            events: path("events"),
        }
    }
}

/// One arm's entities.
pub struct ArmPaths {
    /// Its links, per step: one strip from joint to joint, as wide as each capsule.
    pub links: String,
    /// Its tip's trail.
    pub trail: String,
    /// Its base (static).
    pub base: String,
    /// Its target: the point's disc, or the arm at the target joints (static).
    pub target: String,
    /// Contacts (WARN).
    pub events: String,
    /// The root of its joint space (two links): `…/field` (`log10(1 − V)` as an image, one
    /// pixel per cell, placed in radians) and `…/path` (its joint angles so far).
    pub joint_space: String,
}

impl ArmPaths {
    /// The entities of the arm called `name`.
    pub fn of(name: &str) -> Self {
        let path = |part: &str| format!("{WORLD}/arms/{name}/{part}");
        Self {
            links: path("links"),
            trail: path("trail"),
            base: path("base"),
            target: path("target"),
            events: path("events"),
            joint_space: format!("joint_space/{name}"),
        }
    }
}

/// Every arm's plots, in the order of the views.
pub const ARM_PLOTS: &[Plot<ArmSettings, ArmState>] = &[
    Plot {
        key: "joints",
        piecewise_constant: false,
        view: "arm: joint angles (rad)",
        series: &[
            Series {
                label: "q1 (rad)",
                shown: always,
                value: |_, s| s.q[0],
            },
            Series {
                label: "q2 (rad)",
                shown: always,
                value: |_, s| s.q[1],
            },
            Series {
                label: "q3 (rad)",
                shown: |a| a.links.len() > 2,
                value: |_, s| s.q.get(2).copied().unwrap_or(0.0),
            },
        ],
    },
    Plot {
        key: "torques",
        piecewise_constant: false,
        view: "arm: joint torques (N·m)",
        series: &[
            Series {
                label: "τ1 (N·m)",
                shown: always,
                value: |_, s| s.torque[0],
            },
            Series {
                label: "τ2 (N·m)",
                shown: always,
                value: |_, s| s.torque[1],
            },
            Series {
                label: "τ3 (N·m)",
                shown: |a| a.links.len() > 2,
                value: |_, s| s.torque.get(2).copied().unwrap_or(0.0),
            },
        ],
    },
];

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

/// A time-series plot of an owner (an agent or a pendulum): the entity `plots/OWNER/KEY`, one
/// view in the layout, and one scalar per series the owner has, sent together in one row a step
/// (one row for the force's three components, not three: rows, not values, are most of a long
/// recording's size).
pub struct Plot<Owner: 'static, State: 'static> {
    /// The entity name under `plots/OWNER/`.
    pub key: &'static str,
    /// The title of its time-series view.
    pub view: &'static str,
    /// Its series, in the order of the row's scalars.
    pub series: &'static [Series<Owner, State>],
    /// Whether its series hold their values between jumps (flags, a bias): their rows are
    /// mostly the ends of runs of equal values (`columns::Runs`), so the plot is drawn without
    /// the viewer's aggregation of the points that share a pixel, which would average a jump
    /// and draw a slope from it to the next row a minute later.
    pub piecewise_constant: bool,
}

impl<Owner, State> Plot<Owner, State> {
    /// How the plot of `owner` is drawn: its series' labels, and the aggregation.
    pub fn lines(&self, owner: &Owner) -> rerun::SeriesLines {
        let lines = rerun::SeriesLines::new().with_names(self.series_of(owner).map(|s| s.label));
        if self.piecewise_constant {
            lines.with_aggregation_policy(rerun::components::AggregationPolicy::Off)
        } else {
            lines
        }
    }

    /// The series `owner` has (from its settings), in order: the scalars of the plot's rows.
    pub fn series_of<'a>(
        &'a self,
        owner: &'a Owner,
    ) -> impl Iterator<Item = &'a Series<Owner, State>> {
        self.series.iter().filter(move |s| (s.shown)(owner))
    }
}

/// Logs the labels of every plot of `table` that `owner` (called `name`) has (static).
pub fn log_plot_labels<Owner, State>(
    rec: &rerun::RecordingStream,
    table: &[Plot<Owner, State>],
    name: &str,
    owner: &Owner,
) -> Result<(), rerun::RecordingStreamError> {
    for p in table {
        rec.log_static(plot(name, p.key), &p.lines(owner))?;
    }
    Ok(())
}

/// Logs one row of every plot of `table` for `owner` (called `name`) in `state`, at the
/// stream's current time.
pub fn log_plot_rows<Owner, State>(
    rec: &rerun::RecordingStream,
    table: &[Plot<Owner, State>],
    name: &str,
    (owner, state): (&Owner, &State),
) -> Result<(), rerun::RecordingStreamError> {
    for p in table {
        rec.log(
            plot(name, p.key),
            &rerun::Scalars::new(p.series_of(owner).map(|x| (x.value)(owner, state))),
        )?;
    }
    Ok(())
}

/// Steps between two segments of a shape's or an arm's trail.
pub const TRAIL_EVERY: usize = 25;

/// A path logged a segment at a time (the layout shows every segment up to the time cursor):
/// the points since the last segment, the last of which starts the next.
#[derive(Debug, Clone, Default)]
pub struct Trail {
    points: Vec<[f32; 2]>,
}

impl Trail {
    /// A trail from `start`.
    pub fn from(start: [f32; 2]) -> Self {
        Self {
            points: vec![start],
        }
    }

    /// Adds `point`; when `due`, returns the segment to log (and keeps its last point).
    pub fn push(&mut self, point: [f32; 2], due: bool) -> Option<Vec<[f32; 2]>> {
        self.points.push(point);
        if !due {
            return None;
        }
        let segment = std::mem::take(&mut self.points);
        self.points.push(*segment.last().expect("a point"));
        Some(segment)
    }
}

/// One series of a plot: its label, whether an owner has it, and its value after a step.
pub struct Series<Owner, State> {
    /// Its label in the viewer.
    pub label: &'static str,
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

/// Every agent's plots, in the order of the views.
pub const AGENT_PLOTS: &[Plot<Agent, AgentState>] = &[
    Plot {
        key: "distance",
        piecewise_constant: false,
        view: "distance to target (m)",
        series: &[Series {
            label: "distance to target (m)",
            shown: always,
            value: |_, s| s.distance,
        }],
    },
    Plot {
        key: "speed",
        piecewise_constant: false,
        view: "speed (m/s)",
        series: &[
            Series {
                label: "speed (m/s)",
                shown: always,
                value: |_, s| s.velocity.norm(),
            },
            Series {
                label: "speed along the guidance (m/s)",
                shown: always,
                value: |_, s| s.radial_speed,
            },
        ],
    },
    Plot {
        key: "force",
        piecewise_constant: false,
        view: "control force (N)",
        series: &[
            Series {
                label: "|F| (N)",
                shown: always,
                value: |_, s| s.force.norm(),
            },
            Series {
                label: "Fx (N)",
                shown: always,
                value: |_, s| s.force.x,
            },
            Series {
                label: "Fy (N)",
                shown: always,
                value: |_, s| s.force.y,
            },
        ],
    },
    Plot {
        key: "potential",
        piecewise_constant: false,
        view: "potential V",
        series: &[Series {
            label: "V",
            shown: always,
            value: |_, s| s.potential,
        }],
    },
    Plot {
        key: "limits",
        piecewise_constant: true,
        view: "limits active (0/1)",
        series: &[
            Series {
                label: "clamping active",
                shown: |a| a.controller.clamp.is_some(),
                value: |_, s| flag(s.clamping),
            },
            Series {
                label: "speed limit active",
                shown: |a| a.controller.speed_limit.is_some() || a.controller.brake.is_some(),
                value: |_, s| flag(s.speed_limited),
            },
            Series {
                label: "clearance envelope active",
                shown: |a| a.drive.is_none() && a.controller.envelope_damping(a.mass).is_some(),
                value: |_, s| flag(s.enveloped),
            },
        ],
    },
    Plot {
        key: "wheel_speeds",
        piecewise_constant: false,
        view: "wheel speeds (m/s)",
        series: &[
            Series {
                label: "left wheel (m/s)",
                shown: |a| a.drive.is_some(),
                value: |_, s| s.wheels.map_or(0.0, |w| w.speeds[0]),
            },
            Series {
                label: "right wheel (m/s)",
                shown: |a| a.drive.is_some(),
                value: |_, s| s.wheels.map_or(0.0, |w| w.speeds[1]),
            },
        ],
    },
    Plot {
        key: "wheel_forces",
        piecewise_constant: false,
        view: "wheel forces (N)",
        series: &[
            Series {
                label: "left wheel (N)",
                shown: |a| a.drive.is_some(),
                value: |_, s| s.wheels.map_or(0.0, |w| w.forces[0]),
            },
            Series {
                label: "right wheel (N)",
                shown: |a| a.drive.is_some(),
                value: |_, s| s.wheels.map_or(0.0, |w| w.forces[1]),
            },
            Series {
                label: "grip (N)",
                shown: |a| a.drive.is_some(),
                value: |_, s| s.wheels.map_or(0.0, |w| w.lateral_force),
            },
        ],
    },
    Plot {
        key: "heading",
        piecewise_constant: false,
        view: "heading (rad)",
        series: &[Series {
            label: "heading (rad)",
            shown: |a| a.drive.is_some(),
            value: |_, s| s.axle.map_or(0.0, |(_, h)| h),
        }],
    },
    Plot {
        key: "bias",
        piecewise_constant: true,
        view: "bias β (N)",
        series: &[
            Series {
                label: "β x (N)",
                shown: |a| a.controller.bias.is_some(),
                value: |_, s| s.beta.map_or(0.0, |b| b.x),
            },
            Series {
                label: "β y (N)",
                shown: |a| a.controller.bias.is_some(),
                value: |_, s| s.beta.map_or(0.0, |b| b.y),
            },
        ],
    },
];

/// Every shaped agent's plots, in the order of the views.
pub const SHAPED_PLOTS: &[Plot<Agent, ShapedState>] = &[
    Plot {
        key: "distance",
        piecewise_constant: false,
        view: "shape: distance to target (m)",
        series: &[Series {
            label: "distance to target (m)",
            shown: always,
            value: |_, s| s.distance,
        }],
    },
    Plot {
        key: "heading",
        piecewise_constant: false,
        view: "shape: heading θ (rad)",
        series: &[
            Series {
                label: "θ (rad)",
                shown: always,
                value: |_, s| s.pose[2],
            },
            Series {
                label: "θ − θ_T (rad)",
                shown: |a| a.target_heading.is_some(),
                value: |_, s| s.heading_error.unwrap_or(0.0),
            },
        ],
    },
    Plot {
        key: "speed",
        piecewise_constant: false,
        view: "shape: speed (m/s, rad/s)",
        series: &[
            Series {
                label: "speed (m/s)",
                shown: always,
                value: |_, s| s.velocity.norm(),
            },
            Series {
                label: "angular speed (rad/s)",
                shown: always,
                value: |_, s| s.angular_velocity,
            },
        ],
    },
    Plot {
        key: "control",
        piecewise_constant: false,
        view: "shape: control (N, N·m)",
        series: &[
            Series {
                label: "|F| (N)",
                shown: always,
                value: |_, s| s.force.norm(),
            },
            Series {
                label: "τ (N·m)",
                shown: always,
                value: |_, s| s.torque,
            },
        ],
    },
    Plot {
        key: "clearance",
        piecewise_constant: false,
        view: "shape: clearance (m)",
        series: &[Series {
            label: "shape to nearest wall (m)",
            shown: always,
            value: |_, s| s.clearance,
        }],
    },
];

/// Every pendulum's plots, in the order of the views.
pub const PENDULUM_PLOTS: &[Plot<Pendulum, PendulumState>] = &[
    Plot {
        key: "theta",
        piecewise_constant: false,
        view: "pendulum angle θ (rad)",
        series: &[
            Series {
                label: "θ (rad)",
                shown: always,
                value: |_, s| s.theta,
            },
            Series {
                label: "θ_T (rad)",
                shown: always,
                value: |p, _| p.target,
            },
        ],
    },
    Plot {
        key: "torque",
        piecewise_constant: false,
        view: "torque u (N·m)",
        series: &[Series {
            label: "u (N·m)",
            shown: always,
            value: |_, s| s.torque,
        }],
    },
    Plot {
        key: "bias",
        piecewise_constant: true,
        view: "bias β (N·m)",
        series: &[Series {
            label: "β (N·m)",
            shown: always,
            value: |_, s| s.beta,
        }],
    },
];
