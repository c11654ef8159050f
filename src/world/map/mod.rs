//! Maps as worlds: ROS `map_server` occupancy grids (`ros.rs`) and Moving AI grid benchmarks
//! (`movingai.rs`), read into an [`Occupancy`] grid whose blocked cells become walls: the
//! rows of blocked cells merged into as few boxes as a greedy sweep finds (`rectangles`).
//!
//! The map is y-up in the world, like everything else: a map's first text row or image row is
//! its top. Cell `(i, j)` of an [`Occupancy`] (`i` along x, `j` along y from the bottom) covers
//! `origin + [i, i + 1] × [j, j + 1] · cell`.

mod maze;
mod movingai;
pub(crate) mod occupancy;
mod ros;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use maze::perfect_maze;
pub use movingai::{Scenario, read_scenarios};
pub use occupancy::{CellState, Occupancy};

use super::schema::{MapSettings, UnknownCells, Wall};

/// A map file that cannot be read: the file, the line (and column) when known, and what.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}{}: {message}", file.display(), location.map_or_else(String::new, |(l, c)| format!(":{l}:{c}")))]
pub struct MapError {
    /// The map file (the YAML, its image, or the `.map`).
    pub file: PathBuf,
    /// 1-based line and column, when the problem has one.
    pub location: Option<(usize, usize)>,
    /// What is wrong.
    pub message: String,
}

impl MapError {
    fn at(file: &Path, location: Option<(usize, usize)>, message: impl Into<String>) -> Self {
        Self {
            file: file.to_path_buf(),
            location,
            message: message.into(),
        }
    }
}

/// Reads the map of `settings`, its file relative to `base` (the world file's directory).
pub fn read(settings: &MapSettings, base: &Path) -> Result<Occupancy, MapError> {
    let file = base.join(&settings.file);
    let is_ros = file
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("yaml") || e.eq_ignore_ascii_case("yml"));
    let mut map = if is_ros {
        if settings.cell.is_some() {
            return Err(MapError::at(
                &file,
                None,
                "`cell` is only used with a Moving AI `.map` (a ROS map gives its `resolution`)",
            ));
        }
        ros::read(&file)?
    } else {
        if settings.unknown.is_some() {
            return Err(MapError::at(
                &file,
                None,
                "`unknown` is only used with a ROS map (a Moving AI map has no unknown cells)",
            ));
        }
        movingai::read(&file, settings.cell.unwrap_or(1.0))?
    };
    map.unknown_blocked = settings.unknown.unwrap_or_default() == UnknownCells::Blocked;
    Ok(map)
}

/// The blocked cells of `map` as boxes: each row's runs of blocked cells, merged with the same run
/// of the rows above while it continues. Exactly the blocked cells, no more (every cell of
/// a box is blocked) and no less (every blocked cell is in one box).
pub fn rectangles(map: &Occupancy) -> Vec<Wall> {
    // Open boxes: their first row, keyed by their columns `[i0, i1)` (ordered, so the walls
    // come out in the same order every time).
    let mut open: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    let mut walls = Vec::new();
    for j in 0..=map.height {
        let runs = if j < map.height {
            map.runs(j)
        } else {
            Vec::new()
        };
        let mut next = BTreeMap::new();
        for run in runs {
            next.insert(run, open.remove(&run).unwrap_or(j));
        }
        for ((i0, i1), j0) in std::mem::replace(&mut open, next) {
            walls.push(cells_box(map, [i0, i1], [j0, j]));
        }
    }
    walls
}

/// The box covering the cells `[i0, i1) × [j0, j1)`.
fn cells_box(map: &Occupancy, [i0, i1]: [usize; 2], [j0, j1]: [usize; 2]) -> Wall {
    let half = [
        0.5 * (i1 - i0) as f64 * map.cell,
        0.5 * (j1 - j0) as f64 * map.cell,
    ];
    Wall::Box {
        center: [
            map.origin[0] + i0 as f64 * map.cell + half[0],
            map.origin[1] + j0 as f64 * map.cell + half[1],
        ],
        half_extents: half,
        angle: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(rows: &[&str]) -> Occupancy {
        let height = rows.len();
        let width = rows[0].len();
        let mut cells = Vec::new();
        for row in rows.iter().rev() {
            cells.extend(row.chars().map(|c| match c {
                '@' => CellState::Blocked,
                '?' => CellState::Unknown,
                _ => CellState::Free,
            }));
        }
        Occupancy {
            file: "t".into(),
            width,
            height,
            cell: 0.5,
            origin: [1.0, 2.0],
            cells,
            unknown_blocked: true,
        }
    }

    /// Every blocked cell lies in exactly one box, and no free cell in any.
    #[test]
    fn rectangles_cover_exactly_the_blocked_cells() {
        let m = map(&[
            "@@@@@@", //
            "@..?.@", //
            "@.@@.@", //
            "@.@@..", //
            "@@@@@@",
        ]);
        let boxes = rectangles(&m);
        let shapes: Vec<_> = boxes
            .iter()
            .map(|w| crate::world::wall_shape(w).unwrap())
            .collect();
        for j in 0..m.height {
            for i in 0..m.width {
                let [x, y] = m.center(i, j);
                let inside = shapes
                    .iter()
                    .filter(|s| s.signed_distance_to_point(x, y) < 0.0)
                    .count();
                assert_eq!(inside, usize::from(m.blocked(i, j)), "cell ({i}, {j})");
            }
        }
        // Merged: far fewer boxes than blocked cells.
        let blocked = (0..m.height)
            .flat_map(|j| (0..m.width).map(move |i| (i, j)))
            .filter(|&(i, j)| m.blocked(i, j))
            .count();
        assert!(
            boxes.len() * 2 < blocked,
            "{} boxes for {blocked} cells",
            boxes.len()
        );
        // The top row is y-up's last row: a full row of six cells, one box.
        assert!(
            boxes
                .iter()
                .any(|w| matches!(w, Wall::Box { half_extents, .. }
            if *half_extents == [1.5, 0.25]))
        );
    }

    #[test]
    fn cells_are_found_y_up_from_the_origin() {
        let m = map(&["@.", ".."]);
        assert!(m.blocked(0, 1) && !m.blocked(0, 0));
        assert_eq!(m.center(0, 0), [1.25, 2.25]);
        assert_eq!(m.cell_of([1.3, 2.9]), Some((0, 1)));
        assert_eq!(m.cell_of([0.9, 2.1]), None);
        assert_eq!(m.extent(), [1.0, 1.0]);
    }
}
