//! `W` in (x, y, θ) to any depth: the first solve, then nested solves of the cells it does not
//! resolve, each at its own scale (the plane's `nested.rs`, in a simpler form).
//!
//! A narrow passage of the configuration space (a board turning a corner) decays like a maze's
//! corridor, `e^(−π x √(1/a² + 1/b²))` along its length for a cross-section `a × b`, so `W`
//! falls below what one solve to a relative residual of 1e-12 resolves within a few metres.
//! After a solve, a cell is *resolved* when it holds at least [`DEPTH_STEP`] of the solve's
//! scale, or at least [`FLOOR`] of it within [`REACH`] steps of such a cell (a cell next to a
//! wall is small but as precise as its neighbours). The others are solved again, together, with
//! the resolved cells around them as Dirichlet values scaled so that the largest is about 1,
//! over their bounding box in x and y. There is no cut: each level solves every cell still
//! pending, so its values are exact up to the solver's tolerance at that scale, and the levels
//! cost (levels × the deep region), which for the shapes' worlds is a fraction of the first
//! solve. (The plane's solver also cuts each level into bands; a maze-sized (x, y, θ) grid
//! would need that too.)

use super::super::scaled::{ScaledW, exponent_of};
use super::multigrid::{self, Dims, Lattice};

/// A cell is resolved by a solve when it holds at least this fraction of the solve's scale.
pub const DEPTH_STEP: f64 = 1e-6;
/// Steps through free cells from a cell above [`DEPTH_STEP`] within which a smaller cell still
/// counts as resolved.
pub const REACH: usize = 6;
/// No cell below this fraction of its solve's scale counts as resolved.
pub const FLOOR: f64 = 1e-11;
/// CG iterations allowed per solve.
pub const MAX_ITERATIONS: usize = 500;
/// Nested levels allowed (each resolves at least six more decades).
pub const MAX_LEVELS: usize = 400;

/// How the solves went.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DepthStats {
    /// Solves: the first and one per nested level.
    pub solves: usize,
    /// CG iterations over all solves.
    pub iterations: usize,
    /// The worst final relative residual.
    pub relative_residual: f64,
}

/// Solves for `W` on the `unknown` cells of `lattice` with `W = 1` on the `target` cells and
/// 0 elsewhere, each solve to `tolerance`, at any depth.
pub fn solve_w(
    lattice: &Lattice,
    unknown: &[bool],
    target: &[usize],
    tolerance: f64,
) -> (ScaledW, DepthStats) {
    let dims = lattice.dims;
    let mut w = vec![0.0; dims.len()];
    for &t in target {
        w[t] = 1.0;
    }
    let first = multigrid::solve(lattice, unknown, &mut w, tolerance, MAX_ITERATIONS);
    let mut stats = DepthStats {
        solves: 1,
        iterations: first.iterations,
        relative_residual: first.relative_residual,
    };
    let mut values = ScaledW::from_plain(w);
    // The cells of the last solve, and its scale's exponent.
    let mut last: Vec<bool> = unknown.to_vec();
    for _ in 0..MAX_LEVELS {
        let pending = unresolved(lattice, &last, &values);
        if !pending.iter().any(|p| *p) {
            break;
        }
        let Some(level) = solve_level(lattice, &pending, &mut values, tolerance) else {
            break;
        };
        stats.solves += 1;
        stats.iterations += level.iterations;
        stats.relative_residual = stats.relative_residual.max(level.relative_residual);
        last = pending;
    }
    (values, stats)
}

/// The cells of the last solve (`last`) that it did not resolve (see the module).
fn unresolved(lattice: &Lattice, last: &[bool], values: &ScaledW) -> Vec<bool> {
    let dims = lattice.dims;
    let value = |c: usize| values.mantissa[c];
    let mut pending: Vec<bool> = (0..dims.len())
        .map(|c| last[c] && value(c) < DEPTH_STEP)
        .collect();
    // Breadth-first, REACH steps through the last solve's cells, from the resolved ones.
    let mut front: Vec<usize> = (0..dims.len())
        .filter(|&c| last[c] && !pending[c])
        .collect();
    for _ in 0..REACH {
        let mut next = Vec::new();
        for &c in &front {
            let (i, j, k) = coordinates(dims, c);
            for (m, _) in lattice.neighbours((i, j, k)) {
                if pending[m] && value(m) >= FLOOR {
                    pending[m] = false;
                    next.push(m);
                }
            }
        }
        front = next;
    }
    pending
}

/// `(i, j, k)` of cell `c`.
pub fn coordinates(dims: Dims, c: usize) -> (usize, usize, usize) {
    (
        c % dims.nx,
        (c / dims.nx) % dims.ny,
        c / (dims.nx * dims.ny),
    )
}

/// Solves the `pending` cells with the others as Dirichlet values, at the scale of the largest
/// value next to them, over their bounding box along the bounded x and y (the whole of a
/// periodic axis); stores them at that scale. `None` when no pending cell has a non-zero
/// neighbour (nothing flows in: they stay 0).
fn solve_level(
    lattice: &Lattice,
    pending: &[bool],
    values: &mut ScaledW,
    tolerance: f64,
) -> Option<multigrid::Stats> {
    let dims = lattice.dims;
    let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
    let mut scale: Option<(f64, i32)> = None;
    for c in (0..dims.len()).filter(|&c| pending[c]) {
        let (i, j, k) = coordinates(dims, c);
        (lo, hi) = ([lo[0].min(i), lo[1].min(j)], [hi[0].max(i), hi[1].max(j)]);
        for (m, _) in lattice.neighbours((i, j, k)) {
            if !pending[m] && values.mantissa[m] > 0.0 {
                let e = values.exponent[m] + exponent_of(values.mantissa[m]);
                if scale.is_none_or(|(_, best)| e > best) {
                    scale = Some((values.mantissa[m], e));
                }
            }
        }
    }
    let (_, e) = scale?;
    // The box around the pending cells, one cell wider for their Dirichlet neighbours.
    let (mut i0, mut j0) = (lo[0].saturating_sub(1), lo[1].saturating_sub(1));
    let (mut i1, mut j1) = ((hi[0] + 1).min(dims.nx - 1), (hi[1] + 1).min(dims.ny - 1));
    if lattice.periodic[0] {
        (i0, i1) = (0, dims.nx - 1);
    }
    if lattice.periodic[1] {
        (j0, j1) = (0, dims.ny - 1);
    }
    let sub = Dims {
        nx: i1 - i0 + 1,
        ny: j1 - j0 + 1,
        nt: dims.nt,
    };
    let outer = |i: usize, j: usize, k: usize| dims.index(i0 + i, j0 + j, k);
    let mut unknown = vec![false; sub.len()];
    let mut w = vec![0.0; sub.len()];
    for k in 0..sub.nt {
        for j in 0..sub.ny {
            for i in 0..sub.nx {
                let (c, s) = (outer(i, j, k), sub.index(i, j, k));
                if pending[c] {
                    unknown[s] = true;
                }
                // The last solve's estimate of a pending cell is the starting guess.
                if values.mantissa[c] > 0.0 {
                    w[s] = values.at_scale(c, e);
                }
            }
        }
    }
    let sub_lattice = Lattice {
        dims: sub,
        ..*lattice
    };
    let stats = multigrid::solve(&sub_lattice, &unknown, &mut w, tolerance, MAX_ITERATIONS);
    for k in 0..sub.nt {
        for j in 0..sub.ny {
            for i in 0..sub.nx {
                let (c, s) = (outer(i, j, k), sub.index(i, j, k));
                if unknown[s] {
                    values.mantissa[c] = w[s];
                    values.exponent[c] = e;
                }
            }
        }
    }
    Some(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A passage along x, 3 cells across in y, at every heading: `W` falls far below what one
    /// solve resolves (to 1e-100 and less), and every cell keeps a positive value that decreases
    /// along it at the rate of the slowest discrete mode.
    #[test]
    fn a_long_passage_keeps_full_relative_precision() {
        let dims = Dims {
            nx: 400,
            ny: 5,
            nt: 8,
        };
        let mut unknown = vec![false; dims.len()];
        let mut target = Vec::new();
        for k in 0..dims.nt {
            for j in 1..4 {
                for i in 0..dims.nx {
                    if i == 0 {
                        target.push(dims.index(i, j, k));
                    } else {
                        unknown[dims.index(i, j, k)] = true;
                    }
                }
            }
        }
        let (w, stats) = solve_w(&Lattice::pose(dims, 0.5), &unknown, &target, 1e-12);
        assert!(stats.solves > 3, "{stats:?}");
        let row: Vec<f64> = (0..dims.nx).map(|i| w.log2(dims.index(i, 2, 3))).collect();
        // Decay per cell of the slowest mode across 3 cells (zeros one beyond): cosh κ = 2 −
        // cos(π/4); the field is uniform in θ, so θ adds nothing.
        let kappa = (2.0 - (std::f64::consts::PI / 4.0).cos()).acosh();
        for i in [50, 150, 250, 350] {
            let rate = (row[i] - row[i + 1]) * std::f64::consts::LN_2;
            assert!(
                (rate / kappa - 1.0).abs() < 1e-6,
                "cell {i}: {rate} vs {kappa}"
            );
        }
        assert!(
            row[dims.nx - 1] * std::f64::consts::LOG10_2 < -100.0,
            "{}",
            row[dims.nx - 1]
        );
    }
}
