//! Local replanning (`field.replan = "local"`): the part of an agent's field that the other
//! agents change, re-solved in a square window around the agent, with the field of the walls
//! holding the window's edge ([`Window`]).
//!
//! Why it is enough: the other agents are small obstacles (`W = 0` on their discs). Their effect
//! on `W` is largest next to them and is forced to zero on the window's edge, where the field of
//! the walls is kept; inside the window the solution is harmonic with the agents as obstacles,
//! so it has no local maximum of `W` (a local minimum of `V`) there, and a streamline from the
//! agent either reaches the target or leaves the window, into the field of the walls, which
//! leads to the target. What a full re-solve adds is the others' effect beyond the window, which
//! decays with the distance from them (measured in `tests/crowd.rs` as the angle between the two
//! guidances along the agents' paths).
//!
//! Cost: the window's cells, `(2 · replan_window / cell)²` (3 721 for a 3 m window at 10 cm),
//! however large the world: the cost per replan does not grow with the map.

// The cell loops fill several arrays of one window by one index: the form that reads like the
// problem it sets up.
#![allow(clippy::needless_range_loop)]

use std::sync::Arc;
use std::time::{Duration, Instant};

use super::grid::Grid;
use super::mask::{Disc, disc_cells, obstacle_discs};
use super::multigrid::{self, Cycle};
use super::nested::{DEPTH_STEP, MAX_ITERATIONS, Stop, WINDOW_MAX_BAND, deep_cells, solve_levels};
use super::sample::NEAR;
use super::scaled::{ScaledW, exponent_of, ldexp};
use super::{FieldError, Sampler};
use crate::world::Agent;

/// The field re-solved in a window around an agent, with the other agents in it as obstacles.
///
/// - The window is the square of the agent's grid `replan_window` metres either side of it. Its
///   outermost ring of cells, the target disc's cells (`W = 1`) and the cells the field of the
///   walls does not reach (`W = 0`) are the Dirichlet data; so are the cells of the other
///   agents' discs, grown by the agent's radius (`W = 0`).
/// - The ring's values come from a coarse window: `replan_reach` metres either side at four
///   times the cell, solved the same way, with the field of the walls on its own ring. So
///   agents up to `replan_reach` away bend the guidance (a crowd ahead is gone around early).
///   It is re-solved every fifth replan, while the agent stays within a quarter of its reach of
///   where it was solved (the agents it shows are far and move little between replans); being
///   read only on those windows' rings, its nested levels stop once the cells the rings read
///   are solved (see `read_by_rings`).
/// - Both are solved to a relative residual of 1e-9 (or the field's tolerance if looser): their
///   difference from a full re-solve, degrees of guidance near the others, is far above what a
///   tighter solve changes, and it takes about a third fewer iterations than 1e-12 (see
///   `WINDOW_TOLERANCE`). Cells below what the solve resolves go to the nested levels, as in
///   a full solve.
/// - The unknown cells start from 0 when a coarse window gives the ring, else from the field
///   of the walls (see `zero_start`).
/// - A replan that sets the very problem the last one solved (an agent parked among parked
///   neighbours, while its coarse window is reused) is served that solution, which is the
///   solve's to the bit (see `Solved`).
/// - An agent that the others cut off, or whose every way on they block within the window
///   (every ring cell it can reach has a lower `W` of the walls than it has, and no target cell),
///   gets [`FieldError::Unreachable`]: whether a detour exists beyond the window only a full
///   re-solve can say, and the simulation falls back to one for that replan.
#[derive(Debug, Clone)]
pub struct Window {
    /// The window's problem and its field, on a part of the agent's grid (shared with the next
    /// replan when that sets the same problem: see [`Solved`]).
    solved: Arc<Solved>,
    /// Where samples are read from the window: the points whose interpolation stencil lies at
    /// least one cell inside its edge (central differences there read only window cells), as
    /// fractional cell coordinates `[lo, hi)` along x and y.
    interior: [[f64; 2]; 2],
    /// The other agents that were inside the window, as obstacles.
    pub discs: usize,
    /// The coarse window that gave the window's edge, if any (shared with the next replans,
    /// which may reuse it: see [`COARSE_REUSE`]).
    coarse: Option<Arc<Coarse>>,
    /// Conjugate gradient iterations of the solve (the coarse window's too, when it was
    /// solved for this one).
    pub iterations: usize,
    /// Wall-clock time of the solve.
    pub solve_time: Duration,
}

/// A Dirichlet problem on a window: which cells the agent's centre may be in, which hold
/// fixed values, and the values (fixed ones, and the starting guess of the others).
#[derive(Debug)]
struct Problem {
    grid: Grid,
    /// Free: the field of the walls reaches it and no disc covers it.
    free: Vec<bool>,
    /// Dirichlet cells: the ring, the target disc, and every cell that is not free (`W = 0`).
    known: Vec<bool>,
    /// The Dirichlet values, and the starting guess elsewhere: the field of the walls, or 0
    /// in a window whose ring comes from a coarse window (see `zero_start`).
    values: ScaledW,
}

impl Problem {
    /// Every cell of `grid` blocked and known at `W = 0`, to be filled in.
    fn blank(grid: Grid) -> Self {
        let n = grid.len();
        Self {
            grid,
            free: vec![false; n],
            known: vec![true; n],
            values: ScaledW {
                mantissa: vec![0.0; n],
                exponent: vec![0; n],
            },
        }
    }

    /// Whether `other` is this problem to the bit (`-0.0` is not `0.0` here: the solve is a
    /// function of the bits).
    fn same_as(&self, other: &Self) -> bool {
        self.grid == other.grid
            && self.free == other.free
            && self.known == other.known
            && self.values.exponent == other.values.exponent
            && (self.values.mantissa.iter().map(|m| m.to_bits())).eq(other
                .values
                .mantissa
                .iter()
                .map(|m| m.to_bits()))
    }
}

/// A window's problem with its solution. The solve is a function of the problem, the agent's
/// cell in it and where its nested levels stop alone, so a replan that sets the very same
/// problem is served this solution, which is the solve's to the bit: an agent settled among
/// settled neighbours sets the same fine problem at every replan while its coarse window is
/// reused, and the same coarse problem while nothing in its reach moves by a cell.
#[derive(Debug)]
struct Solved {
    problem: Problem,
    /// The agent's cell in the problem's grid.
    at: Option<(usize, usize)>,
    stop: Stop,
    sampler: Sampler,
}

impl Solved {
    /// `problem` solved for the agent at `position` (see `solve_problem`), or `previous` when
    /// that set the same problem with the agent in the same cell and the same `stop`. Returns
    /// the iterations done (0 when served).
    fn solve(
        problem: Problem,
        agent: &Agent,
        position: [f64; 2],
        (tolerance, stop): (f64, Stop),
        previous: Option<&Arc<Solved>>,
    ) -> Result<(Arc<Self>, usize), FieldError> {
        let at = problem.grid.cell_of(position);
        if let Some(p) = previous.filter(|p| p.at == at && p.stop == stop)
            && p.problem.same_as(&problem)
        {
            return Ok((Arc::clone(p), 0));
        }
        let (sampler, iterations) = solve_problem(&problem, agent, position, tolerance, &stop)?;
        let solved = Self {
            problem,
            at,
            stop,
            sampler,
        };
        Ok((Arc::new(solved), iterations))
    }
}

/// How many fine cells a cell of the coarse window spans along x and y.
///
/// Not 8, though the coarse windows are about half of a dense crowd's CPU (128 robots on the
/// 1.8 m circle: 47 %). With 8, that crowd ran in 100.6 s against 154.6 s for its 94 s, but
/// only 84 of 128 robots reached in time against 115. With 8 for the whole grid's coarse window
/// alone: 146.8 s, 90 reached. With 8 for the coarse windows around the agents alone: 115.7 s,
/// 113 reached, but 64 robots (`scripts/crowds.py`, seeds 0–5) settled last at 59.5 s on
/// average against 44.7 s, in no less time. At 0.8 m (the crowds' 0.1 m cell times 8) a cell
/// is wider than a robot (0.6 m across), and as wide as a thin wall's band of free space (0.2 m
/// grown by 0.3 m each side).
pub const COARSE: usize = 4;

/// How many replans after the one that solved it a coarse window serves (with the discs where
/// they were then), while the agent stays within a quarter of its reach of where it was solved:
/// the agents it shows are far, and move little between replans, so it is re-solved every fifth
/// replan (twice a second at 10 Hz).
///
/// Not more: 9 saved about a tenth of 32 robots' wall time on the 1.8 m circle, but the last
/// robot settled 25.8 → 29.3 s on average over ten seeds (a staler ring steers worse; both
/// measured with windows started from 0, see `Problem`). On 128 robots, 9 ran the 94 s in
/// 135.3 s against 154.6 s, with 110 robots reached in time against 115.
pub const COARSE_REUSE: u32 = 4;

/// The relative residual a window is solved to, unless the field's own tolerance is looser:
/// the window's difference from a full re-solve (degrees of guidance near the others) is far
/// above what a tighter solve would change, and 1e-9 takes about a third fewer iterations than
/// the default 1e-12. Cells below what it resolves go to the nested levels as in a full solve.
///
/// Not looser: 1e-7 saved about a tenth of a crowd's time, but it leaves one digit at the depth
/// the nested levels take over from ([`DEPTH_STEP`], 1e-6), and the guidance there steers
/// worse. With 1e-7, a coarse window reused 9 times and windows started from 0, 16 robots on
/// the 2.5 m circle settled 17.8 → 18.9 s on average over ten seeds, 32 robots 30.5 → 32.2 s;
/// with those two alone (windows from the walls' field), the shipped `circle-16` 18.4 → 22.8 s.
pub const WINDOW_TOLERANCE: f64 = 1e-9;

/// A window at most this many cells along each side is solved with V-cycles, a larger one
/// (the whole grid's coarse window in a large room) with W-cycles. On a small grid the W-cycle's
/// extra visits cost more than the iterations they save: its coarse levels are a few rows of a
/// few cells each, where a row's overhead outweighs its arithmetic. Measured: 64 robots on the
/// 1.8 m circle (fine windows 62² cells, coarse ones up to 98²), first 12 s in 12.4–12.7 s
/// against 13.1–13.6 s with W-cycles, the whole 57 s in 33.7 s against 34.4–37.5 s; the paper's
/// room at 101² (to 1e-12) in 4.9 ms with V-cycles (20 iterations) against 5.2 ms (13), but at
/// 201² in 17.2 ms against 11.3. Full solves keep the W-cycle: the nested levels' parts, small
/// too, took 4 % more iterations (and up to 3 % more time) with V-cycles on the rooms map's
/// longest field.
pub const V_CYCLE_SIDE: usize = 128;

/// How far the coarse window that gives a window's edge extends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reach {
    /// This many metres either side of the agent (`replan_reach`; no coarse window when it is
    /// not beyond the window's own half-side). The next replans may reuse it
    /// (`COARSE_REUSE`, see [`Window`]).
    Around(f64),
    /// The whole grid: the field among the others over the whole grid at `COARSE` (4) times
    /// the cell, for a window whose guidance turns back on the agent's last field (which way
    /// is right only a field over the whole grid can say, and at the coarse cell it costs a
    /// sixteenth of the fine one's cells). Only the next wide windows may reuse it
    /// (`COARSE_REUSE`, while the agent stays within a quarter of the window's half-side),
    /// never an ordinary one (see [`Window`]).
    Whole,
}

/// A coarse window, and how it was made.
#[derive(Debug)]
struct Coarse {
    solved: Arc<Solved>,
    /// Whether it covers the whole grid ([`Reach::Whole`]): such a window serves only wide windows.
    whole: bool,
    /// Where the agent was when it was solved, m.
    centre: [f64; 2],
    /// Replans it has served since.
    reused: u32,
}

impl Window {
    /// Re-solves `field` (the agent's field of the walls, on `grid` with `reachable` cells and
    /// its `w`) in the square of half-side `half` metres around `position`, with the discs
    /// `others` as obstacles, to a relative residual of `tolerance`.
    ///
    /// The window's outermost ring of cells holds the Dirichlet data, and so do the target
    /// disc's cells (`W = 1`) and the cells the field does not reach (`W = 0`); the cells of the
    /// other agents' discs (grown by the agent's radius) are `W = 0`. Cells cut off by the
    /// discs from the ring and the target are `W = 0` too. An agent cut off itself is an error
    /// ([`FieldError::Unreachable`]), as in a full re-solve; so is an agent whose way on the
    /// others block in the window (see `leads_on`): whether there is a detour beyond the
    /// window only a full re-solve can say.
    ///
    /// The ring's values come from a coarse window first, when `reach` exceeds `half`: the
    /// square of half-side `reach` at [`COARSE`] times the cell, solved the same way with the
    /// discs in it and the field of the walls on its own ring. So the agents up to `reach` away
    /// bend the guidance (a crowd ahead is gone around early), at the cost of a second window
    /// of about as many cells, whatever the size of the world.
    ///
    /// With [`Reach::Whole`] the coarse window covers the whole grid, and its values alone make
    /// the fine window's ring (0 where it has none): it knows the detours the others leave
    /// beyond any window, so the fine window is not asked to lead on along the field of the
    /// walls (`leads_on`), only not to be cut off.
    ///
    /// `previous` is the window of the last replan on the same field of the walls, whose
    /// coarse window may serve again ([`COARSE_REUSE`]).
    pub(super) fn solve(
        (grid, reachable, w): (&Grid, &[bool], &ScaledW),
        agent: &Agent,
        position: [f64; 2],
        (half, reach): (f64, Reach),
        (others, previous): (&[Disc], Option<&Window>),
        tolerance: f64,
    ) -> Result<Self, FieldError> {
        let started = Instant::now();
        let unreachable = || FieldError::Unreachable {
            agent: agent.name.clone(),
            radius: agent.radius,
        };
        let whole = reach == Reach::Whole;
        // The coarse window's half-side: the whole grid's extent covers it from anywhere.
        let reach = match reach {
            Reach::Around(reach) => reach,
            Reach::Whole => grid.cell * (grid.nx.max(grid.ny) as f64),
        };
        let discs: Vec<Disc> = obstacle_discs(agent, position, grid.cell, others)
            .filter(|d| {
                let r = d.radius + agent.radius + half.max(reach);
                (d.center[0] - position[0]).abs() < r && (d.center[1] - position[1]).abs() < r
            })
            .collect();
        // How far from where it was solved a coarse window serves the next replans' rings (its
        // nested levels stop once those are solved): a wide window's, only as far as its agent
        // goes in a few replans in a crowd. A wide window reuses only a wide window's coarse
        // one, an ordinary window only an ordinary one: the field among the others over the
        // whole grid, held as the edge of ordinary windows, milled crossing flows about for
        // good (see the commit that reverted that reuse). Wide after wide is what a crowd
        // asks when the window keeps turning back (128 robots on the 1.8 m circle: 4,876 of
        // 5,371 wide windows 0.1 s after another), and reusing it there took that crowd from
        // 1.87 to 1.38 s of wall time per simulated second, every robot arriving, no contact.
        // An ordinary window after a wide one solves its coarse window anew, though the
        // ordinary window of the wide one's replan (which turned back) solved one too: kept
        // in the wide window and reused, it saved 4,485 of 12,298 coarse solves in the first
        // 30 s of the shipped 128 robots (the whole run 163.6 → 150.5 s; 160.4 → 159.2 s on
        // `scripts/crowds.py`'s seed 1), but it steered worse just after a turn back, where a
        // fresh view of the crowd matters: 64 robots (`crowds.py`, seeds 0–5) last settled
        // 44.7 → 46.7 s on average (later on four seeds, as late on two) for 2 % less time,
        // and of the shipped 128, 111 reached in the 94 s against 115.
        let serves = if whole { 0.25 * half } else { 0.25 * reach };
        let last_coarse = previous.and_then(|p| p.coarse.as_ref());
        let reusable = last_coarse.filter(|c| {
            whole == c.whole
                && c.reused < COARSE_REUSE
                && (c.centre[0] - position[0]).hypot(c.centre[1] - position[1]) < serves
        });
        let mut coarse_iterations = 0;
        let coarse = match reusable {
            Some(c) => Some(Arc::new(Coarse {
                solved: Arc::clone(&c.solved),
                whole,
                centre: c.centre,
                reused: c.reused + 1,
            })),
            None if reach > half => {
                let problem = coarse_problem((grid, reachable, w), agent, position, reach, &discs);
                let read = read_by_rings((&problem.grid, grid), position, half, serves);
                let last = last_coarse.map(|c| &c.solved);
                match Solved::solve(problem, agent, position, (tolerance, read), last) {
                    Ok((solved, iterations)) => {
                        coarse_iterations = iterations;
                        Some(Arc::new(Coarse {
                            solved,
                            whole,
                            centre: position,
                            reused: 0,
                        }))
                    }
                    // The discs cut the agent off at the coarse cell: the fine window's ring
                    // would hold the field of the walls as if nothing closed the way (a door
                    // shutting in the window: the ring behind the agent then outweighs the
                    // slit left, and the window leads away from the door). Whether a way
                    // remains only the whole field can say.
                    Err(FieldError::Unreachable { .. }) => return Err(unreachable()),
                    Err(_) => None,
                }
            }
            None => None,
        };
        // The fine window: a part of the agent's grid.
        let (ir, jr) = grid.cells_in(
            [position[0] - half, position[1] - half],
            [position[0] + half, position[1] + half],
        );
        let local = grid.part(ir.clone(), jr.clone());
        if local.nx < 3 || local.ny < 3 {
            return Err(unreachable());
        }
        let global = |k: usize| grid.index(ir.start + k % local.nx, jr.start + k / local.nx);
        let n = local.len();
        let under_disc = stamp(&local, &discs, agent.radius);
        let mut problem = Problem::blank(local);
        for k in 0..n {
            let (i, j) = (k % local.nx, k / local.nx);
            let g = global(k);
            let centre = local.center(i, j);
            problem.free[k] = reachable[g] && !under_disc[k];
            let ring = i == 0 || j == 0 || i + 1 == local.nx || j + 1 == local.ny;
            problem.known[k] = !problem.free[k] || ring;
            (problem.values.mantissa[k], problem.values.exponent[k]) =
                (w.mantissa[g], w.exponent[g]);
            // The ring from the coarse window where it has a value there (with the whole
            // grid's coarse window, only there: the field of the walls would lead into what
            // it shows closed).
            if ring
                && problem.free[k]
                && let Some(coarse) = &coarse
            {
                match coarse.solved.sampler.w_scaled(centre) {
                    Some((m, e)) if m > 0.0 => {
                        (problem.values.mantissa[k], problem.values.exponent[k]) = (m, e);
                    }
                    _ if whole => {
                        (problem.values.mantissa[k], problem.values.exponent[k]) = (0.0, 0);
                    }
                    _ => {}
                }
            }
        }
        for g in disc_cells(
            grid,
            reachable,
            agent.target,
            agent.target_disc() + 0.5 * grid.cell,
        ) {
            let (gi, gj) = (g % grid.nx, g / grid.nx);
            if ir.contains(&gi) && jr.contains(&gj) {
                problem.known[local.index(gi - ir.start, gj - jr.start)] = true;
            }
        }
        if !whole && !leads_on(&problem, (grid, reachable, w), (&ir, &jr), position) {
            return Err(unreachable());
        }
        if coarse.is_some() {
            zero_start(&mut problem);
        }
        let last = previous.map(|p| &p.solved);
        let (solved, iterations) =
            Solved::solve(problem, agent, position, (tolerance, Stop::Never), last)?;
        let interior = [[1.0, local.nx as f64 - 2.0], [1.0, local.ny as f64 - 2.0]];
        Ok(Self {
            solved,
            interior,
            discs: discs.len(),
            coarse,
            iterations: iterations + coarse_iterations,
            solve_time: started.elapsed(),
        })
    }

    /// The window's field.
    pub fn sampler(&self) -> &Sampler {
        &self.solved.sampler
    }

    /// The window's cells.
    pub fn grid(&self) -> &Grid {
        self.solved.sampler.grid()
    }

    /// Whether samples at `p` are read from the window: its interior, where the interpolation
    /// stencil lies at least one cell inside the window's edge.
    pub fn covers(&self, p: [f64; 2]) -> bool {
        let g = self.grid();
        let fx = (p[0] - g.origin[0]) / g.cell - 0.5;
        let fy = (p[1] - g.origin[1]) / g.cell - 0.5;
        let [x, y] = self.interior;
        fx >= x[0] && fx < x[1] && fy >= y[0] && fy < y[1]
    }
}

/// Starts `problem`'s solve from 0 on its unknown cells: for a window whose ring comes from a
/// coarse window. Where the others close the way, that ring is far below the field of the
/// walls (the coarse window shows the crowd, the walls do not), and from that field the first
/// residual was a median 1e4 and up to 1e9 times the right-hand side (64 robots on the 1.8 m
/// circle). CG's recurrence then drifted from the true residual: 11 % of the windows ended
/// above 1e-8 of it, up to 3e-6, reported under 1e-9 (the solver now recomputes the residual
/// and restarts, see `multigrid::solve`). From 0 the first residual is the right-hand side:
/// 12.2 iterations a window against 17.8, and the whole 57 s run in 28.1 s against 31.7 s.
///
/// The accurate field steers the densest crowds differently from the drifted one, whose error
/// had the walls' shape and led on through the crowd's shadow: 64 robots on the 1.2 m circle
/// (seeds 0–5) settle last at 38.5–40.5 s, 59.0 s on one seed, against 35.0–43.5 s, with
/// 7–13 robots flagged parked a seed against 1–5. With the walls' field as the guess solved
/// to 1e-11 (still drifted), 0–4 on seeds 0–2; from 0 to 1e-11, 8–13; from 0 with the nested
/// levels' floor scaled to the window's tolerance, 6–11 on seeds 0–1. The crowd checks are in
/// the README.
fn zero_start(problem: &mut Problem) {
    for k in 0..problem.grid.len() {
        if !problem.known[k] {
            (problem.values.mantissa[k], problem.values.exponent[k]) = (0.0, 0);
        }
    }
}

/// The coarse window's cells: [`COARSE`] times the cell of `grid`, half-side `reach` around
/// `position`, clipped to `grid`.
fn coarse_grid(grid: &Grid, position: [f64; 2], reach: f64) -> Grid {
    let cell = grid.cell * COARSE as f64;
    let (lo, hi) = grid.bounds();
    let from = [
        (position[0] - reach).max(lo[0]),
        (position[1] - reach).max(lo[1]),
    ];
    let to = [
        (position[0] + reach).min(hi[0]),
        (position[1] + reach).min(hi[1]),
    ];
    Grid {
        nx: (((to[0] - from[0]) / cell).ceil() as usize).max(1),
        ny: (((to[1] - from[1]) / cell).ceil() as usize).max(1),
        cell,
        origin: from,
    }
}

/// The cells of the coarse window on `coarse` (solved for an agent at `position` on `grid`)
/// that the fine windows it serves read, as the box its nested levels may stop at
/// ([`Stop::Within`]): it gives only the rings of windows of half-side `half` around agents
/// within `serves` of `position`. A ring's cell centres lie within `half` and a fine cell of
/// its agent, so within `serves + half + cell` of `position` (the box's extent, with a fine
/// cell to spare); a sample reads the coarse cells of its interpolation stencil, or, off the
/// field, the nearest reachable cell within [`NEAR`] more.
fn read_by_rings(
    (coarse, grid): (&Grid, &Grid),
    position: [f64; 2],
    half: f64,
    serves: f64,
) -> Stop {
    let r = serves + half + 2.0 * grid.cell;
    let (i, j) = coarse.cells_in(
        [position[0] - r, position[1] - r],
        [position[0] + r, position[1] + r],
    );
    let near = NEAR as usize;
    let grow =
        |r: std::ops::Range<usize>, n: usize| r.start.saturating_sub(near)..(r.end + near).min(n);
    Stop::Within(grow(i, coarse.nx), grow(j, coarse.ny))
}

/// The coarse window: [`COARSE`] times the cell, half-side `reach` around `position`, clipped
/// to the agent's grid. A coarse cell is free when the fine cell at its centre is reachable and
/// no disc covers its centre; its ring holds the field of the walls, the cells of the target
/// disc hold `W = 1`.
fn coarse_problem(
    (grid, reachable, w): (&Grid, &[bool], &ScaledW),
    agent: &Agent,
    position: [f64; 2],
    reach: f64,
    discs: &[Disc],
) -> Problem {
    let coarse = coarse_grid(grid, position, reach);
    let cell = coarse.cell;
    let n = coarse.len();
    let under_disc = stamp(&coarse, discs, agent.radius);
    let target_radius = agent.target_disc() + 0.5 * cell;
    let target_cell = coarse.cell_of(agent.target);
    let mut problem = Problem::blank(coarse);
    for k in 0..n {
        let (i, j) = (k % coarse.nx, k / coarse.nx);
        let centre = coarse.center(i, j);
        let Some((fi, fj)) = grid.cell_of(centre) else {
            continue;
        };
        let g = grid.index(fi, fj);
        problem.free[k] = reachable[g] && !under_disc[k];
        let ring = i == 0 || j == 0 || i + 1 == coarse.nx || j + 1 == coarse.ny;
        let target = target_cell == Some((i, j))
            || square(centre[0] - agent.target[0], centre[1] - agent.target[1])
                <= target_radius * target_radius;
        problem.known[k] = !problem.free[k] || ring || target;
        if target && problem.free[k] {
            (problem.values.mantissa[k], problem.values.exponent[k]) = (1.0, 0);
        } else {
            (problem.values.mantissa[k], problem.values.exponent[k]) =
                (w.mantissa[g], w.exponent[g]);
        }
    }
    problem
}

/// Solves a window's Dirichlet problem: the free cells connected to the Dirichlet data (the
/// free known cells with `W > 0`) are solved, at the scale of the largest Dirichlet value, then
/// the nested levels below what the solve resolves, as in a full solve. The Dirichlet cells
/// keep their own values and exponents (they may be deeper than f64 reaches at that scale).
/// The nested levels may `stop` short of every cell (see [`Stop`]). Returns the sampler and
/// the iterations; an error when the agent at `position` is cut off.
fn solve_problem(
    problem: &Problem,
    agent: &Agent,
    position: [f64; 2],
    tolerance: f64,
    stop: &Stop,
) -> Result<(Sampler, usize), FieldError> {
    let Problem {
        grid: local,
        free,
        known,
        values: given,
    } = problem;
    let unreachable = || FieldError::Unreachable {
        agent: agent.name.clone(),
        radius: agent.radius,
    };
    let local = *local;
    let n = local.len();
    let mut connected = vec![false; n];
    let mut stack: Vec<usize> = (0..n)
        .filter(|&k| free[k] && known[k] && given.mantissa[k] > 0.0)
        .collect();
    for &k in &stack {
        connected[k] = true;
    }
    while let Some(k) = stack.pop() {
        for m in local.neighbours_of(k) {
            if free[m] && !connected[m] {
                connected[m] = true;
                stack.push(m);
            }
        }
    }
    let at = local.cell_of(position).ok_or_else(unreachable)?;
    let near = |c: usize, len: usize| c.saturating_sub(1)..=(c + 1).min(len - 1);
    if !near(at.0, local.nx).any(|i| near(at.1, local.ny).any(|j| connected[local.index(i, j)])) {
        return Err(unreachable());
    }
    let unknown: Vec<bool> = (0..n).map(|k| connected[k] && !known[k]).collect();
    // Everything at the scale of the largest Dirichlet value, so the solve works on values of
    // order 1 wherever the window is (deep in a maze too).
    let top = (0..n)
        .filter(|&k| connected[k] && known[k] && given.mantissa[k] > 0.0)
        .map(|k| given.exponent[k] + exponent_of(given.mantissa[k]))
        .max()
        .ok_or_else(unreachable)?;
    let mut values: Vec<f64> = (0..n)
        .map(|k| {
            if connected[k] {
                ldexp(given.mantissa[k], given.exponent[k] - top)
            } else {
                0.0
            }
        })
        .collect();
    let cycle = if local.nx.max(local.ny) <= V_CYCLE_SIDE {
        Cycle::V
    } else {
        Cycle::W
    };
    let stats = multigrid::solve_with(
        cycle,
        &local,
        &unknown,
        &mut values,
        tolerance,
        MAX_ITERATIONS,
    );
    if stats.relative_residual.is_nan() || stats.relative_residual > tolerance {
        return Err(FieldError::Solver {
            agent: agent.name.clone(),
            iterations: stats.iterations,
            relative_residual: stats.relative_residual,
        });
    }
    let pending = deep_cells(&local, &unknown, &values, DEPTH_STEP);
    let mut scaled = ScaledW {
        mantissa: values,
        exponent: vec![top; n],
    };
    for k in 0..n {
        if connected[k] && known[k] {
            scaled.mantissa[k] = given.mantissa[k];
            scaled.exponent[k] = given.exponent[k];
        } else if !connected[k] {
            scaled.exponent[k] = 0;
        }
    }
    let nested = solve_levels(
        &local,
        pending,
        &mut scaled,
        (tolerance, WINDOW_MAX_BAND),
        stop,
    );
    Ok((
        Sampler::new(local, scaled, connected),
        stats.iterations + nested.iterations,
    ))
}

/// The cells of `grid` whose centres lie inside one of the `discs` grown by `radius`: each
/// disc marks only the cells of its bounding box.
fn stamp(grid: &Grid, discs: &[Disc], radius: f64) -> Vec<bool> {
    let mut under = vec![false; grid.len()];
    for d in discs {
        let r = d.radius + radius;
        let (ir, jr) = grid.cells_in(
            [d.center[0] - r, d.center[1] - r],
            [d.center[0] + r, d.center[1] + r],
        );
        for j in jr {
            for i in ir.clone() {
                let [x, y] = grid.center(i, j);
                if square(x - d.center[0], y - d.center[1]) < r * r {
                    under[grid.index(i, j)] = true;
                }
            }
        }
    }
    under
}

/// `x² + y²`: the cell loops compare squared distances (`hypot` was 4 % of a crowd's time).
fn square(x: f64, y: f64) -> f64 {
    x * x + y * y
}

/// Whether the part of the window the agent is in leads on: it holds a cell of the target disc,
/// or a cell of the ring where the field of the walls is at least what it is at the agent.
///
/// Without the others, the field of the walls rises along the agent's streamline to the target,
/// which leaves the window through a ring cell where `W` is higher than at the agent (or ends
/// at the target inside it). When the others cut the agent off from every such cell, the only
/// ways out of the window go back down the field: a window solved with that edge would turn the
/// agent round whether or not a detour exists (in a corridor one robot wide it does not), so the
/// caller decides with a full re-solve instead.
fn leads_on(
    problem: &Problem,
    (grid, reachable, w): (&Grid, &[bool], &ScaledW),
    (ir, jr): (&std::ops::Range<usize>, &std::ops::Range<usize>),
    position: [f64; 2],
) -> bool {
    let local = &problem.grid;
    let global = |k: usize| grid.index(ir.start + k % local.nx, jr.start + k / local.nx);
    let log2 = |g: usize| w.mantissa[g].log2() + f64::from(w.exponent[g]);
    // The field of the walls at the agent: the best reachable cell around it.
    let Some((ci, cj)) = grid.cell_of(position) else {
        return false;
    };
    let near = |c: usize, len: usize| c.saturating_sub(1)..=(c + 1).min(len - 1);
    let here = near(ci, grid.nx)
        .flat_map(|i| near(cj, grid.ny).map(move |j| grid.index(i, j)))
        .filter(|&g| reachable[g] && w.mantissa[g] > 0.0)
        .map(log2)
        .fold(f64::NEG_INFINITY, f64::max);
    let Some((li, lj)) = local.cell_of(position) else {
        return false;
    };
    let mut seen = vec![false; local.len()];
    let mut stack: Vec<usize> = near(li, local.nx)
        .flat_map(|i| near(lj, local.ny).map(move |j| local.index(i, j)))
        .filter(|&k| problem.free[k])
        .collect();
    for &k in &stack {
        seen[k] = true;
    }
    while let Some(k) = stack.pop() {
        if problem.known[k] {
            let g = global(k);
            // A target cell (W = 1), or a ring cell at least as high as the agent.
            if w.mantissa[g] > 0.0 && log2(g) >= here {
                return true;
            }
            continue;
        }
        for m in local.neighbours_of(k) {
            if problem.free[m] && !seen[m] {
                seen[m] = true;
                stack.push(m);
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::HarmonicField;

    /// `worlds/crowds/circle-16.toml` and its first agent's field of the walls.
    fn circle_16() -> (crate::world::World, HarmonicField) {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/crowds/circle-16.toml");
        let world = crate::world::load(&path, &[]).unwrap();
        let walls = HarmonicField::solve(&world, &world.agents[0]).unwrap();
        (world, walls)
    }

    /// A wide window's coarse window covers the whole grid and serves the next wide window,
    /// never an ordinary one (the field among the others over the whole grid, held as the edge
    /// of ordinary windows, milled crossing flows about for good: see the commit that reverted
    /// that reuse); an ordinary coarse window serves the next ordinary replan.
    #[test]
    fn a_wide_windows_coarse_window_covers_the_grid_and_serves_only_wide_windows() {
        let (world, walls) = circle_16();
        let agent = &world.agents[0];
        let others: Vec<Disc> = (world.agents[1..].iter())
            .map(|a| Disc {
                center: a.start,
                radius: a.radius,
            })
            .collect();
        let coarse = |f: &HarmonicField| f.window.as_ref().unwrap().coarse.clone().unwrap();
        let solved = |f: &HarmonicField| Arc::clone(&coarse(f).solved);
        let settings = crate::world::FieldSettings {
            replan_reach: 4.0,
            ..world.field.clone()
        };
        let wide = walls
            .with_wide_window(agent, agent.start, &others, &settings)
            .unwrap()
            .unwrap();
        let covered = solved(&wide).sampler.grid().len() * COARSE * COARSE;
        assert!(
            coarse(&wide).whole && covered >= walls.grid().len(),
            "{covered}"
        );
        let wide_again = wide
            .with_wide_window(agent, agent.start, &others, &settings)
            .unwrap()
            .unwrap();
        assert!(Arc::ptr_eq(&solved(&wide), &solved(&wide_again)));
        assert!(coarse(&wide_again).whole && coarse(&wide_again).reused == 1);
        let next = wide
            .with_window(agent, agent.start, &others, &settings)
            .unwrap();
        assert!(!coarse(&next).whole && coarse(&next).reused == 0);
        let again = next
            .with_window(agent, agent.start, &others, &settings)
            .unwrap();
        assert!(Arc::ptr_eq(&solved(&next), &solved(&again)));
        assert_eq!(coarse(&again).reused, 1);
    }

    /// A replan that sets the very problem of the last one (the same discs, the agent where it
    /// was, the coarse window reused) is served the last solution, solving nothing; one disc
    /// moved by two cells makes a new problem, which is solved.
    #[test]
    fn a_replan_that_sets_the_same_problem_is_served_the_last_solution() {
        let (world, walls) = circle_16();
        let agent = &world.agents[0];
        // Two robots a metre or so down the agent's guidance.
        let g = walls.gradient(agent.start).unwrap().normalize();
        let ahead = |d: f64, s: f64| Disc {
            center: [
                agent.start[0] - d * g.x - s * g.y,
                agent.start[1] - d * g.y + s * g.x,
            ],
            radius: agent.radius,
        };
        let others = [ahead(1.2, 0.3), ahead(2.0, -0.5)];
        let window = |f: &HarmonicField| Arc::clone(f.window.as_ref().unwrap());
        let first = walls
            .with_window(agent, agent.start, &others, &world.field)
            .unwrap();
        assert!(window(&first).iterations > 0);
        let again = first
            .with_window(agent, agent.start, &others, &world.field)
            .unwrap();
        assert!(Arc::ptr_eq(&window(&first).solved, &window(&again).solved));
        assert_eq!(window(&again).iterations, 0);
        let moved = [ahead(1.2, 0.3 + 2.0 * world.field.cell), ahead(2.0, -0.5)];
        let next = again
            .with_window(agent, agent.start, &moved, &world.field)
            .unwrap();
        assert!(!Arc::ptr_eq(&window(&again).solved, &window(&next).solved));
        assert!(window(&next).iterations > 0);
        let (a, b) = (
            again.gradient(agent.start).unwrap(),
            next.gradient(agent.start).unwrap(),
        );
        assert_ne!(a, b);
    }

    /// The box a coarse window's levels stop at holds every cell that a ring of a fine window
    /// it serves can read: the interpolation stencils of the ring's cell centres and the
    /// cells within `NEAR` of them, for agents anywhere within the reach it serves, near the
    /// grid's edges too.
    #[test]
    fn a_coarse_window_keeps_every_cell_its_rings_read() {
        let grid = Grid {
            nx: 400,
            ny: 300,
            cell: 0.1,
            origin: [-0.05, 0.03],
        };
        let (half, reach) = (3.0, 24.0);
        for position in [[20.0, 15.0], [1.0, 2.0], [39.5, 29.0], [5.33, 27.1]] {
            let coarse = coarse_grid(&grid, position, reach);
            for serves in [0.0, 0.25 * reach] {
                let Stop::Within(bi, bj) = read_by_rings((&coarse, &grid), position, half, serves)
                else {
                    panic!("a box");
                };
                let steps = 12;
                for a in 0..=steps {
                    for b in 0..=steps {
                        let d = [a, b].map(|s| serves * (2.0 * s as f64 / steps as f64 - 1.0));
                        if d[0].hypot(d[1]) >= serves && serves > 0.0 {
                            continue;
                        }
                        let q = [position[0] + d[0], position[1] + d[1]];
                        let (ir, jr) =
                            grid.cells_in([q[0] - half, q[1] - half], [q[0] + half, q[1] + half]);
                        for j in jr.clone() {
                            for i in ir.clone() {
                                let ring = i == ir.start
                                    || j == jr.start
                                    || i + 1 == ir.end
                                    || j + 1 == jr.end;
                                if !ring {
                                    continue;
                                }
                                let p = grid.center(i, j);
                                let f = [0, 1].map(|x| {
                                    ((p[x] - coarse.origin[x]) / coarse.cell - 0.5).floor() as i64
                                });
                                for (f, range, n) in
                                    [(f[0], &bi, coarse.nx), (f[1], &bj, coarse.ny)]
                                {
                                    let lo = (f - NEAR).max(0) as usize;
                                    let hi = ((f + 1 + NEAR).min(n as i64 - 1)).max(0) as usize;
                                    assert!(
                                        range.contains(&lo) && range.contains(&hi),
                                        "{position:?} serving {serves}: ring point {p:?} reads {lo}..={hi}, the box keeps {range:?}"
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}
