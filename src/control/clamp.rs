//! The clamping control, eq. 35–36: `F = -K_c · (x - x_T) · Φ(σ - |x - x_T|) · Φ(vᵀ(x - x_T))`.
//!
//! It acts only inside the ball of radius σ around the target and only while the body moves away
//! from the target, so it never disturbs the approach and is passive for any `K_c > 0`
//! (Proposition 3). Under an external force `G` it traps the body: the rest point solves
//! `G + F_guidance + K_c (x - x_T) = 0` (eq. 47), within `|G| / K_c` of the target or closer.

use nalgebra::SVector;

use super::ControlInput;
use super::nadf::step;

/// The clamping control.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clamp {
    /// Gain K_c, N/m (the paper uses 10). Proposition 3 asks for `K_c ≥ F_max / ε` to keep the
    /// error under ε against an external force of at most `F_max`. Any value is stable: the
    /// stiffness is integrated implicitly ([`super::Integrator`]).
    pub kc: f64,
    /// Radius σ of the clamping region, m (the paper's figure 27 uses 0.5).
    pub sigma: f64,
}

impl Clamp {
    /// Whether the clamp acts for this input: inside σ (`Φ(σ - |e|)`) and not moving towards the
    /// target (`Φ(vᵀe)`, with `Φ(0) = 1`: at rest it holds).
    ///
    /// In discrete time "not moving towards the target" must allow a small speed towards it,
    /// `rest_speed` (m/s). Held at rest by the clamp against an external force, a body that
    /// the clamp switches off for one step is pushed out by the other forces, switching it on
    /// again: a two-step limit cycle (measured on the drift world with `r_c = 0.25`: the force
    /// jumping by 1.5 N every step, a control variation of 9157 N instead of 424 N). The
    /// controller therefore counts as rest any approach slower than twice what the forces other
    /// than the clamp (guidance, bias, the estimated external force) change the velocity by in
    /// one step, `2 |F_other| dt/m` ([`Clamp::rest_speed`]). It must not depend on `K_c`: a
    /// band of `K_c |e| dt/m` lets a stiff clamp that holds a body off its rest point release
    /// its spring inwards "at rest" (measured: K_c = 10⁴ threw the drift world's body at 28 m/s).
    pub fn active<const N: usize>(&self, input: &ControlInput<N>, rest_speed: f64) -> bool {
        let e = &input.offset;
        let distance = e.norm();
        step(self.sigma - distance) * step(input.velocity.dot(e) + rest_speed * distance) > 0.0
    }

    /// The band of [`Clamp::active`], m/s: twice the change of velocity the other forces,
    /// `|F_other|` N, give a body of `mass` kg over a step of `dt` s.
    pub fn rest_speed(other_force: f64, dt: f64, mass: f64) -> f64 {
        2.0 * other_force * dt / mass
    }

    /// The clamp's force, N: `-K_c e` when [`Clamp::active`], else zero.
    pub fn force<const N: usize>(
        &self,
        input: &ControlInput<N>,
        rest_speed: f64,
    ) -> SVector<f64, N> {
        if self.active(input, rest_speed) {
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
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: None,
        }
    }

    #[test]
    fn pulls_back_only_inside_sigma_and_only_when_moving_away() {
        let clamp = Clamp {
            kc: 10.0,
            sigma: 0.5,
        };
        // Moving away, inside σ: a spring back to the target.
        let f = clamp.force(&input([0.3, 0.0], [0.1, 0.0]), 0.0);
        assert_eq!(f, Vector2::new(-3.0, 0.0));
        // At rest inside σ: Φ(0) = 1, it holds.
        assert_eq!(
            clamp.force(&input([0.0, 0.2], [0.0, 0.0]), 0.0),
            Vector2::new(0.0, -2.0)
        );
        // Moving towards the target: inactive.
        assert_eq!(
            clamp.force(&input([0.3, 0.0], [-0.1, 0.0]), 0.0),
            Vector2::zeros()
        );
        // Approaching slower than the rest band (here what 3 N give 1 kg in two steps of
        // 0.01 s, 0.06 m/s) is rest: it holds.
        let rest = Clamp::rest_speed(3.0, 0.01, 1.0);
        assert!((rest - 0.06).abs() < 1e-15);
        assert_eq!(
            clamp.force(&input([0.3, 0.0], [-0.05, 0.0]), rest),
            Vector2::new(-3.0, 0.0)
        );
        assert_eq!(
            clamp.force(&input([0.3, 0.0], [-0.07, 0.0]), rest),
            Vector2::zeros()
        );
        // Outside σ: inactive.
        assert_eq!(
            clamp.force(&input([0.6, 0.0], [0.1, 0.0]), rest),
            Vector2::zeros()
        );
    }

    #[test]
    fn is_passive() {
        // vᵀF ≤ 0 for every state (the last term of eq. 44), up to the rest band: a body creeping
        // in slower than the band gains at most K_c|e| times it, W.
        let clamp = Clamp {
            kc: 7.0,
            sigma: 1.0,
        };
        let rest = 0.06;
        for (e, v) in [
            ([0.3, -0.2], [1.0, 0.5]),
            ([0.1, 0.1], [-1.0, 0.2]),
            ([0.9, 0.0], [0.0, 3.0]),
            ([0.5, 0.0], [-0.05, 0.0]),
        ] {
            let i = input(e, v);
            let bound = clamp.kc * i.offset.norm() * rest;
            assert!(i.velocity.dot(&clamp.force(&i, rest)) <= bound);
        }
    }
}
