//! The smoother: red-black Gauss-Seidel on one level, run as a wavefront over its rows, and the
//! residual of a row. Every function here runs inside [`super::kernels::wide`], so each is
//! `#[inline(always)]` (the inlining rule of `kernels.rs`).

#[cfg(target_arch = "x86_64")]
use super::kernels::{self, x86};
use super::kernels::{Neighbourhood, flushed};
use super::level::{Level, Stencil};

/// Cells a short row's update computes at once: one AVX2 register of f32.
const LANES: usize = 8;

/// Rows at least this long are updated through a buffer (see [`in_place`]).
const LONG_ROW: usize = 256;

/// Gauss-Seidel's new values `out` of cells `i .. i + out.len()` of a row on the finest
/// level's uniform stencil. `row` holds the row's old values from the cell before the first
/// (so cell `l`'s west, itself and its east are `row[l]`, `row[l + 1]`, `row[l + 2]`); `down`,
/// `up`, `b`, `d` and `keep` are the row's neighbours below and above, right-hand side,
/// `1 / diagonal` and keep pattern, each sliced to the row. `keep`'s cells keep their value.
#[inline(always)]
fn uniform(
    out: &mut [f32],
    row: &[f32],
    (down, up): (&[f32], &[f32]),
    (b, d, keep): (&[f32], &[f32], &[f32]),
    i: usize,
) {
    let n = out.len();
    let w = &row[i..i + n + 2];
    let (west, mid, east) = (&w[..n], &w[1..n + 1], &w[2..n + 2]);
    let (down, up) = (&down[i..i + n], &up[i..i + n]);
    let (b, d, keep) = (&b[i..i + n], &d[i..i + n], &keep[i..i + n]);
    for l in 0..n {
        let new = d[l] * (b[l] + west[l] + east[l] + up[l] + down[l]);
        out[l] = flushed(keep[l] * mid[l] + (1.0 - keep[l]) * new);
    }
}

/// [`uniform`] on a coarse level's stencil: `east` holds the row's east couplings from the
/// cell before the first (cell `l`'s west and east couplings are `east[l]` and
/// `east[l + 1]`), `north` and `north_down` the north couplings of the row and of the row
/// below.
#[inline(always)]
fn coefficients(
    out: &mut [f32],
    row: &[f32],
    (down, up): (&[f32], &[f32]),
    (b, d, keep): (&[f32], &[f32], &[f32]),
    (east, north, north_down): (&[f32], &[f32], &[f32]),
    i: usize,
) {
    let n = out.len();
    let w = &row[i..i + n + 2];
    let (west, mid, east_x) = (&w[..n], &w[1..n + 1], &w[2..n + 2]);
    let (down, up) = (&down[i..i + n], &up[i..i + n]);
    let (b, d, keep) = (&b[i..i + n], &d[i..i + n], &keep[i..i + n]);
    let e = &east[i..i + n + 1];
    let (e_west, e_mid) = (&e[..n], &e[1..n + 1]);
    let (no_mid, no_down) = (&north[i..i + n], &north_down[i..i + n]);
    for l in 0..n {
        let new = d[l]
            * (b[l]
                + e_mid[l] * east_x[l]
                + e_west[l] * west[l]
                + no_mid[l] * up[l]
                + no_down[l] * down[l]);
        out[l] = flushed(keep[l] * mid[l] + (1.0 - keep[l]) * new);
    }
}

/// The [`LANES`] values of the slice `$s` from index `$at` as one AVX2 vector, unchecked
/// (the caller's contract: `$s` holds `$at + LANES` values at least).
#[cfg(target_arch = "x86_64")]
macro_rules! lanes {
    ($s:expr, $at:expr) => {{
        debug_assert!($at + LANES <= $s.len());
        // SAFETY: `$s` holds `$at + 8` values at least (the caller's contract); loadu reads
        // them at any alignment.
        unsafe { std::arch::x86_64::_mm256_loadu_ps($s.as_ptr().add($at)) }
    }};
}

/// `keep · mid + (1 − keep) · new`, flushed, stored to `out`: the end of a chunk's update.
///
/// # Safety
/// The processor must have AVX2 ([`super::kernels::avx2_on`]).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn store_kept(
    out: &mut [f32; LANES],
    keep: std::arch::x86_64::__m256,
    mid: std::arch::x86_64::__m256,
    new: std::arch::x86_64::__m256,
) {
    use std::arch::x86_64::{
        _mm256_add_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_storeu_ps, _mm256_sub_ps,
    };
    // SAFETY: the processor has AVX2 (the caller's contract); `out` holds 8 f32, which storeu
    // writes at any alignment.
    unsafe {
        let kept = _mm256_mul_ps(keep, mid);
        let changed = _mm256_mul_ps(_mm256_sub_ps(_mm256_set1_ps(1.0), keep), new);
        let v = x86::flushed(_mm256_add_ps(kept, changed));
        _mm256_storeu_ps(out.as_mut_ptr(), v);
    }
}

/// [`uniform`] for the [`LANES`] cells `i .. i + LANES` in AVX2, as [`coefficients_avx2`] is
/// [`coefficients`]: the same values to the bit. The compiler vectorized [`uniform`]'s chunks
/// well (34 instructions, 4 of them bounds checks): this one drops the checks (27), and makes
/// both stencils' chunks one form.
///
/// # Safety
/// The processor must have AVX2 ([`super::kernels::avx2_on`]), `row` must hold `i + LANES + 2`
/// values at least and the other inputs `i + LANES`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn uniform_avx2(
    out: &mut [f32; LANES],
    row: &[f32],
    (down, up): (&[f32], &[f32]),
    (b, d, keep): (&[f32], &[f32], &[f32]),
    i: usize,
) {
    use std::arch::x86_64::{_mm256_add_ps, _mm256_mul_ps};
    let (west, mid, east) = (lanes!(row, i), lanes!(row, i + 1), lanes!(row, i + 2));
    let (up, down) = (lanes!(up, i), lanes!(down, i));
    let (b, d, keep) = (lanes!(b, i), lanes!(d, i), lanes!(keep, i));
    // SAFETY: the processor has AVX2 (the caller's contract).
    unsafe {
        // d · (b + west + east + up + down), summed left to right.
        let sum = _mm256_add_ps(_mm256_add_ps(b, west), east);
        let sum = _mm256_add_ps(_mm256_add_ps(sum, up), down);
        store_kept(out, keep, mid, _mm256_mul_ps(d, sum));
    }
}

/// [`coefficients`] for the [`LANES`] cells `i .. i + LANES` in AVX2: the same operations in
/// the same order on 8 lanes, so the same values to the bit.
///
/// Why by hand: on a chunk of 8 cells the compiler unrolls [`coefficients`]' loop, merges the
/// loads that the shifted views share (cell `l`'s east is cell `l + 1`'s middle) into single
/// floats, and gathers them back into vectors with shuffles: 59 instructions a chunk, the
/// largest single loop of a crowd (11 % of its samples) and of the 1024² room (13 %). Here a
/// chunk is 37, and the loop's samples fell by a fifth in a crowd; the 1024² room's solve
/// took 8 % less time, the rooms map's longest field 4 % (with [`uniform_avx2`]).
///
/// Not a `#[target_feature]` function, which the compiler would not inline into its callers:
/// it is inlined into [`super::kernels::wide`]'s AVX2 function, and so are the intrinsics it
/// calls.
///
/// # Safety
/// The processor must have AVX2 ([`super::kernels::avx2_on`]), and the inputs must hold the
/// chunk's cells: `row` `i + LANES + 2` values at least, `east` `i + LANES + 1`, the others
/// `i + LANES` (they are read unchecked: a check per input and chunk was a third of its
/// instructions).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn coefficients_avx2(
    out: &mut [f32; LANES],
    row: &[f32],
    (down, up): (&[f32], &[f32]),
    (b, d, keep): (&[f32], &[f32], &[f32]),
    (east, north, north_down): (&[f32], &[f32], &[f32]),
    i: usize,
) {
    use std::arch::x86_64::{_mm256_add_ps, _mm256_mul_ps};
    let (west, mid, east_x) = (lanes!(row, i), lanes!(row, i + 1), lanes!(row, i + 2));
    let (e_west, e_mid) = (lanes!(east, i), lanes!(east, i + 1));
    let (up, down) = (lanes!(up, i), lanes!(down, i));
    let (no_mid, no_down) = (lanes!(north, i), lanes!(north_down, i));
    let (b, d, keep) = (lanes!(b, i), lanes!(d, i), lanes!(keep, i));
    // SAFETY: the processor has AVX2 (the caller's contract).
    unsafe {
        // d · (b + e_mid·east + e_west·west + n_mid·up + n_down·down), summed left to right.
        let sum = _mm256_add_ps(b, _mm256_mul_ps(e_mid, east_x));
        let sum = _mm256_add_ps(sum, _mm256_mul_ps(e_west, west));
        let sum = _mm256_add_ps(sum, _mm256_mul_ps(no_mid, up));
        let sum = _mm256_add_ps(sum, _mm256_mul_ps(no_down, down));
        store_kept(out, keep, mid, _mm256_mul_ps(d, sum));
    }
}

/// Writes the new values of the `n` cells of a row: `row` holds them with a cell either side
/// (`n + 2` values), and `new(out, row, i)` computes those of cells `i .. i + out.len()` from
/// the old values around them.
///
/// A short row is updated in place, [`LANES`] cells at a time, each chunk's new values stored
/// only after the next chunk has read its old ones: every read sees the old row, as through a
/// buffer (the same values, to the bit), without copying the buffer back, a call to `memcpy`
/// per row and pass that was 7 % of a crowd's time on the windows' rows of 61 cells. The last
/// chunk overlaps the one before it when `LANES` does not divide `n`; a cell both compute gets
/// the same value from both. Every chunk starts at most `n − LANES` cells in, and its inputs
/// are cut to the row once ([`Level::relax_row`]): `chunk(out, row, i)` computes the [`LANES`]
/// cells from `i` as `new` does (the same values), with AVX2 reading them unchecked
/// ([`uniform_avx2`], [`coefficients_avx2`]); else the compiler drops most of a chunk's bounds
/// checks, 3 or 4 left of 16, which were most of its instructions when each chunk sliced the
/// level's whole vectors (without them a crowd's run takes 16 % less time, the rooms map's
/// longest field 12 % and the 1024² room's solve 20 %, every value the same). A long row, or
/// one shorter than `LANES`, is computed into the buffer `t` and copied back (on a long row the
/// copy's call costs nothing, and the loop over the whole row is faster than chunks: measured,
/// 1024² room, 8 % slower in chunks before the AVX2 chunks, as fast with them).
#[inline(always)]
fn in_place(
    row: &mut [f32],
    t: &mut [f32],
    new: impl Fn(&mut [f32], &[f32], usize),
    chunk: impl Fn(&mut [f32; LANES], &[f32], usize),
) {
    let n = row.len() - 2;
    if !(LANES..LONG_ROW).contains(&n) {
        new(&mut t[..n], row, 0);
        row[1..n + 1].copy_from_slice(&t[..n]);
        return;
    }
    let last = n - LANES;
    let mut pending = [0.0; LANES];
    chunk(&mut pending, row, 0);
    let mut at = 0;
    while at < last {
        let i = (at + LANES).min(last);
        let mut next = [0.0; LANES];
        chunk(&mut next, row, i);
        row[at + 1..at + 1 + LANES].copy_from_slice(&pending);
        (pending, at) = (next, i);
    }
    row[at + 1..at + 1 + LANES].copy_from_slice(&pending);
}

/// The rows of a level that one wavefront covers ([`Level::sweep`]).
///
/// Two threads sweep a tall level together, exactly as one would: one the rows [`Part::Below`]
/// its middle row `mid`, the other those [`Part::Above`] it, then one the rows
/// [`Part::Between`] them. A pass `p` of Below stops `p + 1` rows short of `mid`, and one of
/// Above starts `p + 1` rows past it, so that each reads only rows it alone writes or rows no
/// one writes until both are done (`mid − 1` and `mid`), and no pass reads a row that a later
/// pass has already updated (a pass updates one colour and reads the other, so a neighbour row
/// may be one pass ahead, never two). Between then runs the passes over the triangle of rows
/// they left. Each cell gets the very update it gets in one sweep of the whole level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Part {
    /// Every row.
    Whole,
    /// The rows below `mid`.
    Below {
        /// The middle row (even).
        mid: usize,
    },
    /// The rows above `mid`; its slice of `x` starts at row `mid`.
    Above {
        /// The middle row (even).
        mid: usize,
    },
    /// The rows Below and Above leave.
    Between {
        /// The middle row (even).
        mid: usize,
    },
}

impl Part {
    /// The rows pass `p` relaxes, of `ny`.
    #[inline(always)]
    pub fn relax(self, ny: usize, p: usize) -> std::ops::Range<usize> {
        match self {
            Part::Whole => 0..ny,
            Part::Below { mid } => 0..mid.saturating_sub(p + 1),
            Part::Above { mid } => (mid + p + 1).min(ny)..ny,
            Part::Between { mid } => mid.saturating_sub(p + 1)..(mid + p + 1).min(ny),
        }
    }

    /// The rows `before` runs for: those of the part's slice of `x`.
    fn before(self, ny: usize) -> std::ops::Range<usize> {
        match self {
            Part::Whole => 0..ny,
            Part::Below { mid } => 0..mid,
            Part::Above { mid } => mid..ny,
            Part::Between { .. } => 0..0,
        }
    }

    /// The rows `after` runs for, after `passes` passes: the rows whose neighbours' last
    /// passes the part does or follows. Above's start even, so that the two rows a coarse cell
    /// restricts from are done in order (the even one sets, the odd one adds).
    pub fn after(self, ny: usize, passes: usize) -> std::ops::Range<usize> {
        let below = |mid: usize| mid.saturating_sub(passes + 1);
        let above = |mid: usize| (mid + passes + 1).next_multiple_of(2).min(ny);
        match self {
            Part::Whole => 0..ny,
            Part::Below { mid } => 0..below(mid),
            Part::Above { mid } => above(mid)..ny,
            Part::Between { mid } => below(mid)..above(mid),
        }
    }

    /// The index where the part's slice of a level's vector starts.
    pub fn origin(self, level: &Level) -> usize {
        match self {
            Part::Above { mid } => level.row_start(mid),
            _ => 0,
        }
    }
}

/// The alternating patterns `keep[q][i] = 0` if `i % 2 == q`, else 1 (see [`Level::relax_row`]).
pub type Keep = [Vec<f32>; 2];

/// The patterns of [`Keep`] for rows up to `nx` cells long.
pub fn keep_patterns(nx: usize) -> Keep {
    [0, 1].map(|q| {
        (0..nx + 1)
            .map(|i| if i % 2 == q { 0.0 } else { 1.0 })
            .collect()
    })
}

impl Level {
    /// One Gauss-Seidel update of the cells of colour `c` (`(i + j) % 2 == c`) in row `j`,
    /// for `A x = b`.
    ///
    /// Cells of one colour depend only on cells of the other, so the row is computed whole
    /// from the old values and the other colour's cells are kept (`keep`, an alternating 0/1
    /// pattern): twice the arithmetic of updating every other cell, but in straight-line loops
    /// the compiler vectorizes, which is several times faster. A short row is updated in place,
    /// a long one through the buffer `t` (see [`in_place`]).
    #[inline(always)]
    pub fn relax_row(
        &self,
        c: usize,
        j: usize,
        (x, origin): (&mut [f32], usize),
        b: &[f32],
        t: &mut [f32],
        keep: &Keep,
    ) {
        let (at, cols) = self.run(j);
        let n = cols.len();
        if n == 0 {
            return;
        }
        let keep = &keep[(c + j) % 2][cols][..n];
        // The rows below, the row and the rows above, apart: the update writes only the row.
        let (first, next) = (self.row_start(j), self.row_start(j + 1));
        let (below, rest) = x.split_at_mut(first - origin);
        let (here, above) = rest.split_at_mut(next - first);
        let row = &mut here[at.mid - 1 - first..at.mid + n + 1 - first];
        let down = &below[at.down - origin..at.down - origin + n];
        let up = &above[at.up - next..at.up - next + n];
        let (b, d) = (&b[at.mid..at.mid + n], &self.inv_diag[at.mid..at.mid + n]);
        match &self.stencil {
            Stencil::Uniform => {
                #[cfg(target_arch = "x86_64")]
                if kernels::avx2_on() {
                    return in_place(
                        row,
                        t,
                        #[inline(always)]
                        |out, row, i| uniform(out, row, (down, up), (b, d, keep), i),
                        #[inline(always)]
                        |out, row, i| {
                            // SAFETY: the processor has AVX2, checked just above; `in_place`
                            // starts a chunk at most `n − LANES` cells in, `row` holds `n + 2`
                            // values and the others `n` (cut above).
                            unsafe { uniform_avx2(out, row, (down, up), (b, d, keep), i) }
                        },
                    );
                }
                in_place(
                    row,
                    t,
                    #[inline(always)]
                    |out, row, i| uniform(out, row, (down, up), (b, d, keep), i),
                    #[inline(always)]
                    |out, row, i| uniform(out, row, (down, up), (b, d, keep), i),
                )
            }
            Stencil::Coefficients { east, north, .. } => {
                let east = &east[at.mid - 1..at.mid + n];
                let north_down = &north[at.down..at.down + n];
                let north = &north[at.mid..at.mid + n];
                let (rows, inputs, couplings) =
                    ((down, up), (b, d, keep), (east, north, north_down));
                #[cfg(target_arch = "x86_64")]
                if kernels::avx2_on() {
                    return in_place(
                        row,
                        t,
                        #[inline(always)]
                        |out, row, i| coefficients(out, row, rows, inputs, couplings, i),
                        #[inline(always)]
                        |out, row, i| {
                            // SAFETY: the processor has AVX2, checked just above; `in_place`
                            // starts a chunk at most `n − LANES` cells in, `row` holds `n + 2`
                            // values, `east` `n + 1` and the others `n` (cut above).
                            unsafe { coefficients_avx2(out, row, rows, inputs, couplings, i) }
                        },
                    );
                }
                in_place(
                    row,
                    t,
                    #[inline(always)]
                    |out, row, i| coefficients(out, row, rows, inputs, couplings, i),
                    #[inline(always)]
                    |out, row, i| coefficients(out, row, rows, inputs, couplings, i),
                )
            }
        }
    }

    /// [`Level::relax_row`] when `x` is 0: `x = b / diagonal` on colour `c`, 0 elsewhere. It
    /// reads nothing of `x`, so a cycle that starts from 0 need not clear it first. Its values
    /// are flushed as every pass's are: a later pass rewrites the whole row, the other colour
    /// included, through `flushed`, so a kept value below [`super::kernels`]'s flush level
    /// would read as itself before that pass and as 0 after it, and what a neighbour row saw
    /// would depend on the order the rows are swept in (on a deep field, where such values
    /// occur, the two threads' sweep of a tall level differed from one thread's in the last
    /// bits, and so did every solve after it).
    #[inline(always)]
    pub fn relax_row_from_zero(
        &self,
        c: usize,
        j: usize,
        (x, origin): (&mut [f32], usize),
        b: &[f32],
        keep: &Keep,
    ) {
        let (k, n) = self.row(j);
        let keep = &keep[(c + j) % 2][self.span(j)];
        let x = &mut x[k - origin..k - origin + n];
        // `keep` is `n` long already (the span's pattern), but the compiler cannot tell: sliced
        // to `n` as the others are, the loop has no bounds check and is vectorized.
        let (b, d, keep) = (&b[k..k + n], &self.inv_diag[k..k + n], &keep[..n]);
        for i in 0..n {
            x[i] = flushed((1.0 - keep[i]) * d[i] * b[i]);
        }
    }

    /// The Gauss-Seidel passes `colours` (one colour each, in order) over the rows of `part`,
    /// as a wavefront: at step `s`, pass `p` updates row `s − p`. That is exactly the passes one
    /// after another (a row's update reads only rows beside it, which every earlier pass has
    /// already updated and no later pass has touched yet), but the rows in flight stay in
    /// cache, so the level is read from memory once instead of once per pass. `before(r)` runs
    /// before any pass reads row `r`; `after(r)` once every pass is done with rows `r − 1`,
    /// `r` and `r + 1` (for the rows `part` gives them). With `zero_start`, the first pass
    /// takes `x` as 0, whatever it holds. `x` is the part's slice of the level's vector, from
    /// index [`Part::origin`].
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn sweep(
        &self,
        colours: &[usize],
        zero_start: bool,
        part: Part,
        (x, b): (&mut [f32], &[f32]),
        (t, keep): (&mut [f32], &Keep),
        mut before: impl FnMut(usize, &mut [f32]),
        mut after: impl FnMut(usize, &[f32]),
    ) {
        let (passes, ny) = (colours.len(), self.ny);
        let origin = part.origin(self);
        let (early, late) = (part.before(ny), part.after(ny, passes));
        if early.contains(&0) {
            before(0, x);
        }
        for step in 0..ny + passes + 1 {
            if early.contains(&(step + 1)) {
                before(step + 1, x);
            }
            for (p, &c) in colours.iter().enumerate() {
                if let Some(j) = step
                    .checked_sub(p)
                    .filter(|j| part.relax(ny, p).contains(j))
                {
                    if p == 0 && zero_start {
                        self.relax_row_from_zero(c, j, (x, origin), b, keep);
                    } else {
                        self.relax_row(c, j, (x, origin), b, t, keep);
                    }
                }
            }
            if let Some(j) = step.checked_sub(passes).filter(|j| late.contains(j)) {
                after(j, x);
            }
        }
    }

    /// The residual `b − A x` of row `j` into `row` (0 on inactive cells); `x` starts at
    /// index `origin`.
    #[inline(always)]
    pub fn residual_row(&self, j: usize, (x, origin): (&[f32], usize), b: &[f32], row: &mut [f32]) {
        let (at, cols) = self.run(j);
        let n = cols.len();
        let k = at.mid;
        let row = &mut row[..n];
        let x = Neighbourhood::of(x, at.from(origin), n);
        let b = &b[k..k + n];
        match &self.stencil {
            Stencil::Uniform => {
                let d = &self.inv_diag[k..k + n];
                for i in 0..n {
                    let ax = 4.0 * x.mid[i] - x.west[i] - x.east[i] - x.up[i] - x.down[i];
                    // Computed on every cell, then selected: written inside the condition,
                    // the loads were masked (`vmaskmovps`), 7 % of a crowd's samples.
                    let r = b[i] - ax;
                    row[i] = if d[i] != 0.0 { r } else { 0.0 };
                }
            }
            Stencil::Coefficients { diag, east, north } => {
                let d = &diag[k..k + n];
                let e = Neighbourhood::of(east, at, n);
                let no = Neighbourhood::of(north, at, n);
                for i in 0..n {
                    let ax = d[i] * x.mid[i]
                        - e.mid[i] * x.east[i]
                        - e.west[i] * x.west[i]
                        - no.mid[i] * x.up[i]
                        - no.down[i] * x.down[i];
                    row[i] = b[i] - ax;
                }
            }
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use crate::random::SplitMix;

    /// Values of every kind a chunk meets: ordinary ones of both signs, values about the flush
    /// level (which the update rounds to 0 or keeps), zeros of both signs, and keep patterns
    /// of 0 and 1.
    fn values(n: usize, seed: u64) -> Vec<f32> {
        let mut rng = SplitMix::new(seed);
        (0..n)
            .map(|_| {
                let u = rng.uniform() as f32;
                match rng.next_u64() % 11 {
                    0 => 0.0,
                    1 => -0.0,
                    2 => (u - 0.5) * 3e-30,
                    // Not a multiple of one power of two, so that sums round.
                    _ => (u - 0.5) * 8.0 / (1.1 + u),
                }
            })
            .collect()
    }

    /// The AVX2 chunks give the portable loops' values to the bit, at every offset of a row.
    #[test]
    fn the_avx2_chunks_give_the_loops_values_to_the_bit() {
        if !kernels::avx2_on() {
            return;
        }
        let n = 203;
        let row = values(n + 2, 1);
        let (down, up, b, d) = (values(n, 2), values(n, 3), values(n, 4), values(n, 5));
        let keep: Vec<f32> = (0..n).map(|i| (i % 2) as f32).collect();
        let (east, north, north_down) = (values(n + 1, 6), values(n, 7), values(n, 8));
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for i in 0..=n - LANES {
            let (mut by_loop, mut by_avx2) = ([0.0; LANES], [0.0; LANES]);
            uniform(&mut by_loop, &row, (&down, &up), (&b, &d, &keep), i);
            // SAFETY: AVX2 checked above; every input holds `i + LANES` values and more.
            unsafe { uniform_avx2(&mut by_avx2, &row, (&down, &up), (&b, &d, &keep), i) };
            assert_eq!(bits(&by_loop), bits(&by_avx2), "uniform at {i}");
            let couplings = (&east[..], &north[..], &north_down[..]);
            coefficients(
                &mut by_loop,
                &row,
                (&down, &up),
                (&b, &d, &keep),
                couplings,
                i,
            );
            // SAFETY: as above.
            unsafe {
                coefficients_avx2(
                    &mut by_avx2,
                    &row,
                    (&down, &up),
                    (&b, &d, &keep),
                    couplings,
                    i,
                )
            };
            assert_eq!(bits(&by_loop), bits(&by_avx2), "coefficients at {i}");
        }
    }
}
