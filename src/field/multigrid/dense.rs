//! The Cholesky factor and solve of a coarsest level, shared by the plane's solver and the
//! (x, y, θ) one. A non-positive pivot (which an SPD matrix never has, but rounding could)
//! leaves its unknown at 0.
//!
//! A coarsest level's matrix is a grid's stencil in row order: each row's nonzeros lie within
//! a row of cells of the diagonal, and the factor keeps that profile (a row of `L` starts where
//! the row of `A` does: no fill before it). The factor and the solves therefore run over each
//! row's profile only: about `n · nx` operations per solve instead of `n²`, with exactly the
//! dense result (every term skipped is a product with an exact zero). A W-cycle visits its
//! coarsest level `2^(levels − 1)` times, so this is what makes the small grids of the local
//! windows cheap.

/// The Cholesky factor `A = L Lᵀ` of a symmetric positive definite matrix, within its profile.
#[derive(Debug, Clone)]
pub struct Factor {
    n: usize,
    /// `L`, row-major `n × n` (zero outside the profile).
    l: Vec<f64>,
    /// The first column of each row's profile (`L[r][c] = 0` for `c < first[r]`).
    first: Vec<usize>,
    /// The last row whose profile reaches each column (`L[p][c] = 0` for `p > last[c]`).
    last: Vec<usize>,
}

impl Factor {
    /// Factors the row-major `n × n` matrix `a` (its lower triangle is read).
    pub fn new(a: Vec<f64>, n: usize) -> Self {
        assert_eq!(a.len(), n * n, "an n × n matrix");
        let first: Vec<usize> = (0..n)
            .map(|r| (0..r).find(|&c| a[r * n + c] != 0.0).unwrap_or(r))
            .collect();
        let mut last: Vec<usize> = (0..n).collect();
        for (r, &f) in first.iter().enumerate() {
            for c in f..r {
                last[c] = last[c].max(r);
            }
        }
        Self::within(a, n, first, last)
    }

    /// Factors `a` over the profile `first`, `last` (see the fields), which must hold every
    /// nonzero of `a`'s lower triangle; the whole triangle (`first = 0`, `last = n − 1`) is
    /// the plain dense factor.
    fn within(mut a: Vec<f64>, n: usize, first: Vec<usize>, last: Vec<usize>) -> Self {
        for c in 0..n {
            let mut pivot = a[c * n + c];
            for p in first[c]..c {
                pivot -= a[c * n + p] * a[c * n + p];
            }
            let pivot = if pivot > 0.0 { pivot.sqrt() } else { 0.0 };
            a[c * n + c] = pivot;
            for r in c + 1..=last[c] {
                if first[r] > c {
                    continue;
                }
                let mut v = a[r * n + c];
                for p in first[r].max(first[c])..c {
                    v -= a[r * n + p] * a[c * n + p];
                }
                a[r * n + c] = over_pivot(v, pivot);
            }
        }
        Self {
            n,
            l: a,
            first,
            last,
        }
    }

    /// Solves `L Lᵀ y = b` in place (`y` holds `b`).
    pub fn solve(&self, y: &mut [f64]) {
        let (n, l) = (self.n, &self.l);
        for r in 0..n {
            let mut v = y[r];
            for p in self.first[r]..r {
                v -= l[r * n + p] * y[p];
            }
            y[r] = over_pivot(v, l[r * n + r]);
        }
        for r in (0..n).rev() {
            let mut v = y[r];
            for p in r + 1..=self.last[r] {
                v -= l[p * n + r] * y[p];
            }
            y[r] = over_pivot(v, l[r * n + r]);
        }
    }
}

/// `v / pivot`, or 0 for a non-positive pivot (its unknown is left at 0).
fn over_pivot(v: f64, pivot: f64) -> f64 {
    if pivot > 0.0 { v / pivot } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain dense factor and solve (the whole lower triangle as the profile): what the
    /// profile-limited ones must equal bit for bit.
    fn dense(a: Vec<f64>, n: usize, y: &mut [f64]) {
        Factor::within(a, n, vec![0; n], vec![n - 1; n]).solve(y);
    }

    /// The 5-point matrix of a `nx × ny` grid with some cells removed (a wall), in row order.
    fn stencil(nx: usize, ny: usize) -> (Vec<f64>, usize) {
        let cells: Vec<(usize, usize)> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .filter(|&(i, j)| !(i == nx / 2 && j < ny - 2))
            .collect();
        let n = cells.len();
        let mut a = vec![0.0; n * n];
        for (r, &(i, j)) in cells.iter().enumerate() {
            a[r * n + r] = 4.0 + 0.01 * (i + j) as f64;
            for (c, &(k, m)) in cells.iter().enumerate() {
                if i.abs_diff(k) + j.abs_diff(m) == 1 {
                    // Unequal couplings, symmetric in the pair.
                    a[r * n + c] = -1.0 - 0.001 * (i * j + k * m) as f64;
                }
            }
        }
        (a, n)
    }

    /// Over a grid's stencil with a wall through it, the profile-limited factor and solve give
    /// exactly the dense ones' result.
    #[test]
    fn the_profile_solve_is_the_dense_solve_bit_for_bit() {
        for (nx, ny) in [(8, 8), (5, 9), (11, 4), (1, 6)] {
            let (a, n) = stencil(nx, ny);
            let b: Vec<f64> = (0..n).map(|k| ((k * 37) % 11) as f64 - 5.0).collect();
            let mut expected = b.clone();
            dense(a.clone(), n, &mut expected);
            let mut got = b.clone();
            Factor::new(a.clone(), n).solve(&mut got);
            assert_eq!(
                got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                expected.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                "{nx} × {ny}"
            );
            // And it solves the system.
            let worst = (0..n)
                .map(|r| ((0..n).map(|c| a[r * n + c] * got[c]).sum::<f64>() - b[r]).abs())
                .fold(0.0, f64::max);
            assert!(worst < 1e-12, "{nx} × {ny}: residual {worst:e}");
        }
    }
}
