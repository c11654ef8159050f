//! The walls as parry shapes: the one place where a world file's geometry becomes collider
//! geometry. The simulation inserts these shapes into Rapier, the field rasterizes them and the
//! metrics measure clearance against them, so all three see exactly the same walls.

use parry2d::math::{Pose, Vector};
use parry2d::shape::SharedShape;

use super::schema::{OUTER_WALL_THICKNESS, Wall, World};

/// A wall ready for Rapier and parry: its pose and its shape.
#[derive(Clone)]
pub struct WallShape {
    /// Where the shape sits in the world.
    pub pose: Pose,
    /// The shape in its local frame.
    pub shape: SharedShape,
    /// Its bounding box in the world, `[x0, y0, x1, y1]`, m: a cheap lower bound of the
    /// distance to it (a map has thousands of walls, and the clearance is measured every step).
    bounds: [f64; 4],
}

impl WallShape {
    /// The wall of `shape` at `pose`.
    pub fn new(pose: Pose, shape: SharedShape) -> Self {
        let aabb = shape.compute_aabb(&pose);
        let bounds = [aabb.mins.x, aabb.mins.y, aabb.maxs.x, aabb.maxs.y];
        Self {
            pose,
            shape,
            bounds,
        }
    }

    /// Its bounding box, `[x0, y0, x1, y1]`, m.
    pub fn bounds(&self) -> [f64; 4] {
        self.bounds
    }

    /// A lower bound of the distance from `(x, y)` to the wall (from its bounding box), m.
    pub fn distance_bound(&self, x: f64, y: f64) -> f64 {
        let [x0, y0, x1, y1] = self.bounds;
        let dx = (x0 - x).max(x - x1).max(0.0);
        let dy = (y0 - y).max(y - y1).max(0.0);
        // Less a margin for the f32 rounding of the box and of parry's distance.
        dx.hypot(dy) - 1e-4
    }

    /// Distance from a point to the wall, m (0 inside it).
    pub fn distance_to_point(&self, x: f64, y: f64) -> f64 {
        self.shape
            .distance_to_point(&self.pose, Vector::new(x, y), true)
    }

    /// Signed distance from `(x, y)` to the wall's boundary, m: positive outside, negative
    /// inside by the depth.
    pub fn signed_distance_to_point(&self, x: f64, y: f64) -> f64 {
        self.signed_distance_and_direction(x, y).0
    }

    /// The signed distance of [`signed_distance_to_point`](Self::signed_distance_to_point) and
    /// the unit direction in which it grows fastest (away from the boundary outside, towards it
    /// inside; zero on the boundary itself).
    pub fn signed_distance_and_direction(&self, x: f64, y: f64) -> (f64, [f64; 2]) {
        let p = Vector::new(x, y);
        let projection = self.shape.project_point(&self.pose, p, false);
        let away = [p.x - projection.point.x, p.y - projection.point.y];
        let d = away[0].hypot(away[1]);
        let sign = if projection.is_inside { -1.0 } else { 1.0 };
        let direction = if d > 0.0 {
            [sign * away[0] / d, sign * away[1] / d]
        } else {
            [0.0, 0.0]
        };
        (sign * d, direction)
    }
}

/// Converts one wall entry into a shape; `None` when parry cannot build it (a degenerate polygon).
pub fn wall_shape(wall: &Wall) -> Option<WallShape> {
    let v = |p: [f64; 2]| Vector::new(p[0], p[1]);
    Some(match wall {
        Wall::Box {
            center,
            half_extents,
            angle,
        } => WallShape::new(
            Pose::new(v(*center), *angle),
            SharedShape::cuboid(half_extents[0], half_extents[1]),
        ),
        Wall::Segment { a, b, thickness } => WallShape::new(
            Pose::IDENTITY,
            SharedShape::capsule(v(*a), v(*b), *thickness / 2.0),
        ),
        Wall::Disc { center, radius } => WallShape::new(
            Pose::from_translation(v(*center)),
            SharedShape::ball(*radius),
        ),
        Wall::Polygon { points } => WallShape::new(
            Pose::IDENTITY,
            SharedShape::convex_polyline(points.iter().map(|p| v(*p)).collect())?,
        ),
    })
}

/// The four walls `walls_around = true` adds: boxes of [`OUTER_WALL_THICKNESS`] just inside
/// the box `origin + [0, W] × [0, H]`.
pub fn outer_walls(origin: [f64; 2], size: [f64; 2]) -> Vec<Wall> {
    let [w, h] = size;
    let t = OUTER_WALL_THICKNESS / 2.0;
    let wall = |cx: f64, cy: f64, hx: f64, hy: f64| Wall::Box {
        center: [origin[0] + cx, origin[1] + cy],
        half_extents: [hx, hy],
        angle: 0.0,
    };
    vec![
        wall(w / 2.0, t, w / 2.0, t),
        wall(w / 2.0, h - t, w / 2.0, t),
        wall(t, h / 2.0, t, h / 2.0),
        wall(w - t, h / 2.0, t, h / 2.0),
    ]
}

/// Every wall of the world, the outer ones first, as shapes. Walls that parry cannot build are
/// skipped here; validation reports them before a world ever reaches this point.
pub fn all_wall_shapes(world: &World) -> Vec<WallShape> {
    all_walls(world).iter().filter_map(wall_shape).collect()
}

/// Every wall of the world: the outer ones (if any), the map's, the file's.
pub fn all_walls(world: &World) -> Vec<Wall> {
    named_walls(world).map(|(_, wall)| wall).collect()
}

/// The walls drawn one by one: the outer ones and the file's (a map's are drawn as an image).
pub fn drawn_walls(world: &World) -> Vec<Wall> {
    let mut walls = if world.walls_around {
        outer_walls(world.origin, world.size)
    } else {
        Vec::new()
    };
    walls.extend(world.walls.iter().cloned());
    walls
}

/// Every wall of the world in the order of [`all_walls`], with the name a message gives it:
/// `the outer wall`, `the map` (a blocked cell of its `[map]`), or `walls.N` for the world
/// file's `[[walls]]` entry N.
pub fn named_walls(world: &World) -> impl Iterator<Item = (String, Wall)> + '_ {
    let outer = if world.walls_around {
        outer_walls(world.origin, world.size)
    } else {
        Vec::new()
    };
    let map = world
        .loaded_map
        .iter()
        .flat_map(|m| m.walls.iter().cloned());
    outer
        .into_iter()
        .map(|w| ("the outer wall".to_string(), w))
        .chain(map.map(|w| ("the map".to_string(), w)))
        .chain(
            world
                .walls
                .iter()
                .enumerate()
                .map(|(i, w)| (format!("walls.{i}"), w.clone())),
        )
}

/// The closed outline of a box of half-extents `half` centred on `center`, turned by `angle`
/// (rad), m: its four corners and the first again.
pub fn outline_box(center: [f64; 2], half: [f64; 2], angle: f64) -> Vec<[f64; 2]> {
    let (s, c) = angle.sin_cos();
    [
        [-1.0, -1.0],
        [1.0, -1.0],
        [1.0, 1.0],
        [-1.0, 1.0],
        [-1.0, -1.0],
    ]
    .iter()
    .map(|[sx, sy]| {
        let (x, y) = (sx * half[0], sy * half[1]);
        [center[0] + c * x - s * y, center[1] + s * x + c * y]
    })
    .collect()
}

/// The closed outline of a wall (its first point again at the end), m: what the recording and
/// the reproduction's figures draw. A disc is 16 chords, each round end of a segment 16 too.
pub fn wall_outline(wall: &Wall) -> Vec<[f64; 2]> {
    const ARC: usize = 16;
    let arc = |center: [f64; 2], r: f64, from: f64, to: f64| -> Vec<[f64; 2]> {
        (0..=ARC)
            .map(|k| {
                let a = from + (to - from) * k as f64 / ARC as f64;
                [center[0] + r * a.cos(), center[1] + r * a.sin()]
            })
            .collect()
    };
    match wall {
        Wall::Box {
            center,
            half_extents,
            angle,
        } => outline_box(*center, *half_extents, *angle),
        Wall::Disc { center, radius } => arc(*center, *radius, 0.0, std::f64::consts::TAU),
        Wall::Segment { a, b, thickness } => {
            let r = thickness / 2.0;
            let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
            let half_turn = std::f64::consts::FRAC_PI_2;
            let mut points = arc(*b, r, heading - half_turn, heading + half_turn);
            points.extend(arc(*a, r, heading + half_turn, heading + 3.0 * half_turn));
            points.push(points[0]);
            points
        }
        Wall::Polygon { points } => {
            let mut out = points.clone();
            out.push(out[0]);
            out
        }
    }
}
