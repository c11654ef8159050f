//! Building the Rapier world from a world file, and the one conversion between the control
//! laws' nalgebra `f64` vectors and Rapier's `glam` `f32` ones.

use nalgebra::Vector2;
use rapier2d::prelude::*;

use crate::world::{Agent, WallShape};

/// Rapier vector → control-law vector.
pub fn from_rapier(v: Vector) -> Vector2<f64> {
    Vector2::new(f64::from(v.x), f64::from(v.y))
}

/// Control-law vector → Rapier vector.
pub fn to_rapier(v: Vector2<f64>) -> Vector {
    Vector::new(v.x as f32, v.y as f32)
}

/// A Rapier world with the given step whose gravity is the world's external acceleration, m/s²
/// (Rapier applies `m·a` to every dynamic body).
pub fn empty_world(dt: f64, external_acceleration: [f64; 2]) -> PhysicsWorld {
    PhysicsWorld {
        gravity: Vector::new(
            external_acceleration[0] as f32,
            external_acceleration[1] as f32,
        ),
        integration_parameters: IntegrationParameters {
            dt: dt as f32,
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
            .translation(Vector::new(axle[0] as f32, axle[1] as f32))
            .rotation(agent.heading as f32)
            .can_sleep(false)
            .ccd_enabled(true)
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                agent.mass as f32,
                inertia as f32,
            ));
        let collider = ColliderBuilder::ball(r as f32)
            .density(0.0)
            .friction(0.0)
            .restitution(0.0);
        return physics.insert(body, collider);
    }
    let [vx, vy] = agent.initial_velocity;
    let body = RigidBodyBuilder::dynamic()
        .translation(Vector::new(agent.start[0] as f32, agent.start[1] as f32))
        .linvel(Vector::new(vx as f32, vy as f32))
        .lock_rotations()
        .can_sleep(false)
        .ccd_enabled(true);
    let collider = ColliderBuilder::ball(agent.radius as f32)
        .mass(agent.mass as f32)
        .friction(0.0)
        .restitution(0.0);
    physics.insert(body, collider)
}
