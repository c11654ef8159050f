//! A body's configuration space as the control laws see it ([`ConfigurationSpace`]): a guidance
//! field over configurations, in coordinates whose metric makes the body's inertia `m·I`.
//!
//! The laws of `control` are stated in R^N for a body of one mass `m` (eq. 9–11, 36). Every
//! kind of body is brought to that form by its configuration space's coordinates:
//!
//! - a disc: its position `(x, y)` in the plane ([`super::GuidanceField`]);
//! - a shape that turns: `(x, y, ρθ)` with ρ its radius of gyration, so that
//!   `D = diag(m, m, I) = m·I₃` ([`super::PoseField`]);
//! - (to come: an arm's joint angles, scaled by its inertia; a wheeled robot's point ahead of
//!   its axle).
//!
//! A space gives, at a configuration, the offset from the target, the gradient and curvature of
//! the potential and the potential itself, all in those coordinates; the body (`sim::Body`)
//! reads its configuration and velocity from Rapier and turns a force in those coordinates
//! into Rapier's forces and torques. `sim::control` joins the two through a `Controller`.

use nalgebra::{SMatrix, SVector};

/// A configuration space with the guidance field of one body (see the module).
pub trait ConfigurationSpace<const N: usize> {
    /// A configuration as the body reports it (a position, a pose).
    type Config: Copy;

    /// `q − q_T` in the metric coordinates, m: the controllers' offset from the target (the
    /// parts the target leaves free are 0, e.g. the heading without a target heading).
    fn offset(&self, q: Self::Config) -> SVector<f64, N>;

    /// The gradient `∇V` at `q` in the metric coordinates, 1/m; `None` where the field is
    /// undefined.
    fn gradient(&self, q: Self::Config) -> Option<SVector<f64, N>>;

    /// The potential `V` at `q`.
    fn potential(&self, q: Self::Config) -> f64;

    /// `q` moved by `by` metres along metric axis `axis`.
    fn moved(&self, q: Self::Config, axis: usize, by: f64) -> Self::Config;

    /// The step of the curvature's central differences, m.
    fn curvature_step(&self) -> f64;

    /// The curvature `∇∇V` at `q`, 1/m², by central differences of the gradient
    /// [`Self::curvature_step`] either side along each axis, symmetrized; `None` where a
    /// gradient is undefined. The integrator treats its positive part as the guidance's
    /// stiffness.
    fn curvature(&self, q: Self::Config) -> Option<SMatrix<f64, N, N>> {
        let h = self.curvature_step();
        let mut m = SMatrix::<f64, N, N>::zeros();
        for axis in 0..N {
            let up = self.gradient(self.moved(q, axis, h))?;
            let down = self.gradient(self.moved(q, axis, -h))?;
            m.set_column(axis, &((up - down) / (2.0 * h)));
        }
        let m = (m + m.transpose()) * 0.5;
        m.iter().all(|c| c.is_finite()).then_some(m)
    }
}
