//! One agent's life in a step, in the order the step loop calls it:
//!
//! 1. [`AgentRun::plan`]: read the body's state from Rapier, take a sensor reading if one is
//!    due, and decide whether the field must be rebuilt (a reading, or a replan with the other
//!    agents where they are now).
//! 2. [`AgentRun::resolve`]: re-solve a harmonic field that is due. It reads only the agent's
//!    own plan and last field, so the loop runs it for all agents in parallel.
//! 3. [`AgentRun::apply`]: install the new field, compute the control force from the guidance
//!    and the state, and give it to Rapier (after resetting the body's forces: Rapier's user
//!    forces persist across steps).
//! 4. [`AgentRun::observe`]: after Rapier's step, read the state back, count contact starts,
//!    watch for faults, update the metrics, and report the step as an [`AgentState`].
//!
//! What a step produces along the way (fault events, control notes, the sensed walls) is kept
//! in the agent until `observe` hands it out.

use std::collections::HashSet;

use nalgebra::Vector2;
use rapier2d::prelude::{ColliderHandle, PhysicsWorld};

use super::body::{Body, DiscBody, Sensed, control};
use super::drive::{DriveBody, DriveMetrics, DriveSummary, Wheels};
use super::faults::{FaultMonitor, Observation};
use super::lidar::Lidar;
use super::physics::{self, from_rapier};
use super::{CONTACT_TOLERANCE, Sensor, WallIndex};
use crate::control::{
    ControlOutput, Controller, ENVELOPE_MARGIN, Envelope, Enveloped, Neighbour, Orca, Step, Sweep,
    unit,
};
use crate::field::{
    Beam, Disc, FieldError, GuidanceField, HarmonicField, KnownMap, Streamline, WAY_AHEAD, Way,
};
use crate::metrics::{Metrics, Summary};
use crate::world::{Agent, ControllerKind, GuidanceKind, Replan, SensorKind, WallShape, World};

/// One agent in a running simulation.
pub struct AgentRun {
    /// The agent as the world file describes it.
    pub agent: Agent,
    /// Its guidance field: of the true walls, or of the last sensed walls with a sensor (and
    /// the other agents where they were at the last replan).
    pub field: GuidanceField,
    /// With local replanning: its harmonic field of the walls alone, which every replan's
    /// window is solved on.
    walls: Option<HarmonicField>,
    /// With local replanning: its last field solved over the whole grid with the others in
    /// it, and when (s): the starting guess of the next one while it is recent.
    last_whole: Option<(HarmonicField, f64)>,
    /// Where it and the others were (its position and their discs) when its field was last
    /// re-solved among them: in a crowd parked on its targets, a replan where none has moved
    /// since is skipped (see [`STILL`]).
    solved_among: Option<(Vector2<f64>, Vec<Disc>)>,
    /// Its wall sensor, if it senses the walls with noise.
    pub sensor: Option<Sensor>,
    /// Whether its guidance is the gradient law, whose curvature the integrator uses (four
    /// more samples of the field a step, so only then).
    gradient_guidance: bool,
    /// Its lidar and the map it builds, if it has one.
    pub lidar: Option<LidarRun>,
    /// Its kinematic path (the streamline from its start).
    pub kinematic: Streamline,
    /// Its controller.
    pub controller: Controller<2>,
    /// ORCA, when its controller is `orca`: the velocity its controller tracks.
    pub orca: Option<Orca>,
    /// Its metrics so far.
    pub metrics: Metrics,
    /// Its numerical faults so far.
    pub faults: FaultMonitor,
    body: AgentBody,
    /// With wheels: what they measured so far.
    pub drive: Option<DriveMetrics>,
    collider: ColliderHandle,
    /// The colliders it touched after the last step.
    touching: HashSet<ColliderHandle>,
    /// Set once its state became non-finite: no control from then on.
    frozen: bool,
    /// Whether the last rebuild of its field failed (noted once until one succeeds).
    rebuild_failed: bool,
    /// The last sensor reading: how far each wall is sensed outside its true position, m.
    offsets: Vec<f64>,
    /// The error of the agent's estimate of its position since the last reading, m.
    position_error: Vector2<f64>,
    /// Replans so far (the first field counts as one).
    replans: usize,
    /// Its clearance envelope (a disc with `envelope` on).
    envelope: Option<Envelope>,
    /// The world's external acceleration, m/s² (the envelope compensates it).
    external: Vector2<f64>,
    /// What the current step has produced so far.
    log: StepLog,
    /// A force commanded from outside (see [`AgentRun::command`]), N.
    command: Option<Vector2<f64>>,
    /// The plan of the last step whose re-solve for the lidar's new walls was put off while
    /// the body was commanded (see [`AgentRun::bring_up_to_date`]).
    put_off: Option<Plan>,
    /// Its way: the next metres of its guidance at the last replan, which the agents after it
    /// give way to (see `field/yielding.rs`).
    way: Option<Way>,
    /// Whether its field is one that takes it out of another's way.
    yielding: bool,
    /// Whether it has come within its band of the target (once is enough: from then on it
    /// gives way to every agent that has not).
    arrived: bool,
}

/// An agent's body: a disc pushed in any direction, or a robot on wheels steered by its
/// look-ahead point (the agent's position, to everything that plans or measures).
enum AgentBody {
    Disc(DiscBody),
    Drive(DriveBody),
}

impl AgentBody {
    fn state(&self, physics: &PhysicsWorld) -> Option<([f64; 2], Vector2<f64>)> {
        match self {
            Self::Disc(b) => b.state(physics),
            Self::Drive(b) => b.state(physics),
        }
    }

    /// Applies `force` for the next step; a drive's wheels report what they did.
    fn actuate(&self, physics: &mut PhysicsWorld, force: &Vector2<f64>) -> Option<Wheels> {
        match self {
            Self::Disc(b) => {
                b.actuate(physics, force);
                None
            }
            Self::Drive(b) => {
                let wheels = b.wheels(physics, force);
                b.apply(physics, &wheels);
                Some(wheels)
            }
        }
    }
}

/// A lidar agent's sensor and what it knows.
pub struct LidarRun {
    /// The lidar.
    pub lidar: Lidar,
    /// The map built from its scans.
    pub map: KnownMap,
    /// When the known map closed every route to the target, s (in a world with moving
    /// obstacles: when it last did, if no route has opened since).
    pub intractable_at: Option<f64>,
    /// Fields solved on the map so far (the first one counts).
    pub fields: usize,
    /// Whether it scans on, standing still, while its map closes every route: in a world with
    /// moving obstacles what closes a route (a shut door, a cart) may move away again; in a
    /// still world it is final and the agent stops for good.
    pub keeps_looking: bool,
}

/// What one step produces for the recording, collected from `plan` to `observe`.
#[derive(Default)]
struct StepLog {
    control: Option<ControlOutput<2>>,
    events: Vec<String>,
    notes: Vec<String>,
    sensed_walls: Option<Vec<[f64; 2]>>,
    scan: Option<Vec<Beam>>,
    wheels: Option<Wheels>,
    enveloped: bool,
    /// The order of way changed its field (see [`Replanned`]).
    turned: bool,
    /// Its field was solved anew in this step.
    replanned: bool,
}

/// An agent's part of a step, read before any field is re-solved.
#[derive(Clone)]
pub struct Plan {
    /// Position at the start of the step.
    x: Vector2<f64>,
    /// Velocity at the start of the step.
    v: Vector2<f64>,
    /// Whether its sensor took a reading this step.
    sensed_now: bool,
    /// The time at the start of the step, s.
    time: f64,
    /// The other agents' discs.
    others: Vec<Disc>,
    /// The other agents with their velocities, for ORCA (empty for the other controllers).
    neighbours: Vec<Neighbour>,
    /// Whether its field is rebuilt this step (a harmonic one is re-solved, in parallel).
    rebuild: bool,
    /// Whether what the walls' part of the field is solved from changed (a sensor reading,
    /// the lidar's map), so a local replan must re-solve that part too.
    walls_changed: bool,
    /// Which of `others` are the agents after this one, which give way to it.
    after: Vec<usize>,
    /// The ways of the agents before this one, which it gives way to (when it rebuilds).
    ways: Vec<Way>,
}

/// What an agent knows of another for the order of way: its way and its
/// [`AgentRun::right_of_way`].
pub type CrowdMember = (Option<Way>, (bool, usize));

/// A re-solved field, the field of the walls it was solved on when that was re-solved too,
/// how the order of way made it, and the way it gives the agent.
pub struct Replanned {
    field: HarmonicField,
    walls: Option<HarmonicField>,
    /// The field solved over the whole grid among the others for a local replan (the window
    /// cut off, or turned back), if one was.
    whole_among: Option<HarmonicField>,
    /// It takes the agent out of another's way.
    yielded: bool,
    /// The order of way chose it (a yield, or a field past the agents after this one): the
    /// agent may turn about on it, by the rule and not at a critical point of its field.
    by_rule: bool,
    /// Solves over the whole grid it took (see [`Summary::whole_resolves`]).
    whole: usize,
    way: Option<Way>,
}

/// What happened to one agent in the last step, for recording.
#[derive(Debug, Clone, PartialEq)]
pub struct AgentState {
    /// Position, m.
    pub position: Vector2<f64>,
    /// Velocity, m/s.
    pub velocity: Vector2<f64>,
    /// The control force applied during the step, N.
    pub force: Vector2<f64>,
    /// Distance to the target, m.
    pub distance: f64,
    /// Speed along the guidance, `-uᵀv` with `u = ∇V/|∇V|` (the paper's "radial speed": the
    /// component of motion along the radial basis of the field's coordinates, figure 12), m/s.
    pub radial_speed: f64,
    /// The potential `V` at the position.
    pub potential: f64,
    /// Distance from the agent's disc to the nearest wall, m.
    pub clearance: f64,
    /// Points where the agent touches something, m.
    pub contact_points: Vec<Vector2<f64>>,
    /// Whether the clamping control acted in this step.
    pub clamping: bool,
    /// Whether the speed limit acted in this step.
    pub speed_limited: bool,
    /// Whether the clearance envelope changed the control force in this step.
    pub enveloped: bool,
    /// The bias β after this step, N (with the bias option).
    pub beta: Option<Vector2<f64>>,
    /// The configuration-space boundary of the walls sensed in this step (the centres of
    /// blocked cells next to free ones), m; `None` when no reading was taken.
    pub sensed_walls: Option<Vec<[f64; 2]>>,
    /// Faults and contacts that started in this step, as messages.
    pub events: Vec<String>,
    /// Control events of this step (bias updates, sensing), as messages.
    pub notes: Vec<String>,
    /// The lidar scan taken in this step, if any.
    pub scan: Option<Vec<Beam>>,
    /// With wheels: what they did in this step.
    pub wheels: Option<Wheels>,
    /// With wheels: the axle's centre, m, and the heading, rad, after this step.
    pub axle: Option<(Vector2<f64>, f64)>,
}

impl AgentRun {
    /// Puts the agent at `index` of `world` into `physics`, guided by `field` (with local
    /// replanning, on the field of the `walls` alone).
    pub(super) fn new(
        world: &World,
        index: usize,
        (field, walls): (GuidanceField, Option<HarmonicField>),
        physics: &mut PhysicsWorld,
    ) -> Self {
        let agent = &world.agents[index];
        let length = 4.0 * (world.size[0] + world.size[1]);
        let lidar = agent
            .sensor
            .filter(|s| s.kind == SensorKind::Lidar)
            .zip(field.harmonic())
            .map(|(settings, h)| LidarRun {
                lidar: Lidar::new(settings, world.seed, index),
                map: KnownMap::new(*h.grid()),
                intractable_at: None,
                fields: 1,
                keeps_looking: !world.obstacles.is_empty(),
            });
        // A lidar agent plans on what it sees; its kinematic path is the one with full
        // knowledge of the walls (empty if the true walls enclose its target).
        let kinematic = match &lidar {
            None => field.streamline(agent.start, length),
            Some(_) => match HarmonicField::solve(world, agent) {
                Ok(full) => full.streamline_within(agent.start, length),
                Err(_) => Streamline {
                    points: vec![agent.start],
                    reached: false,
                },
            },
        };
        let (body, collider) = physics::insert_agent(physics, agent);
        Self {
            controller: Controller::from_settings(
                &agent.controller,
                world.field.guidance,
                agent.mass,
            ),
            orca: (agent.controller.kind == ControllerKind::Orca).then(|| {
                let settings = agent.controller.orca.unwrap_or_default();
                Orca {
                    max_speed: agent.controller.speed_limit.unwrap_or(0.0),
                    time_horizon: settings.time_horizon,
                    neighbour_distance: settings.neighbour_distance,
                    capture_radius: agent.controller.capture_radius,
                }
            }),
            metrics: Metrics::new(&agent.name, agent.start, agent.target, world.distance_at),
            agent: agent.clone(),
            walls,
            last_whole: None,
            solved_among: None,
            field,
            sensor: agent
                .sensor
                .filter(|s| s.kind == SensorKind::Walls)
                .map(|settings| Sensor::new(settings, world.seed, index)),
            gradient_guidance: world.field.guidance == GuidanceKind::Gradient,
            lidar,
            kinematic,
            faults: FaultMonitor::default(),
            body: match agent.drive {
                None => AgentBody::Disc(DiscBody { handle: body }),
                Some(_) => AgentBody::Drive(DriveBody::new(
                    body,
                    agent,
                    world.dt,
                    world.external_acceleration,
                )),
            },
            drive: agent.drive.map(|_| DriveMetrics::default()),
            collider,
            touching: HashSet::new(),
            frozen: false,
            rebuild_failed: false,
            offsets: Vec::new(),
            position_error: Vector2::zeros(),
            replans: 1,
            envelope: (agent.drive.is_none())
                .then(|| agent.controller.envelope_damping(agent.mass))
                .flatten()
                .map(|damping| Envelope {
                    damping,
                    mass: agent.mass,
                    radius: agent.radius,
                }),
            external: Vector2::from(world.external_acceleration),
            log: StepLog::default(),
            command: None,
            put_off: None,
            way: None,
            yielding: false,
            arrived: false,
        }
    }

    /// Its way at the last replan (see `field/yielding.rs`): what the agents after it keep
    /// out of; `None` before its first replan among others.
    pub fn way(&self) -> Option<&Way> {
        self.way.as_ref()
    }

    /// Its place in the order of way (see `field/yielding.rs`), for its `index` in the world:
    /// the agents that have not yet arrived first, in the world's order, then those that
    /// have. The lower goes first.
    pub fn right_of_way(&self, index: usize) -> (bool, usize) {
        (self.arrived, index)
    }

    /// Commands the force applied to the body from the next step on, N, instead of its control
    /// law's (which still runs, so that its own state moves on), until `None` gives control
    /// back: a policy other than the law drives the body (from Python, say). The clearance
    /// envelope, when on, still keeps the commanded body from touching a wall, and the speed
    /// limit does not apply. While commanded, a lidar agent's field is not re-solved at each
    /// change of its map (the law runs on the field it has): the change is solved for when
    /// the field is read ([`AgentRun::bring_up_to_date`]: the law's force, the field's
    /// arrays), at the next replan among others, or when control comes back. A force that is
    /// not finite is refused (`false`), as is any force for a robot on wheels under the
    /// unicycle law, which commands its wheels itself.
    pub fn command(&mut self, force: Option<Vector2<f64>>) -> bool {
        let unicycle = self.agent.controller.kind == ControllerKind::Unicycle;
        if force.is_some_and(|f| !f.iter().all(|c| c.is_finite()) || unicycle) {
            return false;
        }
        self.command = force;
        true
    }

    /// Whether it keeps the clearance envelope.
    pub fn has_envelope(&self) -> bool {
        self.envelope.is_some()
    }

    /// Its collider (a lidar excludes it from its own scans).
    pub fn collider(&self) -> ColliderHandle {
        self.collider
    }

    /// Its summary so far.
    pub fn summary(&self) -> Summary {
        let mut summary = self.metrics.summary(&self.kinematic, &self.faults.faults);
        if let Some(run) = &self.lidar {
            summary.intractable = run.intractable_at;
            summary.map_seen = Some(run.map.seen_fraction());
        }
        summary
    }

    /// Its disc and velocity where it is now (where it last was, at rest, if Rapier's state is
    /// not finite): an obstacle in the other agents' fields, a neighbour for ORCA.
    pub(super) fn body(&self, physics: &PhysicsWorld) -> Neighbour {
        // A robot on wheels is its look-ahead point with the disc that holds it all.
        let (p, v) = self
            .body
            .state(physics)
            .map_or((self.last_position(), Vector2::zeros()), |(p, v)| {
                (Vector2::from(p), v)
            });
        Neighbour {
            position: p,
            velocity: v,
            radius: self.agent.radius,
            reciprocal: true,
        }
    }

    /// With wheels: its summary beside the agent's.
    pub fn drive_summary(&self) -> Option<DriveSummary> {
        (self.drive.as_ref()).map(|d| d.summary(&self.agent.name, &self.kinematic))
    }

    /// The disc that collides, m: the agent's (a robot on wheels: its footprint at its axle,
    /// not the look-ahead point's larger disc).
    fn footprint(&self, physics: &PhysicsWorld, position: Vector2<f64>) -> (Vector2<f64>, f64) {
        match (&self.body, &self.agent.drive) {
            (AgentBody::Drive(b), Some(d)) => (b.axle(physics), d.body_radius),
            _ => (position, self.agent.radius),
        }
    }

    /// Step 1: reads the state, takes a sensor reading of the `walls` if one is due at `time`
    /// (s), and decides whether the field is rebuilt with the `others` where they are now
    /// (an ORCA agent's field has the walls only: ORCA steers it among the others). The
    /// `others` are the agents but this one, at `index` of the `crowd` (every agent's way and
    /// [`AgentRun::right_of_way`]), in order, then the moving obstacles.
    pub(super) fn plan(
        &mut self,
        physics: &PhysicsWorld,
        time: f64,
        (world, walls): (&World, &[WallShape]),
        others: Vec<Neighbour>,
        (index, crowd): (usize, &[CrowdMember]),
    ) -> Plan {
        // The last whole field is kept only while it may serve as a starting guess: held
        // past that it costs as much memory as the agent's own field (measured: 64 robots on
        // a 39 m grid, 117 MB), and a crowd parked on its targets replans no more to drop it.
        if (self.last_whole.as_ref()).is_some_and(|(_, at)| time - at >= WARM_FOR) {
            self.last_whole = None;
        }
        let (x, v) = self.read_state(physics);
        let mut plan = Plan {
            x,
            v,
            sensed_now: false,
            time,
            others: Vec::new(),
            neighbours: Vec::new(),
            rebuild: false,
            walls_changed: false,
            after: Vec::new(),
            ways: Vec::new(),
        };
        if self.frozen {
            return plan;
        }
        plan.sensed_now = match &mut self.sensor {
            Some(sensor) if sensor.due(time) => {
                self.offsets = sensor.read(walls.len());
                self.position_error = Vector2::from(sensor.position_error());
                // Without wall noise a reading changes nothing the field is solved from.
                sensor.settings.noise > 0.0
            }
            _ => false,
        };
        let replan_hz = world.field.replan_hz;
        let replan_due = self.orca.is_none()
            && !others.is_empty()
            && replan_hz > 0.0
            && time + 1e-9 >= self.replans as f64 / replan_hz;
        if replan_due {
            self.replans += 1;
        }
        let mut map_changed = false;
        if let Some(run) = &mut self.lidar
            && (run.intractable_at.is_none() || run.keeps_looking)
            && run.lidar.due(time)
        {
            let to_target = Vector2::from(self.agent.target) - x;
            let heading = to_target.y.atan2(to_target.x);
            let beams = run.lidar.scan(physics, x.into(), heading, self.collider);
            map_changed = run.map.update(&beams);
            self.log.scan = Some(beams);
        }
        if self.orca.is_some() {
            plan.neighbours = self.grown_for_orca(others, world.dt);
        } else {
            // Each other agent's disc is grown by how far it moves before the next replan, so
            // the field keeps the agent off where the other will be, not only where it is
            // (the disc stays clear of the agent itself).
            // (An attractive-repulsive field sees them anew every step.)
            let replanned = replan_hz > 0.0 && self.field.harmonic().is_some();
            let horizon = if replanned { 1.0 / replan_hz } else { 0.0 };
            plan.others = others
                .iter()
                .map(|n| {
                    let disc = Disc {
                        center: n.position.into(),
                        radius: n.radius,
                    };
                    let by = n.velocity.norm() * horizon;
                    disc.grown(by, (&self.agent, x.into()), world.field.cell)
                })
                .collect();
        }
        // A re-solve put off while commanded is due with this one, or now control is back.
        let put_off = self.put_off.take().is_some();
        plan.walls_changed = plan.sensed_now || map_changed || put_off;
        // A crowd parked on its targets: every agent has arrived, this one is in its band,
        // and nothing moved since its field was last solved among the others, so a re-solve
        // would give the field it has (they were re-solved ten times a second to the end of
        // the run). Not a crowd stuck short of its targets: there a replan may change who
        // gives way (measured: skipping every replan where nothing moved froze a door swap
        // of 16 robots with 13 short of their targets, where 15 arrive otherwise).
        let parked = || {
            (Vector2::from(self.agent.target) - x).norm() <= self.metrics.band()
                && crowd.iter().all(|(_, (arrived, _))| *arrived)
        };
        let still = |(x0, discs): &(Vector2<f64>, Vec<Disc>)| {
            let by = STILL * world.field.cell;
            (x - x0).norm() <= by
                && discs.len() == plan.others.len()
                && discs.iter().zip(&plan.others).all(|(a, b)| {
                    let moved = (a.center[0] - b.center[0]).hypot(a.center[1] - b.center[1]);
                    moved <= by && (a.radius - b.radius).abs() <= by
                })
        };
        let skipped = replan_due && parked() && self.solved_among.as_ref().is_some_and(still);
        plan.rebuild = plan.walls_changed || (replan_due && !skipped);
        if plan.rebuild && index < crowd.len() {
            // Agent k is `others[k]` before this one and `others[k - 1]` after it.
            let mine = crowd[index].1;
            let before = |k: usize| k != index && crowd[k].1 < mine;
            plan.ways = (0..crowd.len())
                .filter(|&k| before(k))
                .filter_map(|k| crowd[k].0.clone())
                .collect();
            plan.after = (0..crowd.len())
                .filter(|&k| k != index && !before(k))
                .map(|k| if k < index { k } else { k - 1 })
                .collect();
        }
        if plan.rebuild && !replan_due && !plan.sensed_now && self.command.is_some() {
            // Commanded, the body goes where the policy sends it whatever its field: the
            // lidar's new walls are solved for when the law's force is asked for or control
            // comes back (a policy trained on the scans alone never pays for a field).
            self.put_off = Some(plan.clone());
            plan.rebuild = false;
            plan.walls_changed = false;
        }
        plan
    }

    /// Re-solves its field for the lidar's walls seen while it was commanded, if that was
    /// put off (see [`AgentRun::command`]): the field of the last step's plan, the one that
    /// step would have solved, so the law's force ([`AgentRun::law_force`]) and the field read
    /// now are what they would be had nothing been put off.
    pub fn bring_up_to_date(&mut self, world: &World) {
        if let Some(plan) = self.put_off.take() {
            let solved = self.resolve(&plan, world);
            self.update_field(plan, solved);
        }
    }

    /// Step 2: the harmonic field re-solved for `plan`, if it is due (warm-started from the
    /// last one); `None` when nothing is re-solved. Reads only this agent, so agents run it in
    /// parallel.
    ///
    /// With `field.replan = "full"` the whole field is re-solved with the others in it. With
    /// `"local"` (the default) the field of the walls is re-solved only when they were sensed
    /// anew, and the others go into a window around the agent ([`HarmonicField::with_window`]).
    ///
    /// A window cut off from the target or the field's way on (see [`HarmonicField::with_window`])
    /// falls back to the full re-solve for that replan.
    ///
    /// An agent stuck among the others gives way to the agents before it or plans past the
    /// ones after it, by the rule of `field/yielding.rs`; the new field's way is published for
    /// the agents after it.
    pub(super) fn resolve(
        &self,
        plan: &Plan,
        world: &World,
    ) -> Option<Result<Replanned, FieldError>> {
        let GuidanceField::Harmonic(field) = &self.field else {
            return None;
        };
        if !plan.rebuild {
            return None;
        }
        let local = world.field.replan == Replan::Local;
        // Solves over the whole grid, counted (see `Summary::whole_resolves`).
        let whole = std::cell::Cell::new(0);
        // A whole field among the others starts from the last one solved among them while that
        // is recent (the others moved little since; `plan` drops it after that), else from the
        // last field, whose values over the whole grid are the walls' alone with local
        // replanning (measured: 64 robots on a 1.8 m circle, a tenth less time in these solves).
        let warm = |others: &[Disc]| {
            (self.last_whole.as_ref())
                .filter(|_| !others.is_empty())
                .map_or(field, |(f, _)| f)
        };
        // The whole field solved among the others for a local replan, if one was.
        let whole_among = std::cell::RefCell::new(None);
        let solve = |others: &[Disc]| {
            whole.set(whole.get() + 1);
            match &self.lidar {
                Some(run) => HarmonicField::solve_known(
                    world,
                    &self.agent,
                    plan.x.into(),
                    &run.map,
                    others,
                    Some(warm(others)),
                ),
                None => HarmonicField::solve_among(
                    world,
                    &self.agent,
                    plan.x.into(),
                    &self.offsets,
                    others,
                    Some(warm(others)),
                ),
            }
        };
        // The field of the walls: solved again when they were sensed anew, else the one kept,
        // with the last window (whose work the new one may reuse) if the field has one.
        let (walls, new_walls) = match &self.walls {
            _ if !local => (field.clone(), None),
            Some(walls) if !plan.walls_changed => (
                HarmonicField {
                    window: field.window.clone(),
                    ..walls.clone()
                },
                None,
            ),
            _ => match solve(&[]) {
                Ok(walls) => (walls.clone(), Some(walls)),
                Err(e) => return Some(Err(e)),
            },
        };
        // The field among the discs `others`: in a window on the field of the walls, or the
        // whole field when the window is cut off or its way on is blocked in it (whether a
        // detour exists beyond the window, and which, only the whole field can say).
        let whole_among_others = |others: &[Disc]| {
            let whole = solve(others);
            if let Ok(f) = &whole {
                *whole_among.borrow_mut() = Some(f.clone());
            }
            whole
        };
        let x: [f64; 2] = plan.x.into();
        let among = |others: &[Disc]| {
            if !local {
                solve(others)
            } else if others.is_empty() {
                Ok(walls.without_window())
            } else {
                match walls.with_window(&self.agent, x, others, &world.field) {
                    Err(FieldError::Unreachable { .. }) => whole_among_others(others),
                    // A window whose guidance at the agent turns back on the last field's:
                    // the window moved with the agent and the field of the walls on its edge
                    // disagrees with the others beyond it (at a crowd parked by a door, the
                    // agent turns back and forth between two windows for good). Which way is
                    // right only a field over the whole grid can say: in a room wider than
                    // the coarse window, the wide window (the whole grid's field among the
                    // others at the coarse cell on its edge, a sixteenth of the cells), which
                    // has no edge that moves with the agent; else the whole field (where the
                    // coarse window covers the room, the wide window is the window's own
                    // problem again: two groups swapping through a door, one robot of 16
                    // livelocked when it decided there).
                    Ok(window) if turns_back(field, &window, plan.x) => {
                        match walls.with_wide_window(&self.agent, x, others, &world.field) {
                            Some(Ok(wide)) => Ok(wide),
                            _ => whole_among_others(others),
                        }
                    }
                    result => result,
                }
            }
        };
        // The replanned field with the way it gives (computed here unless `way` has it).
        let done = |field: HarmonicField, way: Option<Way>, (yielded, by_rule): (bool, bool)| {
            let way = way.unwrap_or_else(|| way_of(&field, plan.x, self.agent.radius));
            Ok(Replanned {
                field,
                walls: new_walls.clone(),
                whole_among: whole_among.borrow().clone(),
                yielded,
                by_rule,
                whole: whole.get(),
                way: Some(way),
            })
        };
        let first = among(&plan.others);
        let first_way = first
            .as_ref()
            .ok()
            .map(|f| way_of(f, plan.x, self.agent.radius));
        // Stuck among the others (see `field/yielding.rs`): they close every way, or the way
        // the field gives runs into one of them (one at the agent's skin).
        let cell = world.field.cell;
        let unreachable = matches!(first, Err(FieldError::Unreachable { .. }));
        let stuck = match &first_way {
            None => unreachable && !plan.others.is_empty(),
            Some(way) => plan.others.iter().any(|d| way.runs_into(d, cell)),
        };
        let me = Disc {
            center: plan.x.into(),
            radius: self.agent.radius,
        };
        // An agent before it planned past it (it is after that one, or on its target): its way
        // comes within the envelope's margin of this disc, so the envelope would stop that
        // agent here. The way's own overlap with the disc is no measure of it: a field threads
        // a gap between two neighbours at its skin narrower than the two discs (they are
        // shrunk there, see `obstacle_discs`), and an agent held in such a gap is held for good
        // unless the neighbours give way (measured: two groups swapping through a door, 4 of 16
        // robots in with the one-cell slack of `stuck`, 16 of 16 with this one).
        let overrun = plan.ways.iter().any(|w| w.runs_into(&me, -ENVELOPE_MARGIN));
        // A yielding agent goes on yielding while it stands in the way of an agent before it:
        // were it to take its own field back as soon as no way runs into it, it would step
        // back into the way and be overrun again at the next replan (at a group parked by a
        // door, the robots in front of it went back and forth by centimetres for good).
        // The ways of the agents before it that it stands in: only looked for when they can
        // matter (every agent's replan passes here; most are neither yielding nor stuck).
        let blocked: Vec<&Way> = if self.yielding || stuck || overrun {
            plan.ways.iter().filter(|w| w.in_the_way(&me)).collect()
        } else {
            Vec::new()
        };
        let still_in_the_way = self.yielding && !blocked.is_empty();
        // And a yielding agent out of the ways waits where its yield took it while its own
        // target stands in the way of an agent before it: its field would lead it straight back
        // into that way.
        let target = Disc {
            center: self.agent.target,
            radius: self.agent.radius,
        };
        if self.yielding
            && !stuck
            && !overrun
            && blocked.is_empty()
            && plan.ways.iter().any(|w| w.in_the_way(&target))
        {
            return Some(done(field.clone(), None, (true, true)));
        }
        if !stuck && !overrun && !still_in_the_way {
            return Some(first.and_then(|f| done(f, first_way, (false, false))));
        }
        if !blocked.is_empty() && self.lidar.is_none() {
            let others = (self.offsets.as_slice(), plan.others.as_slice());
            if let Ok(aside) = HarmonicField::yielding(
                world,
                (&self.agent, self.arrived),
                plan.x.into(),
                others,
                &blocked,
            ) {
                whole.set(whole.get() + 1);
                return Some(done(aside, None, (true, true)));
            }
        }
        if unreachable && !plan.after.is_empty() {
            // In no one's way: the agents after it give way to it.
            let before: Vec<Disc> = (plan.others.iter().enumerate())
                .filter(|(k, _)| !plan.after.contains(k))
                .map(|(_, d)| *d)
                .collect();
            return Some(among(&before).and_then(|f| done(f, None, (false, true))));
        }
        Some(first.and_then(|f| done(f, first_way, (false, false))))
    }

    /// Its remaining sweep at the start of the step of `plan` (see [`Envelope`]): its disc
    /// moved along its velocity for as far as it goes braking from it; without an envelope,
    /// as far as its velocity takes it in the step.
    pub(super) fn sweep(&self, plan: &Plan, step: Step) -> Sweep {
        match &self.envelope {
            Some(e) => e.remaining(plan.x, plan.v, step),
            None => self.bare_sweep(plan.x, plan.x + plan.v * step.dt),
        }
    }

    /// The sweep of a body without an envelope from `x` to where its step takes it, `to`:
    /// that one step, nothing after (a robot on wheels: the look-ahead point's disc, which
    /// holds its footprint).
    fn bare_sweep(&self, x: Vector2<f64>, to: Vector2<f64>) -> Sweep {
        Sweep {
            points: [x, to, to],
            radius: self.agent.radius,
        }
    }

    /// Step 3: installs the field `solved` for `plan`, computes the control force for a
    /// `step` and applies it to the body; the clearance envelope keeps it clear of the walls
    /// and of the `sweeps` of the agents (the ones before this agent's `index` for the step
    /// they have chosen, the others for their last), and this agent's sweep is then set to
    /// the step it takes.
    pub(super) fn apply(
        &mut self,
        mut plan: Plan,
        solved: Option<Result<Replanned, FieldError>>,
        physics: &mut PhysicsWorld,
        step: Step,
        (sweeps, index): (&mut [Sweep], usize),
    ) {
        let dt = step.dt;
        let (x, v) = (plan.x, plan.v);
        if !self.frozen {
            let neighbours = std::mem::take(&mut plan.neighbours);
            self.update_field(plan, solved);
            self.log.control = Some(self.control(x, v, dt, &neighbours));
            if self
                .lidar
                .as_ref()
                .is_some_and(|r| r.intractable_at.is_some())
                && let Some(control) = &mut self.log.control
            {
                // The task is intractable on what it has seen: it stops (in one step).
                control.force = -v * (self.agent.mass / dt);
            }
        }
        let mut force = self.log.control.map_or(Vector2::zeros(), |c| c.force);
        if let Some(commanded) = self.command.filter(|_| !self.frozen) {
            // Commanded from outside: the law ran (its state, a bias or a clamp, moves on as
            // if it were in control) but this force goes to the body instead.
            force = commanded;
            if let Some(control) = &mut self.log.control {
                control.force = commanded;
            }
        }
        let c = &self.agent.controller;
        match (&self.body, &self.agent.drive) {
            (AgentBody::Drive(body), Some(drive))
                if c.kind == ControllerKind::Unicycle && !self.frozen =>
            {
                // The peers' baseline commands the wheels itself, on the same field.
                let x = x + self.position_error;
                let guidance = self.field.gradient(x.into()).and_then(|g| unit(&-g));
                let distance = (x - Vector2::from(self.agent.target)).norm();
                let v_max = c.speed_limit.unwrap_or(drive.max_wheel_speed);
                let gains = (v_max, c.turn_gain.unwrap_or(2.0), c.capture_radius);
                let wheels = body.unicycle(physics, guidance, gains, distance);
                force = body.body_force(physics, &wheels);
                body.apply(physics, &wheels);
                self.log.wheels = Some(wheels);
            }
            _ => {
                if let Some(envelope) = self.envelope.filter(|_| !self.frozen) {
                    let out =
                        self.envelope(&envelope, physics, (x, v), force, step, (sweeps, index));
                    if out.bound {
                        self.log.enveloped = true;
                        self.metrics.record_envelope(dt);
                        if let Some(control) = &mut self.log.control {
                            control.force = out.force;
                        }
                    }
                    force = out.force;
                    sweeps[index] = out.sweep;
                } else {
                    let next = v + (force / self.agent.mass + self.external) * dt;
                    sweeps[index] = self.bare_sweep(x, step.moved(x, v, next));
                }
                if !self.frozen {
                    // What the body gets (a command, the envelope's force, the stop of an
                    // intractable task) is what the law's estimate of the external force
                    // must subtract: the difference to the law's own is no external force.
                    self.controller.applied_instead(&force);
                }
                self.log.wheels = self.body.actuate(physics, &force);
            }
        }
        self.metrics.record_force(force);
    }

    /// The envelope's force for a body at `x` moving at `v` whose law asks for `force`: a
    /// sweep is clear when it keeps the margin from the walls (its disc cast through Rapier's
    /// fixed colliders) and from the other agents' `sweeps` (all but its own, at `index`).
    fn envelope(
        &self,
        envelope: &Envelope,
        physics: &PhysicsWorld,
        state: (Vector2<f64>, Vector2<f64>),
        force: Vector2<f64>,
        step: Step,
        (sweeps, index): (&[Sweep], usize),
    ) -> Enveloped {
        let here = |sweep: &Sweep| Sweep {
            points: [sweep.points[0]; 3],
            radius: sweep.radius,
        };
        envelope.filter(force, state, self.external, step, |sweep| {
            // Keeping the margin, or (already nearer: Rapier resolves a step a little
            // differently) no nearer than it is: a body stopped at the margin may still move
            // along or away.
            let apart = sweeps.iter().enumerate().all(|(j, other)| {
                if j == index || !sweep.near(other, ENVELOPE_MARGIN) {
                    return true;
                }
                let d = sweep.distance(other);
                d >= ENVELOPE_MARGIN || d >= here(sweep).distance(other)
            });
            apart && physics::clear_of_walls(physics, sweep)
        })
    }

    /// Step 4: after Rapier's step that ended at `time` (s), reads the state back, counts
    /// contact starts, watches for faults against `walls` and the box `bounds`, measures the
    /// distance to the moving `obstacles` (their shapes now, with their colliders), and
    /// updates the metrics.
    pub(super) fn observe(
        &mut self,
        physics: &PhysicsWorld,
        time: f64,
        (walls, index, colliders): (&[WallShape], &WallIndex, &[ColliderHandle]),
        bounds: ([f64; 2], [f64; 2]),
        obstacles: &[(WallShape, ColliderHandle)],
    ) -> AgentState {
        let (position, velocity) = self.read_state(physics);
        let p: [f64; 2] = position.into();
        let radial_speed = self
            .field
            .gradient(p)
            .and_then(|g| unit(&g))
            .map_or(0.0, |u| -u.dot(&velocity));
        let (centre, radius) = self.footprint(physics, position);
        let (signed, nearest) = index.nearest_wall(walls, centre, radius);
        let clearance = signed.max(0.0);
        let faults = self.faults.observe(&Observation {
            field: &self.field,
            position,
            signed_clearance: signed,
            bounds,
            giving_way: self.yielding || self.log.turned,
            replanned: self.log.replanned,
        });
        self.log.events.extend(faults);
        // A disc at or inside a wall touches it, whatever Rapier's narrow phase has seen yet
        // (it runs at the start of a step, so it sees the end of this one only in the next).
        let overlapped = nearest.filter(|_| signed <= 0.0).map(|k| colliders[k]);
        let nearest_obstacle = (obstacles.iter())
            .map(|(shape, collider)| {
                let d = shape.signed_distance_to_point(centre.x, centre.y) - radius;
                (d, *collider)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((d, _)) = nearest_obstacle {
            self.metrics.record_obstacle_distance(d);
        }
        // Likewise an obstacle the disc is at or inside now.
        let on_obstacle = nearest_obstacle.filter(|(d, _)| *d <= 0.0).map(|(_, c)| c);
        let contact_points = self.contacts(physics, (centre, radius), overlapped, on_obstacle);
        if let (Some(metrics), Some(wheels)) = (&mut self.drive, self.log.wheels) {
            metrics.record(&wheels, centre);
        }
        self.metrics.record_state(time, position, velocity, signed);
        let distance = (position - Vector2::from(self.agent.target)).norm();
        self.arrived |= distance <= self.metrics.band();
        let log = std::mem::take(&mut self.log);
        let control = log.control;
        AgentState {
            position,
            velocity,
            force: control.map_or(Vector2::zeros(), |c| c.force),
            distance,
            radial_speed,
            potential: self.field.potential(p),
            clearance,
            contact_points,
            clamping: control.is_some_and(|c| c.clamping),
            speed_limited: control.is_some_and(|c| c.speed_limited),
            enveloped: log.enveloped,
            beta: self.controller.beta(),
            sensed_walls: log.sensed_walls,
            events: log.events,
            notes: log.notes,
            scan: log.scan,
            wheels: log.wheels,
            axle: match &self.body {
                AgentBody::Drive(b) => Some((centre, b.heading(physics))),
                AgentBody::Disc(_) => None,
            },
        }
    }

    /// The position and velocity Rapier has for the body. A state that is not finite freezes
    /// the body for the rest of the run (the fault is logged once) and reads as the last
    /// finite position at rest, so nothing non-finite reaches the controller or the metrics.
    fn read_state(&mut self, physics: &PhysicsWorld) -> (Vector2<f64>, Vector2<f64>) {
        if let Some((x, v)) = self.body.state(physics) {
            return (Vector2::from(x), v);
        }
        if !self.frozen {
            self.frozen = true;
            self.log.events.extend(self.faults.non_finite_state());
        }
        (self.last_position(), Vector2::zeros())
    }

    /// The last position recorded (the start before the first step).
    fn last_position(&self) -> Vector2<f64> {
        Vector2::from(*self.metrics.path().last().expect("starts at the start"))
    }

    /// Installs the re-solved harmonic field (keeping the last one, with a note, when the
    /// rebuild failed), or gives an attractive-repulsive field the new reading and the others.
    fn update_field(&mut self, plan: Plan, solved: Option<Result<Replanned, FieldError>>) {
        match (&mut self.field, solved) {
            (GuidanceField::Harmonic(field), Some(Ok(new))) => {
                *field = new.field;
                if new.yielded && !self.yielding {
                    self.log.notes.push(format!(
                        "stuck among the others in the way of an agent before it at t = {:.2} s; steps aside",
                        plan.time
                    ));
                }
                self.log.turned = new.by_rule || self.yielding;
                self.log.replanned = true;
                self.yielding = new.yielded;
                self.way = new.way;
                if let Some(walls) = new.walls {
                    self.walls = Some(walls);
                    self.last_whole = None;
                }
                if let Some(whole) = new.whole_among {
                    self.last_whole = Some((whole, plan.time));
                }
                self.solved_among = Some((plan.x, plan.others.clone()));
                self.rebuild_failed = false;
                self.metrics.record_resolve(new.whole);
                if let Some(run) = &mut self.lidar {
                    run.fields += 1;
                    if run.intractable_at.take().is_some() {
                        self.log.notes.push(format!(
                            "a route to the target is open again at t = {:.2} s; going on",
                            plan.time
                        ));
                    }
                }
                if plan.sensed_now {
                    self.log.sensed_walls = Some(boundary(field));
                }
            }
            (GuidanceField::Harmonic(_), Some(Err(e)))
                if self.lidar.is_some()
                    && matches!(
                        e,
                        FieldError::Unreachable { .. } | FieldError::TargetBlocked { .. }
                    ) =>
            {
                if let Some(run) = &mut self.lidar
                    && run.intractable_at.is_none()
                {
                    run.intractable_at = Some(plan.time);
                    let then = if run.keeps_looking {
                        "waiting for the moving obstacles to open one"
                    } else {
                        "stopping"
                    };
                    self.log.events.push(format!(
                        "intractable at t = {:.2} s: the walls seen so far close every route to the target ({e}); {then}",
                        plan.time
                    ));
                }
            }
            (GuidanceField::Harmonic(field), Some(Err(e))) => {
                // The field kept is the way it goes on.
                self.way = Some(way_of(field, plan.x, self.agent.radius));
                if !self.rebuild_failed {
                    self.log.notes.push(format!(
                        "the sensed walls and the other agents give no usable field ({e}); keeping the last one"
                    ));
                }
                self.rebuild_failed = true;
            }
            (GuidanceField::AttractiveRepulsive(field), _) => {
                if plan.sensed_now {
                    field.sense(&self.offsets);
                }
                field.set_others(plan.others);
            }
            (GuidanceField::Harmonic(_), None) => {}
        }
    }

    /// The control force at position `x` and velocity `v`, from the current field, as the
    /// controller sees them (the position through the sensor's position error); an ORCA
    /// agent's among its `neighbours`.
    fn control(
        &mut self,
        x: Vector2<f64>,
        v: Vector2<f64>,
        dt: f64,
        neighbours: &[Neighbour],
    ) -> ControlOutput<2> {
        let (x, sensed) = self.sensed(x, v, dt);
        let reference = self.reference(x, v, dt, neighbours);
        let (out, rejected) = control(
            &self.field,
            |input| self.controller.step(input),
            x.into(),
            sensed,
            reference,
        );
        if rejected {
            self.log.events.extend(self.faults.rejected_force());
        }
        if out.bias_updated
            && let Some(beta) = self.controller.beta()
        {
            self.metrics.record_bias_update();
            self.log.notes.push(format!(
                "settling instant at distance {:.4} m: β ← holding force = [{:.4}, {:.4}] N (update {})",
                (x - Vector2::from(self.agent.target)).norm(),
                beta.x,
                beta.y,
                self.controller.bias.as_ref().map_or(0, |b| b.updates())
            ));
        }
        out
    }

    /// What its law sees of a body at `x` moving at `v` for a step of `dt`: the position
    /// through the sensor's position error, and the rest of the state.
    fn sensed(&self, x: Vector2<f64>, v: Vector2<f64>, dt: f64) -> (Vector2<f64>, Sensed<2>) {
        let sensed = Sensed {
            velocity: v,
            dt,
            touching: !self.touching.is_empty(),
            curvature: self.gradient_guidance,
        };
        (x + self.position_error, sensed)
    }

    /// ORCA's velocity for the agent at `x` (as it sees itself) moving at `v` among its
    /// `neighbours` (grown in `plan`), from the offset to the target and the gradient; `None`
    /// for any other controller.
    fn reference<'a>(
        &self,
        x: Vector2<f64>,
        v: Vector2<f64>,
        dt: f64,
        neighbours: &'a [Neighbour],
    ) -> impl FnOnce(&Vector2<f64>, Option<Vector2<f64>>) -> Option<Vector2<f64>> + use<'a> {
        let (orca, radius) = (self.orca, self.agent.radius + self.orca_growth(dt));
        move |offset, gradient| {
            orca.map(|orca| {
                let me = Neighbour {
                    position: x,
                    velocity: v,
                    radius,
                    reciprocal: true,
                };
                let preferred = orca.preferred_velocity(gradient, *offset);
                orca.velocity(&me, preferred, neighbours, dt)
            })
        }
    }

    /// The force its law would apply in a step of `dt` (s) from the state the body is in now,
    /// N, computed without changing anything (see [`Controller::evaluate`]); an ORCA agent's
    /// among the `others` (the other agents and the obstacles, as the step loop gives them).
    /// As in a step: zero for a frozen body, the stopping force for a lidar agent whose map
    /// closes every route. The field is the current one: a replan or a scan due at the next
    /// step is not anticipated, so the law's force in that step can differ.
    pub fn law_force(
        &self,
        physics: &PhysicsWorld,
        dt: f64,
        others: Vec<Neighbour>,
    ) -> Vector2<f64> {
        let Some((x, v)) = self.body.state(physics).filter(|_| !self.frozen) else {
            return Vector2::zeros();
        };
        let x = Vector2::from(x);
        if self
            .lidar
            .as_ref()
            .is_some_and(|r| r.intractable_at.is_some())
        {
            return -v * (self.agent.mass / dt);
        }
        let neighbours = self.grown_for_orca(others, dt);
        let (seen, sensed) = self.sensed(x, v, dt);
        let reference = self.reference(seen, v, dt, &neighbours);
        let law = |input: &_| self.controller.evaluate(input);
        control(&self.field, law, seen.into(), sensed, reference)
            .0
            .force
    }

    /// The `others` as ORCA sees them for steps of `dt` (s): each disc grown by
    /// [`AgentRun::orca_growth`].
    fn grown_for_orca(&self, mut others: Vec<Neighbour>, dt: f64) -> Vec<Neighbour> {
        let grown = self.orca_growth(dt);
        for n in &mut others {
            n.radius += grown;
        }
        others
    }

    /// How much ORCA grows every disc, its own and its neighbours', for steps of `dt` (s), m.
    /// Under the clearance envelope: one step at its top speed and the envelope's margin. Its
    /// velocities graze the others (they lie on its constraints) in continuous time, and a
    /// graze that the discrete step overshoots is one the envelope stops. (Measured, 32 robots
    /// on 1.2 m of arc each: grown by the margin alone, 9 of 32 arrive, the rest jam; grown so,
    /// all 32 do, in 16.6 s.) Zero without the envelope or ORCA.
    fn orca_growth(&self, dt: f64) -> f64 {
        match (&self.envelope, &self.orca) {
            (Some(_), Some(orca)) => orca.max_speed * dt + ENVELOPE_MARGIN,
            _ => 0.0,
        }
    }

    /// Counts the contacts that started in the last step and returns where the body touches
    /// something now: Rapier's contacts within [`CONTACT_TOLERANCE`], the wall collider
    /// `overlapped` that the disc is at or inside now, if any (by the clearance), and the
    /// moving obstacle it is at or inside now, `on_obstacle`.
    fn contacts(
        &mut self,
        physics: &PhysicsWorld,
        (position, radius): (Vector2<f64>, f64),
        overlapped: Option<ColliderHandle>,
        on_obstacle: Option<ColliderHandle>,
    ) -> Vec<Vector2<f64>> {
        let mut now = HashSet::new();
        let mut points = Vec::new();
        for pair in physics.narrow_phase.contact_pairs_with(self.collider) {
            if !pair.has_any_active_contact() {
                continue;
            }
            let (other, side) = if pair.collider1 == self.collider {
                (pair.collider2, 1.0)
            } else {
                (pair.collider1, -1.0)
            };
            for manifold in pair.manifolds() {
                if manifold.points.iter().any(|c| c.dist <= CONTACT_TOLERANCE) {
                    // The normal points from collider 1 to collider 2.
                    let n = from_rapier(manifold.data.normal);
                    points.push(position + n * (side * radius));
                    now.insert(other);
                }
            }
        }
        if let Some(wall) = overlapped
            && !now.iter().any(|c| is_wall(physics, *c))
        {
            // Rapier has not seen it (yet): the wall the clearance found, touched now. While
            // the body stays on walls, another collider of the same walls starts nothing new.
            if self.touching.iter().any(|c| is_wall(physics, *c)) {
                now.extend(self.touching.iter().filter(|c| is_wall(physics, **c)));
            } else {
                now.insert(wall);
            }
            if let Some(shape) = physics.colliders.get(wall) {
                let p = physics::to_rapier(position);
                let q = shape.shape().project_point(shape.position(), p, false);
                points.push(from_rapier(q.point));
            }
        }
        if let Some(obstacle) = on_obstacle
            && now.insert(obstacle)
            && let Some(shape) = physics.colliders.get(obstacle)
        {
            let p = physics::to_rapier(position);
            let q = shape.shape().project_point(shape.position(), p, false);
            points.push(from_rapier(q.point));
        }
        let started: Vec<ColliderHandle> = now.difference(&self.touching).copied().collect();
        let with_obstacles = started.iter().filter(|c| is_obstacle(physics, **c)).count();
        self.touching = now;
        self.metrics.record_contacts(started.len());
        self.metrics.record_obstacle_contacts(with_obstacles);
        if !started.is_empty() {
            // A contact is a failure of the run: an event on the timeline, not just a mark.
            let what = if with_obstacles > 0 {
                ", a moving obstacle among them"
            } else {
                ""
            };
            self.log.events.push(format!(
                "contact at [{:.3}, {:.3}] m ({} collider(s) touched now{what})",
                position.x,
                position.y,
                self.touching.len()
            ));
        }
        points
    }
}

/// The centres of the blocked cells of `field`'s mask that have a free 4-neighbour: the outline
/// of the configuration-space obstacles the field was solved for.
fn boundary(field: &HarmonicField) -> Vec<[f64; 2]> {
    let grid = field.grid();
    let blocked = &field.blocked;
    let mut points = Vec::new();
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            if !blocked[grid.index(i, j)] {
                continue;
            }
            let free = |a: usize, b: usize| !blocked[grid.index(a, b)];
            if (i > 0 && free(i - 1, j))
                || (i + 1 < grid.nx && free(i + 1, j))
                || (j > 0 && free(i, j - 1))
                || (j + 1 < grid.ny && free(i, j + 1))
            {
                points.push(grid.center(i, j));
            }
        }
    }
    points
}

/// The way `field` gives a disc of `radius` m at `x` (see [`Way`]).
fn way_of(field: &HarmonicField, x: Vector2<f64>, radius: f64) -> Way {
    let ahead = field.streamline_within(x.into(), WAY_AHEAD + field.grid().cell);
    Way::new(&ahead, radius)
}

/// How far the agent and every other may have moved since its field was last solved among
/// them (and the others' discs grown or shrunk), as a fraction of the field's cell, for a
/// replan of a crowd parked on its targets to be skipped (every agent arrived, this one in its
/// settling band). A disc blocks the cells whose centres it covers, so the field knows where
/// it is to half a cell; a rim moved a tenth of a cell changes the mask only in the cells
/// whose centres lie that close to it. Robots parked on their targets creep (measured:
/// 0.1 mm/s under clamping in `crowd`), so a tolerance far below this one re-solves them all
/// again every few seconds.
pub const STILL: f64 = 0.1;

/// How long a whole field solved among the others serves as the starting guess of the next
/// one, s: the others move at most a metre in this time at the crowd worlds' 2 m/s.
pub const WARM_FOR: f64 = 0.5;

/// Whether the guidance of `new` at `x` points against that of `last` (their gradients'
/// angle above 90°).
fn turns_back(last: &HarmonicField, new: &HarmonicField, x: Vector2<f64>) -> bool {
    let at = |f: &HarmonicField| f.gradient(x.into()).and_then(|g| unit(&g));
    at(last).zip(at(new)).is_some_and(|(a, b)| a.dot(&b) < 0.0)
}

/// Whether `collider` is a moving obstacle's (on a kinematic body).
fn is_obstacle(physics: &PhysicsWorld, collider: ColliderHandle) -> bool {
    (physics.colliders.get(collider))
        .and_then(|c| c.parent())
        .and_then(|b| physics.bodies.get(b))
        .is_some_and(|b| b.is_kinematic())
}

/// Whether `collider` is one of the walls (on the fixed body they all hang from).
fn is_wall(physics: &PhysicsWorld, collider: ColliderHandle) -> bool {
    (physics.colliders.get(collider))
        .and_then(|c| c.parent())
        .and_then(|b| physics.bodies.get(b))
        .is_some_and(|b| b.is_fixed())
}
