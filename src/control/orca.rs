//! ORCA beside NADF: optimal reciprocal collision avoidance (van den Berg, Guy, Lin & Manocha,
//! *Reciprocal n-body collision avoidance*, 2011), the method crowd and multi-robot research
//! compares against, through the maintained `dodgy_2d` crate (a port of RVO2).
//!
//! Not the paper's method. Each step an ORCA agent's *preferred velocity* is its harmonic
//! guidance at full speed, `−v_max ∇V/|∇V|` (slowing down linearly inside `capture_radius` of
//! the target), so it still goes around walls; ORCA replaces it with the velocity closest to it
//! that keeps the agent clear of every neighbour for `time_horizon` seconds, each pair sharing
//! the avoidance half and half; and a force tracks that velocity ([`VelocityTracking`]). ORCA
//! works on velocities, so the only dynamics are the tracking's time constant. The walls are
//! left to the guidance (ORCA sees agents only).
//!
//! `dodgy_2d` works in f32 on its own `glam` vectors: the conversion is here, at the ORCA
//! boundary, and nowhere else.

use std::borrow::Cow;

use dodgy_2d::{Agent, AvoidanceOptions, Vec2};
use nalgebra::{SMatrix, SVector, Vector2};

use super::integrator::Split;
use super::{ControlInput, ControlLaw, unit};

/// Another agent as ORCA sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Position, m.
    pub position: Vector2<f64>,
    /// Velocity, m/s.
    pub velocity: Vector2<f64>,
    /// Radius, m.
    pub radius: f64,
    /// Whether it takes its half of the avoiding, as an agent running ORCA does; a scripted
    /// obstacle does not, and leaves all of it to the agent (ORCA's avoidance responsibility:
    /// 1 or 0).
    pub reciprocal: bool,
}

/// ORCA's settings for one agent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orca {
    /// Top speed `v_max`, m/s: the preferred speed, and the largest ORCA returns (the
    /// controller's `speed_limit`; typical: 1–2 m/s for a robot).
    pub max_speed: f64,
    /// How far ahead ORCA keeps clear of the neighbours, s. Longer: earlier, gentler
    /// avoidance, but more conservative in a crowd (typical: 2–10 s).
    pub time_horizon: f64,
    /// Agents nearer than this (centre to centre) are neighbours, m (typical: a few times the
    /// distance covered in `time_horizon`).
    pub neighbour_distance: f64,
    /// Inside this distance from the target the preferred speed falls linearly to zero, m.
    pub capture_radius: f64,
}

impl Orca {
    /// The preferred velocity: along the guidance `−g/|g|` at `max_speed`, slower inside the
    /// capture radius; zero where the guidance gives no direction. `offset` is `x − x_T`.
    ///
    /// ```
    /// use nalgebra::Vector2;
    /// let orca = nadf::control::Orca {
    ///     max_speed: 2.0, time_horizon: 2.0, neighbour_distance: 10.0, capture_radius: 0.5,
    /// };
    /// // Far from the target: down the gradient at full speed.
    /// let v = orca.preferred_velocity(Some(Vector2::new(0.0, 3.0)), Vector2::new(0.0, 5.0));
    /// assert_eq!(v, Vector2::new(0.0, -2.0));
    /// // Half-way into the capture radius: half speed.
    /// let v = orca.preferred_velocity(Some(Vector2::new(0.0, 3.0)), Vector2::new(0.0, 0.25));
    /// assert!((v.y + 1.0).abs() < 1e-12);
    /// ```
    pub fn preferred_velocity(
        &self,
        gradient: Option<Vector2<f64>>,
        offset: Vector2<f64>,
    ) -> Vector2<f64> {
        let Some(u) = gradient.as_ref().and_then(unit) else {
            return Vector2::zeros();
        };
        let taper = if self.capture_radius > 0.0 {
            (offset.norm() / self.capture_radius).min(1.0)
        } else {
            1.0
        };
        -u * (self.max_speed * taper)
    }

    /// ORCA's velocity for an agent `me` that prefers `preferred`, among `neighbours` (those
    /// farther than `neighbour_distance` are left out), for a step of `dt` seconds. Finite
    /// and at most `max_speed` long.
    pub fn velocity(
        &self,
        me: &Neighbour,
        preferred: Vector2<f64>,
        neighbours: &[Neighbour],
        dt: f64,
    ) -> Vector2<f64> {
        let agent = |n: &Neighbour| Agent {
            position: to_orca(n.position),
            velocity: to_orca(n.velocity),
            radius: n.radius as f32,
            avoidance_responsibility: if n.reciprocal { 1.0 } else { 0.0 },
        };
        let near: Vec<Cow<'_, Agent>> = neighbours
            .iter()
            .filter(|n| (n.position - me.position).norm() < self.neighbour_distance)
            .map(|n| Cow::Owned(agent(n)))
            .collect();
        let options = AvoidanceOptions {
            obstacle_margin: 0.0,
            time_horizon: self.time_horizon as f32,
            obstacle_time_horizon: self.time_horizon as f32,
        };
        let v = agent(me).compute_avoiding_velocity(
            &near,
            &[],
            to_orca(preferred),
            self.max_speed as f32,
            dt as f32,
            &options,
        );
        let v = Vector2::new(f64::from(v.x), f64::from(v.y));
        if v.iter().all(|c| c.is_finite()) {
            v
        } else {
            Vector2::zeros()
        }
    }
}

/// A nalgebra vector as ORCA's (f32) vector.
fn to_orca(v: Vector2<f64>) -> Vec2 {
    Vec2::new(v.x as f32, v.y as f32)
}

/// The force that tracks a reference velocity `v_ref` ([`ControlInput::reference_velocity`]):
/// `F = B (v_ref − v)`, with `B = m/τ`. Integrated exactly ([`super::Integrator`]), the
/// velocity error decays as `e^{−t/τ}` for any step. Without a reference it is plain viscous
/// damping (the body stops).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityTracking {
    /// The tracking gain `B = m/τ`, N·s/m (τ, the time constant, typical 0.05–0.5 s).
    pub b: f64,
}

impl<const N: usize> ControlLaw<N> for VelocityTracking {
    fn force(&self, input: &ControlInput<N>) -> SVector<f64, N> {
        let target = input.reference_velocity.unwrap_or_else(SVector::zeros);
        (target - input.velocity) * self.b
    }

    fn split(&self, input: &ControlInput<N>) -> Split<N> {
        let target = input.reference_velocity.unwrap_or_else(SVector::zeros);
        let mut split = Split::damping(self.b, SMatrix::identity());
        split.explicit = target * self.b;
        split
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn orca() -> Orca {
        Orca {
            max_speed: 2.0,
            time_horizon: 2.0,
            neighbour_distance: 10.0,
            capture_radius: 0.5,
        }
    }

    /// Two agents head-on: ORCA turns each one aside (the same way, so they pass), and
    /// keeps the speed within the top speed.
    #[test]
    fn head_on_agents_turn_aside() {
        let a = Neighbour {
            position: Vector2::new(0.0, 0.0),
            velocity: Vector2::new(2.0, 0.0),
            radius: 0.3,
            reciprocal: true,
        };
        let b = Neighbour {
            position: Vector2::new(2.0, 0.0),
            velocity: Vector2::new(-2.0, 0.0),
            radius: 0.3,
            reciprocal: true,
        };
        let va = orca().velocity(&a, Vector2::new(2.0, 0.0), &[b], 0.01);
        let vb = orca().velocity(&b, Vector2::new(-2.0, 0.0), &[a], 0.01);
        assert!(va.norm() <= 2.0 + 1e-6 && vb.norm() <= 2.0 + 1e-6);
        assert!(va.y.abs() > 0.1 && vb.y.abs() > 0.1, "{va} {vb}");
        // Opposite sides in the world: each passes the other on the same hand.
        assert!(va.y * vb.y < 0.0, "{va} {vb}");
        // Nobody in the way: the preferred velocity itself.
        let alone = orca().velocity(&a, Vector2::new(2.0, 0.0), &[], 0.01);
        assert!((alone - Vector2::new(2.0, 0.0)).norm() < 1e-6);
        // The same body as a scripted obstacle, which holds its course: the agent does all
        // the avoiding, so it turns further aside than when the other takes its half.
        let obstacle = Neighbour {
            reciprocal: false,
            ..b
        };
        let alone_avoids = orca().velocity(&a, Vector2::new(2.0, 0.0), &[obstacle], 0.01);
        assert!(
            alone_avoids.y.abs() > va.y.abs() + 0.05,
            "{alone_avoids} vs {va}"
        );
    }

    /// The tracking law's split gives the same force as the law, and pulls the velocity
    /// towards the reference.
    #[test]
    fn tracking_pulls_towards_the_reference() {
        let law = VelocityTracking { b: 10.0 };
        let input = ControlInput::<2> {
            offset: Vector2::new(1.0, 0.0),
            velocity: Vector2::new(0.5, 0.0),
            gradient: None,
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: Some(Vector2::new(2.0, 1.0)),
        };
        let f = ControlLaw::force(&law, &input);
        assert_eq!(f, Vector2::new(15.0, 10.0));
        let split = ControlLaw::split(&law, &input);
        assert!((split.force(&input.velocity) - f).norm() < 1e-12);
    }
}
