//! The clearance of a disc to the walls, measured after every step: the signed distance to the
//! nearest wall less the radius. A map has tens of thousands of walls (a 512 × 512 maze:
//! 38,223 boxes), so [`WallIndex`] buckets them (`buckets.rs`) and searches outwards from the
//! disc. The distances are the same parry queries as a scan of every wall, so the result is the
//! same to the bit.

use nalgebra::Vector2;

use crate::buckets::Buckets;
use crate::world::WallShape;

/// Below this many walls a plain scan is as fast as the index.
const SCAN: usize = 64;

/// Signed distance from a disc of `radius` at `position` to the nearest of `walls`, m: positive
/// when clear, negative by the overlap depth when the disc is inside a wall. Scans every wall
/// (a box test each, a distance query only for the walls whose box is nearer than the nearest
/// so far).
pub fn signed_clearance(walls: &[WallShape], position: Vector2<f64>, radius: f64) -> f64 {
    nearest_wall(walls, position, radius).0
}

/// [`signed_clearance`] and the index of the wall that gives it (`None` without walls).
fn nearest_wall(walls: &[WallShape], position: Vector2<f64>, radius: f64) -> (f64, Option<usize>) {
    let (x, y) = (position.x, position.y);
    let (mut nearest, mut which) = (f64::INFINITY, None);
    for (k, w) in walls.iter().enumerate() {
        let d = nearer(w, x, y, nearest);
        if d < nearest {
            (nearest, which) = (d, Some(k));
        }
    }
    (nearest - radius, which)
}

/// The smaller of `nearest` and the signed distance from `(x, y)` to `w`, measuring the latter
/// only when `w`'s bounding box could be nearer. (Inside a box the wall may hold the point
/// deeper than any other: always measured.)
fn nearer(w: &WallShape, x: f64, y: f64, nearest: f64) -> f64 {
    let bound = w.distance_bound(x, y);
    if bound < nearest || bound <= 0.0 {
        nearest.min(w.signed_distance_to_point(x, y))
    } else {
        nearest
    }
}

/// The walls by bucket of a coarse grid over their bounding boxes (none for a few walls).
#[derive(Debug, Clone)]
pub struct WallIndex(Option<Buckets>);

impl WallIndex {
    /// The index of `walls`; empty (a plain scan) for a few walls.
    pub fn new(walls: &[WallShape]) -> Self {
        if walls.len() < SCAN {
            return Self(None);
        }
        let boxes: Vec<[f64; 4]> = walls.iter().map(WallShape::bounds).collect();
        let (w, h) = (
            boxes.iter().map(|b| b[2]).fold(f64::NEG_INFINITY, f64::max)
                - boxes.iter().map(|b| b[0]).fold(f64::INFINITY, f64::min),
            boxes.iter().map(|b| b[3]).fold(f64::NEG_INFINITY, f64::max)
                - boxes.iter().map(|b| b[1]).fold(f64::INFINITY, f64::min),
        );
        // About four walls a bucket.
        let size = (4.0 * w * h / walls.len() as f64).sqrt();
        Self(Buckets::new(&boxes, size))
    }

    /// [`signed_clearance`] of `walls` (those the index was built from), searching the buckets
    /// ring by ring outwards from the disc.
    pub fn signed_clearance(
        &self,
        walls: &[WallShape],
        position: Vector2<f64>,
        radius: f64,
    ) -> f64 {
        self.nearest_wall(walls, position, radius).0
    }

    /// [`WallIndex::signed_clearance`] and the index of the wall that gives it (`None`
    /// without walls).
    pub fn nearest_wall(
        &self,
        walls: &[WallShape],
        position: Vector2<f64>,
        radius: f64,
    ) -> (f64, Option<usize>) {
        let Some(buckets) = &self.0 else {
            return nearest_wall(walls, position, radius);
        };
        let (x, y) = (position.x, position.y);
        let mut which = None;
        let nearest = buckets.nearest([x, y], |k, best| {
            let d = nearer(&walls[k], x, y, best);
            if d < best {
                which = Some(k);
            }
            d
        });
        (nearest - radius, which)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Wall, wall_shape};

    /// Hundreds of small boxes: the index gives exactly the scan's clearance everywhere,
    /// inside walls and outside the grid included.
    #[test]
    fn the_index_agrees_with_a_scan_to_the_bit() {
        let walls: Vec<WallShape> = (0..400)
            .map(|k| {
                let (i, j) = ((k % 20) as f64, (k / 20) as f64);
                wall_shape(&Wall::Box {
                    center: [i * 1.7 + 0.3 * (j % 3.0), j * 1.3],
                    half_extents: [0.2 + 0.05 * (i % 4.0), 0.15],
                    angle: 0.1 * (k % 7) as f64,
                })
                .unwrap()
            })
            .collect();
        let index = WallIndex::new(&walls);
        assert!(index.0.is_some());
        for k in 0..5000 {
            let p = Vector2::new(
                -3.0 + (k % 100) as f64 * 0.4 + 0.013 * (k % 7) as f64,
                -3.0 + (k / 100) as f64 * 0.55,
            );
            let scan = signed_clearance(&walls, p, 0.2);
            let fast = index.signed_clearance(&walls, p, 0.2);
            assert_eq!(scan.to_bits(), fast.to_bits(), "at {p}: {scan} vs {fast}");
        }
    }
}
