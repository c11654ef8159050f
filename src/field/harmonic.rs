//! An agent's harmonic field ([`HarmonicField`]) and its production solve of `W = 1 − V`
//! ([`solve_w`]): multigrid-preconditioned CG (`multigrid/`) over the whole grid (on a large
//! map, over a box around the target when that resolves as much: see [`FIRST_BOX`]), then the
//! nested levels below what that resolves (`nested.rs`).
//!
//! A solve to a relative residual of 1e-10 gives `W` to about 1e-12 absolute. Behind a few
//! turns `W` is far smaller than that (1e-13 in the 10 m room at 1 cm cells, 1e-17 in a
//! 16 m × 10 m world with three shelves, 1e-140 in the spiral maze, 1e-6500 in a benchmark
//! maze), so the first solution there is noise, and the guidance direction with it. The cells
//! below τ = 1e-6 (less those next to a wall, see `deep_cells`) are therefore solved again,
//! band after band, each at its own scale and stored with its exponent ([`ScaledW`]): the
//! field never goes flat where a path exists, however deep.

use std::sync::Arc;
use std::time::{Duration, Instant};

use nalgebra::Vector2;

use super::grid::Grid;
use super::mask::CellCounts;
use super::multigrid;
use super::nested::{
    DEPTH_STEP, LevelStats, MAX_BAND, MAX_ITERATIONS, Stop, cut_from_the_rest, deep_cells,
    solve_levels,
};
use super::scaled::{ScaledW, ldexp};
use super::window::{Reach, Window};
use super::{Disc, FieldError, FreeSpace, KnownMap, Sampler, Streamline};
use crate::control::unit;
use crate::world::{Agent, FieldSettings, World};

/// The smallest `|∇V|` [`HarmonicField::gradient`] returns, 1/m: a gradient below it is
/// returned at this magnitude with its direction (above `control::MIN_GRADIENT`, far below
/// anything a force in f32 can carry).
pub const GRADIENT_FLOOR: f64 = 1e-270;

/// The solved field of one agent, with the statistics of the solve.
///
/// The grid's values and mask are shared ([`Arc`]): a local replan ([`HarmonicField::with_window`])
/// makes a new field from the same solve of the walls and a new [`Window`] without copying them.
#[derive(Debug, Clone)]
pub struct HarmonicField {
    /// The field over the whole grid, ready to sample.
    pub sampler: Arc<Sampler>,
    /// The configuration-space mask: `true` where the agent's centre cannot be.
    pub blocked: Arc<Vec<bool>>,
    /// The field re-solved around the agent with the other agents in it (local replanning);
    /// samples inside it are read from it.
    pub window: Option<Arc<Window>>,
    /// The target, m.
    pub target: [f64; 2],
    /// The radius of the target disc where `V = 0`, m (see [`HarmonicField::gradient`]).
    pub target_radius: f64,
    /// Conjugate gradient iterations over all solves.
    pub iterations: usize,
    /// Solves: the first plus the nested ones for the deep regions (see [`solve_w`]).
    pub solves: usize,
    /// The unknown cells of the first solve: every reachable cell, or on a large map those of
    /// a box around the target (both, when the box was too small: see [`solve_w`]).
    pub first_cells: usize,
    /// Whether the first solve's result is that of a box around the target (a large map's,
    /// when the box was large enough: see [`solve_w`]).
    pub first_on_box: bool,
    /// The nested levels below the first solve.
    pub nested: LevelStats,
    /// The worst final relative residual of the solves.
    pub relative_residual: f64,
    /// Wall-clock time of the solve.
    pub solve_time: Duration,
}

impl HarmonicField {
    /// Rasterizes the world for `agent` and solves its field, to every cell however deep (the
    /// field `nadf field` exports and draws).
    pub fn solve(world: &World, agent: &Agent) -> Result<Self, FieldError> {
        let started = Instant::now();
        let space = FreeSpace::of(world, agent)?;
        Self::solve_space(world, agent, space, (None, None), started)
    }

    /// Solves the field with the agent at `position`, the walls sensed with `offsets` and the
    /// discs `others` (the other agents) as obstacles too (see [`FreeSpace::among`]),
    /// warm-started from `previous` (the last field, on the same grid). A field of any depth is
    /// solved only to [`BELOW_AGENT`](super::BELOW_AGENT) of `W` at `position` (the cells
    /// beyond are 0: see [`solve_w_for`](super::solvers::solve_w_for));
    /// [`HarmonicField::solve`] solves every cell.
    pub fn solve_among(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        offsets: &[f64],
        others: &[Disc],
        previous: Option<&HarmonicField>,
    ) -> Result<Self, FieldError> {
        let started = Instant::now();
        let space = FreeSpace::among(world, agent, position, offsets, others)?;
        Self::solve_at(world, agent, space, (position, previous), started)
    }

    /// Solves the field of a lidar agent at `position` on the map it has built (see
    /// [`FreeSpace::known`]), warm-started from `previous`, as deep as
    /// [`HarmonicField::solve_among`] solves.
    pub fn solve_known(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        known: &KnownMap,
        others: &[Disc],
        previous: Option<&HarmonicField>,
    ) -> Result<Self, FieldError> {
        let started = Instant::now();
        let space = FreeSpace::known(world, agent, position, known, others)?;
        Self::solve_at(world, agent, space, (position, previous), started)
    }

    /// Solves the field of `space` for `agent` at `position`, as deep as it can use,
    /// warm-started from `previous` (timed from `started`).
    fn solve_at(
        world: &World,
        agent: &Agent,
        space: FreeSpace,
        (position, previous): ([f64; 2], Option<&HarmonicField>),
        started: Instant,
    ) -> Result<Self, FieldError> {
        let warm = previous.map(|f| f.sampler.values().to_plain());
        Self::solve_space(
            world,
            agent,
            space,
            (warm.as_deref(), Some(position)),
            started,
        )
    }

    /// Solves the field of `space` for `agent` (warm-started from `warm`, timed from `started`):
    /// for the agent at `at`, if given, only as deep as it can use (see [`solve_w_for`]).
    pub(super) fn solve_space(
        world: &World,
        agent: &Agent,
        space: FreeSpace,
        (warm, at): (Option<&[f64]>, Option<[f64; 2]>),
        started: Instant,
    ) -> Result<Self, FieldError> {
        let grid = &space.grid;
        let stop = (at.and_then(|p| grid.cell_of(p)))
            .map_or(Stop::Never, |(i, j)| Stop::BelowAgent(grid.index(i, j)));
        let solution = solve_w_for(
            grid,
            (&space.reachable, &space.target_cells),
            world.field.tolerance,
            warm,
            &stop,
        );
        if solution.relative_residual.is_nan() || solution.relative_residual > world.field.tolerance
        {
            return Err(FieldError::Solver {
                agent: agent.name.clone(),
                iterations: solution.iterations,
                relative_residual: solution.relative_residual,
            });
        }
        Ok(Self {
            sampler: Arc::new(Sampler::new(space.grid, solution.w, space.reachable)),
            blocked: Arc::new(space.blocked),
            window: None,
            target: agent.target,
            target_radius: agent.target_disc(),
            iterations: solution.iterations,
            solves: solution.solves,
            first_cells: solution.first_cells,
            first_on_box: solution.first_on_box,
            nested: solution.nested,
            relative_residual: solution.relative_residual,
            solve_time: started.elapsed(),
        })
    }

    /// This field (its walls' part) with the field re-solved in a window around `position`
    /// with the discs `others` as obstacles (see [`Window`]): a local replan, with the window's
    /// extent (`replan_window`, `replan_reach`) and tolerance from `settings`. The whole grid's
    /// values are shared, not copied.
    ///
    /// ```
    /// # let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
    /// # let world = nadf::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
    /// let agent = &world.agents[0];
    /// let walls = nadf::field::HarmonicField::solve(&world, agent).unwrap();
    /// // Another robot a metre down this one's guidance.
    /// let [x, y] = agent.start;
    /// let g = walls.gradient(agent.start).unwrap();
    /// let ahead = [x - g.x / g.norm(), y - g.y / g.norm()];
    /// let other = nadf::field::Disc { center: ahead, radius: 0.2 };
    /// let replanned = walls.with_window(agent, agent.start, &[other], &world.field).unwrap();
    /// // The guidance turns aside: no longer straight at the other robot.
    /// let turned = replanned.gradient(agent.start).unwrap();
    /// let cos = g.dot(&turned) / (g.norm() * turned.norm());
    /// assert!(cos < 0.98, "{cos}");
    /// ```
    ///
    /// On a field that already has a window (the last replan's, on the same walls), parts of
    /// that one's work may be reused (its coarse window: see [`Window`]).
    pub fn with_window(
        &self,
        agent: &Agent,
        position: [f64; 2],
        others: &[Disc],
        settings: &FieldSettings,
    ) -> Result<Self, FieldError> {
        self.windowed(
            agent,
            position,
            others,
            settings,
            Reach::Around(settings.replan_reach),
        )
    }

    /// [`HarmonicField::with_window`] with the window's edge from the field among the others
    /// over the whole grid at four times the cell ([`Reach::Whole`]) instead of a coarse window
    /// around the agent: which way a crowd leaves, wherever it leaves it, at a sixteenth of
    /// the cells of a full re-solve. The arbiter of a window whose guidance turns back on the
    /// agent's last field. `None` where the coarse window around the agent (`replan_reach`)
    /// already covers the grid: the wide window would be the window's own problem again, and
    /// what is left to tell them apart is the coarse cell, which only the full re-solve
    /// resolves. When `self`'s window is the last replan's wide window, its field over the
    /// whole grid may serve again (see [`Reach::Whole`]); an ordinary window's never does.
    ///
    /// ```
    /// # let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
    /// # let world = nadf::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
    /// use nadf::field::{Disc, HarmonicField};
    /// let agent = &world.agents[0];
    /// let walls = HarmonicField::solve(&world, agent).unwrap();
    /// // A row of robots across the guidance, 2 m ahead in the gap the agent heads for.
    /// let [x, y] = agent.start;
    /// let g = walls.gradient(agent.start).unwrap().normalize();
    /// let across = |s: f64| [x - 2.0 * g.x - s * g.y, y - 2.0 * g.y + s * g.x];
    /// let others: Vec<Disc> = (-1..=1)
    ///     .map(|k| Disc { center: across(0.5 * k as f64), radius: 0.25 })
    ///     .collect();
    /// // A coarse window of 4 m, so that the whole grid's is wider.
    /// let settings = nadf::world::FieldSettings { replan_reach: 4.0, ..world.field.clone() };
    /// let wide = walls.with_wide_window(agent, agent.start, &others, &settings).unwrap().unwrap();
    /// assert!(walls.with_wide_window(agent, agent.start, &others, &world.field).is_none());
    /// let full = HarmonicField::solve_among(&world, agent, agent.start, &[], &others, None).unwrap();
    /// // The same way round the robots as the full re-solve's.
    /// let (a, b) = (wide.gradient(agent.start).unwrap(), full.gradient(agent.start).unwrap());
    /// assert!(a.dot(&b) / (a.norm() * b.norm()) > 0.9);
    /// ```
    pub fn with_wide_window(
        &self,
        agent: &Agent,
        position: [f64; 2],
        others: &[Disc],
        settings: &FieldSettings,
    ) -> Option<Result<Self, FieldError>> {
        let ((lo, hi), reach) = (self.grid().bounds(), settings.replan_reach);
        let covered = (0..2).all(|a| position[a] - reach <= lo[a] && position[a] + reach >= hi[a]);
        (!covered).then(|| self.windowed(agent, position, others, settings, Reach::Whole))
    }

    /// This field with a window around `position` whose coarse window extends to `reach`.
    fn windowed(
        &self,
        agent: &Agent,
        position: [f64; 2],
        others: &[Disc],
        settings: &FieldSettings,
        reach: Reach,
    ) -> Result<Self, FieldError> {
        let values = (
            self.grid(),
            self.sampler.reachable_cells(),
            self.sampler.values(),
        );
        let window = Window::solve(
            values,
            agent,
            position,
            (settings.replan_window, reach),
            (others, self.window.as_deref()),
            settings.tolerance.max(super::window::WINDOW_TOLERANCE),
        )?;
        Ok(Self {
            window: Some(Arc::new(window)),
            ..self.clone()
        })
    }

    /// This field without its window: the field of the walls alone.
    pub fn without_window(&self) -> Self {
        Self {
            window: None,
            ..self.clone()
        }
    }

    /// The field samples at `p` are read from: the window where it covers `p`, else the
    /// whole grid's.
    fn sampler_at(&self, p: [f64; 2]) -> &Sampler {
        match &self.window {
            Some(w) if w.covers(p) => w.sampler(),
            _ => &self.sampler,
        }
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        self.sampler.grid()
    }

    /// How many cells are reachable, blocked and unreachable.
    pub fn counts(&self) -> CellCounts {
        CellCounts::of(&self.blocked, self.sampler.reachable_cells())
    }

    /// The potential `V` at `p` (1 where nothing reachable is near).
    pub fn potential(&self, p: [f64; 2]) -> f64 {
        1.0 - self.sampler_at(p).w(p).unwrap_or(0.0)
    }

    /// `1 - V` at `p`, with full relative precision where `V` is close to 1 (0 where it is
    /// below f64's range: see [`HarmonicField::log10_one_minus_potential`]).
    pub fn one_minus_potential(&self, p: [f64; 2]) -> f64 {
        self.sampler_at(p).w(p).unwrap_or(0.0)
    }

    /// `log10(1 − V)` at `p`, at any depth (−∞ where nothing reachable is near).
    pub fn log10_one_minus_potential(&self, p: [f64; 2]) -> f64 {
        match self.sampler_at(p).w_scaled(p) {
            Some((w, e)) if w > 0.0 => (w.log2() + f64::from(e)) * std::f64::consts::LOG10_2,
            _ => f64::NEG_INFINITY,
        }
    }

    /// The gradient `g = ∇V` at `p`; `None` where the field is undefined (far from any
    /// reachable cell). Callers treat `None` like a vanishing gradient.
    ///
    /// Deep in a maze `|∇V|` is far below f64's range (1e-6500 and less). There the gradient
    /// is returned at magnitude [`GRADIENT_FLOOR`] with its exact direction: the paper's
    /// `−K∇V` is still nothing (no force that small survives the conversion to Rapier's f32),
    /// while normalized guidance and NADF's split, which use the direction only, keep it.
    ///
    /// **The target disc.** `V = 0` on the disc, so its gradient vanishes there, and within a
    /// cell or two outside it the interpolated gradient mixes in the disc's cells. Within
    /// [`HarmonicField::rim`] of the target the gradient therefore continues as a bowl,
    /// `∇V = |∇V(rim)| · (x − x_T)/rim`: radial (the disc is an equipotential, so the field
    /// leaves it radially), as large as the field at the rim in that direction and falling
    /// linearly to zero at the target, so a body is brought to the target point itself rather
    /// than left anywhere on the disc.
    ///
    /// ```
    /// # let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
    /// # let world = nadf::world::load(&path, &[]).unwrap();
    /// let field = nadf::field::HarmonicField::solve(&world, &world.agents[0]).unwrap();
    /// let [tx, ty] = field.target;
    /// // Inside the disc, half-way to its centre: pointing away from the target (V grows).
    /// let g = field.gradient([tx + 0.5 * field.target_radius, ty]).unwrap();
    /// assert!(g.x > 0.0 && g.y.abs() < 1e-12 * g.x);
    /// ```
    pub fn gradient(&self, p: [f64; 2]) -> Option<Vector2<f64>> {
        let e = Vector2::new(p[0] - self.target[0], p[1] - self.target[1]);
        let d = e.norm();
        let rim = self.rim();
        if d < rim {
            if d == 0.0 {
                return Some(Vector2::zeros());
            }
            let edge = [
                self.target[0] + e.x * rim / d,
                self.target[1] + e.y * rim / d,
            ];
            if let Some(g) = self.sampled_gradient(edge)
                && g.norm() > 0.0
                && g.norm().is_finite()
            {
                return Some(e * (g.norm() / rim));
            }
        }
        self.sampled_gradient(p)
    }

    /// The radius of the bowl around the target (see [`HarmonicField::gradient`]), m: half as
    /// large again as the target disc, so that it does not depend on the grid, and at least
    /// 1.5 cells beyond the disc, where the interpolation no longer reaches the disc's cells.
    pub fn rim(&self) -> f64 {
        (1.5 * self.target_radius).max(self.target_radius + 1.5 * self.grid().cell)
    }

    /// The interpolated gradient of the solved cells at `p` (see [`HarmonicField::gradient`]).
    fn sampled_gradient(&self, p: [f64; 2]) -> Option<Vector2<f64>> {
        let (g, e) = self.sampler_at(p).grad_w_scaled(p)?;
        let true_size = g.map(|c| ldexp(c, e));
        let size = g.norm();
        if true_size.norm() >= GRADIENT_FLOOR || !(size > 0.0 && size.is_finite()) {
            return Some(-true_size);
        }
        Some(-g * (GRADIENT_FLOOR / size))
    }

    /// Checks that the field gives `agent` a direction at its start (or that it starts on its
    /// target): with no direction there, a run could only stand still.
    pub fn check_start(&self, agent: &Agent) -> Result<(), FieldError> {
        let [sx, sy] = agent.start;
        let at_target = (sx - self.target[0]).hypot(sy - self.target[1])
            <= self.grid().cell.max(self.target_radius);
        if at_target || self.gradient(agent.start).and_then(|g| unit(&g)).is_some() {
            Ok(())
        } else {
            Err(FieldError::NoGuidance {
                agent: agent.name.clone(),
                start: agent.start,
            })
        }
    }

    /// The kinematic path from `start` (eq. 4, normalized).
    pub fn streamline(&self, start: [f64; 2]) -> Streamline {
        let g = self.grid();
        self.streamline_within(start, 4.0 * (g.nx * g.ny) as f64 * g.cell)
    }

    /// The streamline from `start`, at most `max_length` long, m.
    pub fn streamline_within(&self, start: [f64; 2], max_length: f64) -> Streamline {
        let cell = self.grid().cell;
        // The direction of descent, −∇V, with the bowl of the target disc (as a unit vector:
        // deep in a maze |∇V| is at the floor, whose square underflows).
        super::streamline::integrate(
            |p| self.gradient(p).and_then(|g| unit(&-g)),
            start,
            self.target,
            0.5 * cell,
            cell,
            max_length,
        )
    }
}

/// The solved field and how the solve went.
#[derive(Debug, Clone)]
pub struct HarmonicSolution {
    /// `W` per cell: 1 at the target, 0 on blocked and unreachable cells, at any depth.
    pub w: ScaledW,
    /// CG iterations over all solves.
    pub iterations: usize,
    /// Solves: the first one plus the nested ones.
    pub solves: usize,
    /// The unknown cells of the first solve (see [`HarmonicField::first_cells`]).
    pub first_cells: usize,
    /// Whether the first solve's result is a box's (see [`HarmonicField::first_on_box`]).
    pub first_on_box: bool,
    /// The worst final relative residual of the solves.
    pub relative_residual: f64,
    /// The nested levels (see `nested.rs`).
    pub nested: LevelStats,
}

/// Solves for `W` on the `reachable` cells with `W = 1` on the `target` cells (the target
/// disc), each solve to a relative residual of `tolerance`: the first solve over the whole
/// grid (on a map of 16 boxes 512 cells wide or more, over one around the target when that
/// resolves as much), then the nested levels below what it resolves. `warm` is a previous `W`
/// on the same grid to start the first solve from (after a small change of the world), if any.
pub fn solve_w(
    grid: &Grid,
    reachable: &[bool],
    target: &[usize],
    tolerance: f64,
    warm: Option<&[f64]>,
) -> HarmonicSolution {
    solve_w_for(grid, (reachable, target), tolerance, warm, &Stop::Never)
}

/// [`solve_w`] with nested levels that may `stop` short of every cell and leave the rest at 0
/// (for an agent, once every cell left is below [`BELOW_AGENT`](super::BELOW_AGENT) of `W`
/// there: see [`Stop`]). Every cell kept is [`solve_w`]'s to the bit (the levels run alike
/// until they stop, and only ever write cells not yet accepted).
pub fn solve_w_for(
    grid: &Grid,
    (reachable, target): (&[bool], &[usize]),
    tolerance: f64,
    warm: Option<&[f64]>,
    stop: &Stop,
) -> HarmonicSolution {
    let mut unknown = reachable.to_vec();
    for &t in target {
        unknown[t] = false;
    }
    let mut w = match warm {
        Some(w) if w.len() == grid.len() => w
            .iter()
            .zip(&unknown)
            .map(|(w, u)| if *u { *w } else { 0.0 })
            .collect(),
        _ => vec![0.0; grid.len()],
    };
    for &t in target {
        w[t] = 1.0;
    }
    let boxed = (warm.is_none())
        .then(|| first_box(grid, &unknown, target, FIRST_BOX))
        .flatten();
    let (first, pending) = first_solve(grid, (&unknown, boxed.as_deref()), &mut w, tolerance);
    let mut w = ScaledW::from_plain(w);
    let nested = solve_levels(grid, pending, &mut w, (tolerance, MAX_BAND), stop);
    HarmonicSolution {
        w,
        iterations: first.iterations + nested.iterations,
        solves: first.solves + nested.solves,
        first_cells: first.cells,
        first_on_box: first.on_box,
        relative_residual: first.relative_residual.max(nested.relative_residual),
        nested,
    }
}

/// The side of the box, in cells, that a large map's first solve is made on (see
/// [`first_box`]).
pub const FIRST_BOX: usize = 512;

/// The unknown cells of the box `side` ([`FIRST_BOX`]) cells wider than the `target` cells,
/// when the grid has at least 16 times its cells and unknown cells beyond it.
///
/// The first solve resolves `W` to [`DEPTH_STEP`] only: on a map of rooms, a few rooms around
/// the target (on the Moving AI rooms map's 2560² grid, 1 153 of its 4.58 M cells; `W` falls
/// below 1e-44 within 256 cells of the target there), and the nested levels solve the rest
/// again band by band. So the first solve is made on a box, a sixteenth of the grid at most,
/// and on the whole grid only when the box turns out too small for the field (see
/// [`first_solve`]). That costs the box's solve on top (the paper's room at 2049² cells, whose
/// field is shallow everywhere: 13 iterations on 262 k cells, an eighth more CPU time); a room
/// smaller than sixteen boxes is solved whole at once.
fn first_box(grid: &Grid, unknown: &[bool], target: &[usize], side: usize) -> Option<Vec<bool>> {
    if grid.len() / 16 < side * side {
        return None;
    }
    let (i, j) = grid.box_around(target.iter().copied())?;
    let half = side / 2;
    let i = i.start.saturating_sub(half)..(i.end + half).min(grid.nx);
    let j = j.start.saturating_sub(half)..(j.end + half).min(grid.ny);
    let mut boxed = vec![false; grid.len()];
    let mut beyond = false;
    for (k, &u) in unknown.iter().enumerate() {
        let inside = i.contains(&(k % grid.nx)) && j.contains(&(k / grid.nx));
        boxed[k] = u && inside;
        beyond |= u && !inside;
    }
    beyond.then_some(boxed)
}

/// How the first solve went: its CG iterations and final residual, how many solves it took
/// (two when a box was too small), their unknown cells, and whether the box's was kept.
#[derive(Default)]
struct FirstSolve {
    iterations: usize,
    relative_residual: f64,
    solves: usize,
    cells: usize,
    on_box: bool,
}

/// The first solve of `w` on the `unknown` cells (from `w` as it is), and the cells it leaves
/// pending for the nested levels: those below [`DEPTH_STEP`] ([`deep_cells`]). With `boxed`
/// (see [`first_box`]), it is made on those cells first, the others held at 0, and the cells
/// the cut may have changed are pending too; if the cut kept a cell above the depth from being
/// accepted, the box was too small, and the solve is made again on every cell from the start,
/// as without a box.
fn first_solve(
    grid: &Grid,
    (unknown, boxed): (&[bool], Option<&[bool]>),
    w: &mut [f64],
    tolerance: f64,
) -> (FirstSolve, Vec<bool>) {
    let mut tried = FirstSolve::default();
    let count = |cells: &[bool]| cells.iter().filter(|&&u| u).count();
    if let Some(boxed) = boxed {
        let start: Vec<f64> = (0..w.len()).filter(|&k| boxed[k]).map(|k| w[k]).collect();
        let stats = multigrid::solve(grid, boxed, w, tolerance, MAX_ITERATIONS);
        let converged = stats.relative_residual <= tolerance;
        let mut pending = deep_cells(grid, unknown, w, DEPTH_STEP);
        if converged && cut_from_the_rest(grid, (unknown, boxed), w, &mut pending) {
            let first = FirstSolve {
                iterations: stats.iterations,
                relative_residual: stats.relative_residual,
                solves: 1,
                cells: count(boxed),
                on_box: true,
            };
            return (first, pending);
        }
        // Too small: from the start again, on every cell.
        for (k, v) in (0..w.len()).filter(|&k| boxed[k]).zip(start) {
            w[k] = v;
        }
        tried = FirstSolve {
            iterations: stats.iterations,
            solves: 1,
            cells: count(boxed),
            ..FirstSolve::default()
        };
    }
    let stats = multigrid::solve(grid, unknown, w, tolerance, MAX_ITERATIONS);
    let first = FirstSolve {
        iterations: tried.iterations + stats.iterations,
        relative_residual: stats.relative_residual,
        solves: tried.solves + 1,
        cells: tried.cells + count(unknown),
        on_box: false,
    };
    (first, deep_cells(grid, unknown, w, DEPTH_STEP))
}

/// The field with `W = 1` on the one free cell `target` of the `blocked` mask, to 1e-12: the
/// point target of the solver tests.
#[cfg(test)]
pub(crate) fn solve_from_cell(
    grid: &Grid,
    blocked: &[bool],
    target: (usize, usize),
) -> HarmonicSolution {
    let reachable = super::laplace::reachable_from(grid, blocked, target);
    solve_w(
        grid,
        &reachable,
        &[grid.index(target.0, target.1)],
        1e-12,
        None,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::nested::REACH;

    /// A field flat around the start gives it no direction: an error, not a run that stands
    /// still.
    #[test]
    fn a_start_without_direction_is_an_error() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
        let world = crate::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
        let agent = &world.agents[0];
        let mut field = HarmonicField::solve(&world, agent).unwrap();
        assert_eq!(field.check_start(agent), Ok(()));
        // The same cells, with W constant: no gradient anywhere inside.
        let grid = *field.grid();
        let reachable = field.sampler.reachable_cells().to_vec();
        let flat = ScaledW::from_plain(reachable.iter().map(|r| f64::from(u8::from(*r))).collect());
        field.sampler = Arc::new(Sampler::new(grid, flat, reachable));
        let error = field.check_start(agent).unwrap_err();
        assert!(
            error.to_string().contains("no direction at its start"),
            "{error}"
        );
        // On its target, an agent needs none.
        let mut there = agent.clone();
        there.start = there.target;
        assert_eq!(field.check_start(&there), Ok(()));
    }

    /// Cells below the depth next to a shallow cell are resolved (a wall's neighbours), cells
    /// more than `REACH` steps in are deep, and reach does not cross a wall.
    #[test]
    fn deep_cells_lie_beyond_reach_of_the_shallow_ones() {
        let grid = Grid::covering([3.0, 0.1], 0.1);
        assert_eq!((grid.nx, grid.ny), (30, 1));
        let mut unknown = vec![true; grid.len()];
        unknown[20] = false; // a wall
        // Shallow cells 0..5, then tiny values along the row, and behind the wall.
        let w: Vec<f64> = (0..30).map(|i| if i < 5 { 0.5 } else { 1e-9 }).collect();
        let deep = deep_cells(&grid, &unknown, &w, 1e-6);
        for (i, deep) in deep.iter().enumerate() {
            assert_eq!(*deep, i >= 5 + REACH && i != 20, "cell {i}");
        }
    }

    /// The unknown cells and `W`'s start (1 on the target cells) of the field of `target` on
    /// the free cells of `blocked`.
    fn start_of(grid: &Grid, blocked: &[bool], target: (usize, usize)) -> (Vec<bool>, Vec<f64>) {
        let mut unknown = crate::field::laplace::reachable_from(grid, blocked, target);
        let t = grid.index(target.0, target.1);
        unknown[t] = false;
        let mut w = vec![0.0; grid.len()];
        w[t] = 1.0;
        (unknown, w)
    }

    /// `W` solved to 1e-12 after a first solve on `boxed` cells, or on every cell.
    fn solved_after(
        grid: &Grid,
        (unknown, w): (&[bool], &[f64]),
        boxed: Option<&[bool]>,
    ) -> (FirstSolve, ScaledW) {
        let mut w = w.to_vec();
        let (first, pending) = first_solve(grid, (unknown, boxed), &mut w, 1e-12);
        let mut w = ScaledW::from_plain(w);
        solve_levels(grid, pending, &mut w, (1e-12, MAX_BAND), &Stop::Never);
        (first, w)
    }

    /// A corridor three cells wide and 398 long in a grid of 400 × 400 (the rest blocked):
    /// `W` falls by about half per cell, to 1e-120 at its end. Its first solve on a box 96
    /// cells wide around the target (a sixteenth of the grid) resolves what the solve on every
    /// cell does (`W` at the box's edge is below 1e-13), and with the nested levels every cell
    /// gets the same `W` to six digits.
    #[test]
    fn a_first_solve_on_a_box_gives_the_field_of_one_on_every_cell() {
        let grid = Grid::covering([40.0, 40.0], 0.1);
        assert_eq!(grid.len(), 160_000);
        let blocked: Vec<bool> = (0..grid.len())
            .map(|k| !((1..399).contains(&(k % grid.nx)) && (1..4).contains(&(k / grid.nx))))
            .collect();
        let (unknown, w) = start_of(&grid, &blocked, (1, 2));
        let boxed = first_box(&grid, &unknown, &[grid.index(1, 2)], 96).expect("a box");
        assert!(boxed.iter().filter(|b| **b).count() < 200);
        let (first, on_box) = solved_after(&grid, (&unknown, &w), Some(&boxed));
        assert_eq!(first.solves, 1, "the box was enough");
        assert!(first.on_box);
        let (_, whole) = solved_after(&grid, (&unknown, &w), None);
        let far = whole.log2(grid.index(398, 2)) * std::f64::consts::LOG10_2;
        assert!(far < -100.0, "log10 W at the end: {far}");
        crate::field::scaled::assert_same_to_six_digits(&on_box, &whole, &unknown);
    }

    /// In an open room `W` is above the depth everywhere, and a box 32 cells wide in a grid
    /// 160 wide cuts through it: the first solve is made again on every cell, from the start,
    /// and gives that solve's field to the bit.
    #[test]
    fn a_box_too_small_for_the_field_is_solved_again_on_every_cell() {
        let grid = Grid::covering([16.0, 16.0], 0.1);
        let blocked = vec![false; grid.len()];
        let (unknown, w) = start_of(&grid, &blocked, (80, 80));
        let boxed = first_box(&grid, &unknown, &[grid.index(80, 80)], 32).expect("a box");
        let (first, again) = solved_after(&grid, (&unknown, &w), Some(&boxed));
        assert_eq!(first.solves, 2);
        assert!(!first.on_box);
        let (whole_first, whole) = solved_after(&grid, (&unknown, &w), None);
        assert!(first.iterations > whole_first.iterations);
        let bits = |w: &ScaledW| {
            (0..grid.len())
                .map(|k| w.value(k).to_bits())
                .collect::<Vec<_>>()
        };
        assert!(bits(&again) == bits(&whole), "the fields differ");
        // A room under sixteen boxes is solved whole at once.
        assert!(first_box(&grid, &unknown, &[grid.index(80, 80)], 41).is_none());
    }

    /// A long corridor: `W` decays by about e^(−π) per corridor width, to far below what one
    /// solve resolves. Every cell still gets a positive `W` that decreases along the corridor.
    #[test]
    fn deep_regions_keep_full_relative_precision() {
        let grid = Grid::covering([12.0, 0.5], 0.05);
        let blocked = vec![false; grid.len()];
        let target = (0, 5);
        let s = solve_from_cell(&grid, &blocked, target);
        assert!(s.solves > 3, "{} solves", s.solves);
        let row: Vec<f64> = (0..grid.nx).map(|i| s.w.value(grid.index(i, 5))).collect();
        assert!(
            row[grid.nx - 1] > 0.0 && row[grid.nx - 1] < 1e-25,
            "{:e}",
            row[grid.nx - 1]
        );
        for pair in row.windows(2) {
            assert!(pair[1] < pair[0], "{pair:?}");
        }
        // Away from both ends, the decay per cell is that of the slowest discrete mode: with
        // zeros one cell beyond both walls (11 cells apart), cosh κ = 2 − cos(π/11).
        let expected = (-(2.0 - (std::f64::consts::PI / 11.0).cos()).acosh()).exp();
        for i in [60, 100, 150, 200] {
            let ratio = row[i + 1] / row[i];
            assert!(
                (ratio / expected - 1.0).abs() < 1e-6,
                "cell {i}: {ratio} vs {expected}"
            );
        }
    }
}
