//! One level of the hierarchy ([`Level`]): its ragged layout, its stencil, the spans of its
//! rows, and how the next coarser level is made from it (Galerkin coarsening).

use super::kernels::At;
use super::rows::Rows;

/// Factor on the Galerkin coarse operators (see [`Level::coarsen`]).
const COARSE_SCALE: f32 = 0.5;

/// A level's 5-point stencil.
pub enum Stencil {
    /// The finest level: `4` on the diagonal of every active cell, `−1` between adjacent active
    /// cells. Since the vectors hold 0 on inactive cells it needs no coefficient arrays (less
    /// memory traffic, where most of the work is).
    Uniform,
    /// A coarse level: Galerkin coefficients, 0 on and next to inactive cells.
    Coefficients {
        /// The diagonal.
        diag: Vec<f32>,
        /// Coupling to the east neighbour (≥ 0).
        east: Vec<f32>,
        /// Coupling to the north neighbour (≥ 0).
        north: Vec<f32>,
    },
}

/// One level of the hierarchy: a grid with a ring of inactive cells around it and a 5-point
/// stencil, stored ragged: each row holds only the columns that the passes over it and over
/// the rows beside it read (its span and theirs, a cell wider: see [`Layout::new`]), one row
/// after another. A nested part's box can be mostly empty (the rooms map's: 5.5 times its
/// rows' spans), and its vectors, its stencil and their setup then cost the spans, not the
/// box.
/// Inactive cells have `inv_diag = 0` and no coupling, so every sweep can run over a row's
/// span without branches, and the vectors a level works on hold 0 there. Each row is
/// processed only over its span ([`Level::span`]), outside which every cell is inactive.
pub struct Level {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// `1 / diagonal` on active cells, 0 on inactive ones.
    pub inv_diag: Vec<f32>,
    /// The stencil.
    pub stencil: Stencil,
    /// Active cells.
    pub unknowns: usize,
    /// Per pair of rows `(2p, 2p + 1)`: the columns `[lo, hi)` that hold all their active
    /// cells, `lo` even. The two rows share it so that their residuals restrict onto exactly
    /// the coarse cells `[lo / 2, ⌈hi / 2⌉)`, which hold every active coarse cell of that row.
    spans: Vec<[usize; 2]>,
    /// The layout (see [`Layout`]).
    layout: Layout,
}

/// Where a level's rows are stored. Rows and columns are counted with the ring: padded row
/// `r` is the grid's row `r − 1`, padded column `c` its column `c − 1`. Padded row `r` holds
/// the padded columns `first[r] .. first[r] + (start[r + 1] − start[r])`, from index
/// `start[r]` of a level's vectors.
struct Layout {
    /// Per padded row: its first stored padded column.
    first: Vec<usize>,
    /// Per padded row, and one more: where it starts in a level's vectors (the last entry is
    /// where the rows end).
    start: Vec<usize>,
}

impl Layout {
    /// The layout of a level `nx` wide and `ny` high whose pairs of rows have `spans`: padded
    /// row `r` stores the spans of the grid's rows `r − 2`, `r − 1` and `r` (the rows whose
    /// passes read it), each widened by a cell each way (a cell's west and east neighbours),
    /// within the ring.
    fn new(nx: usize, ny: usize, spans: &[[usize; 2]]) -> Self {
        let rows = ny + 2;
        let (mut first, mut start) = (Vec::with_capacity(rows), Vec::with_capacity(rows + 1));
        // One spare element before the rows and two after them (see [`Level::run`]).
        start.push(1);
        for r in 0..rows {
            let read_by = r.saturating_sub(2)..(r + 1).min(ny);
            let (lo, hi) = read_by
                .map(|j| spans[j / 2])
                .filter(|[lo, hi]| lo < hi)
                // Cells `lo − 1 .. hi + 1`: padded columns `lo .. hi + 2`.
                .map(|[lo, hi]| (lo, (hi + 2).min(nx + 2)))
                .fold((usize::MAX, 0), |(a, b), (lo, hi)| (a.min(lo), b.max(hi)));
            let (lo, hi) = if lo < hi { (lo, hi) } else { (0, 0) };
            first.push(lo);
            start.push(start[r] + hi - lo);
        }
        Self { first, start }
    }

    /// The index of padded column `c` of padded row `r`, which the row stores.
    #[inline(always)]
    fn at(&self, c: usize, r: usize) -> usize {
        self.start[r] + c - self.first[r]
    }

    /// The padded columns padded row `r` stores (none where there is no such row).
    fn columns(&self, r: usize) -> std::ops::Range<usize> {
        match self.first.get(r) {
            Some(&first) => first..first + self.start[r + 1] - self.start[r],
            None => 0..0,
        }
    }

    /// The index of padded column `c` of padded row `r`, if the row stores it.
    fn stored(&self, c: usize, r: usize) -> Option<usize> {
        self.columns(r).contains(&c).then(|| self.at(c, r))
    }
}

/// [`Level::spans`] of the finest level of a problem stored in `rows` with its `unknown` cells.
fn spans(rows: &Rows, unknown: &[bool]) -> Vec<[usize; 2]> {
    (0..rows.ny.div_ceil(2))
        .map(|p| {
            let pair = 2 * p..(2 * p + 2).min(rows.ny);
            let row = |j: usize| {
                let (k, cols) = rows.row(j);
                (cols.start, &unknown[k..k + cols.len()])
            };
            let lo = (pair.clone().map(row))
                .filter_map(|(first, u)| u.iter().position(|u| *u).map(|i| first + i))
                .min();
            let hi = (pair.map(row))
                .filter_map(|(first, u)| u.iter().rposition(|u| *u).map(|i| first + i))
                .max();
            match (lo, hi) {
                (Some(lo), Some(hi)) => [lo / 2 * 2, hi + 1],
                _ => [0, 0],
            }
        })
        .collect()
}

impl Level {
    /// The length of the level's vectors.
    pub fn len(&self) -> usize {
        self.layout.start[self.ny + 2] + 2
    }

    /// The index of cell `(i, j)`, which the layout must store (every cell of a row's span
    /// and its neighbours: see [`Layout::new`]).
    #[inline(always)]
    pub fn pad(&self, i: usize, j: usize) -> usize {
        self.layout.at(i + 1, j + 1)
    }

    /// Where the run of cells from `(i, j)` and the runs beside it in rows `j − 1` and
    /// `j + 1` start: the neighbourhood of cells in row `j`'s span.
    #[inline(always)]
    pub fn around(&self, i: usize, j: usize) -> At {
        At {
            down: self.layout.at(i + 1, j),
            mid: self.layout.at(i + 1, j + 1),
            up: self.layout.at(i + 1, j + 2),
        }
    }

    /// Where the run of row `j`'s span and the runs beside it start, and the span. An empty
    /// span's run is placed just inside the row's storage (one past its start: the level's
    /// vectors have a spare element before the rows and two after them), so that its empty
    /// neighbourhood slices stay in bounds, in the part of the vector the row is in.
    #[inline(always)]
    pub fn run(&self, j: usize) -> (At, std::ops::Range<usize>) {
        let cols = self.span(j);
        let at = if cols.is_empty() {
            let k = self.layout.start[j + 1] + 1;
            At {
                down: k,
                mid: k,
                up: k,
            }
        } else {
            self.around(cols.start, j)
        };
        (at, cols)
    }

    /// The index where row `j`'s storage begins: split there, a vector's rows below `j` and
    /// its rows from `j` on are two disjoint slices.
    #[inline(always)]
    pub fn row_start(&self, j: usize) -> usize {
        self.layout.start[j + 1]
    }

    /// The columns of row `j` that a pass goes over (see [`Level::spans`]).
    #[inline(always)]
    pub fn span(&self, j: usize) -> std::ops::Range<usize> {
        let [lo, hi] = self.spans[j / 2];
        lo..hi
    }

    /// Where row `j`'s span starts in the level's vectors, and how many cells it has.
    #[inline(always)]
    pub fn row(&self, j: usize) -> (usize, usize) {
        let (at, cols) = self.run(j);
        (at.mid, cols.len())
    }

    /// The cells of row `j` inside the grid that the layout stores, and the index of the
    /// first.
    pub fn stored(&self, j: usize) -> (usize, std::ops::Range<usize>) {
        let padded = self.layout.columns(j + 1);
        // The padded columns less the ring's two: cells from one before the first.
        let cells = padded.start.max(1) - 1..padded.end.min(self.nx + 1).saturating_sub(1);
        let cells = cells.start..cells.end.max(cells.start);
        let k = if cells.is_empty() {
            0
        } else {
            self.pad(cells.start, j)
        };
        (k, cells)
    }

    /// The fine level of a problem stored in `rows` with its `unknown` cells (in the order of
    /// `rows`).
    pub fn finest(rows: &Rows, unknown: &[bool]) -> Self {
        let (nx, ny) = (rows.nx, rows.ny);
        let spans = spans(rows, unknown);
        let layout = Layout::new(nx, ny, &spans);
        let mut inv_diag = vec![0.0; layout.start[ny + 2] + 2];
        for j in 0..ny {
            let [lo, hi] = spans[j / 2];
            let cols = lo..hi;
            // The span's cells that `rows` stores (every unknown cell among them).
            let (u, stored) = rows.within(j, cols);
            if stored.is_empty() {
                continue;
            }
            let k = layout.at(stored.start + 1, j + 1);
            let row = &unknown[u..u + stored.len()];
            for (inv, u) in inv_diag[k..k + stored.len()].iter_mut().zip(row) {
                *inv = if *u { 0.25 } else { 0.0 };
            }
        }
        let unknowns = unknown.iter().filter(|u| **u).count();
        Self {
            nx,
            ny,
            inv_diag,
            stencil: Stencil::Uniform,
            unknowns,
            spans,
            layout,
        }
    }

    /// Whether the cell at index `k` is active, as 1 or 0.
    pub fn active(&self, k: usize) -> f32 {
        if self.inv_diag[k] != 0.0 { 1.0 } else { 0.0 }
    }

    /// Padded row `r`'s values of the level vector `v` over the padded columns `cols`, 0 where
    /// the row stores none (or where there is no such row), into `out`.
    fn row_of(&self, v: &[f32], r: usize, cols: std::ops::Range<usize>, out: &mut Vec<f32>) {
        out.clear();
        out.resize(cols.len(), 0.0);
        let stored = self.layout.columns(r);
        let (lo, hi) = (cols.start.max(stored.start), cols.end.min(stored.end));
        if lo < hi {
            let k = self.layout.at(lo, r);
            out[lo - cols.start..hi - cols.start].copy_from_slice(&v[k..k + hi - lo]);
        }
    }

    /// The diagonals, east couplings and north couplings of padded row `r` over the padded
    /// columns `cols` (what [`Level::diag_at`], [`Level::east_at`] and [`Level::north_at`]
    /// give), into `[diag, east, north]`: what [`Level::coarsen`] sums, a row at a time.
    fn stencil_of_row(&self, r: usize, cols: std::ops::Range<usize>, out: &mut [Vec<f32>; 3]) {
        let [d, e, n] = out;
        match &self.stencil {
            Stencil::Coefficients { diag, east, north } => {
                self.row_of(diag, r, cols.clone(), d);
                self.row_of(east, r, cols.clone(), e);
                self.row_of(north, r, cols, n);
            }
            Stencil::Uniform => {
                // Whether each cell is active, and its east and north neighbours.
                let width = cols.len();
                self.row_of(&self.inv_diag, r, cols.start..cols.end + 1, d);
                self.row_of(&self.inv_diag, r + 1, cols, n);
                let active = |v: f32| if v != 0.0 { 1.0 } else { 0.0 };
                e.clear();
                for i in 0..width {
                    let (here, east, north) = (active(d[i]), active(d[i + 1]), active(n[i]));
                    e.push(here * east);
                    n[i] = here * north;
                    d[i] = 4.0 * here;
                }
                d.truncate(width);
            }
        }
    }

    /// The diagonal at cell `(i, j)` (0 where not stored).
    pub fn diag_at(&self, i: usize, j: usize) -> f32 {
        let Some(k) = self.layout.stored(i + 1, j + 1) else {
            return 0.0;
        };
        match &self.stencil {
            Stencil::Uniform => 4.0 * self.active(k),
            Stencil::Coefficients { diag, .. } => diag[k],
        }
    }

    /// The coupling of cell `(i, j)` to its east neighbour (0 where not stored).
    pub fn east_at(&self, i: usize, j: usize) -> f32 {
        let Some(k) = self.layout.stored(i + 1, j + 1) else {
            return 0.0;
        };
        match &self.stencil {
            Stencil::Uniform => {
                let east = (self.layout.stored(i + 2, j + 1)).map_or(0.0, |m| self.active(m));
                self.active(k) * east
            }
            Stencil::Coefficients { east, .. } => east[k],
        }
    }

    /// The coupling of cell `(i, j)` to its north neighbour (0 where not stored).
    pub fn north_at(&self, i: usize, j: usize) -> f32 {
        let Some(k) = self.layout.stored(i + 1, j + 1) else {
            return 0.0;
        };
        match &self.stencil {
            Stencil::Uniform => {
                let north = (self.layout.stored(i + 1, j + 2)).map_or(0.0, |m| self.active(m));
                self.active(k) * north
            }
            Stencil::Coefficients { north, .. } => north[k],
        }
    }

    /// The Galerkin coarse level `R A P` for piecewise-constant `P` (coarse cell `(I, J)` owns
    /// fine cells `(2I..2I+1, 2J..2J+1)`), `R = Pᵀ`: a coarse cell's diagonal is the sum of
    /// its children's less twice the couplings inside it (once for each ordering of a pair),
    /// and two coarse cells couple by the sum of the fine couplings across their shared side.
    /// Children beyond the fine grid fall in its inactive ring and add nothing.
    ///
    /// Coarse row `J`'s active cells are the parents of its fine pair's span, `[lo / 2,
    /// ⌈hi / 2⌉)` (a parent of an active cell is active: a part of the grid has a Dirichlet
    /// neighbour, so no group of its cells has a zero row sum), and only those are computed;
    /// the others are inactive, with no coupling.
    pub fn coarsen(&self) -> Self {
        let (nx, ny) = (self.nx.div_ceil(2), self.ny.div_ceil(2));
        // Coarse row J's columns: the parents of fine pair J's span.
        let parents = |jj: usize| {
            let [lo, hi] = self.spans[jj];
            lo / 2..hi.div_ceil(2)
        };
        let spans: Vec<[usize; 2]> = (0..ny.div_ceil(2))
            .map(|p| {
                let rows = (2 * p..(2 * p + 2).min(ny)).map(parents);
                let (lo, hi) = rows
                    .filter(|cols| !cols.is_empty())
                    .fold((usize::MAX, 0), |(a, b), c| (a.min(c.start), b.max(c.end)));
                if lo < hi { [lo / 2 * 2, hi] } else { [0, 0] }
            })
            .collect();
        let layout = Layout::new(nx, ny, &spans);
        let n = layout.start[ny + 2] + 2;
        let (mut diag, mut east, mut north) = (vec![0.0f32; n], vec![0.0; n], vec![0.0; n]);
        // The stencils of the pair's two fine rows over the children's columns.
        let mut pair = [[(); 3].map(|_| Vec::new()), [(); 3].map(|_| Vec::new())];
        for j in 0..ny {
            let cols = parents(j);
            if cols.is_empty() {
                continue;
            }
            // Children, in padded coordinates: a (2I, 2J), b (2I+1, 2J) in row r, d (2I, 2J+1),
            // e (2I+1, 2J+1) in the row above; at a = 2t and b = 2t + 1 of the buffers.
            let children = 2 * cols.start + 1..2 * cols.end + 1;
            for (q, buffers) in pair.iter_mut().enumerate() {
                self.stencil_of_row(2 * j + 1 + q, children.clone(), buffers);
            }
            let [[d0, e0, n0], [d1, e1, n1]] = &pair;
            let c0 = layout.at(cols.start + 1, j + 1);
            for t in 0..cols.len() {
                let (a, b, c) = (2 * t, 2 * t + 1, c0 + t);
                let inside = e0[a] + e1[a] + n0[a] + n0[b];
                let sum = d0[a] + d0[b] + d1[a] + d1[b];
                // Piecewise-constant transfers make R A P twice the rediscretized 2h stencil,
                // which under-corrects smooth errors; the factor restores its size.
                diag[c] = COARSE_SCALE * (sum - 2.0 * inside);
                east[c] = COARSE_SCALE * (e0[b] + e1[b]);
                north[c] = COARSE_SCALE * (n1[a] + n1[b]);
            }
        }
        let inv_diag: Vec<f32> = diag
            .iter()
            .map(|&d| if d > 0.0 { 1.0 / d } else { 0.0 })
            .collect();
        let unknowns = diag.iter().filter(|&&d| d > 0.0).count();
        Self {
            nx,
            ny,
            inv_diag,
            stencil: Stencil::Coefficients { diag, east, north },
            unknowns,
            spans,
            layout,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thin band across a wide box, with a gap of empty rows: every level of its hierarchy
    /// stores what its passes read (each span cell's neighbours, and the coarse cells its
    /// pairs restrict onto), and the finest level stores a tenth of its box, not all of it.
    #[test]
    fn a_band_stores_its_spans_and_what_they_read() {
        let (nx, ny) = (400, 301);
        let inside = |i: usize, j: usize| {
            let band = (i as f64 - 1.2 * j as f64 - 20.0).abs() <= 8.0;
            band && !(120..126).contains(&j)
        };
        let unknown: Vec<bool> = (0..nx * ny).map(|k| inside(k % nx, k / nx)).collect();
        let mut level = Level::finest(&Rows::whole(nx, ny), &unknown);
        assert!(
            10 * level.len() < (nx + 2) * (ny + 3),
            "{} stored",
            level.len()
        );
        loop {
            let stored = |i: isize, j: isize| {
                let (c, r) = ((i + 1) as usize, (j + 1) as usize);
                level.layout.stored(c, r).is_some()
            };
            for j in 0..level.ny {
                for i in level.span(j) {
                    let (i, j) = (i as isize, j as isize);
                    let reads = [(i - 1, j), (i, j), (i + 1, j), (i, j - 1), (i, j + 1)];
                    for (a, b) in reads {
                        assert!(stored(a, b), "({a}, {b}) around ({i}, {j})");
                    }
                    let k = level.pad(i as usize, j as usize);
                    assert_eq!(
                        level.active(k) != 0.0,
                        level.diag_at(i as usize, j as usize) > 0.0
                    );
                }
            }
            if level.nx <= 2 || level.unknowns <= 4 {
                break;
            }
            let coarse = level.coarsen();
            for j in 0..level.ny {
                for i in level.span(j).step_by(2) {
                    let parent = coarse.layout.stored(i / 2 + 1, j / 2 + 1);
                    assert!(parent.is_some(), "the parent of ({i}, {j})");
                }
            }
            assert!(coarse.unknowns > 0);
            level = coarse;
        }
    }
}
