//! The joint-space mask of a planar arm (issue 27): a grid over its joint angles, a cell blocked
//! when any link at *any* configuration in the cell touches a wall, leaves the box, or touches a
//! link it is not jointed to ([`JointMask`]).
//!
//! **The bound.** When the joints move by at most `δ_j` each, a point of link `i` at distance
//! `r_j` from joint `j` moves by at most `Σ_{j≤i} r_j δ_j` (each joint's turn moves it along an
//! arc of radius `r_j`; the moves add up at most). Every point of link `i` is within
//! `R_{j,i} = L_j + … + L_i` of joint `j`, so over a cell of half-widths `δ_j` link `i` stays
//! within `ε_i = Σ_{j≤i} δ_j R_{j,i}` of where it is at the cell's centre. A cell is blocked when
//! link `i`'s segment at the centre is within `radius_i + ε_i` of a wall (parry's distance), of
//! the box's edge, or within `radius_i + radius_k + ε_i + ε_k` of a link `k` with `|i − k| ≥ 2`.
//! So a free cell is free at every configuration in it, and a configuration whose links keep
//! more than `2ε_i` from everything is in a free cell.
//!
//! **The method.** Link `i` depends on the first `i` joints only, so the cells are visited as a
//! tree: a blocked prefix blocks every cell under it, and link `i` is measured once per prefix
//! (128 + 128² + 128³ segments for three links at 128 cells a joint, not three per cell). A wall
//! whose bounding box is farther than the segment's bounding circle reaches is not measured.
//! The first joint's cells run in parallel (rayon); each writes its own part of the mask.

use parry2d::math::{Pose, Vector};
use parry2d::shape::Segment;
use rayon::prelude::*;

use crate::world::{Chain, WallShape};

/// One joint's axis of the grid: periodic over a full turn `[−π, π)` without limits, the
/// interval `[min, max]` with them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointAxis {
    /// Cells along the axis.
    pub cells: usize,
    /// The joint's limits, rad, if any.
    pub limits: Option<[f64; 2]>,
}

impl JointAxis {
    /// Where the axis starts and how wide a cell is, rad.
    fn span(&self) -> (f64, f64) {
        let [lo, hi] = self
            .limits
            .unwrap_or([-std::f64::consts::PI, std::f64::consts::PI]);
        (lo, (hi - lo) / self.cells as f64)
    }

    /// The angle at the centre of cell `k`, rad.
    pub fn center(&self, k: usize) -> f64 {
        let (lo, step) = self.span();
        lo + (k as f64 + 0.5) * step
    }

    /// The width of a cell, rad.
    pub fn step(&self) -> f64 {
        self.span().1
    }

    /// Whether the axis wraps (the joint has no limits).
    pub fn periodic(&self) -> bool {
        self.limits.is_none()
    }

    /// The cell holding `angle` (wrapped onto a periodic axis; `None` outside the limits).
    pub fn cell_of(&self, angle: f64) -> Option<usize> {
        let (lo, step) = self.span();
        let f = ((angle - lo) / step).floor();
        if self.periodic() {
            return Some((f as i64).rem_euclid(self.cells as i64) as usize);
        }
        (f >= 0.0 && f < self.cells as f64).then_some(f as usize)
    }
}

/// The joint-space mask of an arm: `blocked[index(k)]`, the last joint's cell fastest.
#[derive(Debug, Clone, PartialEq)]
pub struct JointMask {
    /// The axes, one per joint from the base out.
    pub axes: Vec<JointAxis>,
    /// Each link's margin `ε_i` over a cell, m (see the module).
    pub margins: Vec<f64>,
    /// Whether each cell is blocked.
    pub blocked: Vec<bool>,
}

impl JointMask {
    /// The linear index of the cell with joint cells `k` (one per joint).
    pub fn index(&self, k: &[usize]) -> usize {
        k.iter()
            .zip(&self.axes)
            .fold(0, |index, (k, axis)| index * axis.cells + k)
    }

    /// The cell holding the configuration `q`, if it is within the limits.
    pub fn cell_of(&self, q: &[f64]) -> Option<usize> {
        let k: Option<Vec<usize>> = (self.axes.iter().zip(q))
            .map(|(axis, a)| axis.cell_of(*a))
            .collect();
        Some(self.index(&k?))
    }

    /// The mask of `chain` among `walls` in the box `[lo, hi]`, one axis per joint.
    pub fn build(
        chain: &Chain,
        axes: &[JointAxis],
        walls: &[WallShape],
        (lo, hi): ([f64; 2], [f64; 2]),
    ) -> Self {
        let n = chain.links.len();
        assert_eq!(axes.len(), n, "one axis per joint");
        let margins: Vec<f64> = (0..n)
            .map(|i| {
                (0..=i)
                    .map(|j| {
                        let reach: f64 = chain.links[j..=i].iter().map(|l| l.length).sum();
                        0.5 * axes[j].step() * reach
                    })
                    .sum()
            })
            .collect();
        let len: usize = axes.iter().map(|a| a.cells).product();
        let below = len / axes[0].cells;
        let mut blocked = vec![false; len];
        let scene = Scene {
            chain,
            axes,
            walls,
            margins: &margins,
            bounds: (lo, hi),
        };
        blocked
            .par_chunks_mut(below)
            .enumerate()
            .for_each(|(k0, cells)| {
                let mut q = vec![0.0; n];
                let mut segments = Vec::with_capacity(n);
                scene.visit(0, k0, &mut q, &mut segments, cells);
            });
        Self {
            axes: axes.to_vec(),
            margins,
            blocked,
        }
    }
}

/// What a mask is built from.
struct Scene<'a> {
    chain: &'a Chain,
    axes: &'a [JointAxis],
    walls: &'a [WallShape],
    margins: &'a [f64],
    bounds: ([f64; 2], [f64; 2]),
}

impl Scene<'_> {
    /// Sets joint `i` to its cell `k`, measures link `i`, and blocks `cells` (the cells under
    /// this prefix) when it is too close to something, else goes on to the next joint.
    fn visit(
        &self,
        i: usize,
        k: usize,
        q: &mut [f64],
        segments: &mut Vec<[[f64; 2]; 2]>,
        cells: &mut [bool],
    ) {
        q[i] = self.axes[i].center(k);
        let phi: f64 = q[..=i].iter().sum();
        let a = segments.last().map_or(self.chain.base, |s| s[1]);
        let length = self.chain.links[i].length;
        let b = [a[0] + length * phi.cos(), a[1] + length * phi.sin()];
        if self.link_blocked(i, [a, b], segments) {
            cells.fill(true);
            return;
        }
        segments.push([a, b]);
        if i + 1 < self.axes.len() {
            let below = cells.len() / self.axes[i + 1].cells;
            for (next, part) in cells.chunks_mut(below).enumerate() {
                self.visit(i + 1, next, q, segments, part);
            }
        }
        segments.pop();
    }

    /// Whether link `i` at `segment` (the earlier links at `earlier`) is within its margin of a
    /// wall, the box's edge or a link it is not jointed to.
    fn link_blocked(&self, i: usize, [a, b]: [[f64; 2]; 2], earlier: &[[[f64; 2]; 2]]) -> bool {
        let link = &self.chain.links[i];
        let keep = link.radius + self.margins[i];
        let (lo, hi) = self.bounds;
        if [a, b].iter().any(|p| {
            p[0] < lo[0] + keep || p[1] < lo[1] + keep || p[0] > hi[0] - keep || p[1] > hi[1] - keep
        }) {
            return true;
        }
        // Links i − 2 and before: not jointed to link i.
        for (k, s) in earlier.iter().enumerate().take(i.saturating_sub(1)) {
            let other = &self.chain.links[k];
            if segment_distance([a, b], *s) <= keep + other.radius + self.margins[k] {
                return true;
            }
        }
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        let half = 0.5 * (b[0] - a[0]).hypot(b[1] - a[1]);
        let segment = Segment::new(Vector::new(a[0], a[1]), Vector::new(b[0], b[1]));
        self.walls.iter().any(|wall| {
            wall.distance_bound(mid[0], mid[1]) - half <= keep
                && parry2d::query::distance(
                    &Pose::IDENTITY,
                    &segment,
                    &wall.pose,
                    wall.shape.as_ref(),
                )
                .is_ok_and(|d| d.distance <= keep)
        })
    }
}

/// The distance between two segments, m.
pub fn segment_distance([a, b]: [[f64; 2]; 2], [c, d]: [[f64; 2]; 2]) -> f64 {
    let cross = |o: [f64; 2], p: [f64; 2], q: [f64; 2]| {
        (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0])
    };
    // Proper crossing: distance 0.
    let (d1, d2) = (cross(a, b, c), cross(a, b, d));
    let (d3, d4) = (cross(c, d, a), cross(c, d, b));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return 0.0;
    }
    let to = |p: [f64; 2], [s, e]: [[f64; 2]; 2]| {
        let (vx, vy) = (e[0] - s[0], e[1] - s[1]);
        let len2 = vx * vx + vy * vy;
        let t = if len2 > 0.0 {
            (((p[0] - s[0]) * vx + (p[1] - s[1]) * vy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p[0] - s[0] - t * vx).hypot(p[1] - s[1] - t * vy)
    };
    to(a, [c, d])
        .min(to(b, [c, d]))
        .min(to(c, [a, b]))
        .min(to(d, [a, b]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Link, Wall, wall_shape};

    fn link(length: f64) -> Link {
        Link::rod(length, 1.0, 0.05)
    }

    /// A three-link arm on a table between a post, a shelf and a disc.
    fn scene() -> (Chain, Vec<WallShape>) {
        let chain = Chain {
            base: [2.0, 2.0],
            links: vec![link(0.8), link(0.6), link(0.4)],
        };
        let walls = [
            Wall::Box {
                center: [3.0, 2.4],
                half_extents: [0.1, 0.3],
                angle: 0.2,
            },
            Wall::Disc {
                center: [1.2, 1.3],
                radius: 0.2,
            },
            Wall::Segment {
                a: [1.0, 3.0],
                b: [2.6, 3.3],
                thickness: 0.08,
            },
        ]
        .iter()
        .map(|w| wall_shape(w).unwrap())
        .collect();
        (chain, walls)
    }

    /// The arm's clearance at `q`, by parry: its links' distance (less their radii, and less
    /// `spare` times their margins `eps`) to the walls, the box's edge and each other
    /// (non-adjacent), m.
    fn clearance(
        (chain, walls): (&Chain, &[WallShape]),
        q: &[f64],
        size: f64,
        (eps, spare): (&[f64], f64),
    ) -> f64 {
        let joints = chain.joints(q);
        let segments: Vec<[[f64; 2]; 2]> = joints.windows(2).map(|w| [w[0], w[1]]).collect();
        let mut gap = f64::INFINITY;
        for (i, s) in segments.iter().enumerate() {
            let r = chain.links[i].radius + spare * eps[i];
            let seg = Segment::new(Vector::new(s[0][0], s[0][1]), Vector::new(s[1][0], s[1][1]));
            for w in walls {
                let d = parry2d::query::distance(&Pose::IDENTITY, &seg, &w.pose, w.shape.as_ref())
                    .unwrap();
                gap = gap.min(d.distance - r);
            }
            for p in s {
                gap = gap.min(p[0].min(p[1]).min(size - p[0]).min(size - p[1]) - r);
            }
            for (k, t) in segments.iter().enumerate().take(i.saturating_sub(1)) {
                let other = chain.links[k].radius + spare * eps[k];
                gap = gap.min(segment_distance(*s, *t) - r - other);
            }
        }
        gap
    }

    /// Sound: no configuration in a free cell touches anything (thousands of configurations,
    /// spread over their cells). Not needlessly conservative: every configuration whose links
    /// keep twice their margins from everything is in a free cell.
    #[test]
    fn free_cells_hold_no_touching_configuration_and_clear_ones_are_free() {
        let (chain, walls) = scene();
        let axes = [
            JointAxis {
                cells: 128,
                limits: None,
            },
            JointAxis {
                cells: 96,
                limits: Some([-2.6, 2.6]),
            },
            JointAxis {
                cells: 64,
                limits: None,
            },
        ];
        let mask = JointMask::build(&chain, &axes, &walls, ([0.0, 0.0], [4.0, 4.0]));
        let eps = &mask.margins;
        let (mut free, mut clear, mut state) = (0, 0, 0x2545_f491_4f6c_dd1du64);
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20_000 {
            let q: Vec<f64> = axes
                .iter()
                .map(|a| {
                    let [lo, hi] = a
                        .limits
                        .unwrap_or([-std::f64::consts::PI, std::f64::consts::PI]);
                    lo + (hi - lo) * next()
                })
                .collect();
            let cell = mask.cell_of(&q).unwrap();
            let gap = clearance((&chain, &walls), &q, 4.0, (eps, 0.0));
            if !mask.blocked[cell] {
                free += 1;
                assert!(
                    gap > -1e-5,
                    "{q:?} is in a free cell, {gap} m from touching"
                );
            }
            if clearance((&chain, &walls), &q, 4.0, (eps, 2.0)) > 1e-5 {
                clear += 1;
                assert!(!mask.blocked[cell], "{q:?} is {gap} m clear but blocked");
            }
        }
        assert!(free > 2000 && clear > 1000, "{free} free, {clear} clear");
    }

    #[test]
    fn segments_measure_their_distance() {
        let d = segment_distance([[0.0, 0.0], [1.0, 0.0]], [[0.5, 0.3], [0.5, 2.0]]);
        assert!((d - 0.3).abs() < 1e-12);
        assert_eq!(
            segment_distance([[0.0, 0.0], [1.0, 1.0]], [[0.0, 1.0], [1.0, 0.0]]),
            0.0
        );
        let d = segment_distance([[0.0, 0.0], [1.0, 0.0]], [[2.0, 1.0], [3.0, 1.0]]);
        assert!((d - 2f64.sqrt()).abs() < 1e-12);
    }
}
