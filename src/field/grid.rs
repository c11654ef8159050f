//! The regular grid the field lives on: cell `(i, j)` has its centre at
//! `origin + ((i + ½)·h, (j + ½)·h)`, and the grid covers the box `[0, W] × [0, H]`.
//!
//! A field's grid is anchored so that the target is exactly a cell centre: the potential's
//! minimum (the target cell) is then where the target is, and a body settles on the target
//! rather than up to half a cell diagonal (3.5 cm at 5 cm cells) beside it.

/// A regular grid over the world's box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Cell size h, m.
    pub cell: f64,
    /// Corner of cell (0, 0), m: `[0, 0]`, or up to one cell below and left of it.
    pub origin: [f64; 2],
}

impl Grid {
    /// The grid of `cell`-sized cells that covers a box of `size` metres.
    pub fn covering(size: [f64; 2], cell: f64) -> Self {
        Self {
            nx: ((size[0] / cell).ceil() as usize).max(1),
            ny: ((size[1] / cell).ceil() as usize).max(1),
            cell,
            origin: [0.0, 0.0],
        }
    }

    /// The grid of `cell`-sized cells that covers a box of `size` metres from `[0, 0]` and has
    /// a cell centred exactly on `anchor` (a point inside the box).
    pub fn anchored(size: [f64; 2], cell: f64, anchor: [f64; 2]) -> Self {
        Self::anchored_in(([0.0, 0.0], size), cell, anchor)
    }

    /// The grid of `cell`-sized cells that covers the box `[lo, hi]` and has a cell centred
    /// exactly on `anchor` (a point inside the box).
    pub fn anchored_in((lo, hi): ([f64; 2], [f64; 2]), cell: f64, anchor: [f64; 2]) -> Self {
        let offset = |k: usize| {
            let a = anchor[k] - lo[k];
            let o = a - ((a / cell).floor() + 0.5) * cell;
            lo[k] + if o > 0.0 { o - cell } else { o }
        };
        let origin = [offset(0), offset(1)];
        Self {
            nx: (((hi[0] - origin[0]) / cell).ceil() as usize).max(1),
            ny: (((hi[1] - origin[1]) / cell).ceil() as usize).max(1),
            cell,
            origin,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Whether the grid has no cells (never, for a grid built by [`Grid::covering`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Linear index of cell `(i, j)`, x index fastest.
    pub fn index(&self, i: usize, j: usize) -> usize {
        j * self.nx + i
    }

    /// The 4-neighbours of cell `(i, j)` that are on the grid.
    pub fn neighbours(&self, i: usize, j: usize) -> impl Iterator<Item = (usize, usize)> + use<> {
        let (nx, ny) = (self.nx, self.ny);
        [
            (i.wrapping_sub(1), j),
            (i + 1, j),
            (i, j.wrapping_sub(1)),
            (i, j + 1),
        ]
        .into_iter()
        .filter(move |&(a, b)| a < nx && b < ny)
    }

    /// The 4-neighbours of the cell of linear index `k` that are on the grid, as linear indices.
    pub fn neighbours_of(&self, k: usize) -> impl Iterator<Item = usize> + use<> {
        let nx = self.nx;
        self.neighbours(k % nx, k / nx)
            .map(move |(a, b)| b * nx + a)
    }

    /// Centre of cell `(i, j)`, m.
    pub fn center(&self, i: usize, j: usize) -> [f64; 2] {
        [
            self.origin[0] + (i as f64 + 0.5) * self.cell,
            self.origin[1] + (j as f64 + 0.5) * self.cell,
        ]
    }

    /// The cell containing point `p`, if it is on the grid.
    pub fn cell_of(&self, p: [f64; 2]) -> Option<(usize, usize)> {
        let (fx, fy) = (
            (p[0] - self.origin[0]) / self.cell,
            (p[1] - self.origin[1]) / self.cell,
        );
        if !(fx >= 0.0 && fy >= 0.0) {
            return None;
        }
        let (i, j) = (fx as usize, fy as usize);
        (i < self.nx && j < self.ny).then_some((i, j))
    }

    /// The cells within the axis-aligned rectangle `[lo, hi]`, clamped to the grid, as index
    /// ranges `(i_range, j_range)`.
    pub fn cells_in(
        &self,
        lo: [f64; 2],
        hi: [f64; 2],
    ) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
        let range = |lo: f64, hi: f64, o: f64, n: usize| {
            let a = ((lo - o) / self.cell - 0.5).floor().max(0.0) as usize;
            let b = (((hi - o) / self.cell - 0.5).ceil() + 1.0).clamp(0.0, n as f64) as usize;
            a.min(n)..b
        };
        (
            range(lo[0], hi[0], self.origin[0], self.nx),
            range(lo[1], hi[1], self.origin[1], self.ny),
        )
    }

    /// The corners of the grid's extent, m: `(origin, origin + (nx, ny) · cell)`.
    ///
    /// ```
    /// let grid = nadf::field::Grid::covering([2.0, 1.0], 0.5);
    /// assert_eq!(grid.bounds(), ([0.0, 0.0], [2.0, 1.0]));
    /// ```
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let hi = [
            self.origin[0] + self.nx as f64 * self.cell,
            self.origin[1] + self.ny as f64 * self.cell,
        ];
        (self.origin, hi)
    }

    /// The box of cells around `cells` (cell indices) grown by one cell on each side and
    /// clipped to the grid, as index ranges `(i_range, j_range)`: the cells and every
    /// neighbour of theirs. `None` when `cells` is empty.
    ///
    /// ```
    /// let grid = nadf::field::Grid::covering([1.0, 1.0], 0.1);
    /// let (i, j) = grid.box_around([grid.index(0, 4), grid.index(3, 5)]).unwrap();
    /// assert_eq!((i, j), (0..5, 3..7));
    /// assert!(grid.box_around([]).is_none());
    /// ```
    pub fn box_around(
        &self,
        cells: impl IntoIterator<Item = usize>,
    ) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
        let nx = self.nx;
        self.box_of(cells.into_iter().map(|k| (k % nx, k / nx)))
    }

    /// [`Grid::box_around`] the cells `(i, j)`.
    ///
    /// ```
    /// let grid = nadf::field::Grid::covering([1.0, 1.0], 0.1);
    /// assert_eq!(grid.box_of([(0, 4), (3, 5)]), Some((0..5, 3..7)));
    /// ```
    pub fn box_of(
        &self,
        cells: impl IntoIterator<Item = (usize, usize)>,
    ) -> Option<(std::ops::Range<usize>, std::ops::Range<usize>)> {
        let (mut lo, mut hi) = ([usize::MAX; 2], [0usize; 2]);
        for (i, j) in cells {
            lo = [lo[0].min(i), lo[1].min(j)];
            hi = [hi[0].max(i), hi[1].max(j)];
        }
        (lo[0] != usize::MAX).then(|| {
            (
                lo[0].saturating_sub(1)..(hi[0] + 2).min(self.nx),
                lo[1].saturating_sub(1)..(hi[1] + 2).min(self.ny),
            )
        })
    }

    /// The part of this grid made of the cells `i` along x and `j` along y: the same cells,
    /// numbered from the part's corner (a window, a box around some cells).
    ///
    /// ```
    /// let grid = nadf::field::Grid::covering([2.0, 1.0], 0.1);
    /// let part = grid.part(3..8, 2..4);
    /// assert_eq!((part.nx, part.ny), (5, 2));
    /// assert_eq!(part.center(0, 0), grid.center(3, 2));
    /// ```
    pub fn part(&self, i: std::ops::Range<usize>, j: std::ops::Range<usize>) -> Grid {
        Grid {
            nx: i.len(),
            ny: j.len(),
            cell: self.cell,
            origin: self.center(i.start, j.start).map(|c| c - 0.5 * self.cell),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn covering_rounds_up_and_centres_are_half_a_cell_in() {
        let g = Grid::covering([1.0, 0.52], 0.1);
        assert_eq!((g.nx, g.ny), (10, 6));
        assert_eq!(g.center(0, 0), [0.05, 0.05]);
        assert_eq!(g.cell_of([0.95, 0.51]), Some((9, 5)));
        assert_eq!(g.cell_of([-0.01, 0.2]), None);
        assert_eq!(g.cell_of([1.05, 0.2]), None);
    }

    #[test]
    fn anchored_grids_centre_a_cell_on_the_anchor_and_cover_the_box() {
        for anchor in [[1.5, 8.5], [0.0, 0.0], [0.05, 9.99], [3.333, 2.0]] {
            let g = Grid::anchored([10.0, 10.0], 0.05, anchor);
            let (i, j) = g.cell_of(anchor).unwrap();
            let c = g.center(i, j);
            assert!((c[0] - anchor[0]).abs() < 1e-12 && (c[1] - anchor[1]).abs() < 1e-12);
            assert!(g.origin.iter().all(|o| *o <= 0.0 && *o > -0.05));
            assert!(g.cell_of([9.999, 9.999]).is_some() && g.cell_of([0.0, 0.0]).is_some());
        }
    }

    #[test]
    fn a_box_away_from_the_origin_is_covered_the_same_way() {
        let g = Grid::anchored_in(([-10.0, 5.0], [0.0, 15.0]), 0.05, [-3.3, 7.7]);
        let (i, j) = g.cell_of([-3.3, 7.7]).unwrap();
        let c = g.center(i, j);
        assert!(
            (c[0] + 3.3).abs() < 1e-12 && (c[1] - 7.7).abs() < 1e-12,
            "{c:?}"
        );
        assert!(g.origin[0] <= -10.0 && g.origin[0] > -10.05);
        assert!(g.origin[1] <= 5.0 && g.origin[1] > 4.95);
        assert!(g.cell_of([-0.001, 14.999]).is_some() && g.cell_of([-10.0, 5.0]).is_some());
        assert_eq!(
            Grid::anchored([10.0, 10.0], 0.05, [1.5, 8.5]),
            Grid::anchored_in(([0.0, 0.0], [10.0, 10.0]), 0.05, [1.5, 8.5])
        );
    }

    #[test]
    fn cells_in_covers_every_centre_inside_the_rectangle() {
        let g = Grid::covering([1.0, 1.0], 0.1);
        let (ir, jr) = g.cells_in([0.22, 0.0], [0.48, 1.0]);
        for i in 0..g.nx {
            let c = g.center(i, 0)[0];
            if (0.22..=0.48).contains(&c) {
                assert!(ir.contains(&i), "{i} {ir:?}");
            }
        }
        assert_eq!(jr, 0..10);
    }
}
