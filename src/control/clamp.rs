//! The clamping control, eq. 35–36: `F = -K_c · (x - x_T) · Φ(σ - |x - x_T|) · Φ(vᵀ(x - x_T))`.
//!
//! It acts only inside the ball of radius σ around the target and only while the body moves away
//! from the target, so it never disturbs the approach and is passive for any `K_c > 0`
//! (Proposition 3). Under an external force `G` it traps the body: the rest point solves
//! `G + F_guidance + K_c (x - x_T) = 0` (eq. 47), within `|G| / K_c` of the target or closer.

use nalgebra::SVector;

use super::nadf::step;
use super::{ControlInput, ControlLaw};

/// The clamping control.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clamp {
    /// Gain K_c, N/m (the paper uses 10). Proposition 3 asks for `K_c ≥ F_max / ε` to keep the
    /// error under ε against an external force of at most `F_max`.
    pub kc: f64,
    /// Radius σ of the clamping region, m (the paper's figure 27 uses 0.5).
    pub sigma: f64,
    /// The body's mass, kg (for the discrete-time rest band of [`Clamp::active`]).
    pub mass: f64,
}

impl Clamp {
    /// Whether the clamp acts for this input: inside σ (`Φ(σ - |e|)`) and not moving towards the
    /// target (`Φ(vᵀe)`, with `Φ(0) = 1`: at rest it holds).
    ///
    /// In discrete time "not moving towards the target" must allow a small speed towards it.
    /// Held at rest by the clamp against an external force, a body that the clamp's own force
    /// `K_c|e|` nudges inwards for one step gets a speed `K_c|e|·dt/m` towards the target; if
    /// that switched the clamp off, the external force would push it back out the next step,
    /// switching it on again: a two-step limit cycle (measured on the drift world with
    /// `r_c = 0.25`: the force jumping by 1.5 N every step, a control variation of 9157 N
    /// instead of 424 N). So a body approaching slower than twice that speed counts as at rest.
    pub fn active<const N: usize>(&self, input: &ControlInput<N>) -> bool {
        let e = &input.offset;
        let distance = e.norm();
        let rest_speed = 2.0 * self.kc * distance * input.dt / self.mass;
        step(self.sigma - distance) * step(input.velocity.dot(e) + rest_speed * distance) > 0.0
    }
}

impl<const N: usize> ControlLaw<N> for Clamp {
    fn force(&self, input: &ControlInput<N>) -> SVector<f64, N> {
        if self.active(input) {
            -input.offset * self.kc
        } else {
            SVector::zeros()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    fn input(offset: [f64; 2], velocity: [f64; 2]) -> ControlInput<2> {
        ControlInput {
            offset: Vector2::from(offset),
            velocity: Vector2::from(velocity),
            gradient: None,
            dt: 0.01,
        }
    }

    #[test]
    fn pulls_back_only_inside_sigma_and_only_when_moving_away() {
        let clamp = Clamp {
            kc: 10.0,
            sigma: 0.5,
            mass: 1.0,
        };
        // Moving away, inside σ: a spring back to the target.
        let f = clamp.force(&input([0.3, 0.0], [0.1, 0.0]));
        assert_eq!(f, Vector2::new(-3.0, 0.0));
        // At rest inside σ: Φ(0) = 1, it holds.
        assert_eq!(
            clamp.force(&input([0.0, 0.2], [0.0, 0.0])),
            Vector2::new(0.0, -2.0)
        );
        // Moving towards the target: inactive.
        assert_eq!(
            clamp.force(&input([0.3, 0.0], [-0.1, 0.0])),
            Vector2::zeros()
        );
        // Approaching slower than one step of the clamp's pull (2·K_c|e|·dt/m = 0.06 m/s) is
        // rest: it holds.
        assert_eq!(
            clamp.force(&input([0.3, 0.0], [-0.05, 0.0])),
            Vector2::new(-3.0, 0.0)
        );
        // Outside σ: inactive.
        assert_eq!(
            clamp.force(&input([0.6, 0.0], [0.1, 0.0])),
            Vector2::zeros()
        );
    }

    #[test]
    fn is_passive() {
        // vᵀF ≤ 0 for every state (the last term of eq. 44), up to the rest band: a body creeping
        // in slower than 2·K_c|e|·dt/m gains at most K_c|e| times that, W.
        let clamp = Clamp {
            kc: 7.0,
            sigma: 1.0,
            mass: 1.0,
        };
        for (e, v) in [
            ([0.3, -0.2], [1.0, 0.5]),
            ([0.1, 0.1], [-1.0, 0.2]),
            ([0.9, 0.0], [0.0, 3.0]),
            ([0.5, 0.0], [-0.05, 0.0]),
        ] {
            let i = input(e, v);
            let d = i.offset.norm();
            let bound = clamp.kc * d * (2.0 * clamp.kc * d * i.dt / clamp.mass);
            assert!(i.velocity.dot(&clamp.force(&i)) <= bound);
        }
    }
}
