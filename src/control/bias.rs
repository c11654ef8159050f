//! Iterative blind error cancellation, eq. 48–50: the control gets a bias, `u = K_P·e - B·v + β`,
//! and at each settling instant β is set to the control measured at that instant, `β ← u`.
//!
//! At rest the control equals the holding force `-G(x_i)` the body needs against the external
//! force at `x_i`, so the recursion is `G(x_i) = G(x_{i-1}) + K_P (x_T - x_i)` (eq. 50): a
//! fixed-point iteration whose fixed point is `x_i = x_T` (Propositions 4 and 5). For a constant
//! external force it converges in one update made at rest. The scheme is blind: it needs only
//! the control it sends, the body's velocity and its mass, not the external force.
//!
//! A settling instant is when the speed has stayed below α for `dwell` seconds after having been
//! above it. Requiring a dwell keeps the turning points of an oscillation, where the speed dips
//! below α for a step, from counting as rest. The paper iterates eq. 50 until the error is
//! cancelled (figure 55), so the body need not move faster than α again between updates: while
//! it stays slow, β is measured again at the end of every `dwell` seconds.
//!
//! **What is measured.** "The control at rest" is the holding force only if the body is exactly
//! at rest; a body slower than α may still accelerate, and then `u = −G + m a`. Measured on the
//! drift world at α = 0.5 m/s: one sample of `u` per rest left 13 mm (the pendulum at α = 0.2 and
//! 0.5 rad/s kept 9 and 6 mrad), and sampling `u` every dwell while slow locked into a 1 s limit
//! cycle of 0.8 mm with β swinging by 0.04 N. So β is set to the control averaged over the
//! dwell, less the momentum it changed: `β ← (1/T)∫u dt − m (v_end − v_start)/T`, which is
//! exactly `−(1/T)∫G dt` (Newton's law over the window) however the body moves in it, and
//! equals `u` for a body at rest. It needs the mass the integrator already uses. The damping
//! term is kept in `u`: it belongs to the momentum balance like every other force.
//!
//! Re-measurements that change β by less than [`CONVERGED`] of its size are made but not
//! counted, so the count says how many updates the iteration needed.

use nalgebra::{SMatrix, SVector};

use super::ControlInput;

/// The relative change of β below which a re-measurement is not counted as an update:
/// `|Δβ| ≤ CONVERGED·|β|`. Far above the noise of an f32 physics at rest (about 1e-6 of the
/// holding force) and below the precision wanted (for the drift world's 5.7 N held by
/// 26 N/m, 1e-4 is 0.02 mm).
pub const CONVERGED: f64 = 1e-4;

/// The bias β and the settling detector that updates it.
#[derive(Debug, Clone, PartialEq)]
pub struct Bias<const N: usize> {
    /// Settling threshold α, m/s (the paper: `0 < α ≪ 1`; typical 0.01–0.5). The body is taken
    /// to be settling while its speed is below α. Any α converges; a smaller one waits for a
    /// slower body before the first update.
    pub alpha: f64,
    /// How long the speed must stay below α before β is updated, and the window over which
    /// the holding force is averaged, s (typical 0.2–1).
    pub dwell: f64,
    /// The body's mass, kg (moment of inertia, kg·m², for a joint): to take the momentum
    /// change out of the averaged control.
    pub mass: f64,
    beta: SVector<f64, N>,
    moved: bool,
    window: Option<Window<N>>,
    updates: usize,
}

/// The control summed since the body became slow, and its velocity then.
#[derive(Debug, Clone, PartialEq)]
struct Window<const N: usize> {
    start_velocity: SVector<f64, N>,
    impulse: SVector<f64, N>,
    time: f64,
}

impl<const N: usize> Bias<N> {
    /// A bias of zero that updates when the speed stays below `alpha` (m/s) for `dwell` (s),
    /// for a body of `mass` kg.
    pub fn new(alpha: f64, dwell: f64, mass: f64) -> Self {
        Self {
            alpha,
            dwell,
            mass,
            beta: SVector::zeros(),
            moved: false,
            window: None,
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

    /// Re-expresses β, and what the current window has summed, in new coordinates: `β ← M β`,
    /// for a controller whose coordinates move with the body. An arm's laws act where its
    /// inertia is the identity, `y = Lᵀ q` with `D(q) = LLᵀ`, and a force `f` there is the
    /// torque `L f`; the paper's β is a torque (eq. 48: the control fed to the robot), so as
    /// `L` changes the bias must keep its torque, `M = L_new⁻¹ L_old`. (Held in the moving
    /// coordinates instead, it acts as a configuration-dependent torque beside the weight's,
    /// and eq. 50 is no longer the recursion: measured on an arm under gravity, the error fell
    /// by 2–3 % per update where eq. 65 gives 80–90 %.) The window's impulse and its starting
    /// momentum are force-like in the same way and take the same map.
    ///
    /// ```
    /// use nadf::control::Bias;
    /// use nalgebra::Matrix2;
    /// let mut bias = Bias::<2>::new(0.1, 0.5, 1.0);
    /// // Nothing measured yet: β stays zero in any coordinates.
    /// bias.reexpress(&Matrix2::new(2.0, 0.0, 0.0, 0.5));
    /// assert_eq!(bias.beta().norm(), 0.0);
    /// ```
    pub fn reexpress(&mut self, m: &SMatrix<f64, N, N>) {
        self.beta = m * self.beta;
        if let Some(window) = &mut self.window {
            window.impulse = m * window.impulse;
            window.start_velocity = m * window.start_velocity;
        }
    }

    /// Watches one step that started at `input` and in which the control `u` (N) was applied;
    /// at the end of each dwell below α sets β to the holding force measured over it (module
    /// docs). Returns whether that was an update: a change of β by more than [`CONVERGED`] of
    /// its size.
    ///
    /// ```
    /// use nadf::control::{Bias, ControlInput};
    /// use nalgebra::Vector1;
    /// // A 2 kg body slowed by the control against an external force of 3 N.
    /// let mut bias = Bias::<1>::new(0.5, 0.1, 2.0);
    /// let (dt, g, u) = (0.01, 3.0, -12.0);
    /// let mut v = 0.6;
    /// let mut updated = false;
    /// for _ in 0..14 {
    ///     let input = ControlInput {
    ///         offset: Vector1::new(0.0),
    ///         velocity: Vector1::new(v),
    ///         gradient: None,
    ///         curvature: None,
    ///         dt,
    ///         touching: false,
    ///         reference_velocity: None,
    ///     };
    ///     updated |= bias.observe(&input, &Vector1::new(u));
    ///     v += dt * (u + g) / 2.0;
    /// }
    /// // Decelerating at 4.5 m/s² all along, yet β is the holding force −G, not the control.
    /// assert!(updated && (bias.beta().x + g).abs() < 1e-9);
    /// ```
    pub fn observe(&mut self, input: &ControlInput<N>, u: &SVector<f64, N>) -> bool {
        let v = input.velocity;
        if v.norm() >= self.alpha {
            // Moving: the next slow spell is a new settling candidate.
            self.moved = true;
            self.window = None;
            return false;
        }
        if !self.moved || !u.iter().all(|c| c.is_finite()) {
            // At rest before ever moving (the start): not a settling instant.
            self.window = None;
            return false;
        }
        let window = self.window.get_or_insert(Window {
            start_velocity: v,
            impulse: SVector::zeros(),
            time: 0.0,
        });
        let mut updated = false;
        if window.time + 1e-12 >= self.dwell {
            // Newton over the window: ∫(u + G) dt = m Δv, so −mean(G) = mean(u) − m Δv/T.
            let t = window.time;
            let holding = window.impulse / t - (v - window.start_velocity) * (self.mass / t);
            if holding.iter().all(|c| c.is_finite()) {
                updated = (holding - self.beta).norm() > CONVERGED * self.beta.norm();
                self.beta = holding;
                self.updates += usize::from(updated);
            }
            // The next window starts here, with this step's control.
            *window = Window {
                start_velocity: v,
                impulse: SVector::zeros(),
                time: 0.0,
            };
        }
        window.impulse += u * input.dt;
        window.time += input.dt;
        updated
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
            curvature: None,
            dt: 0.1,
            touching: false,
            reference_velocity: None,
        }
    }

    #[test]
    fn updates_after_moving_and_every_dwell_below_alpha_counting_real_changes() {
        // A body at rest (the velocity does not change): the holding force is the control.
        let mut bias = Bias::<1>::new(0.05, 0.3, 1.0);
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
        // Three slow steps of 0.1 s, then the instant at the start of the fourth.
        for _ in 0..3 {
            assert!(!bias.observe(&at(0.01), &u));
        }
        assert!(bias.observe(&at(0.01), &u));
        assert!((bias.beta() - u).norm() < 1e-12 && bias.updates() == 1);
        // Still slow: measured again after another dwell (eq. 50 iterated).
        let v = Vector1::new(2.6);
        for _ in 0..2 {
            assert!(!bias.observe(&at(0.01), &v));
        }
        assert!(bias.observe(&at(0.01), &v));
        // The window held one step of 2.5 N and two of 2.6 N.
        assert!((bias.beta().x - 7.7 / 3.0).abs() < 1e-12, "{}", bias.beta());
        assert_eq!(bias.updates(), 2);
        // Held at the same control, β settles on it; once there, the re-measurements (changes
        // below CONVERGED) are made but not counted.
        let held = Vector1::new(2.58);
        for _ in 0..9 {
            bias.observe(&at(0.01), &held);
        }
        let counted = bias.updates();
        assert!((bias.beta() - held).norm() < 1e-12, "{}", bias.beta());
        let settled = held * (1.0 + 0.5 * CONVERGED);
        for _ in 0..30 {
            assert!(!bias.observe(&at(0.01), &settled));
        }
        assert!((bias.beta() - settled).norm() < 1e-12 && bias.updates() == counted);
        // Moving, then slow again: a new settling instant.
        assert!(!bias.observe(&at(0.2), &u));
        for _ in 0..3 {
            assert!(!bias.observe(&at(0.01), &Vector1::new(3.0)));
        }
        assert!(bias.observe(&at(0.01), &u));
        assert!((bias.beta().x - 3.0).abs() < 1e-12 && bias.updates() == counted + 1);
    }

    #[test]
    fn cancels_a_constant_external_force_on_a_spring_in_one_update() {
        // A body held by u = -k·x + β against G: at rest x = (G + β)/k. With β ← u = -G the
        // next rest point is x = 0 (eq. 50 with constant G).
        let (k, g) = (20.0, 4.0);
        let mut bias = Bias::<1>::new(0.05, 0.1, 1.0);
        let rest = |beta: f64| (g + beta) / k;
        let x1 = rest(0.0);
        assert!((x1 - 0.2).abs() < 1e-12);
        bias.observe(&at(1.0), &Vector1::new(0.0));
        let u = Vector1::new(-k * x1 + bias.beta()[0]);
        assert!(!bias.observe(&at(0.0), &u));
        assert!(bias.observe(&at(0.0), &u));
        assert!(rest(bias.beta()[0]).abs() < 1e-12);
    }

    #[test]
    fn a_bias_reexpressed_keeps_its_torque_and_its_window() {
        // An arm's coordinates where the laws act scale by 1/2 (M = 2 maps the old coordinates'
        // forces to the new ones'): the same torque is twice the force there.
        let mut bias = Bias::<1>::new(0.05, 0.3, 1.0);
        let u = Vector1::new(2.5);
        bias.observe(&at(1.0), &u);
        for _ in 0..4 {
            bias.observe(&at(0.01), &u);
        }
        assert!((bias.beta() - u).norm() < 1e-12);
        // Half-way through the next window the coordinates change; the body is held by the same
        // torque throughout, so the window must measure it as one force in the new coordinates.
        bias.observe(&at(0.01), &u);
        let m = nalgebra::Matrix1::new(2.0);
        bias.reexpress(&m);
        assert!((bias.beta() - u * 2.0).norm() < 1e-12);
        for _ in 0..2 {
            bias.observe(&at(0.02), &(u * 2.0));
        }
        assert!(
            !bias.observe(&at(0.02), &(u * 2.0)),
            "no change: not an update"
        );
        assert!((bias.beta() - u * 2.0).norm() < 1e-12, "{}", bias.beta());
    }
}
