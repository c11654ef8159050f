//! A multigrid-preconditioned conjugate gradient solver for Laplace's equation on a masked 3-D
//! grid whose axes are each periodic or bounded ([`Lattice`]): the 7-point system
//!
//! `Σ_axes w_a Σ_± (u_k − u_n) = 0`.
//!
//! For a shaped body (`pose/mod.rs`) the axes are x and y, bounded with `w = 1`, and θ,
//! periodic with `w_θ = (h / (ρ Δθ))²`: the system is `h² ∇²u = 0` in the coordinates
//! `(x, y, ρθ)`. For an arm, the axes are its joints, periodic where a joint has no limits.
//! Cells that are not unknown hold Dirichlet values; cells beyond a bounded axis count as 0.
//!
//! It follows the plane's solver (`field/multigrid`), in three dimensions:
//!
//! - CG in f64, with one W-cycle in f32 as the preconditioner.
//! - Aggregation of 2 cells along every axis that can be halved: a bounded one always; a
//!   periodic one while the halved count stays even, or becomes 1.
//! - Galerkin coarse operators `R A P`, scaled per axis to the rediscretized stencil.
//! - Red-black Gauss-Seidel on every level: red then black before the coarse correction, black
//!   then red after it, so the cycle is symmetric.
//! - A dense Cholesky solve of the coarsest level.
//!
//! A periodic axis has an even number of cells on every level (or 1), so the red-black
//! colouring wraps: a cell's neighbours all have the other colour. Along a periodic x or y, the
//! padding ring holds copies of the cells across the wrap (ghosts), refreshed after every pass,
//! so the row loops read the wrap as any other neighbour.
//!
//! The passes run over θ slabs in parallel (rayon). A colour pass updates the even slabs and
//! then the odd ones, so that no slab is written while a neighbour reads it; the result is the
//! same as one sequential pass, whatever the number of threads. Sums are taken per slab and
//! added in slab order, so a solve is deterministic.

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

/// A grid with its axes' topology and couplings: each axis periodic or bounded (cells beyond a
/// bounded axis count as 0), and the coupling between neighbours along it (the system is
/// `Σ_axes w_a Σ_± (u_k − u_n) = 0`). A shaped body's field is bounded in x and y, periodic in
/// θ with `w_θ = (h/(ρΔθ))²`; an arm's joint space has one axis per joint, periodic without
/// limits. A periodic axis has an even number of cells (the red-black colouring wraps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// The grid's size.
    pub dims: Dims,
    /// Whether x, y and θ (the third axis) wrap.
    pub periodic: [bool; 3],
    /// The coupling along x, y and the third axis.
    pub weights: [f64; 3],
}

impl Lattice {
    /// A shaped body's lattice: bounded x and y with unit couplings, periodic θ coupled by
    /// `w_theta`.
    pub fn pose(dims: Dims, w_theta: f64) -> Self {
        Self {
            dims,
            periodic: [false, false, true],
            weights: [1.0, 1.0, w_theta],
        }
    }

    /// The neighbours of cell `(i, j, k)` with their couplings, in the order x−, x+, y−, y+,
    /// θ+, θ−: beyond a bounded axis none, across a periodic one the cell on the other side (an
    /// axis of one cell has no neighbour along it).
    pub fn neighbours(
        &self,
        (i, j, k): (usize, usize, usize),
    ) -> impl Iterator<Item = (usize, f64)> + use<> {
        let (d, l) = (self.dims, *self);
        let step = |at: usize, n: usize, axis: usize, forward: bool| -> Option<usize> {
            if n == 1 {
                return None;
            }
            match (forward, at) {
                (true, a) if a + 1 < n => Some(a + 1),
                (false, a) if a > 0 => Some(a - 1),
                (true, _) => l.periodic[axis].then_some(0),
                (false, _) => l.periodic[axis].then_some(n - 1),
            }
        };
        let w = self.weights;
        [
            step(i, d.nx, 0, false).map(|a| (d.index(a, j, k), w[0])),
            step(i, d.nx, 0, true).map(|a| (d.index(a, j, k), w[0])),
            step(j, d.ny, 1, false).map(|b| (d.index(i, b, k), w[1])),
            step(j, d.ny, 1, true).map(|b| (d.index(i, b, k), w[1])),
            step(k, d.nt, 2, true).map(|c| (d.index(i, j, c), w[2])),
            step(k, d.nt, 2, false).map(|c| (d.index(i, j, c), w[2])),
        ]
        .into_iter()
        .flatten()
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
/// stride `(nx + 2)(ny + 2)`), with couplings to the next cell along x, y and θ (0 beyond a
/// bounded axis), and the diagonal split into its parts along each axis (the coarsening needs
/// them apart). Along a periodic x or y the ring holds copies of the cells across the wrap (its
/// ghosts: [`Level::sync_ghosts`]) and the couplings to them, so the row loops read the wrap like
/// any neighbour.
struct Level {
    dims: Dims,
    periodic: [bool; 3],
    stride: usize,
    slab: usize,
    inv_diag: Vec<f32>,
    diag_x: Vec<f32>,
    diag_y: Vec<f32>,
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

    /// The slabs above and below `k` (wrapping; the couplings to them are 0 across a bounded θ).
    fn around(&self, k: usize) -> (usize, usize) {
        let nt = self.dims.nt;
        ((k + 1) % nt, (k + nt - 1) % nt)
    }

    /// A level of `dims` with no active cell.
    fn empty(dims: Dims, periodic: [bool; 3]) -> Self {
        let (stride, slab) = (dims.nx + 2, (dims.nx + 2) * (dims.ny + 2));
        let n = slab * dims.nt;
        Self {
            dims,
            periodic,
            stride,
            slab,
            inv_diag: vec![0.0; n],
            diag_x: vec![0.0; n],
            diag_y: vec![0.0; n],
            diag_t: vec![0.0; n],
            east: vec![0.0; n],
            north: vec![0.0; n],
            up: vec![0.0; n],
            active: 0,
        }
    }

    /// The finest level of `lattice`'s `unknown` cells (its couplings rounded to f32).
    fn finest(lattice: &Lattice, unknown: &[bool]) -> Self {
        let (dims, periodic) = (lattice.dims, lattice.periodic);
        let [wx, wy, wt] = lattice.weights.map(|w| w as f32);
        let mut level = Self::empty(dims, periodic);
        let on = |i: usize, j: usize, k: usize| unknown[dims.index(i, j, k)];
        for k in 0..dims.nt {
            let up = (k + 1) % dims.nt;
            let up_coupled = dims.nt > 1 && (k + 1 < dims.nt || periodic[2]);
            for j in 0..dims.ny {
                let north = (j + 1 < dims.ny)
                    .then_some(j + 1)
                    .or((periodic[1] && dims.ny > 1).then_some(0));
                for i in 0..dims.nx {
                    if !on(i, j, k) {
                        continue;
                    }
                    let p = level.pad(i, j, k);
                    level.active += 1;
                    level.diag_x[p] = 2.0 * wx;
                    level.diag_y[p] = 2.0 * wy;
                    level.diag_t[p] = 2.0 * wt;
                    level.inv_diag[p] = 1.0 / (2.0 * wx + 2.0 * wy + 2.0 * wt);
                    let east = (i + 1 < dims.nx)
                        .then_some(i + 1)
                        .or((periodic[0] && dims.nx > 1).then_some(0));
                    if east.is_some_and(|e| on(e, j, k)) {
                        level.east[p] = wx;
                    }
                    if north.is_some_and(|n| on(i, n, k)) {
                        level.north[p] = wy;
                    }
                    if up_coupled && on(i, j, up) {
                        level.up[p] = wt;
                    }
                }
            }
        }
        level.wrap_couplings();
        level
    }

    /// Copies the couplings across a periodic x or y into the ring, where the row loops read a
    /// cell's west and south couplings.
    fn wrap_couplings(&mut self) {
        let d = self.dims;
        for k in 0..d.nt {
            if self.periodic[0] && d.nx > 1 {
                for j in 0..d.ny {
                    let (last, ghost) = (self.pad(d.nx - 1, j, k), self.pad(0, j, k) - 1);
                    self.east[ghost] = self.east[last];
                }
            }
            if self.periodic[1] && d.ny > 1 {
                for i in 0..d.nx {
                    let (last, ghost) = (self.pad(i, d.ny - 1, k), self.pad(i, 0, k) - self.stride);
                    self.north[ghost] = self.north[last];
                }
            }
        }
    }

    /// Refreshes the ghosts of slab `k` of `x` across a periodic x or y (see [`Level`]).
    #[inline(always)]
    fn sync_ghosts<T: Copy>(&self, k: usize, x: &mut [T]) {
        sync_ghosts(self.dims, self.periodic, k, x);
    }

    /// The Galerkin coarse level for aggregates of 2 cells along each axis that can be halved
    /// (a bounded x or y always; θ or a periodic x or y while the halved count stays even, or
    /// becomes 1), each coupling scaled by [`HALVED`] along the axes that were halved. A coarse
    /// cell's diagonal along an axis is its children's less twice the couplings between them
    /// along it.
    fn coarsen(&self) -> Self {
        let (d, periodic) = (self.dims, self.periodic);
        let halves = |n: usize, wraps: bool| {
            if wraps {
                n.is_multiple_of(2) && (n == 2 || (n / 2).is_multiple_of(2))
            } else {
                n > 1
            }
        };
        let halve = [
            halves(d.nx, periodic[0]) || !periodic[0],
            halves(d.ny, periodic[1]) || !periodic[1],
            halves(d.nt, periodic[2]),
        ];
        let by = halve.map(|h| if h { 2 } else { 1 });
        let dims = Dims {
            nx: d.nx.div_ceil(by[0]),
            ny: d.ny.div_ceil(by[1]),
            nt: d.nt.div_ceil(by[2]),
        };
        let mut c = Self::empty(dims, periodic);
        let scale = halve.map(|h| if h { HALVED } else { 1.0 });
        // Whether the coupling of a child at position `at` of `by` along an axis of `n` cells
        // stays inside its aggregate: from the first child, and from the second too when the
        // two are all there is and the axis wraps.
        let inside =
            |at: usize, by: usize, n: usize, wraps: bool| by == 2 && (at == 0 || (wraps && n == 2));
        for kc in 0..dims.nt {
            for jc in 0..dims.ny {
                for ic in 0..dims.nx {
                    let (mut sum, mut within) = ([0.0f32; 3], [0.0f32; 3]);
                    let (mut east, mut north, mut up) = (0.0, 0.0, 0.0);
                    for dk in 0..by[2] {
                        let k = by[2] * kc + dk;
                        if k >= d.nt {
                            continue;
                        }
                        for dj in 0..by[1] {
                            let j = by[1] * jc + dj;
                            for di in 0..by[0] {
                                let i = by[0] * ic + di;
                                // Children beyond the fine grid are in its inactive ring.
                                let p = k * self.slab + (j + 1) * self.stride + i + 1;
                                sum[0] += self.diag_x[p];
                                sum[1] += self.diag_y[p];
                                sum[2] += self.diag_t[p];
                                if inside(di, by[0], d.nx, periodic[0]) {
                                    within[0] += self.east[p];
                                } else if di + 1 == by[0] {
                                    east += self.east[p];
                                }
                                if inside(dj, by[1], d.ny, periodic[1]) {
                                    within[1] += self.north[p];
                                } else if dj + 1 == by[1] {
                                    north += self.north[p];
                                }
                                if inside(dk, by[2], d.nt, periodic[2]) {
                                    within[2] += self.up[p];
                                } else if dk + 1 == by[2] {
                                    up += self.up[p];
                                }
                            }
                        }
                    }
                    let diag = [0, 1, 2].map(|a| scale[a] * (sum[a] - 2.0 * within[a]));
                    let p = c.pad(ic, jc, kc);
                    (c.diag_x[p], c.diag_y[p], c.diag_t[p]) = (diag[0], diag[1], diag[2]);
                    // An axis of one cell couples a cell to itself: nothing.
                    c.east[p] = if dims.nx == 1 && periodic[0] {
                        0.0
                    } else {
                        scale[0] * east
                    };
                    c.north[p] = if dims.ny == 1 && periodic[1] {
                        0.0
                    } else {
                        scale[1] * north
                    };
                    c.up[p] = if dims.nt == 1 { 0.0 } else { scale[2] * up };
                    let total = diag[0] + diag[1] + diag[2];
                    if total > 0.0 {
                        c.inv_diag[p] = 1.0 / total;
                        c.active += 1;
                    }
                }
            }
        }
        c.wrap_couplings();
        c
    }

    /// The diagonal at padded cell `p`, in f64.
    fn apply_diag(&self, p: usize) -> f64 {
        f64::from(self.diag_x[p] + self.diag_y[p]) + f64::from(self.diag_t[p])
    }

    /// The cells padded cell `p` couples to (across the wraps: the cells, not the ghosts) with
    /// their couplings, in the order east, west, north, south, up, down (0 where it couples to
    /// nothing).
    fn neighbour_cells(&self, p: usize) -> [(usize, f32); 6] {
        let (s, d) = (self.stride, self.dims);
        let k = p / self.slab;
        let (i, j) = ((p % self.slab) % s - 1, (p % self.slab) / s - 1);
        let (up, down) = self.around(k);
        let wrap = |a: usize, n: usize, forward: bool| {
            if forward {
                (a + 1) % n
            } else {
                (a + n - 1) % n
            }
        };
        let east = if i + 1 < d.nx {
            p + 1
        } else {
            self.pad(wrap(i, d.nx, true), j, k)
        };
        let west = if i > 0 {
            p - 1
        } else {
            self.pad(wrap(i, d.nx, false), j, k)
        };
        let north = if j + 1 < d.ny {
            p + s
        } else {
            self.pad(i, wrap(j, d.ny, true), k)
        };
        let south = if j > 0 {
            p - s
        } else {
            self.pad(i, wrap(j, d.ny, false), k)
        };
        let (pu, pd) = (self.pad(i, j, up), self.pad(i, j, down));
        [
            (east, self.east[p]),
            (west, self.east[p - 1]),
            (north, self.north[p]),
            (south, self.north[p - s]),
            (pu, self.up[p]),
            (pd, self.up[pd]),
        ]
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
        let (dx, dy, dt) = (
            &self.diag_x[p..p + nx],
            &self.diag_y[p..p + nx],
            &self.diag_t[p..p + nx],
        );
        let (e, w) = (&self.east[p..p + nx], &self.east[p - 1..p - 1 + nx]);
        let (no, so) = (&self.north[p..p + nx], &self.north[p - s..p - s + nx]);
        let (u, dn) = (&self.up[p..p + nx], &self.up[pd..pd + nx]);
        let (xm, xe, xw) = (&x[p..p + nx], &x[p + 1..p + 1 + nx], &x[p - 1..p - 1 + nx]);
        let (xn, xs) = (&x[p + s..p + s + nx], &x[p - s..p - s + nx]);
        let (xu, xd) = (&x[pu..pu + nx], &x[pd..pd + nx]);
        let bb = &b[p..p + nx];
        for i in 0..nx {
            out[i] = bb[i] - (dx[i] + dy[i] + dt[i]) * xm[i]
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
        // A bounded θ of odd length has its first and last slabs of one parity: they do not
        // couple, but would read each other while written.
        if self.len() < PARALLEL || !nt.is_multiple_of(2) {
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
        // Each row read only its own ghosts, of the other colour: unchanged in this pass.
        self.sync_ghosts(k, x);
    }
}

/// Refreshes the ghosts of slab `k` of a padded vector `x` of a grid of `dims` across its
/// periodic x or y (see [`Level`]).
#[inline(always)]
fn sync_ghosts<T: Copy>(dims: Dims, periodic: [bool; 3], k: usize, x: &mut [T]) {
    let stride = dims.nx + 2;
    let slab = stride * (dims.ny + 2);
    let pad = |i: usize, j: usize| k * slab + (j + 1) * stride + i + 1;
    if periodic[0] && dims.nx > 1 {
        for j in 0..dims.ny {
            let p = pad(0, j);
            x[p - 1] = x[p + dims.nx - 1];
            x[p + dims.nx] = x[p];
        }
    }
    if periodic[1] && dims.ny > 1 {
        let (first, last) = (pad(0, 0) - 1, pad(0, dims.ny - 1) - 1);
        x.copy_within(last..last + stride, first - stride);
        x.copy_within(first..first + stride, last + stride);
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
    factor: dense::Factor,
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
        for (r, &(p, _)) in cells.iter().enumerate() {
            a[r * n + r] = level.apply_diag(p);
            for (m, coupling) in level.neighbour_cells(p) {
                if let Some(&c) = position.get(&m) {
                    a[r * n + c] -= f64::from(coupling);
                }
            }
        }
        Self {
            cells: cells.into_iter().map(|(p, _)| p).collect(),
            factor: dense::Factor::new(a, n),
        }
    }

    fn solve(&self, x: &mut [f32], b: &[f32]) {
        let mut y: Vec<f64> = self.cells.iter().map(|&p| f64::from(b[p])).collect();
        self.factor.solve(&mut y);
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
        let by = ratios(fine, coarse);
        let x = &self.x[l];
        let (fine_b, coarse_b) = self.b.split_at_mut(l + 1);
        let (b, out) = (&fine_b[l], &mut coarse_b[0]);
        out.par_chunks_mut(coarse.slab)
            .with_min_len(tasks(fine))
            .enumerate()
            .for_each(|(kc, out)| {
                out.fill(0.0);
                let mut row = vec![0.0f32; fine.dims.nx];
                for k in (by[2] * kc..by[2] * (kc + 1)).filter(|&k| k < fine.dims.nt) {
                    for j in 0..fine.dims.ny {
                        wide(
                            #[inline(always)]
                            || fine.residual_row(k, j, x, b, &mut row),
                        );
                        let o = (j / by[1] + 1) * coarse.stride + 1;
                        for (i, r) in row.iter().enumerate() {
                            out[o + i / by[0]] += r;
                        }
                    }
                }
            });
    }

    /// Adds level `l + 1`'s correction to level `l` (`P`: piecewise constant).
    fn prolong(&mut self, l: usize) {
        let (fine, coarse) = (&self.levels[l], &self.levels[l + 1]);
        let by = ratios(fine, coarse);
        let (fine_x, coarse_x) = self.x.split_at_mut(l + 1);
        let e = &coarse_x[0];
        fine_x[l]
            .par_chunks_mut(fine.slab)
            .with_min_len(tasks(fine))
            .enumerate()
            .for_each(|(k, x)| {
                let kc = k / by[2];
                let ce = &e[kc * coarse.slab..(kc + 1) * coarse.slab];
                let on = &fine.inv_diag[k * fine.slab..(k + 1) * fine.slab];
                for j in 0..fine.dims.ny {
                    let (p, c) = (
                        (j + 1) * fine.stride + 1,
                        (j / by[1] + 1) * coarse.stride + 1,
                    );
                    let (row, on) = (&mut x[p..p + fine.dims.nx], &on[p..p + fine.dims.nx]);
                    for i in 0..fine.dims.nx {
                        let add = ce[c + i / by[0]];
                        row[i] += if on[i] != 0.0 { add } else { 0.0 };
                    }
                }
                // The slab's own ghosts (this chunk is the slab: its index 0).
                fine.sync_ghosts(0, x);
            });
    }
}

/// How many cells of `fine` each cell of `coarse` aggregates along x, y and θ (1 or 2).
fn ratios(fine: &Level, coarse: &Level) -> [usize; 3] {
    let (f, c) = (fine.dims, coarse.dims);
    [(f.nx, c.nx), (f.ny, c.ny), (f.nt, c.nt)].map(|(f, c)| if c < f || f == 1 { 2 } else { 1 })
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

/// Solves the 7-point system of `lattice` on its `unknown` cells, with the other cells of
/// `values` as Dirichlet values (cells beyond a bounded axis count as 0); the unknown cells of
/// `values` are the starting guess. Stops at a relative residual of `tolerance` or after
/// `max_iterations` (check the returned stats).
pub fn solve(
    lattice: &Lattice,
    unknown: &[bool],
    values: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> Stats {
    let dims = lattice.dims;
    let fine = Level::finest(lattice, unknown);
    // The operator CG works with: the fine level's, couplings rounded to f32 once (the same
    // operator in every product, so the residual CG tracks is the true one of that system).
    let [wx, wy, wt] = lattice.weights.map(|w| f64::from(w as f32));
    let rounded = Lattice {
        weights: [wx, wy, wt],
        ..*lattice
    };
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
                for (m, w) in rounded.neighbours((i, j, k)) {
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
    let apply = |x: &mut [f64], out: &mut [f64]| {
        let periodic = lattice.periodic;
        x.par_chunks_mut(slab)
            .for_each(|x| sync_ghosts(dims, periodic, 0, x));
        let x = &*x;
        out.par_chunks_mut(slab).enumerate().for_each(|(k, out)| {
            let (up, down) = ((k + 1) % dims.nt, (k + dims.nt - 1) % dims.nt);
            let (nx, centre) = (dims.nx, 2.0 * wx + 2.0 * wy + 2.0 * wt);
            // Across a bounded θ there is nothing (the vectors do wrap).
            let wraps = lattice.periodic[2] && dims.nt > 1;
            let fu = if k + 1 < dims.nt || wraps { 1.0 } else { 0.0 };
            let fd = if k > 0 || wraps { 1.0 } else { 0.0 };
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
                    let v = centre * xm[i]
                        - wx * xe[i]
                        - wx * xw[i]
                        - wy * xn[i]
                        - wy * xs[i]
                        - wt * (fu * xu[i] + fd * xd[i]);
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
    apply(&mut u, &mut ax);
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
            apply(&mut p, &mut ap);
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

    /// Plain Gauss-Seidel on the same system, to `1e-15` of its update: the reference.
    fn reference(lattice: &Lattice, unknown: &[bool], values: &mut [f64]) {
        let dims = lattice.dims;
        let rounded = Lattice {
            weights: lattice.weights.map(|w| f64::from(w as f32)),
            ..*lattice
        };
        let diag: f64 = rounded.weights.iter().map(|w| 2.0 * w).sum();
        for _ in 0..200_000 {
            let mut change: f64 = 0.0;
            for k in 0..dims.nt {
                for j in 0..dims.ny {
                    for i in 0..dims.nx {
                        let c = dims.index(i, j, k);
                        if !unknown[c] {
                            continue;
                        }
                        let sum: f64 = rounded
                            .neighbours((i, j, k))
                            .map(|(m, w)| w * values[m])
                            .sum();
                        let new = sum / diag;
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
            let stats = solve(&Lattice::pose(dims, wt), &unknown, &mut w, 1e-13, 100);
            assert!(stats.relative_residual <= 1e-13, "{stats:?}");
            let mut r = w0.clone();
            reference(&Lattice::pose(dims, wt), &unknown, &mut r);
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

    /// Any topology: periodic x and y with a bounded third axis (an arm's two free joints and
    /// one with limits), a torus in x alone, weights that differ per axis. Multigrid agrees
    /// with the reference on each, and a torus with its target in a band is uniform along the
    /// band (the wrap couples the band's ends as well as its middle).
    #[test]
    fn every_topology_matches_the_reference_solver() {
        let cases = [
            ([true, true, false], [1.0, 0.6, 1.7], (16, 12, 6)),
            ([true, false, true], [0.8, 1.0, 0.5], (12, 9, 8)),
            ([false, true, false], [1.0, 1.0, 1.0], (9, 8, 5)),
            ([true, true, true], [1.0, 1.0, 1.0], (8, 8, 8)),
        ];
        for (periodic, weights, (nx, ny, nt)) in cases {
            let lattice = Lattice {
                dims: Dims { nx, ny, nt },
                periodic,
                weights,
            };
            let dims = lattice.dims;
            let mut unknown = vec![true; dims.len()];
            let mut w0 = vec![0.0; dims.len()];
            for k in 0..nt {
                for j in 0..ny {
                    for i in 0..nx {
                        let c = dims.index(i, j, k);
                        // A wall across x at i = nx / 2 with a gap, and a target block.
                        if i == nx / 2 && j > 1 && k != nt / 2 {
                            unknown[c] = false;
                        }
                        if i == 1 && j <= 1 && k <= 1 {
                            unknown[c] = false;
                            w0[c] = 1.0;
                        }
                    }
                }
            }
            let mut w = w0.clone();
            let stats = solve(&lattice, &unknown, &mut w, 1e-13, 200);
            assert!(stats.relative_residual <= 1e-13, "{periodic:?}: {stats:?}");
            let mut r = w0;
            reference(&lattice, &unknown, &mut r);
            let worst = w
                .iter()
                .zip(&r)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-10, "{periodic:?}: largest difference {worst:e}");
        }
        // A band around a torus in x with W = 1 along its first column: W depends on j alone.
        let lattice = Lattice {
            dims: Dims {
                nx: 16,
                ny: 10,
                nt: 1,
            },
            periodic: [true, false, false],
            weights: [1.0, 1.0, 1.0],
        };
        let dims = lattice.dims;
        let mut unknown = vec![true; dims.len()];
        let mut w = vec![0.0; dims.len()];
        for i in 0..dims.nx {
            unknown[dims.index(i, 0, 0)] = false;
            w[dims.index(i, 0, 0)] = 1.0;
        }
        solve(&lattice, &unknown, &mut w, 1e-13, 200);
        for j in 0..dims.ny {
            let row: Vec<f64> = (0..dims.nx).map(|i| w[dims.index(i, j, 0)]).collect();
            let spread = row.iter().fold(0.0f64, |m, v| m.max((v - row[0]).abs()));
            assert!(spread < 1e-11, "row {j}: {row:?}");
        }
    }

    /// The W-cycle keeps CG's iteration count flat as the grid grows.
    #[test]
    fn iterations_stay_flat_as_the_grid_grows() {
        let counts: Vec<usize> = [(24, 16), (48, 32), (96, 64)]
            .iter()
            .map(|&(n, nt)| {
                let (dims, unknown, mut w) = problem(n, nt);
                let stats = solve(&Lattice::pose(dims, 1.0), &unknown, &mut w, 1e-10, 100);
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
        solve(&Lattice::pose(dims, 3.0), &unknown, &mut w, 1e-13, 100);
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
