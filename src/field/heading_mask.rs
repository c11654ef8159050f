//! The configuration-space mask of a shaped body in (x, y, θ): one slice of the plane's grid per
//! heading, θ periodic over `headings` equal intervals.
//!
//! A cell `(i, j, k)` is blocked when the body, its reference point at the cell's centre, at
//! *any* heading of the interval `[θ_k − Δθ/2, θ_k + Δθ/2]` (`θ_k = k Δθ`), overlaps a wall or
//! leaves the box. It is built per slice from Minkowski sums, not from per-cell distance
//! queries:
//!
//! - every wall is a convex core grown by a radius (a box: 4 vertices and 0; a thick segment: 2
//!   vertices and half its thickness; a disc: its centre and its radius; a convex polygon: its
//!   vertices and 0), and every part of the body a convex polygon in the body frame;
//! - the body's part `P` at heading θ overlaps the wall `W ⊕ disc(r)` exactly when its reference
//!   point lies within `r` of the convex polygon `W ⊕ (−R(θ) P)` (the hull of the pairwise
//!   differences of vertices: convex ⊕ convex is convex);
//! - a vertex at distance `ρ` from the reference point moves by at most `2ρ sin(δ/2)` when the
//!   body turns by δ, so over the half-interval `Δθ/2` the whole body stays within
//!   `ε = 2 ρ_max sin(Δθ/4)` of where it is at θ_k: growing every slice's obstacles by `ε` is
//!   conservative across the interval, and costs no more than `ε` of clearance (the test below
//!   holds the mask to both);
//! - each grown obstacle is rasterized like the plane's mask, over the cells of its bounding
//!   box, with the distance from the cell's centre to one convex polygon.

use super::Grid;
use super::bounds::Bounds;
use crate::world::WallShape;

/// Why a body's shape cannot be masked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShapeError {
    /// A part has fewer than three points.
    #[error("part {part}: {points} points, a convex part needs at least 3")]
    TooFewPoints {
        /// The part's index.
        part: usize,
        /// Its number of points.
        points: usize,
    },
    /// A part's points are not a convex polygon in counter-clockwise order.
    #[error(
        "part {part}: the points turn clockwise or inwards at point {point}: a part must be convex, counter-clockwise"
    )]
    NotConvex {
        /// The part's index.
        part: usize,
        /// The point where the boundary turns the wrong way.
        point: usize,
    },
    /// A part has no area.
    #[error("part {part}: zero area")]
    ZeroArea {
        /// The part's index.
        part: usize,
    },
    /// Too few headings to be meaningful (the interval would span a quarter turn or more).
    #[error("{0} headings: at least 8 are needed")]
    TooFewHeadings(usize),
}

/// The (x, y, θ) mask: `blocked[index(i, j, k)]`.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadingMask {
    /// The plane's grid (every slice).
    pub grid: Grid,
    /// Heading intervals over a full turn.
    pub headings: usize,
    /// How far every obstacle is grown to make a slice hold for its whole interval, m.
    pub margin: f64,
    /// Whether each cell is blocked, slice after slice (`k` slowest, then `j`, then `i`).
    pub blocked: Vec<bool>,
}

impl HeadingMask {
    /// The cell of `(i, j)` in slice `k`.
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        k * self.grid.len() + self.grid.index(i, j)
    }

    /// The heading at the middle of slice `k`, rad.
    pub fn heading(&self, k: usize) -> f64 {
        k as f64 * self.step()
    }

    /// The width of a slice's heading interval, rad.
    pub fn step(&self) -> f64 {
        std::f64::consts::TAU / self.headings as f64
    }

    /// The slice whose interval holds `theta` (any angle).
    pub fn slice_of(&self, theta: f64) -> usize {
        let turns = (theta / self.step() + 0.5).floor() as i64;
        turns.rem_euclid(self.headings as i64) as usize
    }

    /// Checks that every part is a convex, counter-clockwise polygon with area.
    pub fn check_parts(parts: &[Vec<[f64; 2]>]) -> Result<(), ShapeError> {
        for (part, points) in parts.iter().enumerate() {
            let n = points.len();
            if n < 3 {
                return Err(ShapeError::TooFewPoints { part, points: n });
            }
            let mut area = 0.0;
            for p in 0..n {
                let (a, b, c) = (points[p], points[(p + 1) % n], points[(p + 2) % n]);
                if cross(sub(b, a), sub(c, b)) < 0.0 {
                    return Err(ShapeError::NotConvex {
                        part,
                        point: (p + 1) % n,
                    });
                }
                area += cross(a, b);
            }
            if area.abs() < 1e-12 {
                return Err(ShapeError::ZeroArea { part });
            }
        }
        Ok(())
    }

    /// The mask of a body made of the convex `parts` (body frame, counter-clockwise, m) among
    /// `walls` in the box `[lo, hi]`, on `grid` with `headings` slices.
    ///
    /// ```
    /// use nadf::field::{Grid, HeadingMask};
    /// // A 1 m × 0.2 m board in an empty 3 m box: lying along x it fits nearer the box's top
    /// // than standing along y does.
    /// let grid = Grid::covering([3.0, 3.0], 0.05);
    /// let board = vec![vec![[-0.5, -0.1], [0.5, -0.1], [0.5, 0.1], [-0.5, 0.1]]];
    /// let mask = HeadingMask::build(&grid, 64, ([0.0, 0.0], [3.0, 3.0]), &[], &board).unwrap();
    /// let (i, j) = grid.cell_of([1.5, 2.7]).unwrap();
    /// assert!(!mask.blocked[mask.index(i, j, mask.slice_of(0.0))]);
    /// assert!(mask.blocked[mask.index(i, j, mask.slice_of(std::f64::consts::FRAC_PI_2))]);
    /// ```
    pub fn build(
        grid: &Grid,
        headings: usize,
        (lo, hi): ([f64; 2], [f64; 2]),
        walls: &[WallShape],
        parts: &[Vec<[f64; 2]>],
    ) -> Result<Self, ShapeError> {
        Self::check_parts(parts)?;
        if headings < 8 {
            return Err(ShapeError::TooFewHeadings(headings));
        }
        let step = std::f64::consts::TAU / headings as f64;
        let reach = (parts.iter().flatten())
            .map(|p| p[0].hypot(p[1]))
            .fold(0.0, f64::max);
        let margin = 2.0 * reach * (step / 4.0).sin();
        let cores: Vec<(Vec<[f64; 2]>, f64)> = walls.iter().map(core_of).collect();
        let mut blocked = vec![false; grid.len() * headings];
        for k in 0..headings {
            let slice = &mut blocked[k * grid.len()..(k + 1) * grid.len()];
            let (s, c) = (k as f64 * step).sin_cos();
            let turned: Vec<Vec<[f64; 2]>> = (parts.iter())
                .map(|part| {
                    (part.iter())
                        .map(|&[x, y]| [c * x - s * y, s * x + c * y])
                        .collect()
                })
                .collect();
            // The box: the body's extent along each axis at this heading, grown by the margin.
            let Bounds { lo: min, hi: max } = Bounds::of(turned.iter().flatten());
            for j in 0..grid.ny {
                for i in 0..grid.nx {
                    let [x, y] = grid.center(i, j);
                    if x + min[0] < lo[0] + margin
                        || y + min[1] < lo[1] + margin
                        || x + max[0] > hi[0] - margin
                        || y + max[1] > hi[1] - margin
                    {
                        slice[grid.index(i, j)] = true;
                    }
                }
            }
            for (core, radius) in &cores {
                let grow = radius + margin;
                for part in &turned {
                    let obstacle = minkowski_difference(core, part);
                    let Bounds { lo: lo_b, hi: hi_b } = Bounds::of(&obstacle).grown(grow);
                    let (ir, jr) = grid.cells_in(lo_b, hi_b);
                    for j in jr {
                        for i in ir.clone() {
                            let cell = grid.index(i, j);
                            if !slice[cell]
                                && distance_to_convex(&obstacle, grid.center(i, j)) <= grow
                            {
                                slice[cell] = true;
                            }
                        }
                    }
                }
            }
        }
        Ok(Self {
            grid: *grid,
            headings,
            margin,
            blocked,
        })
    }
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// A wall as a convex core (its vertices in the world, counter-clockwise where there are three
/// or more) grown by a radius, m.
fn core_of(wall: &WallShape) -> (Vec<[f64; 2]>, f64) {
    let world = |p: parry2d::math::Vector| {
        let q = wall.pose * p;
        [q.x, q.y]
    };
    let shape = wall.shape.as_ref();
    if let Some(c) = shape.as_cuboid() {
        let [hx, hy] = [c.half_extents.x, c.half_extents.y];
        let corners = [[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]];
        let points = corners.map(|[x, y]| world(parry2d::math::Vector::new(x, y)));
        return (points.to_vec(), 0.0);
    }
    if let Some(c) = shape.as_capsule() {
        let ends = [c.segment.a, c.segment.b].map(world);
        return (ends.to_vec(), c.radius);
    }
    if let Some(b) = shape.as_ball() {
        return (vec![world(parry2d::math::Vector::ZERO)], b.radius);
    }
    if let Some(p) = shape.as_convex_polygon() {
        return (p.points().iter().map(|&v| world(v)).collect(), 0.0);
    }
    // Every wall kind of the schema is one of the above; a shape of another kind is masked by
    // its bounding box (conservative).
    let aabb = shape.compute_aabb(&wall.pose);
    let (a, b) = (aabb.mins, aabb.maxs);
    let corners = [[a.x, a.y], [b.x, a.y], [b.x, b.y], [a.x, b.y]];
    (corners.to_vec(), 0.0)
}

/// The convex hull of `{w − p}` for the vertices `w` of `core` and `p` of `part`: the
/// reference points at which the part touches the core, counter-clockwise.
fn minkowski_difference(core: &[[f64; 2]], part: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let mut points: Vec<[f64; 2]> = (core.iter())
        .flat_map(|w| part.iter().map(move |p| sub(*w, *p)))
        .collect();
    convex_hull(&mut points)
}

/// The convex hull of `points`, counter-clockwise (Andrew's monotone chain).
fn convex_hull(points: &mut [[f64; 2]]) -> Vec<[f64; 2]> {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    if points.len() < 3 {
        return points.to_vec();
    }
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in ordered {
            while hull.len() >= start + 2 {
                let (a, b) = (hull[hull.len() - 2], hull[hull.len() - 1]);
                if cross(sub(b, a), sub(p, b)) <= 0.0 {
                    hull.pop();
                } else {
                    break;
                }
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The distance from `q` to the convex polygon `hull` (counter-clockwise), 0 inside; a hull of
/// one or two points is a point or a segment.
fn distance_to_convex(hull: &[[f64; 2]], q: [f64; 2]) -> f64 {
    let n = hull.len();
    let to_segment = |a: [f64; 2], b: [f64; 2]| {
        let (ab, aq) = (sub(b, a), sub(q, a));
        let len2 = ab[0] * ab[0] + ab[1] * ab[1];
        let t = if len2 > 0.0 {
            ((aq[0] * ab[0] + aq[1] * ab[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (aq[0] - t * ab[0]).hypot(aq[1] - t * ab[1])
    };
    match n {
        0 => f64::INFINITY,
        1 => to_segment(hull[0], hull[0]),
        2 => to_segment(hull[0], hull[1]),
        _ => {
            let inside =
                (0..n).all(|e| cross(sub(hull[(e + 1) % n], hull[e]), sub(q, hull[e])) >= 0.0);
            if inside {
                return 0.0;
            }
            (0..n)
                .map(|e| to_segment(hull[e], hull[(e + 1) % n]))
                .fold(f64::INFINITY, f64::min)
        }
    }
}

#[cfg(test)]
mod tests {
    use parry2d::math::{Pose, Vector};
    use parry2d::shape::ConvexPolygon;

    use super::*;
    use crate::world::{Wall, wall_shape};

    /// An L-shaped body of two convex parts and a box, a segment, a disc and a polygon.
    fn scene() -> (Grid, Vec<WallShape>, Vec<Vec<[f64; 2]>>) {
        let grid = Grid::covering([4.0, 4.0], 0.05);
        let walls = [
            Wall::Box {
                center: [1.0, 1.0],
                half_extents: [0.4, 0.2],
                angle: 0.3,
            },
            Wall::Segment {
                a: [2.5, 0.5],
                b: [3.2, 1.6],
                thickness: 0.1,
            },
            Wall::Disc {
                center: [1.2, 3.0],
                radius: 0.35,
            },
            Wall::Polygon {
                points: vec![[2.6, 2.6], [3.4, 2.8], [3.0, 3.4]],
            },
        ]
        .iter()
        .map(|w| wall_shape(w).unwrap())
        .collect();
        let l = vec![
            vec![[-0.3, -0.1], [0.3, -0.1], [0.3, 0.1], [-0.3, 0.1]],
            vec![[0.1, 0.1], [0.3, 0.1], [0.3, 0.4], [0.1, 0.4]],
        ];
        (grid, walls, l)
    }

    /// The clearance of the body at `(x, y, θ)`, judged by parry: its smallest distance to a
    /// wall or to the edge of the `size`-metre box (negative where a vertex is outside the box;
    /// 0 where it touches or overlaps a wall), m.
    fn clearance(walls: &[WallShape], parts: &[Vec<[f64; 2]>], pose: [f64; 3], size: f64) -> f64 {
        let [x, y, theta] = pose;
        let at = Pose::new(Vector::new(x, y), theta);
        let mut gap = f64::INFINITY;
        for part in parts {
            let polygon = ConvexPolygon::from_convex_polyline(
                part.iter().map(|&[a, b]| Vector::new(a, b)).collect(),
            )
            .unwrap();
            for wall in walls {
                let d = parry2d::query::distance(&at, &polygon, &wall.pose, wall.shape.as_ref())
                    .unwrap();
                gap = gap.min(d.distance);
            }
            let (s, c) = theta.sin_cos();
            for &[a, b] in part {
                let (px, py) = (x + c * a - s * b, y + s * a + c * b);
                gap = gap.min(px).min(py).min(size - px).min(size - py);
            }
        }
        gap
    }

    #[test]
    fn no_pose_in_a_free_cell_touches_a_wall_and_clear_poses_are_free() {
        let (grid, walls, parts) = scene();
        let mask = HeadingMask::build(&grid, 64, ([0.0, 0.0], [4.0, 4.0]), &walls, &parts).unwrap();
        let (mut free, mut clear) = (0, 0);
        // Every third cell of every third slice (about 25 000 poses), each at a heading spread
        // over its interval.
        let cells = (0..mask.headings).step_by(3).flat_map(|k| {
            (0..grid.ny)
                .step_by(3)
                .flat_map(move |j| (0..grid.nx).step_by(3).map(move |i| (i, j, k)))
        });
        for (n, (i, j, k)) in cells.enumerate() {
            let [x, y] = grid.center(i, j);
            let blocked = mask.blocked[mask.index(i, j, k)];
            // Sound: any heading of a free cell's interval keeps the body off every wall
            // (parry's f32 geometry: 1e-5 m).
            if !blocked {
                free += 1;
                let spread = (n % 7) as f64 / 6.0 - 0.5;
                let theta = mask.heading(k) + mask.step() * spread;
                let gap = clearance(&walls, &parts, [x, y, theta], 4.0);
                assert!(
                    gap > -1e-5,
                    "cell {i},{j},{k} free, the body at θ = {theta} is {gap} m in"
                );
            }
            // Not needlessly conservative: a pose at the slice's heading clearer than the
            // margin (and the f32 slack) is free.
            let gap = clearance(&walls, &parts, [x, y, mask.heading(k)], 4.0);
            if gap > mask.margin + 1e-5 {
                clear += 1;
                assert!(
                    !blocked,
                    "cell {i},{j},{k} blocked with {gap} m of clearance"
                );
            }
        }
        // Both checks saw many cells.
        assert!(free > 5000 && clear > 5000, "{free} free, {clear} clear");
        // The margin of 64 headings for a 0.5 m reach: 2·0.5·sin(π/128) = 2.5 cm.
        assert!((mask.margin - 0.0245).abs() < 1e-3, "{}", mask.margin);
    }

    #[test]
    fn a_board_fits_a_gap_only_turned_along_it() {
        // A 0.3 m gap between two walls, a 1 m × 0.2 m board: through it lying along the gap's
        // axis, never across.
        let grid = Grid::covering([3.0, 3.0], 0.02);
        let walls: Vec<WallShape> = [[0.75, 1.5], [2.25, 1.5]]
            .iter()
            .map(|&c| {
                wall_shape(&Wall::Box {
                    center: c,
                    half_extents: [0.6, 0.1],
                    angle: 0.0,
                })
                .unwrap()
            })
            .collect();
        let board = vec![vec![[-0.5, -0.1], [0.5, -0.1], [0.5, 0.1], [-0.5, 0.1]]];
        let mask = HeadingMask::build(&grid, 64, ([0.0, 0.0], [3.0, 3.0]), &walls, &board).unwrap();
        let (i, j) = grid.cell_of([1.5, 1.5]).unwrap();
        let up = mask.slice_of(std::f64::consts::FRAC_PI_2);
        assert!(!mask.blocked[mask.index(i, j, up)]);
        assert!(mask.blocked[mask.index(i, j, mask.slice_of(0.0))]);
        assert!(mask.blocked[mask.index(i, j, mask.slice_of(std::f64::consts::FRAC_PI_4))]);
    }

    #[test]
    fn a_cell_inside_an_obstacle_is_blocked_even_without_growth() {
        // A body of 10 µm: the margin all but vanishes with the reach, and the wall's own cells
        // must still be blocked (a point inside an obstacle is at distance 0 from it).
        let grid = Grid::covering([2.0, 2.0], 0.1);
        let wall = wall_shape(&Wall::Box {
            center: [1.0, 1.0],
            half_extents: [0.3, 0.3],
            angle: 0.0,
        })
        .unwrap();
        let speck = vec![vec![[0.0, 0.0], [1e-5, 0.0], [1e-5, 1e-5], [0.0, 1e-5]]];
        let mask = HeadingMask::build(&grid, 8, ([0.0, 0.0], [2.0, 2.0]), &[wall], &speck).unwrap();
        assert!(mask.margin < 1e-5, "{}", mask.margin);
        let (i, j) = grid.cell_of([1.0, 1.0]).unwrap();
        assert!((0..8).all(|k| mask.blocked[mask.index(i, j, k)]));
        let (i, j) = grid.cell_of([1.5, 1.5]).unwrap();
        assert!((0..8).all(|k| !mask.blocked[mask.index(i, j, k)]));
    }

    #[test]
    fn bad_parts_are_named() {
        let err = |parts: Vec<Vec<[f64; 2]>>| HeadingMask::check_parts(&parts).unwrap_err();
        assert_eq!(
            err(vec![vec![[0.0, 0.0], [1.0, 0.0]]]),
            ShapeError::TooFewPoints { part: 0, points: 2 }
        );
        // Clockwise.
        assert!(matches!(
            err(vec![vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]]]),
            ShapeError::NotConvex { part: 0, .. }
        ));
        // An arrow's notch.
        assert!(matches!(
            err(vec![vec![
                [0.0, 0.0],
                [1.0, 0.0],
                [0.5, 0.2],
                [1.0, 1.0],
                [0.0, 1.0]
            ]]),
            ShapeError::NotConvex { part: 0, point: 2 }
        ));
        assert_eq!(
            err(vec![vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]]),
            ShapeError::ZeroArea { part: 0 }
        );
        let grid = Grid::covering([1.0, 1.0], 0.1);
        let square = vec![vec![[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]];
        assert_eq!(
            HeadingMask::build(&grid, 4, ([0.0, 0.0], [1.0, 1.0]), &[], &square).unwrap_err(),
            ShapeError::TooFewHeadings(4)
        );
    }

    #[test]
    fn the_hull_and_the_distance_agree_with_a_square() {
        let mut points = vec![[0.0, 0.0], [1.0, 0.0], [0.5, 0.5], [1.0, 1.0], [0.0, 1.0]];
        let hull = convex_hull(&mut points);
        assert_eq!(hull.len(), 4, "{hull:?}");
        assert_eq!(distance_to_convex(&hull, [0.5, 0.5]), 0.0);
        assert!((distance_to_convex(&hull, [2.0, 0.5]) - 1.0).abs() < 1e-12);
        assert!((distance_to_convex(&hull, [2.0, 2.0]) - 2f64.sqrt()).abs() < 1e-12);
    }
}
