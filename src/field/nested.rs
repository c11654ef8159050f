//! The nested solves that carry `W` below what one solve resolves, level after level, to any
//! depth, each level costing what its band of cells costs (design page, "Fields of any
//! depth").
//!
//! After the first solve, the cells it resolves to full relative precision are *accepted*
//! (those with `W ≥ τ`, and those a few steps from them, see [`deep_cells`]); the others are
//! *pending*, their values only estimates. Each level then:
//!
//! 1. takes a **band** of pending cells next to the accepted cells whose `W` is within
//!    [`LEVEL_RANGE`] of the largest such (so cells are accepted in order of decreasing `W`,
//!    and no cut lies where a larger `W` still flows in): the *core*, every pending cell within
//!    a number of steps that adapts (from [`CORE_STEPS`]) or reached through cells whose
//!    estimate is still reliable (at least [`BAND`] of the scale of the solve that gave it);
//!    a *margin* of [`MARGIN`] more layers; and every pending cell left when they fit in as
//!    many cells again (a room's deep corner: then there is no cut);
//! 2. solves each connected part of the band, with the accepted cells around it as Dirichlet
//!    values, scaled so that the largest is about 1, and `W = 0` at the *cut* (the pending
//!    cells beyond the band): a lower bound of the true `W`, exact at the accepted cells and
//!    close to it away from the cut. A narrow part (a stretch of corridor) is solved directly
//!    (`banded.rs`, accurate cell by cell), a wide one by multigrid on its cells and their
//!    neighbours, row by row (its bounding box can be mostly empty);
//! 3. accepts the cells of the part that the solve resolves (at least `τ` of its scale), that
//!    are more than [`MARGIN`] steps from the cut and at least [`GAP`] times the values near it,
//!    stored with the exponent of the part's scale ([`ScaledW`]).
//!
//! Every level accepts at least the cells next to the largest accepted neighbour, so the
//! levels end when every reachable cell is accepted. A cell is solved in about
//! `(core + margin) / advance` levels (two or three in a corridor), so the levels together
//! cost a few solves of the deep cells, not depth × map.
//!
//! Why the cut is safe: each part's solution is harmonic inside the part with its largest
//! values on the accepted cells around it, so the composite `W` has no local maximum but the
//! target, whatever the error near a cut; and a cut more than a margin away from the cells it
//! accepts changes them by little (in a corridor of width `w`, by about `e^(−2π x / w)` at a
//! distance `x`).

use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

use rayon::prelude::*;

use super::banded;
use super::grid::Grid;
use super::join_if;
use super::multigrid;
use super::scaled::{ScaledW, exponent_of, ldexp};

/// The depth each level resolves: a cell is resolved when its `W` is at least this fraction of
/// the scale of its solve (a solve to a relative residual of 1e-12 gives about 1e-12 of its
/// scale absolutely, so such a cell has six digits).
pub const DEPTH_STEP: f64 = 1e-6;
/// How many steps through free cells a cell below the depth may be from a cell above it and
/// still count as resolved (see [`deep_cells`]).
pub const REACH: usize = 8;
/// No cell below this fraction of its solve's scale counts as resolved, however close to a
/// resolved cell: 10 times the absolute precision of a solve to a relative residual of 1e-12.
/// (A cell next to a wall a few steps from a resolved one is far above it: in a corridor one
/// cell wide, `REACH` steps lose a factor 3e-5. A cell this small near a resolved one is at the
/// end of a dead end, where the solve's own error could leave it negative.)
pub const FLOOR: f64 = 1e-11;
/// Steps from the accepted cells that a band's core covers at first. The extent adapts: it
/// doubles after each level in which the cut, rather than the depth, limited what was
/// accepted (`W` falls slowly there: a wide region), until a level is limited by the depth;
/// from then on it grows by [`CORE_GROWTH`] after a level the cut limited and shrinks by
/// [`CORE_SHRINK`] (not below this) after one the depth did (a narrow corridor).
pub const CORE_STEPS: u32 = 8;
/// The factor a band's core grows by after a level the cut limited, once the extent has first
/// been enough. A level accepts what the depth allows whatever the extent beyond it, so an
/// extent past the cut's reach only costs: the extent tracks the least that the cut does not
/// limit, a little above it after each cut-limited level and a little below it after a few
/// others, so that few cells beyond what the depth allows are solved. (Doubling at first,
/// until the extent is first enough, reaches a wide region in as few levels as before: every
/// field that is never depth-limited solves exactly as it did.)
///
/// Measured on the rooms map (2560² cells; its own field and seven scenarios spread over its
/// scenario file, `1 − V` at their starts from 4e-6 to 1e-544; `nadf field`):
/// - doubling and halving swung the core 64 → 128 → 256 steps and back: 141 levels and
///   22.7 M cells for the longest field;
/// - 1.5 and 0.75 swung it between about 85 and 144 steps, and two thirds of the cells solved
///   ended below what the depth allows (8.5 M of the longest field's 13.2 M): 13.0–14.3 M
///   cells a field, 4.9–5.5 s of CPU;
/// - 1.1 and 0.95 (these): 11.4–12.1 M cells a field (14 % fewer in all), 4.2–4.5 s of CPU;
///   the longest field in 2.68–2.92 s against 3.21–3.84 s (medians 2.75 and 3.31 s, five
///   alternating runs), every cell within 3.4e-6 relative of 1.5 and 0.75's;
/// - gentler still gained little there and cost the corridors of `maze.toml`: 1.05 and 0.98
///   solved 196 k cells against 151 k (these: 163 k).
///
/// Growing by 1.5 from the start, instead of doubling, cost `map-depot` 451 k cells against
/// 325 k (0.30 s against 0.22 s).
pub const CORE_GROWTH: f64 = 1.1;
/// The factor a band's core shrinks by after a level the depth limited (see [`CORE_GROWTH`]).
pub const CORE_SHRINK: f64 = 0.95;
/// The largest extent of a band's core, in steps.
pub const MAX_CORE_STEPS: u32 = 1 << 16;
/// An estimate of at least this fraction of its solve's scale is reliable enough to extend a
/// band's core through.
pub const BAND: f64 = 1e-10;
/// Layers of pending cells beyond a band's core; cells this close to the cut are not accepted.
pub const MARGIN: u32 = 8;
/// Each level works from the frontier cells whose `W` is within this factor of the largest.
pub const LEVEL_RANGE: f64 = 1e-12;
/// A cell is accepted only if it is at least this many times the largest value within
/// [`MARGIN`] of the cut. Where `W` falls exponentially away from the frontier (a corridor),
/// the cut changes a cell by the square of their ratio, so this keeps the relative error below
/// about 1e-6 whatever the corridor's width: the wider the corridor, the slower `W` falls and
/// the farther from the cut a cell must be.
pub const GAP: f64 = 1e3;
/// CG iterations allowed per solve.
pub const MAX_ITERATIONS: usize = 500;
/// An estimate below this fraction of the scale of the solve that made it has no digit left:
/// it is under the rounding of that solve's largest values (f64's epsilon), noise of either
/// sign. A part's multigrid solve starts such cells at 0 rather than from the estimate: scaled
/// to the part, whose scale can be many decades lower, the noise can come out anywhere up to
/// the largest value around the part (the bound it is clamped to), and CG then first has to
/// take that out. Measured on the rooms map's longest field: 4,825 CG iterations over the
/// parts' solves from every estimate, 3,199 with this bar; 3,201–4,050 with bars from 1e-16 to
/// 1e-11 (fewer the lower), 6,624 from 0 everywhere.
pub const NO_DIGIT: f64 = f64::EPSILON;
/// How far below `W` at the agent a field solved for a run is carried: once every pending cell
/// is below this fraction of it, the levels stop and leave those cells at 0 (see
/// `solve_levels`). The guidance leads up `W`, and a body strays from its kinematic path by
/// about `m v / B_d`, under a metre; fifty decades lie far behind it (on the Moving AI rooms map
/// about a room back, through its one-cell door; in a corridor one cell wide, 87 cells). A
/// field exported or drawn on its own (`nadf field`) is solved to every cell.
pub const BELOW_AGENT: f64 = 1e-50;
/// The widest band a part of a field's level may have to be solved directly (`banded.rs`)
/// rather than by multigrid: a corridor or two. The direct solve costs `n · b²` for a band `b`,
/// multigrid about 13 iterations of a few tens of nanoseconds per cell, so past a dozen cells
/// multigrid is the cheaper. Measured on the rooms map's longest field (`nadf field`, 2 cores):
/// 3.33–3.40 s against 3.90–4.44 s with 48; 13.2 M cells solved in both, 4,894 CG iterations
/// against 3,192 (the parts solved directly count none). Bands of 8 and 16 measured like 12.
pub const MAX_BAND: usize = 12;
/// [`MAX_BAND`] for a window's field: with 12 there, the crowds fell back to whole re-solves
/// more often (64 robots on the 1.8 m circle: 146 against 94; over four seeds of 16 and of 32
/// robots, 876 and 1,643 against 797 and 1,514), probably because a window is solved to a
/// looser tolerance, which multigrid meets on a narrow part less exactly than the direct
/// solve, cell by cell.
pub const WINDOW_MAX_BAND: usize = 48;

/// What the nested levels did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LevelStats {
    /// Levels run.
    pub levels: usize,
    /// Solves (connected parts of bands).
    pub solves: usize,
    /// CG iterations over all solves.
    pub iterations: usize,
    /// The worst relative residual.
    pub relative_residual: f64,
    /// Cells solved, summed over the solves (a cell solved in three levels counts three times).
    pub cells_solved: usize,
    /// Reachable cells left at `W = 0`, all below [`BELOW_AGENT`] of `W` at the agent the field
    /// was solved for (0 when solved to every cell).
    pub left: usize,
}

/// The cells below `depth` that need a nested solve: those more than [`REACH`] steps through
/// free cells from any cell at or above it.
///
/// A cell next to a wall has a small `W` however close it is to the target, because `W = 0` on
/// the wall; but so has the solve's error, which is harmonic with the same zero there, so such a
/// cell is known to the relative precision of the cells a few steps away from the wall.
/// Counting them as deep would make the nested solves cover every wall of the world. The
/// distance is counted through free cells: across a wall, a cell's neighbourhood says nothing
/// about it. (In a corridor one cell wide, the narrowest there is, `W` falls by 2 − √3 per
/// cell, so `REACH` steps lose at most a factor 3e-5 of relative precision.)
pub fn deep_cells(grid: &Grid, unknown: &[bool], w: &[f64], depth: f64) -> Vec<bool> {
    let below = |k: usize| unknown[k] && w[k] < depth;
    let mut deep: Vec<bool> = (0..grid.len()).map(below).collect();
    let floor = FLOOR * depth / DEPTH_STEP;
    // Breadth-first from the cells below the depth that touch one above it.
    let mut front = Vec::new();
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let k = grid.index(i, j);
            if deep[k]
                && w[k] >= floor
                && grid
                    .neighbours(i, j)
                    .any(|(a, b)| unknown[grid.index(a, b)] && !below(grid.index(a, b)))
            {
                front.push((i, j));
            }
        }
    }
    for &(i, j) in &front {
        deep[grid.index(i, j)] = false;
    }
    for _ in 1..REACH {
        let mut next = Vec::new();
        for &(i, j) in &front {
            for (a, b) in grid.neighbours(i, j) {
                let k = grid.index(a, b);
                if deep[k] && w[k] >= floor {
                    deep[k] = false;
                    next.push((a, b));
                }
            }
        }
        front = next;
    }
    deep
}

/// After a first solve on the cells `solved` only, with `W = 0` held on the other `unknown`
/// cells (a box around the target on a large map: see `harmonic.rs`), marks `pending` the
/// solved cells that the cut between the two may have changed, by the rule of a nested level
/// (see [`Levels::resolved`]): those within [`MARGIN`] steps of it, and those below [`GAP`]
/// times the largest `W` there. Returns whether that left every cell above [`DEPTH_STEP`]
/// accepted; if not, the cut kept the solve from resolving what it should have (a box too
/// small for the field's depth), and the first solve must be made on every cell.
pub fn cut_from_the_rest(
    grid: &Grid,
    (unknown, solved): (&[bool], &[bool]),
    w: &[f64],
    pending: &mut [bool],
) -> bool {
    let mut near = vec![false; grid.len()];
    // The cut: solved cells next to an unknown one that was not solved.
    let mut layer: Vec<usize> = (0..grid.len())
        .filter(|&k| solved[k] && grid.neighbours_of(k).any(|m| unknown[m] && !solved[m]))
        .collect();
    // The largest `W` within MARGIN steps of the cut.
    let mut at_cut: f64 = 0.0;
    for &k in &layer {
        near[k] = true;
        at_cut = at_cut.max(w[k]);
    }
    for _ in 0..MARGIN {
        let mut next = Vec::new();
        for &k in &layer {
            for m in grid.neighbours_of(k) {
                if solved[m] && !near[m] {
                    near[m] = true;
                    at_cut = at_cut.max(w[m]);
                    next.push(m);
                }
            }
        }
        layer = next;
    }
    for k in 0..grid.len() {
        if solved[k] && !pending[k] && (near[k] || w[k] < GAP * at_cut) {
            if w[k] >= DEPTH_STEP {
                return false;
            }
            pending[k] = true;
        }
    }
    true
}

/// A level's parts are solved in parallel when they hold at least this many cells together
/// (below it, the threads would cost more than they save; the results are the same either way).
pub const PARALLEL_CELLS: usize = 20_000;

/// One connected part of a band.
struct Part {
    /// Its cells, breadth first from the first (their slots).
    cells: Vec<usize>,
    /// Whether the search that found it proved it too wide for a direct solve
    /// ([`banded::proves_wider`] from its first cell, the bound [`banded::solve`] refuses it
    /// on): it goes to multigrid without building the direct solve's system first, a pass
    /// over all its cells (5 ms of the 1024² room's 147 k-cell part).
    wide: bool,
    /// Its number, in its cells' marks (`Levels::part`).
    number: u32,
}

/// `Levels::dist` of a band's cells on the margin's last layer, the only ones that can touch
/// the cut: never a step count (each below the number of cells) nor a tail search's mark
/// (`u32::MAX` less a level, from 1).
const LAST_LAYER: u32 = u32::MAX;

/// A part solved, with its resolved cells and whether the cut kept resolved cells out (see
/// [`Levels::resolved`]).
type Outcome = (Solved, (Vec<usize>, bool));

/// One part of a band, solved: its cells' values (in the part's order) at the scale `2^scale`.
struct Solved {
    values: Vec<f64>,
    scale: i32,
    /// CG iterations (0 for a direct solve).
    iterations: usize,
    relative_residual: f64,
}

/// The state of the nested levels over the whole grid. Every per-level pass touches only the
/// cells of the band and the frontier (marks are level stamps, never cleared), so a level costs
/// what its band costs however large the map.
struct Levels<'a> {
    grid: &'a Grid,
    w: &'a mut ScaledW,
    tolerance: f64,
    /// The widest part solved directly ([`MAX_BAND`] or [`WINDOW_MAX_BAND`]).
    max_band: usize,
    /// Reachable cells not accepted yet.
    pending: Vec<bool>,
    /// How many cells are pending.
    pending_count: usize,
    /// Accepted cells with a pending neighbour.
    frontier: Vec<usize>,
    /// `band[k] == level` when cell `k` is in this level's band.
    band: Vec<u32>,
    /// Steps from the accepted cells (in the band), [`LAST_LAYER`] on the margin's last layer;
    /// beyond the band, the tail search's marks (see [`TailSearch`]).
    dist: Vec<u32>,
    /// The number of the part of the band a cell is in (in the band; see [`PartSearch`]).
    /// Atomic (relaxed loads and stores, plain ones on x86) so that a part's solve can read its
    /// cells' marks while the search goes on numbering the next parts' (see
    /// [`Levels::search_and_solve`]).
    part: Vec<AtomicU32>,
    /// A band cell's index in its part (set with `part` by [`PartSearch`]).
    slot: Vec<AtomicU32>,
    /// Levels whose parts were solved as the search found them (see
    /// [`Levels::search_and_solve`]); `None` when no level may do that.
    pipelined: Option<usize>,
    /// Parts numbered so far (see [`PartSearch`]).
    numbered: u32,
    level: u32,
    /// The extent of the next band's core, in steps.
    core_steps: u32,
    /// Whether a level has been limited by the depth rather than the cut: the core's extent
    /// was enough once, and is tuned from then on rather than doubled.
    settled: bool,
    stats: LevelStats,
}

/// When the nested levels may stop before every reachable cell is accepted, leaving the cells
/// still pending at 0. Whatever the rule, every cell kept is the full solve's to the bit: the
/// levels run alike until they stop, and only ever write pending cells.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Stop {
    /// Never: every reachable cell is solved (a field exported or drawn on its own).
    Never,
    /// For an agent at this cell: once it is accepted and every pending cell is below
    /// [`BELOW_AGENT`] of it. None left out is above the bound: the pending cells are bounded
    /// by the accepted cells around them and the walls' 0, so by the largest `W` on the
    /// frontier (the maximum principle), and the levels stop only when that is below it.
    BelowAgent(usize),
    /// Once every cell of this box (cell index ranges along x and y) is accepted: a field read
    /// only there (a coarse window, which gives the rings of the fine windows near its centre).
    Within(std::ops::Range<usize>, std::ops::Range<usize>),
}

/// Runs the nested levels on `w` (the first solve's values, exponent 0) until every cell is
/// accepted, or until `stop` allows; `pending` are the cells the first solve did not resolve.
/// Each part is solved to `tolerance`, directly when its band is at most `max_band`.
/// The cells still pending then are left at 0 (counted in [`LevelStats::left`]).
pub fn solve_levels(
    grid: &Grid,
    pending: Vec<bool>,
    w: &mut ScaledW,
    (tolerance, max_band): (f64, usize),
    stop: &Stop,
) -> LevelStats {
    run_levels(grid, pending, w, (tolerance, max_band), stop, true).0
}

/// [`solve_levels`], solving a level's parts as its search finds them when `pipelined` allows
/// (see [`Levels::search_and_solve`]), else after it; and how many levels did.
fn run_levels(
    grid: &Grid,
    pending: Vec<bool>,
    w: &mut ScaledW,
    (tolerance, max_band): (f64, usize),
    stop: &Stop,
    pipelined: bool,
) -> (LevelStats, usize) {
    // Nothing deep (a window, most often): nothing to set up.
    if !pending.contains(&true) {
        return (LevelStats::default(), 0);
    }
    let n = grid.len();
    let mut levels = Levels::new(grid, pending, w, (tolerance, max_band));
    levels.pipelined = pipelined.then_some(0);
    // The first frontier: accepted cells (the target among them) next to pending ones.
    for k in 0..n {
        if levels.accepted(k) && levels.neighbours(k).any(|m| levels.pending[m]) {
            levels.frontier.push(k);
        }
    }
    // The pending cells of the box a `Stop::Within` keeps.
    let in_box = |k: usize| match stop {
        Stop::Within(i, j) => i.contains(&(k % grid.nx)) && j.contains(&(k / grid.nx)),
        _ => false,
    };
    let mut in_box_pending = match stop {
        Stop::Within(i, j) => j
            .clone()
            .flat_map(|j| i.clone().map(move |i| grid.index(i, j)))
            .filter(|&k| levels.pending[k])
            .count(),
        _ => 0,
    };
    while !levels.frontier.is_empty() {
        let top = levels.top();
        let done = match stop {
            Stop::Never => false,
            Stop::BelowAgent(k) => levels.deep_enough(*k, top),
            Stop::Within(..) => in_box_pending == 0,
        };
        if done {
            levels.leave_the_rest();
            break;
        }
        let accepted = levels.run_level(top);
        in_box_pending -= accepted.iter().filter(|&&k| in_box(k)).count();
    }
    (levels.stats, levels.pipelined.unwrap_or(0))
}

impl<'a> Levels<'a> {
    /// No level run yet, no frontier, `pending` as given.
    fn new(
        grid: &'a Grid,
        pending: Vec<bool>,
        w: &'a mut ScaledW,
        (tolerance, max_band): (f64, usize),
    ) -> Self {
        let n = grid.len();
        Self {
            grid,
            w,
            tolerance,
            max_band,
            frontier: Vec::new(),
            band: vec![0; n],
            dist: vec![0; n],
            part: (0..n).map(|_| AtomicU32::new(0)).collect(),
            slot: (0..n).map(|_| AtomicU32::new(0)).collect(),
            numbered: 0,
            level: 0,
            core_steps: CORE_STEPS,
            settled: false,
            stats: LevelStats::default(),
            pipelined: None,
            pending_count: pending.iter().filter(|&&p| p).count(),
            pending,
        }
    }

    /// The 4-neighbours of cell `k`, as indices.
    fn neighbours(&self, k: usize) -> impl Iterator<Item = usize> + use<> {
        self.grid.neighbours_of(k)
    }

    fn in_band(&self, k: usize) -> bool {
        self.band[k] == self.level
    }

    fn accepted(&self, k: usize) -> bool {
        !self.pending[k] && self.w.mantissa[k] > 0.0
    }

    /// `log2` of the largest `W` on the frontier: every pending cell is below it.
    fn top(&self) -> f64 {
        self.frontier
            .iter()
            .map(|&k| self.w.log2(k))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether the agent's cell `k` is accepted and every pending cell is below
    /// [`BELOW_AGENT`] of it (`top`: the frontier's [`Levels::top`]).
    fn deep_enough(&self, k: usize, top: f64) -> bool {
        self.accepted(k) && top < self.w.log2(k) + BELOW_AGENT.log2()
    }

    /// Leaves every pending cell at 0, at the scale of the deepest frontier cell (so that no
    /// sample near them is taken at a larger scale than their accepted neighbours').
    fn leave_the_rest(&mut self) {
        let deepest = (self.frontier.iter())
            .map(|&k| self.w.exponent[k])
            .min()
            .unwrap_or(0);
        for k in 0..self.pending.len() {
            if self.pending[k] {
                self.pending[k] = false;
                self.pending_count -= 1;
                self.w.mantissa[k] = 0.0;
                self.w.exponent[k] = deepest;
                self.stats.left += 1;
            }
        }
        self.frontier.clear();
    }

    /// One level: the band, its parts solved, their resolved cells accepted (`top`: the
    /// frontier's [`Levels::top`]). Returns the cells it accepted.
    fn run_level(&mut self, top: f64) -> Vec<usize> {
        self.level += 1;
        self.stats.levels += 1;
        // This level works from the frontier cells within LEVEL_RANGE of the largest, and
        // accepts nothing below GAP times that: cells are accepted in order of decreasing `W`,
        // a few decades per level, so a cut never lies where a larger `W` still flows in.
        let lowest = top + LEVEL_RANGE.log2();
        let (mut band, margin) = self.band_cells(lowest);
        // The band's parts, and meanwhile its tail, when every pending cell left beyond it fits
        // in as many cells again: most levels' rest does not, and the parts found without it
        // stand. Then they are solved; a large band without a tail has them solved as the
        // search finds them (the results are the same).
        let tail_may_fit = self.pending_count - band.len() <= band.len();
        let pipelined = self.pipelined.is_some() && band.len() >= PARALLEL_CELLS;
        let (parts, results) = if tail_may_fit || !pipelined {
            let (parts_search, tail_search) = self.searches();
            let (mut parts, tail) = if tail_may_fit {
                join_if(
                    band.len() >= PARALLEL_CELLS,
                    || parts_search.all(&band),
                    || tail_search.run(margin, band.len()),
                )
            } else {
                (parts_search.all(&band), None)
            };
            if let Some(tail) = tail {
                for &m in &tail {
                    self.band[m] = self.level;
                }
                band.extend_from_slice(&tail);
                // Numbered on from the parts found without the tail, which marked their cells.
                self.numbered += parts.len() as u32;
                parts = self.searches().0.all(&band);
            }
            self.numbered += parts.len() as u32;
            let results = self.solve_parts(&parts, lowest);
            (parts, results)
        } else {
            let found = self.search_and_solve(&band, lowest);
            self.numbered += found.len() as u32;
            self.pipelined = self.pipelined.map(|n| n + 1);
            found.into_iter().unzip()
        };
        let mut accepted = Vec::new();
        let mut cut_limited = false;
        for (Part { cells, .. }, (solved, (resolved, limited))) in parts.iter().zip(results) {
            self.stats.solves += 1;
            self.stats.cells_solved += cells.len();
            self.stats.iterations += solved.iterations;
            self.stats.relative_residual =
                self.stats.relative_residual.max(solved.relative_residual);
            for (&k, &v) in cells.iter().zip(&solved.values) {
                self.w.mantissa[k] = v;
                self.w.exponent[k] = solved.scale;
            }
            accepted.extend(resolved);
            cut_limited |= limited;
        }
        self.settled |= !cut_limited;
        let steps = f64::from(self.core_steps);
        let steps = if cut_limited && !self.settled {
            2.0 * steps
        } else if cut_limited {
            (CORE_GROWTH * steps).ceil()
        } else {
            (CORE_SHRINK * steps).floor()
        };
        self.core_steps = (steps as u32).clamp(CORE_STEPS, MAX_CORE_STEPS);
        for &k in &accepted {
            self.pending[k] = false;
        }
        self.pending_count -= accepted.len();
        // The frontier: the old one and the new cells, where they still touch pending cells.
        let mut frontier = std::mem::take(&mut self.frontier);
        frontier.extend_from_slice(&accepted);
        frontier.retain(|&k| self.neighbours(k).any(|m| self.pending[m]));
        self.frontier = frontier;
        accepted
    }

    /// Solves `parts` and finds their resolved cells (see [`Levels::solve_and_resolve`]): in
    /// parallel when there is enough work.
    fn solve_parts(&self, parts: &[Part], lowest: f64) -> Vec<Outcome> {
        let solve = |part: &Part| self.solve_and_resolve(part, lowest);
        let work: usize = parts.iter().map(|p| p.cells.len()).sum();
        if parts.len() > 1 && work >= PARALLEL_CELLS {
            parts.par_iter().map(solve).collect()
        } else {
            parts.iter().map(solve).collect()
        }
    }

    /// The band's parts, each solved (see [`Levels::solve_and_resolve`]) as soon as the search
    /// has found it, while the search goes on: the search is one thread's work, and the other
    /// would otherwise wait for it. In the order the search found them, so the results are
    /// those of searching first and solving after.
    fn search_and_solve(&self, band: &[usize], lowest: f64) -> Vec<(Part, Outcome)> {
        let search = self.part_search();
        let (sender, found) = std::sync::mpsc::channel();
        rayon::scope(|s| {
            search.run(band, |part| {
                let sender = sender.clone();
                s.spawn(move |_| {
                    let result = self.solve_and_resolve(&part, lowest);
                    // The receiver outlives the scope.
                    let _ = sender.send((part, result));
                });
            });
        });
        drop(sender);
        // The search numbers the parts in the order it finds them.
        let mut found: Vec<_> = found.into_iter().collect();
        found.sort_unstable_by_key(|(part, _)| part.number);
        found
    }

    /// A part solved, and its resolved cells. The parts are disjoint and each reads only the
    /// accepted cells around it and its own cells' marks, so they are solved independently,
    /// with the same results in any order and on any thread.
    fn solve_and_resolve(&self, part: &Part, lowest: f64) -> Outcome {
        let solved = self.solve_part(part);
        let resolved = self.resolved(&part.cells, &solved, lowest);
        (solved, resolved)
    }

    /// This level's band: its core (breadth-first from the frontier) and its margin; and the
    /// margin's last layer (where a tail would start, see [`TailSearch`]).
    fn band_cells(&mut self, lowest: f64) -> (Vec<usize>, Vec<usize>) {
        let level = self.level;
        let mut band = Vec::new();
        for i in 0..self.frontier.len() {
            if self.w.log2(self.frontier[i]) < lowest {
                continue;
            }
            for m in self.neighbours(self.frontier[i]) {
                if self.pending[m] && !self.in_band(m) {
                    self.band[m] = level;
                    self.dist[m] = 1;
                    band.push(m);
                }
            }
        }
        // The core: within CORE_STEPS, or through reliable estimates; and its cells with a
        // pending neighbour it leaves out, where the margin starts (in the core's order, so the
        // margin's layers are those a pass over every core cell would find, in that order).
        let mut edge = Vec::new();
        let mut head = 0;
        while head < band.len() {
            let k = band[head];
            head += 1;
            let d = self.dist[k] + 1;
            for m in self.neighbours(k) {
                if !self.pending[m] || self.band[m] == level {
                    continue;
                }
                if d <= self.core_steps || self.w.mantissa[m] >= BAND {
                    self.band[m] = level;
                    self.dist[m] = d;
                    band.push(m);
                } else if edge.last() != Some(&k) {
                    edge.push(k);
                }
            }
        }
        // The margin. (A cell the core leaves out at one step it leaves out at every later one,
        // which is no shorter, so the core's edge is where its pending neighbours are.)
        let mut layer = edge;
        for _ in 0..MARGIN {
            let mut next = Vec::new();
            for &k in &layer {
                let d = self.dist[k] + 1;
                for m in self.neighbours(k) {
                    if self.pending[m] && self.band[m] != level {
                        self.band[m] = level;
                        self.dist[m] = d;
                        next.push(m);
                    }
                }
            }
            band.extend_from_slice(&next);
            layer = next;
        }
        // Only the margin's last layer can touch the cut (every pending neighbour of a cell
        // before it is in the band): marked so that a part's cells next to the cut are found
        // among those alone (see `Levels::resolved`).
        for &k in &layer {
            self.dist[k] = LAST_LAYER;
        }
        (band, layer)
    }

    /// The searches for this level's band's parts and for its tail, each with the marks it
    /// reads and writes (apart, so that they can run at once).
    fn searches(&mut self) -> (PartSearch<'_>, TailSearch<'_>) {
        let parts = PartSearch::of(
            (self.grid, &self.band),
            (&self.part, &self.slot),
            (self.level, self.max_band, self.numbered),
        );
        let tail = TailSearch {
            grid: self.grid,
            pending: &self.pending,
            band: &self.band,
            level: self.level,
            visited: &mut self.dist,
        };
        (parts, tail)
    }

    /// The search for this level's band's parts alone.
    fn part_search(&self) -> PartSearch<'_> {
        PartSearch::of(
            (self.grid, &self.band),
            (&self.part, &self.slot),
            (self.level, self.max_band, self.numbered),
        )
    }

    /// Solves a part of the band (its cells are in the order of their slots), with the
    /// accepted cells around it as Dirichlet values and 0 at the cut, at the scale `2^e` of its
    /// largest accepted neighbour: directly when it is narrow, else by multigrid (see
    /// [`Levels::solve_wide`]). Reads only `self`.
    fn solve_part(
        &self,
        Part {
            cells,
            wide,
            number,
        }: &Part,
    ) -> Solved {
        // The accepted cells around the part (some more than once), and the scale of the
        // largest.
        let around: Vec<usize> = (cells.iter())
            .flat_map(|&k| self.neighbours(k))
            .filter(|&m| self.accepted(m))
            .collect();
        let scale = (around.iter())
            .map(|&m| self.w.exponent[m] + exponent_of(self.w.mantissa[m]))
            .max()
            .unwrap_or(0);
        let narrow = if *wide {
            None
        } else {
            self.solve_narrow(*number, cells, scale)
        };
        match narrow {
            Some(values) => Solved {
                values,
                scale,
                iterations: 0,
                relative_residual: 0.0,
            },
            None => self.solve_wide(cells, &around, scale),
        }
    }

    /// Solves the part numbered `number` directly (see `banded.rs`) at the scale `2^scale`;
    /// `None` when it is too wide for that.
    fn solve_narrow(&self, number: u32, cells: &[usize], scale: i32) -> Option<Vec<f64>> {
        let mine = |m: usize| self.in_band(m) && self.part[m].load(Relaxed) == number;
        let mut neighbours = Vec::with_capacity(cells.len());
        let mut rhs = vec![0.0; cells.len()];
        for (slot, &k) in cells.iter().enumerate() {
            let mut inside = [u32::MAX; 4];
            for (n, m) in self.neighbours(k).enumerate() {
                if mine(m) {
                    inside[n] = self.slot[m].load(Relaxed);
                } else if self.accepted(m) {
                    rhs[slot] += self.w.at_scale(m, scale);
                }
            }
            neighbours.push(inside);
        }
        banded::solve(&neighbours, &rhs, self.max_band)
    }

    /// Solves a wide part by multigrid at the scale `2^scale`, with the accepted cells `around`
    /// it as Dirichlet values, on its cells and the cells next to them only (see
    /// [`multigrid::Rows`]): the bounding box of a part that winds through a map is mostly
    /// empty.
    fn solve_wide(&self, cells: &[usize], around: &[usize], scale: i32) -> Solved {
        let g = self.grid;
        let column_row = |k: usize| (k % g.nx, k / g.nx);
        let at: Vec<(usize, usize)> = cells.iter().map(|&k| column_row(k)).collect();
        let (ir, jr) = g.box_of(at.iter().copied()).expect("a part has cells");
        let (i0, j0) = (ir.start, jr.start);
        let rows = multigrid::Rows::around(
            ir.len(),
            jr.len(),
            at.iter().map(|&(i, j)| (i - i0, j - j0)),
        );
        let stored = |(i, j): (usize, usize)| {
            rows.index(i - i0, j - j0)
                .expect("a part's cells and their neighbours are stored")
        };
        // Each cell's index in `rows`.
        let local: Vec<usize> = at.into_iter().map(stored).collect();
        let mut unknown = vec![false; rows.len()];
        for &l in &local {
            unknown[l] = true;
        }
        // The accepted cells around the part at its scale; 0 everywhere else (blocked cells,
        // the pending cells beyond the cut, and stored cells that do not touch the part);
        // the part's own estimates as the starting guess, within the bounds of the solution
        // (the values around it): an estimate made at a larger scale can be far above them,
        // and CG, which updates its residual rather than recomputing it, would keep the
        // rounding of a huge first residual. An estimate below [`NO_DIGIT`] of the scale of the
        // solve that made it starts at 0 instead (see there).
        let mut values = vec![0.0; rows.len()];
        let mut largest: f64 = 0.0;
        for &m in around {
            let value = self.w.at_scale(m, scale);
            values[stored(column_row(m))] = value;
            largest = largest.max(value);
        }
        for (&k, &l) in cells.iter().zip(&local) {
            values[l] = if self.w.mantissa[k] >= NO_DIGIT {
                self.w.at_scale(k, scale).clamp(0.0, largest)
            } else {
                0.0
            };
        }
        let stats =
            multigrid::solve_rows(&rows, &unknown, &mut values, self.tolerance, MAX_ITERATIONS);
        Solved {
            values: local.iter().map(|&l| values[l]).collect(),
            scale,
            iterations: stats.iterations,
            relative_residual: stats.relative_residual,
        }
    }

    /// The cells of a solved part that are resolved (at least `τ` of its scale), more than
    /// [`MARGIN`] steps from the cut, and at least [`GAP`] times the values near the cut and the
    /// level's `lowest` source (`log2 W`); and whether the cut kept resolved cells out. Reads
    /// only `self` and the part (its cells by their slots, its solved values at their scale),
    /// so each part's are found on the thread that solved it.
    fn resolved(&self, cells: &[usize], solved: &Solved, lowest: f64) -> (Vec<usize>, bool) {
        let values = &solved.values;
        // Steps from the cut, up to MARGIN, by slot. A band cell next to one of the part's
        // cells is in the part (the parts are the band's connected parts).
        let mut near_cut = vec![false; cells.len()];
        let mut layer: Vec<usize> = (0..cells.len())
            .filter(|&s| {
                self.dist[cells[s]] == LAST_LAYER
                    && (self.neighbours(cells[s])).any(|m| self.pending[m] && !self.in_band(m))
            })
            .collect();
        for &s in &layer {
            near_cut[s] = true;
        }
        for _ in 0..MARGIN {
            let mut next = Vec::new();
            for &s in &layer {
                for m in self.neighbours(cells[s]) {
                    let t = self.slot[m].load(Relaxed) as usize;
                    if self.in_band(m) && !near_cut[t] {
                        near_cut[t] = true;
                        next.push(t);
                    }
                }
            }
            layer = next;
        }
        // The part's values near the cut: a cell far above them is little changed by it.
        let at_cut = values
            .iter()
            .zip(&near_cut)
            .filter(|&(_, near)| *near)
            .map(|(&v, _)| v)
            .fold(
                ldexp(1.0, (lowest.floor() as i32).saturating_sub(solved.scale)),
                f64::max,
            );
        // Resolved: the cells at least τ of the scale. (No REACH rule here, unlike the first
        // solve's: a weak cell a few steps from a strong one is small because `W` decays
        // along a corridor as often as because a wall is near, and the next level, at a
        // smaller scale, resolves it anyway.)
        let mut cut_limited = false;
        let mut accepted = Vec::new();
        for ((&k, &v), &near) in cells.iter().zip(values).zip(&near_cut) {
            if v >= DEPTH_STEP {
                if near || v < GAP * at_cut {
                    cut_limited = true;
                } else {
                    accepted.push(k);
                }
            }
        }
        (accepted, cut_limited)
    }
}

/// The search for the connected parts (4-neighbours) of a band (see [`Levels`] for the marks).
///
/// Parts are numbered on from every part any search numbered before, so a cell whose number
/// is below this search's first has not been reached by it: the numbers are the search's
/// marks too (one grid-wide array, not two: a deep map's levels write nearly every cell of
/// each, and fresh memory costs most at its first write).
struct PartSearch<'a> {
    grid: &'a Grid,
    band: &'a [u32],
    level: u32,
    /// The widest part solved directly (see [`MAX_BAND`]).
    max_band: usize,
    slot: &'a [AtomicU32],
    part: &'a [AtomicU32],
    /// The number of this search's first part: one more than every search numbered before.
    first: u32,
}

impl<'a> PartSearch<'a> {
    /// The search of the band marked `level` in `band`, with the widest direct solve
    /// `max_band`, numbering parts on from the `numbered` parts before.
    fn of(
        (grid, band): (&'a Grid, &'a [u32]),
        (part, slot): (&'a [AtomicU32], &'a [AtomicU32]),
        (level, max_band, numbered): (u32, usize, u32),
    ) -> Self {
        Self {
            grid,
            band,
            level,
            max_band,
            slot,
            part,
            first: numbered + 1,
        }
    }

    /// The parts of `band` (the cells whose mark is `level`), setting each cell's part number
    /// and slot, handed to `found` one by one as each is complete.
    fn run(&self, band: &[usize], mut found: impl FnMut(Part)) {
        let grid = self.grid;
        // Numbers from 1: a cell no search reached holds 0.
        let (first, mut number) = (self.first, self.first);
        let mark = |k: usize, number: u32, slot: usize| {
            self.part[k].store(number, Relaxed);
            self.slot[k].store(slot as u32, Relaxed);
        };
        for &start in band {
            if self.part[start].load(Relaxed) >= first {
                continue;
            }
            let mut cells = vec![start];
            mark(start, number, 0);
            let mut head = 0;
            // The cells within `depth` steps of `start` are `cells[..reached]`.
            let (mut depth, mut reached, mut wide) = (0, 1, false);
            while head < cells.len() {
                let k = cells[head];
                head += 1;
                for m in grid.neighbours_of(k) {
                    if self.band[m] == self.level && self.part[m].load(Relaxed) < first {
                        mark(m, number, cells.len());
                        cells.push(m);
                    }
                }
                if head == reached {
                    (depth, reached) = (depth + 1, cells.len());
                    wide |= banded::proves_wider(reached, depth, self.max_band);
                }
            }
            found(Part {
                cells,
                wide,
                number,
            });
            number += 1;
        }
    }

    /// [`PartSearch::run`]'s parts, in the order it finds them.
    fn all(&self, band: &[usize]) -> Vec<Part> {
        let mut parts = Vec::new();
        self.run(band, |part| parts.push(part));
        parts
    }
}

/// The search for a band's tail: when every pending cell left beyond the margin fits in as
/// many cells again as the band has, the band takes those its margin leads to and has no cut
/// there (a room's deep corner); a maze's rest does not fit, and is left for the next levels
/// without a search (`Levels` counts the pending cells). It marks the cells it visits in
/// `visited` (the steps `Levels::dist`, which no pass reads outside the band), not in the
/// band's marks, so the band's parts can be found meanwhile.
struct TailSearch<'a> {
    grid: &'a Grid,
    pending: &'a [bool],
    band: &'a [u32],
    level: u32,
    visited: &'a mut [u32],
}

impl TailSearch<'_> {
    /// The tail beyond the margin's last layer `margin`, if it has at most `budget` cells.
    fn run(self, margin: Vec<usize>, budget: usize) -> Option<Vec<usize>> {
        // Never a step count (each below the number of cells), and this level's own.
        let mark = u32::MAX - self.level;
        // One queue: the margin's layer, then the tail as it is found (most levels' tail is
        // larger than the budget, and is searched only until it is).
        let beyond = margin.len();
        let mut queue = margin;
        let mut head = 0;
        while let Some(&k) = queue.get(head) {
            head += 1;
            for m in self.grid.neighbours_of(k) {
                if self.pending[m] && self.band[m] != self.level && self.visited[m] != mark {
                    self.visited[m] = mark;
                    queue.push(m);
                }
            }
            if queue.len() - beyond > budget {
                return None;
            }
        }
        Some(queue.split_off(beyond))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::harmonic::solve_from_cell;
    use crate::field::laplace::reachable_from;

    /// A serpentine corridor one cell wide in an `n × n` grid of 1 m cells: the grid, its
    /// blocked cells, the cells reachable from the target `(1, 1)`, and the corridor's cells in
    /// order from the target.
    fn serpentine(n: usize) -> (Grid, Vec<bool>, Vec<bool>, Vec<usize>) {
        let grid = Grid::covering([n as f64, n as f64], 1.0);
        let mut blocked = vec![true; grid.len()];
        // Rows 1, 3, 5, … are free; they connect at alternate ends.
        for j in (1..n - 1).step_by(2) {
            for i in 1..n - 1 {
                blocked[grid.index(i, j)] = false;
            }
            if j + 2 < n - 1 {
                let end = if (j / 2) % 2 == 0 { n - 2 } else { 1 };
                blocked[grid.index(end, j + 1)] = false;
            }
        }
        let reachable = reachable_from(&grid, &blocked, (1, 1));
        let mut path = vec![grid.index(1, 1)];
        let mut seen = vec![false; grid.len()];
        seen[path[0]] = true;
        while let Some(&k) = path.last() {
            let Some(next) = grid.neighbours_of(k).find(|&m| reachable[m] && !seen[m]) else {
                break;
            };
            seen[next] = true;
            path.push(next);
        }
        (grid, blocked, reachable, path)
    }

    /// A serpentine corridor one cell wide, 20,000 cells long: `W` falls by 2 − √3 per cell,
    /// to about 1e-11400 at its end, far below f64. Every cell gets a positive `W` at its
    /// scale, the decay per cell is the corridor's, and the field is harmonic everywhere.
    #[test]
    fn a_corridor_far_deeper_than_f64_keeps_its_decay_to_the_end() {
        let n = 201;
        let (grid, blocked, reachable, path) = serpentine(n);
        let s = solve_from_cell(&grid, &blocked, (1, 1));
        let w = &s.w;
        assert!(path.len() > 19_000, "{}", path.len());
        let end = *path.last().unwrap();
        assert!(w.log10(end) < -10_000.0, "{}", w.log10(end));
        assert!(s.nested.levels > 100, "{:?}", s.nested);
        // The decay per cell, away from the bends and the ends (near the dead end `W` bends
        // up like a cosh), 2 − √3, to a few parts in a million (each level knows its cells to
        // about 1e-6; the first solve's cells a few steps beyond its depth, within 30 cells of
        // the target, to about 1e-5 only).
        let expected = 2.0 - 3f64.sqrt();
        for pair in path[30..path.len() - 20].windows(2) {
            let (a, b) = (pair[0], pair[1]);
            let ratio = (w.log2(b) - w.log2(a)).exp2();
            let straight = a / grid.nx == b / grid.nx
                && grid.neighbours_of(a).filter(|&m| reachable[m]).count() == 2
                && grid.neighbours_of(b).filter(|&m| reachable[m]).count() == 2;
            if straight && (a % grid.nx) > 3 && (a % grid.nx) < n - 4 {
                assert!((ratio / expected - 1.0).abs() < 5e-6, "{ratio} at cell {a}");
            }
        }
        // Harmonic at every cell beyond the first solve's, to relative precision.
        for &k in &path[30..] {
            let e = w.exponent[k];
            let sum: f64 = grid.neighbours_of(k).map(|m| w.at_scale(m, e)).sum();
            let own = w.mantissa[k];
            assert!((4.0 * own - sum).abs() <= 1e-6 * 4.0 * own, "cell {k}");
        }
        // The solved cells: a few times the corridor, not levels × corridor.
        assert!(s.nested.cells_solved < 5 * path.len(), "{:?}", s.nested);
    }

    /// A field solved for an agent 2,000 cells down the serpentine (`W` about 1e-1144) keeps
    /// every cell it solves to the bit of the full solve, leaves only cells more than
    /// [`BELOW_AGENT`] below the agent, and solves far fewer.
    #[test]
    fn a_field_for_an_agent_stops_below_it() {
        let (grid, blocked, reachable, path) = serpentine(101);
        let target = [grid.index(1, 1)];
        let full = solve_from_cell(&grid, &blocked, (1, 1));
        let agent = path[2_000];
        let cut = crate::field::harmonic::solve_w_for(
            &grid,
            (&reachable, &target),
            1e-12,
            None,
            &Stop::BelowAgent(agent),
        );
        assert_eq!(full.nested.left, 0);
        assert!(cut.nested.left > 2_000, "{:?}", cut.nested);
        assert!(
            2 * cut.nested.cells_solved < full.nested.cells_solved,
            "{:?} against {:?}",
            cut.nested,
            full.nested
        );
        let below = full.w.log10(agent) + BELOW_AGENT.log10();
        let mut kept = 0;
        for k in (0..grid.len()).filter(|&k| reachable[k]) {
            if cut.w.mantissa[k] > 0.0 {
                kept += 1;
                assert_eq!(cut.w.mantissa[k], full.w.mantissa[k], "cell {k}");
                assert_eq!(cut.w.exponent[k], full.w.exponent[k], "cell {k}");
            } else {
                assert!(full.w.log10(k) < below, "cell {k}: {}", full.w.log10(k));
            }
        }
        assert_eq!(
            kept + cut.nested.left,
            reachable.iter().filter(|r| **r).count()
        );
        // Everything between the agent and the target is kept, and 80 cells beyond it (46
        // decades; the bound's 50 are 87 cells of this corridor).
        assert!(path[..2_080].iter().all(|&k| cut.w.mantissa[k] > 0.0));
    }

    /// A part that the search for the band's parts proves too wide is one the direct solve
    /// would refuse (so skipping its try changes nothing), and a corridor is still offered to
    /// it and solved: a room 200 cells square and a corridor 3 cells wide, in one band. (From
    /// the room's corner, `(d + 1)(d + 2) / 2` cells lie within `d` steps: more than the
    /// `2 · 48 d + 1` a band of 48 allows once `d` passes 190.)
    #[test]
    fn a_part_proved_wide_is_one_the_direct_solve_refuses() {
        let grid = Grid::covering([220.0, 220.0], 1.0);
        let room = |i: usize, j: usize| (10..210).contains(&i) && (5..205).contains(&j);
        let corridor = |_: usize, j: usize| (210..213).contains(&j);
        let band: Vec<usize> = (0..grid.ny)
            .flat_map(|j| (0..grid.nx).map(move |i| (i, j)))
            .filter(|&(i, j)| room(i, j) || corridor(i, j))
            .map(|(i, j)| grid.index(i, j))
            .collect();
        let mut w = ScaledW::from_plain(vec![0.0; grid.len()]);
        let mut levels = Levels::new(&grid, vec![true; grid.len()], &mut w, (1e-12, MAX_BAND));
        levels.level = 1;
        for &k in &band {
            levels.band[k] = 1;
        }
        let parts = levels.searches().0.all(&band);
        assert_eq!(parts.len(), 2);
        for part in &parts {
            let direct = levels.solve_narrow(part.number, &part.cells, 0);
            if part.cells.len() == 200 * 200 {
                assert!(part.wide && direct.is_none());
            } else {
                assert_eq!(part.cells.len(), 220 * 3);
                assert!(!part.wide && direct.is_some());
            }
        }
    }

    /// `W` of the free cell `target` after its first solve (to 1e-12), and the cells that
    /// solve leaves pending for the nested levels.
    fn after_first_solve(grid: &Grid, reachable: &[bool], target: usize) -> (ScaledW, Vec<bool>) {
        let mut unknown = reachable.to_vec();
        unknown[target] = false;
        let mut w = vec![0.0; grid.len()];
        w[target] = 1.0;
        multigrid::solve(grid, &unknown, &mut w, 1e-12, MAX_ITERATIONS);
        let pending = deep_cells(grid, &unknown, &w, DEPTH_STEP);
        (ScaledW::from_plain(w), pending)
    }

    /// A straight corridor 20 cells wide and 600 long, from a target at one end: `W` falls by
    /// about `e^(−π/21)` per cell, to 1e-38 at the other. With a band of 48 its parts are
    /// solved directly (no CG iteration); with [`MAX_BAND`] (12) by multigrid, and the field
    /// is the same to six digits on every cell.
    #[test]
    fn a_part_wider_than_the_band_is_solved_by_multigrid_to_the_same_field() {
        let grid = Grid::covering([604.0, 24.0], 1.0);
        let blocked: Vec<bool> = (0..grid.len())
            .map(|k| !(2..602).contains(&(k % grid.nx)) || !(2..22).contains(&(k / grid.nx)))
            .collect();
        let reachable = reachable_from(&grid, &blocked, (2, 12));
        let target = grid.index(2, 12);
        let with = |max_band: usize| {
            let (mut w, pending) = after_first_solve(&grid, &reachable, target);
            let stats = solve_levels(&grid, pending, &mut w, (1e-12, max_band), &Stop::Never);
            (w, stats)
        };
        let ((direct, by_band), (by_multigrid, by_cg)) = (with(48), with(MAX_BAND));
        assert!(by_band.levels > 4, "{by_band:?}");
        assert_eq!(by_band.iterations, 0, "{by_band:?}");
        assert!(by_cg.iterations > 0, "{by_cg:?}");
        let end = grid.index(601, 12);
        assert!(direct.log10(end) < -35.0, "{}", direct.log10(end));
        crate::field::scaled::assert_same_to_six_digits(&direct, &by_multigrid, &reachable);
    }

    /// A room of 576 × 576 cells cut by five walls with a door of two cells each, at
    /// alternate ends: bands of tens of thousands of cells. Solving each level's parts as the
    /// search finds them gives the field of searching first and solving after, to the bit.
    #[test]
    fn parts_solved_as_they_are_found_give_the_field_of_parts_solved_after() {
        let n = 576;
        let grid = Grid::covering([n as f64, n as f64], 1.0);
        let blocked: Vec<bool> = (0..grid.len())
            .map(|k| {
                let (i, j) = (k % grid.nx, k / grid.nx);
                let wall = i % 96 == 95;
                let door = if (i / 96) % 2 == 0 { j < 2 } else { j >= n - 2 };
                wall && !door
            })
            .collect();
        let reachable = reachable_from(&grid, &blocked, (1, n / 2));
        let target = grid.index(1, n / 2);
        let with = |pipelined: bool| {
            let (mut w, pending) = after_first_solve(&grid, &reachable, target);
            let params = (1e-12, MAX_BAND);
            let (stats, levels) =
                run_levels(&grid, pending, &mut w, params, &Stop::Never, pipelined);
            (w, stats, levels)
        };
        let ((after, stats, none), (found, same, some)) = (with(false), with(true));
        assert_eq!(none, 0);
        assert!(some > 3, "{some} levels of {stats:?}");
        assert_eq!(stats, same);
        let bits = |w: &ScaledW| (w.mantissa.iter().map(|m| m.to_bits())).collect::<Vec<_>>();
        assert!(bits(&after) == bits(&found), "the fields differ");
        assert_eq!(after.exponent, found.exponent);
        assert!(after.log10(grid.index(n - 2, n / 2)) < -20.0);
    }

    /// The field of the serpentine from the target `(1, 1)`, its nested levels stopping as
    /// `stop` allows.
    fn levels_with(grid: &Grid, reachable: &[bool], stop: &Stop) -> (ScaledW, LevelStats) {
        let target = [grid.index(1, 1)];
        let s = crate::field::harmonic::solve_w_for(grid, (reachable, &target), 1e-12, None, stop);
        (s.w, s.nested)
    }

    /// Levels that stop once a box is solved (a coarse window, read only near its centre)
    /// keep every cell of the box, each cell they keep is the full solve's to the bit, and they
    /// solve far fewer cells; the others are left at 0.
    #[test]
    fn levels_that_stop_once_a_box_is_solved_keep_it_to_the_bit() {
        let (grid, _, reachable, path) = serpentine(101);
        let (full, all) = levels_with(&grid, &reachable, &Stop::Never);
        // A box 2,000 cells down the corridor, across three of its rows.
        let (i, j) = (path[2_000] % grid.nx, path[2_000] / grid.nx);
        let inside = (i - 3..i + 4, j - 2..j + 3);
        let (cut, part) = levels_with(
            &grid,
            &reachable,
            &Stop::Within(inside.0.clone(), inside.1.clone()),
        );
        assert_eq!(all.left, 0);
        assert!(part.left > 2_000, "{part:?}");
        assert!(
            2 * part.cells_solved < all.cells_solved,
            "{part:?} against {all:?}"
        );
        let mut kept = 0;
        for k in (0..grid.len()).filter(|&k| reachable[k]) {
            let boxed = inside.0.contains(&(k % grid.nx)) && inside.1.contains(&(k / grid.nx));
            if cut.mantissa[k] > 0.0 {
                kept += 1;
                assert_eq!(cut.mantissa[k], full.mantissa[k], "cell {k}");
                assert_eq!(cut.exponent[k], full.exponent[k], "cell {k}");
            } else {
                assert!(!boxed, "cell {k} of the box left out");
            }
        }
        assert_eq!(kept + part.left, reachable.iter().filter(|r| **r).count());
    }
}
