//! The conjugate gradient driver: the vectors in f64 (and the search direction in f32), the
//! initial residual, the iteration with one W-cycle per step as the preconditioner, and the
//! copy of the solution back onto the grid.

use std::ops::Range;

use super::Stats;
use super::cycle::{Hierarchy, split_at};
use super::kernels::{Neighbourhood, dot, flushed, for_cycle, wide};
use super::level::Level;
use super::rows::Rows;

/// The CG vectors on the fine level's layout. The search direction is kept in f32 as
/// `q = scale · p`, scaled like the cycle's output it is made from (see [`Krylov::iterate`]);
/// the solution `x` and the residual `r` stay in f64, since they carry the solution's precision.
pub struct Krylov {
    x: Vec<f64>,
    r: Vec<f64>,
    q: Vec<f32>,
    /// One row of `A q` per thread (see [`split_at`]).
    rows: [Vec<f64>; 2],
    /// Each row's term of a sum over the rows, summed in row order (whichever thread computed
    /// it).
    dots: Vec<f64>,
    /// `‖b‖`, the norm the residual is measured against.
    norm_b: f64,
    /// `r · r`.
    rr: f64,
}

impl Krylov {
    /// The starting guess (the unknown cells of `values`, both stored as `problem` says), the
    /// right-hand side `b` (the sum of each unknown cell's fixed neighbours; cells `problem`
    /// does not store and cells outside the grid count as 0) and the initial residual
    /// `r = b − A x`, on the layout of the fine level.
    pub fn start(fine: &Level, problem: &Rows, unknown: &[bool], values: &[f64]) -> Self {
        let (nx, ny) = (problem.nx, problem.ny);
        let n = fine.len();
        // `fixed` holds the Dirichlet values and then becomes the residual: fresh memory costs
        // page faults.
        let mut x = vec![0.0; n];
        let mut fixed = laid_out(fine, problem, (unknown, values), Some(&mut x));
        // r = b − A x row by row, trailing two rows behind so that `fixed` (read up to a row
        // ahead) can be overwritten with r. Only a row's span holds active cells (a nested
        // part's box is mostly empty); the sums skip only zeros, so they are those over the
        // whole row to the bit.
        let (mut bb, mut rr) = (0.0, 0.0);
        let mut rows = [vec![0.0; nx], vec![0.0; nx]];
        for j in 0..ny + 2 {
            if j >= 2 {
                let (k, cols) = fine.stored(j - 2);
                fixed[k..k + cols.len()].copy_from_slice(&rows[j % 2][cols]);
            }
            if j < ny {
                let (at, cols) = fine.run(j);
                let f = Neighbourhood::of(&fixed, at, cols.len());
                let u = Neighbourhood::of(&x, at, cols.len());
                let d = &fine.inv_diag[at.mid..at.mid + cols.len()];
                let row = &mut rows[j % 2];
                row.fill(0.0);
                let mut b_row = 0.0;
                for (l, i) in cols.clone().enumerate() {
                    if d[l] != 0.0 {
                        let f = [f.west[l], f.east[l], f.up[l], f.down[l]];
                        let (b, r) =
                            residual_at(f, [u.mid[l], u.west[l], u.east[l], u.up[l], u.down[l]]);
                        b_row += b * b;
                        row[i] = r;
                    }
                }
                bb += b_row;
                rr += row_dot(row, cols);
            }
        }
        Self {
            x,
            r: fixed,
            q: vec![0.0; n],
            rows: [vec![0.0; nx], vec![0.0; nx]],
            dots: vec![0.0; ny],
            norm_b: bb.sqrt(),
            rr,
        }
    }

    /// `‖r‖ / ‖b‖` (`‖r‖` when `b` is 0).
    fn relative(&self) -> f64 {
        self.relative_of(self.rr)
    }

    /// `sqrt(rr) / ‖b‖` (`sqrt(rr)` when `b` is 0).
    fn relative_of(&self, rr: f64) -> f64 {
        if self.norm_b > 0.0 {
            rr.sqrt() / self.norm_b
        } else {
            rr.sqrt()
        }
    }

    /// The relative residual `‖b − A x‖ / ‖b‖` recomputed from the solution (not CG's
    /// recurrence), with the Dirichlet values read from `values` as [`Krylov::start`] reads
    /// them (see `laid_out`): to the bit what a new start from the solution would measure, over
    /// the rows' spans only (a nested part's box is mostly empty) and with one vector on the
    /// level's layout where a new start makes three.
    pub fn true_relative(
        &self,
        fine: &Level,
        problem: &Rows,
        unknown: &[bool],
        values: &[f64],
    ) -> f64 {
        let (nx, ny) = (problem.nx, problem.ny);
        let fixed = laid_out(fine, problem, (unknown, values), None);
        let mut row = vec![0.0; nx];
        let mut rr = 0.0;
        for j in 0..ny {
            let (at, cols) = fine.run(j);
            let n = cols.len();
            let f = Neighbourhood::of(&fixed, at, n);
            let u = Neighbourhood::of(&self.x, at, n);
            let d = &fine.inv_diag[at.mid..at.mid + n];
            let out = &mut row[cols.clone()];
            // A loop the compiler vectorizes: each neighbour's value at a fixed offset (it
            // looked each one up in the problem's rows: 1.9 % of 64 robots' time on the 1.8 m
            // circle, about 0.6 % now with its half of `laid_out`; the same sums to the bit).
            wide(
                #[inline(always)]
                || {
                    for l in 0..n {
                        let f = [f.west[l], f.east[l], f.up[l], f.down[l]];
                        let u = [u.mid[l], u.west[l], u.east[l], u.up[l], u.down[l]];
                        // Inactive cells hold 0 (as the row does between rows).
                        out[l] = if d[l] != 0.0 {
                            residual_at(f, u).1
                        } else {
                            0.0
                        };
                    }
                },
            );
            rr += row_dot(&row, cols.clone());
            row[cols].fill(0.0);
        }
        self.relative_of(rr)
    }

    /// Preconditioned CG until the relative residual is at most `tolerance` or
    /// `max_iterations` are done: `z = M r`, `p = z + β p`, `x += α p`, `r −= α A p`,
    /// `α = r·z / p·A p`, `β = r_next·z_next / r·z`.
    ///
    /// The cycle's right-hand side `r` is scaled by `scale`, about `1 / ‖r‖`, so that f32 sees
    /// no extreme values. The cycle then returns `scale · z`, and the direction is kept as
    /// `q = scale · p`, which is also O(1): `p · A p = q · A q / scale²`, and the next
    /// `q = scale' · z' + β (scale' / scale) q`.
    pub fn iterate(&mut self, h: &mut Hierarchy, tolerance: f64, max_iterations: usize) -> Stats {
        let mut stats = Stats {
            iterations: 0,
            relative_residual: self.relative(),
        };
        if stats.relative_residual <= tolerance {
            return stats;
        }
        let mut scale = 1.0 / self.rr.sqrt();
        let r = &self.r;
        wide(
            #[inline(always)]
            || {
                for (o, r) in h.work[0][1].iter_mut().zip(r) {
                    *o = for_cycle(*r, scale);
                }
            },
        );
        let mut rz = h.precondition() / (scale * scale);
        let mut gamma = 0.0;
        while stats.iterations < max_iterations {
            stats.iterations += 1;
            let pap = self.direct(&h.levels[0], &h.work[0][0], gamma) / (scale * scale);
            if pap.is_nan() || pap <= 0.0 {
                break;
            }
            let alpha = rz / pap;
            let next_scale = 1.0 / self.rr.sqrt();
            self.rr = self.step(&h.levels[0], alpha / scale, next_scale, &mut h.work[0][1]);
            stats.relative_residual = self.relative();
            if stats.relative_residual <= tolerance {
                break;
            }
            let rz_next = h.precondition() / (next_scale * next_scale);
            gamma = (rz_next / rz * next_scale / scale) as f32;
            (rz, scale) = (rz_next, next_scale);
        }
        stats
    }

    /// Writes the solution into the unknown cells of `values`.
    pub fn copy_out(&self, fine: &Level, problem: &Rows, unknown: &[bool], values: &mut [f64]) {
        for j in 0..problem.ny {
            let (k, cols, row) = both(fine, problem, j);
            for ((v, x), u) in values[row.clone()]
                .iter_mut()
                .zip(&self.x[k..k + cols.len()])
                .zip(&unknown[row])
            {
                if *u {
                    *v = *x;
                }
            }
        }
    }

    /// The new direction `q = z + γ q` and its curvature `q · A q`: one pass, `A q` trailing a
    /// row behind the rows it reads. (`q` is 0 on inactive cells, so they add nothing to the
    /// sum whatever the stencil gives there.) On a tall level two threads take the rows below
    /// and above the middle, each leaving `A q` on the row next to the other's; those two rows
    /// come last.
    fn direct(&mut self, level: &Level, z: &[f32], gamma: f32) -> f64 {
        let Self { q, rows, dots, .. } = self;
        let dots = &mut dots[..level.ny];
        // `q = z + γ q` on `rows` and `q · A q` of the rows `applied` among them, with `q`
        // starting at index `origin` and `dots` at row `first`.
        let part = |rows: Range<usize>,
                    applied: Range<usize>,
                    (q, origin): (&mut [f32], usize),
                    (row, dots, first): (&mut [f64], &mut [f64], usize)| {
            wide(
                #[inline(always)]
                || {
                    for j in rows.start..rows.end + 1 {
                        if j < rows.end {
                            let (k, n) = level.row(j);
                            let q = &mut q[k - origin..k - origin + n];
                            for (q, z) in q.iter_mut().zip(&z[k..k + n]) {
                                *q = flushed(z + gamma * *q);
                            }
                        }
                        if let Some(j) = j.checked_sub(1).filter(|j| applied.contains(j)) {
                            dots[j - first] = curvature(level, (q, origin), j, row);
                        }
                    }
                },
            )
        };
        let [row, second] = rows;
        match split_at(level) {
            None => part(0..level.ny, 0..level.ny, (q, 0), (row, dots, 0)),
            Some(mid) => {
                let at = level.row_start(mid);
                let ((q_below, q_above), (d_below, d_above)) =
                    (q.split_at_mut(at), dots.split_at_mut(mid));
                rayon::join(
                    || part(0..mid, 0..mid - 1, (q_below, 0), (row, d_below, 0)),
                    || {
                        part(
                            mid..level.ny,
                            mid + 1..level.ny,
                            (q_above, at),
                            (second, d_above, mid),
                        )
                    },
                );
                for j in mid - 1..mid + 1 {
                    dots[j] = wide(
                        #[inline(always)]
                        || curvature(level, (q, 0), j, row),
                    );
                }
            }
        }
        dots.iter().fold(0.0, |sum, d| sum + d)
    }

    /// The step `x += c q`, `r −= c A q` (on the active cells), the new `r · r`, and
    /// `out = r · scale` in f32 (the next cycle's right-hand side): one pass (on a tall level,
    /// two threads each take half the rows).
    fn step(&mut self, level: &Level, c: f64, scale: f64, out: &mut [f32]) -> f64 {
        let Self {
            x,
            r,
            q,
            rows,
            dots,
            ..
        } = self;
        let (q, dots) = (&*q, &mut dots[..level.ny]);
        // The step on `rows`, with `x`, `r` and `out` starting at index `origin` and
        // `dots` at the first row.
        let part = |rows: Range<usize>,
                    origin: usize,
                    (x, r, out): (&mut [f64], &mut [f64], &mut [f32]),
                    (row, dots): (&mut [f64], &mut [f64])| {
            wide(
                #[inline(always)]
                || {
                    for j in rows.clone() {
                        apply_row(level, (q, 0), j, row);
                        let (k, n) = level.row(j);
                        let d = &level.inv_diag[k..k + n];
                        let (k, q) = (k - origin, &q[k..k + n]);
                        let (x, r, out) = (&mut x[k..k + n], &mut r[k..k + n], &mut out[k..k + n]);
                        // Every slice `n` long and both factors in locals: the loop then has no
                        // bounds check and no load that a store might alias, and is vectorized.
                        // Scalar, it took 7 % of the samples of 64 robots on the 1.8 m circle;
                        // vectorized, their first 15 s take 27.1 s against 27.6 s (the same run
                        // to the bit).
                        let (row, c, scale) = (&row[..n], c, scale);
                        for i in 0..n {
                            x[i] += c * f64::from(q[i]);
                            // Computed on every cell, then selected (see
                            // `Level::residual_row`): no masked loads.
                            let step = c * row[i];
                            r[i] -= if d[i] != 0.0 { step } else { 0.0 };
                            out[i] = for_cycle(r[i], scale);
                        }
                        dots[j - rows.start] = dot(r, r);
                    }
                },
            )
        };
        let [row, second] = rows;
        match split_at(level) {
            None => part(0..level.ny, 0, (x, r, out), (row, dots)),
            Some(mid) => {
                let at = level.row_start(mid);
                let (x_below, x_above) = x.split_at_mut(at);
                let (r_below, r_above) = r.split_at_mut(at);
                let (out_below, out_above) = out.split_at_mut(at);
                let (d_below, d_above) = dots.split_at_mut(mid);
                rayon::join(
                    || part(0..mid, 0, (x_below, r_below, out_below), (row, d_below)),
                    || {
                        part(
                            mid..level.ny,
                            at,
                            (x_above, r_above, out_above),
                            (second, d_above),
                        )
                    },
                );
            }
        }
        dots.iter().fold(0.0, |sum, d| sum + d)
    }
}

/// The cells of row `j` that both the fine level and the problem's `rows` store: their index
/// in the level's vectors, their columns, and their indices in the problem's arrays.
fn both(fine: &Level, rows: &Rows, j: usize) -> (usize, Range<usize>, Range<usize>) {
    let (k, cols) = fine.stored(j);
    let (u, common) = rows.within(j, cols.clone());
    if common.is_empty() {
        return (0, 0..0, 0..0);
    }
    (
        k + common.start - cols.start,
        common.clone(),
        u..u + common.len(),
    )
}

/// The Dirichlet values of `problem` on the fine level's layout: `values` on its known cells,
/// 0 on its unknown ones and on the cells the level stores beyond it (the level stores every
/// cell next to an active one, see `level.rs`); with `guess`, the starting guess into it:
/// `values` on the unknown cells, 0 elsewhere. What [`Krylov::start`] starts from and
/// [`Krylov::true_relative`] measures with.
fn laid_out(
    fine: &Level,
    problem: &Rows,
    (unknown, values): (&[bool], &[f64]),
    mut guess: Option<&mut [f64]>,
) -> Vec<f64> {
    let mut fixed = vec![0.0; fine.len()];
    for j in 0..problem.ny {
        let (k, cols, row) = both(fine, problem, j);
        let (values, unknown) = (&values[row.clone()], &unknown[row]);
        let cells = k..k + cols.len();
        for ((f, v), u) in fixed[cells.clone()].iter_mut().zip(values).zip(unknown) {
            *f = if *u { 0.0 } else { *v };
        }
        if let Some(x) = guess.as_deref_mut() {
            for ((x, v), u) in x[cells].iter_mut().zip(values).zip(unknown) {
                *x = if *u { *v } else { 0.0 };
            }
        }
    }
    fixed
}

/// `q · A q` on row `j` (`q` starting at index `origin`), with `row` to hold `A q`.
#[inline(always)]
fn curvature(level: &Level, (q, origin): (&[f32], usize), j: usize, row: &mut [f64]) -> f64 {
    apply_row(level, (q, origin), j, row);
    let (k, n) = level.row(j);
    dot(&q[k - origin..k - origin + n], &row[..n])
}

/// `A q` on row `j` of the fine level, in f64, into `out`: the 5-point stencil on every cell,
/// so it is `A q` on the active cells only (`q` is 0 on the others). `q` holds f32 values, so
/// the sums are exact in f64. `q` starts at index `origin`.
#[inline(always)]
fn apply_row(level: &Level, (q, origin): (&[f32], usize), j: usize, out: &mut [f64]) {
    let (at, cols) = level.run(j);
    let n = cols.len();
    let q = Neighbourhood::of(q, at.from(origin), n);
    let out = &mut out[..n];
    for i in 0..n {
        out[i] = 4.0 * f64::from(q.mid[i])
            - f64::from(q.west[i])
            - f64::from(q.east[i])
            - f64::from(q.up[i])
            - f64::from(q.down[i]);
    }
}

/// The right-hand side `b` and the residual `b − A x` at an active cell of the fine level,
/// from its neighbours' Dirichlet values `f` (west, east, north, south; 0 on unknown cells
/// and off the grid) and the values `u` of the cell and of its neighbours (centre, west, east,
/// north, south; 0 on Dirichlet cells).
#[inline(always)]
fn residual_at(f: [f64; 4], u: [f64; 5]) -> (f64, f64) {
    let b = f[0] + f[1] + f[2] + f[3];
    (b, b - (4.0 * u[0] - u[1] - u[2] - u[3] - u[4]))
}

/// `row · row` for a row whose cells outside `span` are 0: the sum [`dot`] gives over the
/// whole row, to the bit (it starts at the chunk of four that holds the span's first cell and
/// runs to the row's end, so every cell falls in the same partial sum; the cells it skips add
/// only zeros).
#[inline(always)]
fn row_dot(row: &[f64], span: Range<usize>) -> f64 {
    if span.is_empty() {
        return 0.0;
    }
    let from = span.start / 4 * 4;
    dot(&row[from..], &row[from..])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::multigrid::Cycle;

    /// A row's sum over its span is the whole row's to the bit, wherever the span starts.
    #[test]
    fn a_span_sums_as_its_whole_row() {
        let n = 23;
        for start in 0..n {
            for end in start..=n {
                let row: Vec<f64> = (0..n)
                    .map(|i| {
                        let v = ((i * 7919 % 1013) as f64).sqrt() / 3.0;
                        if (start..end).contains(&i) { v } else { 0.0 }
                    })
                    .collect();
                let (span, whole) = (row_dot(&row, start..end), dot(&row, &row));
                assert_eq!(span.to_bits(), whole.to_bits(), "{start}..{end}");
            }
        }
    }

    /// Every cell of an `nx × ny` grid.
    fn unit_grid(nx: usize, ny: usize) -> Rows {
        Rows::whole(nx, ny)
    }

    /// A ring of unknown cells in a box (rows whose span holds a hole, rows with no unknown
    /// cell), uneven Dirichlet values around it: after each of a few iterations, the check
    /// measures the residual of the solution to the bit as a new start from it does, which
    /// the solve relies on to stop where it stopped before the check.
    #[test]
    fn the_check_measures_what_a_new_start_would_to_the_bit() {
        let grid = unit_grid(37, 29);
        let unknown: Vec<bool> = (0..grid.len())
            .map(|k| {
                let (i, j) = ((k % grid.nx) as f64, (k / grid.nx) as f64);
                (6.0..11.0).contains(&(i - 17.0).hypot(j - 13.0))
            })
            .collect();
        let mut values: Vec<f64> = (0..grid.len())
            .map(|k| (((k * 7919) % 1013) as f64).sqrt() / 32.0)
            .collect();
        let mut h = Hierarchy::new(grid.nx, grid.ny, &unknown, Cycle::V);
        let mut cg = Krylov::start(&h.levels[0], &grid, &unknown, &values);
        for _ in 0..3 {
            let run = cg.iterate(&mut h, 1e-30, 1);
            assert_eq!(run.iterations, 1);
            cg.copy_out(&h.levels[0], &grid, &unknown, &mut values);
            let check = cg.true_relative(&h.levels[0], &grid, &unknown, &values);
            let fresh = Krylov::start(&h.levels[0], &grid, &unknown, &values).relative();
            assert!(check > 0.0);
            assert_eq!(
                check.to_bits(),
                fresh.to_bits(),
                "{check:e} against {fresh:e}"
            );
        }
    }

    /// A corridor four cells wide and 600 long, held at 1 at one end: the field decays by a
    /// quarter of a decade a cell (a factor 0.544), to 1e-158 at the far end, and so do the
    /// cycle's corrections. No value the cycle or CG's direction holds is ever a subnormal f32
    /// (see `FLUSH`), on any level, after any of a few iterations.
    #[test]
    fn a_decaying_field_leaves_no_subnormal_in_the_cycle() {
        let grid = unit_grid(600, 4);
        let unknown: Vec<bool> = (0..grid.len()).map(|k| k % grid.nx > 0).collect();
        let values: Vec<f64> = (0..grid.len())
            .map(|k| if k % grid.nx == 0 { 1.0 } else { 0.0 })
            .collect();
        for cycle in [Cycle::V, Cycle::W] {
            let mut h = Hierarchy::new(grid.nx, grid.ny, &unknown, cycle);
            let mut cg = Krylov::start(&h.levels[0], &grid, &unknown, &values);
            for _ in 0..4 {
                assert_eq!(cg.iterate(&mut h, 1e-30, 1).iterations, 1);
                let held = (h.work.iter().flatten().flatten()).chain(&cg.q);
                let subnormals = held.filter(|v| v.is_subnormal()).count();
                assert_eq!(subnormals, 0, "{cycle:?}");
            }
            // The corrections did reach far down the corridor: what the flush acts on.
            let far =
                (cg.x.iter().filter(|x| **x != 0.0)).fold(f64::INFINITY, |m, x| m.min(x.abs()));
            assert!(far < 1e-30, "{cycle:?}: smallest value {far:e}");
        }
    }
}
