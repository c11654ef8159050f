//! An agent's harmonic field ([`HarmonicField`]) and its production solve of `W = 1 − V`:
//! multigrid-preconditioned CG (`multigrid/`), then nested, rescaled re-solves of the regions
//! where `W` is tiny.
//!
//! A solve to a relative residual of 1e-10 gives `W` to about 1e-12 absolute. Behind a few
//! turns `W` is far smaller than that (1e-13 in the 10 m room at 1 cm cells, 1e-17 in a
//! 16 m × 10 m world with three shelves, 1e-140 in the maze), so the first solution there is
//! noise, and the guidance direction with it. The deep region `D`, the cells below τ = 1e-6
//! (less those next to a wall, see [`deep_cells`]), is therefore solved again: each connected
//! part of it on its own, on its bounding box. Its boundary values — the neighbouring cells,
//! where `W` is known to full relative precision — are divided by τ, the problem is solved on
//! the part alone, and the result multiplied by τ. By the maximum principle a relative error ε
//! in the boundary values is at most ε relative everywhere inside, so each level keeps relative
//! precision and reaches six orders of magnitude deeper. This repeats until no cell is below the
//! current depth: the field never goes flat where a path exists.

use std::time::{Duration, Instant};

use nalgebra::Vector2;

use super::grid::Grid;
use super::mask::CellCounts;
use super::multigrid;
use super::{Disc, FieldError, FreeSpace, Sampler, Streamline};
use crate::world::{Agent, World};

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
    /// Solves: the first plus the nested ones for the deep regions (see [`solve_w`]).
    pub solves: usize,
    /// The worst final relative residual of the solves.
    pub relative_residual: f64,
    /// Wall-clock time of the solve.
    pub solve_time: Duration,
}

impl HarmonicField {
    /// Rasterizes the world for `agent` and solves its field.
    pub fn solve(world: &World, agent: &Agent) -> Result<Self, FieldError> {
        let started = Instant::now();
        let space = FreeSpace::of(world, agent)?;
        Self::solve_space(world, agent, space, None, started)
    }

    /// Solves the field with the agent at `position`, the walls sensed with `offsets` and the
    /// discs `others` (the other agents) as obstacles too (see [`FreeSpace::among`]),
    /// warm-started from `previous` (the last field, on the same grid).
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
        let solution = solve_w(
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

    /// How many cells are reachable, blocked and unreachable.
    pub fn counts(&self) -> CellCounts {
        CellCounts::of(&self.blocked, self.sampler.reachable_cells())
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
        self.streamline_within(start, 4.0 * (g.nx * g.ny) as f64 * g.cell)
    }

    /// The streamline from `start`, at most `max_length` long, m.
    pub fn streamline_within(&self, start: [f64; 2], max_length: f64) -> Streamline {
        super::streamline::streamline(&self.sampler, start, self.target, max_length)
    }
}

/// The depth gained by each nested solve.
pub const DEPTH_STEP: f64 = 1e-6;
/// How many steps through free cells a cell below the depth may be from a cell above it and
/// still count as resolved (see [`deep_cells`]).
pub const REACH: usize = 8;
/// CG iterations allowed per solve.
pub const MAX_ITERATIONS: usize = 500;

/// The solved field and how the solve went.
#[derive(Debug, Clone)]
pub struct HarmonicSolution {
    /// `W` per cell: 1 at the target, 0 on blocked and unreachable cells.
    pub w: Vec<f64>,
    /// CG iterations over all solves.
    pub iterations: usize,
    /// Solves: the first one plus the nested ones.
    pub solves: usize,
    /// The worst final relative residual of the solves.
    pub relative_residual: f64,
}

/// Solves for `W` on the `reachable` cells with `W = 1` at `target`, each solve to a relative
/// residual of `tolerance`. `warm` is a previous `W` on the same grid to start from (after a
/// small change of the world), if any.
pub fn solve_w(
    grid: &Grid,
    reachable: &[bool],
    target: (usize, usize),
    tolerance: f64,
    warm: Option<&[f64]>,
) -> HarmonicSolution {
    let t = grid.index(target.0, target.1);
    let mut unknown = reachable.to_vec();
    unknown[t] = false;
    let mut w = match warm {
        Some(w) if w.len() == grid.len() => w
            .iter()
            .zip(&unknown)
            .map(|(w, u)| if *u { *w } else { 0.0 })
            .collect(),
        _ => vec![0.0; grid.len()],
    };
    w[t] = 1.0;
    let first = multigrid::solve(grid, &unknown, &mut w, tolerance, MAX_ITERATIONS);
    let mut out = HarmonicSolution {
        w: Vec::new(),
        iterations: first.iterations,
        solves: 1,
        relative_residual: first.relative_residual,
    };
    let mut depth = DEPTH_STEP;
    while depth > 1e-290 {
        let deep = deep_cells(grid, &unknown, &w, depth);
        let regions = regions(grid, &deep);
        if regions.is_empty() {
            break;
        }
        for cells in &regions {
            let stats = solve_deep(grid, cells, &mut w, depth, tolerance);
            out.iterations += stats.iterations;
            out.solves += 1;
            out.relative_residual = out.relative_residual.max(stats.relative_residual);
        }
        depth *= DEPTH_STEP;
    }
    out.w = w;
    out
}

/// The cells below `depth` that need a nested solve: those more than [`REACH`] steps through
/// free cells from any cell at or above it.
///
/// A cell next to a wall has a small `W` however close it is to the target, because `W = 0` on
/// the wall; but so has the solve's error, which is harmonic with the same zero there, so such a
/// cell is known to the relative precision of the cells a few steps away from the wall.
/// Counting them as deep would make the nested solves cover every wall of the world. The
/// distance is counted through free cells: across a wall, a cell's neighbourhood says nothing
/// about it. (In a corridor one cell wide, the narrowest there is, `W` falls by 2 − √3 per
/// cell, so `REACH` steps lose at most a factor 3e-5 of relative precision.)
pub fn deep_cells(grid: &Grid, unknown: &[bool], w: &[f64], depth: f64) -> Vec<bool> {
    let below = |k: usize| unknown[k] && w[k] < depth;
    let mut deep: Vec<bool> = (0..grid.len()).map(below).collect();
    // Breadth-first from the cells below the depth that touch one above it.
    let mut front = Vec::new();
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let k = grid.index(i, j);
            if deep[k]
                && grid
                    .neighbours(i, j)
                    .any(|(a, b)| unknown[grid.index(a, b)] && !below(grid.index(a, b)))
            {
                front.push((i, j));
            }
        }
    }
    for &(i, j) in &front {
        deep[grid.index(i, j)] = false;
    }
    for _ in 1..REACH {
        let mut next = Vec::new();
        for &(i, j) in &front {
            for (a, b) in grid.neighbours(i, j) {
                let k = grid.index(a, b);
                if deep[k] {
                    deep[k] = false;
                    next.push((a, b));
                }
            }
        }
        front = next;
    }
    deep
}

/// The connected regions (4-neighbours) of the `deep` cells, each as a list of cell indices.
fn regions(grid: &Grid, deep: &[bool]) -> Vec<Vec<usize>> {
    let mut seen = vec![false; grid.len()];
    let mut regions = Vec::new();
    for start in 0..grid.len() {
        if !deep[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        let mut cells = vec![start];
        let mut next = 0;
        while next < cells.len() {
            let k = cells[next];
            next += 1;
            for (a, b) in grid.neighbours(k % grid.nx, k / grid.nx) {
                let m = grid.index(a, b);
                if deep[m] && !seen[m] {
                    seen[m] = true;
                    cells.push(m);
                }
            }
        }
        regions.push(cells);
    }
    regions
}

/// Re-solves `W` on one connected region of deep cells, scaled by `1/depth`, with the cells
/// around it as Dirichlet values. Works on the region's bounding box plus a one-cell margin
/// (which holds their fixed neighbours), so small regions and deeper levels cost little. Other
/// regions inside the box are not its neighbours, so their values do not matter.
fn solve_deep(
    grid: &Grid,
    cells: &[usize],
    w: &mut [f64],
    depth: f64,
    tolerance: f64,
) -> multigrid::Stats {
    let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
    for &k in cells {
        let (i, j) = (k % grid.nx, k / grid.nx);
        lo = [lo[0].min(i), lo[1].min(j)];
        hi = [hi[0].max(i), hi[1].max(j)];
    }
    let (i0, j0) = (lo[0].saturating_sub(1), lo[1].saturating_sub(1));
    let (i1, j1) = ((hi[0] + 1).min(grid.nx - 1), (hi[1] + 1).min(grid.ny - 1));
    let sub = Grid {
        nx: i1 - i0 + 1,
        ny: j1 - j0 + 1,
        cell: grid.cell,
        origin: grid.center(i0, j0).map(|c| c - 0.5 * grid.cell),
    };
    let mut unknown = vec![false; sub.len()];
    for &k in cells {
        unknown[sub.index(k % grid.nx - i0, k / grid.nx - j0)] = true;
    }
    let mut scaled = vec![0.0; sub.len()];
    for j in 0..sub.ny {
        let row = grid.index(i0, j0 + j);
        for (i, v) in scaled[j * sub.nx..(j + 1) * sub.nx].iter_mut().enumerate() {
            *v = w[row + i].max(0.0) / depth;
        }
    }
    let stats = multigrid::solve(&sub, &unknown, &mut scaled, tolerance, MAX_ITERATIONS);
    for &k in cells {
        w[k] = scaled[sub.index(k % grid.nx - i0, k / grid.nx - j0)] * depth;
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::laplace::reachable_from;

    /// Cells below the depth next to a shallow cell are resolved (a wall's neighbours), cells
    /// more than `REACH` steps in are deep, and reach does not cross a wall.
    #[test]
    fn deep_cells_lie_beyond_reach_of_the_shallow_ones() {
        let grid = Grid::covering([3.0, 0.1], 0.1);
        assert_eq!((grid.nx, grid.ny), (30, 1));
        let mut unknown = vec![true; grid.len()];
        unknown[20] = false; // a wall
        // Shallow cells 0..5, then tiny values along the row, and behind the wall.
        let w: Vec<f64> = (0..30).map(|i| if i < 5 { 0.5 } else { 1e-9 }).collect();
        let deep = deep_cells(&grid, &unknown, &w, 1e-6);
        for (i, deep) in deep.iter().enumerate() {
            assert_eq!(*deep, i >= 5 + REACH && i != 20, "cell {i}");
        }
        // Two separate regions: either side of the wall.
        let regions = regions(&grid, &deep);
        assert_eq!(regions.len(), 2);
        assert_eq!(regions[0], (5 + REACH..20).collect::<Vec<_>>());
        assert_eq!(regions[1], (21..30).collect::<Vec<_>>());
    }

    /// A long corridor: `W` decays by about e^(−π) per corridor width, to far below what one
    /// solve resolves. Every cell still gets a positive `W` that decreases along the corridor.
    #[test]
    fn deep_regions_keep_full_relative_precision() {
        let grid = Grid::covering([12.0, 0.5], 0.05);
        let blocked = vec![false; grid.len()];
        let target = (0, 5);
        let reachable = reachable_from(&grid, &blocked, target);
        let s = solve_w(&grid, &reachable, target, 1e-12, None);
        assert!(s.solves > 3, "{} solves", s.solves);
        let row: Vec<f64> = (0..grid.nx).map(|i| s.w[grid.index(i, 5)]).collect();
        assert!(
            row[grid.nx - 1] > 0.0 && row[grid.nx - 1] < 1e-25,
            "{:e}",
            row[grid.nx - 1]
        );
        for pair in row.windows(2) {
            assert!(pair[1] < pair[0], "{pair:?}");
        }
        // Away from both ends, the decay per cell is that of the slowest discrete mode: with
        // zeros one cell beyond both walls (11 cells apart), cosh κ = 2 − cos(π/11).
        let expected = (-(2.0 - (std::f64::consts::PI / 11.0).cos()).acosh()).exp();
        for i in [60, 100, 150, 200] {
            let ratio = row[i + 1] / row[i];
            assert!(
                (ratio / expected - 1.0).abs() < 1e-6,
                "cell {i}: {ratio} vs {expected}"
            );
        }
    }
}
