//! Integrating the linear parts of a control law exactly, so that damping and clamping are stable
//! for any gain (paper §III, Propositions 2 and 3: δ_m falls as B_d grows, clamping is passive
//! for any K_c).
//!
//! Rapier integrates a force with one semi-implicit Euler step, `v' = v + dt (F + G)/m`,
//! `x' = x + dt v'`. A damping force `-B v` computed at the start of the step is then unstable
//! once `B dt/m > 2` (measured on the room at dt = 0.01 s, m = 1 kg: B_d = 199 reaches, 201 runs
//! away at 400 m/s), and a stiff clamp ejects the body (K_c = 10⁴: 55 m/s). The paper's laws are
//! continuous; what is unstable is the explicit step, not the law.
//!
//! Every law here is linear in the velocity and the offset once its switches (Φ of eq. 10 and
//! 35) are fixed for the step: `F = F_e − B P v − K e`, where `P` is a projector (the identity
//! for viscous damping, the damped directions of NADF, eq. 9) and `K` the stiffness of the clamp
//! (eq. 35) or of the pendulum's spring (eq. 75). [`Integrator`] integrates that over the step,
//! holding `F_e` constant:
//!
//! - the damped components (range of `P`) decay exactly as `m v̇ = −B v + F` says:
//!   `v' = e^{−x} v + φ(x)·dt/m·F` with `x = B dt/m` and `φ(x) = (1 − e^{−x})/x`, the exponential
//!   (zero-order hold) solution, which tends to the continuous law's terminal velocity `F/B`
//!   for any B;
//! - the stiffness acts at the end of the step's position, `e + dt v'` (implicit Euler, which
//!   is stable and dissipative for any K): the damped components are divided by `1 + φ K dt²/m`,
//!   the free ones by `1 + K dt²/m`.
//!
//! The result is handed to Rapier as the force `m (v' − v)/dt` it integrates back to `v'`. For
//! small gains this is the explicit law to first order in `dt`.
//!
//! External forces (gravity, drift) are not known to the controller, but the law's rest points
//! (eq. 47) and the bias (eq. 50) balance them. A blind disturbance observer therefore estimates
//! them from the last step, `Ĝ = m (v − v_prev)/dt − F_prev`, and they enter the integration
//! beside `F_e`; at rest the applied force is then exactly the continuous law's. Steps in
//! which the body touched something are not used: a contact impulse is not an external force,
//! and counting it as one would press the body back into the wall.

use nalgebra::{SMatrix, SVector};

use super::ControlInput;

/// A law's force at one instant, split into what the integrator treats exactly and the rest:
/// `F(x + δ, v) ≈ explicit − stiffness · δ − damping · damped · v` for a small displacement δ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Split<const N: usize> {
    /// The force at the body's position, without the damping, N.
    pub explicit: SVector<f64, N>,
    /// The damping coefficient B, N·s/m (N·m·s/rad for a joint); zero for none.
    pub damping: f64,
    /// The projector `P` onto the damped directions (the identity for viscous damping).
    pub damped: SMatrix<f64, N, N>,
    /// The stiffness `S = −∂F/∂x`, N/m (N·m/rad for a joint), symmetric and positive
    /// semi-definite: `K I` for a spring to the target, `K ∇∇V` (its positive part) for the
    /// gradient guidance.
    pub stiffness: SMatrix<f64, N, N>,
}

impl<const N: usize> Split<N> {
    /// A constant force with no linear part.
    pub fn explicit(force: SVector<f64, N>) -> Self {
        Self {
            explicit: force,
            damping: 0.0,
            damped: SMatrix::identity(),
            stiffness: SMatrix::zeros(),
        }
    }

    /// Damping `-B P v`.
    pub fn damping(b: f64, damped: SMatrix<f64, N, N>) -> Self {
        Self {
            damping: b,
            damped,
            ..Self::explicit(SVector::zeros())
        }
    }

    /// A spring `-K e` towards the target, `e` the offset from it.
    pub fn spring(k: f64, e: &SVector<f64, N>) -> Self {
        Self {
            stiffness: SMatrix::identity() * k,
            ..Self::explicit(-e * k)
        }
    }

    /// The force the split stands for at velocity `v` (the continuous law at the body).
    pub fn force(&self, v: &SVector<f64, N>) -> SVector<f64, N> {
        self.explicit - self.damped * v * self.damping
    }

    /// Adds another law's split. Only one damping law can be integrated exactly; a second
    /// (no controller has one) is added as the constant force it is at `v`.
    pub fn add(mut self, other: Self, v: &SVector<f64, N>) -> Self {
        self.explicit += other.explicit;
        self.stiffness += other.stiffness;
        if other.damping != 0.0 {
            if self.damping == 0.0 {
                (self.damping, self.damped) = (other.damping, other.damped);
            } else {
                self.explicit -= other.damped * v * other.damping;
            }
        }
        self
    }
}

/// The positive semi-definite part of a symmetric matrix: its negative eigenvalues set to zero.
/// Only a restoring stiffness is integrated implicitly; a negative one (a saddle of the field,
/// which pushes away) stays explicit, where it cannot make the step's system singular.
pub fn positive_part<const N: usize>(m: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    if !m.iter().all(|c| c.is_finite()) {
        return SMatrix::zeros();
    }
    // Cyclic Jacobi rotations: exact after one rotation for N = 2, a few sweeps beyond.
    let mut a = (m + m.transpose()) * 0.5;
    let mut vectors = SMatrix::<f64, N, N>::identity();
    for _ in 0..16 {
        for p in 0..N {
            for q in p + 1..N {
                if a[(p, q)] == 0.0 {
                    continue;
                }
                let theta = 0.5 * (2.0 * a[(p, q)]).atan2(a[(q, q)] - a[(p, p)]);
                let (sin, cos) = theta.sin_cos();
                let mut rotation = SMatrix::<f64, N, N>::identity();
                rotation[(p, p)] = cos;
                rotation[(q, q)] = cos;
                rotation[(p, q)] = sin;
                rotation[(q, p)] = -sin;
                a = rotation.transpose() * a * rotation;
                vectors *= rotation;
            }
        }
    }
    let clipped = SVector::<f64, N>::from_fn(|k, _| a[(k, k)].max(0.0));
    vectors * SMatrix::from_diagonal(&clipped) * vectors.transpose()
}

/// `φ(x) = (1 − e^{−x})/x`, the fraction of a constant force's impulse that survives damping
/// over a step of `x = B dt/m` time constants (1 at x = 0, `1/x` for large x).
pub fn phi(x: f64) -> f64 {
    if x < 1e-8 {
        1.0 - 0.5 * x
    } else {
        -(-x).exp_m1() / x
    }
}

/// The exact integration of a controller's linear parts for a body of one mass.
#[derive(Debug, Clone, PartialEq)]
pub struct Integrator<const N: usize> {
    /// The body's mass, kg (its moment of inertia about the joint, kg·m², for a joint).
    pub mass: f64,
    last: Option<(SVector<f64, N>, SVector<f64, N>)>,
    external: SVector<f64, N>,
}

impl<const N: usize> Integrator<N> {
    /// An integrator for a body of `mass` kg, with no estimate of the external force yet.
    pub fn new(mass: f64) -> Self {
        Self {
            mass,
            last: None,
            external: SVector::zeros(),
        }
    }

    /// The estimate `Ĝ` of the external force, N, from the last step that touched nothing.
    pub fn external(&self) -> SVector<f64, N> {
        self.external
    }

    /// The force to hand to the physics for one step so that the body's velocity at its end is
    /// the one the law integrated exactly gives (module docs), with the external force as last
    /// estimated by [`Integrator::observe`].
    ///
    /// ```
    /// use nadf::control::{ControlInput, Integrator, Split};
    /// use nalgebra::{Matrix1, Vector1};
    /// // B = 10⁴ kg/s on 1 kg with dt = 0.01 s: explicitly, v' = v − 100 v.
    /// let integrator = Integrator::new(1.0);
    /// let split = Split::damping(1e4, Matrix1::identity());
    /// let input = ControlInput {
    ///     offset: Vector1::new(1.0),
    ///     velocity: Vector1::new(2.0),
    ///     gradient: None,
    ///     curvature: None,
    ///     dt: 0.01,
    ///     touching: false,
    ///     reference_velocity: None,
    /// };
    /// let f = integrator.force(&split, &input);
    /// // The velocity decays by e^{-100} over the step: the force removes it, and no more.
    /// assert!((f.x - (-200.0)).abs() < 1e-9);
    /// ```
    pub fn force(&self, split: &Split<N>, input: &ControlInput<N>) -> SVector<f64, N> {
        let (v, dt, m) = (input.velocity, input.dt, self.mass);
        if split.damping == 0.0 && split.stiffness == SMatrix::<f64, N, N>::zeros() {
            return split.explicit;
        }
        let identity = SMatrix::<f64, N, N>::identity();
        let x = split.damping * dt / m;
        let p = split.damped;
        // Over the step the damped components decay by e^{−x} and keep φ(x) of a constant
        // force's impulse; the free ones decay not at all and keep all of it.
        let decay = p * (-x).exp() + (identity - p);
        let weight = p * phi(x) + (identity - p);
        let f = split.explicit + self.external;
        // The stiffness acts at the end of the step, x + dt v': solve
        // (I + (dt²/m) Φ S) v' = E v + (dt/m) Φ f.
        let system = identity + weight * split.stiffness * (dt * dt / m);
        let rhs = decay * v + weight * f * (dt / m);
        let Some(next) = system.try_inverse().map(|inverse| inverse * rhs) else {
            return split.force(&v);
        };
        (next - v) * (m / dt) - self.external
    }

    /// Updates the estimate of the external force from the step that ended at `input`: what
    /// changed the velocity beyond the force applied (kept as it was when the body touched
    /// something).
    pub fn observe(&mut self, input: &ControlInput<N>) {
        if let Some((v_prev, f_prev)) = self.last
            && !input.touching
        {
            let estimate = (input.velocity - v_prev) * (self.mass / input.dt) - f_prev;
            if estimate.iter().all(|c| c.is_finite()) {
                self.external = estimate;
            }
        }
    }

    /// Records the force actually applied in this step (after saturation and the speed limit),
    /// for the next step's estimate of the external force.
    pub fn applied(&mut self, input: &ControlInput<N>, force: &SVector<f64, N>) {
        self.last = Some((input.velocity, *force));
    }

    /// Corrects the force recorded for this step by [`Integrator::applied`] to `force`, N,
    /// when something other than the law decided what the body got (a force commanded from
    /// outside, the clearance envelope's): counted as the law's, the difference would be taken
    /// for an external force and fought in the next step.
    pub fn applied_instead(&mut self, force: &SVector<f64, N>) {
        if let Some((_, last)) = &mut self.last {
            *last = *force;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector1, Vector2};

    fn input(e: f64, v: f64, dt: f64) -> ControlInput<1> {
        ControlInput {
            offset: Vector1::new(e),
            velocity: Vector1::new(v),
            gradient: None,
            curvature: None,
            dt,
            touching: false,
            reference_velocity: None,
        }
    }

    /// Simulates `m v̇ = F + G` with Rapier's step (`v += dt a`, `x += dt v`) under the
    /// integrated law; returns the trajectory of (x, v).
    fn simulate(
        split: impl Fn(f64, f64) -> Split<1>,
        g: f64,
        dt: f64,
        steps: usize,
    ) -> Vec<(f64, f64)> {
        let m = 2.0;
        let mut integrator = Integrator::new(m);
        let (mut x, mut v) = (1.0, 3.0);
        let mut out = Vec::new();
        for _ in 0..steps {
            let i = input(x, v, dt);
            integrator.observe(&i);
            let f = integrator.force(&split(x, v), &i);
            integrator.applied(&i, &f);
            v += dt * (f.x + g) / m;
            x += dt * v;
            out.push((x, v));
        }
        out
    }

    #[test]
    fn only_the_restoring_part_of_a_curvature_is_kept() {
        // Eigenvalues 3 and −1 along (1, 1)/√2 and (1, −1)/√2.
        let m = Matrix2::new(1.0, 2.0, 2.0, 1.0);
        let p = positive_part(&m);
        assert!((p - Matrix2::new(1.5, 1.5, 1.5, 1.5)).norm() < 1e-12, "{p}");
        assert_eq!(
            positive_part(&Matrix2::new(f64::NAN, 0.0, 0.0, 1.0)),
            Matrix2::zeros()
        );
    }

    #[test]
    fn phi_is_one_at_zero_and_one_over_x_far_out() {
        assert_eq!(phi(0.0), 1.0);
        assert!((phi(1e-3) - (1.0 - (-1e-3f64).exp()) / 1e-3).abs() < 1e-12);
        assert!((phi(1e4) - 1e-4).abs() < 1e-18);
    }

    #[test]
    fn damped_velocity_decays_exactly_and_reaches_the_terminal_velocity_for_any_gain() {
        // m v̇ = −B v + F: v(t) = F/B + (v0 − F/B) e^{−B t/m}, sampled at the steps.
        for b in [0.5, 10.0, 1e3, 1e6] {
            let dt = 0.01;
            let path = simulate(
                |_, _| Split {
                    explicit: Vector1::new(4.0),
                    ..Split::damping(b, nalgebra::Matrix1::identity())
                },
                0.0,
                dt,
                300,
            );
            for (n, (_, v)) in path.iter().enumerate() {
                let t = (n + 1) as f64 * dt;
                let exact = 4.0 / b + (3.0 - 4.0 / b) * (-b * t / 2.0).exp();
                assert!(
                    (v - exact).abs() < 1e-9 * (1.0 + exact.abs()),
                    "B {b}: {v} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn a_stiff_spring_with_damping_never_grows_and_comes_to_rest() {
        // Explicitly, K dt²/m > 4 diverges; implicitly the energy never grows.
        for (k, b) in [(1e4, 0.0), (1e6, 0.0), (1e6, 1e5), (50.0, 100.0)] {
            let path = simulate(
                |x, _| {
                    Split::damping(b, nalgebra::Matrix1::identity())
                        .add(Split::spring(k, &Vector1::new(x)), &Vector1::zeros())
                },
                0.0,
                0.01,
                2000,
            );
            let energy = |(x, v): (f64, f64)| 0.5 * k * x * x + v * v;
            let mut last = energy((1.0, 3.0));
            for &s in &path {
                assert!(
                    energy(s) <= last * (1.0 + 1e-12),
                    "K {k} B {b}: energy grew"
                );
                last = energy(s);
            }
            let (x, v) = *path.last().unwrap();
            assert!(x.abs() < 1e-3 && v.abs() < 1e-3, "K {k} B {b}: {x} {v}");
        }
    }

    #[test]
    fn the_rest_point_under_an_unknown_constant_force_is_the_continuous_laws() {
        // Rest of −K e + G = 0 (eq. 47): e = G/K, whatever B and K.
        for (k, b) in [(10.0, 10.0), (1e4, 10.0), (1e4, 1e4)] {
            let g = 5.657;
            let path = simulate(
                |x, _| {
                    Split::damping(b, nalgebra::Matrix1::identity())
                        .add(Split::spring(k, &Vector1::new(x)), &Vector1::zeros())
                },
                g,
                0.01,
                20_000,
            );
            let (x, v) = *path.last().unwrap();
            assert!(
                (x - g / k).abs() < 1e-9 * (1.0 + g / k) && v.abs() < 1e-9,
                "K {k} B {b}: {x}"
            );
        }
    }

    #[test]
    fn undamped_directions_get_the_explicit_force() {
        // NADF moving downhill along u = x: P damps y only.
        let p = Matrix2::new(0.0, 0.0, 0.0, 1.0);
        let integrator = Integrator::new(1.0);
        let input = ControlInput {
            offset: Vector2::new(3.0, 0.0),
            velocity: Vector2::new(-2.0, 0.5),
            gradient: None,
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: None,
        };
        let split = Split {
            explicit: Vector2::new(-1.0, 0.0),
            ..Split::damping(1e5, p)
        };
        let f = integrator.force(&split, &input);
        assert!((f.x - (-1.0)).abs() < 1e-12, "{f}");
        // The sideways 0.5 m/s is removed in the step, and no more.
        assert!((f.y - (-50.0)).abs() < 1e-9, "{f}");
    }

    #[test]
    fn contacts_are_not_taken_for_an_external_force() {
        let mut integrator = Integrator::<1>::new(1.0);
        let first = input(0.0, 0.0, 0.01);
        integrator.applied(&first, &Vector1::new(0.0));
        // A wall stopped the body: 0 → −3 m/s in one step with no control.
        let mut hit = input(0.0, -3.0, 0.01);
        hit.touching = true;
        integrator.observe(&hit);
        assert_eq!(integrator.external(), Vector1::zeros());
        integrator.applied(&hit, &Vector1::new(1.0));
        // A free step at −3 + 0.01·(1 + 2) m/s: the external force is 2 N.
        integrator.observe(&input(0.0, -2.97, 0.01));
        assert!((integrator.external().x - 2.0).abs() < 1e-9);
    }

    #[test]
    fn a_force_applied_instead_of_the_laws_is_not_taken_for_an_external_force() {
        let mut integrator = Integrator::<1>::new(2.0);
        let first = input(0.0, 0.0, 0.01);
        // The law asked for 5 N; a policy's 1 N went to the body, with no external force.
        integrator.applied(&first, &Vector1::new(5.0));
        integrator.applied_instead(&Vector1::new(1.0));
        integrator.observe(&input(0.0, 0.005, 0.01));
        assert!(
            integrator.external().x.abs() < 1e-12,
            "{}",
            integrator.external()
        );
    }
}
