//! Where a problem's cells are stored ([`Rows`]): a whole grid, row after row, or only the
//! columns of each row that a nested part's solve reads.

use std::ops::Range;

/// The cells of an `nx × ny` grid that a problem stores, row after row: row `j` holds the
/// columns `first[j] ..` up to the next row's start, from index `start[j]` of the problem's
/// arrays (its `unknown` flags and its `values`). A cell not stored is a Dirichlet cell at 0.
///
/// A whole grid ([`Rows::whole`]) stores every cell, at its grid index. A nested part of a
/// deep field ([`Rows::around`]) stores only its cells and their neighbours: its bounding box
/// can be five times its cells (the rooms map's), and a box-sized array of values costs its
/// memory's first touch, the largest cost of a small solve on a large map.
///
/// ```
/// use nadf::field::solvers::Rows;
/// // Two cells of a 10 × 5 grid, at (2, 1) and (7, 3).
/// let rows = Rows::around(10, 5, [(2, 1), (7, 3)]);
/// assert_eq!(rows.index(2, 1), Some(rows.index(1, 1).unwrap() + 1));
/// assert!(rows.index(7, 3).is_some() && rows.index(7, 4).is_some());
/// assert_eq!(rows.index(9, 4), None);
/// assert!(rows.len() < 50);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Rows {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Per row: its first stored column.
    first: Vec<usize>,
    /// Per row, and one more: where it starts in the arrays (the last entry is their length).
    start: Vec<usize>,
}

impl Rows {
    /// Every cell of an `nx × ny` grid, each at its grid index `j · nx + i`.
    pub fn whole(nx: usize, ny: usize) -> Self {
        Self {
            nx,
            ny,
            first: vec![0; ny],
            start: (0..=ny).map(|j| j * nx).collect(),
        }
    }

    /// The `cells` `(i, j)` of an `nx × ny` grid and every cell next to one: row `j` stores the
    /// columns from one before the first to one past the last cell of rows `j − 1`, `j` and
    /// `j + 1`, within the grid.
    pub fn around(nx: usize, ny: usize, cells: impl IntoIterator<Item = (usize, usize)>) -> Self {
        let mut span = vec![(usize::MAX, 0); ny];
        for (i, j) in cells {
            let (lo, hi) = &mut span[j];
            (*lo, *hi) = ((*lo).min(i), (*hi).max(i + 1));
        }
        let (mut first, mut start) = (Vec::with_capacity(ny), Vec::with_capacity(ny + 1));
        start.push(0);
        for j in 0..ny {
            let beside = j.saturating_sub(1)..(j + 2).min(ny);
            let (lo, hi) = (span[beside].iter())
                .filter(|(lo, hi)| lo < hi)
                .fold((usize::MAX, 0), |(a, b), &(lo, hi)| (a.min(lo), b.max(hi)));
            let (lo, hi) = if lo < hi {
                (lo.saturating_sub(1), (hi + 1).min(nx))
            } else {
                (0, 0)
            };
            first.push(lo);
            start.push(start[j] + hi - lo);
        }
        Self {
            nx,
            ny,
            first,
            start,
        }
    }

    /// The length of the problem's arrays.
    pub fn len(&self) -> usize {
        self.start[self.ny]
    }

    /// Whether nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `j`'s stored columns, and the index of the first.
    #[inline]
    pub fn row(&self, j: usize) -> (usize, Range<usize>) {
        let first = self.first[j];
        (
            self.start[j],
            first..first + self.start[j + 1] - self.start[j],
        )
    }

    /// The index of cell `(i, j)`, if stored.
    #[inline]
    pub fn index(&self, i: usize, j: usize) -> Option<usize> {
        let (k, cols) = self.row(j);
        cols.contains(&i).then(|| k + i - cols.start)
    }

    /// Row `j`'s stored columns within `cols`, and the index of the first of them (of the
    /// row's first stored cell when there is none).
    #[inline]
    pub fn within(&self, j: usize, cols: Range<usize>) -> (usize, Range<usize>) {
        let (k, stored) = self.row(j);
        let (lo, hi) = (cols.start.max(stored.start), cols.end.min(stored.end));
        if lo >= hi {
            return (k, lo..lo);
        }
        (k + lo - stored.start, lo..hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A whole grid stores every cell at its grid index.
    #[test]
    fn a_whole_grid_is_its_grid_indices() {
        let rows = Rows::whole(7, 4);
        assert_eq!(rows.len(), 28);
        for (i, j) in (0..7).flat_map(|i| (0..4).map(move |j| (i, j))) {
            assert_eq!(rows.index(i, j), Some(j * 7 + i));
        }
        assert_eq!(rows.within(2, 3..12), (17, 3..7));
    }

    /// Around a slanted line of cells and a straight one, every cell and its four neighbours
    /// within the grid are stored, each at its own index, and a row with no cell near it
    /// stores nothing.
    #[test]
    fn cells_and_their_neighbours_are_stored() {
        let (nx, ny) = (40, 30);
        let slanted = (3..20).map(|j| (2 * j - 3, j));
        let cells: Vec<(usize, usize)> = slanted.chain((20..26).map(|j| (5, j))).collect();
        let rows = Rows::around(nx, ny, cells.iter().copied());
        let mut seen = vec![false; rows.len()];
        for j in 0..ny {
            let (k, cols) = rows.row(j);
            for (n, i) in cols.enumerate() {
                assert_eq!(rows.index(i, j), Some(k + n));
                assert!(!std::mem::replace(&mut seen[k + n], true));
            }
        }
        assert!(seen.iter().all(|s| *s));
        for &(i, j) in &cells {
            for (a, b) in [(i, j), (i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1)] {
                assert!(rows.index(a, b).is_some(), "({a}, {b}) beside ({i}, {j})");
            }
        }
        assert_eq!(rows.row(28).1.len(), 0);
        assert!(rows.len() < nx * ny / 4, "{}", rows.len());
        // Within: the stored part of a range of columns.
        let (k, cols) = rows.row(10);
        assert_eq!(rows.within(10, 0..nx), (k, cols.clone()));
        assert_eq!(
            rows.within(10, cols.start + 1..nx),
            (k + 1, cols.start + 1..cols.end)
        );
        assert_eq!(rows.within(10, 0..cols.start).1.len(), 0);
    }
}
