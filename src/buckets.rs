//! Nearest-item queries among many items (a map's walls, measured from a body near them at
//! every step): the items' bounding boxes in buckets of a coarse grid, searched ring by ring
//! outwards from the query point until no farther bucket can hold a nearer item. The distances
//! are whatever the caller measures, so the nearest is exactly the one a scan of every item
//! finds. (A point far from every item visits every empty bucket on its way: a path's segments,
//! measured from states metres off it, are in a tree instead: `field/segment_tree.rs`.)

/// Items by bucket of a grid over their bounding boxes.
#[derive(Debug, Clone)]
pub struct Buckets {
    /// Lower-left corner of bucket (0, 0), m.
    origin: [f64; 2],
    /// Bucket size, m.
    size: f64,
    nx: usize,
    ny: usize,
    /// Per bucket, the items whose box overlaps it.
    items: Vec<Vec<u32>>,
}

impl Buckets {
    /// The items of bounding boxes `boxes` (`[x0, y0, x1, y1]`) in buckets of `size` metres;
    /// `None` when the boxes span nothing finite.
    pub fn new(boxes: &[[f64; 4]], size: f64) -> Option<Self> {
        let lo = [
            boxes.iter().map(|b| b[0]).fold(f64::INFINITY, f64::min),
            boxes.iter().map(|b| b[1]).fold(f64::INFINITY, f64::min),
        ];
        let hi = [
            boxes.iter().map(|b| b[2]).fold(f64::NEG_INFINITY, f64::max),
            boxes.iter().map(|b| b[3]).fold(f64::NEG_INFINITY, f64::max),
        ];
        if !(lo.iter().chain(&hi).all(|v| v.is_finite()) && size > 0.0) {
            return None;
        }
        let nx = ((hi[0] - lo[0]) / size).floor() as usize + 1;
        let ny = ((hi[1] - lo[1]) / size).floor() as usize + 1;
        let mut buckets = Self {
            origin: lo,
            size,
            nx,
            ny,
            items: vec![Vec::new(); nx * ny],
        };
        for (k, b) in boxes.iter().enumerate() {
            let (i0, j0) = buckets.bucket_of([b[0], b[1]]);
            let (i1, j1) = buckets.bucket_of([b[2], b[3]]);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    buckets.items[j * nx + i].push(k as u32);
                }
            }
        }
        Some(buckets)
    }

    /// The bucket holding `p`, clamped to the grid.
    fn bucket_of(&self, p: [f64; 2]) -> (usize, usize) {
        let f =
            |v: f64, o: f64, n: usize| (((v - o) / self.size).floor().max(0.0) as usize).min(n - 1);
        (
            f(p[0], self.origin[0], self.nx),
            f(p[1], self.origin[1], self.ny),
        )
    }

    /// The smallest `nearer(k, best)` over the items `k` that could be nearer to `p` than the
    /// best so far, searching the buckets ring by ring from `p`'s. `nearer` returns the smaller
    /// of `best` and its item's distance; an item in several buckets may be offered more than
    /// once, which does not change the minimum. A point off the grid is searched from the bucket
    /// it is clamped to: the buckets a ring away are still at least a ring's width from it.
    pub fn nearest(&self, p: [f64; 2], mut nearer: impl FnMut(usize, f64) -> f64) -> f64 {
        let (ci, cj) = self.bucket_of(p);
        let mut best = f64::INFINITY;
        for ring in 0..self.nx.max(self.ny) {
            let (i0, i1) = (ci.saturating_sub(ring), (ci + ring).min(self.nx - 1));
            let (j0, j1) = (cj.saturating_sub(ring), (cj + ring).min(self.ny - 1));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    if i.abs_diff(ci) != ring && j.abs_diff(cj) != ring {
                        continue;
                    }
                    for &k in &self.items[j * self.nx + i] {
                        best = nearer(k as usize, best);
                    }
                }
            }
            // Buckets beyond this ring are at least `ring` bucket widths from `p` (less a
            // margin for the f32 rounding of walls' boxes).
            if best <= ring as f64 * self.size - 1e-3 {
                break;
            }
        }
        best
    }
}
