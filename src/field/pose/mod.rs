//! The harmonic guidance field of a shaped body in its configuration space (x, y, θ)
//! ([`PoseField`]).
//!
//! **The metric.** Laplace's equation needs lengths along every axis, and θ is an angle. The
//! field is solved in the coordinates `q = (x, y, ρθ)` with `ρ = √(I/m)`, the body's radius of
//! gyration: then the kinetic energy is `½ m |q̇|²`, so the inertia matrix in `q` is `m·I₃`
//! (the paper's `D = diag(m, m, I)` made isotropic), a unit of `|∇V|` means the same along every
//! axis, and the control laws of the plane apply in `q` unchanged, with the torque `τ = ρ F_3`.
//! A body that turns by δ moves its material by about `ρ δ` on average, so distances in `q`
//! are distances the body's mass travels. (A choice of ρ changes the field, not its lack of
//! local minima: any constant metric keeps it harmonic.)
//!
//! **The grid.** The plane's grid (anchored on the target) times `headings` slices of θ, each
//! masked by [`HeadingMask`] (conservative over its interval). `W = 1 − V` is 1 on the target
//! set — the free cells within the target radius of the target point, and with a
//! `target_heading` within that radius in `q` (a ball) — and 0 on blocked cells; it is solved
//! on the free cells connected to the target set ([`depth::solve_w`], multigrid-preconditioned
//! CG periodic in θ, nested to any depth). A start pose whose cell is not connected is
//! intractable.
//!
//! **Sampling.** `W` is interpolated trilinearly over the reachable corners of the point's cell
//! (θ wrapping), and `∇W` from central differences at those corners, at their largest scale, so
//! the direction keeps full precision at any depth. Near the target the gradient continues as
//! the plane field's bowl, in `q`.

pub mod depth;
pub mod multigrid;

use std::sync::Arc;
use std::time::{Duration, Instant};

use nalgebra::Vector3;

use super::scaled::{ScaledW, ldexp};
use super::{FieldError, GRADIENT_FLOOR, Grid, HeadingMask};
use crate::control::unit;
use crate::world::{Agent, BodyShape, World, all_wall_shapes};
use multigrid::Dims;

/// The solved field of one shaped agent in (x, y, θ).
#[derive(Debug, Clone)]
pub struct PoseField {
    /// The configuration-space mask, slice after slice.
    pub mask: Arc<HeadingMask>,
    /// The length that scales θ in the metric, m (the radius of gyration, see the module).
    pub rho: f64,
    /// `W = 1 − V` per cell (1 on the target set, 0 on blocked and unreachable cells).
    pub w: ScaledW,
    /// The free cells connected to the target set.
    pub reachable: Vec<bool>,
    /// The target point, m.
    pub target: [f64; 2],
    /// The heading to reach, rad, if any.
    pub target_heading: Option<f64>,
    /// The radius of the target set in `q`, m.
    pub target_radius: f64,
    /// Solves (the first and the nested ones for deep regions).
    pub solves: usize,
    /// CG iterations over all solves.
    pub iterations: usize,
    /// The worst final relative residual.
    pub relative_residual: f64,
    /// Wall-clock time of the mask.
    pub mask_time: Duration,
    /// Wall-clock time of the solves.
    pub solve_time: Duration,
}

/// A point of the configuration space: position (m) and heading (rad).
pub type Pose = [f64; 3];

/// The smallest difference `a − b` of two angles, in `(−π, π]`.
pub fn angle_difference(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    if d > std::f64::consts::PI {
        d - std::f64::consts::TAU
    } else {
        d
    }
}

impl PoseField {
    /// Builds the mask of `agent`'s shape among `world`'s walls and solves its field; `rho` is
    /// the metric's length for θ, m.
    ///
    /// Errors: a target set with no free cell ([`FieldError::TargetBlocked`]), a start pose not
    /// connected to it ([`FieldError::PoseUnreachable`]), a solve that missed the tolerance.
    pub fn solve(
        world: &World,
        agent: &Agent,
        shape: &BodyShape,
        rho: f64,
    ) -> Result<Self, FieldError> {
        let started = Instant::now();
        let grid = Grid::anchored_in(world.bounds(), world.field.cell, agent.target);
        let headings = world.field.headings as usize;
        let walls = all_wall_shapes(world);
        let mask = HeadingMask::build(&grid, headings, world.bounds(), &walls, &shape.parts)
            .expect("validated shape and headings");
        let mask_time = started.elapsed();
        let dims = Dims {
            nx: grid.nx,
            ny: grid.ny,
            nt: headings,
        };
        let target_radius = agent.target_disc();
        let mut field = Self {
            mask: Arc::new(mask),
            rho,
            w: ScaledW::from_plain(Vec::new()),
            reachable: Vec::new(),
            target: agent.target,
            target_heading: agent.target_heading,
            target_radius,
            solves: 0,
            iterations: 0,
            relative_residual: 0.0,
            mask_time,
            solve_time: Duration::ZERO,
        };
        // The target set: free cells within the target radius (plus half a cell) in q.
        let reach = target_radius + 0.5 * grid.cell;
        let target: Vec<usize> = (0..dims.len())
            .filter(|&c| {
                let (i, j, k) = depth::coordinates(dims, c);
                !field.mask.blocked[c]
                    && field
                        .offset([
                            grid.center(i, j)[0],
                            grid.center(i, j)[1],
                            field.mask.heading(k),
                        ])
                        .norm()
                        <= reach
            })
            .collect();
        if target.is_empty() {
            return Err(FieldError::TargetBlocked {
                agent: agent.name.clone(),
                cell: grid.cell,
            });
        }
        let w_theta = (grid.cell / (rho * field.mask.step())).powi(2);
        field.reachable = connected(dims, &field.mask.blocked, &target, w_theta);
        let start = field.cell_of([agent.start[0], agent.start[1], agent.heading]);
        if !start.is_some_and(|c| field.reachable[c]) {
            return Err(FieldError::PoseUnreachable {
                agent: agent.name.clone(),
            });
        }
        let mut unknown = field.reachable.clone();
        for &t in &target {
            unknown[t] = false;
        }
        let solved = Instant::now();
        let lattice = multigrid::Lattice::pose(dims, w_theta);
        let (w, stats) = depth::solve_w(&lattice, &unknown, &target, world.field.tolerance);
        field.solve_time = solved.elapsed();
        if stats.relative_residual > world.field.tolerance {
            return Err(FieldError::Solver {
                agent: agent.name.clone(),
                iterations: stats.iterations,
                relative_residual: stats.relative_residual,
            });
        }
        (field.w, field.solves, field.iterations) = (w, stats.solves, stats.iterations);
        field.relative_residual = stats.relative_residual;
        Ok(field)
    }

    /// The plane's grid (of every slice).
    pub fn grid(&self) -> &Grid {
        &self.mask.grid
    }

    /// The grid's size.
    pub fn dims(&self) -> Dims {
        Dims {
            nx: self.grid().nx,
            ny: self.grid().ny,
            nt: self.mask.headings,
        }
    }

    /// `q − q_T` in the metric coordinates `(x, y, ρθ)`, m: the heading's part is 0 without a
    /// target heading (any heading is the target).
    pub fn offset(&self, [x, y, theta]: Pose) -> Vector3<f64> {
        let turn = self
            .target_heading
            .map_or(0.0, |t| self.rho * angle_difference(theta, t));
        Vector3::new(x - self.target[0], y - self.target[1], turn)
    }

    /// The cell holding `pose`, if it is on the grid.
    pub fn cell_of(&self, [x, y, theta]: Pose) -> Option<usize> {
        let (i, j) = self.grid().cell_of([x, y])?;
        Some(self.mask.index(i, j, self.mask.slice_of(theta)))
    }

    /// The (up to eight) reachable cells around `pose` with their trilinear weights.
    fn corners(&self, [x, y, theta]: Pose) -> ([(usize, f64); 8], usize) {
        let g = self.grid();
        let (fx, fy) = (
            (x - g.origin[0]) / g.cell - 0.5,
            (y - g.origin[1]) / g.cell - 0.5,
        );
        let ft = theta / self.mask.step();
        let (i0, j0, k0) = (fx.floor(), fy.floor(), ft.floor());
        let (tx, ty, tt) = (fx - i0, fy - j0, ft - k0);
        let nt = self.mask.headings as i64;
        let mut out = [(0, 0.0); 8];
        let mut n = 0;
        for (dk, wk) in [(0, 1.0 - tt), (1, tt)] {
            let k = (k0 as i64 + dk).rem_euclid(nt) as usize;
            for (dj, wj) in [(0, 1.0 - ty), (1, ty)] {
                let j = j0 as i64 + dj;
                for (di, wi) in [(0, 1.0 - tx), (1, tx)] {
                    let i = i0 as i64 + di;
                    if i < 0 || j < 0 || i >= g.nx as i64 || j >= g.ny as i64 {
                        continue;
                    }
                    let c = self.mask.index(i as usize, j as usize, k);
                    let w = wi * wj * wk;
                    if self.reachable[c] && w > 0.0 {
                        out[n] = (c, w);
                        n += 1;
                    }
                }
            }
        }
        (out, n)
    }

    /// `W` at `pose` as `(m, e)` with `W = m · 2^e`; `None` where no reachable cell is near.
    pub fn w_scaled(&self, pose: Pose) -> Option<(f64, i32)> {
        let (corners, n) = self.corners(pose);
        let corners = &corners[..n];
        let e = corners.iter().map(|&(c, _)| self.w.exponent[c]).max()?;
        let total: f64 = corners.iter().map(|&(_, w)| w).sum();
        let sum: f64 = corners
            .iter()
            .map(|&(c, w)| w * self.w.at_scale(c, e))
            .sum();
        Some((sum / total, e))
    }

    /// `log10(1 − V)` at `pose`, at any depth (−∞ where nothing reachable is near).
    pub fn log10_one_minus_potential(&self, pose: Pose) -> f64 {
        match self.w_scaled(pose) {
            Some((w, e)) if w > 0.0 => (w.log2() + f64::from(e)) * std::f64::consts::LOG10_2,
            _ => f64::NEG_INFINITY,
        }
    }

    /// The potential `V` at `pose` (1 where nothing reachable is near).
    pub fn potential(&self, pose: Pose) -> f64 {
        1.0 - self.w_scaled(pose).map_or(0.0, |(m, e)| ldexp(m, e))
    }

    /// `∇W` at cell `c` by central differences in `q`, at the scale `2^e`.
    fn grad_at(&self, c: usize, e: i32) -> Vector3<f64> {
        let dims = self.dims();
        let (i, j, k) = depth::coordinates(dims, c);
        let at = |m: Option<usize>| {
            m.filter(|&m| self.reachable[m])
                .map_or(0.0, |m| self.w.at_scale(m, e))
        };
        let h = self.grid().cell;
        let nt = dims.nt;
        let gx = at((i + 1 < dims.nx).then(|| dims.index(i + 1, j, k)))
            - at((i > 0).then(|| dims.index(i - 1, j, k)));
        let gy = at((j + 1 < dims.ny).then(|| dims.index(i, j + 1, k)))
            - at((j > 0).then(|| dims.index(i, j - 1, k)));
        let gt = at(Some(dims.index(i, j, (k + 1) % nt)))
            - at(Some(dims.index(i, j, (k + nt - 1) % nt)));
        Vector3::new(
            gx / (2.0 * h),
            gy / (2.0 * h),
            gt / (2.0 * self.rho * self.mask.step()),
        )
    }

    /// The interpolated gradient of `V` at `pose`, in `q` (1/m), before the bowl.
    fn sampled_gradient(&self, pose: Pose) -> Option<Vector3<f64>> {
        let (corners, n) = self.corners(pose);
        let corners = &corners[..n];
        let e = corners.iter().map(|&(c, _)| self.w.exponent[c]).max()?;
        let total: f64 = corners.iter().map(|&(_, w)| w).sum();
        let g: Vector3<f64> = corners
            .iter()
            .map(|&(c, w)| self.grad_at(c, e) * (w / total))
            .sum();
        let true_size = g.map(|c| ldexp(c, e));
        let size = g.norm();
        if true_size.norm() >= GRADIENT_FLOOR || !(size > 0.0 && size.is_finite()) {
            return Some(-true_size);
        }
        Some(-g * (GRADIENT_FLOOR / size))
    }

    /// The radius of the bowl around the target in `q`, m (as the plane's field's: half as large
    /// again as the target set, and 1.5 cells beyond it).
    pub fn rim(&self) -> f64 {
        let cell = self.grid().cell.max(self.rho * self.mask.step());
        (1.5 * self.target_radius).max(self.target_radius + 1.5 * cell)
    }

    /// The gradient `∇V` at `pose` in `q = (x, y, ρθ)`, 1/m; `None` where the field is
    /// undefined. Within [`PoseField::rim`] of the target it continues as a bowl towards it
    /// (as [`super::HarmonicField::gradient`] does in the plane).
    pub fn gradient(&self, pose: Pose) -> Option<Vector3<f64>> {
        let e = self.offset(pose);
        let d = e.norm();
        let rim = self.rim();
        if d < rim {
            if d == 0.0 {
                return Some(Vector3::zeros());
            }
            let edge = self.pose_at_offset(pose, e * (rim / d));
            if let Some(g) = self.sampled_gradient(edge)
                && g.norm() > 0.0
                && g.norm().is_finite()
            {
                return Some(e * (g.norm() / rim));
            }
        }
        self.sampled_gradient(pose)
    }

    /// The pose whose offset from the target is `offset` (the heading of `near` where the
    /// target has none).
    fn pose_at_offset(&self, near: Pose, offset: Vector3<f64>) -> Pose {
        let theta = match self.target_heading {
            Some(t) => t + offset.z / self.rho,
            None => near[2],
        };
        [self.target[0] + offset.x, self.target[1] + offset.y, theta]
    }

    /// The kinematic path from `start`: the streamline of `−∇V` in `q` (midpoint steps of half a
    /// cell) until it enters the target set, at most `max_length` long in `q`, m. The poses,
    /// and whether it reached the target.
    pub fn streamline(&self, start: Pose, max_length: f64) -> (Vec<Pose>, bool) {
        let step = 0.5 * self.grid().cell;
        let direction = |p: Pose| self.gradient(p).and_then(|g| unit(&-g));
        let advance = |p: Pose, d: Vector3<f64>, by: f64| {
            [p[0] + d.x * by, p[1] + d.y * by, p[2] + d.z * by / self.rho]
        };
        let mut points = vec![start];
        let mut p = start;
        let mut length = 0.0;
        while length < max_length {
            if self.offset(p).norm() <= self.target_radius {
                return (points, true);
            }
            let Some(d1) = direction(p) else { break };
            let Some(d2) = direction(advance(p, d1, 0.5 * step)) else {
                break;
            };
            p = advance(p, d2, step);
            length += step;
            points.push(p);
        }
        let reached = self.offset(p).norm() <= self.target_radius;
        (points, reached)
    }

    /// `log10(1 − V)` of every cell of the slice holding `theta` (−∞ where blocked or
    /// unreachable), row after row: the field the body sees at that heading.
    pub fn slice_log10(&self, theta: f64) -> Vec<f64> {
        let k = self.mask.slice_of(theta);
        let n = self.grid().len();
        (k * n..(k + 1) * n)
            .map(|c| {
                if self.reachable[c] {
                    self.w.log10(c)
                } else {
                    f64::NEG_INFINITY
                }
            })
            .collect()
    }
}

/// A shaped body's configuration space: `(x, y, θ)` in the metric `(x, y, ρθ)`.
impl super::ConfigurationSpace<3> for PoseField {
    type Config = Pose;

    fn offset(&self, pose: Pose) -> Vector3<f64> {
        PoseField::offset(self, pose)
    }

    fn gradient(&self, pose: Pose) -> Option<Vector3<f64>> {
        PoseField::gradient(self, pose)
    }

    fn potential(&self, pose: Pose) -> f64 {
        PoseField::potential(self, pose)
    }

    fn moved(&self, mut pose: Pose, axis: usize, by: f64) -> Pose {
        pose[axis] += if axis == 2 { by / self.rho } else { by };
        pose
    }

    fn curvature_step(&self) -> f64 {
        0.5 * self.grid().cell
    }
}

/// The free cells connected to the `target` cells through the six neighbours (θ wrapping).
fn connected(dims: Dims, blocked: &[bool], target: &[usize], w_theta: f64) -> Vec<bool> {
    let mut reached = vec![false; dims.len()];
    let mut queue: Vec<usize> = target.to_vec();
    for &t in target {
        reached[t] = true;
    }
    while let Some(c) = queue.pop() {
        for (m, _) in dims.neighbours(depth::coordinates(dims, c), w_theta) {
            if !blocked[m] && !reached[m] {
                reached[m] = true;
                queue.push(m);
            }
        }
    }
    reached
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world(text: &str) -> World {
        crate::world::load_str(text, std::path::Path::new("test.toml"), &[]).unwrap()
    }

    const ROOM: &str = r#"
        size = [4.0, 3.0]
        [field]
        cell = 0.05
        headings = 32
        [[walls]]
        shape = "box"
        center = [2.0, 1.0]
        half_extents = [0.05, 1.0]
        [[agents]]
        name = "board"
        start = [1.0, 1.0]
        target = [3.0, 1.0]
        target_radius = 0.2
        [agents.shape]
        kind = "box"
        half_extents = [0.4, 0.05]
        [agents.controller]
        kind = "nadf"
        b = 10.0
    "#;

    fn solved(text: &str) -> (World, PoseField) {
        let world = world(text);
        let agent = &world.shaped[0];
        let shape = BodyShape::of_agent(agent).unwrap().unwrap();
        let rho = (shape.inertia(agent.mass) / agent.mass).sqrt();
        let field = PoseField::solve(&world, agent, &shape, rho).unwrap();
        (world, field)
    }

    /// The field has no local minimum: from every reachable cell, some neighbour holds a larger
    /// `W` (the discrete maximum principle), and the streamline from the start goes round the
    /// divider to the target.
    #[test]
    fn the_field_leads_round_the_divider_from_every_cell() {
        let (world, field) = solved(ROOM);
        let dims = field.dims();
        let mut target_cells = 0;
        for c in (0..dims.len()).filter(|&c| field.reachable[c]) {
            let w = field.w.log2(c);
            if field.w.value(c) == 1.0 {
                target_cells += 1;
                continue;
            }
            let best = dims
                .neighbours(depth::coordinates(dims, c), 1.0)
                .filter(|&(m, _)| field.reachable[m])
                .map(|(m, _)| field.w.log2(m))
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(best > w, "cell {c:?}: a local maximum of W");
        }
        assert!(target_cells > 0);
        let agent = &world.shaped[0];
        let (path, reached) = field.streamline([agent.start[0], agent.start[1], 0.0], 40.0);
        assert!(reached, "{:?}", path.last());
        // It passes above the divider's end (y = 2): the only way round.
        assert!(path.iter().any(|p| p[1] > 2.0 && (p[0] - 2.0).abs() < 0.1));
    }

    /// A target heading makes a ball in q: the field's minimum at the target turns with it.
    #[test]
    fn a_target_heading_is_a_ball_in_the_metric() {
        let text = ROOM.replace(
            "target_radius = 0.2",
            "target_radius = 0.2\ntarget_heading = 1.5707963",
        );
        let (_, field) = solved(&text);
        let at = |theta: f64| field.log10_one_minus_potential([3.0, 1.0, theta]);
        assert!(
            at(std::f64::consts::FRAC_PI_2) > at(0.0) + 0.1,
            "{} {}",
            at(1.57),
            at(0.0)
        );
        // Turning towards the target heading is downhill: ∇V's heading part is negative below it.
        let g = field.gradient([3.0, 1.0, 1.0]).unwrap();
        assert!(g.z < 0.0, "{g}");
    }
}
