//! The simulation: a Rapier world with the walls as fixed colliders, each agent as a dynamic
//! disc (`agent.rs`) and each pendulum on a revolute joint ([`pendulum`]), and the step loop
//! that closes the control loop through it.
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
//! A noisy sensor rebuilds the field from each reading. A rebuild that fails (the others or the
//! sensed walls cut the agent off) keeps the last field and logs a note once.

mod agent;
mod clearance;
pub mod faults;
pub mod lidar;
pub mod pendulum;
mod physics;
mod sensor;

use rapier2d::prelude::PhysicsWorld;
use rayon::prelude::*;

pub use agent::{AgentRun, AgentState, LidarRun};
pub use clearance::{WallIndex, signed_clearance};
pub use physics::{from_rapier, to_rapier};
pub use sensor::Sensor;

use crate::field::{Disc, FieldError, GuidanceField};
use crate::metrics::Summary;
use crate::world::{WallShape, World, all_wall_shapes};

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
    /// The agents.
    pub agents: Vec<AgentRun>,
    /// The pendulums.
    pub pendulums: Vec<pendulum::PendulumRun>,
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
        physics::insert_walls(&mut physics, &walls);
        let starts: Vec<Disc> = world
            .agents
            .iter()
            .map(|a| Disc {
                center: a.start,
                radius: a.radius,
            })
            .collect();
        let mut agents = Vec::with_capacity(world.agents.len());
        for (index, agent) in world.agents.iter().enumerate() {
            let others = others_than(&starts, index);
            let field = match GuidanceField::build(world, agent, &others) {
                Err(FieldError::Unreachable { .. }) if !others.is_empty() => {
                    GuidanceField::build(world, agent, &[])?
                }
                result => result?,
            };
            if let Some(harmonic) = field.harmonic() {
                harmonic.check_start(agent)?;
            }
            agents.push(AgentRun::new(world, index, field, &mut physics));
        }
        let pendulums = world
            .pendulums
            .iter()
            .map(|p| pendulum::insert(&mut physics, p))
            .collect();
        if agents.iter().any(|a| a.lidar.is_some()) {
            // Rapier fills its scene-query structure during a step; a lidar scans before the
            // first one, and would see through every wall.
            physics.detect_collisions(&(), &());
        }
        Ok(Self {
            world: world.clone(),
            index: WallIndex::new(&walls),
            walls,
            agents,
            pendulums,
            physics,
            time: 0.0,
            steps: 0,
        })
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
        let discs: Vec<Disc> = self.agents.iter().map(|a| a.disc(&self.physics)).collect();
        let scene = (&self.world, self.walls.as_slice());
        let plans: Vec<_> = (self.agents.iter_mut().enumerate())
            .map(|(i, a)| a.plan(&self.physics, self.time, scene, others_than(&discs, i)))
            .collect();
        // Each re-solve reads only its own agent, so the results do not depend on the threads.
        let solved: Vec<_> = (self.agents.par_iter().zip(&plans))
            .map(|(agent, plan)| agent.resolve(plan, &self.world))
            .collect();
        for ((agent, plan), solved) in self.agents.iter_mut().zip(plans).zip(solved) {
            agent.apply(plan, solved, &mut self.physics, self.world.dt);
        }
        for p in &mut self.pendulums {
            p.apply(&mut self.physics, self.time, self.world.dt);
        }
        self.physics.step();
        self.steps += 1;
        self.time = self.steps as f64 * self.world.dt;
        for p in &mut self.pendulums {
            p.observe(&self.physics, self.time);
        }
        let walls = (self.walls.as_slice(), &self.index);
        let bounds = self.world.bounds();
        let mut states: Vec<AgentState> = (self.agents.iter_mut())
            .map(|a| a.observe(&self.physics, self.time, walls, bounds))
            .collect();
        self.watch_deadlocks(&mut states);
        states
    }

    /// Marks the agents that make no progress while another agent is next to them (within
    /// their own diameter, disc to disc) as deadlocked, with an event in their state.
    fn watch_deadlocks(&mut self, states: &mut [AgentState]) {
        if self.agents.len() < 2 {
            return;
        }
        for i in 0..self.agents.len() {
            let r = self.agents[i].agent.radius;
            let blocked = (0..self.agents.len()).any(|j| {
                let gap = (states[i].position - states[j].position).norm()
                    - r
                    - self.agents[j].agent.radius;
                j != i && gap < 2.0 * r
            });
            if self.agents[i].metrics.watch_progress(self.time, blocked) {
                states[i].events.push(format!(
                    "deadlocked at t = {:.2} s: no progress towards the target for {} s, another agent next to it",
                    self.time,
                    crate::metrics::DEADLOCK_AFTER
                ));
            }
        }
    }

    /// Each pendulum's summary so far.
    pub fn pendulum_summaries(&self) -> Vec<pendulum::PendulumSummary> {
        self.pendulums
            .iter()
            .map(|p| p.summary(self.world.external_acceleration))
            .collect()
    }

    /// Each agent's summary so far.
    pub fn summaries(&self) -> Vec<Summary> {
        self.agents.iter().map(AgentRun::summary).collect()
    }
}

/// Every disc of `discs` but the one at `index`.
fn others_than(discs: &[Disc], index: usize) -> Vec<Disc> {
    discs
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != index)
        .map(|(_, d)| *d)
        .collect()
}
