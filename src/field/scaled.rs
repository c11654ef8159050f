//! `W = 1 − V` per cell with no limit on how small it gets: a mantissa and a binary exponent
//! per cell, `W = m · 2^e` ([`ScaledW`]).
//!
//! An f64 stops at 1e-308, while `W` in a benchmark maze goes down to 1e-6500 and beyond
//! (design page, "Fields of any depth"). Each nested solve works on values of order 1 and
//! stores them with the exponent of its scale; sampling brings the (up to four) cells it
//! interpolates to their largest exponent, which is exact (a multiplication by a power of two),
//! so the guidance direction keeps full relative precision at any depth. Cells of the first
//! solve have exponent 0, so where `W` fits in an f64 every value and every sample is exactly
//! what a plain f64 field gives.

/// `m · 2^e`, exact wherever the result is a normal f64 (0 when it is too small even for a
/// subnormal; the exponent can be anything).
pub fn ldexp(m: f64, e: i32) -> f64 {
    // 2^k for k in [-1022, 1023], exactly.
    let power = |k: i32| f64::from_bits(((k + 1023) as u64) << 52);
    let (mut m, mut e) = (m, e);
    while e > 1023 {
        m *= power(1023);
        e -= 1023;
    }
    while e < -1022 {
        if m == 0.0 {
            return m;
        }
        m *= power(-1022);
        e += 1022;
    }
    m * power(e)
}

/// The binary exponent of the largest power of two at most `|x|`, for a normal, non-zero `x`.
pub fn exponent_of(x: f64) -> i32 {
    ((x.abs().to_bits() >> 52) & 0x7ff) as i32 - 1023
}

/// `W` per cell as `mantissa[k] · 2^exponent[k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaledW {
    /// The mantissas (the values of the solve that gave each cell, at that solve's scale).
    pub mantissa: Vec<f64>,
    /// The binary exponents of each cell's scale (0 for the first solve).
    pub exponent: Vec<i32>,
}

impl ScaledW {
    /// Plain values (exponent 0).
    pub fn from_plain(w: Vec<f64>) -> Self {
        let exponent = vec![0; w.len()];
        Self {
            mantissa: w,
            exponent,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.mantissa.len()
    }

    /// Whether there are no cells.
    pub fn is_empty(&self) -> bool {
        self.mantissa.is_empty()
    }

    /// `W` at cell `k` as an f64 (0 where it is below f64's range).
    pub fn value(&self, k: usize) -> f64 {
        ldexp(self.mantissa[k], self.exponent[k])
    }

    /// `W` at cell `k` at the scale `2^e`: `W / 2^e`.
    pub fn at_scale(&self, k: usize, e: i32) -> f64 {
        if self.exponent[k] == e {
            self.mantissa[k]
        } else {
            ldexp(self.mantissa[k], self.exponent[k] - e)
        }
    }

    /// `log2 W` at cell `k` (−∞ where `W` is 0 or negative: blocked, or solver noise).
    pub fn log2(&self, k: usize) -> f64 {
        let m = self.mantissa[k];
        if m > 0.0 {
            m.log2() + f64::from(self.exponent[k])
        } else {
            f64::NEG_INFINITY
        }
    }

    /// `log10 W` at cell `k` (−∞ where `W` is 0 or negative). Exactly `W.log10()` for cells
    /// of the first solve.
    pub fn log10(&self, k: usize) -> f64 {
        match self.exponent[k] {
            0 => self.mantissa[k].log10(),
            _ => self.log2(k) * std::f64::consts::LOG10_2,
        }
    }

    /// Every cell's `W` as an f64 (0 below f64's range): a warm start, an export.
    pub fn to_plain(&self) -> Vec<f64> {
        (0..self.len()).map(|k| self.value(k)).collect()
    }
}

/// Checks that `a` and `b` agree on each of `cells` to six digits (`log2 W` within 1e-5),
/// at any depth: two solves of one field.
#[cfg(test)]
pub(crate) fn assert_same_to_six_digits(a: &ScaledW, b: &ScaledW, cells: &[bool]) {
    for k in (0..cells.len()).filter(|&k| cells[k]) {
        let (a, b) = (a.log2(k), b.log2(k));
        assert!((a - b).abs() < 1e-5, "cell {k}: log2 W {a} against {b}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ldexp_is_exact_and_reaches_any_exponent() {
        assert_eq!(ldexp(0.75, 0), 0.75);
        assert_eq!(ldexp(0.75, 2), 3.0);
        assert_eq!(ldexp(3.0, -1), 1.5);
        assert_eq!(ldexp(1.0, -1074), f64::from_bits(1));
        assert_eq!(ldexp(1.0, -1100), 0.0);
        assert_eq!(ldexp(0.5, 1024), 2f64.powi(1023));
        // A value that underflowed is 0 for good.
        assert_eq!(ldexp(ldexp(0.3, -5000), 5000), 0.0);
        assert_eq!(exponent_of(0.75), -1);
        assert_eq!(exponent_of(1.0), 0);
        assert_eq!(exponent_of(1e-300), -997);
    }

    #[test]
    fn values_far_below_f64_keep_their_logarithm() {
        let w = ScaledW {
            mantissa: vec![0.5, 0.25, 0.0],
            exponent: vec![0, -10_000, -10_000],
        };
        assert_eq!(w.value(0), 0.5);
        assert_eq!(w.value(1), 0.0);
        assert_eq!(w.log2(1), -10_002.0);
        assert!((w.log10(1) - -10_002.0 * std::f64::consts::LOG10_2).abs() < 1e-9);
        assert_eq!(w.log10(2), f64::NEG_INFINITY);
        assert_eq!(w.at_scale(1, -10_000), 0.25);
        assert_eq!(w.at_scale(1, -9_999), 0.125);
    }
}
