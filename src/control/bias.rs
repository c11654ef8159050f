//! Iterative blind error cancellation, eq. 48–50: the control gets a bias, `u = K_P·e - B·v + β`,
//! and at each settling instant β is set to the control measured at that instant, `β ← u`.
//!
//! At rest the control equals the holding force `-G(x_i)` the body needs against the external
//! force at `x_i`, so the recursion is `G(x_i) = G(x_{i-1}) + K_P (x_T - x_i)` (eq. 50): a
//! fixed-point iteration whose fixed point is `x_i = x_T` (Propositions 4 and 5). For a constant
//! external force it converges in one update. The scheme is blind: it needs only the control
//! it sends and the body's speed, not the external force.
//!
//! A settling instant is when the speed has stayed below α for `dwell` seconds after having been
//! above it: one update per rest. Requiring a dwell keeps the turning points of an oscillation,
//! where the speed dips below α for a step, from counting as rest. A body that stays at rest is
//! not re-measured: near the target the control is dominated by the discrete field's jitter
//! (measured on the drift world: β re-measured every 0.5 s wandered by ±0.04 N with the body
//! already within 1 mm), so re-measuring would only add noise. α sets the precision: an update
//! that moves the body slower than α is the last one.

use nalgebra::SVector;

use super::ControlInput;

/// The bias β and the settling detector that updates it.
#[derive(Debug, Clone, PartialEq)]
pub struct Bias<const N: usize> {
    /// Settling threshold α, m/s (the paper: `0 < α ≪ 1`; typical 0.01–0.1). The body is taken
    /// to be settling while its speed is below α.
    pub alpha: f64,
    /// How long the speed must stay below α before β is updated, s (typical 0.2–1).
    pub dwell: f64,
    beta: SVector<f64, N>,
    moved: bool,
    slow_for: f64,
    updates: usize,
}

impl<const N: usize> Bias<N> {
    /// A bias of zero that updates when the speed stays below `alpha` (m/s) for `dwell` (s).
    pub fn new(alpha: f64, dwell: f64) -> Self {
        Self {
            alpha,
            dwell,
            beta: SVector::zeros(),
            moved: false,
            slow_for: 0.0,
            updates: 0,
        }
    }

    /// The current bias β, N.
    pub fn beta(&self) -> SVector<f64, N> {
        self.beta
    }

    /// Updates of β so far.
    pub fn updates(&self) -> usize {
        self.updates
    }

    /// Watches one step in which the control `u` (N) was applied; at a settling instant sets
    /// `β ← u` (eq. 49). Returns whether it did.
    pub fn observe(&mut self, input: &ControlInput<N>, u: &SVector<f64, N>) -> bool {
        if input.velocity.norm() >= self.alpha {
            // Moving: the next slow spell is a new settling candidate.
            self.moved = true;
            self.slow_for = 0.0;
            return false;
        }
        if !self.moved {
            // At rest before moving again (the start, or after an update): not a new instant.
            return false;
        }
        self.slow_for += input.dt;
        if self.slow_for + 1e-12 < self.dwell || !u.iter().all(|c| c.is_finite()) {
            return false;
        }
        self.moved = false;
        self.slow_for = 0.0;
        self.beta = *u;
        self.updates += 1;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector1;

    fn at(speed: f64) -> ControlInput<1> {
        ControlInput {
            offset: Vector1::new(0.1),
            velocity: Vector1::new(speed),
            gradient: None,
            dt: 0.1,
            touching: false,
        }
    }

    #[test]
    fn updates_only_after_moving_and_dwelling_below_alpha() {
        let mut bias = Bias::<1>::new(0.05, 0.3);
        let u = Vector1::new(2.5);
        // At rest at the start: never an instant.
        for _ in 0..10 {
            assert!(!bias.observe(&at(0.0), &u));
        }
        assert!(!bias.observe(&at(1.0), &u));
        // A one-step dip (a turning point) is not enough.
        assert!(!bias.observe(&at(0.01), &u));
        assert!(!bias.observe(&at(1.0), &u));
        assert_eq!(bias.beta(), Vector1::zeros());
        // Three slow steps of 0.1 s: the third is the settling instant.
        assert!(!bias.observe(&at(0.01), &u));
        assert!(!bias.observe(&at(0.01), &u));
        assert!(bias.observe(&at(0.01), &u));
        assert_eq!((bias.beta(), bias.updates()), (u, 1));
        // Still at rest: no new instant until it has moved again.
        for _ in 0..10 {
            assert!(!bias.observe(&at(0.01), &Vector1::new(9.0)));
        }
        assert_eq!((bias.beta(), bias.updates()), (u, 1));
        assert!(!bias.observe(&at(0.2), &u));
        for _ in 0..2 {
            assert!(!bias.observe(&at(0.01), &u));
        }
        assert!(bias.observe(&at(0.01), &Vector1::new(3.0)));
        assert_eq!((bias.beta(), bias.updates()), (Vector1::new(3.0), 2));
    }

    #[test]
    fn cancels_a_constant_external_force_on_a_spring_in_one_update() {
        // A body held by u = -k·x + β against G: at rest x = (G + β)/k. With β ← u = -G the
        // next rest point is x = 0 (eq. 50 with constant G).
        let (k, g) = (20.0, 4.0);
        let mut bias = Bias::<1>::new(0.05, 0.1);
        let rest = |beta: f64| (g + beta) / k;
        let x1 = rest(0.0);
        assert!((x1 - 0.2).abs() < 1e-12);
        bias.observe(&at(1.0), &Vector1::new(0.0));
        let u = Vector1::new(-k * x1 + bias.beta()[0]);
        assert!(bias.observe(&at(0.0), &u));
        assert!(rest(bias.beta()[0]).abs() < 1e-12);
    }
}
