//! The map an agent builds online from its lidar ([`KnownMap`]): an occupancy grid on its
//! field's grid, updated with the standard log-odds rule (Thrun, Burgard and Fox, *Probabilistic
//! Robotics*, §9.2). The free segment of each ray lowers the log-odds of the cells it crosses, its
//! end raises the log-odds of the cell it hits. Cells never seen stay at zero and count as free
//! for planning: the optimistic assumption of online harmonic planning, under which the field is
//! re-solved as walls come into view and a target that the seen walls enclose is found
//! intractable.

use super::grid::Grid;

/// Log-odds added to a cell a ray ends in (p = 0.7).
const HIT: f32 = 0.85;
/// Log-odds added to a cell a ray crosses (p = 0.4).
const MISS: f32 = -0.4;
/// The log-odds are kept in `[-BOUND, BOUND]`, so that a cell can change its mind.
const BOUND: f32 = 4.0;

/// One ray of a scan: where it starts and, if it hit something, where.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// The sensor's position, m.
    pub from: [f64; 2],
    /// The end of the ray, m: the hit, or the end of the range.
    pub to: [f64; 2],
    /// Whether it hit something at `to` (else it saw free space up to its range).
    pub hit: bool,
}

/// An occupancy grid built online.
#[derive(Debug, Clone)]
pub struct KnownMap {
    grid: Grid,
    log_odds: Vec<f32>,
    seen: Vec<bool>,
    occupied: Vec<bool>,
}

impl KnownMap {
    /// A map of `grid` with nothing seen yet.
    pub fn new(grid: Grid) -> Self {
        Self {
            grid,
            log_odds: vec![0.0; grid.len()],
            seen: vec![false; grid.len()],
            occupied: vec![false; grid.len()],
        }
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// Whether cell `k` is believed occupied (log-odds above zero).
    pub fn occupied(&self) -> &[bool] {
        &self.occupied
    }

    /// Whether cell `k` has been crossed or hit by a ray.
    pub fn seen(&self) -> &[bool] {
        &self.seen
    }

    /// The fraction of the grid's cells seen.
    pub fn seen_fraction(&self) -> f64 {
        self.seen.iter().filter(|s| **s).count() as f64 / self.seen.len().max(1) as f64
    }

    /// Adds a scan; returns whether a cell changed between free and occupied.
    ///
    /// ```
    /// use nadf::field::{Beam, Grid, KnownMap};
    /// let mut map = KnownMap::new(Grid::covering([4.0, 1.0], 0.1));
    /// let changed = map.update(&[Beam { from: [0.05, 0.55], to: [3.05, 0.55], hit: true }]);
    /// let grid = *map.grid();
    /// let (hit, crossed) = (grid.cell_of([3.05, 0.55]).unwrap(), grid.cell_of([1.0, 0.55]).unwrap());
    /// assert!(changed && map.occupied()[grid.index(hit.0, hit.1)]);
    /// assert!(map.seen()[grid.index(crossed.0, crossed.1)] && !map.occupied()[grid.index(crossed.0, crossed.1)]);
    /// ```
    pub fn update(&mut self, beams: &[Beam]) -> bool {
        let mut touched = Vec::new();
        for beam in beams {
            let end = self
                .grid
                .cell_of(beam.to)
                .map(|(i, j)| self.grid.index(i, j));
            let (dx, dy) = (beam.to[0] - beam.from[0], beam.to[1] - beam.from[1]);
            let length = dx.hypot(dy);
            // Half-cell steps visit every cell the segment crosses but at worst a corner.
            let steps = (2.0 * length / self.grid.cell).ceil() as usize;
            let mut last = None;
            for s in 0..=steps {
                let t = s as f64 / steps.max(1) as f64;
                let p = [beam.from[0] + t * dx, beam.from[1] + t * dy];
                let Some((i, j)) = self.grid.cell_of(p) else {
                    break;
                };
                let k = self.grid.index(i, j);
                if Some(k) == last || (beam.hit && Some(k) == end) {
                    continue;
                }
                last = Some(k);
                self.add(k, MISS);
                touched.push(k);
            }
            if beam.hit
                && let Some(k) = end
            {
                self.add(k, HIT);
                touched.push(k);
            }
        }
        let mut changed = false;
        for k in touched {
            let now = self.log_odds[k] > 0.0;
            changed |= now != self.occupied[k];
            self.occupied[k] = now;
        }
        changed
    }

    fn add(&mut self, k: usize, delta: f32) {
        self.log_odds[k] = (self.log_odds[k] + delta).clamp(-BOUND, BOUND);
        self.seen[k] = true;
    }
}
