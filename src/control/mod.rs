//! The control laws: how the guidance field and a damping law become the force on a body.
//!
//! Every law is stated in R^N as in the paper (N = 2 for a planar body, N = 1 for a pendulum
//! joint) on nalgebra vectors; the one conversion to Rapier's `glam` types is in `sim`.
//!
//! A controller is a guidance force ([`Guidance`], from `g = ∇V`) plus a damping force from a
//! [`Damping`] law ([`Viscous`], eq. 1, or [`Nadf`], eq. 9–10). The total is what the simulation
//! applies: `F = F_g + F_d` (eq. 1 and eq. 34 with the signs of the design page).

mod guidance;
mod nadf;
mod viscous;

pub use guidance::{Guidance, GuidanceMode};
pub use nadf::Nadf;
pub use viscous::Viscous;

use nalgebra::SVector;

use crate::world::{ControllerKind, ControllerSettings, GuidanceKind};

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

/// A damping law: the force that manages the body's inertia, given its velocity and the
/// gradient of the guidance potential at its position.
pub trait Damping<const N: usize>: Send + Sync {
    /// The damping force `F_d`, N, for velocity `v` (m/s) where the gradient is `g = ∇V`.
    /// Never returns a non-finite vector for finite inputs.
    fn force(&self, v: &SVector<f64, N>, g: &SVector<f64, N>) -> SVector<f64, N>;
}

/// Guidance plus damping for one body.
pub struct Controller<const N: usize> {
    /// The guidance force law.
    pub guidance: Guidance,
    /// The damping law.
    pub damping: Box<dyn Damping<N>>,
}

impl<const N: usize> Controller<N> {
    /// The total control force, N, at distance `distance` (m) from the target with velocity `v`
    /// and gradient `g` (`None` where the field is undefined: then only damping acts, with
    /// NADF's viscous fallback).
    pub fn force(
        &self,
        distance: f64,
        v: &SVector<f64, N>,
        g: Option<&SVector<f64, N>>,
    ) -> SVector<f64, N> {
        let zero = SVector::<f64, N>::zeros();
        let g = g.copied().unwrap_or(zero);
        let total = self.guidance.force(distance, &g) + self.damping.force(v, &g);
        if total.iter().all(|c| c.is_finite()) {
            total
        } else {
            zero
        }
    }
}

impl Controller<2> {
    /// The controller a world file's `[agents.controller]` table describes.
    pub fn from_settings(settings: &ControllerSettings, guidance: GuidanceKind) -> Self {
        let mode = match guidance {
            GuidanceKind::Normalized => GuidanceMode::Normalized {
                capture_radius: settings.capture_radius,
            },
            GuidanceKind::Gradient => GuidanceMode::Gradient,
        };
        let damping: Box<dyn Damping<2>> = match settings.kind {
            ControllerKind::Nadf => Box::new(Nadf { b_d: settings.b }),
            ControllerKind::Viscous => Box::new(Viscous { b: settings.b }),
        };
        Self {
            guidance: Guidance {
                k: settings.k,
                mode,
            },
            damping,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

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
        let c = Controller::from_settings(
            &ControllerSettings {
                kind: ControllerKind::Nadf,
                k: 1.0,
                b: 10.0,
                capture_radius: 0.25,
            },
            GuidanceKind::Gradient,
        );
        let f = c.force(
            1.0,
            &Vector2::new(1.0, 0.0),
            Some(&Vector2::new(f64::MAX, f64::MAX)),
        );
        assert!(f.iter().all(|x| x.is_finite()));
        let f = c.force(1.0, &Vector2::new(f64::NAN, 0.0), None);
        assert_eq!(f, Vector2::zeros());
    }
}
