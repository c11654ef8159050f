//! A shaped agent's run: a rigid body of convex polygons that turns freely, guided in its
//! configuration space (x, y, θ) by its [`PoseField`] and steered by the plane's control laws
//! in the metric coordinates `q = (x, y, ρθ)` (`field/pose`): there the inertia matrix
//! `D = diag(m, m, I)` is `m·I₃` (ρ = √(I/m)), so guidance, NADF, the clamp, the bias, the speed
//! limit and the exact integration act on `q` as on a disc's position, and the third component
//! of the force `F` becomes the torque `τ = ρ F₃`. Proposition 1's energy is then
//! `K·V + ½ m |q̇|² = K·V + ½ m |v|² + ½ I ω²`.
//!
//! Each step, as for a disc (`agent.rs`): read the pose and velocities from Rapier, compute
//! the control in `q`, reset the body's forces and torques and apply the new ones; after
//! Rapier's step read the state back, count the contacts that started (any collider of the
//! shape), measure the shape's clearance from the walls with parry, and update the metrics.

use std::collections::HashSet;

use nalgebra::{Vector2, Vector3};
use parry2d::math::{Pose as ParryPose, Vector};
use rapier2d::prelude::*;
use serde::Serialize;

use super::CONTACT_TOLERANCE;
use super::body::{Body, Sensed, TurningBody, control};
use super::physics::from_rapier;
use crate::control::{ControlOutput, Controller};
use crate::field::{FieldError, PoseField, Streamline, angle_difference};
use crate::metrics::{Faults, Metrics, Summary};
use crate::world::{Agent, BodyShape, GuidanceKind, WallShape, World};

/// A shaped agent in a running simulation.
pub struct ShapedRun {
    /// The agent as the world file describes it.
    pub agent: Agent,
    /// Its shape about its centroid.
    pub shape: BodyShape,
    /// Its moment of inertia about the centroid, kg·m².
    pub inertia: f64,
    /// The metric's length for θ, √(I/m), m.
    pub rho: f64,
    /// Its guidance field in (x, y, θ).
    pub field: PoseField,
    /// Its kinematic path: the streamline of the field from its start pose.
    pub kinematic: Vec<[f64; 3]>,
    /// The kinematic path's positions, for `δ_m`.
    kinematic_xy: Streamline,
    /// Its controller, in `q`.
    pub controller: Controller<3>,
    /// Its metrics so far (positions of its centroid).
    pub metrics: Metrics,
    /// Its numerical faults so far.
    pub faults: Faults,
    body: TurningBody,
    colliders: Vec<ColliderHandle>,
    touching: HashSet<ColliderHandle>,
    frozen: bool,
    /// Whether its guidance is the gradient law, whose curvature the integrator uses.
    gradient_guidance: bool,
    peak_angular_speed: f64,
    last: ShapedState,
}

/// What happened to a shaped agent in the last step, for recording.
#[derive(Debug, Clone, PartialEq)]
pub struct ShapedState {
    /// The centroid's position, m, and the heading, rad (continuous).
    pub pose: [f64; 3],
    /// The centroid's velocity, m/s.
    pub velocity: Vector2<f64>,
    /// The angular velocity, rad/s.
    pub angular_velocity: f64,
    /// The control force during the step, N.
    pub force: Vector2<f64>,
    /// The control torque during the step, N·m.
    pub torque: f64,
    /// Distance of the centroid to the target, m.
    pub distance: f64,
    /// The heading's difference from the target heading, rad (`None` without one).
    pub heading_error: Option<f64>,
    /// `log10(1 − V)` at the pose.
    pub log10_w: f64,
    /// The shape's distance to the nearest wall (parry), m.
    pub clearance: f64,
    /// Points where the shape touches something, m.
    pub contact_points: Vec<Vector2<f64>>,
    /// Whether the clamping control acted.
    pub clamping: bool,
    /// Whether the speed limit acted.
    pub speed_limited: bool,
    /// Contacts and faults that started in this step, as messages.
    pub events: Vec<String>,
}

crate::measured! {
    /// A shaped agent's summary: the disc's metrics (of its centroid; `min_clearance` is the
    /// shape's, by parry) and its heading, with the key names of `--json`.
    #[derive(Debug, Clone, PartialEq, Serialize)]
    pub struct ShapedSummary {
        /// The metrics every agent has.
        #[serde(flatten)]
        pub summary: Summary,
        /// The final heading's distance from `target_heading`, `|θ − θ_T|` wrapped to `[0, π]`,
        /// rad; `None` without a target heading.
        pub heading_error: Option<f64> [unit("rad"), column("head_rad"), missing("any heading")],
        /// The final heading, rad (continuous from the start heading).
        pub final_heading: f64 [unit("rad")],
        /// Largest angular speed, rad/s.
        pub peak_angular_speed: f64 [unit("rad/s"), digits(2)],
    }
}

impl ShapedRun {
    /// Puts the shaped agent at `index` of `world.shaped` into `physics` and solves its field.
    pub(super) fn new(
        world: &World,
        index: usize,
        physics: &mut PhysicsWorld,
    ) -> Result<Self, FieldError> {
        let agent = world.shaped[index].clone();
        let shape = BodyShape::of_agent(&agent)
            .expect("validated shape")
            .expect("not a disc");
        let inertia = agent.inertia.unwrap_or_else(|| shape.inertia(agent.mass));
        let rho = (inertia / agent.mass).sqrt();
        let field = PoseField::solve(world, &agent, &shape, rho)?;
        let start = [agent.start[0], agent.start[1], agent.heading];
        let length = 4.0 * (world.size[0] + world.size[1]);
        let (kinematic, reached) = field.streamline(start, length);
        let kinematic_xy = Streamline {
            points: kinematic.iter().map(|p| [p[0], p[1]]).collect(),
            reached,
        };
        let [vx, vy] = agent.initial_velocity;
        let builder = RigidBodyBuilder::dynamic()
            .pose(ParryPose::new(Vector::new(start[0], start[1]), start[2]))
            .linvel(Vector::new(vx, vy))
            .can_sleep(false)
            .ccd_enabled(true)
            .additional_mass_properties(MassProperties::new(Vector::ZERO, agent.mass, inertia));
        let handle = physics.insert_body(builder);
        let colliders = (shape.polygons().into_iter())
            .map(|polygon| {
                let collider = ColliderBuilder::new(SharedShape::new(polygon))
                    .density(0.0)
                    .friction(0.0)
                    .restitution(0.0);
                physics.insert_collider(collider, Some(handle))
            })
            .collect();
        let controller =
            Controller::from_settings(&agent.controller, world.field.guidance, agent.mass);
        let last = ShapedState {
            pose: start,
            velocity: Vector2::from(agent.initial_velocity),
            angular_velocity: 0.0,
            force: Vector2::zeros(),
            torque: 0.0,
            distance: (Vector2::from(agent.start) - Vector2::from(agent.target)).norm(),
            heading_error: agent
                .target_heading
                .map(|t| angle_difference(agent.heading, t)),
            log10_w: field.log10_one_minus_potential(start),
            clearance: f64::INFINITY,
            contact_points: Vec::new(),
            clamping: false,
            speed_limited: false,
            events: Vec::new(),
        };
        Ok(Self {
            metrics: Metrics::new(&agent.name, agent.start, agent.target, world.distance_at),
            controller,
            body: TurningBody {
                handle,
                rho,
                heading: agent.heading,
            },
            agent,
            shape,
            inertia,
            rho,
            field,
            kinematic,
            kinematic_xy,
            faults: Faults::default(),
            colliders,
            touching: HashSet::new(),
            frozen: false,
            gradient_guidance: world.field.guidance == GuidanceKind::Gradient,
            peak_angular_speed: 0.0,
            last,
        })
    }

    /// Its state after the last step (at the start before the first).
    pub fn state(&self) -> &ShapedState {
        &self.last
    }

    /// Its colliders (one per convex part).
    pub fn colliders(&self) -> &[ColliderHandle] {
        &self.colliders
    }

    /// Computes the control for a step of `dt` (s) and applies it to the body.
    pub(super) fn apply(&mut self, physics: &mut PhysicsWorld, dt: f64) {
        let control = match (self.frozen, self.body.state(physics)) {
            (false, Some((pose, velocity))) => Some(self.control(pose, velocity, dt)),
            _ => None,
        };
        let f = control.map_or(Vector3::zeros(), |c| c.force);
        self.body.actuate(physics, &f);
        let force = Vector2::new(f.x, f.y);
        self.metrics.record_force(force);
        (self.last.force, self.last.torque) = (force, self.body.torque(&f));
        self.last.clamping = control.is_some_and(|c| c.clamping);
        self.last.speed_limited = control.is_some_and(|c| c.speed_limited);
    }

    fn control(&mut self, pose: [f64; 3], velocity: Vector3<f64>, dt: f64) -> ControlOutput<3> {
        let sensed = Sensed {
            velocity,
            dt,
            touching: !self.touching.is_empty(),
            curvature: self.gradient_guidance,
        };
        let (out, rejected) = control(
            &self.field,
            |input| self.controller.step(input),
            pose,
            sensed,
            |_, _| None,
        );
        if rejected {
            self.faults.rejected_forces += 1;
        }
        if self.field.gradient(pose).is_none() && self.field.offset(pose).norm() > self.field.rim()
        {
            self.faults.guidance_lost_steps += 1;
        }
        out
    }

    /// After Rapier's step that ended at `time` (s): reads the state back, counts contact
    /// starts, measures the shape's clearance from `walls` and updates the metrics.
    pub(super) fn observe(
        &mut self,
        physics: &PhysicsWorld,
        time: f64,
        walls: &[WallShape],
    ) -> ShapedState {
        let mut events = Vec::new();
        let (pose, velocity) = match self.body.state(physics) {
            Some(state) => state,
            None => {
                if !self.frozen {
                    self.frozen = true;
                    self.faults.non_finite_state = true;
                    events.push(format!(
                        "Rapier's state became non-finite at t = {time:.3} s: the body is frozen"
                    ));
                }
                (self.last.pose, Vector3::zeros())
            }
        };
        self.body.heading = pose[2];
        let position = Vector2::new(pose[0], pose[1]);
        let v = Vector2::new(velocity.x, velocity.y);
        let clearance = self.clearance(walls, pose);
        if clearance < -0.01 {
            self.faults.penetrations += 1;
        }
        let contact_points = self.contacts(physics, &mut events);
        self.metrics
            .record_state(time, position, v, clearance.max(0.0));
        let distance = (position - Vector2::from(self.agent.target)).norm();
        self.last = ShapedState {
            pose,
            velocity: v,
            angular_velocity: velocity.z / self.rho,
            distance,
            heading_error: self
                .agent
                .target_heading
                .map(|t| angle_difference(pose[2], t)),
            log10_w: self.field.log10_one_minus_potential(pose),
            clearance,
            contact_points,
            events,
            ..self.last.clone()
        };
        self.peak_angular_speed = self
            .peak_angular_speed
            .max(self.last.angular_velocity.abs());
        self.last.clone()
    }

    /// The shape's signed distance from the nearest wall at `pose`, by parry (negative inside
    /// one by the penetration depth), m. Walls whose bounding box is farther than the nearest so
    /// far (less the shape's reach) are not measured.
    pub fn clearance(&self, walls: &[WallShape], [x, y, theta]: [f64; 3]) -> f64 {
        let at = ParryPose::new(Vector::new(x, y), theta);
        let polygons = self.shape.polygons();
        let mut nearest = f64::INFINITY;
        for wall in walls {
            if wall.distance_bound(x, y) - self.shape.reach >= nearest {
                continue;
            }
            for polygon in &polygons {
                let d = match parry2d::query::contact(
                    &at,
                    polygon,
                    &wall.pose,
                    wall.shape.as_ref(),
                    0.0,
                ) {
                    Ok(Some(contact)) => contact.dist,
                    _ => match parry2d::query::distance(
                        &at,
                        polygon,
                        &wall.pose,
                        wall.shape.as_ref(),
                    ) {
                        Ok(d) => d.distance,
                        Err(_) => continue,
                    },
                };
                nearest = nearest.min(d);
            }
        }
        nearest
    }

    /// Counts the contacts that started in the last step (with anything, by any part), and
    /// returns where the shape touches now.
    fn contacts(&mut self, physics: &PhysicsWorld, events: &mut Vec<String>) -> Vec<Vector2<f64>> {
        let mut now = HashSet::new();
        let mut points = Vec::new();
        for &collider in &self.colliders {
            for pair in physics.narrow_phase.contact_pairs_with(collider) {
                if !pair.has_any_active_contact() {
                    continue;
                }
                let (other, mine_first) = if pair.collider1 == collider {
                    (pair.collider2, true)
                } else {
                    (pair.collider1, false)
                };
                for manifold in pair.manifolds() {
                    for c in &manifold.points {
                        if c.dist <= CONTACT_TOLERANCE {
                            let local = if mine_first { c.local_p1 } else { c.local_p2 };
                            let on = physics.colliders[collider].position() * local;
                            points.push(from_rapier(on));
                            now.insert(other);
                        }
                    }
                }
            }
        }
        let started = now.difference(&self.touching).count();
        self.touching = now;
        self.metrics.record_contacts(started);
        if started > 0 {
            let [x, y, theta] = self.last.pose;
            events.push(format!(
                "contact at [{x:.3}, {y:.3}] m, heading {theta:.3} rad ({} collider(s) touched now)",
                self.touching.len()
            ));
        }
        points
    }

    /// Its summary so far.
    pub fn summary(&self) -> ShapedSummary {
        ShapedSummary {
            summary: self.metrics.summary(&self.kinematic_xy, &self.faults),
            heading_error: self.last.heading_error.map(f64::abs),
            final_heading: self.last.pose[2],
            peak_angular_speed: self.peak_angular_speed,
        }
    }
}
