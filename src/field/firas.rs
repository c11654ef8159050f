//! Khatib's attractive-repulsive potential (paper §VI.6): the baseline the NADF is compared
//! against in the narrow corridor.
//!
//! `U(x) = U_att(x) + Σ_k U_rep,k(x)`, with
//! - attraction `U_att = d` (`conic`: a pull of constant magnitude, tapered to a spring
//!   `d²/(2 r_c)` inside the capture radius `r_c` so the pull does not flip sides at the target)
//!   or `U_att = ½ d²` (`quadratic`), where `d = |x - x_T|`;
//! - FIRAS repulsion (Khatib 1986) `U_rep,k = ½ η (1/ρ_k - 1/ρ0)²` for `ρ_k < ρ0`, zero beyond,
//!   where `ρ_k` is the distance from the agent's disc to obstacle `k` as parry computes it (the
//!   wall's sensed position with a noisy sensor; the other agents' discs with several agents).
//!
//! Unlike the harmonic field this potential has local minima (in front of a barrier, for
//! instance), and its gradient is computed in closed form at the body, with no grid.

use nalgebra::Vector2;

use super::mask::Disc;
use super::streamline::{Streamline, integrate};
use crate::world::{Attraction, WallShape};

/// Below this distance to an obstacle, m, the repulsion is evaluated at this distance: the
/// FIRAS term grows without bound at contact, and a finite force (however large) is what a
/// body pushed into a wall by noise or inertia must get, never an infinity.
pub const MIN_DISTANCE: f64 = 1e-3;

/// One agent's attractive-repulsive potential.
#[derive(Clone)]
pub struct AttractiveRepulsive {
    /// The target, m.
    pub target: [f64; 2],
    /// The agent's radius, m.
    pub radius: f64,
    /// How the target attracts.
    pub attraction: Attraction,
    /// Capture radius of the conic attraction, m.
    pub capture_radius: f64,
    /// Repulsion gain η, m³ (so that `U` is in metres, like the conic attraction).
    pub eta: f64,
    /// Range of the repulsion ρ0, m.
    pub rho0: f64,
    /// Step of the kinematic path, m.
    pub cell: f64,
    walls: Vec<WallShape>,
    offsets: Vec<f64>,
    others: Vec<Disc>,
}

impl AttractiveRepulsive {
    /// The potential of `walls` (known exactly until [`sense`](Self::sense) is called) for an
    /// agent of `radius` heading for `target`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        walls: Vec<WallShape>,
        target: [f64; 2],
        radius: f64,
        attraction: Attraction,
        capture_radius: f64,
        eta: f64,
        rho0: f64,
        cell: f64,
    ) -> Self {
        Self {
            target,
            radius,
            attraction,
            capture_radius,
            eta,
            rho0,
            cell,
            offsets: vec![0.0; walls.len()],
            walls,
            others: Vec::new(),
        }
    }

    /// Registers wall `k` at `offsets[k]` m outside its true boundary (a sensor reading).
    pub fn sense(&mut self, offsets: &[f64]) {
        self.offsets = offsets.to_vec();
        self.offsets.resize(self.walls.len(), 0.0);
    }

    /// Sets the other agents' discs, which repel like walls.
    pub fn set_others(&mut self, others: Vec<Disc>) {
        self.others = others;
    }

    /// Distance from the agent's disc at `p` to every obstacle, with the unit vector along
    /// which that distance grows fastest.
    fn obstacles(&self, p: [f64; 2]) -> impl Iterator<Item = (f64, Vector2<f64>)> + '_ {
        let walls = self
            .walls
            .iter()
            .zip(&self.offsets)
            .map(move |(w, offset)| {
                let (signed, direction) = w.signed_distance_and_direction(p[0], p[1]);
                (signed - offset - self.radius, Vector2::from(direction))
            });
        let others = self.others.iter().map(move |o| {
            let away = Vector2::new(p[0] - o.center[0], p[1] - o.center[1]);
            let d = away.norm();
            let direction = if d > 0.0 { away / d } else { Vector2::zeros() };
            (d - o.radius - self.radius, direction)
        });
        walls.chain(others)
    }

    /// The potential `U` at `p`, m.
    pub fn potential(&self, p: [f64; 2]) -> f64 {
        let d = (p[0] - self.target[0]).hypot(p[1] - self.target[1]);
        let attraction = match self.attraction {
            Attraction::Conic if d < self.capture_radius => {
                0.5 * (d * d / self.capture_radius + self.capture_radius)
            }
            Attraction::Conic => d,
            Attraction::Quadratic => 0.5 * d * d,
        };
        let repulsion: f64 = self
            .obstacles(p)
            .filter(|(rho, _)| *rho < self.rho0)
            .map(|(rho, _)| {
                let s = 1.0 / rho.max(MIN_DISTANCE) - 1.0 / self.rho0;
                0.5 * self.eta * s * s
            })
            .sum();
        attraction + repulsion
    }

    /// The gradient `∇U` at `p`, 1 (dimensionless for the conic attraction). Always finite.
    pub fn gradient(&self, p: [f64; 2]) -> Option<Vector2<f64>> {
        let offset = Vector2::new(p[0] - self.target[0], p[1] - self.target[1]);
        let d = offset.norm();
        let attraction = match self.attraction {
            Attraction::Conic if d < self.capture_radius => offset / self.capture_radius,
            Attraction::Conic if d > 0.0 => offset / d,
            Attraction::Conic => Vector2::zeros(),
            Attraction::Quadratic => offset,
        };
        // ∇½η(1/ρ - 1/ρ0)² = -η (1/ρ - 1/ρ0) ∇ρ / ρ².
        let repulsion: Vector2<f64> = self
            .obstacles(p)
            .filter(|(rho, _)| *rho < self.rho0)
            .map(|(rho, direction)| {
                let rho = rho.max(MIN_DISTANCE);
                -direction * (self.eta * (1.0 / rho - 1.0 / self.rho0) / (rho * rho))
            })
            .sum();
        let g = attraction + repulsion;
        g.iter().all(|c| c.is_finite()).then_some(g)
    }

    /// The kinematic path from `start`: the streamline of `-∇U/|∇U|`. It ends at the target,
    /// or where it stops making progress: at a local minimum (in front of a barrier).
    pub fn streamline(&self, start: [f64; 2], max_length: f64) -> Streamline {
        integrate(
            |p| self.gradient(p).map(|g| -g),
            start,
            self.target,
            0.5 * self.cell,
            self.cell,
            max_length,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Wall, wall_shape};

    fn corridor(attraction: Attraction) -> AttractiveRepulsive {
        // Walls along y = 0 and y = 2 (their faces), target far along +x.
        let walls = [
            Wall::Box {
                center: [20.0, -0.5],
                half_extents: [20.0, 0.5],
                angle: 0.0,
            },
            Wall::Box {
                center: [20.0, 2.5],
                half_extents: [20.0, 0.5],
                angle: 0.0,
            },
        ]
        .iter()
        .map(|w| wall_shape(w).unwrap())
        .collect();
        AttractiveRepulsive::new(walls, [38.0, 1.0], 0.2, attraction, 0.25, 0.1, 0.5, 0.05)
    }

    #[test]
    fn the_gradient_is_the_derivative_of_the_potential() {
        for attraction in [Attraction::Conic, Attraction::Quadratic] {
            let f = corridor(attraction);
            for p in [[5.0, 0.45], [5.0, 1.0], [10.0, 1.6], [37.9, 1.05]] {
                let g = f.gradient(p).unwrap();
                // Parry measures in f32: a step well above its rounding at 40 m.
                let h = 1e-3;
                let dx =
                    (f.potential([p[0] + h, p[1]]) - f.potential([p[0] - h, p[1]])) / (2.0 * h);
                let dy =
                    (f.potential([p[0], p[1] + h]) - f.potential([p[0], p[1] - h])) / (2.0 * h);
                assert!(
                    (g - Vector2::new(dx, dy)).norm() < 1e-2 * (1.0 + g.norm()),
                    "{attraction:?} at {p:?}: {g} vs ({dx}, {dy})"
                );
            }
        }
    }

    #[test]
    fn firas_repels_within_rho0_only_and_stays_finite_at_contact() {
        let f = corridor(Attraction::Conic);
        // Centre line: the walls are 1 - 0.2 = 0.8 m away, beyond ρ0 = 0.5: pure attraction.
        let g = f.gradient([5.0, 1.0]).unwrap();
        assert!((g - Vector2::new(-1.0, 0.0)).norm() < 1e-12, "{g}");
        // 0.3 m from the lower wall (0.1 m from the disc): pushed up (∇U points down).
        let g = f.gradient([5.0, 0.3]).unwrap();
        let expected = 0.1 * (1.0 / 0.1 - 1.0 / 0.5) / 0.01;
        assert!((g.y + expected).abs() < 1e-3 * expected, "{g}");
        // Overlapping the wall: large, finite, still pushing out.
        let g = f.gradient([5.0, 0.1]).unwrap();
        assert!(g.y < -1e6 && g.y.is_finite(), "{g}");
    }

    #[test]
    fn a_sensed_wall_moves_the_repulsion() {
        let mut f = corridor(Attraction::Conic);
        // The disc is 0.55 m from the lower wall: beyond ρ0.
        let before = f.gradient([5.0, 0.75]).unwrap();
        let pull = (0.75 - 1.0) / (33.0f64.powi(2) + 0.25f64.powi(2)).sqrt();
        assert!((before.y - pull).abs() < 1e-12, "{before}");
        // The lower wall sensed 0.3 m thicker: the disc is now 0.25 m from it.
        f.sense(&[0.3, 0.0]);
        let after = f.gradient([5.0, 0.75]).unwrap();
        let expected = 0.1 * (1.0 / 0.25 - 1.0 / 0.5) / (0.25 * 0.25);
        assert!(
            (after.y - pull + expected).abs() < 1e-3 * expected,
            "{after}"
        );
    }

    #[test]
    fn other_agents_repel_like_walls() {
        let mut f = corridor(Attraction::Conic);
        f.set_others(vec![Disc {
            center: [5.6, 1.0],
            radius: 0.2,
        }]);
        // 0.6 m apart centre to centre: the discs are 0.2 m apart, within ρ0; pushed back (-x).
        let g = f.gradient([5.0, 1.0]).unwrap();
        assert!(g.x > 0.0, "{g}");
    }

    #[test]
    fn the_kinematic_path_follows_the_corridor_to_the_target() {
        let f = corridor(Attraction::Conic);
        let s = f.streamline([2.0, 1.0], 100.0);
        assert!(s.reached);
        assert!(s.points.iter().all(|p| (p[1] - 1.0).abs() < 1e-9));
    }
}
