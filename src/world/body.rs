//! The geometry and mass of an agent's shape ([`BodyShape`]): its convex parts about their
//! centroid, its area, its moment of inertia and how far it reaches from its centre.
//!
//! The body frame's origin is the shape's centroid: the points a world file gives are shifted
//! so (a box or a symmetric polygon is already centred). Then the centre of mass is the point
//! the field plans for and the point Rapier turns the body about, and the inertia matrix of
//! the configuration `(x, y, θ)` is `D = diag(m, m, I)`, with no coupling between translation
//! and rotation (the paper's Proposition 1 with a constant `D`).

use parry2d::math::Vector;
use parry2d::shape::ConvexPolygon;

use super::schema::{Agent, AgentShape};
use crate::field::{HeadingMask, ShapeError};

/// A shape's convex parts about its centroid, with the mass properties of uniform density.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyShape {
    /// The convex parts, counter-clockwise, about the centroid, m.
    pub parts: Vec<Vec<[f64; 2]>>,
    /// Where the centroid is in the frame the points were given in, m (the shift applied).
    pub centroid: [f64; 2],
    /// Total area, m².
    pub area: f64,
    /// Polar moment of the area about the centroid, m⁴: the inertia is `mass · second_moment /
    /// area` at uniform density.
    pub second_moment: f64,
    /// The largest distance from the centroid to a vertex, m.
    pub reach: f64,
}

impl BodyShape {
    /// The shape of `shape`'s parts, checked: convex, counter-clockwise, with area. `None` for
    /// a disc.
    pub fn of(shape: &AgentShape) -> Result<Option<Self>, ShapeError> {
        let parts = shape.parts();
        if parts.is_empty() {
            return Ok(None);
        }
        HeadingMask::check_parts(&parts)?;
        // Area and first and second moments of each part, by its triangles from the origin.
        let (mut area, mut first, mut second) = (0.0, [0.0, 0.0], 0.0);
        for part in &parts {
            let n = part.len();
            for v in 0..n {
                let ([x0, y0], [x1, y1]) = (part[v], part[(v + 1) % n]);
                let c = x0 * y1 - x1 * y0;
                area += c / 2.0;
                first[0] += c * (x0 + x1) / 6.0;
                first[1] += c * (y0 + y1) / 6.0;
                second += c * (x0 * x0 + x0 * x1 + x1 * x1 + y0 * y0 + y0 * y1 + y1 * y1) / 12.0;
            }
        }
        let centroid = [first[0] / area, first[1] / area];
        // Parallel axes: the polar moment about the centroid.
        let second_moment = second - area * (centroid[0].powi(2) + centroid[1].powi(2));
        let parts: Vec<Vec<[f64; 2]>> = (parts.iter())
            .map(|p| {
                p.iter()
                    .map(|&[x, y]| [x - centroid[0], y - centroid[1]])
                    .collect()
            })
            .collect();
        let reach = (parts.iter().flatten())
            .map(|p| p[0].hypot(p[1]))
            .fold(0.0, f64::max);
        Ok(Some(Self {
            parts,
            centroid,
            area,
            second_moment,
            reach,
        }))
    }

    /// The shape of `agent` (`None` for a disc), checked.
    pub fn of_agent(agent: &Agent) -> Result<Option<Self>, ShapeError> {
        agent.shape.as_ref().map_or(Ok(None), Self::of)
    }

    /// The moment of inertia about the centroid of a body of `mass` kg at uniform density,
    /// kg·m².
    pub fn inertia(&self, mass: f64) -> f64 {
        mass * self.second_moment / self.area
    }

    /// The parts as parry polygons, for Rapier's colliders and parry's queries.
    pub fn polygons(&self) -> Vec<ConvexPolygon> {
        (self.parts.iter())
            .filter_map(|p| {
                ConvexPolygon::from_convex_polyline(
                    p.iter().map(|&[x, y]| Vector::new(x, y)).collect(),
                )
            })
            .collect()
    }

    /// The parts' vertices at the pose `(x, y, θ)`, m.
    pub fn placed(&self, [x, y, theta]: [f64; 3]) -> Vec<Vec<[f64; 2]>> {
        let (s, c) = theta.sin_cos();
        (self.parts.iter())
            .map(|p| {
                p.iter()
                    .map(|&[a, b]| [x + c * a - s * b, y + s * a + c * b])
                    .collect()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_boxs_inertia_is_the_textbook_one_and_an_l_is_centred_on_its_centroid() {
        let board = BodyShape::of(&AgentShape::Box {
            half_extents: [0.75, 0.05],
        })
        .unwrap()
        .unwrap();
        // m (a² + b²) / 12 for a 1.5 m × 0.1 m board of 2 kg.
        let expected = 2.0 * (1.5f64.powi(2) + 0.1f64.powi(2)) / 12.0;
        assert!((board.inertia(2.0) - expected).abs() < 1e-12);
        assert_eq!(board.centroid, [0.0, 0.0]);
        // An L of three unit squares, centred at (0.5, 0.5), (1.5, 0.5) and (0.5, 1.5): its
        // centroid is their mean.
        let l = BodyShape::of(&AgentShape::Compound {
            parts: vec![
                vec![[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]],
                vec![[0.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]],
            ],
        })
        .unwrap()
        .unwrap();
        let c = 2.5 / 3.0;
        assert!((l.centroid[0] - c).abs() < 1e-12 && (l.centroid[1] - c).abs() < 1e-12);
        assert!((l.area - 3.0).abs() < 1e-12);
        // Each unit square: 1/6 about its centre, plus its squared distance to the centroid.
        let d2: f64 = [[0.5, 0.5], [1.5, 0.5], [0.5, 1.5]]
            .iter()
            .map(|p: &[f64; 2]| (p[0] - c).powi(2) + (p[1] - c).powi(2))
            .sum();
        assert!((l.second_moment - (0.5 + d2)).abs() < 1e-12);
    }

    #[test]
    fn a_clockwise_part_is_an_error_naming_it() {
        let e = BodyShape::of(&AgentShape::Polygon {
            points: vec![[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]],
        })
        .unwrap_err();
        assert!(matches!(e, ShapeError::NotConvex { part: 0, .. }), "{e}");
    }
}
