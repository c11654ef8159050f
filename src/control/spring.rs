//! A spring towards the target, `F = -K_P (x - x_T) = K_P e`: the position feedback of the
//! pendulum's controller (eq. 48 and 75, where there is no guidance field).

use nalgebra::SVector;

use super::{ControlInput, ControlLaw, Split};

/// The spring law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// Stiffness K_P: N/m for a body, N·m/rad for a joint (typical 5–100 for a 1 kg, 1 m
    /// pendulum, whose weight gives a torque of up to 9.81 N·m).
    pub k: f64,
}

impl<const N: usize> ControlLaw<N> for Spring {
    fn force(&self, input: &ControlInput<N>) -> SVector<f64, N> {
        -input.offset * self.k
    }

    fn split(&self, input: &ControlInput<N>) -> Split<N> {
        Split::spring(self.k, &input.offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector1;

    #[test]
    fn the_spring_pulls_towards_the_target() {
        let input = ControlInput {
            offset: Vector1::new(-0.5),
            velocity: Vector1::new(3.0),
            gradient: None,
            curvature: None,
            dt: 0.01,
            touching: false,
            reference_velocity: None,
        };
        assert_eq!(Spring { k: 20.0 }.force(&input), Vector1::new(10.0));
    }
}
