//! A multigrid-preconditioned conjugate gradient solver for Laplace's equation on a masked
//! (x, y, θ) grid, periodic in θ, in the body's metric: the 7-point system
//!
//! `Σ_xy (u_k − u_n) + w_θ Σ_θ (u_k − u_n) = 0`, `w_θ = (h / (ρ Δθ))²`,
//!
//! is `h² ∇²u = 0` for the coordinates `(x, y, ρθ)` (see `pose/mod.rs` for the choice of ρ).
//! Cells that are not unknown hold Dirichlet values; cells beyond the box in x and y count as 0.
//!
//! It follows the plane's solver (`field/multigrid`), in three dimensions: CG in f64, one W-cycle
//! in f32 as the preconditioner, aggregation of 2 × 2 × 2 cells (2 × 2 × 1 once the heading
//! axis cannot be halved to an even count) with Galerkin coarse operators `R A P` scaled per
//! axis to the rediscretized stencil, red-black Gauss-Seidel on every level (red then black
//! before the coarse correction, black then red after it, so the cycle is symmetric), and a dense
//! Cholesky solve of the coarsest level. The heading count is even on every level (or 1), so the
//! periodic axis keeps the red-black colouring: a cell's neighbours all have the other colour.
//!
//! The passes run over heading slabs in parallel (rayon): a colour pass updates the even slabs
//! and then the odd ones, so that no slab is written while a neighbour reads it, and the result
//! is the same as one sequential pass whatever the threads. Sums are taken per slab and added in
//! slab order, so a solve is deterministic.

// The row loops index several slices of one length with one counter: the form the compiler
// vectorizes without bounds checks, and the one that reads like the stencil it computes.
#![allow(clippy::needless_range_loop)]

use rayon::prelude::*;

use super::super::multigrid::dense;
use super::super::multigrid::kernels::wide;

/// Smoothing sweeps (red and black) before and after each coarse correction.
const SWEEPS: usize = 2;
/// A level with at most this many active cells is solved exactly.
const COARSEST: usize = 400;
/// Levels smaller than this (padded cells) run their passes on one thread: rayon's hand-offs
/// cost more than they save there.
const PARALLEL: usize = 1 << 16;
/// Factor on a Galerkin coupling along an axis that was halved (piecewise-constant transfers
/// make it twice the rediscretized one, see `multigrid/level.rs`); 1 along an axis that was not.
const HALVED: f32 = 0.5;

/// The size of a 3-D grid: `nx × ny` cells per slab, `nt` heading slabs (periodic).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dims {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Heading slabs (periodic).
    pub nt: usize,
}

impl Dims {
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny * self.nt
    }

    /// Whether there are no cells.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The index of `(i, j, k)`: slab after slab, then rows, then columns.
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.ny + j) * self.nx + i
    }

    /// The six neighbours of cell `(i, j, k)` with their couplings (1 along x and y, `w_theta`
    /// along θ, which wraps): the neighbours beyond the box in x or y are left out.
    pub fn neighbours(
        &self,
        (i, j, k): (usize, usize, usize),
        w_theta: f64,
    ) -> impl Iterator<Item = (usize, f64)> + use<> {
        let d = *self;
        let (up, down) = ((k + 1) % d.nt, (k + d.nt - 1) % d.nt);
        let xy = [
            (i > 0).then(|| d.index(i - 1, j, k)),
            (i + 1 < d.nx).then(|| d.index(i + 1, j, k)),
            (j > 0).then(|| d.index(i, j - 1, k)),
            (j + 1 < d.ny).then(|| d.index(i, j + 1, k)),
        ];
        let theta = [d.index(i, j, up), d.index(i, j, down)];
        (xy.into_iter().flatten().map(|n| (n, 1.0)))
            .chain(theta.into_iter().map(move |n| (n, w_theta)))
    }
}

/// How a solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Conjugate gradient iterations (one W-cycle each).
    pub iterations: usize,
    /// Final `‖b − A u‖ / ‖b‖` (0 when the right-hand side is 0).
    pub relative_residual: f64,
}

/// One level: a grid padded by a ring of inactive cells in x and y (row stride `nx + 2`, slab
/// stride `(nx + 2)(ny + 2)`), with couplings to the next cell along x, y and θ (wrapping), and
/// the diagonal split into its xy and θ parts (the coarsening needs them apart).
struct Level {
    dims: Dims,
    stride: usize,
    slab: usize,
    inv_diag: Vec<f32>,
    diag_xy: Vec<f32>,
    diag_t: Vec<f32>,
    east: Vec<f32>,
    north: Vec<f32>,
    up: Vec<f32>,
    active: usize,
}

impl Level {
    fn len(&self) -> usize {
        self.slab * self.dims.nt
    }

    fn pad(&self, i: usize, j: usize, k: usize) -> usize {
        k * self.slab + (j + 1) * self.stride + i + 1
    }

    /// The slabs above and below `k` (periodic).
    fn around(&self, k: usize) -> (usize, usize) {
        let nt = self.dims.nt;
        ((k + 1) % nt, (k + nt - 1) % nt)
    }

    /// A level of `dims` with no active cell.
    fn empty(dims: Dims) -> Self {
        let (stride, slab) = (dims.nx + 2, (dims.nx + 2) * (dims.ny + 2));
        let n = slab * dims.nt;
        Self {
            dims,
            stride,
            slab,
            inv_diag: vec![0.0; n],
            diag_xy: vec![0.0; n],
            diag_t: vec![0.0; n],
            east: vec![0.0; n],
            north: vec![0.0; n],
            up: vec![0.0; n],
            active: 0,
        }
    }

    /// The finest level of the `unknown` cells, with coupling `w_theta` along θ.
    fn finest(dims: Dims, unknown: &[bool], w_theta: f32) -> Self {
        let mut level = Self::empty(dims);
        let on = |i: usize, j: usize, k: usize| unknown[dims.index(i, j, k)];
        for k in 0..dims.nt {
            let up = (k + 1) % dims.nt;
            for j in 0..dims.ny {
                for i in 0..dims.nx {
                    if !on(i, j, k) {
                        continue;
                    }
                    let p = level.pad(i, j, k);
                    level.active += 1;
                    level.diag_xy[p] = 4.0;
                    level.diag_t[p] = 2.0 * w_theta;
                    level.inv_diag[p] = 1.0 / (4.0 + 2.0 * w_theta);
                    if i + 1 < dims.nx && on(i + 1, j, k) {
                        level.east[p] = 1.0;
                    }
                    if j + 1 < dims.ny && on(i, j + 1, k) {
                        level.north[p] = 1.0;
                    }
                    if on(i, j, up) {
                        level.up[p] = w_theta;
                    }
                }
            }
        }
        level
    }

    /// The Galerkin coarse level for aggregates of 2 × 2 cells in x and y and 2 slabs in θ
    /// (1 when the slab count halved would be odd and above 1), each coupling scaled by
    /// [`HALVED`] along the axes that were halved. A coarse cell's diagonal along an axis is its
    /// children's less twice the couplings between them along it.
    fn coarsen(&self) -> Self {
        let d = self.dims;
        let halve_t = d.nt.is_multiple_of(2) && (d.nt == 2 || (d.nt / 2).is_multiple_of(2));
        let dims = Dims {
            nx: d.nx.div_ceil(2),
            ny: d.ny.div_ceil(2),
            nt: if halve_t { d.nt / 2 } else { d.nt },
        };
        let mut c = Self::empty(dims);
        let scale_t = if halve_t { HALVED } else { 1.0 };
        for kc in 0..dims.nt {
            let slabs: &[usize] = if halve_t {
                &[2 * kc, 2 * kc + 1]
            } else {
                &[kc]
            };
            for jc in 0..dims.ny {
                for ic in 0..dims.nx {
                    let (mut sum_xy, mut sum_t, mut inside_xy, mut inside_t) = (0.0, 0.0, 0.0, 0.0);
                    let (mut east, mut north, mut up) = (0.0, 0.0, 0.0);
                    for &k in slabs {
                        for (dj, j) in [(0, 2 * jc), (1, 2 * jc + 1)] {
                            for (di, i) in [(0, 2 * ic), (1, 2 * ic + 1)] {
                                // Children beyond the fine grid are in its inactive ring.
                                let p = k * self.slab + (j + 1) * self.stride + i + 1;
                                sum_xy += self.diag_xy[p];
                                sum_t += self.diag_t[p];
                                if di == 0 {
                                    inside_xy += self.east[p];
                                } else {
                                    east += self.east[p];
                                }
                                if dj == 0 {
                                    inside_xy += self.north[p];
                                } else {
                                    north += self.north[p];
                                }
                                // Along θ: the coupling to the next slab is inside the
                                // aggregate from its first slab, and from its second too when
                                // the two are all there is (it wraps back to the first).
                                let inner = halve_t && (k % 2 == 0 || d.nt == 2);
                                if inner {
                                    inside_t += self.up[p];
                                } else {
                                    up += self.up[p];
                                }
                            }
                        }
                    }
                    let diag_xy = HALVED * (sum_xy - 2.0 * inside_xy);
                    let diag_t = scale_t * (sum_t - 2.0 * inside_t);
                    let p = c.pad(ic, jc, kc);
                    c.diag_xy[p] = diag_xy;
                    c.diag_t[p] = diag_t;
                    c.east[p] = HALVED * east;
                    c.north[p] = HALVED * north;
                    c.up[p] = if dims.nt == 1 { 0.0 } else { scale_t * up };
                    let diag = diag_xy + diag_t;
                    if diag > 0.0 {
                        c.inv_diag[p] = 1.0 / diag;
                        c.active += 1;
                    }
                }
            }
        }
        c
    }

    /// `(A x)_p` at padded cell `p` of slab `k`, in f64.
    fn apply_at(&self, x: &[f32], p: usize, k: usize) -> f64 {
        let (up, down) = self.around(k);
        let (pu, pd) = (
            p - k * self.slab + up * self.slab,
            p - k * self.slab + down * self.slab,
        );
        let diag = f64::from(self.diag_xy[p]) + f64::from(self.diag_t[p]);
        diag * f64::from(x[p])
            - f64::from(self.east[p]) * f64::from(x[p + 1])
            - f64::from(self.east[p - 1]) * f64::from(x[p - 1])
            - f64::from(self.north[p]) * f64::from(x[p + self.stride])
            - f64::from(self.north[p - self.stride]) * f64::from(x[p - self.stride])
            - f64::from(self.up[p]) * f64::from(x[pu])
            - f64::from(self.up[pd]) * f64::from(x[pd])
    }

    /// The residual `b − A x` of row `j` of slab `k`, in f32 (0 on inactive cells: their
    /// couplings and right-hand side are 0).
    #[inline(always)]
    fn residual_row(&self, k: usize, j: usize, x: &[f32], b: &[f32], out: &mut [f32]) {
        let (nx, s) = (self.dims.nx, self.stride);
        let p = self.pad(0, j, k);
        let (up, down) = self.around(k);
        let (pu, pd) = (
            p - k * self.slab + up * self.slab,
            p - k * self.slab + down * self.slab,
        );
        let (dxy, dt) = (&self.diag_xy[p..p + nx], &self.diag_t[p..p + nx]);
        let (e, w) = (&self.east[p..p + nx], &self.east[p - 1..p - 1 + nx]);
        let (no, so) = (&self.north[p..p + nx], &self.north[p - s..p - s + nx]);
        let (u, dn) = (&self.up[p..p + nx], &self.up[pd..pd + nx]);
        let (xm, xe, xw) = (&x[p..p + nx], &x[p + 1..p + 1 + nx], &x[p - 1..p - 1 + nx]);
        let (xn, xs) = (&x[p + s..p + s + nx], &x[p - s..p - s + nx]);
        let (xu, xd) = (&x[pu..pu + nx], &x[pd..pd + nx]);
        let bb = &b[p..p + nx];
        for i in 0..nx {
            out[i] = bb[i] - (dxy[i] + dt[i]) * xm[i]
                + e[i] * xe[i]
                + w[i] * xw[i]
                + no[i] * xn[i]
                + so[i] * xs[i]
                + u[i] * xu[i]
                + dn[i] * xd[i];
        }
    }

    /// One colour pass of red-black Gauss-Seidel (`(i + j + k) % 2 == colour`) for `A x = b`,
    /// even slabs then odd ones, each half in parallel. With `from_zero`, `x` is taken as 0
    /// (nothing of it is read, so it need not be cleared).
    fn relax(&self, colour: usize, x: &mut [f32], b: &[f32], from_zero: bool) {
        let nt = self.dims.nt;
        if self.len() < PARALLEL {
            for parity in 0..2 {
                for k in (parity..nt).step_by(2) {
                    wide(
                        #[inline(always)]
                        || self.relax_slab(colour, k, x, b, from_zero),
                    );
                }
            }
            return;
        }
        for parity in 0..2 {
            let shared = Shared(x.as_mut_ptr());
            (0..nt)
                .into_par_iter()
                .filter(|k| k % 2 == parity)
                .for_each(|k| {
                    // SAFETY: this task writes only slab k; it reads slabs k ± 1, which have
                    // the other parity and are written by no task of this half-pass (with one
                    // or two slabs in all, the halves run one slab each). The vector outlives
                    // the pass, which joins before returning.
                    let x = unsafe { std::slice::from_raw_parts_mut(shared.get(), self.len()) };
                    wide(
                        #[inline(always)]
                        || self.relax_slab(colour, k, x, b, from_zero),
                    );
                });
        }
    }

    #[inline(always)]
    fn relax_slab(&self, colour: usize, k: usize, x: &mut [f32], b: &[f32], from_zero: bool) {
        let (nx, s) = (self.dims.nx, self.stride);
        let (up, down) = self.around(k);
        let (du, dd) = (
            up as isize * self.slab as isize - (k * self.slab) as isize,
            down as isize * self.slab as isize - (k * self.slab) as isize,
        );
        let mut t = vec![0.0f32; nx];
        for j in 0..self.dims.ny {
            let p = self.pad(0, j, k);
            // Columns of this colour in the row: i ≡ colour + j + k (mod 2).
            let first = (colour + j + k) % 2;
            let (pu, pd) = ((p as isize + du) as usize, (p as isize + dd) as usize);
            let d = &self.inv_diag[p..p + nx];
            let bb = &b[p..p + nx];
            if from_zero {
                let row = &mut x[p..p + nx];
                for i in 0..nx {
                    row[i] = if i % 2 == first { d[i] * bb[i] } else { 0.0 };
                }
                continue;
            }
            {
                let (e, w) = (&self.east[p..p + nx], &self.east[p - 1..p - 1 + nx]);
                let (no, so) = (&self.north[p..p + nx], &self.north[p - s..p - s + nx]);
                let (u, dn) = (&self.up[p..p + nx], &self.up[pd..pd + nx]);
                let (xm, xe, xw) = (&x[p..p + nx], &x[p + 1..p + 1 + nx], &x[p - 1..p - 1 + nx]);
                let (xn, xs) = (&x[p + s..p + s + nx], &x[p - s..p - s + nx]);
                let (xu, xd) = (&x[pu..pu + nx], &x[pd..pd + nx]);
                for i in 0..nx {
                    let new = d[i]
                        * (bb[i]
                            + e[i] * xe[i]
                            + w[i] * xw[i]
                            + no[i] * xn[i]
                            + so[i] * xs[i]
                            + u[i] * xu[i]
                            + dn[i] * xd[i]);
                    t[i] = if i % 2 == first { new } else { xm[i] };
                }
            }
            x[p..p + nx].copy_from_slice(&t);
        }
    }
}

/// A raw pointer that rayon's tasks may share (see [`Level::relax`]).
#[derive(Clone, Copy)]
struct Shared(*mut f32);
// SAFETY: the tasks that share it write disjoint slabs (see `Level::relax`).
unsafe impl Send for Shared {}
// SAFETY: as above.
unsafe impl Sync for Shared {}

impl Shared {
    fn get(self) -> *mut f32 {
        self.0
    }
}

/// The exact solve of the coarsest level (dense Cholesky of its active cells).
struct Coarsest {
    cells: Vec<usize>,
    factor: Vec<f64>,
}

impl Coarsest {
    fn new(level: &Level) -> Self {
        let d = level.dims;
        let mut cells = Vec::new();
        for k in 0..d.nt {
            for j in 0..d.ny {
                for i in 0..d.nx {
                    let p = level.pad(i, j, k);
                    if level.inv_diag[p] != 0.0 {
                        cells.push((p, k));
                    }
                }
            }
        }
        let n = cells.len();
        let position: std::collections::HashMap<usize, usize> = cells
            .iter()
            .enumerate()
            .map(|(r, &(p, _))| (p, r))
            .collect();
        let mut a = vec![0.0f64; n * n];
        let mut unit = vec![0.0f32; level.len()];
        for (c, &(p, _)) in cells.iter().enumerate() {
            // Column c of A: A applied to the unit vector of cell p, read at p's neighbours.
            unit[p] = 1.0;
            let (up, down) = level.around(p / level.slab);
            let base = p % level.slab;
            let near = [
                p,
                p + 1,
                p - 1,
                p + level.stride,
                p - level.stride,
                up * level.slab + base,
                down * level.slab + base,
            ];
            for m in near {
                if let Some(&r) = position.get(&m) {
                    a[r * n + c] = level.apply_at(&unit, m, m / level.slab);
                }
            }
            unit[p] = 0.0;
        }
        dense::cholesky(&mut a, n);
        Self {
            cells: cells.into_iter().map(|(p, _)| p).collect(),
            factor: a,
        }
    }

    fn solve(&self, x: &mut [f32], b: &[f32]) {
        let n = self.cells.len();
        let mut y: Vec<f64> = self.cells.iter().map(|&p| f64::from(b[p])).collect();
        dense::solve(&self.factor, n, &mut y);
        for (&p, v) in self.cells.iter().zip(y) {
            x[p] = v as f32;
        }
    }
}

/// The levels, with their work vectors.
struct Hierarchy {
    levels: Vec<Level>,
    coarsest: Coarsest,
    /// Per level: solution and right-hand side (level 0's right-hand side is the CG residual).
    x: Vec<Vec<f32>>,
    b: Vec<Vec<f32>>,
}

impl Hierarchy {
    fn new(fine: Level) -> Self {
        let mut levels = vec![fine];
        loop {
            let last = levels.last().expect("one level");
            let d = last.dims;
            if last.active <= COARSEST {
                break;
            }
            let next = last.coarsen();
            if next.dims == d {
                break;
            }
            levels.push(next);
        }
        let coarsest = Coarsest::new(levels.last().expect("one level"));
        let x = levels.iter().map(|l| vec![0.0; l.len()]).collect();
        let b = levels.iter().map(|l| vec![0.0; l.len()]).collect();
        Self {
            levels,
            coarsest,
            x,
            b,
        }
    }

    /// One W-cycle on level `l` for its `b`, into its `x` (from 0 when `from_zero`).
    fn cycle(&mut self, l: usize, from_zero: bool) {
        if l + 1 == self.levels.len() {
            self.coarsest.solve(&mut self.x[l], &self.b[l]);
            return;
        }
        {
            let (level, x, b) = (&self.levels[l], &mut self.x[l], &self.b[l]);
            for sweep in 0..SWEEPS {
                level.relax(0, x, b, from_zero && sweep == 0);
                level.relax(1, x, b, false);
            }
        }
        self.restrict(l);
        // Two visits of the coarser level: a W-cycle (the second continues from the first).
        self.cycle(l + 1, true);
        if l + 2 < self.levels.len() {
            self.cycle(l + 1, false);
        }
        self.prolong(l);
        let (level, x, b) = (&self.levels[l], &mut self.x[l], &self.b[l]);
        for _ in 0..SWEEPS {
            level.relax(1, x, b, false);
            level.relax(0, x, b, false);
        }
    }

    /// The coarse right-hand side of level `l + 1`: the sum of level `l`'s residual over each
    /// aggregate (`R = Pᵀ`).
    fn restrict(&mut self, l: usize) {
        let (fine, coarse) = (&self.levels[l], &self.levels[l + 1]);
        let halve_t = coarse.dims.nt != fine.dims.nt;
        let x = &self.x[l];
        let (fine_b, coarse_b) = self.b.split_at_mut(l + 1);
        let (b, out) = (&fine_b[l], &mut coarse_b[0]);
        out.par_chunks_mut(coarse.slab)
            .with_min_len(tasks(fine))
            .enumerate()
            .for_each(|(kc, out)| {
                out.fill(0.0);
                let slabs: &[usize] = if halve_t {
                    &[2 * kc, 2 * kc + 1]
                } else {
                    &[kc]
                };
                let mut row = vec![0.0f32; fine.dims.nx];
                for &k in slabs {
                    for j in 0..fine.dims.ny {
                        wide(
                            #[inline(always)]
                            || fine.residual_row(k, j, x, b, &mut row),
                        );
                        let o = (j / 2 + 1) * coarse.stride + 1;
                        for (i, r) in row.iter().enumerate() {
                            out[o + i / 2] += r;
                        }
                    }
                }
            });
    }

    /// Adds level `l + 1`'s correction to level `l` (`P`: piecewise constant).
    fn prolong(&mut self, l: usize) {
        let (fine, coarse) = (&self.levels[l], &self.levels[l + 1]);
        let halve_t = coarse.dims.nt != fine.dims.nt;
        let (fine_x, coarse_x) = self.x.split_at_mut(l + 1);
        let e = &coarse_x[0];
        fine_x[l]
            .par_chunks_mut(fine.slab)
            .with_min_len(tasks(fine))
            .enumerate()
            .for_each(|(k, x)| {
                let kc = if halve_t { k / 2 } else { k };
                let ce = &e[kc * coarse.slab..(kc + 1) * coarse.slab];
                let on = &fine.inv_diag[k * fine.slab..(k + 1) * fine.slab];
                for j in 0..fine.dims.ny {
                    let (p, c) = ((j + 1) * fine.stride + 1, (j / 2 + 1) * coarse.stride + 1);
                    let (x, on) = (&mut x[p..p + fine.dims.nx], &on[p..p + fine.dims.nx]);
                    for i in 0..fine.dims.nx {
                        let add = ce[c + i / 2];
                        x[i] += if on[i] != 0.0 { add } else { 0.0 };
                    }
                }
            });
    }
}

/// The fewest slabs a task of a pass over `level` takes: all of them (one thread) below
/// [`PARALLEL`] cells.
fn tasks(level: &Level) -> usize {
    if level.len() < PARALLEL {
        level.dims.nt
    } else {
        1
    }
}

/// Per-slab sums added in slab order: deterministic whatever the threads.
fn slab_sum(n: usize, slab: usize, f: impl Fn(std::ops::Range<usize>) -> f64 + Sync) -> f64 {
    let parts: Vec<f64> = (0..n / slab)
        .into_par_iter()
        .map(|k| f(k * slab..(k + 1) * slab))
        .collect();
    parts.iter().sum()
}

/// Solves the 7-point system on the `unknown` cells of `dims`, with `w_theta` the coupling
/// along θ and the other cells of `values` as Dirichlet values (cells beyond x and y count as
/// 0); the unknown cells of `values` are the starting guess. Stops at a relative residual of
/// `tolerance` or after `max_iterations` (check the returned stats).
pub fn solve(
    dims: Dims,
    unknown: &[bool],
    values: &mut [f64],
    w_theta: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Stats {
    let fine = Level::finest(dims, unknown, w_theta as f32);
    // The operator CG works with: the fine level's, coupling rounded to f32 once (the same
    // operator in every product, so the residual CG tracks is the true one of that system).
    let wt = f64::from(w_theta as f32);
    let n = fine.len();
    let (stride, slab) = (fine.stride, fine.slab);
    let pad = |i: usize, j: usize, k: usize| k * slab + (j + 1) * stride + i + 1;
    // b: the Dirichlet neighbours' values; u: the starting guess on unknown cells.
    let mut b = vec![0.0f64; n];
    let mut u = vec![0.0f64; n];
    for k in 0..dims.nt {
        for j in 0..dims.ny {
            for i in 0..dims.nx {
                let c = dims.index(i, j, k);
                if !unknown[c] {
                    continue;
                }
                u[pad(i, j, k)] = values[c];
                let mut sum = 0.0;
                for (m, w) in dims.neighbours((i, j, k), wt) {
                    if !unknown[m] {
                        sum += w * values[m];
                    }
                }
                b[pad(i, j, k)] = sum;
            }
        }
    }
    let active = fine.inv_diag.clone();
    // A·x in f64, row by row (straight-line loops the compiler vectorizes): the vectors hold 0
    // on inactive cells, so only the row's own inactive cells need masking.
    let apply = |x: &[f64], out: &mut [f64]| {
        out.par_chunks_mut(slab).enumerate().for_each(|(k, out)| {
            let (up, down) = ((k + 1) % dims.nt, (k + dims.nt - 1) % dims.nt);
            let (nx, centre) = (dims.nx, 4.0 + 2.0 * wt);
            for j in 0..dims.ny {
                let p = (j + 1) * stride + 1;
                let q = k * slab + p;
                let (qu, qd) = (up * slab + p, down * slab + p);
                let (xm, xe, xw) = (&x[q..q + nx], &x[q + 1..q + 1 + nx], &x[q - 1..q - 1 + nx]);
                let (xn, xs) = (
                    &x[q + stride..q + stride + nx],
                    &x[q - stride..q - stride + nx],
                );
                let (xu, xd) = (&x[qu..qu + nx], &x[qd..qd + nx]);
                let (on, o) = (&active[q..q + nx], &mut out[p..p + nx]);
                for i in 0..nx {
                    let v = centre * xm[i] - xe[i] - xw[i] - xn[i] - xs[i] - wt * (xu[i] + xd[i]);
                    o[i] = if on[i] != 0.0 { v } else { 0.0 };
                }
            }
        });
    };
    let dot = |a: &[f64], c: &[f64]| {
        slab_sum(n, slab, |r| {
            a[r.clone()].iter().zip(&c[r]).map(|(x, y)| x * y).sum()
        })
    };
    let b_norm = dot(&b, &b).sqrt();
    let mut ax = vec![0.0; n];
    apply(&u, &mut ax);
    let mut r: Vec<f64> = (b.iter().zip(&ax)).map(|(b, a)| b - a).collect();
    drop(b);
    let mut rr = dot(&r, &r);
    let relative = |rr: f64| {
        if b_norm > 0.0 {
            rr.sqrt() / b_norm
        } else {
            0.0
        }
    };
    let mut stats = Stats {
        iterations: 0,
        relative_residual: relative(rr),
    };
    if stats.relative_residual > tolerance {
        let mut hierarchy = Hierarchy::new(fine);
        let mut p = vec![0.0f64; n];
        let mut ap = ax;
        let mut rz_old = 0.0;
        while stats.iterations < max_iterations && stats.relative_residual > tolerance {
            // z = M r: the residual scaled to unit size for the f32 cycle.
            let scale = r
                .par_chunks(slab)
                .map(|c| c.iter().fold(0.0f64, |m, v| m.max(v.abs())))
                .reduce(|| 0.0, f64::max);
            if scale == 0.0 {
                break;
            }
            (hierarchy.b[0].par_chunks_mut(slab))
                .zip(r.par_chunks(slab))
                .for_each(|(b, r)| {
                    for (bv, rv) in b.iter_mut().zip(r) {
                        *bv = (rv / scale) as f32;
                    }
                });
            hierarchy.cycle(0, true);
            let z = &hierarchy.x[0];
            let rz = slab_sum(n, slab, |c| {
                (r[c.clone()].iter().zip(&z[c]))
                    .map(|(r, z)| r * (f64::from(*z) * scale))
                    .sum()
            });
            let beta = if stats.iterations == 0 {
                0.0
            } else {
                rz / rz_old
            };
            rz_old = rz;
            p.par_chunks_mut(slab)
                .zip(z.par_chunks(slab))
                .for_each(|(p, z)| {
                    for (pv, zv) in p.iter_mut().zip(z) {
                        *pv = f64::from(*zv) * scale + beta * *pv;
                    }
                });
            apply(&p, &mut ap);
            let pap = dot(&p, &ap);
            if pap.is_nan() || pap <= 0.0 {
                break;
            }
            let alpha = rz / pap;
            let parts: Vec<f64> = (u.par_chunks_mut(slab))
                .zip(r.par_chunks_mut(slab))
                .zip(p.par_chunks(slab).zip(ap.par_chunks(slab)))
                .map(|((u, r), (p, ap))| {
                    let mut sum = 0.0;
                    for i in 0..u.len() {
                        u[i] += alpha * p[i];
                        r[i] -= alpha * ap[i];
                        sum += r[i] * r[i];
                    }
                    sum
                })
                .collect();
            rr = parts.iter().sum();
            stats.iterations += 1;
            stats.relative_residual = relative(rr);
        }
    }
    for k in 0..dims.nt {
        for j in 0..dims.ny {
            for i in 0..dims.nx {
                let c = dims.index(i, j, k);
                if unknown[c] {
                    values[c] = u[pad(i, j, k)];
                }
            }
        }
    }
    stats
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Plain Gauss-Seidel on the same system, to `1e-13` of its update: the reference.
    fn reference(dims: Dims, unknown: &[bool], values: &mut [f64], w_theta: f64) {
        let wt = f64::from(w_theta as f32);
        for _ in 0..200_000 {
            let mut change: f64 = 0.0;
            for k in 0..dims.nt {
                for j in 0..dims.ny {
                    for i in 0..dims.nx {
                        let c = dims.index(i, j, k);
                        if !unknown[c] {
                            continue;
                        }
                        let sum: f64 = dims
                            .neighbours((i, j, k), wt)
                            .map(|(m, w)| w * values[m])
                            .sum();
                        let new = sum / (4.0 + 2.0 * wt);
                        change = change.max((new - values[c]).abs());
                        values[c] = new;
                    }
                }
            }
            if change < 1e-15 {
                return;
            }
        }
        panic!("the reference did not converge");
    }

    /// A box with a wall across part of it in some slabs only, and a target block: W = 1 on
    /// the target, 0 on the walls.
    fn problem(n: usize, nt: usize) -> (Dims, Vec<bool>, Vec<f64>) {
        let dims = Dims { nx: n, ny: n, nt };
        let mut unknown = vec![true; dims.len()];
        let mut w = vec![0.0; dims.len()];
        for k in 0..nt {
            for j in 0..n {
                for i in 0..n {
                    let c = dims.index(i, j, k);
                    let wall = i == n / 2 && j < 2 * n / 3 && (k < nt / 2 || j < n / 3);
                    let edge = i == 0 || j == 0 || i + 1 == n || j + 1 == n;
                    if wall || edge {
                        unknown[c] = false;
                    }
                    if (i as isize - 3).abs() <= 1 && (j as isize - 3).abs() <= 1 && k < 2 {
                        unknown[c] = false;
                        w[c] = 1.0;
                    }
                }
            }
        }
        (dims, unknown, w)
    }

    #[test]
    fn multigrid_matches_the_reference_solver() {
        for (n, nt, wt) in [(14, 8, 0.7), (17, 12, 2.5), (9, 16, 0.2)] {
            let (dims, unknown, w0) = problem(n, nt);
            let mut w = w0.clone();
            let stats = solve(dims, &unknown, &mut w, wt, 1e-13, 100);
            assert!(stats.relative_residual <= 1e-13, "{stats:?}");
            let mut r = w0.clone();
            reference(dims, &unknown, &mut r, wt);
            let worst = w
                .iter()
                .zip(&r)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-10,
                "n {n}, nt {nt}: largest difference {worst:e}"
            );
        }
    }

    /// The W-cycle keeps CG's iteration count flat as the grid grows.
    #[test]
    fn iterations_stay_flat_as_the_grid_grows() {
        let counts: Vec<usize> = [(24, 16), (48, 32), (96, 64)]
            .iter()
            .map(|&(n, nt)| {
                let (dims, unknown, mut w) = problem(n, nt);
                let stats = solve(dims, &unknown, &mut w, 1.0, 1e-10, 100);
                assert!(stats.relative_residual <= 1e-10, "{stats:?}");
                stats.iterations
            })
            .collect();
        let (lo, hi) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
        assert!(hi - lo <= 3 && *hi <= 20, "{counts:?}");
    }

    /// A field that does not depend on θ (walls and target the same in every slab) is the
    /// plane's field in every slab: the θ couplings carry nothing, whatever their weight.
    #[test]
    fn a_field_uniform_in_heading_is_the_planes_field() {
        let (n, nt) = (20, 8);
        let dims = Dims { nx: n, ny: n, nt };
        let plane = crate::field::Grid::covering([n as f64, n as f64], 1.0);
        let mut unknown = vec![true; dims.len()];
        let mut w = vec![0.0; dims.len()];
        let mut unknown2 = vec![true; plane.len()];
        let mut w2 = vec![0.0; plane.len()];
        for k in 0..nt {
            for j in 0..n {
                for i in 0..n {
                    let c = dims.index(i, j, k);
                    if i == 10 && j > 4 {
                        unknown[c] = false;
                        unknown2[plane.index(i, j)] = false;
                    }
                    if i == 3 && j == 15 {
                        unknown[c] = false;
                        w[c] = 1.0;
                        unknown2[plane.index(i, j)] = false;
                        w2[plane.index(i, j)] = 1.0;
                    }
                }
            }
        }
        solve(dims, &unknown, &mut w, 3.0, 1e-13, 100);
        crate::field::solvers::solve(&plane, &unknown2, &mut w2, 1e-13, 100);
        for k in 0..nt {
            for j in 0..n {
                for i in 0..n {
                    let (a, b) = (w[dims.index(i, j, k)], w2[plane.index(i, j)]);
                    assert!((a - b).abs() < 1e-10, "({i}, {j}, {k}): {a} vs {b}");
                }
            }
        }
    }
}
