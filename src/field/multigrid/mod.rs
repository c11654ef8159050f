//! A multigrid-preconditioned conjugate gradient solver (after McAdams, Sifakis & Teran 2010)
//! for the masked Dirichlet problem `∇²u = 0` on a cell-centred grid.
//!
//! Unknowns are the cells marked `unknown`; every other cell holds a fixed (Dirichlet) value.
//! The 5-point system `4 u_k − Σ u_neighbour = 0` is symmetric positive definite, and conjugate
//! gradients solve it in f64.
//!
//! The preconditioner is one W-cycle (or one V-cycle, see below). Its hierarchy aggregates 2 × 2
//! cells with piecewise-constant prolongation, restriction by its transpose and Galerkin coarse
//! operators `R A P`. These stay 5-point stencils and follow the mask exactly, however thin its
//! walls are: two regions that a wall separates are never coupled on a coarse level. Each level
//! smooths with red-black Gauss-Seidel (red then black before the coarse correction, black then red
//! after it; twice on the W-cycle's finest level, once elsewhere: see `Cycle::sweeps` in
//! `cycle.rs`) and the coarsest level is solved exactly (Cholesky), so the cycle is a symmetric
//! operator, as CG needs. A V-cycle of this hierarchy loses a little on every level (26 CG
//! iterations at 1024², growing with the grid); visiting each coarse level twice (the W-cycle)
//! keeps the count flat (11 at 256² and at 2048², measured with two sweeps on every level) for
//! about 1.5× the work per cycle. A caller may ask for the V-cycle ([`solve_with`]): the windows
//! of local replanning do (see `window.rs`).
//!
//! The cycle runs in f32. It only has to approximate `A⁻¹`: its rounding (1e-7) is far below
//! its approximation error, CG in f64 corrects both, and f32 halves the memory traffic, which is
//! what a cycle's time is made of. The residual is scaled to unit size before it is rounded, and
//! every value the cycle makes below 1e-30 is rounded to 0 (`kernels::FLUSH`), so no value it
//! sees comes near f32's range limits: a field decaying through a maze would otherwise fill the
//! deep rooms with subnormals, which the processor computes on a slow path.
//!
//! The parts: `rows.rs` (where a problem's cells are stored), `level.rs` (a level's ragged
//! layout and stencil, and Galerkin coarsening), `smoother.rs` (red-black Gauss-Seidel as a
//! wavefront, the residual), `cycle.rs` (the hierarchy and the W-cycle, the exact coarsest
//! solve), `krylov.rs` (the CG driver), `kernels.rs` (the AVX2 trampoline and its inlining
//! rule, the 5-point neighbourhood, reductions).
//!
//! Where the time goes, and what is done about it: each level's smoothing passes and its
//! residual restriction (or its prolongation and smoothing passes) run as one wavefront over the
//! rows, so a level is read from memory once per half-cycle rather than once per pass; every
//! row loop is straight-line code that the compiler vectorizes, built for AVX2 when the
//! processor has it (`wide`), and goes over only the row's span of active cells, and each level
//! stores only those spans and their neighbours, row after row (`level.rs`), as a nested part's
//! problem stores only its cells and theirs (`rows.rs`): a part's bounding box can be five
//! times its cells, and memory first touched costs more than the arithmetic on it; a cycle
//! starts from zero without clearing its vectors (its first pass reads nothing of them), and it
//! sums `z · r` in its last pass, while each row is still in cache; and each CG iteration makes
//! two passes over its vectors besides the cycle (`Krylov`): one makes the new search
//! direction and its curvature `p · A p`, the other updates the solution and the residual. The
//! search direction is kept in f32, scaled like the cycle's output it is made from, and `A p`
//! is recomputed from it rather than stored: the solution and the residual, in f64, take the
//! same exact steps, so rounding the direction only changes which direction CG takes (by 1e-7,
//! as the f32 cycle already does) and never lets the residual drift from `b − A x`.
//!
//! A level at least 256 rows tall (the fine levels of a whole map's field) is swept by two
//! threads: the rows below its middle and those above it at once, each pass stopping short of
//! the middle by one row more than the last, then the rows between (`Part` in `smoother.rs`).
//! Every cell gets the update one sweep gives it, and the sums are taken in row order, so the
//! solution does not depend on the threads. The windows of local replanning are smaller: they
//! are solved one per thread.
//!
//! The initial values of the unknown cells are the starting guess: a warm start from a previous
//! solution makes a re-solve after a small change cheaper, though not by much, since CG still
//! has to take the residual the change leaves (4–6e-3 of the first one for a wall moved by a
//! cell) down to the tolerance at the same rate.

// The row loops index several slices of one length with one counter: the form the compiler
// vectorizes without bounds checks, and the one that reads like the stencil it computes.
#![allow(clippy::needless_range_loop)]

mod cycle;
pub(super) mod dense;
pub(super) mod kernels;
mod krylov;
mod level;
mod rows;
mod smoother;

pub use cycle::Cycle;
pub use kernels::set_portable;
pub use rows::Rows;

use super::grid::Grid;
use super::join_if;
use cycle::{Coarse, Hierarchy, split_at};
use krylov::Krylov;
use level::Level;

/// How a solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Conjugate gradient iterations (one cycle each), over the restarts too.
    pub iterations: usize,
    /// Final `‖b − A u‖ / ‖b‖` (0 when the right-hand side is 0).
    pub relative_residual: f64,
}

/// Solves `∇²u = 0` on the `unknown` cells of `grid`, with the other cells of `values` as
/// Dirichlet values and the unknown cells of `values` as the starting guess, until the relative
/// residual is at most `tolerance` (or `max_iterations` is reached: check the returned stats).
/// Cells outside the grid count as 0. The residual is the true one, recomputed from the
/// solution (CG is restarted from it when its own recurrence drifted, see `RESTARTS`).
pub fn solve(
    grid: &Grid,
    unknown: &[bool],
    values: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> Stats {
    solve_with(Cycle::W, grid, unknown, values, tolerance, max_iterations)
}

/// [`solve`] with `cycle` as the preconditioner ([`solve`] takes [`Cycle::W`]).
pub fn solve_with(
    cycle: Cycle,
    grid: &Grid,
    unknown: &[bool],
    values: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> Stats {
    match Crop::of(grid, unknown) {
        Some(crop) => crop.solve(cycle, (grid, unknown, values), tolerance, max_iterations),
        None => {
            let problem = (&Rows::whole(grid.nx, grid.ny), unknown, values);
            solve_all(cycle, problem, tolerance, max_iterations)
        }
    }
}

/// [`solve`] on the cells that `rows` stores (the others are Dirichlet cells at 0), with
/// `unknown` and `values` in its order: a nested part of a deep field, whose bounding box is
/// mostly empty.
pub fn solve_rows(
    rows: &Rows,
    unknown: &[bool],
    values: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> Stats {
    solve_all(Cycle::W, (rows, unknown, values), tolerance, max_iterations)
}

/// [`solve_with`] over every cell `rows` stores.
fn solve_all(
    cycle: Cycle,
    (rows, unknown, values): (&Rows, &[bool], &mut [f64]),
    tolerance: f64,
    max_iterations: usize,
) -> Stats {
    // The coarse levels and CG's start each fault in fresh memory (most of their time on a
    // large grid): on a tall one, the two threads build them at once.
    let fine = Level::finest(rows, unknown);
    let (coarse, mut cg) = join_if(
        split_at(&fine).is_some(),
        || Coarse::of(&fine),
        || Krylov::start(&fine, rows, unknown, values),
    );
    let mut hierarchy = Hierarchy::on(fine, coarse, cycle);
    let mut stats = Stats {
        iterations: 0,
        relative_residual: f64::NAN,
    };
    // CG carries its residual by recurrence (`r −= α A p`), and each step rounds it at the size
    // of the first residual: from a guess far from the solution (a window's field of the walls
    // where the others close the way: a first residual up to 1e9 times `b`) the recurrence
    // reaches the tolerance while `b − A x` is still orders of magnitude above it. So the
    // residual is recomputed from the solution, and CG restarted from it while that is above
    // the tolerance (a NaN or an exhausted budget ends the solve as it is).
    for restart in 0..=RESTARTS {
        let left = max_iterations - stats.iterations;
        let run = cg.iterate(&mut hierarchy, tolerance, left);
        stats.relative_residual = run.relative_residual;
        if run.iterations == 0 {
            break;
        }
        stats.iterations += run.iterations;
        let fine = &hierarchy.levels[0];
        cg.copy_out(fine, rows, unknown, values);
        let converged = run.relative_residual <= tolerance;
        if !converged || stats.iterations >= max_iterations || restart == RESTARTS {
            break;
        }
        // The check costs one pass over the cells; a new start (its vectors) only when it
        // fails.
        stats.relative_residual = cg.true_relative(fine, rows, unknown, values);
        if stats.relative_residual <= tolerance {
            break;
        }
        cg = Krylov::start(fine, rows, unknown, values);
    }
    stats
}

/// How many times a solve restarts CG from its solution when the residual recomputed from it
/// is above the tolerance (see `solve_all`). One is enough where it happens: the restart's
/// first residual is already small (a window from the walls' field on 64 robots on the 1.8 m
/// circle). The shipped worlds' full solves never restart (`tests/summaries/solve-work.json`
/// kept its counts).
const RESTARTS: usize = 2;

/// The box of a grid that holds every unknown cell and the cells next to them, when it is at
/// most half the grid: a problem whose unknowns are few among many Dirichlet cells (the field
/// that takes a yielding agent out of the others' ways: `W = 1` on every free cell clear of
/// them) is solved on that box. The system is the same (no cell outside the box is a neighbour
/// of an unknown), and the hierarchy, the cycles and the passes over the vectors cost the box's
/// cells instead of the grid's.
struct Crop {
    /// The box's cells along x and y, in the grid's cell indices.
    i: std::ops::Range<usize>,
    j: std::ops::Range<usize>,
}

impl Crop {
    /// The box of `grid` around its `unknown` cells, if it is at most half the grid (and not
    /// empty).
    fn of(grid: &Grid, unknown: &[bool]) -> Option<Self> {
        if grid.nx == 0 {
            return None;
        }
        // Each row's first and last unknown cell, by row: the cells' own indices would be
        // divided by the row length, two divisions a cell (2 % of a crowd's time).
        let ends = (unknown.chunks_exact(grid.nx).enumerate()).flat_map(|(j, row)| {
            let first = row.iter().position(|&u| u);
            let last = row.iter().rposition(|&u| u);
            first.into_iter().chain(last).map(move |i| (i, j))
        });
        let (i, j) = grid.box_of(ends)?;
        (2 * i.len() * j.len() <= grid.len()).then_some(Self { i, j })
    }

    /// [`solve_with`] on the box: its cells copied out, solved, and the unknown ones copied back.
    fn solve(
        &self,
        cycle: Cycle,
        (grid, unknown, values): (&Grid, &[bool], &mut [f64]),
        tolerance: f64,
        max_iterations: usize,
    ) -> Stats {
        let sub = grid.part(self.i.clone(), self.j.clone());
        // The box's part of row `j` of the grid.
        let row = |j: usize| grid.index(self.i.start, j)..grid.index(self.i.end, j);
        let rows = || self.j.clone().map(row);
        let sub_unknown: Vec<bool> = rows().flat_map(|r| &unknown[r]).copied().collect();
        let mut sub_values: Vec<f64> = rows().flat_map(|r| &values[r]).copied().collect();
        let sub_problem = (
            &Rows::whole(sub.nx, sub.ny),
            &sub_unknown[..],
            &mut sub_values[..],
        );
        let stats = solve_all(cycle, sub_problem, tolerance, max_iterations);
        let solved = sub_unknown
            .chunks_exact(sub.nx)
            .zip(sub_values.chunks_exact(sub.nx));
        for (r, (unknown, solved)) in rows().zip(solved) {
            for ((v, &u), &s) in values[r].iter_mut().zip(unknown).zip(solved) {
                if u {
                    *v = s;
                }
            }
        }
        stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::laplace::{reachable_from, solve_sor};

    /// Solves the field of `target` on the free cells reachable from it with multigrid and with
    /// the SOR reference, both to 1e-13, and checks they agree to 1e-9.
    fn agrees_with_the_reference(grid: &Grid, blocked: &[bool], target: (usize, usize)) -> Stats {
        let reachable = reachable_from(grid, blocked, target);
        let reference = solve_sor(grid, &reachable, target, 1e-13, 1_000_000).unwrap();

        let mut unknown = reachable.clone();
        unknown[grid.index(target.0, target.1)] = false;
        let mut w = vec![0.0; grid.len()];
        w[grid.index(target.0, target.1)] = 1.0;
        let stats = solve(grid, &unknown, &mut w, 1e-13, 200);
        assert!(stats.relative_residual <= 1e-13, "{stats:?}");
        let worst = w
            .iter()
            .zip(&reference.w)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "largest difference {worst:e}");
        stats
    }

    /// A grid tall enough for two threads to sweep its fine levels (see `cycle.rs`'s
    /// `in_parts`), with walls across the rows where the two parts meet: the solution is the
    /// one-thread solution to the bit.
    #[test]
    fn two_threads_give_the_one_thread_solution_to_the_bit() {
        let grid = Grid::covering([3.4, 3.0], 0.01);
        assert!(grid.ny >= 256, "{} rows", grid.ny);
        let mut blocked = vec![false; grid.len()];
        for (i, j) in (0..grid.nx).flat_map(|i| (0..grid.ny).map(move |j| (i, j))) {
            // A wall across the middle rows with a gap, and a slanted one.
            let across = (140..160).contains(&j) && !(40..60).contains(&i);
            let slanted = i.abs_diff(j + 30) < 3 && j < 250;
            blocked[grid.index(i, j)] = across || slanted;
        }
        let (one, two) = on_one_thread_and_two(&grid, &blocked, (300, 280));
        assert!(one.0.relative_residual <= 1e-12, "{:?}", one.0);
        assert_eq!(one.0, two.0);
        assert!(bits(&one.1) == bits(&two.1), "the solutions differ");
    }

    /// The field of `target` solved to 1e-12 with tall levels swept by one thread, then by two.
    fn on_one_thread_and_two(
        grid: &Grid,
        blocked: &[bool],
        target: (usize, usize),
    ) -> ((Stats, Vec<f64>), (Stats, Vec<f64>)) {
        // The switch is global: one test at a time flips it.
        static SWITCH: std::sync::Mutex<()> = std::sync::Mutex::new(());
        let _only = SWITCH.lock().unwrap_or_else(|e| e.into_inner());
        let mut unknown = reachable_from(grid, blocked, target);
        unknown[grid.index(target.0, target.1)] = false;
        let solve_with = |split: bool| {
            cycle::set_split(split);
            let mut w = vec![0.0; grid.len()];
            w[grid.index(target.0, target.1)] = 1.0;
            let stats = solve(grid, &unknown, &mut w, 1e-12, 200);
            cycle::set_split(true);
            (stats, w)
        };
        (solve_with(false), solve_with(true))
    }

    /// The bit patterns of `values`, to compare solutions exactly.
    fn bits(values: &[f64]) -> Vec<u64> {
        values.iter().map(|v| v.to_bits()).collect()
    }

    /// As above on a field that decays through a serpentine of corridors to 1e-14 and below,
    /// where the cycle makes values under its flush level (1e-30 of its unit scale): every value
    /// it stores is flushed, so each pass keeps the other colour's cells exactly and the order
    /// the two threads sweep the rows in changes nothing. (When the first pass from zero and
    /// the prolongation stored such values unflushed, a later pass's rewrite of the row turned
    /// them into 0, before or after a neighbour row read them depending on the order: 23 819
    /// cells of this field differed between one thread and two.)
    #[test]
    fn two_threads_give_the_one_thread_solution_on_a_deep_field() {
        let grid = Grid::covering([3.0, 3.0], 0.01);
        assert!(grid.ny >= 256, "{} rows", grid.ny);
        let mut blocked = vec![false; grid.len()];
        for (i, j) in (0..grid.nx).flat_map(|i| (0..grid.ny).map(move |j| (i, j))) {
            // A wall every sixth column, its gap at the bottom and the top in turn.
            let gap_below = (i / 6) % 2 == 0;
            blocked[grid.index(i, j)] =
                i % 6 == 5 && if gap_below { j > 3 } else { j + 4 < grid.ny };
        }
        let (one, two) = on_one_thread_and_two(&grid, &blocked, (1, 1));
        assert!(one.0.relative_residual <= 1e-12, "{:?}", one.0);
        let free = (one.1.iter()).zip(&blocked).filter(|(_, b)| !**b);
        let deepest = free.map(|(w, _)| w.abs()).fold(f64::MAX, f64::min);
        assert!(deepest < 1e-14, "{deepest:e}");
        assert_eq!(one.0, two.0);
        let differ = (bits(&one.1).into_iter().zip(bits(&two.1))).filter(|(a, b)| a != b);
        assert_eq!(differ.count(), 0, "cells that differ");
    }

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
        let stats = agrees_with_the_reference(&grid, &blocked, target);
        assert!(stats.iterations <= 15, "{stats:?}");
    }

    /// A domain that fills little of its grid (a slanted band, so every pair of rows spans
    /// other columns, starting on odd and even ones, and some rows hold nothing): multigrid,
    /// which works on the rows' spans only, agrees with the SOR reference.
    #[test]
    fn a_sparse_domain_matches_the_reference_solver() {
        let grid = Grid::covering([3.2, 2.0], 0.05);
        let mut blocked = vec![true; grid.len()];
        for j in 3..grid.ny - 2 {
            for i in 0..grid.nx {
                if (i as f64 - 1.5 * j as f64 - 8.0).abs() <= 6.0 {
                    blocked[grid.index(i, j)] = false;
                }
            }
        }
        let target = (30, 15);
        assert!(!blocked[grid.index(target.0, target.1)]);
        agrees_with_the_reference(&grid, &blocked, target);
    }

    /// A band, straight and then slanted, held at 1 at its lower end and at uneven values along
    /// its sides, with a starting guess: solved on the cells `Rows::around` stores (a nested
    /// part's way), it gives the solution over its whole grid to the bit, in the same
    /// iterations, and stores under a quarter of the grid.
    #[test]
    fn a_problem_stored_around_its_cells_solves_as_on_its_whole_grid() {
        let grid = Grid::covering([3.2, 2.0], 0.02);
        // Straight up, then slanted.
        let axis = |j: usize| 30.0 + 1.5 * j.saturating_sub(50) as f64;
        let band = |i: usize, j: usize| (i as f64 - axis(j)).abs() <= 6.0;
        let cells: Vec<(usize, usize)> = (0..grid.len())
            .map(|k| (k % grid.nx, k / grid.nx))
            .filter(|&(i, j)| j >= 3 && band(i, j))
            .collect();
        let mut unknown = vec![false; grid.len()];
        let mut w = vec![0.0; grid.len()];
        for &(i, j) in &cells {
            let k = grid.index(i, j);
            unknown[k] = true;
            w[k] = 0.1 + 0.01 * ((k * 7919) % 13) as f64;
        }
        for (i, j) in (0..grid.nx).flat_map(|i| (0..grid.ny).map(move |j| (i, j))) {
            let touches = grid
                .neighbours(i, j)
                .any(|(a, b)| unknown[grid.index(a, b)]);
            let k = grid.index(i, j);
            if !unknown[k] && touches {
                w[k] = if j < 3 { 1.0 } else { 0.3 * (i % 3) as f64 };
            }
        }
        let rows = Rows::around(grid.nx, grid.ny, cells.iter().copied());
        assert!(
            4 * rows.len() < grid.len(),
            "{} of {}",
            rows.len(),
            grid.len()
        );
        let at = |k: usize| rows.index(k % grid.nx, k / grid.nx);
        let (mut stored_unknown, mut stored_w) = (vec![false; rows.len()], vec![0.0; rows.len()]);
        for k in (0..grid.len()).filter(|&k| at(k).is_some()) {
            (stored_unknown[at(k).unwrap()], stored_w[at(k).unwrap()]) = (unknown[k], w[k]);
        }
        let whole = solve(&grid, &unknown, &mut w, 1e-12, 100);
        let stored = solve_rows(&rows, &stored_unknown, &mut stored_w, 1e-12, 100);
        assert!(whole.relative_residual <= 1e-12, "{whole:?}");
        assert_eq!(whole, stored);
        for &(i, j) in &cells {
            let (a, b) = (w[grid.index(i, j)], stored_w[rows.index(i, j).unwrap()]);
            assert_eq!(a.to_bits(), b.to_bits(), "({i}, {j}): {a} against {b}");
        }
    }

    /// A unit square at `n²` cells with a divider over two thirds of its height and the target
    /// (`W = 1`) low on one side of it: the grid, the unknown cells and the starting `W`.
    fn divided_room(n: usize) -> (Grid, Vec<bool>, Vec<f64>) {
        let grid = Grid::covering([1.0, 1.0], 1.0 / n as f64);
        let mut unknown = vec![true; grid.len()];
        for j in 0..n * 2 / 3 {
            unknown[grid.index(n / 2, j)] = false;
        }
        let target = grid.index(n / 8, n / 8);
        unknown[target] = false;
        let mut w = vec![0.0; grid.len()];
        w[target] = 1.0;
        (grid, unknown, w)
    }

    /// The W-cycle's point: the iteration count does not grow with the grid. A room with a
    /// divider at 64², 128² and 256² cells takes the same number of CG iterations, within one.
    #[test]
    fn iterations_stay_flat_as_the_grid_grows() {
        let counts: Vec<usize> = [64, 128, 256]
            .iter()
            .map(|&n| {
                let (grid, unknown, mut w) = divided_room(n);
                let stats = solve(&grid, &unknown, &mut w, 1e-10, 100);
                assert!(stats.relative_residual <= 1e-10, "{stats:?}");
                stats.iterations
            })
            .collect();
        assert!(
            counts.iter().max().unwrap() - counts.iter().min().unwrap() <= 1 && counts[2] <= 13,
            "{counts:?}"
        );
    }

    /// The V-cycle, which the windows of local replanning take, solves the same system to the
    /// tolerance (the solution agrees with the W-cycle's to it), in more iterations than the
    /// W-cycle but fewer than twice as many on a window's size of grid.
    #[test]
    fn the_v_cycle_solves_a_window_sized_grid() {
        let (grid, unknown, w) = divided_room(62);
        let (mut by_v, mut by_w) = (w.clone(), w);
        let v = solve_with(Cycle::V, &grid, &unknown, &mut by_v, 1e-10, 100);
        let w = solve_with(Cycle::W, &grid, &unknown, &mut by_w, 1e-10, 100);
        assert!(v.relative_residual <= 1e-10 && w.relative_residual <= 1e-10);
        assert!(
            v.iterations > w.iterations && v.iterations < 2 * w.iterations,
            "{v:?} {w:?}"
        );
        let worst = (by_v.iter().zip(&by_w))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "largest difference {worst:e}");
    }

    /// A few unknowns among many Dirichlet cells are solved on their box (see `Crop`): the
    /// same solution as over the whole grid, to the tolerance, and no cell outside the box is
    /// written. The unknowns: a ring of cells around a square held at 1, at the grid's corner
    /// and in its middle; everything else fixed at 0.5 or 0.
    #[test]
    fn few_unknowns_are_solved_on_their_box() {
        let grid = Grid::covering([2.0, 2.0], 1.0 / 64.0);
        for corner in [0, 50] {
            let mut unknown = vec![false; grid.len()];
            let mut w = vec![0.5; grid.len()];
            for j in corner..corner + 20 {
                for i in corner..corner + 30 {
                    let k = grid.index(i, j);
                    let inner = (5..25).contains(&(i - corner)) && (5..15).contains(&(j - corner));
                    (unknown[k], w[k]) = if inner { (false, 1.0) } else { (true, 0.0) };
                }
            }
            let crop = Crop::of(&grid, &unknown).expect("a small box");
            assert_eq!(
                (crop.i.len(), crop.j.len()),
                (
                    30 + 1 + usize::from(corner > 0),
                    20 + 1 + usize::from(corner > 0)
                )
            );
            let mut whole = w.clone();
            let on_box = solve(&grid, &unknown, &mut w, 1e-12, 100);
            let rows = Rows::whole(grid.nx, grid.ny);
            let all = solve_all(Cycle::W, (&rows, &unknown, &mut whole), 1e-12, 100);
            assert!(on_box.relative_residual <= 1e-12 && all.relative_residual <= 1e-12);
            let worst = (w.iter().zip(&whole))
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-10, "largest difference {worst:e}");
            assert!((0..grid.len()).all(|k| unknown[k] || w[k] == whole[k]));
        }
        // A problem that fills the grid is solved over all of it.
        let (grid, unknown, _) = divided_room(64);
        assert!(Crop::of(&grid, &unknown).is_none());
    }

    /// CG updates its residual rather than recomputing it, from a search direction rounded to
    /// f32: the residual recomputed in f64 from the returned field must still be the one
    /// reported, to far below f32's rounding.
    #[test]
    fn the_reported_residual_is_the_true_residual() {
        let n = 128;
        let (grid, unknown, mut w) = divided_room(n);
        let stats = solve(&grid, &unknown, &mut w, 1e-12, 100);
        assert!(stats.relative_residual <= 1e-12, "{stats:?}");
        let truth = true_relative_residual(&grid, &unknown, &w);
        assert!(
            (truth - stats.relative_residual).abs() <= 1e-3 * stats.relative_residual,
            "true {truth:e}, reported {:e}",
            stats.relative_residual
        );
    }

    /// A guess far above the solution (a window's field of the walls where the others close
    /// the way) leaves a first residual 1e10 times `b`; CG's recurrence then reaches the
    /// tolerance while `b − A x` is still far above it (8e-5 of `b` here without the restart,
    /// with V-cycles: 6e-10 reported), so
    /// the solve recomputes the residual and restarts. Both cycles, to a window's 1e-9.
    #[test]
    fn a_guess_far_from_the_solution_still_meets_the_tolerance() {
        for cycle in [Cycle::V, Cycle::W] {
            let (grid, unknown, mut w) = divided_room(64);
            for (w, u) in w.iter_mut().zip(&unknown) {
                if *u {
                    *w = 1e10;
                }
            }
            let stats = solve_with(cycle, &grid, &unknown, &mut w, 1e-9, 100);
            let truth = true_relative_residual(&grid, &unknown, &w);
            assert!(
                stats.relative_residual <= 1e-9 && truth <= 1e-9,
                "{cycle:?}: true {truth:e}, {stats:?}"
            );
        }
    }

    /// `‖b − A w‖ / ‖b‖` over the `unknown` cells, computed from `w` itself.
    fn true_relative_residual(grid: &Grid, unknown: &[bool], w: &[f64]) -> f64 {
        let (mut rr, mut bb) = (0.0, 0.0);
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let k = grid.index(i, j);
                if !unknown[k] {
                    continue;
                }
                let (mut b, mut sum) = (0.0, 0.0);
                for (a, c) in grid.neighbours(i, j) {
                    let m = grid.index(a, c);
                    sum += w[m];
                    if !unknown[m] {
                        b += w[m];
                    }
                }
                rr += (sum - 4.0 * w[k]).powi(2);
                bb += b * b;
            }
        }
        (rr / bb).sqrt()
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

#[cfg(test)]
mod fast_path {
    use super::*;

    /// The AVX2 path and the portable one do the same arithmetic in the same order: the
    /// solutions are identical to the bit.
    #[test]
    fn the_fast_path_and_the_portable_one_agree_to_the_bit() {
        let grid = Grid::covering([1.0, 1.0], 1.0 / 96.0);
        let mut unknown = vec![true; grid.len()];
        for j in 0..60 {
            unknown[grid.index(48, j)] = false;
        }
        let target = grid.index(10, 10);
        unknown[target] = false;
        let solve_with = |portable: bool| {
            set_portable(portable);
            let mut w = vec![0.0; grid.len()];
            w[target] = 1.0;
            let stats = solve(&grid, &unknown, &mut w, 1e-12, 100);
            set_portable(false);
            (stats, w)
        };
        let (fast, portable) = (solve_with(false), solve_with(true));
        assert_eq!(fast.0, portable.0);
        assert!(
            fast.1
                .iter()
                .zip(&portable.1)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
    }
}

#[cfg(test)]
mod warm {
    use super::*;

    #[test]
    fn a_warm_start_far_from_the_solution_still_converges_to_it() {
        let grid = Grid::covering([1.0, 3.0], 1.0 / 64.0);
        let mut unknown = vec![false; grid.len()];
        for j in 2..grid.ny - 2 {
            for i in 20..30 {
                unknown[grid.index(i, j)] = true;
            }
        }
        let mut w = vec![0.0; grid.len()];
        for i in 20..30 {
            w[grid.index(i, 1)] = 1.0;
        }
        for (k, v) in w.iter_mut().enumerate() {
            if unknown[k] {
                *v = 0.3 + 0.2 * ((k * 7919) % 13) as f64 / 13.0;
            }
        }
        let stats = solve(&grid, &unknown, &mut w, 1e-12, 100);
        let mut worst: f64 = 0.0;
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let k = grid.index(i, j);
                if unknown[k] {
                    let s: f64 = grid
                        .neighbours(i, j)
                        .map(|(a, b)| w[grid.index(a, b)])
                        .sum();
                    worst = worst.max((4.0 * w[k] - s).abs());
                }
            }
        }
        assert!(worst < 1e-10, "{stats:?}: worst residual {worst:e}");
    }
}
