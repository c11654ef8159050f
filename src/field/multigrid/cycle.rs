//! The preconditioner: the hierarchy of levels ([`Hierarchy`]) and one W-cycle over it —
//! pre-smoothing and restriction, two visits of the next coarser level, prolongation and
//! post-smoothing — with an exact solve on the coarsest level ([`Coarsest`]) — or, when the
//! caller asks for it ([`Cycle::V`]), one V-cycle.

use std::sync::atomic::{AtomicBool, Ordering};

use super::dense::Factor;
use super::kernels::{dot, flushed, wide};
use super::level::Level;
use super::smoother::{Keep, Part, keep_patterns};

/// The most smoothing sweeps before and after a coarse correction (see [`Cycle::sweeps`]).
const MAX_SWEEPS: usize = 2;
/// The cycle that preconditions each CG iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cycle {
    /// Each coarse level visited once per visit of the level above.
    V,
    /// Each coarse level visited twice: the iteration count stays flat with the grid's size
    /// (see the module `multigrid`), for about 1.5× a V-cycle's work.
    W,
}

impl Cycle {
    /// Coarse-level visits per visit of the level above.
    fn visits(self) -> usize {
        match self {
            Cycle::V => 1,
            Cycle::W => 2,
        }
    }

    /// Red-black sweeps before and after each coarse correction: on the finest level, and on
    /// the coarser ones (at most [`MAX_SWEEPS`]).
    ///
    /// A W-cycle visits level `l` `2^l` times per cycle, so its coarse levels together cost
    /// about what the finest one does (each a quarter of the cells, twice the visits, and rows
    /// too short to hide their overhead): one sweep there, two on the finest. A V-cycle (the
    /// windows of local replanning, 62² cells) does one sweep on every level: cheaper cycles
    /// outweigh the iterations they add. Measured against two sweeps everywhere (alternating
    /// runs on this repository's 2-vCPU Zen 1 machine):
    /// - W-cycle: the 1024² room's solve 0.266 s median against 0.311 s (19 → 20 CG
    ///   iterations); the rooms map's longest field 3.83 s against 4.43 s. One sweep on every
    ///   level: 0.287 s (24 iterations), 4.11 s; one on the finest and two below: 0.355 s;
    ///   three on the finest: as two.
    /// - V-cycle: 64 robots on the 1.8 m circle, first 15 s, 19.6 s against 20.7 s; two
    ///   sweeps on the finest level and one below: 20.7 s; one and two: 20.0 s.
    fn sweeps(self) -> [usize; 2] {
        match self {
            Cycle::V => [1, 1],
            Cycle::W => [2, 1],
        }
    }
}

/// A level with at most this many unknowns is solved exactly.
const COARSEST: usize = 64;
/// A level at least this many rows tall is swept by two threads (see [`Part`]): the fine levels
/// of a whole map's field. Measured on the 1024² room's first solve (13 iterations), the CG
/// loop's median time over 8 runs: 241 ms on one thread, 197 ms on two (a level this tall is
/// read from memory at each half-cycle, and one core alone does not draw all the bandwidth).
/// The windows of local replanning (61 rows) are solved one per thread already, and below
/// this a half-cycle's work is too small for handing half of it over.
const SPLIT_ROWS: usize = 256;

/// The exact solve of the coarsest level: a dense Cholesky factor of its matrix.
pub struct Coarsest {
    /// The index of each unknown in the level's vectors.
    cells: Vec<usize>,
    /// The Cholesky factor of the level's matrix (see [`Factor`]).
    factor: Factor,
}

impl Coarsest {
    /// The factor of `level`'s matrix.
    pub fn new(level: &Level) -> Self {
        let unknowns: Vec<(usize, usize, usize)> = (0..level.ny)
            .flat_map(|j| level.span(j).map(move |i| (i, j)))
            .map(|(i, j)| (i, j, level.pad(i, j)))
            .filter(|&(_, _, k)| level.active(k) != 0.0)
            .collect();
        let n = unknowns.len();
        let mut a = vec![0.0f64; n * n];
        for (r, &(i, j, _)) in unknowns.iter().enumerate() {
            for (c, &(p, q, _)) in unknowns.iter().enumerate() {
                a[r * n + c] = if (p, q) == (i, j) {
                    f64::from(level.diag_at(i, j))
                } else if (p, q) == (i + 1, j) {
                    -f64::from(level.east_at(i, j))
                } else if (i, j) == (p + 1, q) {
                    -f64::from(level.east_at(p, q))
                } else if (p, q) == (i, j + 1) {
                    -f64::from(level.north_at(i, j))
                } else if (i, j) == (p, q + 1) {
                    -f64::from(level.north_at(p, q))
                } else {
                    0.0
                };
            }
        }
        Self {
            cells: unknowns.into_iter().map(|(_, _, k)| k).collect(),
            factor: Factor::new(a, n),
        }
    }

    /// `x = A⁻¹ b` on the coarsest level.
    fn solve(&self, x: &mut [f32], b: &[f32], scratch: &mut Vec<f64>) {
        scratch.clear();
        scratch.extend(self.cells.iter().map(|&k| f64::from(b[k])));
        let y = scratch;
        self.factor.solve(y);
        for (&k, &v) in self.cells.iter().zip(y.iter()) {
            x[k] = flushed(v as f32);
        }
    }
}

/// The levels below a finest level, and the exact solve of the coarsest of all: what
/// [`Hierarchy::on`] adds to the finest level. Built apart from it so that a tall grid's CG
/// start can fault in its vectors on the other thread meanwhile (see `solve_all`).
pub struct Coarse {
    /// The coarse levels, finest first.
    levels: Vec<Level>,
    coarsest: Coarsest,
}

impl Coarse {
    /// The coarse levels of `fine`: each the Galerkin coarsening of the one before, down to
    /// [`COARSEST`] unknowns or a 2 × 2 grid.
    pub fn of(fine: &Level) -> Self {
        let mut levels: Vec<Level> = Vec::new();
        loop {
            let last = levels.last().unwrap_or(fine);
            if last.unknowns <= COARSEST || (last.nx <= 2 && last.ny <= 2) {
                break;
            }
            let coarse = last.coarsen();
            levels.push(coarse);
        }
        let coarsest = Coarsest::new(levels.last().unwrap_or(fine));
        Self { levels, coarsest }
    }
}

/// The hierarchy and its work vectors.
pub struct Hierarchy {
    /// The levels, finest first.
    pub levels: Vec<Level>,
    coarsest: Coarsest,
    /// Per level: solution and right-hand side.
    pub work: Vec<[Vec<f32>; 2]>,
    /// Per thread (see [`Part`]): one row of relaxed values, and one row of residuals or of
    /// prolonged corrections.
    rows: [Rows; 2],
    /// `x · b` of each finest row, summed in row order (whichever thread computed it).
    dots: Vec<f64>,
    /// Which cells a relaxation keeps.
    keep: Keep,
    /// The coarsest solve's scratch.
    scratch: Vec<f64>,
    /// The cycle: its coarse-level visits per visit of the level above and its sweeps on each
    /// level ([`Cycle::visits`], [`Cycle::sweeps`]).
    cycle: Cycle,
}

impl Hierarchy {
    /// The hierarchy of the `nx × ny` grid's `unknown` cells, preconditioning with `cycle`.
    #[cfg(test)]
    pub fn new(nx: usize, ny: usize, unknown: &[bool], cycle: Cycle) -> Self {
        let fine = Level::finest(&super::Rows::whole(nx, ny), unknown);
        let coarse = Coarse::of(&fine);
        Self::on(fine, coarse, cycle)
    }

    /// The hierarchy of the finest level `fine`, with its `coarse` levels, preconditioning
    /// with `cycle`.
    pub fn on(fine: Level, coarse: Coarse, cycle: Cycle) -> Self {
        let (nx, ny) = (fine.nx, fine.ny);
        let Coarse {
            levels: coarse,
            coarsest,
        } = coarse;
        let mut levels = vec![fine];
        levels.extend(coarse);
        let work = levels
            .iter()
            .map(|l| [vec![0.0; l.len()], vec![0.0; l.len()]])
            .collect();
        Self {
            rows: [0, 1].map(|_| Rows {
                relaxed: vec![0.0; nx + 2],
                residual: vec![0.0; nx + 2],
            }),
            dots: vec![0.0; ny],
            keep: keep_patterns(nx),
            levels,
            coarsest,
            work,
            scratch: Vec::new(),
            cycle,
        }
    }

    /// `z ≈ A⁻¹ r`: one cycle from a zero guess. The fine right-hand side is `work[0][1]`,
    /// which the caller fills; the result is left in `work[0][0]`. Returns `z · r`.
    pub fn precondition(&mut self) -> f64 {
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
        for visit in 0..self.cycle.visits() {
            self.cycle(l + 1, visit == 0);
        }
        self.prolong_and_smooth(l)
    }

    /// Sweeps before and after a coarse correction on level `l` (see [`Cycle::sweeps`]).
    fn sweeps_on(&self, l: usize) -> usize {
        self.cycle.sweeps()[usize::from(l > 0)]
    }

    /// Pre-smoothing on level `l` (red then black, [`Cycle::sweeps`] times), then its residual
    /// summed into level `l + 1`'s right-hand side (each coarse cell sums its children's). One
    /// wavefront does it all (in parts, on two threads, on a tall level: see [`in_parts`]).
    fn smooth_and_restrict(&mut self, l: usize, zero_start: bool) {
        let sweeps = self.sweeps_on(l);
        let (fine_work, coarse_work) = self.work.split_at_mut(l + 1);
        let [x, b] = &mut fine_work[l];
        let (level, coarse) = (&self.levels[l], &self.levels[l + 1]);
        let coarse_b = &mut coarse_work[0][1];
        let keep = &self.keep;
        let colours = [[0, 1]; MAX_SWEEPS];
        let colours = &colours.as_flattened()[..2 * sweeps];
        // Above's rows restrict onto coarse rows from half its first `after` row on.
        let split = |part: Part| {
            let first = part.after(level.ny, colours.len()).start;
            coarse.row_start(first / 2)
        };
        let sweep = |part: Part,
                     x: &mut [f32],
                     (coarse_b, c_origin): (&mut [f32], usize),
                     rows: &mut Rows| {
            let origin = part.origin(level);
            let Rows { relaxed, residual } = rows;
            wide(
                #[inline(always)]
                || {
                    level.sweep(
                        colours,
                        zero_start,
                        part,
                        (x, b),
                        (relaxed, keep),
                        |_, _| {},
                        #[inline(always)]
                        |j, x| {
                            let cols = level.span(j);
                            if cols.is_empty() {
                                return;
                            }
                            let residual = &mut residual[..cols.len()];
                            level.residual_row(j, (x, origin), b, residual);
                            let base = coarse.pad(cols.start / 2, j / 2) - c_origin;
                            let parents = &mut coarse_b[base..base + cols.len().div_ceil(2)];
                            // The even row of a pair sets its parents, the odd one adds to them.
                            let first = if j % 2 == 0 { 0.0 } else { 1.0 };
                            let pairs = residual.chunks_exact(2);
                            if let (Some(r), Some(c)) =
                                (pairs.remainder().first(), parents.last_mut())
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
        };
        in_parts(level, (x, coarse_b), split, &mut self.rows, sweep);
    }

    /// Every active cell of level `l` gets its coarse cell's correction; then post-smoothing
    /// (black then red, [`Cycle::sweeps`] times). One wavefront does it all (in parts, on two
    /// threads, on a tall level: see [`in_parts`]). Returns `x · b` on the finest level (CG
    /// needs it, and each row is still in cache when it is final), else 0.
    fn prolong_and_smooth(&mut self, l: usize) -> f64 {
        let sweeps = self.sweeps_on(l);
        let (level, coarse) = (&self.levels[l], &self.levels[l + 1]);
        let (fine_work, coarse_work) = self.work.split_at_mut(l + 1);
        let [x, b] = &mut fine_work[l];
        let correction = &coarse_work[0][0];
        let keep = &self.keep;
        let colours = [[1, 0]; MAX_SWEEPS];
        let colours = &colours.as_flattened()[..2 * sweeps];
        // Above's rows' dots from its first `after` row on.
        let split = |part: Part| part.after(level.ny, colours.len()).start;
        let sweep =
            |part: Part, x: &mut [f32], (dots, d_origin): (&mut [f64], usize), rows: &mut Rows| {
                let origin = part.origin(level);
                let Rows { relaxed, residual } = rows;
                wide(
                    #[inline(always)]
                    || {
                        level.sweep(
                            colours,
                            false,
                            part,
                            (x, b),
                            (relaxed, keep),
                            #[inline(always)]
                            |j, x| {
                                let cols = level.span(j);
                                if cols.is_empty() {
                                    return;
                                }
                                let (start, n) = (level.pad(cols.start, j) - origin, cols.len());
                                let base = coarse.pad(cols.start / 2, j / 2);
                                let parents = &correction[base..base + n.div_ceil(2)];
                                let expanded = &mut residual[..2 * parents.len()];
                                for (pair, c) in expanded.chunks_exact_mut(2).zip(parents) {
                                    pair[0] = *c;
                                    pair[1] = *c;
                                }
                                let cells = &mut x[start..start + n];
                                let active = &level.inv_diag[start + origin..start + origin + n];
                                // Flushed like every value the cycle makes (see
                                // `Level::relax_row_from_zero`).
                                for ((x, a), c) in cells.iter_mut().zip(active).zip(&expanded[..n])
                                {
                                    // `c` read on every cell, then selected (see
                                    // `Level::residual_row`).
                                    let c = *c;
                                    *x = flushed(*x + if *a != 0.0 { c } else { 0.0 });
                                }
                            },
                            #[inline(always)]
                            |j, x| {
                                if l == 0 {
                                    let (k, n) = level.row(j);
                                    dots[j - d_origin] =
                                        dot(&x[k - origin..k - origin + n], &b[k..k + n]);
                                }
                            },
                        )
                    },
                );
            };
        let dots = &mut self.dots[..if l == 0 { level.ny } else { 0 }];
        in_parts(level, (x, dots), split, &mut self.rows, sweep);
        // Summed in row order, as one thread would.
        dots.iter().fold(0.0, |xb, d| xb + d)
    }
}

/// Two threads' buffers of one row each.
struct Rows {
    /// Relaxed values.
    relaxed: Vec<f32>,
    /// Residuals, or prolonged corrections.
    residual: Vec<f32>,
}

/// Runs `sweep(part, x, (out, origin), rows)` over `level` as one [`Part::Whole`]; or, when it
/// is at least [`SPLIT_ROWS`] tall (and `set_split` allows), over [`Part::Below`] and
/// [`Part::Above`] on two threads, each with its own part of `x` (split at Above's
/// [`Part::origin`]), of `out` (split at index `split(Above)`, which is Above's `origin` in
/// it; an empty `out` stays empty) and of `rows`, then over [`Part::Between`] with all of
/// them. Every cell's update is the one a single sweep makes, so the result does not depend on
/// the threads.
fn in_parts<O: Send>(
    level: &Level,
    (x, out): (&mut [f32], &mut [O]),
    split: impl Fn(Part) -> usize,
    rows: &mut [Rows; 2],
    sweep: impl Fn(Part, &mut [f32], (&mut [O], usize), &mut Rows) + Sync,
) {
    let [first, second] = rows;
    let Some(mid) = split_at(level) else {
        return sweep(Part::Whole, x, (out, 0), first);
    };
    let above = Part::Above { mid };
    {
        let (x_below, x_above) = x.split_at_mut(above.origin(level));
        let at = if out.is_empty() { 0 } else { split(above) };
        let (out_below, out_above) = out.split_at_mut(at);
        rayon::join(
            || sweep(Part::Below { mid }, x_below, (out_below, 0), first),
            || sweep(above, x_above, (out_above, at), second),
        );
    }
    sweep(Part::Between { mid }, x, (out, 0), first);
}

/// Whether `level` is tall enough for two threads (see [`in_parts`]), and where its rows split.
pub fn split_at(level: &Level) -> Option<usize> {
    // An even middle, so that each coarse row's two fine rows are in one part or in order.
    (level.ny >= SPLIT_ROWS && SPLIT.load(Ordering::Relaxed)).then_some(level.ny / 4 * 2)
}

/// Whether tall levels are swept by two threads (see [`in_parts`]): on unless a test compares
/// against one thread.
static SPLIT: AtomicBool = AtomicBool::new(true);

/// Lets tall levels be swept by two threads (`true`, the default) or not. The results are the
/// same either way.
#[cfg(test)]
pub fn set_split(split: bool) {
    SPLIT.store(split, Ordering::Relaxed);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix;

    /// `z = M r` of the cycle for `r` (on the finest level's layout), and `z · r` as the cycle
    /// sums it.
    fn precondition(h: &mut Hierarchy, r: &[f32]) -> (Vec<f32>, f64) {
        h.work[0][1].copy_from_slice(r);
        let zr = h.precondition();
        (h.work[0][0].clone(), zr)
    }

    /// CG needs a symmetric preconditioner: `r₂ · M r₁ = r₁ · M r₂` for both cycles, with the
    /// sweeps each takes on each level (the pre-smoothing's colours in one order, the
    /// post-smoothing's in the other, as many of each), on a grid with walls and a ragged edge.
    /// It fails when the post-smoothing sweeps once fewer than the pre-smoothing, or in the
    /// same order.
    #[test]
    fn each_cycle_is_a_symmetric_operator() {
        let (nx, ny) = (45, 38);
        let unknown: Vec<bool> = (0..nx * ny)
            .map(|k| {
                let (i, j) = (k % nx, k / nx);
                let wall = j == 17 && i != 30;
                let ragged = i + 2 * j < 9 || i > 40 + j % 3;
                !(wall || ragged)
            })
            .collect();
        for cycle in [Cycle::V, Cycle::W] {
            let mut h = Hierarchy::new(nx, ny, &unknown, cycle);
            let fine = &h.levels[0];
            let n = fine.len();
            let mut random = SplitMix::new(7);
            let mut draw = || -> Vec<f32> {
                (0..n)
                    .map(|k| {
                        let r = random.uniform() as f32 - 0.5;
                        if fine.active(k) != 0.0 { r } else { 0.0 }
                    })
                    .collect()
            };
            let (r1, r2) = (draw(), draw());
            let (z1, z1r1) = precondition(&mut h, &r1);
            let (z2, z2r2) = precondition(&mut h, &r2);
            let dot = |a: &[f32], b: &[f32]| -> f64 {
                a.iter()
                    .zip(b)
                    .map(|(x, y)| f64::from(*x) * f64::from(*y))
                    .sum()
            };
            let (a, b) = (dot(&r2, &z1), dot(&r1, &z2));
            let scale = (z1r1 * z2r2).sqrt();
            assert!(z1r1 > 0.0 && z2r2 > 0.0, "{cycle:?}: not positive");
            assert!(
                (a - b).abs() <= 1e-5 * scale,
                "{cycle:?}: r2 · M r1 = {a:e}, r1 · M r2 = {b:e} (scale {scale:e})"
            );
        }
    }
}
