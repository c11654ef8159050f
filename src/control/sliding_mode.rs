//! The sliding-mode baseline of Guldner and Utkin (eq. 72–73):
//! `S = v - v_d · (-g/|g|)`, `F = -F_0 · S/|S|` (zero when `S = 0`).
//!
//! The body is driven onto the sliding surface where it moves down the streamline at `v_d`; the
//! discontinuous law then switches every step to stay there, which is what makes its control
//! signal chatter (paper figures 30–33). Like normalized guidance, `v_d` tapers linearly to zero
//! inside the capture radius, so the body comes to rest at the target instead of crossing it at
//! `v_d` and turning back forever.

use nalgebra::SVector;

use super::{ControlInput, ControlLaw, unit};

/// Sliding-mode control on the guidance field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlidingMode {
    /// Desired speed `v_d` along the guidance, m/s: sets the settling time (about the path length
    /// over `v_d`).
    pub vd: f64,
    /// Control magnitude `F_0`, N: the force applied at every step (the paper tunes it to a peak
    /// of 100 N). It must exceed any external force the body meets.
    pub f0: f64,
    /// Radius inside which `v_d` tapers to zero, m.
    pub capture_radius: f64,
}

impl SlidingMode {
    /// The sliding variable `S` of eq. 72, m/s. Where the guidance is undefined the desired
    /// velocity is zero, so the law brakes.
    pub fn surface<const N: usize>(&self, input: &ControlInput<N>) -> SVector<f64, N> {
        let distance = input.offset.norm();
        let taper = if self.capture_radius > 0.0 {
            (distance / self.capture_radius).min(1.0)
        } else {
            1.0
        };
        match input.gradient.as_ref().and_then(unit) {
            // S = v - v_d · (-u) = v + v_d · u.
            Some(u) => input.velocity + u * (self.vd * taper),
            None => input.velocity,
        }
    }
}

impl<const N: usize> ControlLaw<N> for SlidingMode {
    fn force(&self, input: &ControlInput<N>) -> SVector<f64, N> {
        let s = self.surface(input);
        match unit(&s) {
            Some(direction) => -direction * self.f0,
            None => SVector::zeros(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn law() -> SlidingMode {
        SlidingMode {
            vd: 2.0,
            f0: 100.0,
            capture_radius: 0.25,
        }
    }

    #[test]
    fn pushes_towards_the_desired_velocity_with_full_force() {
        // Guidance points -x (g = +x); at rest, S = v_d·u = (2, 0) and F = (-100, 0).
        let input = ControlInput {
            offset: Vector2::new(5.0, 0.0),
            velocity: Vector2::zeros(),
            gradient: Some(Vector2::new(1e-6, 0.0)),
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: None,
        };
        assert_eq!(law().force(&input), Vector2::new(-100.0, 0.0));
        // Faster than v_d along the guidance: S flips and the law brakes.
        let input = ControlInput {
            velocity: Vector2::new(-3.0, 0.0),
            ..input
        };
        assert_eq!(law().force(&input), Vector2::new(100.0, 0.0));
        // On the surface exactly: no force, never NaN.
        let input = ControlInput {
            velocity: Vector2::new(-2.0, 0.0),
            ..input
        };
        assert_eq!(law().force(&input), Vector2::zeros());
    }

    #[test]
    fn without_guidance_it_brakes() {
        let input = ControlInput {
            offset: Vector2::new(5.0, 0.0),
            velocity: Vector2::new(0.0, 1.0),
            gradient: None,
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: None,
        };
        assert_eq!(law().force(&input), Vector2::new(0.0, -100.0));
    }
}
