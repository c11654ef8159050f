//! Building the Rapier world from a world file, and the one conversion between the control
//! laws' nalgebra vectors and Rapier's `glam` ones.
//!
//! Rapier and parry are their f64 builds (`rapier2d-f64`, `parry2d-f64`, renamed `rapier2d` and
//! `parry2d` in `Cargo.toml`). In f32 a position 464 m from the origin is kept to 3e-5 m, and a
//! substep moving a body less than half of that leaves it where it was: a body the clearance
//! envelope slowed to a few mm/s at a door's corner never moved again (measured: the rooms
//! map's campaign run 134, `tests/envelope.rs`). In f64 the same spacing is 6e-14 m.

use nalgebra::Vector2;
use rapier2d::parry::query::ShapeCastOptions;
use rapier2d::parry::shape::Ball;
use rapier2d::prelude::*;

use crate::control::{ENVELOPE_MARGIN, Step, Sweep};
use crate::world::{Agent, WallShape};

/// Rapier vector → control-law vector.
pub fn from_rapier(v: Vector) -> Vector2<f64> {
    Vector2::new(v.x, v.y)
}

/// Control-law vector → Rapier vector.
pub fn to_rapier(v: Vector2<f64>) -> Vector {
    Vector::new(v.x, v.y)
}

/// A Rapier world with the given step whose gravity is the world's external acceleration, m/s²
/// (Rapier applies `m·a` to every dynamic body).
pub fn empty_world(dt: f64, external_acceleration: [f64; 2]) -> PhysicsWorld {
    PhysicsWorld {
        gravity: Vector::new(external_acceleration[0], external_acceleration[1]),
        integration_parameters: IntegrationParameters {
            dt,
            // Rapier keeps a pair's contacts (and their distances) while the pair has moved
            // less than 5 cm since its last full update: a body creeping into a wall would be
            // reported at the distance it had when it was still clear (measured: a touch that
            // counted no contact). Every contact is recomputed every step instead.
            contact_recycling: false,
            ..IntegrationParameters::default()
        },
        ..PhysicsWorld::default()
    }
}

/// Inserts the walls as colliders of one fixed body and returns their handles, in order.
pub fn insert_walls(physics: &mut PhysicsWorld, walls: &[WallShape]) -> Vec<ColliderHandle> {
    let ground = physics.insert_body(RigidBodyBuilder::fixed());
    walls
        .iter()
        .map(|w| {
            let collider = ColliderBuilder::new(w.shape.clone())
                .position(w.pose)
                .friction(0.0);
            physics.insert_collider(collider, Some(ground))
        })
        .collect()
}

/// Inserts an agent at its start with its initial velocity: a dynamic disc of the agent's radius
/// and mass that does not rotate, never
/// sleeps (its control force changes every step) and uses continuous collision detection (a
/// fast body must not tunnel through a thin wall). Contacts are frictionless and inelastic:
/// a touch is a failure to be counted, not a dynamics to be modelled.
pub fn insert_agent(
    physics: &mut PhysicsWorld,
    agent: &Agent,
) -> (RigidBodyHandle, ColliderHandle) {
    if let Some(drive) = &agent.drive {
        // On wheels: the footprint at the axle, behind the look-ahead point the agent's start
        // is (see the loader), turning freely.
        let l = drive.lookahead_for(drive.body_radius);
        let (s, c) = agent.heading.sin_cos();
        let axle = [agent.start[0] - l * c, agent.start[1] - l * s];
        let r = drive.body_radius;
        let inertia = super::drive::DriveBody::inertia_of(agent);
        let body = RigidBodyBuilder::dynamic()
            .translation(Vector::new(axle[0], axle[1]))
            .rotation(agent.heading)
            .can_sleep(false)
            .ccd_enabled(true)
            .additional_mass_properties(MassProperties::new(Vector::ZERO, agent.mass, inertia));
        let collider = ColliderBuilder::ball(r)
            .density(0.0)
            .friction(0.0)
            .restitution(0.0);
        return physics.insert(body, collider);
    }
    let [vx, vy] = agent.initial_velocity;
    let body = RigidBodyBuilder::dynamic()
        .translation(Vector::new(agent.start[0], agent.start[1]))
        .linvel(Vector::new(vx, vy))
        .lock_rotations()
        .can_sleep(false)
        .ccd_enabled(true);
    let collider = ColliderBuilder::ball(agent.radius)
        .mass(agent.mass)
        .friction(0.0)
        .restitution(0.0);
    physics.insert(body, collider)
}

/// How Rapier moves a body over a step of `dt` (s) in `physics` (see [`Step`]): its substeps,
/// one per solver iteration, each add `1/N` of the step's change of velocity.
pub fn step_of(physics: &PhysicsWorld, dt: f64) -> Step {
    let n = physics.integration_parameters.num_solver_iterations.max(1) as f64;
    Step {
        dt,
        blend: (n + 1.0) / (2.0 * n),
    }
}

/// Whether `sweep` keeps the envelope's margin from every wall (Rapier's fixed colliders) and
/// every moving obstacle where it is now (the kinematic ones): its disc cast along each of its
/// segments. A disc already that near and moving away is clear. (An obstacle moves on during
/// the step: the envelope keeps a body from driving into one, not one from running into it.)
pub fn clear_of_walls(physics: &PhysicsWorld, sweep: &Sweep) -> bool {
    let ball = Ball::new(sweep.radius);
    sweep.segments().iter().all(|&(from, to)| {
        let length = (to - from).norm();
        if length <= 0.0 || length.is_nan() {
            return true;
        }
        let options = ShapeCastOptions {
            max_time_of_impact: length,
            target_distance: ENVELOPE_MARGIN,
            stop_at_penetration: false,
            compute_impact_geometry_on_penetration: false,
        };
        let hit = physics.cast_shape(
            &Pose::from_translation(to_rapier(from)),
            to_rapier((to - from) / length),
            &ball,
            options,
            QueryFilter::exclude_dynamic(),
        );
        hit.is_none()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The envelope's model of a step is what Rapier does: a free ball pushed sideways while
    /// moving moves by `dt (v + c (v⁺ − v))`.
    #[test]
    fn a_step_moves_a_body_as_the_envelope_assumes() {
        let dt = 0.01;
        let mut physics = empty_world(dt, [0.0, 0.0]);
        let text = "size = [10.0, 10.0]\n[[agents]]\nname = \"a\"\nstart = [5.0, 5.0]\n\
                    target = [8.0, 5.0]\ninitial_velocity = [3.0, 0.0]\n\
                    controller = { kind = \"nadf\", b = 1.0 }\n";
        let world = crate::world::load_str(text, std::path::Path::new("w.toml"), &[]).unwrap();
        let agent = &world.agents[0];
        let (body, _) = insert_agent(&mut physics, agent);
        let force = Vector2::new(-40.0, 25.0);
        physics.bodies[body].add_force(to_rapier(force), true);
        physics.step();
        let b = &physics.bodies[body];
        let (x, v) = (from_rapier(b.translation()), from_rapier(b.linvel()));
        let v0 = Vector2::new(3.0, 0.0);
        assert!((v - (v0 + force / agent.mass * dt)).norm() < 1e-5, "{v}");
        let moved = step_of(&physics, dt).moved(Vector2::new(5.0, 5.0), v0, v);
        assert!((x - moved).norm() < 1e-6, "{x} vs {moved}");
    }

    /// A body creeping at a few mm/s far from the origin moves as slowly as it goes: where the
    /// rooms map's campaign run 134 stalled (in f32 positions, 464 m out, it never moved).
    #[test]
    fn a_slow_body_far_from_the_origin_moves() {
        let dt = 0.01;
        let mut physics = empty_world(dt, [0.0, 0.0]);
        let text = "size = [500.0, 500.0]\n[field]\ncell = 0.5\n[[agents]]\nname = \"a\"\n\
                    start = [135.74974, 464.16913]\ntarget = [124.7, 322.5]\n\
                    initial_velocity = [-0.0027, -0.0047]\n\
                    controller = { kind = \"nadf\", b = 1.0 }\n";
        let world = crate::world::load_str(text, std::path::Path::new("w.toml"), &[]).unwrap();
        let (body, _) = insert_agent(&mut physics, &world.agents[0]);
        for _ in 0..100 {
            physics.step();
        }
        let x = from_rapier(physics.bodies[body].translation());
        let moved = Vector2::new(135.74974 - 0.0027, 464.16913 - 0.0047);
        assert!((x - moved).norm() < 1e-9, "{x} vs {moved}");
    }
}
