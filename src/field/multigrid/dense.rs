//! The dense Cholesky factor and solve of a coarsest level, shared by the plane's solver and
//! the (x, y, θ) one. A non-positive pivot (which an SPD matrix never has, but rounding could)
//! leaves its unknown at 0.

/// Factors the row-major `n × n` matrix `a` in place: `a = L Lᵀ`, `L` in the lower triangle.
pub fn cholesky(a: &mut [f64], n: usize) {
    for c in 0..n {
        let mut pivot = a[c * n + c];
        for p in 0..c {
            pivot -= a[c * n + p] * a[c * n + p];
        }
        let pivot = if pivot > 0.0 { pivot.sqrt() } else { 0.0 };
        a[c * n + c] = pivot;
        for r in c + 1..n {
            let mut v = a[r * n + c];
            for p in 0..c {
                v -= a[r * n + p] * a[c * n + p];
            }
            a[r * n + c] = if pivot > 0.0 { v / pivot } else { 0.0 };
        }
    }
}

/// Solves `L Lᵀ y = b` in place (`y` holds `b`), with `l` the factor of [`cholesky`].
pub fn solve(l: &[f64], n: usize, y: &mut [f64]) {
    for r in 0..n {
        let mut v = y[r];
        for p in 0..r {
            v -= l[r * n + p] * y[p];
        }
        y[r] = if l[r * n + r] > 0.0 {
            v / l[r * n + r]
        } else {
            0.0
        };
    }
    for r in (0..n).rev() {
        let mut v = y[r];
        for p in r + 1..n {
            v -= l[p * n + r] * y[p];
        }
        y[r] = if l[r * n + r] > 0.0 {
            v / l[r * n + r]
        } else {
            0.0
        };
    }
}
