//! A multigrid-preconditioned conjugate gradient solver (after McAdams, Sifakis & Teran 2010)
//! for the masked Dirichlet problem `∇²u = 0` on a cell-centred grid, in f64.
//!
//! Unknowns are the cells marked `unknown`; every other cell holds a fixed (Dirichlet) value.
//! The 5-point system `4 u_k − Σ u_neighbour = 0` is symmetric positive definite. The
//! preconditioner is one V-cycle: red-black Gauss-Seidel smoothing (red then black before the
//! coarse correction, black then red after it, so the cycle is symmetric), piecewise-constant
//! prolongation, restriction by its transpose, and Galerkin coarse operators `R A P`, which stay
//! 5-point stencils and follow the mask exactly however thin its walls are. CG makes up for what
//! this simple hierarchy lacks, so the iteration count stays nearly constant as the grid grows.
//!
//! The initial values of the unknown cells are the starting guess: a warm start from a previous
//! solution makes a re-solve after a small change cheap.

use super::grid::Grid;

/// Smoothing sweeps before and after each coarse correction.
const SWEEPS: usize = 2;
/// A level with at most this many unknowns is solved by plain Gauss-Seidel.
const COARSEST: usize = 64;
/// Factor on the Galerkin coarse operators (see `Level::coarsen`).
const COARSE_SCALE: f64 = 0.5;
/// Gauss-Seidel sweeps on the coarsest level.
const COARSEST_SWEEPS: usize = 40;

/// How a solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Conjugate gradient iterations (one V-cycle each).
    pub iterations: usize,
    /// Final `‖b − A u‖ / ‖b‖` (0 when the right-hand side is 0).
    pub relative_residual: f64,
}

/// One level of the hierarchy: a padded grid (a ring of inactive cells around it) with a
/// variable-coefficient 5-point stencil.
struct Level {
    nx: usize,
    ny: usize,
    stride: usize,
    /// Diagonal (0 on inactive cells).
    diag: Vec<f64>,
    /// Coupling to the east neighbour (≥ 0; 0 when either cell is inactive).
    east: Vec<f64>,
    /// Coupling to the north neighbour.
    north: Vec<f64>,
    /// Active cells by colour ((i + j) even, odd), padded indices.
    colours: [Vec<usize>; 2],
    /// Whether this is the finest level: diagonal 4, couplings 1 to active neighbours. Since
    /// inactive cells always hold 0 in the vectors a level works on, its stencil needs no
    /// coefficient arrays (half the memory traffic, where most of the work is).
    uniform: bool,
}

impl Level {
    fn len(&self) -> usize {
        self.stride * (self.ny + 2)
    }

    fn pad(&self, i: usize, j: usize) -> usize {
        (j + 1) * self.stride + i + 1
    }

    fn unknowns(&self) -> usize {
        self.colours[0].len() + self.colours[1].len()
    }

    fn from_coefficients(
        nx: usize,
        ny: usize,
        diag: Vec<f64>,
        east: Vec<f64>,
        north: Vec<f64>,
    ) -> Self {
        let stride = nx + 2;
        let mut colours = [Vec::new(), Vec::new()];
        for j in 0..ny {
            for i in 0..nx {
                let k = (j + 1) * stride + i + 1;
                if diag[k] > 0.0 {
                    colours[(i + j) % 2].push(k);
                }
            }
        }
        Self {
            nx,
            ny,
            stride,
            diag,
            east,
            north,
            colours,
            uniform: false,
        }
    }

    /// The fine level: 4 on the diagonal of every unknown, 1 between adjacent unknowns.
    fn finest(grid: &Grid, unknown: &[bool]) -> Self {
        let (nx, ny) = (grid.nx, grid.ny);
        let stride = nx + 2;
        let n = stride * (ny + 2);
        let (mut diag, mut east, mut north) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for j in 0..ny {
            for i in 0..nx {
                if !unknown[grid.index(i, j)] {
                    continue;
                }
                let k = (j + 1) * stride + i + 1;
                diag[k] = 4.0;
                if i + 1 < nx && unknown[grid.index(i + 1, j)] {
                    east[k] = 1.0;
                }
                if j + 1 < ny && unknown[grid.index(i, j + 1)] {
                    north[k] = 1.0;
                }
            }
        }
        let mut level = Self::from_coefficients(nx, ny, diag, east, north);
        level.uniform = true;
        level
    }

    /// The Galerkin coarse level `R A P` for piecewise-constant `P` (coarse cell `(I, J)` owns
    /// fine cells `(2I..2I+1, 2J..2J+1)`), `R = Pᵀ`.
    fn coarsen(&self) -> Self {
        let (nx, ny) = (self.nx.div_ceil(2), self.ny.div_ceil(2));
        let stride = nx + 2;
        let n = stride * (ny + 2);
        let (mut diag, mut east, mut north) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for j in 0..self.ny {
            for i in 0..self.nx {
                let f = self.pad(i, j);
                if self.diag[f] == 0.0 {
                    continue;
                }
                let c = (j / 2 + 1) * stride + i / 2 + 1;
                diag[c] += self.diag[f];
                // East coupling: inside the coarse cell it lowers the diagonal (twice, for
                // both orderings of the pair); across it, it couples the coarse cells.
                if self.east[f] != 0.0 {
                    if i % 2 == 0 {
                        diag[c] -= 2.0 * self.east[f];
                    } else {
                        east[c] += self.east[f];
                    }
                }
                if self.north[f] != 0.0 {
                    if j % 2 == 0 {
                        diag[c] -= 2.0 * self.north[f];
                    } else {
                        north[c] += self.north[f];
                    }
                }
            }
        }
        // Piecewise-constant transfers make R A P twice the rediscretized 2h stencil, which
        // under-corrects smooth errors; halving it restores the coarse correction's size.
        for v in diag
            .iter_mut()
            .chain(east.iter_mut())
            .chain(north.iter_mut())
        {
            *v *= COARSE_SCALE;
        }
        Self::from_coefficients(nx, ny, diag, east, north)
    }

    /// `y = A x` on the active cells.
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let s = self.stride;
        if self.uniform {
            for cells in &self.colours {
                for &k in cells {
                    y[k] = 4.0 * x[k] - x[k + 1] - x[k - 1] - x[k + s] - x[k - s];
                }
            }
            return;
        }
        for cells in &self.colours {
            for &k in cells {
                y[k] = self.diag[k] * x[k]
                    - self.east[k] * x[k + 1]
                    - self.east[k - 1] * x[k - 1]
                    - self.north[k] * x[k + s]
                    - self.north[k - s] * x[k - s];
            }
        }
    }

    /// One Gauss-Seidel sweep over the cells of colour `c` for `A x = b`.
    fn relax(&self, c: usize, x: &mut [f64], b: &[f64]) {
        let s = self.stride;
        if self.uniform {
            for &k in &self.colours[c] {
                x[k] = 0.25 * (b[k] + x[k + 1] + x[k - 1] + x[k + s] + x[k - s]);
            }
            return;
        }
        for &k in &self.colours[c] {
            let off = self.east[k] * x[k + 1]
                + self.east[k - 1] * x[k - 1]
                + self.north[k] * x[k + s]
                + self.north[k - s] * x[k - s];
            x[k] = (b[k] + off) / self.diag[k];
        }
    }
}

/// The hierarchy and its work vectors.
struct Hierarchy {
    levels: Vec<Level>,
    /// Per level: solution, right-hand side, residual.
    work: Vec<[Vec<f64>; 3]>,
}

impl Hierarchy {
    fn new(grid: &Grid, unknown: &[bool]) -> Self {
        let mut levels = vec![Level::finest(grid, unknown)];
        while levels.last().expect("one level").unknowns() > COARSEST {
            let last = levels.last().expect("one level");
            if last.nx <= 2 && last.ny <= 2 {
                break;
            }
            let coarse = last.coarsen();
            levels.push(coarse);
        }
        let work = levels
            .iter()
            .map(|l| [vec![0.0; l.len()], vec![0.0; l.len()], vec![0.0; l.len()]])
            .collect();
        Self { levels, work }
    }

    /// `z = M⁻¹ r`: one V-cycle from a zero guess, on padded fine-level vectors.
    fn precondition(&mut self, r: &[f64], z: &mut [f64]) {
        self.work[0][1].copy_from_slice(r);
        self.v_cycle(0);
        z.copy_from_slice(&self.work[0][0]);
    }

    fn v_cycle(&mut self, l: usize) {
        let level = &self.levels[l];
        let [x, b, residual] = &mut self.work[l];
        x.iter_mut().for_each(|v| *v = 0.0);
        if l + 1 == self.levels.len() {
            for _ in 0..COARSEST_SWEEPS {
                level.relax(0, x, b);
                level.relax(1, x, b);
            }
            for _ in 0..COARSEST_SWEEPS {
                level.relax(1, x, b);
                level.relax(0, x, b);
            }
            return;
        }
        for _ in 0..SWEEPS {
            level.relax(0, x, b);
            level.relax(1, x, b);
        }
        level.apply(x, residual);
        for cells in &level.colours {
            for &k in cells {
                residual[k] = b[k] - residual[k];
            }
        }
        // Restrict: each coarse cell sums its children's residuals.
        let coarse = &self.levels[l + 1];
        let (fine_work, coarse_work) = self.work.split_at_mut(l + 1);
        let coarse_b = &mut coarse_work[0][1];
        coarse_b.iter_mut().for_each(|v| *v = 0.0);
        let residual = &fine_work[l][2];
        for j in 0..level.ny {
            for i in 0..level.nx {
                let f = level.pad(i, j);
                if level.diag[f] != 0.0 {
                    coarse_b[coarse.pad(i / 2, j / 2)] += residual[f];
                }
            }
        }
        self.v_cycle(l + 1);
        // Prolong: every child gets its coarse cell's correction.
        let level = &self.levels[l];
        let coarse = &self.levels[l + 1];
        let (fine_work, coarse_work) = self.work.split_at_mut(l + 1);
        let correction = &coarse_work[0][0];
        let [x, b, _] = &mut fine_work[l];
        for j in 0..level.ny {
            for i in 0..level.nx {
                let f = level.pad(i, j);
                if level.diag[f] != 0.0 {
                    x[f] += correction[coarse.pad(i / 2, j / 2)];
                }
            }
        }
        for _ in 0..SWEEPS {
            level.relax(1, x, b);
            level.relax(0, x, b);
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solves `∇²u = 0` on the `unknown` cells of `grid`, with the other cells of `values` as
/// Dirichlet values and the unknown cells of `values` as the starting guess, until the relative
/// residual is at most `tolerance` (or `max_iterations` is reached: check the returned stats).
/// Cells outside the grid count as 0.
pub fn solve(
    grid: &Grid,
    unknown: &[bool],
    values: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> Stats {
    let mut h = Hierarchy::new(grid, unknown);
    let fine = &h.levels[0];
    let n = fine.len();
    let (nx, ny, stride) = (grid.nx, grid.ny, fine.stride);
    // Right-hand side: the fixed neighbours of every unknown; x: the starting guess.
    let mut b = vec![0.0; n];
    let mut x = vec![0.0; n];
    let value = |i: isize, j: isize| -> Option<f64> {
        (i >= 0 && j >= 0 && (i as usize) < nx && (j as usize) < ny).then(|| {
            let k = grid.index(i as usize, j as usize);
            if unknown[k] { f64::NAN } else { values[k] }
        })
    };
    for j in 0..ny {
        for i in 0..nx {
            let k = grid.index(i, j);
            if !unknown[k] {
                continue;
            }
            let p = (j + 1) * stride + i + 1;
            x[p] = values[k];
            let (i, j) = (i as isize, j as isize);
            b[p] = [(i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)]
                .iter()
                .filter_map(|&(a, c)| value(a, c))
                .filter(|v| !v.is_nan())
                .sum();
        }
    }
    let norm_b = dot(&b, &b).sqrt();
    let mut r = vec![0.0; n];
    fine.apply(&x, &mut r);
    for cells in &fine.colours {
        for &k in cells {
            r[k] = b[k] - r[k];
        }
    }
    let relative = |r: &[f64]| {
        if norm_b > 0.0 {
            dot(r, r).sqrt() / norm_b
        } else {
            dot(r, r).sqrt()
        }
    };
    let mut stats = Stats {
        iterations: 0,
        relative_residual: relative(&r),
    };
    let mut z = vec![0.0; n];
    let mut p = vec![0.0; n];
    let mut ap = vec![0.0; n];
    if stats.relative_residual > tolerance {
        h.precondition(&r, &mut z);
        p.copy_from_slice(&z);
        let mut rz = dot(&r, &z);
        while stats.iterations < max_iterations {
            stats.iterations += 1;
            h.levels[0].apply(&p, &mut ap);
            let pap = dot(&p, &ap);
            if pap.is_nan() || pap <= 0.0 {
                break;
            }
            let alpha = rz / pap;
            for ((x, r), (p, ap)) in x.iter_mut().zip(r.iter_mut()).zip(p.iter().zip(&ap)) {
                *x += alpha * p;
                *r -= alpha * ap;
            }
            stats.relative_residual = relative(&r);
            if stats.relative_residual <= tolerance {
                break;
            }
            h.precondition(&r, &mut z);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            for (p, z) in p.iter_mut().zip(&z) {
                *p = z + beta * *p;
            }
        }
    }
    for j in 0..ny {
        for i in 0..nx {
            let k = grid.index(i, j);
            if unknown[k] {
                values[k] = x[(j + 1) * stride + i + 1];
            }
        }
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::laplace::{reachable_from, solve_sor};

    /// A room with a divider and a pocket: multigrid agrees with the SOR reference.
    #[test]
    fn multigrid_matches_the_reference_solver() {
        let grid = Grid::covering([3.0, 2.0], 0.05);
        let mut blocked = vec![false; grid.len()];
        for j in 0..30 {
            blocked[grid.index(25, j)] = true;
        }
        for i in 40..50 {
            blocked[grid.index(i, 12)] = true;
        }
        let target = (50, 8);
        let reachable = reachable_from(&grid, &blocked, target);
        let reference = solve_sor(&grid, &reachable, target, 1e-13, 1_000_000).unwrap();

        let mut unknown = reachable.clone();
        unknown[grid.index(target.0, target.1)] = false;
        let mut w = vec![0.0; grid.len()];
        w[grid.index(target.0, target.1)] = 1.0;
        let stats = solve(&grid, &unknown, &mut w, 1e-13, 200);
        assert!(stats.relative_residual <= 1e-13, "{stats:?}");
        assert!(stats.iterations < 40, "{stats:?}");
        let worst = w
            .iter()
            .zip(&reference.w)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "largest difference {worst:e}");
    }

    #[test]
    fn a_warm_start_from_the_solution_needs_no_iteration() {
        let grid = Grid::covering([1.0, 1.0], 0.05);
        let mut unknown = vec![true; grid.len()];
        unknown[grid.index(10, 10)] = false;
        let mut w = vec![0.0; grid.len()];
        w[grid.index(10, 10)] = 1.0;
        solve(&grid, &unknown, &mut w, 1e-12, 100);
        let stats = solve(&grid, &unknown, &mut w, 1e-10, 100);
        assert_eq!(stats.iterations, 0, "{stats:?}");
    }
}

#[cfg(test)]
mod annulus {
    use super::*;

    /// The largest error against `ln(r/r0)/ln(R/r0)` on an annulus `r0 < r < R` at cell `h`.
    fn annulus_error(h: f64) -> f64 {
        let (r0, r1) = (0.2, 1.0);
        let grid = Grid {
            nx: (2.2 / h).round() as usize,
            ny: (2.2 / h).round() as usize,
            cell: h,
            origin: [-1.1, -1.1],
        };
        let radius = |i: usize, j: usize| {
            let [x, y] = grid.center(i, j);
            x.hypot(y)
        };
        let mut unknown = vec![false; grid.len()];
        let mut w = vec![0.0; grid.len()];
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let (k, r) = (grid.index(i, j), radius(i, j));
                // W = 1 − V: 1 on the target disc, 0 on the outer wall.
                if r <= r0 {
                    w[k] = 1.0;
                } else if r < r1 {
                    unknown[k] = true;
                }
            }
        }
        let stats = solve(&grid, &unknown, &mut w, 1e-12, 200);
        assert!(stats.relative_residual <= 1e-12, "{stats:?}");
        let mut worst = 0.0_f64;
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let (k, r) = (grid.index(i, j), radius(i, j));
                if unknown[k] {
                    let v = (r / r0).ln() / (r1 / r0).ln();
                    worst = worst.max((1.0 - w[k] - v).abs());
                }
            }
        }
        worst
    }

    /// The discrete field matches the analytic one to within the discretisation error, and
    /// that error shrinks with the cell (first order: the circles are staircases).
    #[test]
    fn the_annulus_matches_the_analytic_potential_and_converges() {
        let errors: Vec<f64> = [0.04, 0.02, 0.01]
            .iter()
            .map(|&h| annulus_error(h))
            .collect();
        println!("annulus errors at h = 0.04, 0.02, 0.01: {errors:?}");
        assert!(errors[2] < 0.03, "{errors:?}");
        assert!(
            errors[1] < 0.8 * errors[0] && errors[2] < 0.8 * errors[1],
            "{errors:?}"
        );
    }
}
