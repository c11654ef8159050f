//! Sampling the solved field between cell centres: `W` and `∇W` by bilinear interpolation over
//! the reachable cells, `∇W` at a centre by central differences. Values are [`ScaledW`]: each
//! sample is taken at the largest scale of the cells it reads, so it keeps its relative
//! precision however deep the field goes (see `scaled.rs`).

use nalgebra::Vector2;

use super::grid::Grid;
use super::scaled::{ScaledW, ldexp};

/// Up to four cells and their interpolation weights, without allocating (sampling runs
/// several times per agent and step).
#[derive(Debug, Clone, Copy, Default)]
struct Stencil {
    cells: [(usize, f64); 4],
    len: usize,
}

impl Stencil {
    fn push(&mut self, k: usize, weight: f64) {
        self.cells[self.len] = (k, weight);
        self.len += 1;
    }

    fn cells(&self) -> &[(usize, f64)] {
        &self.cells[..self.len]
    }
}

/// How many cells beyond the interpolation stencil a point off the field looks for a reachable
/// cell to take its guidance from.
pub(super) const NEAR: i64 = 3;

/// `W` at every cell centre, ready for interpolation, with its central-difference gradient.
#[derive(Debug, Clone)]
pub struct Sampler {
    grid: Grid,
    w: ScaledW,
    reachable: Vec<bool>,
}

impl Sampler {
    /// The sampler of `w` on `grid`, over its `reachable` cells.
    pub fn new(grid: Grid, w: ScaledW, reachable: Vec<bool>) -> Self {
        Self { grid, w, reachable }
    }

    /// `∇W` at the centre of cell `k` by central differences (blocked and off-grid neighbours
    /// count as the boundary value 0), at that cell's scale `2^exponent`; 0 where `k` is not
    /// reachable. Computed where it is read: a sample reads four cells, while a field has
    /// millions, most never read (kept for every cell, it was 16 bytes a cell of every field
    /// and window, and a pass over them all at each solve).
    fn grad_at(&self, k: usize) -> Vector2<f64> {
        if !self.reachable[k] {
            return Vector2::zeros();
        }
        let (grid, w) = (&self.grid, &self.w);
        let e = w.exponent[k];
        let at = |i: isize, j: isize| {
            if i < 0 || j < 0 || i >= grid.nx as isize || j >= grid.ny as isize {
                0.0
            } else {
                w.at_scale(grid.index(i as usize, j as usize), e)
            }
        };
        let (i, j) = ((k % grid.nx) as isize, (k / grid.nx) as isize);
        Vector2::new(at(i + 1, j) - at(i - 1, j), at(i, j + 1) - at(i, j - 1)) / (2.0 * grid.cell)
    }

    /// The bilinear weights of the (up to four) reachable cell centres around `p`, renormalized
    /// over the reachable ones; empty when none of the four is reachable.
    fn stencil(&self, p: [f64; 2]) -> Stencil {
        let g = &self.grid;
        let fx = (p[0] - g.origin[0]) / g.cell - 0.5;
        let fy = (p[1] - g.origin[1]) / g.cell - 0.5;
        let mut out = Stencil::default();
        if !(fx.is_finite() && fy.is_finite()) {
            return out;
        }
        let (i0, j0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - i0, fy - j0);
        let mut total = 0.0;
        for (di, dj, weight) in [
            (0, 0, (1.0 - tx) * (1.0 - ty)),
            (1, 0, tx * (1.0 - ty)),
            (0, 1, (1.0 - tx) * ty),
            (1, 1, tx * ty),
        ] {
            let (i, j) = (i0 as i64 + di, j0 as i64 + dj);
            if i < 0 || j < 0 || i >= g.nx as i64 || j >= g.ny as i64 {
                continue;
            }
            let k = g.index(i as usize, j as usize);
            if self.reachable[k] && weight > 0.0 {
                out.push(k, weight);
                total += weight;
            }
        }
        if total > 0.0 {
            for (_, weight) in &mut out.cells[..out.len] {
                *weight /= total;
            }
        } else if let Some((i, j)) = g.cell_of(p) {
            // Exactly on a centre line with the other cells blocked: the cell itself.
            let k = g.index(i, j);
            if self.reachable[k] {
                out.push(k, 1.0);
            }
        }
        if out.len == 0 {
            // A body pressed into the blocked band along a wall (a hard contact at speed) is
            // off the field: it takes the nearest reachable cell within NEAR cells, whose
            // guidance leads it back out. Farther off the field there is none.
            let nearest = (i0 as i64 - NEAR..=i0 as i64 + 1 + NEAR)
                .flat_map(|i| (j0 as i64 - NEAR..=j0 as i64 + 1 + NEAR).map(move |j| (i, j)))
                .filter(|&(i, j)| i >= 0 && j >= 0 && i < g.nx as i64 && j < g.ny as i64)
                .map(|(i, j)| g.index(i as usize, j as usize))
                .filter(|&k| self.reachable[k])
                .map(|k| {
                    let [x, y] = g.center(k % g.nx, k / g.nx);
                    ((x - p[0]).hypot(y - p[1]), k)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, k)) = nearest {
                out.push(k, 1.0);
            }
        }
        out
    }

    /// The largest exponent among the stencil's cells: the scale a sample is taken at.
    fn scale(&self, s: &[(usize, f64)]) -> i32 {
        s.iter()
            .map(|&(k, _)| self.w.exponent[k])
            .max()
            .unwrap_or(0)
    }

    /// `W = 1 - V` at `p` as `(w, e)` with `W = w · 2^e`, if `p` is next to a reachable cell.
    pub fn w_scaled(&self, p: [f64; 2]) -> Option<(f64, i32)> {
        let s = self.stencil(p);
        let s = s.cells();
        let e = self.scale(s);
        (!s.is_empty()).then(|| (s.iter().map(|&(k, a)| a * self.w.at_scale(k, e)).sum(), e))
    }

    /// `W = 1 - V` at `p` (0 where it is below f64's range), if `p` is next to a reachable
    /// cell.
    pub fn w(&self, p: [f64; 2]) -> Option<f64> {
        self.w_scaled(p).map(|(w, e)| ldexp(w, e))
    }

    /// `∇W = -∇V` at `p` as `(g, e)` with `∇W = g · 2^e`, if `p` is next to a reachable cell:
    /// its direction at full precision however small it is.
    pub fn grad_w_scaled(&self, p: [f64; 2]) -> Option<(Vector2<f64>, i32)> {
        let s = self.stencil(p);
        let s = s.cells();
        let e = self.scale(s);
        let at_scale = |k: usize| match self.w.exponent[k] - e {
            0 => self.grad_at(k),
            shift => self.grad_at(k).map(|c| ldexp(c, shift)),
        };
        (!s.is_empty()).then(|| (s.iter().map(|&(k, a)| at_scale(k) * a).sum(), e))
    }

    /// `W` and `∇W` at `p` at the same scale (the largest exponent of the cells around `p`):
    /// their ratio at full precision at any depth, if `p` is next to a reachable cell.
    pub fn w_and_grad_scaled(&self, p: [f64; 2]) -> Option<(f64, Vector2<f64>)> {
        let (w, e) = self.w_scaled(p)?;
        let (g, eg) = self.grad_w_scaled(p)?;
        debug_assert_eq!(e, eg);
        Some((w, g))
    }

    /// `∇W = -∇V` at `p` (0 where it is below f64's range), if `p` is next to a reachable
    /// cell.
    pub fn grad_w(&self, p: [f64; 2]) -> Option<Vector2<f64>> {
        self.grad_w_scaled(p).map(|(g, e)| g.map(|c| ldexp(c, e)))
    }

    /// `W` at every cell (0 where blocked or unreachable).
    pub fn values(&self) -> &ScaledW {
        &self.w
    }

    /// Whether each cell is free and connected to the target.
    pub fn reachable_cells(&self) -> &[bool] {
        &self.reachable
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 m × 1 m grid of 0.1 m cells holding `W = 0.1 + 0.3 x − 0.2 y`.
    pub fn linear() -> (Grid, Vec<f64>) {
        let grid = Grid::covering([2.0, 1.0], 0.1);
        let mut w = vec![0.0; grid.len()];
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let [x, y] = grid.center(i, j);
                w[grid.index(i, j)] = 0.1 + 0.3 * x - 0.2 * y;
            }
        }
        (grid, w)
    }

    /// A linear `W` is reproduced exactly, with its exact gradient, away from the edges.
    #[test]
    fn linear_fields_are_sampled_exactly() {
        let (grid, w) = linear();
        let s = Sampler::new(grid, ScaledW::from_plain(w), vec![true; grid.len()]);
        let p = [0.93, 0.41];
        assert!((s.w(p).unwrap() - (0.1 + 0.3 * 0.93 - 0.2 * 0.41)).abs() < 1e-12);
        let g = s.grad_w(p).unwrap();
        assert!(
            (g.x - 0.3).abs() < 1e-12 && (g.y + 0.2).abs() < 1e-12,
            "{g}"
        );
    }

    #[test]
    fn points_far_from_reachable_cells_have_no_sample() {
        let grid = Grid::covering([1.0, 1.0], 0.1);
        let mut reachable = vec![true; grid.len()];
        for j in 0..4 {
            for i in 0..4 {
                reachable[grid.index(i, j)] = false;
            }
        }
        let s = Sampler::new(grid, ScaledW::from_plain(vec![0.5; grid.len()]), reachable);
        // Within three cells of a reachable one: its value (a body pushed into a wall's band).
        assert_eq!(s.w([0.15, 0.15]), Some(0.5));
        assert!(s.w([-0.45, -0.45]).is_none());
        assert!(s.grad_w([f64::NAN, 0.5]).is_none());
        assert!(s.w([0.8, 0.8]).is_some());
    }
}

#[cfg(test)]
mod deep {
    use super::tests::linear;
    use super::*;

    /// A linear `W` scaled far below f64's range is sampled with the same direction and the
    /// same value at its scale as at the scale of 1.
    #[test]
    fn fields_below_f64_keep_their_direction() {
        let (grid, w) = linear();
        let plain = Sampler::new(grid, ScaledW::from_plain(w.clone()), vec![true; grid.len()]);
        let deep = ScaledW {
            mantissa: w,
            exponent: vec![-5000; grid.len()],
        };
        let deep = Sampler::new(grid, deep, vec![true; grid.len()]);
        let p = [0.93, 0.41];
        let (g, e) = deep.grad_w_scaled(p).unwrap();
        assert_eq!(e, -5000);
        assert_eq!(g, plain.grad_w(p).unwrap());
        assert_eq!(deep.w_scaled(p).unwrap(), (plain.w(p).unwrap(), -5000));
        assert_eq!(deep.w(p), Some(0.0));
    }
}
