//! The production solve of `W = 1 − V`: multigrid-preconditioned CG ([`multigrid`]), then
//! nested, rescaled re-solves of the regions where `W` is tiny.
//!
//! A solve to a relative residual of 1e-12 gives `W` to about 1e-13 absolute. Behind a few
//! turns `W` is far smaller than that (1e-17 in a 16 m × 10 m world with three shelves, 1e-60 in
//! a maze), so the first solution there is noise, and the guidance direction with it. The deep
//! region `D = {W < τ}` (τ = 1e-6) is therefore solved again on its own: its boundary values —
//! the neighbouring cells, where `W ≥ τ` is known to full relative precision — are divided by τ,
//! the problem is solved on `D` alone, and the result multiplied by τ. By the maximum principle
//! a relative error ε in the boundary values is at most ε relative everywhere inside, so each
//! level keeps relative precision and reaches six orders of magnitude deeper. This repeats until
//! no cell is below the current depth: the field never goes flat where a path exists.

use super::grid::Grid;
use super::multigrid;

/// The depth gained by each nested solve.
pub const DEPTH_STEP: f64 = 1e-6;
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
        let deep: Vec<bool> = unknown
            .iter()
            .zip(&w)
            .map(|(u, w)| *u && *w < depth)
            .collect();
        let Some(stats) = solve_deep(grid, &deep, &mut w, depth, tolerance) else {
            break;
        };
        out.iterations += stats.iterations;
        out.solves += 1;
        out.relative_residual = out.relative_residual.max(stats.relative_residual);
        depth *= DEPTH_STEP;
    }
    out.w = w;
    out
}

/// Re-solves `W` on the `deep` cells alone, scaled by `1/depth`, with the other cells as
/// Dirichlet values. Works on the bounding box of the deep cells plus a one-cell margin (which
/// holds their fixed neighbours), so deeper levels cost less. `None` when no cell is deep.
fn solve_deep(
    grid: &Grid,
    deep: &[bool],
    w: &mut [f64],
    depth: f64,
    tolerance: f64,
) -> Option<multigrid::Stats> {
    let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            if deep[grid.index(i, j)] {
                lo = [lo[0].min(i), lo[1].min(j)];
                hi = [hi[0].max(i), hi[1].max(j)];
            }
        }
    }
    if lo[0] == usize::MAX {
        return None;
    }
    let (i0, j0) = (lo[0].saturating_sub(1), lo[1].saturating_sub(1));
    let (i1, j1) = ((hi[0] + 1).min(grid.nx - 1), (hi[1] + 1).min(grid.ny - 1));
    let sub = Grid {
        nx: i1 - i0 + 1,
        ny: j1 - j0 + 1,
        cell: grid.cell,
        origin: grid.center(i0, j0).map(|c| c - 0.5 * grid.cell),
    };
    let mut sub_deep = vec![false; sub.len()];
    let mut scaled = vec![0.0; sub.len()];
    for j in 0..sub.ny {
        for i in 0..sub.nx {
            let (k, s) = (grid.index(i0 + i, j0 + j), sub.index(i, j));
            sub_deep[s] = deep[k];
            scaled[s] = w[k].max(0.0) / depth;
        }
    }
    let stats = multigrid::solve(&sub, &sub_deep, &mut scaled, tolerance, MAX_ITERATIONS);
    for j in 0..sub.ny {
        for i in 0..sub.nx {
            let s = sub.index(i, j);
            if sub_deep[s] {
                w[grid.index(i0 + i, j0 + j)] = scaled[s] * depth;
            }
        }
    }
    Some(stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::laplace::reachable_from;

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
