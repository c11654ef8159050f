//! The clearance of a disc to the walls, measured after every step: the signed distance to the
//! nearest wall less the radius. A map has tens of thousands of walls (a 512 × 512 maze:
//! 38,223 boxes), so [`WallIndex`] buckets them on a coarse grid and searches outwards from
//! the disc, ring by ring, until no farther bucket can hold a nearer wall. The distances are
//! the same parry queries as a scan of every wall, so the result is the same to the bit.

use nalgebra::Vector2;

use crate::world::WallShape;

/// Below this many walls a plain scan is as fast as the index.
const SCAN: usize = 64;

/// Signed distance from a disc of `radius` at `position` to the nearest of `walls`, m: positive
/// when clear, negative by the overlap depth when the disc is inside a wall. Scans every wall
/// (a box test each, a distance query only for the walls whose box is nearer than the nearest
/// so far).
pub fn signed_clearance(walls: &[WallShape], position: Vector2<f64>, radius: f64) -> f64 {
    let (x, y) = (position.x, position.y);
    let mut nearest = f64::INFINITY;
    for w in walls {
        nearest = nearer(w, x, y, nearest);
    }
    nearest - radius
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

/// The walls' indices by bucket of a coarse grid over their bounding boxes.
#[derive(Debug, Clone)]
pub struct WallIndex {
    /// Lower-left corner of bucket (0, 0), m.
    origin: [f64; 2],
    /// Bucket size, m.
    size: f64,
    nx: usize,
    ny: usize,
    /// Per bucket, the walls whose bounding box overlaps it.
    buckets: Vec<Vec<u32>>,
}

impl WallIndex {
    /// The index of `walls`; empty (a plain scan) for a few walls.
    pub fn new(walls: &[WallShape]) -> Self {
        let empty = Self {
            origin: [0.0; 2],
            size: 1.0,
            nx: 0,
            ny: 0,
            buckets: Vec::new(),
        };
        if walls.len() < SCAN {
            return empty;
        }
        let bounds: Vec<[f64; 4]> = walls.iter().map(WallShape::bounds).collect();
        let lo = [
            bounds.iter().map(|b| b[0]).fold(f64::INFINITY, f64::min),
            bounds.iter().map(|b| b[1]).fold(f64::INFINITY, f64::min),
        ];
        let hi = [
            bounds
                .iter()
                .map(|b| b[2])
                .fold(f64::NEG_INFINITY, f64::max),
            bounds
                .iter()
                .map(|b| b[3])
                .fold(f64::NEG_INFINITY, f64::max),
        ];
        let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
        if !(area.is_finite() && area > 0.0) {
            return empty;
        }
        // About four walls a bucket.
        let size = (4.0 * area / walls.len() as f64).sqrt();
        let nx = ((hi[0] - lo[0]) / size).ceil().max(1.0) as usize;
        let ny = ((hi[1] - lo[1]) / size).ceil().max(1.0) as usize;
        let mut index = Self {
            origin: lo,
            size,
            nx,
            ny,
            buckets: vec![Vec::new(); nx * ny],
        };
        for (k, b) in bounds.iter().enumerate() {
            let (i0, j0) = index.bucket_of(b[0], b[1]);
            let (i1, j1) = index.bucket_of(b[2], b[3]);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    index.buckets[j * nx + i].push(k as u32);
                }
            }
        }
        index
    }

    /// The bucket holding `(x, y)`, clamped to the grid.
    fn bucket_of(&self, x: f64, y: f64) -> (usize, usize) {
        let f =
            |v: f64, o: f64, n: usize| (((v - o) / self.size).floor().max(0.0) as usize).min(n - 1);
        (f(x, self.origin[0], self.nx), f(y, self.origin[1], self.ny))
    }

    /// [`signed_clearance`] of `walls` (those the index was built from), searching the buckets
    /// ring by ring outwards from the disc.
    pub fn signed_clearance(
        &self,
        walls: &[WallShape],
        position: Vector2<f64>,
        radius: f64,
    ) -> f64 {
        let (x, y) = (position.x, position.y);
        let inside = x >= self.origin[0]
            && y >= self.origin[1]
            && x < self.origin[0] + self.nx as f64 * self.size
            && y < self.origin[1] + self.ny as f64 * self.size;
        if self.buckets.is_empty() || !inside {
            return signed_clearance(walls, position, radius);
        }
        let (ci, cj) = self.bucket_of(x, y);
        let mut nearest = f64::INFINITY;
        for ring in 0..self.nx.max(self.ny) {
            // Every bucket of this ring; a wall in several buckets is measured more than once,
            // which does not change the minimum.
            let (i0, i1) = (ci.saturating_sub(ring), (ci + ring).min(self.nx - 1));
            let (j0, j1) = (cj.saturating_sub(ring), (cj + ring).min(self.ny - 1));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    if i.abs_diff(ci) != ring && j.abs_diff(cj) != ring {
                        continue;
                    }
                    for &k in &self.buckets[j * self.nx + i] {
                        nearest = nearer(&walls[k as usize], x, y, nearest);
                    }
                }
            }
            // Buckets beyond this ring are at least `ring` buckets away from the point (less a
            // margin for the f32 rounding of the walls' boxes).
            if nearest <= ring as f64 * self.size - 1e-3 {
                break;
            }
        }
        nearest - radius
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
        assert!(!index.buckets.is_empty());
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
