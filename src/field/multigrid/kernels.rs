//! The row loops' building blocks: the AVX2 trampoline [`wide`], the 5-point neighbourhood of a
//! row ([`Neighbourhood`]), and the reductions and conversions the passes share.
//!
//! # The inlining rule of the fast path
//!
//! [`wide`] runs a closure inside a function compiled with `#[target_feature(enable = "avx2")]`.
//! Only code *inlined into* that function is compiled for AVX2: a function or closure it calls
//! that is not inlined is compiled once, for the baseline target (SSE2), and runs at half the
//! vector width. Rust inlines small closures on its own but gives no guarantee, and a large
//! closure (a whole wavefront) is exactly what it declines to inline. So:
//!
//! - every closure passed to [`wide`], and every closure those closures pass on (the
//!   wavefront's `before` and `after` callbacks), is marked `#[inline(always)]`;
//! - every function they call in a row loop is `#[inline(always)]` (the `Level` methods of
//!   `smoother.rs`, `apply_row`, [`dot`], [`for_cycle`], [`Neighbourhood::of`]).
//!
//! Breaking the rule does not change a single result (the arithmetic per element is the same
//! either way, see [`wide`]); it only makes the solve slower. The benchmark
//! `cargo bench --bench solve -- kernels` times one cycle with the fast path and with it
//! switched off ([`set_portable`]): if the two times are the same on an AVX2 machine, the fast
//! path has been lost.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set by [`set_portable`]: run the baseline code even where AVX2 is available.
static PORTABLE: AtomicBool = AtomicBool::new(false);

/// Switches the AVX2 path off (`true`) or back on, for the benchmark that checks it is there.
/// The results are the same either way.
pub fn set_portable(portable: bool) {
    PORTABLE.store(portable, Ordering::Relaxed);
}

/// Runs `f` compiled for AVX2 when the processor has it, else as it is (see the module's
/// inlining rule). The loops are the same element-wise arithmetic either way (Rust never fuses
/// a multiply and an add on its own), so the results do not depend on the processor; AVX2 only
/// processes 8 f32 at a time instead of 4.
#[inline(always)]
pub fn wide<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2")]
        fn avx2<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        if avx2_on() {
            // SAFETY: the processor supports AVX2, checked just above.
            return unsafe { avx2(f) };
        }
    }
    f()
}

/// Where a run of cells starts in a level's vector, and where the runs beside it in the rows
/// below and above start (the layout is ragged: see `level.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct At {
    /// The run in the row below.
    pub down: usize,
    /// The run itself.
    pub mid: usize,
    /// The run in the row above.
    pub up: usize,
}

impl At {
    /// The same runs in a slice of the vector that starts at index `origin`.
    #[inline(always)]
    pub fn from(self, origin: usize) -> Self {
        Self {
            down: self.down - origin,
            mid: self.mid - origin,
            up: self.up - origin,
        }
    }
}

/// The five shifted views of a level's vector that a 5-point stencil reads for a run of `n`
/// cells: the cells themselves and their west, east, up (north) and down (south) neighbours.
/// Every row loop of the solver is written over these slices, so that the compiler sees
/// straight-line element-wise code with no bounds checks inside the loop.
#[derive(Clone, Copy)]
pub struct Neighbourhood<'a, T> {
    /// The cells.
    pub mid: &'a [T],
    /// Their west neighbours.
    pub west: &'a [T],
    /// Their east neighbours.
    pub east: &'a [T],
    /// Their north neighbours (one row up).
    pub up: &'a [T],
    /// Their south neighbours (one row down).
    pub down: &'a [T],
}

impl<'a, T> Neighbourhood<'a, T> {
    /// The neighbourhood of the `n` cells of `x` at `at`.
    #[inline(always)]
    pub fn of(x: &'a [T], at: At, n: usize) -> Self {
        let k = at.mid;
        Self {
            mid: &x[k..k + n],
            west: &x[k - 1..k - 1 + n],
            east: &x[k + 1..k + 1 + n],
            up: &x[at.up..at.up + n],
            down: &x[at.down..at.down + n],
        }
    }
}

/// `a · b` in f64 (either may hold f32), summed in four interleaved partial sums (a fixed
/// order, so the result does not depend on the machine) that the compiler can keep in vector
/// registers.
#[inline(always)]
pub fn dot<A: Copy + Into<f64>, B: Copy + Into<f64>>(a: &[A], b: &[B]) -> f64 {
    let mut sums = [0.0; 4];
    let (a4, b4) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = a4
        .remainder()
        .iter()
        .zip(b4.remainder())
        .map(|(x, y)| (*x).into() * (*y).into())
        .sum();
    for (a, b) in a4.zip(b4) {
        for l in 0..4 {
            sums[l] += a[l].into() * b[l].into();
        }
    }
    (sums[0] + sums[1]) + (sums[2] + sums[3]) + tail
}

/// The cycle's values below this are rounded to 0: its scaled residual's entries, and what
/// each smoothing pass, the coarsest solve and CG's direction make of them.
///
/// Why: the cycle works on values of order 1, and f32 holds 7 digits of them, so a value below
/// 1e-30 carries nothing; but arithmetic that makes or reads a subnormal f32 (below 1.2e-38)
/// takes a slow path in the processor, about a hundred times the time of the operation. A
/// field decays without bound through a maze (544 decades across the shared rooms map), so the
/// cycle's corrections decay through f32's range into the subnormals over every deep room, and
/// smoothing kept making more of them there: the rooms map's first solve took 3.4 s where the
/// paper's room at the same 2561² takes 0.7 s (0.85 s with the flush). With every value at
/// least 1e-30 or 0, a product by a stencil's coefficients or a difference of two (a multiple
/// of their last digit, 1e-37) stays above the subnormals.
const FLUSH: f32 = 1e-30;

/// `v`, or 0 when it is below [`FLUSH`].
#[inline(always)]
pub fn flushed(v: f32) -> f32 {
    if v.abs() < FLUSH { 0.0 } else { v }
}

/// Whether [`wide`] takes the AVX2 path: the processor has AVX2 and [`set_portable`] has not
/// switched it off. Code that calls AVX2 intrinsics itself ([`x86`]) checks it first.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn avx2_on() -> bool {
    !PORTABLE.load(Ordering::Relaxed) && std::arch::is_x86_feature_detected!("avx2")
}

/// AVX2 forms of the building blocks, for a loop the compiler does not vectorize well on its
/// own (see `smoother.rs`). Each is the scalar one on 8 lanes, to the bit.
#[cfg(target_arch = "x86_64")]
pub mod x86 {
    use std::arch::x86_64::{
        __m256, _CMP_NLT_UQ, _mm256_and_ps, _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_set1_epi32,
        _mm256_set1_ps,
    };

    /// [`super::flushed`] on each lane: `v`, or 0 (+0) where `|v|` is below the flush level;
    /// a NaN is kept, as `|v| < FLUSH` is false for it.
    ///
    /// # Safety
    /// The processor must have AVX2 ([`super::avx2_on`]). Not a `#[target_feature]` function,
    /// which would not be inlined: it is inlined into [`super::wide`]'s AVX2 function.
    #[inline(always)]
    pub unsafe fn flushed(v: __m256) -> __m256 {
        // SAFETY: the processor has AVX2 (the caller's contract).
        unsafe {
            let abs = _mm256_and_ps(v, _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX)));
            let kept = _mm256_cmp_ps::<_CMP_NLT_UQ>(abs, _mm256_set1_ps(super::FLUSH));
            _mm256_and_ps(v, kept)
        }
    }
}

/// `r · scale` rounded to f32 for the cycle, 0 when too small for f32 to hold at full precision.
#[inline(always)]
pub fn for_cycle(r: f64, scale: f64) -> f32 {
    flushed((r * scale) as f32)
}
