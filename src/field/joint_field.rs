//! The harmonic field of a planar arm in its joint space (issue 27, third part): Laplace's
//! equation on the free cells of its [`JointMask`] connected to the target set, solved by the
//! 3-D solver on the mask's topology (a joint without limits is a periodic axis), to any depth
//! ([`JointField`]).
//!
//! The joints map onto the solver's axes last joint first: two joints are `(x, θ) = (q₂, q₁)`
//! with one cell in y, three are `(x, y, θ) = (q₃, q₂, q₁)`, so the grid's index is the mask's.
//! The couplings are those of the Laplacian in radians, `w_a = (Δ₁/Δ_a)²` for cells `Δ_a` wide.
//! The target set is the free cells within `radius` of the target joints (radians, wrapping),
//! or the free cells whose tip lies within `radius` of a target point (metres): every
//! configuration that puts the tip there, a natural Dirichlet set.

use std::time::{Duration, Instant};

use nalgebra::DVector;

use super::pose::depth;
use super::pose::multigrid::{Dims, Lattice};
use super::scaled::ScaledW;
use super::{FieldError, JointMask};
use crate::world::Chain;

/// Where an arm must go.
#[derive(Debug, Clone, PartialEq)]
pub enum JointTarget {
    /// The joint angles (rad), within `radius` (rad).
    Joints {
        /// The angles.
        q: Vec<f64>,
        /// The radius of the ball around them, rad.
        radius: f64,
    },
    /// Any configuration with the tip within `radius` (m) of `point` (m).
    Point {
        /// The point.
        point: [f64; 2],
        /// The radius of the disc around it, m.
        radius: f64,
    },
}

/// A solved joint-space field.
#[derive(Debug, Clone)]
pub struct JointField {
    /// The mask it was solved on.
    pub mask: JointMask,
    /// The solver's grid and topology.
    pub lattice: Lattice,
    /// `W = 1 − V` per cell (1 on the target set, 0 on blocked and unreachable cells).
    pub w: ScaledW,
    /// The free cells connected to the target set.
    pub reachable: Vec<bool>,
    /// The target set's cells.
    pub target_cells: Vec<usize>,
    /// The target the field leads to.
    pub target: JointTarget,
    /// The arm's inertia at the target joints, `D(q_T)`, kg·m²: the metric of the bowl around
    /// them (see [`JointField::gradient`]); `None` for a point target.
    pub bowl_metric: Option<nalgebra::DMatrix<f64>>,
    /// Solves (the first and the nested ones).
    pub solves: usize,
    /// CG iterations over all solves.
    pub iterations: usize,
    /// The worst final relative residual.
    pub relative_residual: f64,
    /// Wall-clock time of the solves.
    pub solve_time: Duration,
}

impl JointField {
    /// Solves the field of `chain` on `mask` towards `target`, from the configuration `start`
    /// (rad); `name` names the arm in errors.
    ///
    /// Errors: no free cell in the target set ([`FieldError::ArmTargetBlocked`]), a start not
    /// connected to it ([`FieldError::PoseUnreachable`]), a solve that missed `tolerance`.
    pub fn solve(
        chain: &Chain,
        mask: JointMask,
        (start, target): (&[f64], &JointTarget),
        tolerance: f64,
        name: &str,
    ) -> Result<Self, FieldError> {
        let n = mask.axes.len();
        assert!((2..=3).contains(&n), "two or three joints");
        let axis = |a: usize| mask.axes[n - 1 - a];
        let dims = Dims {
            nx: axis(0).cells,
            ny: if n == 3 { axis(1).cells } else { 1 },
            nt: mask.axes[0].cells,
        };
        let step0 = mask.axes[0].step();
        let weight = |a: &super::JointAxis| (step0 / a.step()).powi(2);
        let lattice = Lattice {
            dims,
            periodic: [
                axis(0).periodic(),
                n == 3 && axis(1).periodic(),
                mask.axes[0].periodic(),
            ],
            weights: [
                weight(&axis(0)),
                if n == 3 { weight(&axis(1)) } else { 1.0 },
                1.0,
            ],
        };
        let centre = |c: usize| -> Vec<f64> {
            let (i, j, k) = depth::coordinates(dims, c);
            let mut cells = vec![k];
            if n == 3 {
                cells.push(j);
            }
            cells.push(i);
            cells
                .iter()
                .zip(&mask.axes)
                .map(|(k, a)| a.center(*k))
                .collect()
        };
        let in_target = |q: &[f64]| match target {
            JointTarget::Joints { q: t, radius } => {
                let d2: f64 = (q.iter().zip(t))
                    .map(|(a, b)| super::angle_difference(*a, *b).powi(2))
                    .sum();
                d2.sqrt() <= *radius
            }
            JointTarget::Point { point, radius } => {
                let [x, y] = chain.tip(q);
                (x - point[0]).hypot(y - point[1]) <= *radius
            }
        };
        let target_cells: Vec<usize> = (0..dims.len())
            .filter(|&c| !mask.blocked[c] && in_target(&centre(c)))
            .collect();
        if target_cells.is_empty() {
            return Err(FieldError::ArmTargetBlocked {
                arm: name.to_string(),
                cells: mask.axes[0].cells,
                margin: mask.margins.last().copied().unwrap_or(0.0),
            });
        }
        let mut reachable = vec![false; dims.len()];
        let mut queue = target_cells.clone();
        for &t in &target_cells {
            reachable[t] = true;
        }
        while let Some(c) = queue.pop() {
            for (m, _) in lattice.neighbours(depth::coordinates(dims, c)) {
                if !mask.blocked[m] && !reachable[m] {
                    reachable[m] = true;
                    queue.push(m);
                }
            }
        }
        if !mask.cell_of(start).is_some_and(|c| reachable[c]) {
            return Err(FieldError::PoseUnreachable {
                agent: name.to_string(),
            });
        }
        let mut unknown = reachable.clone();
        for &t in &target_cells {
            unknown[t] = false;
        }
        let started = Instant::now();
        let (w, stats) = depth::solve_w(&lattice, &unknown, &target_cells, tolerance);
        if stats.relative_residual > tolerance {
            return Err(FieldError::Solver {
                agent: name.to_string(),
                iterations: stats.iterations,
                relative_residual: stats.relative_residual,
            });
        }
        Ok(Self {
            mask,
            lattice,
            w,
            reachable,
            target_cells,
            target: target.clone(),
            bowl_metric: match target {
                JointTarget::Joints { q, .. } => Some(chain.mass_matrix(q)),
                JointTarget::Point { .. } => None,
            },
            solves: stats.solves,
            iterations: stats.iterations,
            relative_residual: stats.relative_residual,
            solve_time: started.elapsed(),
        })
    }

    /// The cell of each joint's axis holding `q`, and the fractional position in it, for the
    /// interpolation: `(k0, t)` with the centres of `k0` and `k0 + 1` around `q`.
    fn axis_position(&self, a: usize, angle: f64) -> (i64, f64) {
        let axis = self.mask.axes[a];
        let lo = axis.center(0) - 0.5 * axis.step();
        let f = (angle - lo) / axis.step() - 0.5;
        let f = if axis.periodic() {
            f.rem_euclid(axis.cells as f64)
        } else {
            f
        };
        (f.floor() as i64, f - f.floor())
    }

    /// The cell index of per-joint cells `k` (wrapped on periodic axes), if on the grid.
    fn cell(&self, k: &[i64]) -> Option<usize> {
        let cells: Option<Vec<usize>> = (k.iter().zip(&self.mask.axes))
            .map(|(&k, a)| {
                if a.periodic() {
                    Some(k.rem_euclid(a.cells as i64) as usize)
                } else {
                    (k >= 0 && k < a.cells as i64).then_some(k as usize)
                }
            })
            .collect();
        Some(self.mask.index(&cells?))
    }

    /// `∇W` at cell `k` (per-joint cells) by central differences in radians, at scale `2^e`.
    fn grad_at(&self, k: &[i64], e: i32) -> DVector<f64> {
        let at = |k: &[i64]| {
            self.cell(k)
                .filter(|&c| self.reachable[c])
                .map_or(0.0, |c| self.w.at_scale(c, e))
        };
        DVector::from_iterator(
            k.len(),
            (0..k.len()).map(|a| {
                let (mut up, mut down) = (k.to_vec(), k.to_vec());
                up[a] += 1;
                down[a] -= 1;
                (at(&up) - at(&down)) / (2.0 * self.mask.axes[a].step())
            }),
        )
    }

    /// The reachable corners of the cell around `q`, with their per-joint cells and their
    /// multilinear weights.
    fn corners(&self, q: &[f64]) -> Vec<(Vec<i64>, usize, f64)> {
        let n = q.len();
        let positions: Vec<(i64, f64)> = (0..n).map(|a| self.axis_position(a, q[a])).collect();
        let mut corners = Vec::new();
        for bits in 0..(1usize << n) {
            let k: Vec<i64> = (0..n)
                .map(|a| positions[a].0 + ((bits >> a) & 1) as i64)
                .collect();
            let weight: f64 = (0..n)
                .map(|a| {
                    let t = positions[a].1;
                    if (bits >> a) & 1 == 1 { t } else { 1.0 - t }
                })
                .product();
            if let Some(c) = self.cell(&k)
                && self.reachable[c]
                && weight > 0.0
            {
                corners.push((k, c, weight));
            }
        }
        corners
    }

    /// The potential `V` at `q`, interpolated over the reachable corners (1 off the field).
    pub fn potential(&self, q: &[f64]) -> f64 {
        let corners = self.corners(q);
        let Some(e) = corners.iter().map(|(_, c, _)| self.w.exponent[*c]).max() else {
            return 1.0;
        };
        let total: f64 = corners.iter().map(|(_, _, w)| w).sum();
        let w: f64 = corners
            .iter()
            .map(|(_, c, w)| w * self.w.at_scale(*c, e))
            .sum();
        1.0 - super::scaled::ldexp(w / total, e)
    }

    /// `∇V` at the configuration `q` in joint coordinates (1/rad), by interpolating the
    /// central differences of the reachable corners around it; `None` off the field.
    ///
    /// **The bowl of a joints target.** `V = 0` on the ball around the target joints, so the
    /// sampled gradient vanishes there and a body would be left anywhere on the ball. As for a
    /// disc's target disc ([`crate::field::HarmonicField::gradient`]), within
    /// [`JointField::rim`] of the target joints (in radians) the gradient continues as a bowl,
    /// as large as the field at the rim in that direction and falling linearly to zero at
    /// `q_T`. A disc's bowl is radial; an arm's is radial in its inertia metric at the target,
    /// `∇V = |∇V(rim)| · D_T e / (rim |D_T ê|)` with `e = q − q_T` and `D_T = D(q_T)`, so that
    /// where the laws act (the coordinates `y = Lᵀe` in which `D = LLᵀ` is the identity) it
    /// points along `y`: the normalized guidance's taper is then the conservative spring
    /// `−(K/r_c) y`. (Radial in radians it is not conservative there, and NADF, which does not
    /// damp the motion down the guidance, was measured in a limit cycle of 5 mrad around the
    /// target under gravity.) The guidance is so an error channel that is on all the way to the
    /// target, which the iterative bias needs (eq. 48: `u = K_P e + β`; the clamp acts only
    /// while moving away and cannot be one). A point target's set is a family of
    /// configurations (every one with the tip on the disc), with no one point to lead to: it
    /// keeps the flat field, and the clamp holds the arm on it.
    ///
    /// ```
    /// use nadf::field::{JointAxis, JointField, JointMask, JointTarget};
    /// use nadf::world::{Chain, Link};
    /// let link = |length: f64| Link::rod(length, 1.0, 0.05);
    /// let chain = Chain { base: [2.0, 2.0], links: vec![link(1.0), link(0.8)] };
    /// let axis = JointAxis { cells: 64, limits: None };
    /// let mask = JointMask::build(&chain, &[axis, axis], &[], ([0.0, 0.0], [4.0, 4.0]));
    /// let target = JointTarget::Joints { q: vec![0.5, 1.0], radius: 0.2 };
    /// let field = JointField::solve(&chain, mask, (&[-2.0, -1.0], &target), 1e-8, "arm").unwrap();
    /// // Inside the ball: away from q_T in the metric D(q_T), and half as large half-way in.
    /// let d = chain.mass_matrix(&[0.5, 1.0]);
    /// let (near, far) = (field.gradient(&[0.55, 1.0]).unwrap(), field.gradient(&[0.6, 1.0]).unwrap());
    /// let along = d.column(0) / d.column(0).norm();
    /// assert!((&far / far.norm() - &along).norm() < 1e-12);
    /// assert!((&far - &near * 2.0).norm() < 1e-12 * far.norm());
    /// ```
    pub fn gradient(&self, q: &[f64]) -> Option<DVector<f64>> {
        if let JointTarget::Joints { q: t, .. } = &self.target {
            let e = DVector::from_iterator(
                q.len(),
                q.iter()
                    .zip(t)
                    .map(|(a, b)| super::angle_difference(*a, *b)),
            );
            let (d, rim) = (e.norm(), self.rim());
            if d < rim {
                if d == 0.0 {
                    return Some(e);
                }
                let edge: Vec<f64> = t.iter().zip(&e).map(|(t, e)| t + e * rim / d).collect();
                let radial = self.bowl_metric.as_ref().map_or(e.clone(), |m| m * &e);
                if let Some(g) = self.sampled_gradient(&edge)
                    && g.norm() > 0.0
                    && g.norm().is_finite()
                    && radial.norm() > 0.0
                {
                    return Some(&radial * (g.norm() * d / (rim * radial.norm())));
                }
            }
        }
        self.sampled_gradient(q)
    }

    /// The radius of the bowl around target joints (see [`JointField::gradient`]), rad: half
    /// as large again as the target's ball, and at least 1.5 cells beyond it, where the
    /// interpolation no longer reaches its cells. Zero for a point target.
    pub fn rim(&self) -> f64 {
        match &self.target {
            JointTarget::Joints { radius, .. } => {
                let cell = (self.mask.axes.iter().map(|a| a.step())).fold(0.0, f64::max);
                (1.5 * radius).max(radius + 1.5 * cell)
            }
            JointTarget::Point { .. } => 0.0,
        }
    }

    /// The interpolated gradient of the solved cells at `q` (see [`JointField::gradient`]).
    fn sampled_gradient(&self, q: &[f64]) -> Option<DVector<f64>> {
        let corners = self.corners(q);
        let e = corners.iter().map(|(_, c, _)| self.w.exponent[*c]).max()?;
        let total: f64 = corners.iter().map(|(_, _, w)| w).sum();
        let g = corners
            .iter()
            .fold(DVector::zeros(q.len()), |sum, (k, _, w)| {
                sum + self.grad_at(k, e) * (w / total)
            });
        Some(-g.map(|c| super::scaled::ldexp(c, e)))
    }

    /// `log10(1 − V)` at the cell of `q` (−∞ off the reachable cells).
    pub fn log10_one_minus_potential(&self, q: &[f64]) -> f64 {
        match self.mask.cell_of(q) {
            Some(c) if self.reachable[c] => self.w.log10(c),
            _ => f64::NEG_INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::JointAxis;
    use crate::world::{Link, Wall, wall_shape};

    fn link(length: f64) -> Link {
        Link::rod(length, 1.0, 0.05)
    }

    /// A two-link arm on a table whose tip must reach round a post: the field has no local
    /// maximum of `W` but the target set, and following `−∇V` from the start reaches a
    /// configuration whose tip is at the target point, the links never touching the post.
    #[test]
    fn a_two_link_arm_is_guided_round_a_post_to_a_point() {
        let chain = Chain {
            base: [2.0, 2.0],
            links: vec![link(1.0), link(0.8)],
        };
        let post = wall_shape(&Wall::Disc {
            center: [3.2, 2.6],
            radius: 0.2,
        })
        .unwrap();
        let walls = vec![post];
        let axes = [
            JointAxis {
                cells: 256,
                limits: None,
            },
            JointAxis {
                cells: 256,
                limits: Some([-2.8, 2.8]),
            },
        ];
        let mask = JointMask::build(&chain, &axes, &walls, ([0.0, 0.0], [4.0, 4.0]));
        let start = [-0.3, 0.2];
        let point = [2.6, 3.3];
        let target = JointTarget::Point { point, radius: 0.1 };
        let field = JointField::solve(&chain, mask, (&start, &target), 1e-12, "arm").unwrap();
        println!(
            "256² joint cells: {} target cells, {} solve(s), {} CG iterations, {:?}",
            field.target_cells.len(),
            field.solves,
            field.iterations,
            field.solve_time
        );
        let dims = field.lattice.dims;
        for c in (0..dims.len()).filter(|&c| field.reachable[c]) {
            if field.w.value(c) == 1.0 {
                continue;
            }
            let best = field
                .lattice
                .neighbours(depth::coordinates(dims, c))
                .filter(|&(m, _)| field.reachable[m])
                .map(|(m, _)| field.w.log2(m))
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(best > field.w.log2(c), "cell {c}: a local maximum of W");
        }
        // The kinematic path in joint space, by half-cell steps of the unit guidance.
        let mut q = start.to_vec();
        let step = 0.5 * field.mask.axes[1].step();
        let mut reached = false;
        for _ in 0..20_000 {
            let tip = chain.tip(&q);
            if (tip[0] - point[0]).hypot(tip[1] - point[1]) <= 0.1 {
                reached = true;
                break;
            }
            let g = field.gradient(&q).expect("guided everywhere on the way");
            let norm = g.norm();
            assert!(norm > 0.0);
            for (a, d) in q.iter_mut().zip(g.iter()) {
                *a -= step * d / norm;
            }
            let joints = chain.joints(&q);
            for s in joints.windows(2) {
                let d = crate::field::segment_distance([s[0], s[1]], [[3.2, 2.6], [3.2, 2.6]]);
                assert!(d > 0.2 + 0.05, "a link touches the post at {q:?}");
            }
        }
        assert!(reached, "ended at {q:?}, tip {:?}", chain.tip(&q));
        println!("reached the point at q = {q:?}");
    }
}
