//! Linear viscous damping, eq. 1: `F_d = -B · v`. It damps motion in every direction alike,
//! the useful part along the guidance included — the reason it must trade speed for safety.

use nalgebra::{SMatrix, SVector};

use super::{ControlInput, ControlLaw, Split};

/// Viscous damping.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viscous {
    /// Damping coefficient B, N·s/m (kg/s). For a 1 kg body with K = 1 N guidance, B below about
    /// 0.2 lets it hit walls and B above 1 makes it crawl (paper figures 4–8, 23).
    pub b: f64,
}

impl Viscous {
    /// The damping force `F_d = -B · v`, N, for velocity `v` (m/s).
    pub fn force<const N: usize>(&self, v: &SVector<f64, N>) -> SVector<f64, N> {
        -v * self.b
    }
}

impl<const N: usize> ControlLaw<N> for Viscous {
    fn force(&self, input: &ControlInput<N>) -> SVector<f64, N> {
        Viscous::force(self, &input.velocity)
    }

    fn split(&self, _: &ControlInput<N>) -> Split<N> {
        Split::damping(self.b, SMatrix::identity())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn viscous_damping_opposes_velocity_whatever_the_guidance() {
        let d = Viscous { b: 0.7 };
        let v = Vector2::new(1.0, -2.0);
        let input = |g| ControlInput {
            offset: Vector2::new(1.0, 1.0),
            velocity: v,
            gradient: g,
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: None,
        };
        for g in [Some(Vector2::new(1.0, 0.0)), None] {
            assert_eq!(ControlLaw::force(&d, &input(g)), Vector2::new(-0.7, 1.4));
        }
    }
}
