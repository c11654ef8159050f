//! A map's cells ([`Occupancy`]), y-up: what the readers produce and the world keeps.

use std::path::PathBuf;

/// What a map says of one cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellState {
    /// Passable.
    Free,
    /// Occupied: a wall.
    Blocked,
    /// Not known (ROS maps): blocked or free as the world's `[map] unknown` says.
    Unknown,
}

/// A map read from its file, y-up.
#[derive(Debug, Clone, PartialEq)]
pub struct Occupancy {
    /// The file it was read from.
    pub file: PathBuf,
    /// Cells along x.
    pub width: usize,
    /// Cells along y.
    pub height: usize,
    /// Cell size, m.
    pub cell: f64,
    /// The lower-left corner of cell (0, 0), m.
    pub origin: [f64; 2],
    /// The cells, row by row from the bottom: `cells[j * width + i]`.
    pub cells: Vec<CellState>,
    /// Whether unknown cells are walls.
    pub unknown_blocked: bool,
}

impl Occupancy {
    /// The map's width and height, m.
    pub fn extent(&self) -> [f64; 2] {
        [
            self.width as f64 * self.cell,
            self.height as f64 * self.cell,
        ]
    }

    /// Whether cell `(i, j)` is a wall (unknown cells as the settings say).
    pub fn blocked(&self, i: usize, j: usize) -> bool {
        match self.cells[j * self.width + i] {
            CellState::Blocked => true,
            CellState::Unknown => self.unknown_blocked,
            CellState::Free => false,
        }
    }

    /// The centre of cell `(i, j)`, m.
    pub fn center(&self, i: usize, j: usize) -> [f64; 2] {
        [
            self.origin[0] + (i as f64 + 0.5) * self.cell,
            self.origin[1] + (j as f64 + 0.5) * self.cell,
        ]
    }

    /// The cell containing `p`, if it is on the map.
    pub fn cell_of(&self, p: [f64; 2]) -> Option<(usize, usize)> {
        let fx = (p[0] - self.origin[0]) / self.cell;
        let fy = (p[1] - self.origin[1]) / self.cell;
        (fx >= 0.0 && fy >= 0.0 && (fx as usize) < self.width && (fy as usize) < self.height)
            .then_some((fx as usize, fy as usize))
    }

    /// The runs `[i0, i1)` of blocked cells in row `j`.
    pub fn runs(&self, j: usize) -> Vec<(usize, usize)> {
        let mut runs = Vec::new();
        let mut start = None;
        for i in 0..=self.width {
            let blocked = i < self.width && self.blocked(i, j);
            match (blocked, start) {
                (true, None) => start = Some(i),
                (false, Some(s)) => {
                    runs.push((s, i));
                    start = None;
                }
                _ => {}
            }
        }
        runs
    }
}
