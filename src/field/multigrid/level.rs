//! One level of the hierarchy ([`Level`]): its padded layout, its stencil, the spans of its
//! rows, and how the next coarser level is made from it (Galerkin coarsening).

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

/// One level of the hierarchy: a padded grid (a ring of inactive cells around it, row stride
/// `nx + 2`) with a 5-point stencil. Inactive cells have `inv_diag = 0` and no coupling, so
/// every sweep can run over whole rows without branches, and the vectors a level works on hold
/// 0 there. Each row is processed only over its span ([`Level::span`]), outside which every
/// cell is inactive: a nested solve's box can be mostly empty.
pub struct Level {
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Distance between rows in the padded layout.
    pub stride: usize,
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
}

/// [`Level::spans`] of a level `nx` wide and `ny` high with the given active cells.
fn spans(nx: usize, ny: usize, active: impl Fn(usize, usize) -> bool) -> Vec<[usize; 2]> {
    (0..ny.div_ceil(2))
        .map(|p| {
            let rows = 2 * p..(2 * p + 2).min(ny);
            let lo = rows
                .clone()
                .filter_map(|j| (0..nx).find(|&i| active(i, j)))
                .min();
            let hi = rows.filter_map(|j| (0..nx).rfind(|&i| active(i, j))).max();
            match (lo, hi) {
                (Some(lo), Some(hi)) => [lo / 2 * 2, hi + 1],
                _ => [0, 0],
            }
        })
        .collect()
}

impl Level {
    /// The padded length: a ring of inactive cells, plus one more row so that reading the
    /// north neighbour of the top ring stays in bounds.
    pub fn len(&self) -> usize {
        self.stride * (self.ny + 3)
    }

    /// The padded index of cell `(i, j)`.
    #[inline(always)]
    pub fn pad(&self, i: usize, j: usize) -> usize {
        (j + 1) * self.stride + i + 1
    }

    /// The padded index where row `j` begins (its cell in the ring, west of `(0, j)`): split
    /// there, a vector's rows below `j` and its rows from `j` on are two disjoint slices.
    #[inline(always)]
    pub fn row_start(&self, j: usize) -> usize {
        (j + 1) * self.stride
    }

    /// The columns of row `j` that a pass goes over (see [`Level::spans`]).
    #[inline(always)]
    pub fn span(&self, j: usize) -> std::ops::Range<usize> {
        let [lo, hi] = self.spans[j / 2];
        lo..hi
    }

    /// Where row `j`'s span starts in the padded layout, and how many cells it has.
    #[inline(always)]
    pub fn row(&self, j: usize) -> (usize, usize) {
        let cols = self.span(j);
        (self.pad(cols.start, j), cols.len())
    }

    /// The fine level of the `grid`'s `unknown` cells.
    pub fn finest(nx: usize, ny: usize, unknown: &[bool]) -> Self {
        let stride = nx + 2;
        let n = stride * (ny + 3);
        let mut inv_diag = vec![0.0; n];
        for j in 0..ny {
            let k = (j + 1) * stride + 1;
            let row = &unknown[j * nx..(j + 1) * nx];
            for (inv, u) in inv_diag[k..k + nx].iter_mut().zip(row) {
                *inv = if *u { 0.25 } else { 0.0 };
            }
        }
        let unknowns = unknown.iter().filter(|u| **u).count();
        Self {
            nx,
            ny,
            stride,
            inv_diag,
            stencil: Stencil::Uniform,
            unknowns,
            spans: spans(nx, ny, |i, j| unknown[j * nx + i]),
        }
    }

    /// Whether padded cell `k` is active, as 1 or 0.
    pub fn active(&self, k: usize) -> f32 {
        if self.inv_diag[k] != 0.0 { 1.0 } else { 0.0 }
    }

    /// The diagonal at padded cell `k`.
    pub fn diag_at(&self, k: usize) -> f32 {
        match &self.stencil {
            Stencil::Uniform => 4.0 * self.active(k),
            Stencil::Coefficients { diag, .. } => diag[k],
        }
    }

    /// East coupling of padded cell `k`.
    pub fn east_at(&self, k: usize) -> f32 {
        match &self.stencil {
            Stencil::Uniform => self.active(k) * self.active(k + 1),
            Stencil::Coefficients { east, .. } => east[k],
        }
    }

    /// North coupling of padded cell `k`.
    pub fn north_at(&self, k: usize) -> f32 {
        match &self.stencil {
            Stencil::Uniform => self.active(k) * self.active(k + self.stride),
            Stencil::Coefficients { north, .. } => north[k],
        }
    }

    /// The Galerkin coarse level `R A P` for piecewise-constant `P` (coarse cell `(I, J)` owns
    /// fine cells `(2I..2I+1, 2J..2J+1)`), `R = Pᵀ`: a coarse cell's diagonal is the sum of
    /// its children's less twice the couplings inside it (once for each ordering of a pair),
    /// and two coarse cells couple by the sum of the fine couplings across their shared side.
    /// Children beyond the fine grid fall in its inactive ring and add nothing.
    pub fn coarsen(&self) -> Self {
        let (nx, ny) = (self.nx.div_ceil(2), self.ny.div_ceil(2));
        let stride = nx + 2;
        let n = stride * (ny + 3);
        let (mut diag, mut east, mut north) = (vec![0.0f32; n], vec![0.0; n], vec![0.0; n]);
        let s = self.stride;
        for j in 0..ny {
            for i in 0..nx {
                let c = (j + 1) * stride + i + 1;
                // Children: a (2I, 2J), b (2I+1, 2J), d (2I, 2J+1), e (2I+1, 2J+1).
                let a = self.pad(2 * i, 2 * j);
                let (b, d, e) = (a + 1, a + s, a + s + 1);
                let inside =
                    self.east_at(a) + self.east_at(d) + self.north_at(a) + self.north_at(b);
                let sum = self.diag_at(a) + self.diag_at(b) + self.diag_at(d) + self.diag_at(e);
                // Piecewise-constant transfers make R A P twice the rediscretized 2h stencil,
                // which under-corrects smooth errors; the factor restores its size.
                diag[c] = COARSE_SCALE * (sum - 2.0 * inside);
                east[c] = COARSE_SCALE * (self.east_at(b) + self.east_at(e));
                north[c] = COARSE_SCALE * (self.north_at(d) + self.north_at(e));
            }
        }
        let inv_diag: Vec<f32> = diag
            .iter()
            .map(|&d| if d > 0.0 { 1.0 / d } else { 0.0 })
            .collect();
        let unknowns = diag.iter().filter(|&&d| d > 0.0).count();
        let spans = spans(nx, ny, |i, j| diag[(j + 1) * stride + i + 1] > 0.0);
        Self {
            nx,
            ny,
            stride,
            inv_diag,
            stencil: Stencil::Coefficients { diag, east, north },
            unknowns,
            spans,
        }
    }
}
