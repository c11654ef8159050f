//! The smoother: red-black Gauss-Seidel on one level, run as a wavefront over its rows, and the
//! residual of a row. Every function here runs inside [`super::kernels::wide`], so each is
//! `#[inline(always)]` (the inlining rule of `kernels.rs`).

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
/// are cut to the row once ([`Level::relax_row`]), so the compiler drops most of a chunk's
/// bounds checks: 3 or 4 are left of 16, which were most of its instructions when each chunk
/// sliced the level's whole vectors (without them a crowd's run takes 16 % less time, the
/// rooms map's longest field 12 % and the 1024² room's solve 20 %, every value the same;
/// cutting the inputs as `[k..][..n]` removes no more). A long row, or one shorter than
/// `LANES`, is computed into the buffer `t` and copied back (on a long row the copy's call
/// costs nothing, and the loop over the whole row is faster than chunks: measured, 1024² room,
/// 8 % slower in chunks).
#[inline(always)]
fn in_place(row: &mut [f32], t: &mut [f32], new: impl Fn(&mut [f32], &[f32], usize)) {
    let n = row.len() - 2;
    if !(LANES..LONG_ROW).contains(&n) {
        new(&mut t[..n], row, 0);
        row[1..n + 1].copy_from_slice(&t[..n]);
        return;
    }
    let last = n - LANES;
    let mut pending = [0.0; LANES];
    new(&mut pending, row, 0);
    let mut at = 0;
    while at < last {
        let i = (at + LANES).min(last);
        let mut next = [0.0; LANES];
        new(&mut next, row, i);
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
            Stencil::Uniform => in_place(
                row,
                t,
                #[inline(always)]
                |out, row, i| uniform(out, row, (down, up), (b, d, keep), i),
            ),
            Stencil::Coefficients { east, north, .. } => {
                let east = &east[at.mid - 1..at.mid + n];
                let north_down = &north[at.down..at.down + n];
                let north = &north[at.mid..at.mid + n];
                in_place(
                    row,
                    t,
                    #[inline(always)]
                    |out, row, i| {
                        coefficients(
                            out,
                            row,
                            (down, up),
                            (b, d, keep),
                            (east, north, north_down),
                            i,
                        )
                    },
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
