//! A robot on two wheels (`[agents.drive] kind = "differential"`, issue 28): a disc that turns,
//! pushed only along its heading by its two wheels, held sideways by the ground's grip, and
//! steered by its look-ahead point ([`DriveBody`]).
//!
//! **Feedback linearization.** The axle's centre `c` cannot move sideways, so it is not fully
//! actuated; the point `p = c + ℓ h` at the look-ahead `ℓ > 0` ahead of it is. With the heading
//! `h = (cos θ, sin θ)`, its normal `n`, the forward speed `u = v·h`, the turn rate `ω`, the mass
//! `m` and the inertia `I`, rolling without slip gives
//! `p̈ = (F/m − ℓω²) h + (uω + ℓτ/I) n` for the wheels' forward force `F = F_l + F_r` and their
//! torque `τ = (F_r − F_l) s/2` (`s` the wheel separation). The wheels that give `p` the
//! acceleration `a` are therefore `F = m (a·h + ℓω²)` and `τ = I (a·n − uω)/ℓ`: the point then
//! obeys `m p̈ = f` for the controller's force `f = m a`, and every law of `control` (guidance,
//! NADF, the clamp, the bias, the speed limit, the brake) acts on it exactly as on a disc of
//! mass `m`. **Proposition 1 holds for the point**: `K V(p) + ½ m |ṗ|²` never increases while the
//! limits below are not met. It says nothing about the heading, the internal dynamics left
//! free by the linearization: the body trails the point, turning to follow it, and only the
//! point's path is the kinematic path (the axle's strays from it; both are measured).
//!
//! **Limits.** Each wheel's force is at most `max_wheel_force` and its speed at most
//! `max_wheel_speed`. Both are affine in the acceleration asked of the point, so the wheels take
//! the largest fraction `σ ∈ [0, 1]` of it, `σ a`, that keeps all four within their limits over
//! the step: the force keeps its direction, only its size shrinks (the drift terms `ℓω²` and
//! `uω` are always compensated). When even `σ = 0` breaks a limit (a wheel pushed over its speed,
//! or a turn whose drift the motors cannot hold), the wheels aim at the speeds the drift alone
//! would give, clamped to their limit, with forces scaled down together to theirs: the point
//! then follows the law only approximately, and the step is counted (`clipped_steps`).
//!
//! **Grip.** The ground's sideways force is whatever makes the axle's velocity at the end of the
//! step lie along the heading at the end of the step, computed from the step's own update (so
//! that it holds at any `dt`, as the exact damping does), and at most `lateral_grip`; beyond it
//! the robot skids, and its sideways speed is measured (`peak_slip`).

use nalgebra::Vector2;
use rapier2d::prelude::{PhysicsWorld, RigidBodyHandle};
use serde::Serialize;

use super::body::Body;
use super::physics::{from_rapier, to_rapier};
use crate::field::Streamline;
use crate::world::{Agent, DriveSettings};

/// A robot on two wheels in Rapier, as the control laws see it: its configuration is its
/// look-ahead point, its force the one that point should feel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveBody {
    /// Its Rapier body (a disc at the axle's centre).
    pub handle: RigidBodyHandle,
    /// The look-ahead `ℓ`, m.
    pub lookahead: f64,
    /// The wheel separation `s`, m.
    pub separation: f64,
    /// Each wheel's largest speed, m/s.
    pub max_speed: f64,
    /// Each wheel's largest force, N.
    pub max_force: f64,
    /// The largest sideways force of the ground, N (`None`: it never skids).
    pub grip: Option<f64>,
    /// Mass, kg.
    pub mass: f64,
    /// Moment of inertia about the axle's centre, kg·m².
    pub inertia: f64,
    /// The physics step, s.
    pub dt: f64,
    /// The world's external acceleration, m/s² (Rapier applies it; the grip balances its
    /// sideways part).
    pub gravity: Vector2<f64>,
}

/// What the wheels did in one step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wheels {
    /// The left and right wheels' forces, N.
    pub forces: [f64; 2],
    /// The left and right wheels' speeds at the start of the step, m/s.
    pub speeds: [f64; 2],
    /// The ground's sideways force, N.
    pub lateral_force: f64,
    /// The axle's sideways speed at the start of the step, m/s.
    pub slip: f64,
    /// The fraction `σ` of the point's acceleration the limits allowed (0 when even the drift
    /// could not be met: see the module).
    pub scale: f64,
    /// Whether the limits were met only by clipping (`σ = 0` infeasible).
    pub clipped: bool,
    /// The heading, rad, and the turn rate, rad/s, at the start of the step.
    pub heading: (f64, f64),
}

/// The body's state at the start of a step.
#[derive(Debug, Clone, Copy)]
struct Kinematics {
    centre: Vector2<f64>,
    velocity: Vector2<f64>,
    theta: f64,
    omega: f64,
}

impl Kinematics {
    fn heading(&self) -> Vector2<f64> {
        Vector2::new(self.theta.cos(), self.theta.sin())
    }
    fn normal(&self) -> Vector2<f64> {
        Vector2::new(-self.theta.sin(), self.theta.cos())
    }
}

/// The values `q0 + σ q1` of a quantity bounded by `±limit`: the interval of `σ` that keeps it
/// there (`None` if none does).
fn allowed(q0: f64, q1: f64, limit: f64) -> Option<(f64, f64)> {
    if q1.abs() < 1e-300 {
        return (q0.abs() <= limit).then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let (a, b) = ((-limit - q0) / q1, (limit - q0) / q1);
    Some((a.min(b), a.max(b)))
}

impl DriveBody {
    /// The body of `agent` (with a drive) at `handle`, for steps of `dt` s under `gravity`.
    pub fn new(handle: RigidBodyHandle, agent: &Agent, dt: f64, gravity: [f64; 2]) -> Self {
        let drive: &DriveSettings = agent.drive.as_ref().expect("an agent with wheels");
        let r = drive.body_radius;
        Self {
            handle,
            lookahead: drive.lookahead_for(r),
            separation: drive.wheel_separation,
            max_speed: drive.max_wheel_speed,
            max_force: drive.max_wheel_force,
            grip: drive.lateral_grip,
            mass: agent.mass,
            inertia: Self::inertia_of(agent),
            dt,
            gravity: Vector2::from(gravity),
        }
    }

    /// The moment of inertia of `agent` on wheels about its axle's centre, kg·m²: `inertia`,
    /// or a uniform disc's `½ m r²` of its footprint.
    pub fn inertia_of(agent: &Agent) -> f64 {
        let r = agent.drive.as_ref().map_or(agent.radius, |d| d.body_radius);
        agent.inertia.unwrap_or(0.5 * agent.mass * r * r)
    }

    fn kinematics(&self, physics: &PhysicsWorld) -> Kinematics {
        let body = &physics.bodies[self.handle];
        Kinematics {
            centre: from_rapier(body.translation()),
            velocity: from_rapier(body.linvel()),
            theta: body.rotation().angle(),
            omega: body.angvel(),
        }
    }

    /// The axle's centre, m.
    pub fn axle(&self, physics: &PhysicsWorld) -> Vector2<f64> {
        self.kinematics(physics).centre
    }

    /// The heading, rad (Rapier's angle, in (−π, π]).
    pub fn heading(&self, physics: &PhysicsWorld) -> f64 {
        self.kinematics(physics).theta
    }

    /// The wheels' forces for the point force `force` (N), within the limits (see the module),
    /// and what they measure at the start of the step.
    pub fn wheels(&self, physics: &PhysicsWorld, force: &Vector2<f64>) -> Wheels {
        let k = self.kinematics(physics);
        let (h, n) = (k.heading(), k.normal());
        let (m, i, l, s, dt) = (
            self.mass,
            self.inertia,
            self.lookahead,
            self.separation,
            self.dt,
        );
        let u = k.velocity.dot(&h);
        let a = force / m;
        // The forward force and the torque as q0 + σ q1 (the drift, then what σ scales).
        let forward = (m * l * k.omega * k.omega, m * a.dot(&h));
        let torque = (-i * u * k.omega / l, i * a.dot(&n) / l);
        let wheel = |(f0, f1): (f64, f64), (t0, t1): (f64, f64), side: f64| {
            (0.5 * f0 + side * t0 / s, 0.5 * f1 + side * t1 / s)
        };
        let (left, right) = (wheel(forward, torque, -1.0), wheel(forward, torque, 1.0));
        // The wheels' speeds at the end of the step.
        let speed = |side: f64| {
            let v0 = u + side * k.omega * s / 2.0 + dt * self.gravity.dot(&h);
            (
                v0 + dt * (forward.0 / m + side * torque.0 * s / (2.0 * i)),
                dt * (forward.1 / m + side * torque.1 * s / (2.0 * i)),
            )
        };
        let limits = [
            (left, self.max_force),
            (right, self.max_force),
            (speed(-1.0), self.max_speed),
            (speed(1.0), self.max_speed),
        ];
        let mut range = Some((0.0_f64, 1.0_f64));
        for ((q0, q1), limit) in limits {
            range = range.and_then(|(lo, hi)| {
                let (a, b) = allowed(q0, q1, limit)?;
                let (lo, hi) = (lo.max(a), hi.min(b));
                (lo <= hi).then_some((lo, hi))
            });
        }
        let speeds = [u - k.omega * s / 2.0, u + k.omega * s / 2.0];
        let (forces, scale, clipped) = match range {
            Some((_, sigma)) => (
                [left.0 + sigma * left.1, right.0 + sigma * right.1],
                sigma,
                false,
            ),
            None => {
                // Even the drift breaks a limit: the wheels' speeds at the end of the step the
                // drift would give, clamped to their limit, reached by forces within theirs.
                let ends =
                    [speed(-1.0).0, speed(1.0).0].map(|v| v.clamp(-self.max_speed, self.max_speed));
                let (forces, _) = self.forces_for(&k, ends);
                (forces, 0.0, true)
            }
        };
        self.report(&k, (forces, speeds), scale, clipped)
    }

    /// What the wheels do with `forces` (left, right) from `speeds` (at the start of the step):
    /// with the grip for them, the slip and the heading now.
    fn report(
        &self,
        k: &Kinematics,
        (forces, speeds): ([f64; 2], [f64; 2]),
        scale: f64,
        clipped: bool,
    ) -> Wheels {
        Wheels {
            forces,
            speeds,
            lateral_force: self.grip_force(k, forces),
            slip: k.velocity.dot(&k.normal()),
            scale,
            clipped,
            heading: (k.theta, k.omega),
        }
    }

    /// The wheels' `forces` (left, right) as their forward force `F`, N, their torque `τ`,
    /// N·m, and the heading's normal at the end of the step (Rapier's update: ω first, then
    /// the angle), where the grip acts.
    fn push_of(&self, k: &Kinematics, forces: [f64; 2]) -> (f64, f64, Vector2<f64>) {
        let (f, t) = (
            forces[0] + forces[1],
            (forces[1] - forces[0]) * self.separation / 2.0,
        );
        let theta_end = k.theta + self.dt * (k.omega + self.dt * t / self.inertia);
        (f, t, Vector2::new(-theta_end.sin(), theta_end.cos()))
    }

    /// The grip for the wheels' `forces` (left, right): the sideways force that puts the
    /// velocity at the end of the step along the heading at the end of the step, at most
    /// `lateral_grip`.
    fn grip_force(&self, k: &Kinematics, forces: [f64; 2]) -> f64 {
        let (f, _, n_end) = self.push_of(k, forces);
        let before = k.velocity + (k.heading() * f / self.mass + self.gravity) * self.dt;
        let lateral = -self.mass * before.dot(&n_end) / self.dt;
        self.grip.map_or(lateral, |grip| lateral.clamp(-grip, grip))
    }

    /// The peers' kinematic unicycle law on the guidance direction `guidance` (a unit vector,
    /// `None` where the field gives none) at `distance` m from the target: forward speed
    /// `v_max cos e` and turn rate `k e`, both tapered by `min(1, d/r_c)` inside the capture
    /// radius `r_c` as the normalized guidance is (without it the robot spins on the target,
    /// where the guidance's direction flips), `e` the angle from the
    /// heading to the guidance; the wheels' speeds for it scaled down together to their limit
    /// (keeping the turn's radius, as navground does), and reached in one step by forces within
    /// theirs (scaled down together).
    pub fn unicycle(
        &self,
        physics: &PhysicsWorld,
        guidance: Option<Vector2<f64>>,
        (v_max, turn_gain, capture_radius): (f64, f64, f64),
        distance: f64,
    ) -> Wheels {
        let k = self.kinematics(physics);
        let (h, n) = (k.heading(), k.normal());
        let (u_star, omega_star) = guidance.map_or((0.0, 0.0), |g| {
            let e = g.dot(&n).atan2(g.dot(&h));
            let taper = if capture_radius > 0.0 {
                (distance / capture_radius).min(1.0)
            } else {
                1.0
            };
            (v_max * e.cos() * taper, turn_gain * e * taper)
        });
        let s = self.separation;
        let mut targets = [u_star - omega_star * s / 2.0, u_star + omega_star * s / 2.0];
        let fastest = targets[0].abs().max(targets[1].abs());
        if fastest > self.max_speed {
            targets = targets.map(|v| v * self.max_speed / fastest);
        }
        let u = k.velocity.dot(&h);
        let speeds = [u - k.omega * s / 2.0, u + k.omega * s / 2.0];
        let (forces, scale) = self.forces_for(&k, targets);
        self.report(&k, (forces, speeds), scale, false)
    }

    /// The wheels' forces (left, right) that bring their speeds to `targets` (m/s) at the end
    /// of the step, scaled down together to within their limit, and that scale: each wheel's
    /// force changes its own speed by `dt (1/m + s²/4I)` per newton and the other's by
    /// `dt (1/m − s²/4I)`.
    fn forces_for(&self, k: &Kinematics, targets: [f64; 2]) -> ([f64; 2], f64) {
        let (s, dt) = (self.separation, self.dt);
        let h = k.heading();
        let u = k.velocity.dot(&h);
        let speeds = [u - k.omega * s / 2.0, u + k.omega * s / 2.0];
        let alpha = 1.0 / self.mass + s * s / (4.0 * self.inertia);
        let beta = 1.0 / self.mass - s * s / (4.0 * self.inertia);
        let gravity = dt * self.gravity.dot(&h);
        let (dl, dr) = (
            (targets[0] - speeds[0] - gravity) / dt,
            (targets[1] - speeds[1] - gravity) / dt,
        );
        let det = alpha * alpha - beta * beta;
        let forces = [
            (alpha * dl - beta * dr) / det,
            (alpha * dr - beta * dl) / det,
        ];
        let strongest = forces[0].abs().max(forces[1].abs());
        if strongest > self.max_force {
            let scale = self.max_force / strongest;
            (forces.map(|f| f * scale), scale)
        } else {
            (forces, 1.0)
        }
    }

    /// The wheels' forces as the force on the body's centre, N (the control force a disc's
    /// metrics would record).
    pub fn body_force(&self, physics: &PhysicsWorld, wheels: &Wheels) -> Vector2<f64> {
        self.kinematics(physics).heading() * (wheels.forces[0] + wheels.forces[1])
    }

    /// Applies `wheels` (and the grip) for the next step, after resetting the body's forces.
    pub fn apply(&self, physics: &mut PhysicsWorld, wheels: &Wheels) {
        let k = self.kinematics(physics);
        let (f, t, n_end) = self.push_of(&k, wheels.forces);
        let total = k.heading() * f + n_end * wheels.lateral_force;
        let body = &mut physics.bodies[self.handle];
        body.reset_forces(false);
        body.reset_torques(false);
        if total.iter().all(|c| c.is_finite()) && t.is_finite() {
            body.add_force(to_rapier(total), true);
            body.add_torque(t, true);
        }
    }
}

impl Body<2> for DriveBody {
    type Config = [f64; 2];

    /// The look-ahead point `c + ℓh` and its velocity `v + ℓω n`.
    fn state(&self, physics: &PhysicsWorld) -> Option<([f64; 2], Vector2<f64>)> {
        let k = self.kinematics(physics);
        let p = k.centre + k.heading() * self.lookahead;
        let v = k.velocity + k.normal() * (self.lookahead * k.omega);
        p.iter()
            .chain(v.iter())
            .all(|c| c.is_finite())
            .then_some((p.into(), v))
    }

    fn actuate(&self, physics: &mut PhysicsWorld, force: &Vector2<f64>) {
        let wheels = self.wheels(physics, force);
        self.apply(physics, &wheels);
    }
}

crate::measured! {
    /// A robot on wheels' summary beside its agent's (whose metrics are its look-ahead
    /// point's): the wheels, the grip and the heading.
    #[derive(Debug, Clone, PartialEq, Serialize)]
    pub struct DriveSummary {
        /// The agent's name.
        pub name: String,
        /// The largest wheel speed, m/s.
        pub peak_wheel_speed: f64 [unit("m/s"), digits(3), column("wheel_mps")],
        /// The largest wheel force, N.
        pub peak_wheel_force: f64 [unit("N"), digits(3), column("wheel_N")],
        /// The largest sideways speed of the axle, m/s.
        pub peak_slip: f64 [unit("m/s"), column("slip_mps")],
        /// `δ_m` of the axle's centre: its largest distance from the kinematic path of the
        /// look-ahead point, m.
        pub axle_deviation: f64 [unit("m"), column("axle_dev_m")],
        /// The largest turn rate, rad/s.
        pub peak_turn_rate: f64 [unit("rad/s"), digits(2), column("turn_radps")],
        /// Reversals of the turn between turns faster than [`TURN_REVERSAL`]: how much the
        /// heading oscillates.
        pub heading_reversals: usize [column("reversals")],
        /// Steps in which the limits scaled the point's force down (`σ < 1`).
        pub limited_steps: usize [column("limited")],
        /// Steps in which even the drift broke a limit and the wheels were clipped.
        pub clipped_steps: usize [column("clipped")],
    }
}

/// A reversal of the turn counts only between turns faster than this, rad/s, so that the
/// jitter of a robot driving straight is not counted as oscillation.
pub const TURN_REVERSAL: f64 = 0.2;

/// The running measurements of a robot on wheels.
#[derive(Debug, Clone, Default)]
pub struct DriveMetrics {
    peak_wheel_speed: f64,
    peak_wheel_force: f64,
    peak_slip: f64,
    peak_turn_rate: f64,
    reversals: usize,
    last_turn: f64,
    limited: usize,
    clipped: usize,
    axle_path: Vec<[f64; 2]>,
}

impl DriveMetrics {
    /// Records one step's wheels, and the axle's centre after it, m.
    pub fn record(&mut self, wheels: &Wheels, axle: Vector2<f64>) {
        let speed = wheels.speeds[0].abs().max(wheels.speeds[1].abs());
        self.peak_wheel_speed = self.peak_wheel_speed.max(speed);
        let force = wheels.forces[0].abs().max(wheels.forces[1].abs());
        self.peak_wheel_force = self.peak_wheel_force.max(force);
        self.peak_slip = self.peak_slip.max(wheels.slip.abs());
        let omega = wheels.heading.1;
        self.peak_turn_rate = self.peak_turn_rate.max(omega.abs());
        if omega.abs() > TURN_REVERSAL {
            if self.last_turn * omega < 0.0 {
                self.reversals += 1;
            }
            self.last_turn = omega;
        }
        self.limited += usize::from(wheels.scale < 1.0);
        self.clipped += usize::from(wheels.clipped);
        self.axle_path.push(axle.into());
    }

    /// The summary of agent `name` whose look-ahead point's kinematic path is `kinematic`.
    pub fn summary(&self, name: &str, kinematic: &Streamline) -> DriveSummary {
        DriveSummary {
            name: name.to_string(),
            peak_wheel_speed: self.peak_wheel_speed,
            peak_wheel_force: self.peak_wheel_force,
            peak_slip: self.peak_slip,
            axle_deviation: kinematic.max_distance(&self.axle_path),
            peak_turn_rate: self.peak_turn_rate,
            heading_reversals: self.reversals,
            limited_steps: self.limited,
            clipped_steps: self.clipped,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::physics::empty_world;
    use rapier2d::prelude::{ColliderBuilder, MassProperties, RigidBodyBuilder, Vector};

    /// A 1 kg robot of radius 0.1 m, wheels 0.16 m apart, at the origin heading along +x.
    fn robot(omega: f64, v: [f64; 2]) -> (PhysicsWorld, DriveBody) {
        let mut physics = empty_world(0.01, [0.0, 0.0]);
        let body = RigidBodyBuilder::dynamic()
            .linvel(Vector::new(v[0], v[1]))
            .angvel(omega)
            .additional_mass_properties(MassProperties::new(Vector::ZERO, 1.0, 0.005));
        let collider = ColliderBuilder::ball(0.1).density(0.0);
        let (handle, _) = physics.insert(body, collider);
        let drive = DriveBody {
            handle,
            lookahead: 0.05,
            separation: 0.16,
            max_speed: 0.5,
            max_force: 2.0,
            grip: None,
            mass: 1.0,
            inertia: 0.005,
            dt: 0.01,
            gravity: Vector2::zeros(),
        };
        (physics, drive)
    }

    /// The look-ahead point accelerates as the force asks, in any direction, when no limit is
    /// met: forward and sideways from rest, and with the drift of a turn compensated.
    #[test]
    fn the_look_ahead_point_obeys_the_force() {
        for (omega, v, f) in [
            (0.0, [0.0, 0.0], [0.3, 0.0]),
            (0.0, [0.0, 0.0], [0.0, 0.2]),
            (1.5, [0.2, 0.0], [0.1, -0.1]),
        ] {
            let (mut physics, drive) = robot(omega, v);
            let f = Vector2::from(f);
            let (_, before) = drive.state(&physics).unwrap();
            let wheels = drive.wheels(&physics, &f);
            assert!((wheels.scale - 1.0).abs() < 1e-12, "{wheels:?}");
            drive.apply(&mut physics, &wheels);
            physics.step();
            let (_, after) = drive.state(&physics).unwrap();
            let accel = (after - before) / 0.01;
            // To first order in dt (the heading turns during the step).
            assert!(
                (accel - f).norm() < 0.03 + 0.02 * f.norm(),
                "{omega} {v:?}: {accel} vs {f}"
            );
        }
    }

    /// A force beyond the wheels' limits keeps its direction (the scale shrinks), the forces
    /// stay within the limit, and the grip keeps the axle from sliding sideways.
    #[test]
    fn limits_scale_the_force_and_the_grip_holds() {
        let (mut physics, drive) = robot(0.0, [0.0, 0.0]);
        let f = Vector2::new(30.0, 10.0);
        let wheels = drive.wheels(&physics, &f);
        assert!(
            wheels.scale < 1.0 && wheels.scale > 0.0 && !wheels.clipped,
            "{wheels:?}"
        );
        assert!(
            wheels.forces.iter().all(|w| w.abs() <= 2.0 + 1e-9),
            "{wheels:?}"
        );
        // The limited point's force is σ f: its direction.
        for _ in 0..200 {
            let (_, v) = drive.state(&physics).unwrap();
            let wheels = drive.wheels(&physics, &(-v * 4.0 + Vector2::new(3.0, 3.0)));
            drive.apply(&mut physics, &wheels);
            physics.step();
            let after = drive.wheels(&physics, &Vector2::zeros());
            // f32 physics and its rotation update: a tenth of a millimetre per second.
            assert!(after.slip.abs() < 5e-4, "{after:?}");
            assert!(
                after.speeds.iter().all(|s| s.abs() <= 0.5 + 1e-4),
                "{after:?}"
            );
        }
    }
}
