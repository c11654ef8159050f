//! The harmonic guidance field of one agent (paper §II, eq. 3–4).
//!
//! The walls are rasterized into a configuration-space mask for the agent's radius
//! ([`mask`]), Laplace's equation is solved on the free cells connected to the target by
//! multigrid-preconditioned CG ([`multigrid`]) with nested solves of the deep regions
//! ([`harmonic`]; [`laplace`] keeps a plain SOR solver as the reference), and the result is
//! sampled smoothly anywhere in the box ([`sample`]); the kinematic path is the streamline of
//! the normalized guidance from the start ([`streamline`]).
//!
//! With several agents, each agent's field treats the others as obstacles: discs at their
//! current positions, grown by both radii ([`Disc`]). Khatib's attractive-repulsive potential
//! ([`firas`]) is the baseline of the narrow corridor; [`GuidanceField`] holds either.

pub mod export;
pub mod firas;
pub mod grid;
pub mod guidance_field;
pub mod harmonic;
pub mod laplace;
pub mod mask;
pub mod multigrid;
pub mod sample;
pub mod streamline;

use std::time::{Duration, Instant};

use nalgebra::Vector2;

pub use firas::{AttractiveRepulsive, Disc};
pub use grid::Grid;
pub use guidance_field::GuidanceField;
pub use sample::Sampler;
pub use streamline::Streamline;

use crate::world::{Agent, World, all_wall_shapes};

/// Why a field could not be built for an agent.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    /// The target lies in a blocked cell.
    #[error(
        "agent `{agent}`: its target is within its radius of a wall on the {cell} m grid; move the target away from the wall or use a smaller field.cell"
    )]
    TargetBlocked {
        /// The agent's name.
        agent: String,
        /// The grid cell size, m.
        cell: f64,
    },
    /// No free path connects the start to the target.
    #[error(
        "agent `{agent}`: its target cannot be reached from its start (no free path for a disc of radius {radius} m); the task is intractable"
    )]
    Unreachable {
        /// The agent's name.
        agent: String,
        /// The agent's radius, m.
        radius: f64,
    },
    /// The solver did not reach the tolerance.
    #[error(
        "agent `{agent}`: the Laplace solver stopped at a relative residual of {relative_residual:e} after {iterations} iterations, above field.tolerance"
    )]
    Solver {
        /// The agent's name.
        agent: String,
        /// Iterations performed.
        iterations: usize,
        /// The residual reached.
        relative_residual: f64,
    },
}

/// The solved field of one agent, with the statistics of the solve.
#[derive(Debug, Clone)]
pub struct HarmonicField {
    /// The field, ready to sample.
    pub sampler: Sampler,
    /// The configuration-space mask: `true` where the agent's centre cannot be.
    pub blocked: Vec<bool>,
    /// The target, m.
    pub target: [f64; 2],
    /// Conjugate gradient iterations over all solves.
    pub iterations: usize,
    /// Solves: the first plus the nested ones for the deep regions (see [`harmonic`]).
    pub solves: usize,
    /// The worst final relative residual of the solves.
    pub relative_residual: f64,
    /// Wall-clock time of the solve.
    pub solve_time: Duration,
}

/// One agent's configuration space on its grid: where its centre may be, and which of those
/// cells connect to the target. Cheap (no solve), so `nadf check` builds it too.
#[derive(Debug, Clone)]
pub struct FreeSpace {
    /// The grid, anchored on the target.
    pub grid: Grid,
    /// `true` where the agent's centre cannot be.
    pub blocked: Vec<bool>,
    /// The target's cell.
    pub target_cell: (usize, usize),
    /// `true` for the free cells connected to the target cell.
    pub reachable: Vec<bool>,
}

impl FreeSpace {
    /// Rasterizes the world for `agent` and checks that its start connects to its target.
    pub fn of(world: &World, agent: &Agent) -> Result<Self, FieldError> {
        Self::sensed(world, agent, agent.start, &[])
    }

    /// Like [`FreeSpace::of`] for walls sensed with errors: wall `k` of
    /// [`all_wall_shapes`] moved out by `offsets[k]` m (see [`mask::rasterize_sensed`]), and
    /// `position` in place of the start.
    pub fn sensed(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        offsets: &[f64],
    ) -> Result<Self, FieldError> {
        Self::among(world, agent, position, offsets, &[])
    }

    /// Like [`FreeSpace::sensed`] with the discs `others` (the other agents) as obstacles too.
    /// A disc that covers the agent's target or the agent itself is left out: an agent parked
    /// on another's target must not make that target unreachable for good, and two agents in
    /// contact must still each have a field (the contact is counted by the simulation).
    pub fn among(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        offsets: &[f64],
        others: &[Disc],
    ) -> Result<Self, FieldError> {
        let grid = Grid::anchored(world.size, world.field.cell, agent.target);
        let mut walls = all_wall_shapes(world);
        let margin = agent.radius + std::f64::consts::SQRT_2 * grid.cell;
        let covers = |d: &Disc, p: [f64; 2]| {
            (p[0] - d.center[0]).hypot(p[1] - d.center[1]) < d.radius + margin
        };
        walls.extend(
            others
                .iter()
                .filter(|d| !covers(d, agent.target) && !covers(d, position))
                .map(Disc::shape),
        );
        let blocked = mask::rasterize_sensed(&grid, world.size, &walls, agent.radius, offsets);
        let target_cell = grid
            .cell_of(agent.target)
            .filter(|&(i, j)| !blocked[grid.index(i, j)])
            .ok_or_else(|| FieldError::TargetBlocked {
                agent: agent.name.clone(),
                cell: grid.cell,
            })?;
        let reachable = laplace::reachable_from(&grid, &blocked, target_cell);
        // The start is connected when a cell around it is: the cells the sampler interpolates.
        let near = |c: usize, n: usize| c.saturating_sub(1)..=(c + 1).min(n - 1);
        let start_connected = grid.cell_of(position).is_some_and(|(i, j)| {
            near(i, grid.nx).any(|a| near(j, grid.ny).any(|b| reachable[grid.index(a, b)]))
        });
        if !start_connected {
            return Err(FieldError::Unreachable {
                agent: agent.name.clone(),
                radius: agent.radius,
            });
        }
        Ok(Self {
            grid,
            blocked,
            target_cell,
            reachable,
        })
    }
}

impl HarmonicField {
    /// Rasterizes the world for `agent` and solves its field.
    pub fn solve(world: &World, agent: &Agent) -> Result<Self, FieldError> {
        let started = Instant::now();
        let space = FreeSpace::of(world, agent)?;
        Self::solve_space(world, agent, space, None, started)
    }

    /// Solves the field of walls sensed with errors (see [`FreeSpace::sensed`]) with the agent
    /// at `position`, warm-started from `previous` (the last field, on the same grid).
    pub fn solve_sensed(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        offsets: &[f64],
        previous: Option<&HarmonicField>,
    ) -> Result<Self, FieldError> {
        Self::solve_among(world, agent, position, offsets, &[], previous)
    }

    /// Like [`HarmonicField::solve_sensed`] with the discs `others` (the other agents) as
    /// obstacles too (see [`FreeSpace::among`]).
    pub fn solve_among(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        offsets: &[f64],
        others: &[Disc],
        previous: Option<&HarmonicField>,
    ) -> Result<Self, FieldError> {
        let started = Instant::now();
        let space = FreeSpace::among(world, agent, position, offsets, others)?;
        let warm = previous.map(|f| f.sampler.w_cells());
        Self::solve_space(world, agent, space, warm, started)
    }

    fn solve_space(
        world: &World,
        agent: &Agent,
        space: FreeSpace,
        warm: Option<&[f64]>,
        started: Instant,
    ) -> Result<Self, FieldError> {
        let solution = harmonic::solve_w(
            &space.grid,
            &space.reachable,
            space.target_cell,
            world.field.tolerance,
            warm,
        );
        if solution.relative_residual.is_nan() || solution.relative_residual > world.field.tolerance
        {
            return Err(FieldError::Solver {
                agent: agent.name.clone(),
                iterations: solution.iterations,
                relative_residual: solution.relative_residual,
            });
        }
        Ok(Self {
            sampler: Sampler::new(space.grid, solution.w, space.reachable),
            blocked: space.blocked,
            target: agent.target,
            iterations: solution.iterations,
            solves: solution.solves,
            relative_residual: solution.relative_residual,
            solve_time: started.elapsed(),
        })
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        self.sampler.grid()
    }

    /// The potential `V` at `p` (1 where nothing reachable is near).
    pub fn potential(&self, p: [f64; 2]) -> f64 {
        1.0 - self.sampler.w(p).unwrap_or(0.0)
    }

    /// `1 - V` at `p`, with full relative precision where `V` is close to 1.
    pub fn one_minus_potential(&self, p: [f64; 2]) -> f64 {
        self.sampler.w(p).unwrap_or(0.0)
    }

    /// The gradient `g = ∇V` at `p`; `None` where the field is undefined (far from any
    /// reachable cell). Callers treat `None` like a vanishing gradient.
    pub fn gradient(&self, p: [f64; 2]) -> Option<Vector2<f64>> {
        self.sampler.grad_w(p).map(|g| -g)
    }

    /// The kinematic path from `start` (eq. 4, normalized).
    pub fn streamline(&self, start: [f64; 2]) -> Streamline {
        let g = self.grid();
        let max_length = 4.0 * (g.nx * g.ny) as f64 * g.cell;
        streamline::streamline(&self.sampler, start, self.target, max_length)
    }
}
