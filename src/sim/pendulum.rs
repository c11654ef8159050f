//! The pendulum of the paper's §VI.8: a point mass on a massless rod, on a Rapier revolute
//! joint about a fixed pivot, driven by a torque `u = K·e − B·θ̇ + β` (`e = θ_T − θ`) under
//! gravity, with the iterative bias of eq. 48–50 removing the steady-state error the weight
//! causes.
//!
//! The bob is a dynamic body whose rotation is the pendulum's angle: the joint holds the point
//! `(0, L)` of the bob's frame on the pivot, so at rotation θ the bob sits at
//! `pivot + L (sin θ, −cos θ)` (θ counter-clockwise from hanging down). Its collider is a small
//! sensor ball that carries the mass and touches nothing.

use nalgebra::Vector1;
use rapier2d::prelude::*;
use serde::Serialize;

use crate::control::{Bias, ControlInput, Controller, Spring, Viscous};
use crate::metrics::SETTLING_BAND;
use crate::world::Pendulum;

/// Radius of the bob's collider, m. Its own moment of inertia, `½ M r²`, adds 0.125 % to the
/// pendulum's `M L²` for L = 1 m; it changes the transients, not any equilibrium.
pub const BOB_RADIUS: f64 = 0.05;

/// One pendulum in a running simulation.
pub struct PendulumRun {
    /// The pendulum as the world file describes it.
    pub pendulum: Pendulum,
    /// Its torque law.
    pub controller: Controller<1>,
    /// Its state after the last step.
    pub state: PendulumState,
    body: RigidBodyHandle,
    band: f64,
    settled_at: Option<f64>,
    peak_torque: f64,
    updates: Vec<BiasUpdate>,
}

/// A pendulum's state after a step.
#[derive(Debug, Clone, PartialEq)]
pub struct PendulumState {
    /// The angle θ, rad (continuous: not wrapped to ±π).
    pub theta: f64,
    /// The angular velocity θ̇, rad/s.
    pub omega: f64,
    /// The torque applied during the step, N·m.
    pub torque: f64,
    /// The bias β after the step, N·m (zero without the bias option).
    pub beta: f64,
    /// The bob's position, m.
    pub bob: [f64; 2],
    /// A bias update in this step, as a message.
    pub note: Option<String>,
}

/// One update of the bias β (a settling instant).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BiasUpdate {
    /// When: the start of the step in which it was made, s.
    pub time: f64,
    /// The error `θ_T − θ` at that instant, rad.
    pub error: f64,
    /// The new β, N·m.
    pub beta: f64,
}

/// A pendulum's summary, with the key names of `--json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PendulumSummary {
    /// The pendulum's name.
    pub name: String,
    /// The final `θ_T − θ`, rad.
    pub final_error: f64,
    /// The time the error last entered the 5 % band of its initial value, s; `None` if it ends
    /// outside.
    pub settling_time: Option<f64>,
    /// Largest `|u|`, N·m.
    pub peak_torque: f64,
    /// The equilibrium error of the law without bias, `K e = M L (a_y sin θ + a_x cos θ)`
    /// solved exactly at `θ = θ_T − e`, rad (`M g L sin θ_T / K` for small errors and a
    /// downward gravity g).
    pub static_error: Option<f64>,
    /// Every update of β, in order.
    pub bias_updates: Vec<BiasUpdate>,
}

/// The gravity torque about the pivot at angle θ, N·m: `r × M a` with
/// `r = L (sin θ, −cos θ)`.
pub fn gravity_torque(p: &Pendulum, acceleration: [f64; 2], theta: f64) -> f64 {
    p.mass * p.length * (acceleration[1] * theta.sin() + acceleration[0] * theta.cos())
}

/// The error `e` at which `K e + τ_g(θ_T − e) = 0`, the rest point of `u = K e − B θ̇` (found by
/// Newton's method from `e = 0`); `None` when it does not converge (K too weak to hold the
/// weight anywhere near the target).
pub fn static_error(p: &Pendulum, acceleration: [f64; 2]) -> Option<f64> {
    let k = p.controller.k;
    let mut e: f64 = 0.0;
    for _ in 0..100 {
        let theta = p.target - e;
        let f = k * e + gravity_torque(p, acceleration, theta);
        // d/de τ_g(θ_T − e) = −τ_g'(θ).
        let h = 1e-7;
        let slope = (gravity_torque(p, acceleration, theta + h)
            - gravity_torque(p, acceleration, theta - h))
            / (2.0 * h);
        let df = k - slope;
        if df == 0.0 || !df.is_finite() {
            return None;
        }
        let step = f / df;
        e -= step;
        if step.abs() < 1e-15 {
            return e.is_finite().then_some(e);
        }
    }
    None
}

/// Inserts the pendulum's pivot, bob and joint into `physics`.
pub fn insert(physics: &mut PhysicsWorld, pendulum: &Pendulum) -> PendulumRun {
    let [px, py] = pendulum.pivot;
    let (l, theta) = (pendulum.length, pendulum.start);
    let pivot = physics.insert_body(RigidBodyBuilder::fixed().translation(Vector::new(px, py)));
    let bob_at = [px + l * theta.sin(), py - l * theta.cos()];
    let bob = physics.insert_body(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(bob_at[0], bob_at[1]))
            .rotation(theta)
            .can_sleep(false),
    );
    physics.insert_collider(
        ColliderBuilder::ball(BOB_RADIUS)
            .mass(pendulum.mass)
            .sensor(true),
        Some(bob),
    );
    physics.insert_impulse_joint(
        pivot,
        bob,
        RevoluteJointBuilder::new()
            .local_anchor1(Vector::ZERO)
            .local_anchor2(Vector::new(0.0, l)),
    );
    let c = &pendulum.controller;
    // The torque turns the bob about the pivot: M L² plus the bob's own ½ M r².
    let inertia = pendulum.mass * (l * l + 0.5 * BOB_RADIUS * BOB_RADIUS);
    let mut controller = Controller::new(
        vec![Box::new(Spring { k: c.k }), Box::new(Viscous { b: c.b })],
        inertia,
    );
    controller.bias = c.bias.map(|b| Bias::new(b.alpha, b.dwell, inertia));
    let e0 = (pendulum.target - pendulum.start).abs();
    PendulumRun {
        pendulum: pendulum.clone(),
        controller,
        state: PendulumState {
            theta,
            omega: 0.0,
            torque: 0.0,
            beta: 0.0,
            bob: bob_at,
            note: None,
        },
        body: bob,
        band: SETTLING_BAND * e0,
        settled_at: (e0 == 0.0).then_some(0.0),
        peak_torque: 0.0,
        updates: Vec::new(),
    }
}

impl PendulumRun {
    /// Computes the torque for the step that starts at `time` (s) and applies it to the bob.
    pub fn apply(&mut self, physics: &mut PhysicsWorld, time: f64, dt: f64) {
        let input = ControlInput {
            offset: Vector1::new(self.state.theta - self.pendulum.target),
            velocity: Vector1::new(self.state.omega),
            gradient: None,
            curvature: None,
            dt,
            touching: false,
            reference_velocity: None,
        };
        let out = self.controller.step(&input);
        let torque = out.force.x;
        self.state.torque = torque;
        self.state.beta = self.controller.beta().map_or(0.0, |b| b.x);
        self.state.note = None;
        self.peak_torque = self.peak_torque.max(torque.abs());
        if out.bias_updated {
            let update = BiasUpdate {
                time,
                error: -input.offset.x,
                beta: self.state.beta,
            };
            self.state.note = Some(format!(
                "settling instant at error {:.6} rad: β ← holding torque = {:.4} N·m (update {})",
                update.error,
                update.beta,
                self.updates.len() + 1
            ));
            self.updates.push(update);
        }
        let body = &mut physics.bodies[self.body];
        body.reset_torques(false);
        body.add_torque(torque, true);
    }

    /// Reads the pendulum's state back from Rapier after a step that ended at `time` (s).
    pub fn observe(&mut self, physics: &PhysicsWorld, time: f64) {
        let body = &physics.bodies[self.body];
        // Unwrap Rapier's angle in (−π, π] onto the continuous θ.
        let wrapped = body.rotation().angle();
        let turn = std::f64::consts::TAU;
        let delta = (wrapped - self.state.theta).rem_euclid(turn);
        let delta = if delta > 0.5 * turn {
            delta - turn
        } else {
            delta
        };
        let (theta, omega) = (self.state.theta + delta, body.angvel());
        if theta.is_finite() && omega.is_finite() {
            self.state.theta = theta;
            self.state.omega = omega;
        }
        let t = body.translation();
        self.state.bob = [t.x, t.y];
        let error = (self.pendulum.target - self.state.theta).abs();
        if error > self.band {
            self.settled_at = None;
        } else if self.settled_at.is_none() {
            self.settled_at = Some(time);
        }
    }

    /// The summary so far, with gravity `acceleration` (m/s²) for the static error.
    pub fn summary(&self, acceleration: [f64; 2]) -> PendulumSummary {
        let final_error = self.pendulum.target - self.state.theta;
        PendulumSummary {
            name: self.pendulum.name.clone(),
            final_error,
            settling_time: (final_error.abs() <= self.band)
                .then_some(self.settled_at)
                .flatten(),
            peak_torque: self.peak_torque,
            static_error: static_error(&self.pendulum, acceleration),
            bias_updates: self.updates.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::PendulumController;

    fn pendulum(k: f64, target: f64) -> Pendulum {
        Pendulum {
            name: "p".into(),
            pivot: [0.0, 0.0],
            length: 1.0,
            mass: 1.0,
            start: 0.0,
            target,
            controller: PendulumController {
                k,
                b: 5.0,
                bias: None,
            },
            expect: None,
        }
    }

    #[test]
    fn the_static_error_balances_the_spring_against_the_weight() {
        let g = [0.0, -9.81];
        let p = pendulum(20.0, std::f64::consts::FRAC_PI_2);
        let e = static_error(&p, g).unwrap();
        // At θ_T = π/2: K e = M g L cos e.
        assert!((20.0 * e - 9.81 * e.cos()).abs() < 1e-12, "{e}");
        // Small errors: M g L sin θ_T / K.
        let p = pendulum(1000.0, 0.3);
        let e = static_error(&p, g).unwrap();
        let small = 9.81 * 0.3f64.sin() / 1000.0;
        assert!((e - small).abs() < 0.01 * small, "{e} vs {small}");
    }

    #[test]
    fn gravity_pulls_a_raised_pendulum_back_down() {
        let p = pendulum(20.0, 0.0);
        assert!(gravity_torque(&p, [0.0, -9.81], 0.5) < 0.0);
        assert!(gravity_torque(&p, [0.0, -9.81], -0.5) > 0.0);
        assert_eq!(gravity_torque(&p, [0.0, -9.81], 0.0), 0.0);
    }
}
