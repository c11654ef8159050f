//! The control laws: how the guidance field becomes the force on a body.
//!
//! Every law is stated in R^N as in the paper (N = 2 for a planar body, N = 1 for a pendulum
//! joint) on nalgebra vectors; the one conversion to Rapier's `glam` types is in `sim`.
//!
//! Each law is one [`ControlLaw`]: the guidance force ([`Guidance`]), a damping law
//! ([`Viscous`], eq. 1, or [`Nadf`], eq. 9–10), the sliding-mode baseline ([`SlidingMode`],
//! eq. 72–73), the clamping control ([`Clamp`], eq. 35) and, for the pendulum, a plain spring
//! ([`Spring`], eq. 75). A [`Controller`] sums its laws
//! (eq. 36: `F = -B_d M - K ∇V - K_c F_c`), adds the iterative bias ([`Bias`], eq. 48–50) and
//! applies the speed limit ([`SpeedLimit`], §VI.2) last; the clearance envelope
//! ([`Envelope`]) then keeps a disc's force within what it can stop from in the room ahead. The linear parts of the laws (the
//! damping and the clamp's or spring's stiffness) are integrated exactly over each step
//! ([`Integrator`]), so that no gain is unstable.

mod bias;
mod clamp;
mod envelope;
mod guidance;
mod integrator;
mod nadf;
mod orca;
mod sliding_mode;
mod speed_limit;
mod spring;
mod viscous;

pub use bias::{Bias, CONVERGED};
pub use clamp::Clamp;
pub use envelope::{Envelope, Enveloped, MARGIN as ENVELOPE_MARGIN, Step, Sweep};
pub use guidance::{Guidance, GuidanceMode};
pub use integrator::{Integrator, Split, phi, positive_part};
pub use nadf::{Nadf, step};
pub use orca::{Neighbour, Orca, VelocityTracking};
pub use sliding_mode::SlidingMode;
pub use speed_limit::SpeedLimit;
pub use spring::Spring;
pub use viscous::Viscous;

use nalgebra::{SMatrix, SVector};

use crate::world::{ControllerKind, ControllerSettings, GuidanceKind, Integration};

/// Below this `|∇V|` the direction of the gradient is undefined (a saddle, an unreachable cell,
/// a flat region): guidance is zero and NADF falls back to viscous damping (design page).
///
/// The threshold is far below any gradient the solver produces in a reachable cell (those go
/// down to about 1e-20 /m behind many turns), so it only catches true zeros and underflow.
pub const MIN_GRADIENT: f64 = 1e-280;

/// The unit vector `g/|g|`, or `None` when `|g|` is below [`MIN_GRADIENT`] or not finite.
/// Scaled first, so tiny gradients do not underflow when squared.
pub fn unit<const N: usize>(g: &SVector<f64, N>) -> Option<SVector<f64, N>> {
    let scale = g.amax();
    if !(g.iter().all(|c| c.is_finite()) && scale > MIN_GRADIENT) {
        return None;
    }
    let scaled = g / scale;
    Some(scaled / scaled.norm())
}

/// What a control law sees at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlInput<const N: usize> {
    /// `x - x_T`: the body's position relative to its target, m.
    pub offset: SVector<f64, N>,
    /// The body's velocity `v`, m/s.
    pub velocity: SVector<f64, N>,
    /// The gradient `g = ∇V` of the guidance potential at the body, 1/m; `None` where the field
    /// is undefined (then guidance is zero and NADF damps like viscous damping).
    pub gradient: Option<SVector<f64, N>>,
    /// The curvature `∇∇V` of the guidance potential at the body, 1/m² (symmetric), where the
    /// field gives one: the guidance's stiffness, integrated implicitly ([`Integrator`]).
    pub curvature: Option<SMatrix<f64, N, N>>,
    /// The control period, s.
    pub dt: f64,
    /// Whether the body touched something during the last step (then its change of velocity
    /// says nothing about the external force; see [`Integrator`]).
    pub touching: bool,
    /// The velocity to track, m/s, for a law that tracks one ([`VelocityTracking`], ORCA's);
    /// `None` for the others.
    pub reference_velocity: Option<SVector<f64, N>>,
}

/// One term of a control law: a force from the body's state and the guidance.
pub trait ControlLaw<const N: usize>: Send + Sync {
    /// The force, N. Never returns a non-finite vector for finite inputs.
    fn force(&self, input: &ControlInput<N>) -> SVector<f64, N>;

    /// The same force split into a constant part, a damping and a stiffness, for the exact
    /// integration of [`Integrator`]; `split(i).force(v, e)` equals `force(i)`. The default is
    /// all constant.
    fn split(&self, input: &ControlInput<N>) -> Split<N> {
        Split::explicit(self.force(input))
    }
}

/// What a controller did in one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlOutput<const N: usize> {
    /// The control force to apply, N (finite: zero replaces a non-finite sum).
    pub force: SVector<f64, N>,
    /// Whether the clamping control acted.
    pub clamping: bool,
    /// Whether the speed limit removed part of the force.
    pub speed_limited: bool,
    /// Whether the bias β was updated at the end of this step (a settling instant).
    pub bias_updated: bool,
}

/// The whole controller of one body.
pub struct Controller<const N: usize> {
    /// The terms summed into the control force: guidance and a damping law, or sliding mode.
    pub laws: Vec<Box<dyn ControlLaw<N>>>,
    /// The clamping control, if any.
    pub clamp: Option<Clamp>,
    /// The iterative bias, if any.
    pub bias: Option<Bias<N>>,
    /// The speed limit, if any.
    pub speed_limit: Option<SpeedLimit>,
    /// Actuator saturation `F_max`, N (typical: a few times the guidance gain), if any.
    pub max_force: Option<f64>,
    /// The exact integration of the damping and stiffness over a step; `None` hands the
    /// physics the continuous law's force at the start of the step (explicit, unstable for
    /// `B dt/m > 2`).
    pub integrator: Option<Integrator<N>>,
}

impl<const N: usize> Controller<N> {
    /// A controller that only sums `laws`, integrated exactly for a body of `mass` kg (the
    /// moment of inertia, kg·m², for a joint).
    pub fn new(laws: Vec<Box<dyn ControlLaw<N>>>, mass: f64) -> Self {
        Self {
            laws,
            clamp: None,
            bias: None,
            speed_limit: None,
            max_force: None,
            integrator: Some(Integrator::new(mass)),
        }
    }

    /// The control force for one step, and what acted. Updates the bias's settling detector.
    pub fn step(&mut self, input: &ControlInput<N>) -> ControlOutput<N> {
        if let Some(integrator) = &mut self.integrator {
            integrator.observe(input);
        }
        let (force, clamping, speed_limited) = self.law(input, self.integrator.as_ref());
        if let Some(integrator) = &mut self.integrator {
            integrator.applied(input, &force);
        }
        let bias_updated = self
            .bias
            .as_mut()
            .is_some_and(|bias| bias.observe(input, &force));
        ControlOutput {
            force,
            clamping,
            speed_limited,
            bias_updated,
        }
    }

    /// The body got `force`, N, in the step [`Controller::step`] just computed, instead of the
    /// law's (see [`Integrator::applied_instead`]).
    pub fn applied_instead(&mut self, force: &SVector<f64, N>) {
        if let Some(integrator) = &mut self.integrator {
            integrator.applied_instead(force);
        }
    }

    /// The force [`Controller::step`] would return for `input`, without changing anything:
    /// the integrator's estimate of the external force and the bias's settling detector stay
    /// as they are (`bias_updated` is `false`). What a policy learning against the law asks
    /// for as the expert's action in the current state.
    ///
    /// ```
    /// use nadf::control::{ControlInput, Controller, Nadf};
    /// use nalgebra::Vector2;
    ///
    /// let mut controller = Controller::<2>::new(vec![Box::new(Nadf { b_d: 10.0 })], 1.0);
    /// let input = ControlInput {
    ///     offset: Vector2::new(1.0, 0.0),
    ///     velocity: Vector2::new(0.5, 0.0),
    ///     gradient: Some(Vector2::new(1.0, 0.0)),
    ///     curvature: None,
    ///     dt: 0.01,
    ///     touching: false,
    ///     reference_velocity: None,
    /// };
    /// let preview = controller.evaluate(&input);
    /// assert_eq!(preview.force, controller.evaluate(&input).force); // nothing moved on
    /// assert_eq!(preview.force, controller.step(&input).force);
    /// ```
    pub fn evaluate(&self, input: &ControlInput<N>) -> ControlOutput<N> {
        let integrator = self.integrator.clone().map(|mut integrator| {
            integrator.observe(input);
            integrator
        });
        let (force, clamping, speed_limited) = self.law(input, integrator.as_ref());
        ControlOutput {
            force,
            clamping,
            speed_limited,
            bias_updated: false,
        }
    }

    /// The force of the laws, the bias and the clamp for `input`, integrated over the step by
    /// `integrator` (its external force observed for this step), saturated and speed-limited;
    /// with whether the clamp acted and whether the speed limit did.
    fn law(
        &self,
        input: &ControlInput<N>,
        integrator: Option<&Integrator<N>>,
    ) -> (SVector<f64, N>, bool, bool) {
        let v = &input.velocity;
        let mut split = self
            .laws
            .iter()
            .fold(Split::explicit(SVector::zeros()), |sum, law| {
                sum.add(law.split(input), v)
            });
        if let Some(bias) = &self.bias {
            split.explicit += bias.beta();
        }
        let mut clamping = false;
        if let Some(clamp) = &self.clamp {
            // The clamp's rest band: what the other forces do to the velocity in one step.
            let rest_speed = integrator.map_or(0.0, |i| {
                Clamp::rest_speed((split.explicit + i.external()).norm(), input.dt, i.mass)
            });
            clamping = clamp.active(input, rest_speed);
            if clamping {
                split = split.add(Split::spring(clamp.kc, &input.offset), v);
            }
        }
        let mut total = match integrator {
            Some(integrator) => integrator.force(&split, input),
            None => split.force(v),
        };
        if let Some(max) = self.max_force {
            // Saturation keeps the direction: scaled down, damping is still dissipative.
            let norm = total.norm();
            if norm > max {
                total *= max / norm;
            }
        }
        let mut speed_limited = false;
        if let Some(limit) = &self.speed_limit {
            let distance = input.offset.norm();
            (total, speed_limited) = limit.limit(total, &input.velocity, distance, input.dt);
        }
        let force = if total.iter().all(|c| c.is_finite()) {
            total
        } else {
            SVector::zeros()
        };
        (force, clamping, speed_limited)
    }

    /// The current bias β, N, if the controller has one.
    pub fn beta(&self) -> Option<SVector<f64, N>> {
        self.bias.as_ref().map(Bias::beta)
    }
}

impl<const N: usize> Controller<N> {
    /// The controller a world file's `[agents.controller]` table describes (validated: the
    /// parameters its kind needs are present) for a body of `mass` kg.
    pub fn from_settings(settings: &ControllerSettings, guidance: GuidanceKind, mass: f64) -> Self {
        let guidance = Guidance {
            k: settings.k(),
            mode: match guidance {
                GuidanceKind::Normalized => GuidanceMode::Normalized {
                    capture_radius: settings.capture_radius,
                },
                GuidanceKind::Gradient => GuidanceMode::Gradient,
            },
        };
        let b = settings.b.unwrap_or(0.0);
        let laws: Vec<Box<dyn ControlLaw<N>>> = match settings.kind {
            ControllerKind::Nadf => vec![Box::new(guidance), Box::new(Nadf { b_d: b })],
            ControllerKind::Viscous => vec![Box::new(guidance), Box::new(Viscous { b })],
            ControllerKind::SlidingMode => vec![Box::new(SlidingMode {
                vd: settings.vd.unwrap_or(0.0),
                f0: settings.f0.unwrap_or(0.0),
                capture_radius: settings.capture_radius,
            })],
            ControllerKind::Orca => vec![Box::new(VelocityTracking {
                b: mass / settings.orca.unwrap_or_default().tracking_time,
            })],
            // The unicycle law commands the wheels' speeds itself (`sim::drive`): no force.
            ControllerKind::Unicycle => Vec::new(),
        };
        Self {
            laws,
            clamp: settings.clamp.map(|c| Clamp {
                kc: c.kc,
                sigma: c.sigma,
            }),
            bias: settings.bias.map(|b| Bias::new(b.alpha, b.dwell, mass)),
            speed_limit: (settings.speed_limit.is_some() || settings.brake.is_some()).then(|| {
                SpeedLimit {
                    v_max: settings.speed_limit.unwrap_or(f64::INFINITY),
                    brake: settings.brake,
                    mass,
                }
            }),
            max_force: settings.max_force,
            integrator: (settings.integration == Integration::Exact).then(|| Integrator::new(mass)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{BiasSettings, ClampSettings};
    use nalgebra::Vector2;

    fn settings(kind: ControllerKind) -> ControllerSettings {
        ControllerSettings {
            kind,
            k: Some(1.0),
            b: Some(10.0),
            capture_radius: 0.25,
            vd: None,
            f0: None,
            speed_limit: None,
            brake: None,
            max_force: None,
            clamp: None,
            bias: None,
            integration: Integration::Exact,
            orca: None,
            turn_gain: None,
            envelope: true,
            envelope_damping: None,
        }
    }

    fn input(offset: [f64; 2], velocity: [f64; 2], gradient: Option<[f64; 2]>) -> ControlInput<2> {
        ControlInput {
            offset: Vector2::from(offset),
            velocity: Vector2::from(velocity),
            gradient: gradient.map(Vector2::from),
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: None,
        }
    }

    #[test]
    fn unit_survives_tiny_gradients_and_rejects_zero_and_nan() {
        let u = unit(&Vector2::new(3e-200, -4e-200)).unwrap();
        assert!((u - Vector2::new(0.6, -0.8)).norm() < 1e-15);
        assert!(unit(&Vector2::new(0.0, 0.0)).is_none());
        assert!(unit(&Vector2::new(f64::NAN, 1.0)).is_none());
        assert!(unit(&Vector2::new(f64::INFINITY, 1.0)).is_none());
    }

    #[test]
    fn controller_never_returns_non_finite_forces() {
        let mut c =
            Controller::from_settings(&settings(ControllerKind::Nadf), GuidanceKind::Gradient, 1.0);
        let out = c.step(&input([1.0, 0.0], [1.0, 0.0], Some([f64::MAX, f64::MAX])));
        assert!(out.force.iter().all(|x| x.is_finite()));
        let out = c.step(&input([1.0, 0.0], [f64::NAN, 0.0], None));
        assert_eq!(out.force, Vector2::zeros());
    }

    #[test]
    fn nadf_controller_is_guidance_plus_damping_plus_clamp_plus_bias() {
        let mut s = settings(ControllerKind::Nadf);
        s.clamp = Some(ClampSettings {
            kc: 10.0,
            sigma: 0.5,
        });
        s.bias = Some(BiasSettings {
            alpha: 0.05,
            dwell: 0.5,
        });
        let mut c = Controller::from_settings(&s, GuidanceKind::Normalized, 1.0);
        // The laws' sum as the paper states it (the exact integration is tested below).
        c.integrator = None;
        // Inside σ, moving away along +x, gradient +x (uphill): guidance -K·0.2/0.25, NADF
        // -B_d·v, clamp -K_c·e.
        let out = c.step(&input([0.2, 0.0], [0.1, 0.0], Some([1.0, 0.0])));
        let expected = -0.8 - 1.0 - 2.0;
        assert!(
            (out.force - Vector2::new(expected, 0.0)).norm() < 1e-12,
            "{}",
            out.force
        );
        assert!(out.clamping && !out.speed_limited && !out.bias_updated);
        assert_eq!(c.beta(), Some(Vector2::zeros()));
    }

    #[test]
    fn sliding_mode_controller_has_no_separate_guidance() {
        let mut s = settings(ControllerKind::SlidingMode);
        (s.k, s.b, s.vd, s.f0) = (None, None, Some(2.0), Some(50.0));
        let mut c = Controller::from_settings(&s, GuidanceKind::Normalized, 1.0);
        let out = c.step(&input([5.0, 0.0], [0.0, 0.0], Some([1.0, 0.0])));
        assert_eq!(out.force, Vector2::new(-50.0, 0.0));
    }

    #[test]
    fn saturation_scales_the_force_down_keeping_its_direction() {
        let mut s = settings(ControllerKind::Viscous);
        s.max_force = Some(2.0);
        let mut c = Controller::from_settings(&s, GuidanceKind::Gradient, 1.0);
        c.integrator = None;
        // Guidance -K·g = (-3, 0), damping -B·v = (0, -40): 40.1 N, scaled to 2 N.
        let out = c.step(&input([5.0, 0.0], [0.0, 4.0], Some([3.0, 0.0])));
        let expected = Vector2::new(-3.0, -40.0) * (2.0 / 1609.0f64.sqrt());
        assert!((out.force - expected).norm() < 1e-12, "{}", out.force);
    }

    #[test]
    fn the_speed_limit_applies_to_the_whole_force() {
        let mut s = settings(ControllerKind::Nadf);
        s.speed_limit = Some(5.0);
        let mut c = Controller::from_settings(&s, GuidanceKind::Normalized, 1.0);
        // Moving down the guidance at the limit: the guidance's push is dropped.
        let out = c.step(&input([5.0, 0.0], [-5.0, 0.0], Some([1.0, 0.0])));
        assert!(out.speed_limited);
        assert!(out.force.norm() < 1e-12, "{}", out.force);
    }
}
