//! A direct solve for a narrow part of the grid (a stretch of corridor, a few branches of a
//! maze): the 5-point system `4 u_k − Σ u_neighbour = b_k` on the part's cells, ordered by
//! reverse Cuthill–McKee so that its matrix is banded, factored `L D Lᵀ` within the band.
//!
//! The nested levels solve tens of thousands of such parts in a maze; a multigrid hierarchy on
//! each one's bounding box costs far more than the part (its setup, and a box several times
//! the part's cells). The band of a corridor a few cells wide is a few cells, so the factor
//! costs `n · b²` and needs no iteration. It is also accurate cell by cell: the matrix is an
//! M-matrix (positive diagonal, non-positive couplings), so every factor entry off the
//! diagonal is non-positive, and with non-negative data both triangular solves only ever add
//! non-negative terms. No cancellation: each `u_k` has a relative error of a few rounding
//! units, however small it is next to the others.

/// The part's cells' neighbours inside the part, as local indices (`u32::MAX`: none).
pub type Neighbours = [u32; 4];

/// `u` with `4 u_k − Σ u_neighbour = rhs_k` on the part, or `None` when reverse Cuthill–McKee
/// leaves a band wider than `max_band` (a wide region, for multigrid).
pub fn solve(neighbours: &[Neighbours], rhs: &[f64], max_band: usize) -> Option<Vec<f64>> {
    let n = neighbours.len();
    if n == 0 {
        return Some(Vec::new());
    }
    let Banded {
        order,
        position,
        band,
    } = reverse_cuthill_mckee(neighbours, max_band)?;
    let b = band.max(1);
    let mut x: Vec<f64> = order.iter().map(|&k| rhs[k]).collect();
    super::multigrid::kernels::wide(
        #[inline(always)]
        || {
            let (l, d) = factor(neighbours, (&order, &position), n, b);
            substitute(&l, &d, b, &mut x);
        },
    );
    let mut u = vec![0.0; n];
    for (p, &k) in order.iter().enumerate() {
        u[k] = x[p];
    }
    Some(u)
}

/// The factor `L D Lᵀ` of the part's matrix in the band order `order` (with each cell's place
/// `position`) of band `b`: `L` by columns, `l[q * b + (p − q − 1)] = L[p][q]` for `p` in
/// `q + 1 ..= q + b`, and `D`.
///
/// Row `p` of `L` is `L[p][q] = (A[p][q] − Σ_{r<q} L[p][r] D[r] L[q][r]) / D[q]`. The sums run
/// column-wise: once `L[p][r]` is known, `L[p][r] D[r]` times column `r` below it is taken off
/// every later entry of the row at once (a loop the compiler vectorizes, where the sum of each
/// entry on its own is a chain of dependent subtractions); each entry still takes its terms in
/// the order of `r`, so the factor is the row-by-row one's to the bit. Part of the crowds' time
/// (measured: 64 robots on the 1.8 m circle, 12 % of it in this factor, its bands about 40).
///
/// Each row starts at its envelope: the place of its first neighbour in the order. Left of it
/// the row of `A` is 0, and so is the row of `L` (an entry fills in only where an earlier
/// column has entries in both its rows), so the entries there take no terms: the factor is the
/// one over the whole band to the bit (the terms skipped there were `0`, and subtracting one
/// leaves a value as it was). It costs the sum of the rows' squared widths rather than `n b²`:
/// the band is the widest row, and a part's rows are mostly narrower. Measured on 64 robots
/// on the 1.8 m circle (first 15 s, the same run to the bit): the coarse windows' nested
/// levels, mostly such parts, 3.75 s against 5.06 s of the 15 s (two threads' time summed).
#[inline(always)]
fn factor(
    neighbours: &[Neighbours],
    (order, position): (&[usize], &[usize]),
    n: usize,
    b: usize,
) -> (Vec<f64>, Vec<f64>) {
    let mut l = vec![0.0; n * b];
    // Each row's envelope: the place of its first entry left of the diagonal (`p`: none).
    let mut envelope = vec![0; n];
    for (p, &k) in order.iter().enumerate() {
        envelope[p] = p;
        for &m in neighbours[k].iter().filter(|&&m| m != u32::MAX) {
            let q = position[m as usize];
            if q < p {
                l[q * b + (p - q - 1)] = -1.0;
                envelope[p] = envelope[p].min(q);
            }
        }
    }
    let mut d = vec![0.0; n];
    // Row p's entries left of the diagonal as they are reduced: row[q − first].
    let mut row = vec![0.0; b];
    for p in 0..n {
        let first = envelope[p];
        for q in first..p {
            row[q - first] = l[q * b + (p - q - 1)];
        }
        let mut dp = 4.0;
        for r in first..p {
            let lpr = row[r - first] / d[r];
            l[r * b + (p - r - 1)] = lpr;
            let ld = lpr * d[r];
            // Column r's entries in rows r + 1 .. p that its band holds.
            let end = p.min(r + b + 1);
            let column = &l[r * b..r * b + (end - r - 1)];
            for (e, lqr) in row[r + 1 - first..end - first].iter_mut().zip(column) {
                *e -= ld * lqr;
            }
        }
        for r in first..p {
            let lr = l[r * b + (p - r - 1)];
            dp -= lr * lr * d[r];
        }
        d[p] = dp;
    }
    (l, d)
}

/// `L D Lᵀ x = y` in place, in band order, with `l` and `d` from [`factor`]. `L y' = y` runs
/// column-wise (each entry still takes its terms in order), `Lᵀ x = z` row-wise, along `L`'s
/// columns.
#[inline(always)]
fn substitute(l: &[f64], d: &[f64], b: usize, x: &mut [f64]) {
    let n = x.len();
    for r in 0..n {
        let (xr, end) = (x[r], n.min(r + b + 1));
        for (xq, lqr) in x[r + 1..end].iter_mut().zip(&l[r * b..]) {
            *xq -= lqr * xr;
        }
    }
    for p in 0..n {
        x[p] /= d[p];
    }
    for p in (0..n).rev() {
        let end = n.min(p + b + 1);
        let mut s = x[p];
        for (lqp, xq) in l[p * b..p * b + (end - p - 1)].iter().zip(&x[p + 1..end]) {
            s -= lqp * xq;
        }
        x[p] = s;
    }
}

/// Whether `reached` cells within `depth` steps of one cell prove that every order of them has
/// a band wider than `max_band`: in an order of band `b`, the cells within `d` steps of a cell
/// lie within `b · d` places of it, so there are at most `2 b d + 1` of them.
///
/// [`solve`] refuses a part on this bound from its first cell, within a few thousand cells of
/// a wide one; a caller that searches the part breadth first from that cell anyway (the nested
/// levels, finding the parts of a band) can tell by the same bound, before building anything
/// for [`solve`], that it would refuse.
pub fn proves_wider(reached: usize, depth: usize, max_band: usize) -> bool {
    reached > max_band.saturating_mul(2 * depth).saturating_add(1)
}

/// A part's cells in band order.
struct Banded {
    /// The cells in order.
    order: Vec<usize>,
    /// Each cell's place in `order`.
    position: Vec<usize>,
    /// The largest distance in `order` between two neighbours.
    band: usize,
}

/// The cells in reverse Cuthill–McKee order: breadth-first from a pseudo-peripheral cell (the
/// last one reached from the first cell), neighbours by increasing degree, then reversed; `None`
/// as soon as its band is known to exceed `max_band`.
///
/// A wide region is refused within a few thousand cells, not after two passes over all of it
/// (a room's part is a hundred thousand cells):
/// - in any order of band `b`, the cells within `d` steps of a cell lie within `b · d` places of
///   it, so a search that finds more than `2 b d + 1` of them proves every order's band wider
///   ([`proves_wider`]);
/// - in the second search the order is the final one (reversed, which keeps the band), and
///   every pair of neighbours has its places once the first of them is visited, so the band is
///   known exactly as the search goes.
fn reverse_cuthill_mckee(neighbours: &[Neighbours], max_band: usize) -> Option<Banded> {
    let n = neighbours.len();
    let degree = |k: usize| neighbours[k].iter().filter(|&&m| m != u32::MAX).count();
    let mut position = vec![usize::MAX; n];
    // The order from `start` and its band (exact when `track`), or `None` past `max_band`.
    let mut breadth_first = |start: usize, track: bool| {
        position.fill(usize::MAX);
        let mut order = Vec::with_capacity(n);
        position[start] = 0;
        order.push(start);
        let (mut head, mut band) = (0, 0);
        // The cells within `depth` steps are `order[..reached]`, while the part is connected.
        let (mut depth, mut reached, mut connected) = (0, 1, true);
        while head < order.len() {
            let k = order[head];
            head += 1;
            let mut next = [(usize::MAX, usize::MAX); 4];
            let mut count = 0;
            for &m in neighbours[k].iter().filter(|&&m| m != u32::MAX) {
                if position[m as usize] == usize::MAX {
                    next[count] = (degree(m as usize), m as usize);
                    count += 1;
                }
            }
            next[..count].sort_unstable();
            for &(_, m) in &next[..count] {
                position[m] = order.len();
                order.push(m);
            }
            if track {
                for &m in neighbours[k].iter().filter(|&&m| m != u32::MAX) {
                    band = band.max(position[m as usize].abs_diff(head - 1));
                }
                if band > max_band {
                    return None;
                }
            }
            if connected && head == reached {
                // Every cell within `depth` steps is visited: `order` holds those within
                // `depth + 1`.
                (depth, reached) = (depth + 1, order.len());
                if proves_wider(reached, depth, max_band) {
                    return None;
                }
            }
            // A part is connected; should it not be, the rest follows from its first cell.
            if head == order.len()
                && order.len() < n
                && let Some(rest) = (0..n).find(|&m| position[m] == usize::MAX)
            {
                position[rest] = order.len();
                order.push(rest);
                connected = false;
            }
        }
        Some((order, band))
    };
    let (first, _) = breadth_first(0, false)?;
    let far = *first.last().expect("a cell");
    let (mut order, band) = breadth_first(far, true)?;
    order.reverse();
    for (p, &k) in order.iter().enumerate() {
        position[k] = p;
    }
    Some(Banded {
        order,
        position,
        band,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The row-by-row factor and solve that `solve` replaced (see [`factor`]), for the
    /// bit-for-bit comparison.
    fn row_by_row(neighbours: &[Neighbours], rhs: &[f64], max_band: usize) -> Option<Vec<f64>> {
        let n = neighbours.len();
        let Banded {
            order,
            position,
            band,
        } = reverse_cuthill_mckee(neighbours, max_band)?;
        let b = band.max(1);
        // l[p * b + (p − q − 1)] = L[p][q] for q in p − b .. p; a[…] the same of the matrix.
        let mut l = vec![0.0; n * b];
        for (p, &k) in order.iter().enumerate() {
            for &m in neighbours[k].iter().filter(|&&m| m != u32::MAX) {
                let q = position[m as usize];
                if q < p {
                    l[p * b + (p - q - 1)] = -1.0;
                }
            }
        }
        let mut d = vec![0.0; n];
        for p in 0..n {
            let first = p.saturating_sub(b);
            for q in first..p {
                let mut s = l[p * b + (p - q - 1)];
                for r in first.max(q.saturating_sub(b))..q {
                    s -= l[p * b + (p - r - 1)] * d[r] * l[q * b + (q - r - 1)];
                }
                l[p * b + (p - q - 1)] = s / d[q];
            }
            let mut dp = 4.0;
            for r in first..p {
                let lr = l[p * b + (p - r - 1)];
                dp -= lr * lr * d[r];
            }
            d[p] = dp;
        }
        // L y = rhs, D z = y, Lᵀ x = z, in band order.
        let mut x: Vec<f64> = order.iter().map(|&k| rhs[k]).collect();
        for p in 0..n {
            let mut s = x[p];
            for r in p.saturating_sub(b)..p {
                s -= l[p * b + (p - r - 1)] * x[r];
            }
            x[p] = s;
        }
        for p in 0..n {
            x[p] /= d[p];
        }
        for p in (0..n).rev() {
            let mut s = x[p];
            for q in p + 1..(p + b + 1).min(n) {
                s -= l[q * b + (q - p - 1)] * x[q];
            }
            x[p] = s;
        }
        let mut u = vec![0.0; n];
        for (p, &k) in order.iter().enumerate() {
            u[k] = x[p];
        }
        Some(u)
    }

    /// The column-wise factor and solve give the row-by-row ones' values to the bit (corridors
    /// of several widths, so bands of 1 to 9).
    #[test]
    fn the_column_wise_factor_is_the_row_by_row_one_to_the_bit() {
        for width in 1..10 {
            let nb = corridor(50, width);
            let rhs: Vec<f64> = (0..nb.len())
                .map(|k| ((k * 37) % 11) as f64 / 11.0 + 1e-3)
                .collect();
            let bits = |u: Vec<f64>| u.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(solve(&nb, &rhs, 64).unwrap()),
                bits(row_by_row(&nb, &rhs, 64).unwrap()),
                "width {width}"
            );
        }
    }

    /// The factor from each row's envelope gives the whole band's values to the bit on parts
    /// whose rows are mostly narrower than the band, where the envelope saves work: a ring (the
    /// deep cells behind a crowd in a coarse window), a comb and an L of corridors (the comb's
    /// cells odd in number).
    #[test]
    fn the_factor_from_the_envelopes_is_the_whole_bands_to_the_bit() {
        let ring = |i: usize, j: usize| {
            let r2 = (i as f64 - 20.0).powi(2) + (j as f64 - 20.0).powi(2);
            (196.0..=361.0).contains(&r2)
        };
        let comb = |i: usize, j: usize| j == 0 || (i.is_multiple_of(3) && j < 9);
        let l_shape = |i: usize, j: usize| i < 4 || j < 3;
        for (name, nb) in [
            ("ring", masked(41, 41, ring)),
            ("comb", masked(41, 9, comb)),
            ("L", masked(30, 30, l_shape)),
        ] {
            let Banded {
                order,
                position,
                band,
            } = reverse_cuthill_mckee(&nb, usize::MAX).unwrap();
            // Each row's width from its first neighbour to the diagonal.
            let widths: usize = (order.iter().enumerate())
                .map(|(p, &k)| {
                    let first = (nb[k].iter().filter(|&&m| m != u32::MAX))
                        .map(|&m| position[m as usize])
                        .fold(p, usize::min);
                    (p - first).pow(2)
                })
                .sum();
            // (The ring's rows: 42,050 against 101,920; the L's 4,169 against 9,702.)
            assert!(
                4 * widths < 3 * nb.len() * band * band,
                "{name}: the envelope saves nothing"
            );
            let rhs: Vec<f64> = (0..nb.len())
                .map(|k| ((k * 37) % 11) as f64 / 11.0 + 1e-3)
                .collect();
            let bits = |u: Vec<f64>| u.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(solve(&nb, &rhs, usize::MAX).unwrap()),
                bits(row_by_row(&nb, &rhs, usize::MAX).unwrap()),
                "{name}"
            );
        }
    }

    /// The cells `(i, j)` of an `nx × ny` box where `inside` holds, as local neighbour lists
    /// in row order.
    fn masked(nx: usize, ny: usize, inside: impl Fn(usize, usize) -> bool) -> Vec<Neighbours> {
        let cells: Vec<(usize, usize)> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .filter(|&(i, j)| inside(i, j))
            .collect();
        let local = |i: usize, j: usize| {
            if i < nx && j < ny && inside(i, j) {
                let found = cells.binary_search_by_key(&(j, i), |&(a, b)| (b, a));
                found.expect("a cell inside is listed") as u32
            } else {
                u32::MAX
            }
        };
        (cells.iter())
            .map(|&(i, j)| {
                [
                    i.checked_sub(1).map_or(u32::MAX, |i| local(i, j)),
                    local(i + 1, j),
                    j.checked_sub(1).map_or(u32::MAX, |j| local(i, j)),
                    local(i, j + 1),
                ]
            })
            .collect()
    }

    /// A corridor of `len` cells, `width` wide, as local neighbour lists, cell `(i, j)` at
    /// `j * len + i`.
    fn corridor(len: usize, width: usize) -> Vec<Neighbours> {
        masked(len, width, |_, _| true)
    }

    /// A corridor one cell wide, fed 1 at its first cell: `u` falls by `2 − √3` per cell, and
    /// the direct solve keeps that ratio to rounding even 480 cells down, at 1e-274.
    #[test]
    fn a_long_corridor_is_solved_to_relative_precision_at_every_cell() {
        let n = 500;
        let mut rhs = vec![0.0; n];
        rhs[0] = 1.0;
        let u = solve(&corridor(n, 1), &rhs, 8).unwrap();
        let rate = 2.0 - 3f64.sqrt();
        for k in 1..n - 20 {
            assert!(
                (u[k] / u[k - 1] / rate - 1.0).abs() < 1e-12,
                "cell {k}: {}",
                u[k]
            );
        }
        assert!(u[n - 21] < 1e-270 && u[n - 21] > 0.0, "{}", u[n - 21]);
    }

    /// The solution satisfies its equations, and a region too wide for the band is refused.
    #[test]
    fn the_residual_vanishes_and_wide_regions_are_left_to_multigrid() {
        let (len, width) = (60, 5);
        let nb = corridor(len, width);
        let rhs: Vec<f64> = (0..len * width)
            .map(|k| ((k * 37) % 11) as f64 / 11.0)
            .collect();
        let u = solve(&nb, &rhs, 16).unwrap();
        for k in 0..nb.len() {
            let sum: f64 = nb[k]
                .iter()
                .filter(|&&m| m != u32::MAX)
                .map(|&m| u[m as usize])
                .sum();
            assert!((4.0 * u[k] - sum - rhs[k]).abs() < 1e-12, "cell {k}");
        }
        assert!(solve(&corridor(60, 40), &vec![1.0; 2400], 16).is_none());
    }

    /// Refusing early never refuses a part whose order fits: for corridors of every width and a
    /// comb (teeth one cell wide off a spine), `solve` succeeds exactly when the band of the
    /// full ordering is at most `max_band`.
    #[test]
    fn a_part_is_refused_exactly_when_its_band_is_too_wide() {
        let mut shapes: Vec<Vec<Neighbours>> = (1..12).map(|w| corridor(40, w)).collect();
        // A comb: a spine along j = 0 of 30 cells, a tooth of 6 cells up from every other one.
        shapes.push(masked(30, 7, |i, j| j == 0 || i.is_multiple_of(2)));
        // A path of 41 cells numbered from its middle: the search from its first cell meets
        // the bound's limit at every step (2 d + 1 cells within d steps, band 1).
        let at = |i: usize| (i as u32 + 21) % 41;
        shapes.push(
            (0..41)
                .map(|k| (k + 20) % 41)
                .map(|i| {
                    [
                        if i > 0 { at(i - 1) } else { u32::MAX },
                        if i < 40 { at(i + 1) } else { u32::MAX },
                        u32::MAX,
                        u32::MAX,
                    ]
                })
                .collect(),
        );
        for nb in &shapes {
            let band = reverse_cuthill_mckee(nb, usize::MAX).unwrap().band;
            let rhs = vec![1.0; nb.len()];
            for max_band in 0..band + 3 {
                assert_eq!(
                    solve(nb, &rhs, max_band).is_some(),
                    band <= max_band,
                    "{} cells, band {band}, max {max_band}",
                    nb.len()
                );
            }
        }
    }
}
