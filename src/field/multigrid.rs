//! A multigrid-preconditioned conjugate gradient solver (after McAdams, Sifakis & Teran 2010)
//! for the masked Dirichlet problem `∇²u = 0` on a cell-centred grid.
//!
//! Unknowns are the cells marked `unknown`; every other cell holds a fixed (Dirichlet) value.
//! The 5-point system `4 u_k − Σ u_neighbour = 0` is symmetric positive definite, and conjugate
//! gradients solve it in f64.
//!
//! The preconditioner is one W-cycle. Its hierarchy aggregates 2 × 2 cells with
//! piecewise-constant prolongation, restriction by its transpose and Galerkin coarse operators
//! `R A P`. These stay 5-point stencils and follow the mask exactly, however thin its walls are:
//! two regions that a wall separates are never coupled on a coarse level. Each level smooths with
//! red-black Gauss-Seidel (red then black before the coarse correction, black then red after it)
//! and the coarsest level is solved exactly (Cholesky), so the cycle is a symmetric operator, as
//! CG needs. A V-cycle of this hierarchy loses a little on every level (26 CG iterations at
//! 1024², growing with the grid); visiting each coarse level twice (the W-cycle) keeps the count
//! flat (11 at 256² and at 2048²) for about 1.5× the work per cycle.
//!
//! The cycle runs in f32. It only has to approximate `A⁻¹`: its rounding (1e-7) is far below
//! its approximation error, CG in f64 corrects both, and f32 halves the memory traffic, which is
//! what a cycle's time is made of. The residual is scaled to unit size before it is rounded, so
//! no value the cycle sees comes near f32's range limits.
//!
//! Where the time goes, and what is done about it: each level's smoothing passes and its
//! residual restriction (or its prolongation and smoothing passes) run as one wavefront over the
//! rows, so a level is read from memory once per half-cycle rather than once per pass; every
//! row loop is straight-line code that the compiler vectorizes, built for AVX2 when the
//! processor has it (`wide`), and goes over only the row's span of active cells (a nested
//! solve's bounding box can be half empty); a cycle starts from zero without clearing its
//! vectors (its first pass reads nothing of them), and it sums `z · r` in its last pass, while
//! each row is still in cache; and each CG iteration makes two passes over its vectors besides
//! the cycle (`Krylov`): one makes the new search direction and its curvature `p · A p`, the
//! other updates the solution and the residual. The search direction is kept in f32, scaled
//! like the cycle's output it is made from, and `A p` is recomputed from it rather than stored:
//! the solution and the residual, in f64, take the same exact steps, so rounding the direction
//! only changes which direction CG takes (by 1e-7, as the f32 cycle already does) and never
//! lets the residual drift from `b − A x`.
//!
//! The initial values of the unknown cells are the starting guess: a warm start from a previous
//! solution makes a re-solve after a small change cheaper, though not by much, since CG still
//! has to take the residual the change leaves (4–6e-3 of the first one for a wall moved by a
//! cell) down to the tolerance at the same rate.

use super::grid::Grid;

/// Smoothing sweeps before and after each coarse correction.
const SWEEPS: usize = 2;
/// Coarse-level visits per cycle: 1 is a V-cycle, 2 a W-cycle.
const VISITS: usize = 2;
/// A level with at most this many unknowns is solved exactly.
const COARSEST: usize = 64;
/// Factor on the Galerkin coarse operators (see `Level::coarsen`).
const COARSE_SCALE: f32 = 0.5;
/// Scaled residual entries below this are rounded to 0 (keeps f32 away from subnormals).
const FLUSH: f32 = 1e-30;

/// Runs `f` compiled for AVX2 when the processor has it, else as it is. The loops are the
/// same element-wise arithmetic either way (Rust never fuses a multiply and an add on its
/// own), so the results do not depend on the processor; AVX2 only processes 8 f32 at a time
/// instead of 4.
#[inline(always)]
fn wide<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2")]
        fn avx2<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above.
            return unsafe { avx2(f) };
        }
    }
    f()
}

/// How a solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Conjugate gradient iterations (one W-cycle each).
    pub iterations: usize,
    /// Final `‖b − A u‖ / ‖b‖` (0 when the right-hand side is 0).
    pub relative_residual: f64,
}

/// The alternating patterns `keep[q][i] = 0` if `i % 2 == q`, else 1 (see `Level::relax_row`).
type Keep = [Vec<f32>; 2];

/// One level of the hierarchy: a padded grid (a ring of inactive cells around it, row stride
/// `nx + 2`) with a variable-coefficient 5-point stencil. Inactive cells have `inv_diag = 0`
/// and no coupling, so every sweep can run over whole rows without branches, and the vectors a
/// level works on hold 0 there. Each row is processed only over its span ([`Level::span`]),
/// outside which every cell is inactive: a nested solve's box can be mostly empty.
struct Level {
    nx: usize,
    ny: usize,
    stride: usize,
    /// `1 / diagonal` on active cells, 0 on inactive ones.
    inv_diag: Vec<f32>,
    /// Diagonal; empty on the finest level (4 on active cells).
    diag: Vec<f32>,
    /// Coupling to the east neighbour (≥ 0; 0 when either cell is inactive). Empty on the
    /// finest level, whose stencil is the uniform `4, −1` between active cells: since the
    /// vectors hold 0 on inactive cells, it needs no coefficient arrays (less memory traffic,
    /// where most of the work is).
    east: Vec<f32>,
    /// Coupling to the north neighbour; empty on the finest level.
    north: Vec<f32>,
    /// Active cells.
    unknowns: usize,
    /// Per pair of rows `(2p, 2p + 1)`: the columns `[lo, hi)` that hold all their active
    /// cells, `lo` even. The two rows share it so that their residuals restrict onto exactly
    /// the coarse cells `[lo / 2, ⌈hi / 2⌉)`, which hold every active coarse cell of that row.
    spans: Vec<[usize; 2]>,
}

/// [`Level::spans`] of a level `nx` wide and `ny` high with the given active cells.
fn spans(nx: usize, ny: usize, active: impl Fn(usize, usize) -> bool) -> Vec<[usize; 2]> {
    (0..ny.div_ceil(2))
        .map(|p| {
            let rows = 2 * p..(2 * p + 2).min(ny);
            let lo = rows
                .clone()
                .filter_map(|j| (0..nx).find(|&i| active(i, j)))
                .min();
            let hi = rows.filter_map(|j| (0..nx).rfind(|&i| active(i, j))).max();
            match (lo, hi) {
                (Some(lo), Some(hi)) => [lo / 2 * 2, hi + 1],
                _ => [0, 0],
            }
        })
        .collect()
}

impl Level {
    /// The padded length: a ring of inactive cells, plus one more row so that reading the
    /// north neighbour of the top ring stays in bounds.
    fn len(&self) -> usize {
        self.stride * (self.ny + 3)
    }

    fn pad(&self, i: usize, j: usize) -> usize {
        (j + 1) * self.stride + i + 1
    }

    fn uniform(&self) -> bool {
        self.east.is_empty()
    }

    /// The columns of row `j` that a pass goes over (see [`Level::spans`]).
    fn span(&self, j: usize) -> std::ops::Range<usize> {
        let [lo, hi] = self.spans[j / 2];
        lo..hi
    }

    /// The fine level: 4 on the diagonal of every unknown, 1 between adjacent unknowns.
    fn finest(grid: &Grid, unknown: &[bool]) -> Self {
        let (nx, ny) = (grid.nx, grid.ny);
        let stride = nx + 2;
        let n = stride * (ny + 3);
        let mut inv_diag = vec![0.0; n];
        for j in 0..ny {
            let k = (j + 1) * stride + 1;
            let row = &unknown[j * nx..(j + 1) * nx];
            for (inv, u) in inv_diag[k..k + nx].iter_mut().zip(row) {
                *inv = if *u { 0.25 } else { 0.0 };
            }
        }
        let unknowns = unknown.iter().filter(|u| **u).count();
        Self {
            nx,
            ny,
            stride,
            inv_diag,
            diag: Vec::new(),
            east: Vec::new(),
            north: Vec::new(),
            unknowns,
            spans: spans(nx, ny, |i, j| unknown[j * nx + i]),
        }
    }

    /// The diagonal at padded cell `k` (either layout).
    fn diag_at(&self, k: usize) -> f32 {
        if self.uniform() {
            4.0 * self.active(k)
        } else {
            self.diag[k]
        }
    }

    /// Whether padded cell `k` is active, as 1 or 0.
    fn active(&self, k: usize) -> f32 {
        if self.inv_diag[k] != 0.0 { 1.0 } else { 0.0 }
    }

    /// East coupling of padded cell `k` (either layout).
    fn east_at(&self, k: usize) -> f32 {
        if self.uniform() {
            self.active(k) * self.active(k + 1)
        } else {
            self.east[k]
        }
    }

    /// North coupling of padded cell `k` (either layout).
    fn north_at(&self, k: usize) -> f32 {
        if self.uniform() {
            self.active(k) * self.active(k + self.stride)
        } else {
            self.north[k]
        }
    }

    /// The Galerkin coarse level `R A P` for piecewise-constant `P` (coarse cell `(I, J)` owns
    /// fine cells `(2I..2I+1, 2J..2J+1)`), `R = Pᵀ`: a coarse cell's diagonal is the sum of
    /// its children's less twice the couplings inside it (once for each ordering of a pair),
    /// and two coarse cells couple by the sum of the fine couplings across their shared side.
    /// Children beyond the fine grid fall in its inactive ring and add nothing.
    fn coarsen(&self) -> Self {
        let (nx, ny) = (self.nx.div_ceil(2), self.ny.div_ceil(2));
        let stride = nx + 2;
        let n = stride * (ny + 3);
        let (mut diag, mut east, mut north) = (vec![0.0f32; n], vec![0.0; n], vec![0.0; n]);
        let s = self.stride;
        for j in 0..ny {
            for i in 0..nx {
                let c = (j + 1) * stride + i + 1;
                // Children: a (2I, 2J), b (2I+1, 2J), d (2I, 2J+1), e (2I+1, 2J+1).
                let a = self.pad(2 * i, 2 * j);
                let (b, d, e) = (a + 1, a + s, a + s + 1);
                let inside =
                    self.east_at(a) + self.east_at(d) + self.north_at(a) + self.north_at(b);
                let sum = self.diag_at(a) + self.diag_at(b) + self.diag_at(d) + self.diag_at(e);
                // Piecewise-constant transfers make R A P twice the rediscretized 2h stencil,
                // which under-corrects smooth errors; the factor restores its size.
                diag[c] = COARSE_SCALE * (sum - 2.0 * inside);
                east[c] = COARSE_SCALE * (self.east_at(b) + self.east_at(e));
                north[c] = COARSE_SCALE * (self.north_at(d) + self.north_at(e));
            }
        }
        let inv_diag: Vec<f32> = diag
            .iter()
            .map(|&d| if d > 0.0 { 1.0 / d } else { 0.0 })
            .collect();
        let unknowns = diag.iter().filter(|&&d| d > 0.0).count();
        let spans = spans(nx, ny, |i, j| diag[(j + 1) * stride + i + 1] > 0.0);
        Self {
            nx,
            ny,
            stride,
            inv_diag,
            diag,
            east,
            north,
            unknowns,
            spans,
        }
    }

    /// One Gauss-Seidel update of the cells of colour `c` (`(i + j) % 2 == c`) in row `j`,
    /// for `A x = b`.
    ///
    /// Cells of one colour depend only on cells of the other, so the row is computed whole
    /// into `t` from the old values and the other colour's cells are kept (`keep`, an
    /// alternating 0/1 pattern): twice the arithmetic of updating every other cell, but in
    /// straight-line loops the compiler vectorizes, which is several times faster.
    #[inline(always)]
    fn relax_row(&self, c: usize, j: usize, x: &mut [f32], b: &[f32], t: &mut [f32], keep: &Keep) {
        let (cols, s) = (self.span(j), self.stride);
        let (k, n) = (self.pad(cols.start, j), cols.len());
        let t = &mut t[..n];
        let keep = &keep[(c + j) % 2][cols];
        {
            let (mid, west, east) = (&x[k..k + n], &x[k - 1..k - 1 + n], &x[k + 1..k + 1 + n]);
            let (up, down) = (&x[k + s..k + s + n], &x[k - s..k - s + n]);
            let (b, d) = (&b[k..k + n], &self.inv_diag[k..k + n]);
            if self.uniform() {
                for i in 0..n {
                    let new = d[i] * (b[i] + west[i] + east[i] + up[i] + down[i]);
                    t[i] = keep[i] * mid[i] + (1.0 - keep[i]) * new;
                }
            } else {
                let (e, w) = (&self.east[k..k + n], &self.east[k - 1..k - 1 + n]);
                let (nn, sn) = (&self.north[k..k + n], &self.north[k - s..k - s + n]);
                for i in 0..n {
                    let new = d[i]
                        * (b[i]
                            + e[i] * east[i]
                            + w[i] * west[i]
                            + nn[i] * up[i]
                            + sn[i] * down[i]);
                    t[i] = keep[i] * mid[i] + (1.0 - keep[i]) * new;
                }
            }
        }
        x[k..k + n].copy_from_slice(t);
    }

    /// [`Level::relax_row`] when `x` is 0: `x = b / diagonal` on colour `c`, 0 elsewhere. It
    /// reads nothing of `x`, so a cycle that starts from 0 need not clear it first.
    #[inline(always)]
    fn relax_row_from_zero(&self, c: usize, j: usize, x: &mut [f32], b: &[f32], keep: &Keep) {
        let cols = self.span(j);
        let (k, n) = (self.pad(cols.start, j), cols.len());
        let keep = &keep[(c + j) % 2][cols];
        let (x, b, d) = (&mut x[k..k + n], &b[k..k + n], &self.inv_diag[k..k + n]);
        for i in 0..n {
            x[i] = (1.0 - keep[i]) * d[i] * b[i];
        }
    }

    /// The Gauss-Seidel passes `colours` (one colour each, in order) over the whole level, as a
    /// wavefront: at step `s`, pass `p` updates row `s − p`. That is exactly the passes one
    /// after another (a row's update reads only rows beside it, which every earlier pass has
    /// already updated and no later pass has touched yet), but the rows in flight stay in
    /// cache, so the level is read from memory once instead of once per pass. `before(r)` runs
    /// before any pass reads row `r`; `after(r)` once every pass is done with rows `r − 1`,
    /// `r` and `r + 1`. With `zero_start`, the first pass takes `x` as 0, whatever it holds.
    #[inline(always)]
    fn sweep(
        &self,
        colours: &[usize],
        zero_start: bool,
        (x, b): (&mut [f32], &[f32]),
        (t, keep): (&mut [f32], &Keep),
        mut before: impl FnMut(usize, &mut [f32]),
        mut after: impl FnMut(usize, &[f32]),
    ) {
        let passes = colours.len();
        if self.ny > 0 {
            before(0, x);
        }
        for step in 0..self.ny + passes + 1 {
            if step + 1 < self.ny {
                before(step + 1, x);
            }
            for (p, &c) in colours.iter().enumerate() {
                if let Some(j) = step.checked_sub(p).filter(|&j| j < self.ny) {
                    if p == 0 && zero_start {
                        self.relax_row_from_zero(c, j, x, b, keep);
                    } else {
                        self.relax_row(c, j, x, b, t, keep);
                    }
                }
            }
            if let Some(j) = step.checked_sub(passes).filter(|&j| j < self.ny) {
                after(j, x);
            }
        }
    }

    /// The residual `b − A x` of row `j` into `row` (0 on inactive cells).
    #[inline(always)]
    fn residual_row(&self, j: usize, x: &[f32], b: &[f32], row: &mut [f32]) {
        let (cols, s) = (self.span(j), self.stride);
        let (k, n) = (self.pad(cols.start, j), cols.len());
        let row = &mut row[..n];
        let (mid, west, east) = (&x[k..k + n], &x[k - 1..k - 1 + n], &x[k + 1..k + 1 + n]);
        let (up, down) = (&x[k + s..k + s + n], &x[k - s..k - s + n]);
        if self.uniform() {
            let (b, d) = (&b[k..k + n], &self.inv_diag[k..k + n]);
            for i in 0..n {
                let ax = 4.0 * mid[i] - west[i] - east[i] - up[i] - down[i];
                row[i] = if d[i] != 0.0 { b[i] - ax } else { 0.0 };
            }
        } else {
            let (b, d) = (&b[k..k + n], &self.diag[k..k + n]);
            let (e, w) = (&self.east[k..k + n], &self.east[k - 1..k - 1 + n]);
            let (nn, sn) = (&self.north[k..k + n], &self.north[k - s..k - s + n]);
            for i in 0..n {
                let ax = d[i] * mid[i]
                    - e[i] * east[i]
                    - w[i] * west[i]
                    - nn[i] * up[i]
                    - sn[i] * down[i];
                row[i] = b[i] - ax;
            }
        }
    }
}

/// The exact solve of the coarsest level: a dense Cholesky factor of its matrix.
struct Coarsest {
    /// Padded index of each unknown.
    cells: Vec<usize>,
    /// Lower-triangular factor, row-major `n × n`; a non-positive pivot (which an SPD matrix
    /// never has, but rounding could) leaves its unknown at 0.
    factor: Vec<f64>,
}

impl Coarsest {
    fn new(level: &Level) -> Self {
        let cells: Vec<usize> = (0..level.ny)
            .flat_map(|j| (0..level.nx).map(move |i| (i, j)))
            .map(|(i, j)| level.pad(i, j))
            .filter(|&k| level.active(k) != 0.0)
            .collect();
        let n = cells.len();
        let mut a = vec![0.0f64; n * n];
        for (r, &k) in cells.iter().enumerate() {
            for (c, &m) in cells.iter().enumerate() {
                a[r * n + c] = if k == m {
                    f64::from(level.diag_at(k))
                } else if m == k + 1 {
                    -f64::from(level.east_at(k))
                } else if k == m + 1 {
                    -f64::from(level.east_at(m))
                } else if m == k + level.stride {
                    -f64::from(level.north_at(k))
                } else if k == m + level.stride {
                    -f64::from(level.north_at(m))
                } else {
                    0.0
                };
            }
        }
        // In-place Cholesky: a = L Lᵀ, L in the lower triangle.
        for c in 0..n {
            let mut pivot = a[c * n + c];
            for p in 0..c {
                pivot -= a[c * n + p] * a[c * n + p];
            }
            let pivot = if pivot > 0.0 { pivot.sqrt() } else { 0.0 };
            a[c * n + c] = pivot;
            for r in c + 1..n {
                let mut v = a[r * n + c];
                for p in 0..c {
                    v -= a[r * n + p] * a[c * n + p];
                }
                a[r * n + c] = if pivot > 0.0 { v / pivot } else { 0.0 };
            }
        }
        Self { cells, factor: a }
    }

    /// `x = A⁻¹ b` on the coarsest level.
    fn solve(&self, x: &mut [f32], b: &[f32], scratch: &mut Vec<f64>) {
        let n = self.cells.len();
        let l = &self.factor;
        scratch.clear();
        scratch.extend(self.cells.iter().map(|&k| f64::from(b[k])));
        let y = scratch;
        for r in 0..n {
            let mut v = y[r];
            for p in 0..r {
                v -= l[r * n + p] * y[p];
            }
            y[r] = if l[r * n + r] > 0.0 {
                v / l[r * n + r]
            } else {
                0.0
            };
        }
        for r in (0..n).rev() {
            let mut v = y[r];
            for p in r + 1..n {
                v -= l[p * n + r] * y[p];
            }
            y[r] = if l[r * n + r] > 0.0 {
                v / l[r * n + r]
            } else {
                0.0
            };
        }
        for (&k, &v) in self.cells.iter().zip(y.iter()) {
            x[k] = v as f32;
        }
    }
}

/// The hierarchy and its work vectors.
struct Hierarchy {
    levels: Vec<Level>,
    coarsest: Coarsest,
    /// Per level: solution and right-hand side.
    work: Vec<[Vec<f32>; 2]>,
    /// One row of relaxed values.
    row: Vec<f32>,
    /// One row of residuals, or of prolonged corrections.
    residual: Vec<f32>,
    /// Which cells a relaxation keeps.
    keep: Keep,
    /// The coarsest solve's scratch.
    scratch: Vec<f64>,
}

impl Hierarchy {
    fn new(grid: &Grid, unknown: &[bool]) -> Self {
        let mut levels = vec![Level::finest(grid, unknown)];
        loop {
            let last = levels.last().expect("one level");
            if last.unknowns <= COARSEST || (last.nx <= 2 && last.ny <= 2) {
                break;
            }
            let coarse = last.coarsen();
            levels.push(coarse);
        }
        let coarsest = Coarsest::new(levels.last().expect("one level"));
        let work = levels
            .iter()
            .map(|l| [vec![0.0; l.len()], vec![0.0; l.len()]])
            .collect();
        Self {
            row: vec![0.0; grid.nx + 2],
            residual: vec![0.0; grid.nx + 2],
            keep: [0, 1].map(|q| {
                (0..grid.nx + 1)
                    .map(|i| if i % 2 == q { 0.0 } else { 1.0 })
                    .collect()
            }),
            levels,
            coarsest,
            work,
            scratch: Vec::new(),
        }
    }

    /// `z ≈ A⁻¹ r`: one cycle from a zero guess. The fine right-hand side is `work[0][1]`,
    /// which the caller fills; the result is left in `work[0][0]`. Returns `z · r`.
    fn precondition(&mut self) -> f64 {
        self.cycle(0, true)
    }

    /// One cycle on level `l`, from 0 (`zero_start`, whatever `x` holds) or from the current
    /// `x` of that level; returns `x · b` of the result on the finest level, else 0.
    fn cycle(&mut self, l: usize, zero_start: bool) -> f64 {
        if l + 1 == self.levels.len() {
            let [x, b] = &mut self.work[l];
            self.coarsest.solve(x, b, &mut self.scratch);
            return if l == 0 { dot(x, b) } else { 0.0 };
        }
        self.smooth_and_restrict(l, zero_start);
        for visit in 0..VISITS {
            self.cycle(l + 1, visit == 0);
        }
        self.prolong_and_smooth(l)
    }

    /// Pre-smoothing on level `l` (red then black, `SWEEPS` times), then its residual summed
    /// into level `l + 1`'s right-hand side (each coarse cell sums its children's). One
    /// wavefront does it all.
    fn smooth_and_restrict(&mut self, l: usize, zero_start: bool) {
        let (fine_work, coarse_work) = self.work.split_at_mut(l + 1);
        let [x, b] = &mut fine_work[l];
        let (level, coarse) = (&self.levels[l], &self.levels[l + 1]);
        let coarse_b = &mut coarse_work[0][1];
        let (t, residual, keep) = (&mut self.row, &mut self.residual, &self.keep);
        let colours = [[0, 1]; SWEEPS];
        let colours = colours.as_flattened();
        wide(
            #[inline(always)]
            || {
                level.sweep(
                    colours,
                    zero_start,
                    (x, b),
                    (t, keep),
                    |_, _| {},
                    #[inline(always)]
                    |j, x| {
                        let cols = level.span(j);
                        let residual = &mut residual[..cols.len()];
                        level.residual_row(j, x, b, residual);
                        let base = coarse.pad(cols.start / 2, j / 2);
                        let parents = &mut coarse_b[base..base + cols.len().div_ceil(2)];
                        // The even row of a pair sets its parents, the odd one adds to them.
                        let first = if j % 2 == 0 { 0.0 } else { 1.0 };
                        let pairs = residual.chunks_exact(2);
                        if let (Some(r), Some(c)) = (pairs.remainder().first(), parents.last_mut())
                        {
                            *c = first * *c + r;
                        }
                        for (c, r) in parents.iter_mut().zip(pairs) {
                            *c = first * *c + (r[0] + r[1]);
                        }
                    },
                )
            },
        );
    }

    /// Every active cell of level `l` gets its coarse cell's correction; then post-smoothing
    /// (black then red, `SWEEPS` times). One wavefront does it all. Returns `x · b` on the
    /// finest level (CG needs it, and each row is still in cache when it is final), else 0.
    fn prolong_and_smooth(&mut self, l: usize) -> f64 {
        let (level, coarse) = (&self.levels[l], &self.levels[l + 1]);
        let (fine_work, coarse_work) = self.work.split_at_mut(l + 1);
        let [x, b] = &mut fine_work[l];
        let correction = &coarse_work[0][0];
        let (t, expanded, keep) = (&mut self.row, &mut self.residual, &self.keep);
        let colours = [[1, 0]; SWEEPS];
        let colours = colours.as_flattened();
        let mut xb = 0.0;
        wide(
            #[inline(always)]
            || {
                level.sweep(
                    colours,
                    false,
                    (x, b),
                    (t, keep),
                    #[inline(always)]
                    |j, x| {
                        let cols = level.span(j);
                        let (start, n) = (level.pad(cols.start, j), cols.len());
                        let base = coarse.pad(cols.start / 2, j / 2);
                        let parents = &correction[base..base + n.div_ceil(2)];
                        let expanded = &mut expanded[..2 * parents.len()];
                        for (pair, c) in expanded.chunks_exact_mut(2).zip(parents) {
                            pair[0] = *c;
                            pair[1] = *c;
                        }
                        let cells = &mut x[start..start + n];
                        let active = &level.inv_diag[start..start + n];
                        for ((x, a), c) in cells.iter_mut().zip(active).zip(&expanded[..n]) {
                            *x += if *a != 0.0 { *c } else { 0.0 };
                        }
                    },
                    #[inline(always)]
                    |j, x| {
                        if l == 0 {
                            let cols = level.span(j);
                            let (k, n) = (level.pad(cols.start, j), cols.len());
                            xb += dot(&x[k..k + n], &b[k..k + n]);
                        }
                    },
                )
            },
        );
        xb
    }
}

/// `A q` on row `j` of the fine level, in f64, into `out`: the 5-point stencil on every cell,
/// so it is `A q` on the active cells only (`q` is 0 on the others). `q` holds f32 values, so
/// the sums are exact in f64.
#[inline(always)]
fn apply_row(level: &Level, q: &[f32], j: usize, out: &mut [f64]) {
    let (cols, s) = (level.span(j), level.stride);
    let (k, n) = (level.pad(cols.start, j), cols.len());
    let (mid, west, east) = (&q[k..k + n], &q[k - 1..k - 1 + n], &q[k + 1..k + 1 + n]);
    let (up, down) = (&q[k + s..k + s + n], &q[k - s..k - s + n]);
    let out = &mut out[..n];
    for i in 0..n {
        out[i] = 4.0 * f64::from(mid[i])
            - f64::from(west[i])
            - f64::from(east[i])
            - f64::from(up[i])
            - f64::from(down[i]);
    }
}

/// `a · b` in f64 (either may hold f32), summed in four interleaved partial sums (a fixed
/// order, so the result does not depend on the machine) that the compiler can keep in vector
/// registers.
#[inline(always)]
fn dot<A: Copy + Into<f64>, B: Copy + Into<f64>>(a: &[A], b: &[B]) -> f64 {
    let mut sums = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = a4
        .remainder()
        .iter()
        .zip(b4.remainder())
        .map(|(x, y)| (*x).into() * (*y).into())
        .sum();
    for (a, b) in a4.zip(b4) {
        for l in 0..4 {
            sums[l] += a[l].into() * b[l].into();
        }
    }
    (sums[0] + sums[1]) + (sums[2] + sums[3]) + tail
}

/// `r · scale` rounded to f32 for the cycle, 0 when too small for f32 to hold at full precision.
#[inline(always)]
fn for_cycle(r: f64, scale: f64) -> f32 {
    let v = (r * scale) as f32;
    if v.abs() < FLUSH { 0.0 } else { v }
}

/// The CG vectors on the fine level's padded layout. The search direction is kept in f32 as
/// `q = scale · p`, scaled like the cycle's output it is made from (see [`solve`]); the solution
/// `x` and the residual `r` stay in f64, since they carry the solution's precision.
struct Krylov {
    x: Vec<f64>,
    r: Vec<f64>,
    q: Vec<f32>,
    /// One row of `A q`.
    row: Vec<f64>,
}

impl Krylov {
    /// The new direction `q = z + γ q` and its curvature `q · A q`: one pass, `A q` trailing a
    /// row behind the rows it reads. (`q` is 0 on inactive cells, so they add nothing to the
    /// sum whatever the stencil gives there.)
    fn direct(&mut self, level: &Level, z: &[f32], gamma: f32) -> f64 {
        let Self { q, row, .. } = self;
        wide(
            #[inline(always)]
            || {
                let mut qaq = 0.0;
                for j in 0..level.ny + 1 {
                    if j < level.ny {
                        let cols = level.span(j);
                        let (k, n) = (level.pad(cols.start, j), cols.len());
                        for (q, z) in q[k..k + n].iter_mut().zip(&z[k..k + n]) {
                            *q = z + gamma * *q;
                        }
                    }
                    if j > 0 {
                        apply_row(level, q, j - 1, row);
                        let cols = level.span(j - 1);
                        let (k, n) = (level.pad(cols.start, j - 1), cols.len());
                        qaq += dot(&q[k..k + n], &row[..n]);
                    }
                }
                qaq
            },
        )
    }

    /// The step `x += c q`, `r −= c A q` (on the active cells), the new `r · r`, and
    /// `out = r · scale` in f32 (the next cycle's right-hand side): one pass.
    fn step(&mut self, level: &Level, c: f64, scale: f64, out: &mut [f32]) -> f64 {
        let Self { x, r, q, row } = self;
        wide(
            #[inline(always)]
            || {
                let mut rr = 0.0;
                for j in 0..level.ny {
                    apply_row(level, q, j, row);
                    let cols = level.span(j);
                    let (k, n) = (level.pad(cols.start, j), cols.len());
                    let (x, r, q) = (&mut x[k..k + n], &mut r[k..k + n], &q[k..k + n]);
                    let (d, out) = (&level.inv_diag[k..k + n], &mut out[k..k + n]);
                    for i in 0..n {
                        x[i] += c * f64::from(q[i]);
                        r[i] -= if d[i] != 0.0 { c * row[i] } else { 0.0 };
                        out[i] = for_cycle(r[i], scale);
                    }
                    rr += dot(r, r);
                }
                rr
            },
        )
    }
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
    // x: the starting guess; `fixed`: the Dirichlet values (cells outside the grid are its ring
    // of zeros), whose sum around each unknown is the right-hand side b. `fixed` then becomes
    // the residual: fresh memory costs page faults.
    let mut x = vec![0.0; n];
    let mut fixed = vec![0.0; n];
    for j in 0..ny {
        let (k, row) = (fine.pad(0, j), j * nx..(j + 1) * nx);
        for (((x, f), v), u) in x[k..k + nx]
            .iter_mut()
            .zip(&mut fixed[k..k + nx])
            .zip(&values[row.clone()])
            .zip(&unknown[row])
        {
            (*x, *f) = if *u { (*v, 0.0) } else { (0.0, *v) };
        }
    }
    // r = b − A x row by row, trailing two rows behind so that `fixed` (read up to a row ahead)
    // can be overwritten with r.
    let (mut bb, mut rr) = (0.0, 0.0);
    let mut rows = [vec![0.0; nx], vec![0.0; nx]];
    for j in 0..ny + 2 {
        if j >= 2 {
            let k = fine.pad(0, j - 2);
            fixed[k..k + nx].copy_from_slice(&rows[j % 2]);
        }
        if j < ny {
            let k = fine.pad(0, j);
            let (west, east) = (&fixed[k - 1..k - 1 + nx], &fixed[k + 1..k + 1 + nx]);
            let (up, down) = (
                &fixed[k + stride..k + stride + nx],
                &fixed[k - stride..k - stride + nx],
            );
            let (mid, xw, xe) = (&x[k..k + nx], &x[k - 1..k - 1 + nx], &x[k + 1..k + 1 + nx]);
            let (xu, xd) = (
                &x[k + stride..k + stride + nx],
                &x[k - stride..k - stride + nx],
            );
            let d = &fine.inv_diag[k..k + nx];
            let row = &mut rows[j % 2];
            let mut b_row = 0.0;
            for i in 0..nx {
                let (b, r) = if d[i] != 0.0 {
                    let b = west[i] + east[i] + up[i] + down[i];
                    (b, b - (4.0 * mid[i] - xw[i] - xe[i] - xu[i] - xd[i]))
                } else {
                    (0.0, 0.0)
                };
                b_row += b * b;
                row[i] = r;
            }
            bb += b_row;
            rr += dot(row, row);
        }
    }
    let norm_b = bb.sqrt();
    let relative = |rr: f64| {
        if norm_b > 0.0 {
            rr.sqrt() / norm_b
        } else {
            rr.sqrt()
        }
    };
    let mut stats = Stats {
        iterations: 0,
        relative_residual: relative(rr),
    };
    let mut cg = Krylov {
        x,
        r: fixed,
        q: vec![0.0; n],
        row: vec![0.0; nx],
    };
    // Preconditioned CG (z = M r, p = z + β p, x += α p, r −= α A p, α = r·z / p·A p,
    // β = r_next·z_next / r·z), with the cycle's right-hand side r scaled by `scale`, about
    // 1 / ‖r‖, so that f32 sees no extreme values. The cycle then returns `scale · z`, and the
    // direction is kept as `q = scale · p`, which is also O(1): `p · A p = q · A q / scale²`,
    // and the next `q = scale' · z' + β (scale' / scale) q`.
    if stats.relative_residual > tolerance {
        let mut scale = 1.0 / rr.sqrt();
        wide(|| {
            for (o, r) in h.work[0][1].iter_mut().zip(&cg.r) {
                *o = for_cycle(*r, scale);
            }
        });
        let mut rz = h.precondition() / (scale * scale);
        let mut gamma = 0.0;
        while stats.iterations < max_iterations {
            stats.iterations += 1;
            let pap = cg.direct(&h.levels[0], &h.work[0][0], gamma) / (scale * scale);
            if pap.is_nan() || pap <= 0.0 {
                break;
            }
            let alpha = rz / pap;
            let next_scale = 1.0 / rr.sqrt();
            rr = cg.step(&h.levels[0], alpha / scale, next_scale, &mut h.work[0][1]);
            stats.relative_residual = relative(rr);
            if stats.relative_residual <= tolerance {
                break;
            }
            let rz_next = h.precondition() / (next_scale * next_scale);
            gamma = (rz_next / rz * next_scale / scale) as f32;
            (rz, scale) = (rz_next, next_scale);
        }
    }
    for j in 0..ny {
        let (k, row) = (h.levels[0].pad(0, j), j * nx..(j + 1) * nx);
        for ((v, x), u) in values[row.clone()]
            .iter_mut()
            .zip(&cg.x[k..k + nx])
            .zip(&unknown[row])
        {
            if *u {
                *v = *x;
            }
        }
    }
    stats
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

    /// CG updates its residual rather than recomputing it, from a search direction rounded to
    /// f32: the residual recomputed in f64 from the returned field must still be the one
    /// reported, to far below f32's rounding.
    #[test]
    fn the_reported_residual_is_the_true_residual() {
        let n = 128;
        let (grid, unknown, mut w) = divided_room(n);
        let stats = solve(&grid, &unknown, &mut w, 1e-12, 100);
        assert!(stats.relative_residual <= 1e-12, "{stats:?}");
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
        let truth = (rr / bb).sqrt();
        assert!(
            (truth - stats.relative_residual).abs() <= 1e-3 * stats.relative_residual,
            "true {truth:e}, reported {:e}",
            stats.relative_residual
        );
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
