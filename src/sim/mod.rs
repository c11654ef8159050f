//! The simulation: a Rapier world with the walls as fixed colliders, each agent as a dynamic
//! disc (`agent.rs`) or a shape that turns ([`shaped`]), each pendulum on a revolute joint
//! ([`pendulum`]), and the step loop that closes the control loop through it.
//!
//! Every step, for every agent: read its position and velocity from Rapier, sample the
//! gradient of its field there, compute the control force, reset the body's forces and apply
//! the new one (Rapier's user forces persist across steps otherwise), then step Rapier once.
//! Rapier's narrow phase then says which pairs touch.
//!
//! With several agents, each one's field has the others as obstacles (discs grown by both
//! radii): a harmonic field is re-solved at `field.replan_hz` with the others where they are
//! then, warm-started from the last solve; an attractive-repulsive one sees them at every step.
//! The agents whose fields are due are re-solved in parallel (rayon), after every agent's state
//! and sensor reading have been taken in order, so a run does not depend on the threads.
//! Moving obstacles ([`obstacles`]) are kinematic bodies that Rapier moves along their scripts;
//! an agent with a lidar sees them in its scans, any other agent as it sees the other agents:
//! discs that hold them where they are and where their velocities take them within
//! `field.obstacle_horizon` (ORCA: where they are), grown as the other agents' discs are.
//! A noisy sensor rebuilds the field from each reading. A rebuild that fails (the others or the
//! sensed walls cut the agent off) keeps the last field and logs a note once.

mod agent;
pub mod arm;
pub mod arm_run;
pub mod body;
mod clearance;
pub mod drive;
pub mod faults;
pub mod lidar;
pub mod motion;
pub mod obstacles;
pub mod pendulum;
mod physics;
mod sensor;
pub mod shaped;

use nalgebra::Vector2;
use rapier2d::prelude::PhysicsWorld;
use rayon::prelude::*;

pub use agent::{AgentRun, AgentState, LidarRun};
pub use clearance::{WallIndex, signed_clearance};
pub use physics::{from_rapier, to_rapier};
pub use sensor::Sensor;

use crate::control::Neighbour;
use crate::field::{Disc, FieldError, GuidanceField, HarmonicField};
use crate::metrics::{self, Stall, Summary};
use crate::world::{ControllerKind, FieldKind, Replan, WallShape, World, all_wall_shapes};

/// A pair counts as touching when Rapier has an active contact between them whose distance is
/// at most this, m. Rapier also keeps speculative contacts up to its prediction distance
/// (2 cm) ahead of a touch; those are not touches.
pub const CONTACT_TOLERANCE: f64 = 1e-3;

/// A running simulation.
///
/// ```
/// let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
/// let world = nadf::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
/// let mut sim = nadf::sim::Simulation::new(&world).unwrap();
/// let start = world.agents[0].start;
/// while sim.time() < 1.0 {
///     let states = sim.step();
///     assert!(states[0].contact_points.is_empty());
/// }
/// // After a second, the robot is on its way.
/// let moved = (sim.agents[0].metrics.path().last().unwrap()[0] - start[0]).abs();
/// assert!(moved > 0.1, "{moved}");
/// ```
pub struct Simulation {
    /// The world being simulated.
    pub world: World,
    /// The walls' shapes, in the order of their colliders.
    pub walls: Vec<WallShape>,
    /// The walls by bucket, for the clearance after every step.
    index: WallIndex,
    /// The walls' colliders, in the order of `walls`.
    wall_colliders: Vec<rapier2d::prelude::ColliderHandle>,
    /// The agents.
    pub agents: Vec<AgentRun>,
    /// The pendulums.
    pub pendulums: Vec<pendulum::PendulumRun>,
    /// The shaped agents (`world.shaped`), planned in (x, y, θ).
    pub shaped: Vec<shaped::ShapedRun>,
    /// The arms, planned in joint space.
    pub arms: Vec<arm_run::ArmRun>,
    /// The moving obstacles.
    pub obstacles: Vec<obstacles::ObstacleRun>,
    physics: PhysicsWorld,
    time: f64,
    steps: usize,
}

impl Simulation {
    /// Builds the Rapier world and solves every agent's field.
    ///
    /// With several agents, each field starts with the others at their starts; if they cut an
    /// agent off from its target there, its first field ignores them (they will move), and only
    /// a target that the walls alone make unreachable is an error. So is a start where the
    /// field gives no direction ([`FieldError::NoGuidance`]).
    pub fn new(world: &World) -> Result<Self, FieldError> {
        let mut physics = physics::empty_world(world.dt, world.external_acceleration);
        let walls = all_wall_shapes(world);
        let wall_colliders = physics::insert_walls(&mut physics, &walls);
        let obstacles: Vec<_> = (0..world.obstacles.len())
            .map(|index| obstacles::ObstacleRun::new(world, index, &mut physics))
            .collect();
        let starts: Vec<Neighbour> = world
            .agents
            .iter()
            .map(|a| Neighbour {
                position: a.start.into(),
                velocity: a.initial_velocity.into(),
                radius: a.radius,
                reciprocal: true,
            })
            .collect();
        let seen = sighted(&obstacles, world.field.obstacle_horizon);
        let disc = |n: Neighbour| Disc {
            center: n.position.into(),
            radius: n.radius,
        };
        // Every agent's first field, in parallel (each reads only its own agent).
        let fields: Vec<Result<_, FieldError>> = (0..world.agents.len())
            .into_par_iter()
            .map(|index| {
                // A lidar agent sees the moving obstacles in its map, not as discs.
                let lidar = world.agents[index].has_lidar();
                let others = seen_by(&starts, &seen, index, lidar);
                first_field(
                    world,
                    index,
                    &others.into_iter().map(disc).collect::<Vec<_>>(),
                )
            })
            .collect();
        let mut agents = Vec::with_capacity(world.agents.len());
        for (index, field) in fields.into_iter().enumerate() {
            agents.push(AgentRun::new(world, index, field?, &mut physics));
        }
        let pendulums = world
            .pendulums
            .iter()
            .map(|p| pendulum::insert(&mut physics, p))
            .collect();
        let shaped = (0..world.shaped.len())
            .map(|index| shaped::ShapedRun::new(world, index, &mut physics))
            .collect::<Result<_, _>>()?;
        let arms = (0..world.arms.len())
            .map(|index| arm_run::ArmRun::new(world, index, &mut physics, &walls))
            .collect::<Result<_, _>>()?;
        if agents.iter().any(|a| a.lidar.is_some() || a.has_envelope()) {
            // Rapier fills its scene-query structure during a step; a lidar scans (and the
            // envelope casts) before the first one, and would see through every wall.
            physics.detect_collisions(&(), &());
        }
        Ok(Self {
            world: world.clone(),
            index: WallIndex::new(&walls),
            walls,
            wall_colliders,
            agents,
            pendulums,
            shaped,
            arms,
            obstacles,
            physics,
            time: 0.0,
            steps: 0,
        })
    }

    /// The walls by bucket, for clearance queries against `walls`.
    pub fn wall_index(&self) -> &WallIndex {
        &self.index
    }

    /// The Rapier world, for scene queries (a lidar's ray casts).
    pub fn physics(&self) -> &PhysicsWorld {
        &self.physics
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Whether the run has reached the world's duration.
    pub fn finished(&self) -> bool {
        self.steps >= self.world.steps()
    }

    /// Advances one physics step and returns each agent's state after it: plan every agent,
    /// re-solve the due fields in parallel, apply the controls, step Rapier, observe.
    pub fn step(&mut self) -> Vec<AgentState> {
        let bodies: Vec<Neighbour> = self.agents.iter().map(|a| a.body(&self.physics)).collect();
        let seen = sighted(&self.obstacles, 0.0);
        let ahead = sighted(&self.obstacles, self.world.field.obstacle_horizon);
        let scene = (&self.world, self.walls.as_slice());
        // Who gives way to whom (see `field/yielding.rs`): each agent's way and its place.
        let crowd: Vec<_> = (self.agents.iter().enumerate())
            .map(|(i, a)| (a.way().cloned(), a.right_of_way(i)))
            .collect();
        let plans: Vec<_> = (self.agents.iter_mut().enumerate())
            .map(|(i, a)| {
                // ORCA extrapolates the velocities itself; a field is solved on where the
                // obstacles are going.
                let orca = a.agent.controller.kind == ControllerKind::Orca;
                let obstacles = if orca { &seen } else { &ahead };
                let others = seen_by(&bodies, obstacles, i, a.lidar.is_some());
                a.plan(&self.physics, self.time, scene, others, (i, &crowd))
            })
            .collect();
        // Each re-solve reads only its own agent, so the results do not depend on the threads.
        let solved: Vec<_> = (self.agents.par_iter().zip(&plans))
            .map(|(agent, plan)| agent.resolve(plan, &self.world))
            .collect();
        // The envelope decides in the agents' order: each one's sweep is clear of the ones
        // before it as they have just chosen and of the ones after it as they were.
        let step = physics::step_of(&self.physics, self.world.dt);
        let mut sweeps: Vec<_> = (self.agents.iter().zip(&plans))
            .map(|(agent, plan)| agent.sweep(plan, step))
            .collect();
        let applied = self.agents.iter_mut().zip(plans).zip(solved);
        for (index, ((agent, plan), solved)) in applied.enumerate() {
            agent.apply(plan, solved, &mut self.physics, step, (&mut sweeps, index));
        }
        for p in &mut self.pendulums {
            p.apply(&mut self.physics, self.time, self.world.dt);
        }
        for s in &mut self.shaped {
            s.apply(&mut self.physics, self.world.dt);
        }
        for a in &mut self.arms {
            a.apply(&mut self.physics, self.world.dt);
        }
        for o in &mut self.obstacles {
            o.advance(&mut self.physics, self.world.dt);
        }
        self.physics.step();
        self.steps += 1;
        self.time = self.steps as f64 * self.world.dt;
        for p in &mut self.pendulums {
            p.observe(&self.physics, self.time);
        }
        for s in &mut self.shaped {
            s.observe(&self.physics, self.time, &self.walls);
        }
        for a in &mut self.arms {
            a.observe(&self.physics, self.time, &self.walls);
        }
        let walls = (
            self.walls.as_slice(),
            &self.index,
            self.wall_colliders.as_slice(),
        );
        let bounds = self.world.bounds();
        let obstacles: Vec<_> = (self.obstacles.iter())
            .map(|o| (o.shape(), o.collider()))
            .collect();
        let mut states: Vec<AgentState> = (self.agents.iter_mut())
            .map(|a| a.observe(&self.physics, self.time, walls, bounds, &obstacles))
            .collect();
        self.watch_neighbours(&mut states);
        states
    }

    /// The force agent `agent`'s control law would apply in the next step from the state it is
    /// in now, N, changing nothing but a re-solve put off while it was commanded (see
    /// [`AgentRun::law_force`], [`AgentRun::bring_up_to_date`]): the expert's action for a
    /// policy that drives the body instead of its law ([`AgentRun::command`]). `None` for an
    /// agent the world does not have.
    pub fn law_force(&mut self, agent: usize) -> Option<Vector2<f64>> {
        self.agents.get_mut(agent)?.bring_up_to_date(&self.world);
        let run = &self.agents[agent];
        // Only ORCA's law reads the neighbours (the others see them in their field).
        let others = if run.orca.is_some() {
            let bodies: Vec<Neighbour> =
                self.agents.iter().map(|a| a.body(&self.physics)).collect();
            seen_by(
                &bodies,
                &sighted(&self.obstacles, 0.0),
                agent,
                run.lidar.is_some(),
            )
        } else {
            Vec::new()
        };
        Some(run.law_force(&self.physics, self.world.dt, others))
    }

    /// Records each agent's gap to the nearest other agent, and marks the agents that make no
    /// progress while another agent is next to them (within their own diameter, disc to disc)
    /// as deadlocked, and those that make none while they keep moving as livelocked, with an
    /// event in their state.
    fn watch_neighbours(&mut self, states: &mut [AgentState]) {
        if self.agents.len() < 2 {
            return;
        }
        for i in 0..self.agents.len() {
            let r = self.agents[i].agent.radius;
            let gap = (0..self.agents.len())
                .filter(|&j| j != i)
                .map(|j| {
                    (states[i].position - states[j].position).norm()
                        - r
                        - self.agents[j].agent.radius
                })
                .fold(f64::INFINITY, f64::min);
            let metrics = &mut self.agents[i].metrics;
            metrics.record_separation(gap);
            let event = match metrics.watch_progress(self.time, gap < 2.0 * r) {
                Some(Stall::Deadlocked) => format!(
                    "deadlocked at t = {:.2} s: no progress towards the target for {} s, another agent next to it",
                    self.time,
                    metrics::DEADLOCK_AFTER
                ),
                Some(Stall::Livelocked) => format!(
                    "livelocked at t = {:.2} s: no progress towards the target for {} s, moving all the while",
                    self.time,
                    metrics::LIVELOCK_AFTER
                ),
                None => continue,
            };
            states[i].events.push(event);
        }
    }

    /// Each pendulum's summary so far.
    pub fn pendulum_summaries(&self) -> Vec<pendulum::PendulumSummary> {
        self.pendulums
            .iter()
            .map(|p| p.summary(self.world.external_acceleration))
            .collect()
    }

    /// Each arm's summary so far.
    pub fn arm_summaries(&self) -> Vec<arm_run::ArmSummary> {
        self.arms.iter().map(arm_run::ArmRun::summary).collect()
    }

    /// Each shaped agent's summary so far.
    pub fn shaped_summaries(&self) -> Vec<shaped::ShapedSummary> {
        self.shaped.iter().map(shaped::ShapedRun::summary).collect()
    }

    /// The wheels' summary of each agent on wheels so far.
    pub fn drive_summaries(&self) -> Vec<drive::DriveSummary> {
        self.agents
            .iter()
            .filter_map(AgentRun::drive_summary)
            .collect()
    }

    /// Each agent's summary so far.
    pub fn summaries(&self) -> Vec<Summary> {
        self.agents.iter().map(AgentRun::summary).collect()
    }
}

/// The first field of the agent at `index` of `world`, with the discs `others` (the other
/// agents at their starts) as obstacles: in the whole field, or with `field.replan = "local"`
/// in a window around the agent on top of the field of the walls (which it returns too, for
/// the replans; a window cut off there falls back to the whole field).
///
/// If the others cut the agent off from its target there, its first field ignores them (they
/// will move); only a target that the walls alone make unreachable is an error. So is a start
/// where the field gives no direction.
fn first_field(
    world: &World,
    index: usize,
    others: &[Disc],
) -> Result<(GuidanceField, Option<HarmonicField>), FieldError> {
    let agent = &world.agents[index];
    let orca = agent.controller.kind == ControllerKind::Orca;
    let local = world.field.replan == Replan::Local && world.field.kind == FieldKind::Harmonic;
    let (field, walls) = if orca || others.is_empty() {
        // ORCA steers it among the others: its field has the walls only.
        let field = GuidanceField::build(world, agent, &[])?;
        let walls = field.harmonic().filter(|_| local && !orca).cloned();
        (field, walls)
    } else if local {
        let walls = GuidanceField::build(world, agent, &[])?;
        let harmonic = walls.harmonic().expect("a harmonic field").clone();
        let field = match harmonic.with_window(agent, agent.start, others, &world.field) {
            Ok(windowed) => GuidanceField::Harmonic(windowed),
            Err(_) => GuidanceField::build(world, agent, others).unwrap_or(walls),
        };
        (field, Some(harmonic))
    } else {
        let field = match GuidanceField::build(world, agent, others) {
            Err(FieldError::Unreachable { .. }) => GuidanceField::build(world, agent, &[])?,
            result => result?,
        };
        (field, None)
    };
    if let Some(harmonic) = field.harmonic() {
        harmonic.check_start(agent)?;
    }
    Ok((field, walls))
}

/// What the agents without a lidar see of the moving obstacles: the discs that hold each one
/// where it is now and where it will be over the next `horizon` seconds at its velocity.
fn sighted(obstacles: &[obstacles::ObstacleRun], horizon: f64) -> Vec<Neighbour> {
    (obstacles.iter())
        .flat_map(|o| o.neighbours_ahead(horizon))
        .collect()
}

/// What agent `index` sees as neighbours: the other agents' `bodies`, and the discs `seen` of
/// the moving obstacles unless it has a `lidar`.
fn seen_by(bodies: &[Neighbour], seen: &[Neighbour], index: usize, lidar: bool) -> Vec<Neighbour> {
    let mut others = others_than(bodies, index);
    if !lidar {
        others.extend_from_slice(seen);
    }
    others
}

/// Every item of `items` but the one at `index`.
fn others_than<T: Copy>(items: &[T], index: usize) -> Vec<T> {
    items
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != index)
        .map(|(_, d)| *d)
        .collect()
}
