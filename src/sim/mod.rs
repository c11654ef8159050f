//! The simulation: a Rapier world with the walls as fixed colliders, each agent as a dynamic
//! disc and each pendulum on a revolute joint ([`pendulum`]), and the step loop that closes the
//! control loop through it.
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

pub mod faults;
pub mod pendulum;
mod physics;
mod sensor;

use std::collections::HashSet;

use nalgebra::Vector2;
use rapier2d::prelude::{ColliderHandle, PhysicsWorld, RigidBodyHandle};
use rayon::prelude::*;

pub use physics::{from_rapier, to_rapier};
pub use sensor::Sensor;

use crate::control::{ControlInput, Controller, unit};
use crate::field::{Disc, FieldError, GuidanceField, HarmonicField, Streamline};
use crate::metrics::{Metrics, Summary};
use crate::world::{Agent, WallShape, World, all_wall_shapes};
use faults::{FaultMonitor, Observation};

/// A pair counts as touching when Rapier has an active contact between them whose distance is
/// at most this, m. Rapier also keeps speculative contacts up to its prediction distance
/// (2 cm) ahead of a touch; those are not touches.
pub const CONTACT_TOLERANCE: f64 = 1e-3;

/// One agent in a running simulation.
pub struct AgentRun {
    /// The agent as the world file describes it.
    pub agent: Agent,
    /// Its guidance field: of the true walls, or of the last sensed walls with a sensor (and
    /// the other agents where they were at the last replan).
    pub field: GuidanceField,
    /// Its wall sensor, if it senses the walls with noise.
    pub sensor: Option<Sensor>,
    /// Its kinematic path (the streamline from its start).
    pub kinematic: Streamline,
    /// Its controller.
    pub controller: Controller<2>,
    /// Its metrics so far.
    pub metrics: Metrics,
    /// Its numerical faults so far.
    pub faults: FaultMonitor,
    body: RigidBodyHandle,
    collider: ColliderHandle,
    touching: HashSet<ColliderHandle>,
    frozen: bool,
    rebuild_failed: bool,
    offsets: Vec<f64>,
    replans: usize,
}

/// One agent's part of a step, read before any field is re-solved.
struct Plan {
    /// Position at the start of the step.
    x: Vector2<f64>,
    /// Velocity at the start of the step.
    v: Vector2<f64>,
    /// Whether its sensor took a reading this step.
    sensed_now: bool,
    /// The other agents' discs.
    others: Vec<Disc>,
    /// Whether its field is rebuilt this step (a harmonic one is re-solved, in parallel).
    rebuild: bool,
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
    /// The bias β after this step, N (with the bias option).
    pub beta: Option<Vector2<f64>>,
    /// The configuration-space boundary of the walls sensed in this step (the centres of
    /// blocked cells next to free ones), m; `None` when no reading was taken.
    pub sensed_walls: Option<Vec<[f64; 2]>>,
    /// Faults that started in this step, as messages.
    pub events: Vec<String>,
    /// Control events of this step (bias updates, sensing), as messages.
    pub notes: Vec<String>,
}

/// A running simulation.
pub struct Simulation {
    /// The world being simulated.
    pub world: World,
    /// The walls' shapes, in the order of their colliders.
    pub walls: Vec<WallShape>,
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
    /// a target that the walls alone make unreachable is an error.
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
            let kinematic = field.streamline(agent.start, 4.0 * (world.size[0] + world.size[1]));
            let (body, collider) = physics::insert_agent(&mut physics, agent);
            agents.push(AgentRun {
                controller: Controller::from_settings(
                    &agent.controller,
                    world.field.guidance,
                    agent.mass,
                ),
                metrics: Metrics::new(&agent.name, agent.start, agent.target, world.distance_at),
                agent: agent.clone(),
                field,
                sensor: agent
                    .sensor
                    .map(|settings| Sensor::new(settings, world.seed, index)),
                kinematic,
                faults: FaultMonitor::default(),
                body,
                collider,
                touching: HashSet::new(),
                frozen: false,
                rebuild_failed: false,
                offsets: Vec::new(),
                replans: 1,
            });
        }
        let pendulums = world
            .pendulums
            .iter()
            .map(|p| pendulum::insert(&mut physics, p))
            .collect();
        Ok(Self {
            world: world.clone(),
            walls,
            agents,
            pendulums,
            physics,
            time: 0.0,
            steps: 0,
        })
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Whether the run has reached the world's duration.
    pub fn finished(&self) -> bool {
        self.steps >= self.world.steps()
    }

    /// Advances one physics step and returns each agent's state after it.
    pub fn step(&mut self) -> Vec<AgentState> {
        let mut controls = Vec::with_capacity(self.agents.len());
        let mut events: Vec<Vec<String>> = vec![Vec::new(); self.agents.len()];
        let mut notes: Vec<Vec<String>> = vec![Vec::new(); self.agents.len()];
        let mut sensed: Vec<Option<Vec<[f64; 2]>>> = vec![None; self.agents.len()];
        // Every agent's disc where it is now, for the others' fields.
        let discs: Vec<Disc> = self
            .agents
            .iter()
            .map(|run| {
                let p = from_rapier(self.physics.bodies[run.body].translation());
                Disc {
                    center: if p.iter().all(|c| c.is_finite()) {
                        p.into()
                    } else {
                        *run.metrics.path().last().expect("starts at the start")
                    },
                    radius: run.agent.radius,
                }
            })
            .collect();
        // First, in agent order: each agent's state, its sensor reading and whether its
        // harmonic field is due for a re-solve.
        let mut plans = Vec::with_capacity(self.agents.len());
        for (index, (run, events)) in self.agents.iter_mut().zip(&mut events).enumerate() {
            let body = &self.physics.bodies[run.body];
            let (x, v) = (from_rapier(body.translation()), from_rapier(body.linvel()));
            if !run.frozen && !(x.iter().chain(v.iter()).all(|c| c.is_finite())) {
                run.frozen = true;
                events.extend(run.faults.non_finite_state());
            }
            let mut plan = Plan {
                x,
                v,
                sensed_now: false,
                others: Vec::new(),
                rebuild: false,
            };
            if !run.frozen {
                plan.sensed_now = match &mut run.sensor {
                    Some(sensor) if sensor.due(self.time) => {
                        run.offsets = sensor.read(self.walls.len());
                        true
                    }
                    _ => false,
                };
                plan.others = others_than(&discs, index);
                let replan_due = !plan.others.is_empty()
                    && self.world.field.replan_hz > 0.0
                    && self.time + 1e-9 >= run.replans as f64 / self.world.field.replan_hz;
                if replan_due {
                    run.replans += 1;
                }
                plan.rebuild = plan.sensed_now || replan_due;
            }
            plans.push(plan);
        }
        // The due harmonic fields, solved in parallel: each solve depends only on its own
        // agent's plan and last field, so the results do not depend on the order.
        let world = &self.world;
        let solved: Vec<Option<Result<HarmonicField, FieldError>>> = self
            .agents
            .par_iter()
            .zip(&plans)
            .map(|(run, plan)| match &run.field {
                GuidanceField::Harmonic(field) if plan.rebuild => Some(HarmonicField::solve_among(
                    world,
                    &run.agent,
                    plan.x.into(),
                    &run.offsets,
                    &plan.others,
                    Some(field),
                )),
                _ => None,
            })
            .collect();
        // Then, in agent order again: the new fields, the control forces.
        for ((((run, events), notes), sensed), (plan, solved)) in self
            .agents
            .iter_mut()
            .zip(&mut events)
            .zip(&mut notes)
            .zip(&mut sensed)
            .zip(plans.into_iter().zip(solved))
        {
            let body = &mut self.physics.bodies[run.body];
            let (x, v) = (plan.x, plan.v);
            let mut control = None;
            if !run.frozen {
                match (&mut run.field, solved) {
                    (GuidanceField::Harmonic(field), Some(result)) => match result {
                        Ok(new) => {
                            *field = new;
                            run.rebuild_failed = false;
                            if plan.sensed_now {
                                *sensed = Some(boundary(field));
                            }
                        }
                        Err(e) => {
                            if !run.rebuild_failed {
                                notes.push(format!(
                                    "the sensed walls and the other agents give no usable field ({e}); keeping the last one"
                                ));
                            }
                            run.rebuild_failed = true;
                        }
                    },
                    (GuidanceField::AttractiveRepulsive(field), _) => {
                        if plan.sensed_now {
                            field.sense(&run.offsets);
                        }
                        field.set_others(plan.others);
                    }
                    (GuidanceField::Harmonic(_), None) => {}
                }
                let input = ControlInput {
                    offset: x - Vector2::from(run.agent.target),
                    velocity: v,
                    gradient: run.field.gradient(x.into()),
                    dt: self.world.dt,
                };
                let mut out = run.controller.step(&input);
                // Finite in f64 but beyond f32's range is still not finite for Rapier.
                if !to_rapier(out.force).is_finite() {
                    out.force = Vector2::zeros();
                    events.extend(run.faults.rejected_force());
                }
                if out.bias_updated
                    && let Some(beta) = run.controller.beta()
                {
                    notes.push(format!(
                        "settling instant at distance {:.4} m: β ← u = [{:.4}, {:.4}] N (update {})",
                        input.offset.norm(),
                        beta.x,
                        beta.y,
                        run.controller.bias.as_ref().map_or(0, |b| b.updates())
                    ));
                }
                control = Some(out);
            }
            let force = control.map_or(Vector2::zeros(), |c| c.force);
            body.reset_forces(false);
            body.add_force(to_rapier(force), true);
            run.metrics.record_force(force);
            controls.push(control);
        }
        for p in &mut self.pendulums {
            p.control(&mut self.physics, self.time, self.world.dt);
        }
        self.physics.step();
        self.steps += 1;
        self.time = self.steps as f64 * self.world.dt;
        for p in &mut self.pendulums {
            p.observe(&self.physics, self.time);
        }

        let mut states = Vec::with_capacity(self.agents.len());
        for ((((run, control), mut events), notes), sensed_walls) in self
            .agents
            .iter_mut()
            .zip(controls)
            .zip(events)
            .zip(notes)
            .zip(sensed)
        {
            let body = &self.physics.bodies[run.body];
            let (mut position, mut velocity) =
                (from_rapier(body.translation()), from_rapier(body.linvel()));
            if !position
                .iter()
                .chain(velocity.iter())
                .all(|c| c.is_finite())
            {
                if !run.frozen {
                    run.frozen = true;
                    events.extend(run.faults.non_finite_state());
                }
                // Report the last finite state; nothing non-finite reaches the metrics.
                position = Vector2::from(*run.metrics.path().last().expect("starts at the start"));
                velocity = Vector2::zeros();
            }
            let p: [f64; 2] = position.into();
            let distance = (position - Vector2::from(run.agent.target)).norm();
            let radial_speed = run
                .field
                .gradient(p)
                .and_then(|g| unit(&g))
                .map_or(0.0, |u| -u.dot(&velocity));
            let signed = signed_clearance(&self.walls, position, run.agent.radius);
            let clearance = signed.max(0.0);
            events.extend(run.faults.observe(&Observation {
                field: &run.field,
                position,
                signed_clearance: signed,
                size: self.world.size,
            }));

            // Contact starts: pairs touching now that were not touching after the last step.
            let mut now = HashSet::new();
            let mut contact_points = Vec::new();
            for pair in self.physics.narrow_phase.contact_pairs_with(run.collider) {
                if !pair.has_any_active_contact() {
                    continue;
                }
                let (other, side) = if pair.collider1 == run.collider {
                    (pair.collider2, 1.0)
                } else {
                    (pair.collider1, -1.0)
                };
                for manifold in pair.manifolds() {
                    if manifold
                        .points
                        .iter()
                        .any(|c| f64::from(c.dist) <= CONTACT_TOLERANCE)
                    {
                        // The normal points from collider 1 to collider 2.
                        let n = from_rapier(manifold.data.normal);
                        contact_points.push(position + n * (side * run.agent.radius));
                        now.insert(other);
                    }
                }
            }
            let started = now.difference(&run.touching).count();
            run.touching = now;
            run.metrics.record_contacts(started);
            run.metrics
                .record_state(self.time, position, velocity, clearance);
            states.push(AgentState {
                position,
                velocity,
                force: control.map_or(Vector2::zeros(), |c| c.force),
                distance,
                radial_speed,
                potential: run.field.potential(p),
                clearance,
                contact_points,
                clamping: control.is_some_and(|c| c.clamping),
                speed_limited: control.is_some_and(|c| c.speed_limited),
                beta: run.controller.beta(),
                sensed_walls,
                events,
                notes,
            });
        }
        states
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
        self.agents
            .iter()
            .map(|a| a.metrics.summary(&a.kinematic, &a.faults.faults))
            .collect()
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

/// Signed distance from a disc of `radius` at `position` to the nearest wall, m: positive when
/// clear, negative by the overlap depth when the disc is inside a wall.
pub fn signed_clearance(walls: &[WallShape], position: Vector2<f64>, radius: f64) -> f64 {
    walls
        .iter()
        .map(|w| w.signed_distance_to_point(position.x, position.y))
        .fold(f64::INFINITY, f64::min)
        - radius
}
