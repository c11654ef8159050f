//! The one calibration of the reproduction: how the scale the paper leaves unstated is fixed.
//!
//! The paper gives no room size, no gain K for figures 4–24 (eq. 8 has none), no time step and
//! no integrator, and its numbers cannot hold literally: with K = 1 N·m and V ∈ [0, 1],
//! Proposition 1 caps a 1 kg body at √2 m/s, yet §VI.2 reaches a 5 m/s limit. Under the
//! paper's law `m ẍ = −K∇V − B ẋ` a room of size L and a gain K enter only as `K/(m L²)`
//! (scale x by L, keep t: ∇V scales as 1/L, so K must scale as L²); the damping rates B/m and
//! every speed, force and acceleration the paper prints in SI units (5 m/s, 4 m/s², 100 N,
//! ±0.5 m, 25 m) fix the rest. So one number is free, and this module fixes it from one of the
//! paper's numbers, the settling time of figure 16:
//!
//! - **The room** is the sandbox's 10 m × 10 m room with two dividers (the paper shows it only
//!   in figures), the robot a **1 kg point mass** (a 5 cm collider, one field cell, so Rapier has
//!   something to touch with: the field's walls are the real walls grown by 5 cm) and the target
//!   a disc of 0.2 m (a point has zero capacity in 2-D; see the field's docs).
//! - **dt = 5 ms**, the damping and stiffness integrated exactly (the sandbox's integrator); the
//!   paper's unknown integrator is tested as a hypothesis (the explicit step) at every B.
//! - **K** of `F = −K∇V` is [`K_PAPER`]: the K at which NADF B_d = 10 settles in 12 s (figure 16),
//!   read off the sweep [`SWEEP_PAPER`] by log-log interpolation (T_S ∝ K^−½ to within 1 %
//!   between its points). The paper's K = 1 of figure 27 is mapped to the same K; its
//!   K_c = 10 N/m and B_d = 10 N·s/m are rates per unit mass and keep their values.
//! - The sandbox's variant, **normalized guidance** `−K∇V/|∇V|`, gets its own K
//!   ([`K_NORMALIZED`], N) from the same 12 s, on the same sweep principle ([`SWEEP_NORMALIZED`]).
//! - **The corridor** (§VI.6) is guided by Khatib's potential, whose pull is a force, not the
//!   harmonic K: [`PULL`] is fixed from figure 38's 25 m in 10 s with viscous B = 0.3, by the
//!   free-running solution `x(t) = (K/B)[t − (m/B)(1 − e^{−Bt/m})]` (22.78 m per newton).
//!
//! Everything else is a prediction. `tests/reproduce.rs` checks that the declared gains are
//! the ones the sweeps give.

/// The paper's settling time of NADF B_d = 10 in the room (figure 16), s: the calibration's
/// one number.
pub const T_FIGURE_16: f64 = 12.0;

/// K of the paper's law `F = −K∇V`, J (N·m: V is dimensionless), calibrated so that NADF
/// B_d = 10 settles in [`T_FIGURE_16`].
pub const K_PAPER: f64 = 1036.0;

/// K of normalized guidance `F = −K∇V/|∇V|`, N, calibrated the same way.
pub const K_NORMALIZED: f64 = 0.148;

/// The gains of the calibration sweep under the paper's law, J.
pub const SWEEP_PAPER: [f64; 5] = [100.0, 300.0, 1000.0, 3000.0, 10000.0];

/// The gains of the calibration sweep under normalized guidance, N.
pub const SWEEP_NORMALIZED: [f64; 4] = [0.05, 0.1, 0.3, 1.0];

/// The paper's distance at 10 s in the corridor with viscous B = 0.3 (figure 38), m.
pub const D_FIGURE_38: f64 = 25.0;

/// The corridor's pull (Khatib's conic attraction), N: [`D_FIGURE_38`] over the free-running
/// distance per newton of a 1 kg body under B = 0.3 in 10 s.
pub const PULL: f64 = 1.0975;

/// The free-running distance of a body of mass `m` pulled by 1 N against viscous damping `b`
/// after `t` seconds, m: `(1/B)[t − (m/B)(1 − e^{−Bt/m})]`.
///
/// ```
/// use nadf::reproduce::calibration::{D_FIGURE_38, PULL, free_run};
/// let per_newton = free_run(0.3, 1.0, 10.0);
/// assert!((per_newton - 22.78).abs() < 0.01);
/// assert!((D_FIGURE_38 / per_newton - PULL).abs() < 5e-4);
/// ```
pub fn free_run(b: f64, m: f64, t: f64) -> f64 {
    (t - (m / b) * (1.0 - (-b * t / m).exp())) / b
}

/// The gain at which a settling time falling with the gain reaches `t`, by log-log
/// interpolation between the two sampled gains that bracket it; `None` when no pair does.
/// `points` are `(gain, settling time)` in increasing gain.
///
/// ```
/// use nadf::reproduce::calibration::gain_for;
/// // T = 12 s at K = 1000 and T ∝ K^−½: T = 6 s at K = 4000.
/// let k = gain_for(&[(1000.0, 12.0), (16000.0, 3.0)], 6.0).unwrap();
/// assert!((k - 4000.0).abs() < 1e-6);
/// ```
pub fn gain_for(points: &[(f64, f64)], t: f64) -> Option<f64> {
    points.windows(2).find_map(|w| {
        let ((k0, t0), (k1, t1)) = (w[0], w[1]);
        if !(t1 <= t && t <= t0) || t0 <= 0.0 || t1 <= 0.0 {
            return None;
        }
        let slope = (t1 / t0).ln() / (k1 / k0).ln();
        Some(k0 * ((t / t0).ln() / slope).exp())
    })
}
