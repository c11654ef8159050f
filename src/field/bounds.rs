//! The axis-aligned box of some points in the plane ([`Bounds`]).

/// The axis-aligned box of some points, m (empty for none: `lo` above `hi`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Bounds {
    /// The least x and y of the points.
    pub lo: [f64; 2],
    /// The greatest x and y of the points.
    pub hi: [f64; 2],
}

impl Bounds {
    /// The box of `points`.
    pub fn of<'a>(points: impl IntoIterator<Item = &'a [f64; 2]>) -> Self {
        let mut b = Self {
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
        };
        for p in points {
            b.lo = [b.lo[0].min(p[0]), b.lo[1].min(p[1])];
            b.hi = [b.hi[0].max(p[0]), b.hi[1].max(p[1])];
        }
        b
    }

    /// The box grown by `margin` m on every side: the same bounds as the box of the points
    /// each grown first, since a sum rounds monotonically (the least `p − margin` is the least
    /// `p`, less `margin`). An empty box stays empty.
    pub fn grown(&self, margin: f64) -> Self {
        Self {
            lo: self.lo.map(|v| v - margin),
            hi: self.hi.map(|v| v + margin),
        }
    }

    /// The distance from `p` to the box, m: 0 inside it, infinite for an empty box.
    pub fn distance(&self, p: [f64; 2]) -> f64 {
        if self.lo[0] > self.hi[0] {
            return f64::INFINITY;
        }
        let dx = (self.lo[0] - p[0]).max(p[0] - self.hi[0]).max(0.0);
        let dy = (self.lo[1] - p[1]).max(p[1] - self.hi[1]).max(0.0);
        dx.hypot(dy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_holds_its_points_and_measures_from_its_edge() {
        let b = Bounds::of(&[[1.0, 2.0], [3.0, -1.0], [2.0, 0.5]]);
        assert_eq!((b.lo, b.hi), ([1.0, -1.0], [3.0, 2.0]));
        assert_eq!(b.distance([2.0, 0.0]), 0.0);
        assert_eq!(b.distance([6.0, 6.0]), 5.0);
        let g = b.grown(0.5);
        assert_eq!((g.lo, g.hi), ([0.5, -1.5], [3.5, 2.5]));
        let empty = Bounds::of(&[] as &[[f64; 2]]);
        assert_eq!(empty.distance([0.0, 0.0]), f64::INFINITY);
        assert_eq!(empty.grown(1.0).distance([0.0, 0.0]), f64::INFINITY);
    }
}
