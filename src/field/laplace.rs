//! The reference Laplace solver (red-black SOR) and the flood fill that finds the free cells
//! connected to the target. The production solver is [`super::multigrid`] with
//! [`super::harmonic`]; this one is simple enough to trust, and the tests compare with it.
//!
//! We solve for `W = 1 - V` rather than `V`: `W = 0` on blocked cells and outside the grid,
//! `W = 1` at the target cell, `∇²W = 0` elsewhere. Far from the target `V` is within 1e-6 of 1
//! in an ordinary room and within 1e-16 of it behind a few turns, where an f64 `V` rounds to
//! exactly 1 and loses its gradient; `W` keeps full relative precision there (design page,
//! "The field must be solved in f64"). Since `∇V = -∇W`, nothing else changes.
//!
//! The method is red-black successive over-relaxation with a relative, per-cell stopping rule:
//! simple and correct, with a cost that grows like N^1.5. Free cells that cannot reach the
//! target (enclosed pockets) are not solved; they are reported as unreachable.
//!
//! The per-cell rule has a floor: round-off near the target (where `W ~ 1`) keeps exciting the
//! smooth error modes at about 1e-19 absolute, which is a large relative change in a far corner
//! where `W ~ 1e-12`. When the largest relative change stops falling ([`STALL_SWEEPS`] sweeps
//! without halving) the solver stops there, and accepts the result if that floor is below
//! [`STALL_LIMIT`] — the guidance uses only the gradient's direction, which such an error does
//! not change. [`Solution::stalled`] says when this happened.

use super::grid::Grid;

/// The solved field on the grid.
#[derive(Debug, Clone)]
pub struct Solution {
    /// `W = 1 - V` per cell (0 on blocked and unreachable cells, 1 at the target).
    pub w: Vec<f64>,
    /// Whether each cell is free and connected to the target cell.
    pub reachable: Vec<bool>,
    /// SOR sweeps performed.
    pub iterations: usize,
    /// The largest relative change of a cell in the last sweep, `|ΔW| / W`.
    pub relative_change: f64,
    /// Whether the solver stopped at its round-off floor rather than at the tolerance.
    pub stalled: bool,
}

/// Sweeps without the largest relative change halving after which the solve has stalled.
pub const STALL_SWEEPS: usize = 2000;

/// The largest relative change at which a stalled solve is still accepted.
pub const STALL_LIMIT: f64 = 1e-6;

/// Why the solver gave up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// The iteration limit was reached before the tolerance.
    #[error("no convergence after {iterations} sweeps (relative change {relative_change:e})")]
    NoConvergence {
        /// Sweeps performed.
        iterations: usize,
        /// Largest relative change in the last sweep.
        relative_change: f64,
    },
}

/// Cells reachable from `start` through free cells (4-neighbours).
///
/// Run by run along the rows: a run of free cells is marked from wall to wall at once, and
/// each run of free, unmarked cells above or below it is queued once, by its first cell. A
/// cell is read a few times and no cell is divided into its row and column, where a search
/// cell by cell looked up every cell's four neighbours (a third of the time of `nadf field`'s
/// mask at 1025², 7 of 20 ms). The queue holds a few runs per row, not cells.
pub fn reachable_from(grid: &Grid, blocked: &[bool], start: (usize, usize)) -> Vec<bool> {
    let nx = grid.nx;
    let mut seen = vec![false; grid.len()];
    if blocked[grid.index(start.0, start.1)] {
        return seen;
    }
    let free = |k: usize, seen: &[bool]| !blocked[k] && !seen[k];
    // Runs to fill: a free, unmarked cell of each, as (column, row).
    let mut runs = vec![start];
    while let Some((i, j)) = runs.pop() {
        let row = j * nx;
        if !free(row + i, &seen) {
            continue;
        }
        // The run through (i, j): columns lo..hi.
        let mut lo = i;
        while lo > 0 && free(row + lo - 1, &seen) {
            lo -= 1;
        }
        let mut hi = i + 1;
        while hi < nx && free(row + hi, &seen) {
            hi += 1;
        }
        seen[row + lo..row + hi].fill(true);
        // Each run of free, unmarked cells next to it in the rows below and above.
        let neighbours = [j.checked_sub(1), (j + 1 < grid.ny).then_some(j + 1)];
        for b in neighbours.into_iter().flatten() {
            let next = b * nx;
            let mut a = lo;
            while a < hi {
                if free(next + a, &seen) {
                    runs.push((a, b));
                    while a < hi && free(next + a, &seen) {
                        a += 1;
                    }
                } else {
                    a += 1;
                }
            }
        }
    }
    seen
}

/// Solves `∇²W = 0` on the `reachable` cells (those `reachable_from` the free `target` cell)
/// with `W = 1` at `target` and `W = 0` everywhere else, until no cell changes by more than
/// `tolerance` relative to its value in one sweep.
pub fn solve_sor(
    grid: &Grid,
    reachable: &[bool],
    target: (usize, usize),
    tolerance: f64,
    max_iterations: usize,
) -> Result<Solution, SolveError> {
    // A padded copy (one ring of zero cells) so the 5-point stencil needs no bounds checks.
    let stride = grid.nx + 2;
    let pad = |i: usize, j: usize| (j + 1) * stride + i + 1;
    let mut w = vec![0.0_f64; stride * (grid.ny + 2)];
    w[pad(target.0, target.1)] = 1.0;
    let mut colours: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            if reachable[grid.index(i, j)] && (i, j) != target {
                colours[(i + j) % 2].push(pad(i, j));
            }
        }
    }

    // The optimal over-relaxation factor for a square of side max(nx, ny).
    let n = grid.nx.max(grid.ny) as f64;
    let omega = 2.0 / (1.0 + (std::f64::consts::PI / n).sin());

    let mut iterations = 0;
    let mut relative_change = f64::INFINITY;
    let (mut best, mut best_at) = (f64::INFINITY, 0);
    let mut stalled = false;
    while iterations < max_iterations {
        iterations += 1;
        relative_change = 0.0_f64;
        for cells in &colours {
            for &k in cells {
                let gauss_seidel = 0.25 * (w[k - 1] + w[k + 1] + w[k - stride] + w[k + stride]);
                let delta = omega * (gauss_seidel - w[k]);
                w[k] += delta;
                let change = if w[k] > 0.0 {
                    delta.abs() / w[k]
                } else {
                    f64::INFINITY
                };
                relative_change = relative_change.max(change);
            }
        }
        if relative_change <= tolerance {
            break;
        }
        if relative_change < 0.5 * best {
            (best, best_at) = (relative_change, iterations);
        } else if iterations - best_at >= STALL_SWEEPS {
            stalled = true;
            break;
        }
    }
    if relative_change > tolerance && !(stalled && relative_change <= STALL_LIMIT) {
        return Err(SolveError::NoConvergence {
            iterations,
            relative_change,
        });
    }
    let mut out = vec![0.0; grid.len()];
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            out[grid.index(i, j)] = w[pad(i, j)];
        }
    }
    Ok(Solution {
        w: out,
        reachable: reachable.to_vec(),
        iterations,
        relative_change,
        stalled: relative_change > tolerance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The discrete maximum principle: every reachable cell is strictly between 0 and 1, and
    /// every cell is the mean of its four neighbours to within the tolerance.
    #[test]
    fn solution_is_discrete_harmonic_and_bounded() {
        let grid = Grid::covering([3.0, 2.0], 0.1);
        let mut blocked = vec![false; grid.len()];
        for j in 0..15 {
            blocked[grid.index(12, j)] = true; // a divider with a gap at the top
        }
        let reachable = reachable_from(&grid, &blocked, (25, 5));
        let s = solve_sor(&grid, &reachable, (25, 5), 1e-12, 100_000).unwrap();
        assert!(!s.stalled);
        let at = |i: isize, j: isize| {
            if i < 0 || j < 0 || i >= grid.nx as isize || j >= grid.ny as isize {
                0.0
            } else {
                s.w[grid.index(i as usize, j as usize)]
            }
        };
        for j in 0..grid.ny as isize {
            for i in 0..grid.nx as isize {
                let k = grid.index(i as usize, j as usize);
                if !s.reachable[k] || (i, j) == (25, 5) {
                    continue;
                }
                let w = at(i, j);
                assert!(w > 0.0 && w < 1.0);
                let mean = 0.25 * (at(i - 1, j) + at(i + 1, j) + at(i, j - 1) + at(i, j + 1));
                assert!((w - mean).abs() <= 1e-9 * w, "cell {i},{j}: {w} vs {mean}");
            }
        }
    }

    #[test]
    fn enclosed_cells_are_unreachable_and_zero() {
        let grid = Grid::covering([1.0, 1.0], 0.1);
        let mut blocked = vec![false; grid.len()];
        // A ring of blocked cells around (2, 2).
        for (i, j) in [
            (1, 1),
            (2, 1),
            (3, 1),
            (1, 2),
            (3, 2),
            (1, 3),
            (2, 3),
            (3, 3),
        ] {
            blocked[grid.index(i, j)] = true;
        }
        let reachable = reachable_from(&grid, &blocked, (7, 7));
        let s = solve_sor(&grid, &reachable, (7, 7), 1e-10, 100_000).unwrap();
        assert!(!s.reachable[grid.index(2, 2)]);
        assert_eq!(s.w[grid.index(2, 2)], 0.0);
        assert!(s.reachable[grid.index(0, 0)]);
        assert!(s.w[grid.index(0, 0)] > 0.0);
    }

    /// The cells a search cell by cell reaches, on random masks of every density (and the
    /// grid's edges, a start in a pocket, a start next to the edge).
    #[test]
    fn runs_reach_the_cells_a_search_cell_by_cell_reaches() {
        let by_cells = |grid: &Grid, blocked: &[bool], s: (usize, usize)| {
            let mut seen = vec![false; grid.len()];
            let s = grid.index(s.0, s.1);
            let mut stack = Vec::new();
            if !blocked[s] {
                seen[s] = true;
                stack.push(s);
            }
            while let Some(k) = stack.pop() {
                for m in grid.neighbours_of(k) {
                    if !blocked[m] && !seen[m] {
                        seen[m] = true;
                        stack.push(m);
                    }
                }
            }
            seen
        };
        let mut state = 12345u64;
        let mut random = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as f64 / (1u64 << 31) as f64
        };
        for density in [0.0, 0.2, 0.35, 0.45, 0.6] {
            for (nx, ny) in [(1, 1), (1, 9), (9, 1), (37, 23)] {
                let grid = Grid::covering([nx as f64, ny as f64], 1.0);
                let blocked: Vec<bool> = (0..grid.len()).map(|_| random() < density).collect();
                for s in [(0, 0), (nx / 2, ny / 2), (nx - 1, ny - 1)] {
                    assert_eq!(
                        reachable_from(&grid, &blocked, s),
                        by_cells(&grid, &blocked, s),
                        "{nx} x {ny}, density {density}, start {s:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_blocked_start_reaches_nothing() {
        let grid = Grid::covering([1.0, 1.0], 0.1);
        let mut blocked = vec![false; grid.len()];
        blocked[grid.index(5, 5)] = true;
        assert!(reachable_from(&grid, &blocked, (5, 5)).iter().all(|r| !r));
        assert_eq!(
            reachable_from(&grid, &blocked, (4, 5))
                .iter()
                .filter(|r| **r)
                .count(),
            99
        );
    }
}
