//! A body in Rapier as the control laws see it ([`Body`]), and the one control step every kind
//! of body takes ([`control`]).
//!
//! A kind of body is two things: its configuration space with its guidance field
//! ([`ConfigurationSpace`], in `field`) and its body in Rapier (here), both in the coordinates
//! whose metric makes its inertia `m·I` (see `field/space.rs`). The body reads its configuration
//! and velocity from Rapier in those coordinates and turns a force in them into Rapier's forces
//! and torques (the one conversion between the laws' nalgebra vectors and Rapier's `glam` ones
//! is in `physics.rs`; both are f64). [`control`] joins a space and a controller: the guidance
//! at the body's configuration, the control force, checked for Rapier.
//!
//! - [`DiscBody`]: a disc that does not turn, in the plane (`agent.rs`).
//! - [`TurningBody`]: a rigid shape that turns, in `(x, y, ρθ)` (`shaped.rs`).

use nalgebra::{SVector, Vector2, Vector3};
use rapier2d::prelude::{PhysicsWorld, RigidBodyHandle};

use super::physics::{from_rapier, to_rapier};
use crate::control::{ControlInput, ControlOutput};
use crate::field::{ConfigurationSpace, Pose, angle_difference};

/// A body in Rapier whose configuration lives in an `N`-dimensional configuration space.
pub trait Body<const N: usize> {
    /// Its configuration (a position, a pose).
    type Config: Copy;

    /// Its configuration and its velocity in the metric coordinates, from Rapier; `None` when
    /// Rapier's state is not finite.
    fn state(&self, physics: &PhysicsWorld) -> Option<(Self::Config, SVector<f64, N>)>;

    /// Resets the body's forces (Rapier's user forces persist across steps) and applies the
    /// generalized force `force` (N, in the metric coordinates) for the next step.
    fn actuate(&self, physics: &mut PhysicsWorld, force: &SVector<f64, N>);
}

/// A disc that does not turn: its configuration is its centre, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiscBody {
    /// Its Rapier body.
    pub handle: RigidBodyHandle,
}

impl Body<2> for DiscBody {
    type Config = [f64; 2];

    fn state(&self, physics: &PhysicsWorld) -> Option<([f64; 2], Vector2<f64>)> {
        let body = &physics.bodies[self.handle];
        let (x, v) = (from_rapier(body.translation()), from_rapier(body.linvel()));
        x.iter()
            .chain(v.iter())
            .all(|c| c.is_finite())
            .then_some((x.into(), v))
    }

    fn actuate(&self, physics: &mut PhysicsWorld, force: &Vector2<f64>) {
        let body = &mut physics.bodies[self.handle];
        body.reset_forces(false);
        body.add_force(to_rapier(*force), true);
    }
}

/// A rigid shape that turns: its configuration is its centroid and heading, its velocity
/// `(v, ρω)` in the metric `(x, y, ρθ)`, and the third component of a force is applied as the
/// torque `ρ F₃` (N·m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurningBody {
    /// Its Rapier body.
    pub handle: RigidBodyHandle,
    /// The metric's length for θ, m (√(I/m)).
    pub rho: f64,
    /// The heading last read, rad, continuous since the start (Rapier's angle wraps at ±π).
    pub heading: f64,
}

impl TurningBody {
    /// The torque `ρ F₃` of a force in the metric coordinates, N·m.
    pub fn torque(&self, force: &Vector3<f64>) -> f64 {
        self.rho * force.z
    }
}

impl Body<3> for TurningBody {
    type Config = Pose;

    fn state(&self, physics: &PhysicsWorld) -> Option<(Pose, Vector3<f64>)> {
        let body = &physics.bodies[self.handle];
        let (p, v) = (from_rapier(body.translation()), from_rapier(body.linvel()));
        let (angle, omega) = (body.rotation().angle(), body.angvel());
        let heading = self.heading + angle_difference(angle, self.heading);
        let all = [p.x, p.y, v.x, v.y, angle, omega];
        all.iter().all(|c| c.is_finite()).then(|| {
            (
                [p.x, p.y, heading],
                Vector3::new(v.x, v.y, self.rho * omega),
            )
        })
    }

    fn actuate(&self, physics: &mut PhysicsWorld, force: &Vector3<f64>) {
        let body = &mut physics.bodies[self.handle];
        body.reset_forces(false);
        body.reset_torques(false);
        body.add_force(to_rapier(Vector2::new(force.x, force.y)), true);
        body.add_torque(self.torque(force), true);
    }
}

/// What [`control`] needs besides the space and the configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensed<const N: usize> {
    /// The velocity in the metric coordinates.
    pub velocity: SVector<f64, N>,
    /// The control period, s.
    pub dt: f64,
    /// Whether the body touched something during the last step.
    pub touching: bool,
    /// Whether the guidance's curvature is sampled for the integrator (the gradient law only:
    /// it costs more samples of the field).
    pub curvature: bool,
}

/// One control step of a body at configuration `q` (as its controller sees it) in `space`:
/// the guidance there, then the force `law` gives for it (a controller's
/// [`Controller::step`](crate::control::Controller::step), or its side-effect-free
/// [`Controller::evaluate`](crate::control::Controller::evaluate)). `reference` gives
/// the velocity a tracking law follows (ORCA's) from the offset and the gradient, if any. The
/// force is zero, and the second value `true`, when it is not finite in f32 (the recording's
/// precision; Rapier's is f64).
pub fn control<const N: usize, S: ConfigurationSpace<N>>(
    space: &S,
    law: impl FnOnce(&ControlInput<N>) -> ControlOutput<N>,
    q: S::Config,
    sensed: Sensed<N>,
    reference: impl FnOnce(&SVector<f64, N>, Option<SVector<f64, N>>) -> Option<SVector<f64, N>>,
) -> (ControlOutput<N>, bool) {
    let offset = space.offset(q);
    let gradient = space.gradient(q);
    let reference_velocity = reference(&offset, gradient);
    let input = ControlInput {
        offset,
        velocity: sensed.velocity,
        gradient,
        curvature: sensed.curvature.then(|| space.curvature(q)).flatten(),
        dt: sensed.dt,
        touching: sensed.touching,
        reference_velocity,
    };
    let mut out = law(&input);
    // Rapier is f64, but the recording (Rerun's arrows) is f32: a force beyond f32's range
    // (3.4e38 N, far beyond any law that has not run away) would be infinite there.
    let rejected = !out.force.iter().all(|c| (*c as f32).is_finite());
    if rejected {
        out.force = SVector::zeros();
    }
    (out, rejected)
}
