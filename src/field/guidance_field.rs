//! The potential an agent follows: the harmonic field (the method) or Khatib's
//! attractive-repulsive potential (the baseline of the narrow corridor, §VI.6), behind one
//! interface for the simulation, the faults monitor and the recording.

use nalgebra::{Matrix2, Vector2};

use super::firas::AttractiveRepulsive;
use super::mask::Disc;
use super::{ConfigurationSpace, FieldError, HarmonicField, Streamline};
use crate::world::{Agent, FieldKind, World, all_wall_shapes};

/// One agent's guidance potential.
#[derive(Clone)]
pub enum GuidanceField {
    /// Laplace's equation on the free space, solved on a grid (eq. 3).
    Harmonic(HarmonicField),
    /// Attraction plus FIRAS repulsion, evaluated in closed form at the body.
    AttractiveRepulsive(AttractiveRepulsive),
}

impl GuidanceField {
    /// The field of `agent` in `world` (with the world's field kind), with `others` as
    /// obstacles besides the walls.
    pub fn build(world: &World, agent: &Agent, others: &[Disc]) -> Result<Self, FieldError> {
        let lidar = agent.has_lidar();
        Ok(match world.field.kind {
            // A lidar agent has seen nothing yet: every cell counts as free.
            FieldKind::Harmonic if lidar => {
                let grid = super::Grid::anchored_in(world.bounds(), world.field.cell, agent.target);
                Self::Harmonic(HarmonicField::solve_known(
                    world,
                    agent,
                    agent.start,
                    &super::KnownMap::new(grid),
                    others,
                    None,
                )?)
            }
            FieldKind::Harmonic => Self::Harmonic(HarmonicField::solve_among(
                world,
                agent,
                agent.start,
                &[],
                others,
                None,
            )?),
            FieldKind::AttractiveRepulsive => {
                let mut f = AttractiveRepulsive::new(
                    all_wall_shapes(world),
                    agent.target,
                    agent.radius,
                    world.field.attraction,
                    agent.controller.capture_radius,
                    world.field.eta.unwrap_or(0.0),
                    world.field.rho0.unwrap_or(0.0),
                    world.field.cell,
                );
                f.set_others(others.to_vec());
                Self::AttractiveRepulsive(f)
            }
        })
    }

    /// The harmonic field, if this is one.
    pub fn harmonic(&self) -> Option<&HarmonicField> {
        match self {
            Self::Harmonic(h) => Some(h),
            Self::AttractiveRepulsive(_) => None,
        }
    }

    /// The gradient `∇V` (or `∇U`) at `p`; `None` where it is undefined.
    pub fn gradient(&self, p: [f64; 2]) -> Option<Vector2<f64>> {
        match self {
            Self::Harmonic(h) => h.gradient(p),
            Self::AttractiveRepulsive(f) => f.gradient(p),
        }
    }

    /// The curvature `∇∇V` (or `∇∇U`) at `p`, 1/m², by central differences of the gradient
    /// half a cell (1 cm for Khatib's field) either side, symmetrized; `None` where a gradient
    /// is undefined (see [`ConfigurationSpace::curvature`]).
    pub fn curvature(&self, p: [f64; 2]) -> Option<Matrix2<f64>> {
        <Self as ConfigurationSpace<2>>::curvature(self, p)
    }

    /// The potential at `p`: `V` in [0, 1], or Khatib's `U` in metres.
    pub fn potential(&self, p: [f64; 2]) -> f64 {
        match self {
            Self::Harmonic(h) => h.potential(p),
            Self::AttractiveRepulsive(f) => f.potential(p),
        }
    }

    /// The kinematic path from `start`; `max_length` bounds an attractive-repulsive path, m.
    pub fn streamline(&self, start: [f64; 2], max_length: f64) -> Streamline {
        match self {
            Self::Harmonic(h) => h.streamline(start),
            Self::AttractiveRepulsive(f) => f.streamline(start, max_length),
        }
    }

    /// The grid spacing, m.
    pub fn cell(&self) -> f64 {
        match self {
            Self::Harmonic(h) => h.grid().cell,
            Self::AttractiveRepulsive(f) => f.cell,
        }
    }

    /// The target, m.
    pub fn target(&self) -> [f64; 2] {
        match self {
            Self::Harmonic(h) => h.target,
            Self::AttractiveRepulsive(f) => f.target,
        }
    }
}

/// A disc's configuration space: the plane, whose coordinates are already the metric ones.
impl ConfigurationSpace<2> for GuidanceField {
    type Config = [f64; 2];

    fn offset(&self, p: [f64; 2]) -> Vector2<f64> {
        Vector2::from(p) - Vector2::from(self.target())
    }

    fn gradient(&self, p: [f64; 2]) -> Option<Vector2<f64>> {
        GuidanceField::gradient(self, p)
    }

    fn potential(&self, p: [f64; 2]) -> f64 {
        GuidanceField::potential(self, p)
    }

    fn moved(&self, mut p: [f64; 2], axis: usize, by: f64) -> [f64; 2] {
        p[axis] += by;
        p
    }

    fn curvature_step(&self) -> f64 {
        match self {
            Self::Harmonic(f) => 0.5 * f.grid().cell,
            Self::AttractiveRepulsive(_) => 0.01,
        }
    }
}
