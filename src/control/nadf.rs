//! The nonlinear anisotropic damping force (NADF), eq. 9–10:
//!
//! `M(x, v) = (nᵀv) n + (uᵀv) Φ(uᵀv) u`,  `F_d = -B_d · M`,  with `u = g/|g|`, `g = ∇V`.
//!
//! The sideways part of the motion is always damped; the part along `u` is damped only when
//! it climbs the potential (`gᵀv ≥ 0`, i.e. it fights the guidance). Motion down the guidance
//! is left alone, so B_d can be large without slowing the body (paper §III, Proposition 2).
//! Eq. 10 prints `Φ(-g·v)`; eq. 9, 17, 19 and the text fix `Φ(gᵀv)` (design page).

use nalgebra::{SMatrix, SVector};

use super::{ControlInput, ControlLaw, Split, unit};

/// NADF damping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nadf {
    /// Damping coefficient B_d, N·s/m (kg/s). Larger is better: settling time and the deviation
    /// `δ_m` from the kinematic path both fall as B_d grows (paper figure 24); typical 3–30 for
    /// a 1 kg body.
    pub b_d: f64,
}

/// The unit step of the design page: `Φ(s) = 1` for `s ≥ 0`, else 0.
pub fn step(s: f64) -> f64 {
    if s >= 0.0 { 1.0 } else { 0.0 }
}

impl Nadf {
    /// The damped part of the motion, `M(x, v)` of eq. 9. Where the gradient vanishes the split
    /// is undefined and `M = v` (plain viscous damping, still dissipative).
    pub fn damped_motion<const N: usize>(
        v: &SVector<f64, N>,
        g: &SVector<f64, N>,
    ) -> SVector<f64, N> {
        let Some(u) = unit(g) else { return *v };
        let along = u.dot(v);
        // (nᵀv) n is what is left of v once its component along u is removed (N dimensions).
        let sideways = v - u * along;
        sideways + u * (along * step(along))
    }
}

impl Nadf {
    /// The projector `P` with `M(x, v) = P v` for this step: the identity minus `u uᵀ` when the
    /// motion along `u` is downhill (then it is not damped), the identity otherwise (eq. 9 with
    /// the step Φ fixed for the step).
    pub fn damped_directions<const N: usize>(
        v: &SVector<f64, N>,
        g: &SVector<f64, N>,
    ) -> SMatrix<f64, N, N> {
        let identity = SMatrix::identity();
        match unit(g) {
            Some(u) if step(u.dot(v)) == 0.0 => identity - u * u.transpose(),
            _ => identity,
        }
    }

    /// The damping force `F_d = -B_d · M(x, v)`, N, for velocity `v` (m/s) where the gradient
    /// is `g` (eq. 10).
    pub fn force<const N: usize>(
        &self,
        v: &SVector<f64, N>,
        g: &SVector<f64, N>,
    ) -> SVector<f64, N> {
        -Self::damped_motion(v, g) * self.b_d
    }
}

impl<const N: usize> ControlLaw<N> for Nadf {
    fn force(&self, input: &ControlInput<N>) -> SVector<f64, N> {
        let g = input.gradient.unwrap_or_else(SVector::zeros);
        Nadf::force(self, &input.velocity, &g)
    }

    fn split(&self, input: &ControlInput<N>) -> Split<N> {
        let g = input.gradient.unwrap_or_else(SVector::zeros);
        Split::damping(self.b_d, Nadf::damped_directions(&input.velocity, &g))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, Vector2, Vector3};

    #[test]
    fn downhill_motion_is_not_damped() {
        // g points +x, so the guidance pushes -x; moving -x is downhill.
        let f = Nadf { b_d: 10.0 }.force(&Vector2::new(-2.0, 0.0), &Vector2::new(1.0, 0.0));
        assert_eq!(f, Vector2::zeros());
    }

    #[test]
    fn uphill_motion_is_damped_like_viscous() {
        let f = Nadf { b_d: 10.0 }.force(&Vector2::new(2.0, 0.0), &Vector2::new(0.5, 0.0));
        assert_eq!(f, Vector2::new(-20.0, 0.0));
    }

    #[test]
    fn sideways_motion_is_always_damped() {
        let g = Vector2::new(0.0, 3.0);
        let f = Nadf { b_d: 2.0 }.force(&Vector2::new(1.5, -1.0), &g);
        // The -y part is downhill (kept), the x part sideways (damped).
        assert!((f - Vector2::new(-3.0, 0.0)).norm() < 1e-12, "{f}");
    }

    #[test]
    fn matches_the_two_dimensional_form_of_eq_10_with_the_corrected_step() {
        let (gx, gy) = (0.3, -0.7);
        let g = Vector2::new(gx, gy);
        for v in [
            Vector2::new(1.0, 2.0),
            Vector2::new(-1.0, 0.5),
            Vector2::new(0.2, -3.0),
        ] {
            let (vx, vy) = (v.x, v.y);
            let n2 = gx * gx + gy * gy;
            let s = gx * vx + gy * vy;
            let eq10 = (Vector2::new(-gy, gx) * (gx * vy - gy * vx) + g * (s * step(s))) / n2;
            assert!((Nadf::damped_motion(&v, &g) - eq10).norm() < 1e-12);
        }
    }

    #[test]
    fn nadf_is_dissipative_in_any_dimension() {
        // vᵀM ≥ 0 (eq. 19): the damping force never adds energy.
        let cases = [
            (Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.1, 0.2, -0.3)),
            (Vector3::new(-1.0, 0.0, 4.0), Vector3::new(0.0, 0.0, 1.0)),
        ];
        for (v, g) in cases {
            assert!(v.dot(&Nadf::damped_motion(&v, &g)) >= 0.0);
        }
        // N = 1 (a joint): downhill free, uphill damped.
        let g = Vector1::new(2.0);
        assert_eq!(
            Nadf { b_d: 1.0 }.force(&Vector1::new(-1.0), &g),
            Vector1::new(0.0)
        );
        assert_eq!(
            Nadf { b_d: 1.0 }.force(&Vector1::new(1.0), &g),
            Vector1::new(-1.0)
        );
    }

    #[test]
    fn the_split_is_the_same_force() {
        let nadf = Nadf { b_d: 3.0 };
        for (v, g) in [
            ([1.0, 2.0], [0.3, -0.7]),
            ([-1.0, 0.5], [1.0, 0.0]),
            ([2.0, 0.0], [0.0, 0.0]),
        ] {
            let input = ControlInput {
                offset: Vector2::new(1.0, 1.0),
                velocity: Vector2::from(v),
                gradient: Some(Vector2::from(g)),
                curvature: None,
                dt: 0.01,
                touching: false,
                reference_velocity: None,
            };
            let split = ControlLaw::split(&nadf, &input);
            let f = split.force(&input.velocity);
            assert!((f - ControlLaw::force(&nadf, &input)).norm() < 1e-12);
        }
    }

    #[test]
    fn zero_gradient_falls_back_to_viscous() {
        let v = Vector2::new(1.0, -1.0);
        assert_eq!(
            Nadf { b_d: 4.0 }.force(&v, &Vector2::zeros()),
            Vector2::new(-4.0, 4.0)
        );
        let f = Nadf { b_d: 4.0 }.force(&v, &Vector2::new(f64::NAN, 0.0));
        assert_eq!(f, Vector2::new(-4.0, 4.0));
    }
}
