//! The speed limit of paper §VI.2 (design page, "Speed limit"): at or above `v_max`, the part of
//! the control force that would accelerate the body further along its velocity is dropped.
//!
//! NADF leaves motion along the guidance undamped, so a body on a long streamline keeps
//! speeding up; the limit caps the radial speed at `v_max` at the cost of a longer settling time
//! and buys a lower control effort (paper figures 19–22: 12 s → 16 s).
//!
//! In continuous time only the part of the force along `v` changes the speed. In a discrete step
//! the sideways part `F_⊥` also lengthens the velocity, by about `(F_⊥ dt/m)² / 2|v|`; in a
//! long turn at the limit that adds up (measured on the room world with K = 5: 5.16 m/s against
//! a 5 m/s limit). At the limit the along part is therefore set to the small braking force that
//! keeps the speed exactly where it is over the step, and the body never exceeds `v_max` by
//! more than the one step of acceleration that crosses it.
//!
//! A force the controller does not know about (an external drift along the motion) can still
//! push the body past the limit. Above `v_max` the limiter therefore also brakes by the excess,
//! `m (|v| - v_max)/dt` (back to the limit in one step): feedback on the measured speed, which
//! needs no model of the external force. Without external forces the body is never above the
//! limit by more than one step's control acceleration, and this term stays that small.
//!
//! **Braking envelope** (`brake = a`, m/s²): the limit also never exceeds `√(2 a d)`, `d` the
//! distance to the target, the speed from which a deceleration `a` stops the body exactly on the
//! target. NADF leaves motion along the guidance undamped, so without it a body crosses a large
//! map at the speed its guidance has built up and overshoots a target in a corner into the walls
//! (measured on a Moving AI arena: 9.4 m/s at arrival, two contacts). With the envelope the
//! limiter brakes along the way, `m a` at most, and the body arrives at rest. The guidance's own
//! taper inside `capture_radius` is too short to do this: it removes the push, not the speed.

use nalgebra::SVector;

/// The limit holds the speed (pushes no further) from this fraction below `v_max`. Braking back to
/// exactly `v_max` leaves the speed a rounding error (f32 in Rapier) below or above it; a hard
/// switch at `v_max` would then push with the full guidance one step and brake the next, for
/// ever (measured: control variation 442 N instead of 228 N on `room-speed-limit.toml`).
pub const HOLD_BAND: f64 = 1e-3;

/// A cap on the speed the controller drives the body to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedLimit {
    /// The limit `v_max`, m/s (the paper uses 5 m/s; infinite for a braking envelope alone).
    /// The body can overshoot it by at most one step's acceleration, `|F|/m · dt`.
    pub v_max: f64,
    /// The braking envelope's deceleration `a`, m/s² (typical: 0.5–3 for a body that the
    /// guidance accelerates at `K/m` ≈ 1 m/s²): the limit is at most `√(2 a d)` at a distance
    /// `d` from the target. `None`: no envelope.
    pub brake: Option<f64>,
    /// The body's mass, kg (to keep the speed constant over a discrete step).
    pub mass: f64,
}

impl SpeedLimit {
    /// The limit at a distance `d` (m) from the target, m/s.
    pub fn cap(&self, d: f64) -> f64 {
        match self.brake {
            Some(a) => self.v_max.min((2.0 * a * d).sqrt()),
            None => self.v_max,
        }
    }

    /// The force `force` (N) applied over a step of `dt` (s), at a distance `d` (m) from the
    /// target, with its accelerating part along `v` removed when `|v|` reaches the limit
    /// ([`SpeedLimit::cap`]) where the step ends (`|v| dt` closer: the envelope falls as the
    /// body closes in), and whether the limit acted. Braking and steering parts are kept.
    pub fn limit<const N: usize>(
        &self,
        force: SVector<f64, N>,
        v: &SVector<f64, N>,
        d: f64,
        dt: f64,
    ) -> (SVector<f64, N>, bool) {
        let speed = v.norm();
        let v_max = self.cap((d - speed * dt).max(0.0));
        if !(speed >= v_max * (1.0 - HOLD_BAND) && speed > 0.0) {
            return (force, false);
        }
        let heading = v / speed;
        let along = heading.dot(&force);
        let sideways = force - heading * along;
        // The along part that keeps |v + F dt/m| = |v| (zero in continuous time).
        let turn = sideways.norm() * dt / self.mass;
        let hold = if turn < speed {
            self.mass / dt * ((speed * speed - turn * turn).sqrt() - speed)
        } else {
            -self.mass / dt * speed
        } - self.mass / dt * (speed - v_max).max(0.0);
        if along > hold {
            (sideways + heading * hold, true)
        } else {
            (force, false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, Vector2};

    const LIMIT: SpeedLimit = SpeedLimit {
        v_max: 5.0,
        brake: None,
        mass: 2.0,
    };
    /// Far from the target: the envelope does not act.
    const FAR: f64 = 1e9;

    #[test]
    fn below_the_limit_nothing_changes() {
        let f = Vector2::new(3.0, 1.0);
        assert_eq!(
            LIMIT.limit(f, &Vector2::new(4.99, 0.0), FAR, 0.01),
            (f, false)
        );
        // Within the hold band just under the limit, the push is dropped, nothing more.
        let (f, active) = LIMIT.limit(f, &Vector2::new(4.999, 0.0), FAR, 0.01);
        assert!(active && f.x.abs() < 1e-3, "{f}");
    }

    #[test]
    fn at_the_limit_the_accelerating_part_is_dropped_and_the_speed_holds() {
        let dt = 0.01;
        let v = Vector2::new(5.0, 0.0);
        let (f, active) = LIMIT.limit(Vector2::new(3.0, 40.0), &v, FAR, dt);
        assert!(active);
        // Steering is kept; the along part is a tiny brake (zero as dt → 0).
        assert_eq!(f.y, 40.0);
        assert!(f.x < 0.0 && f.x > -1.0, "{f}");
        let next = v + f * dt / LIMIT.mass;
        assert!((next.norm() - 5.0).abs() < 1e-12, "{}", next.norm());
        // Above the limit (pushed by a force the controller does not know): back to it in a step.
        let v = Vector2::new(5.2, 0.0);
        let (f, active) = LIMIT.limit(Vector2::new(3.0, 0.0), &v, FAR, dt);
        assert!(active);
        assert!(((v + f * dt / LIMIT.mass).norm() - 5.0).abs() < 1e-12);
        // Braking harder than the limit needs is kept.
        let (f, active) = LIMIT.limit(Vector2::new(-3.0, 1.0), &Vector2::new(5.0, 0.0), FAR, dt);
        assert!(!active);
        assert_eq!(f, Vector2::new(-3.0, 1.0));
    }

    #[test]
    fn an_unknown_drift_along_the_motion_is_braked() {
        let (dt, mut v) = (0.01, Vector2::new(4.0, 0.0));
        let drift = Vector2::new(8.0, 0.0);
        let mut peak: f64 = 0.0;
        for _ in 0..1000 {
            let (f, _) = LIMIT.limit(Vector2::new(6.0, 0.0), &v, FAR, dt);
            v += (f + drift) * dt / LIMIT.mass;
            peak = peak.max(v.norm());
        }
        // One step of the drift's and the control's acceleration at most: (8 + 6)/2 · 0.01.
        assert!(peak <= 5.0 + 0.07 + 1e-12, "{peak}");
    }

    #[test]
    fn a_long_turn_at_the_limit_does_not_creep_above_it() {
        // A body pushed sideways every step (a turn) with a forward push too.
        let (dt, mut v) = (0.01, Vector2::new(5.0, 0.0));
        for _ in 0..1000 {
            let normal = Vector2::new(-v.y, v.x).normalize();
            let (f, _) = LIMIT.limit(normal * 60.0 + v.normalize() * 10.0, &v, FAR, dt);
            v += f * dt / LIMIT.mass;
        }
        assert!((v.norm() - 5.0).abs() < 1e-9, "{}", v.norm());
    }

    /// A body pushed towards its target at 1 m/s² from 10 m away, with the envelope at 2 m/s²:
    /// it never exceeds √(2 a d) by more than a step's push, and arrives at rest.
    #[test]
    fn the_braking_envelope_stops_the_body_on_the_target() {
        let limit = SpeedLimit {
            v_max: f64::INFINITY,
            brake: Some(2.0),
            mass: 1.0,
        };
        let dt = 0.01;
        let (mut x, mut v) = (-10.0_f64, 0.0_f64);
        let mut arrived_at = None;
        for step in 0..3000 {
            let push = if x < 0.0 { 1.0 } else { -1.0 };
            let (f, _) = limit.limit(Vector1::new(push), &Vector1::new(v), -x, dt);
            v += f.x * dt;
            x += v * dt;
            assert!(
                v.abs() <= limit.cap(x.abs()) * (1.0 + HOLD_BAND) + dt,
                "{v} at {x}"
            );
            if arrived_at.is_none() && x.abs() < 0.01 && v.abs() < 0.1 {
                arrived_at = Some(step);
            }
        }
        assert!(
            arrived_at.is_some() && x.abs() < 0.01 && v.abs() < 0.05,
            "{x} {v}"
        );
        // Without it the body runs past the target at about √(2 · 1 · 10) m/s.
        assert!(
            SpeedLimit {
                brake: None,
                ..limit
            }
            .cap(0.0)
            .is_infinite()
        );
    }
}
