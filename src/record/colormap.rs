//! The potential as a picture: `log10(1 - V)` through a perceptual colour map.

use super::palette::{BLOCKED, UNREACHABLE};

use crate::field::{HarmonicField, JointField, PoseField, ScaledW};

/// The agent's field as RGB bytes, row `j` of the image being grid row `j` (y up in the world;
/// the recording's transforms put it the right way up), and the image's `[width, height]`.
pub fn potential_image(field: &HarmonicField) -> (Vec<u8>, [u32; 2]) {
    let grid = *field.grid();
    let w = field.sampler.values();
    let reachable = field.sampler.reachable_cells();
    // log10(1 − V) once per cell (NaN where nothing is drawn from it).
    let logs: Vec<f64> = (0..grid.len())
        .map(|k| {
            if field.blocked[k] || !reachable[k] {
                f64::NAN
            } else {
                w.log10(k)
            }
        })
        .collect();
    let lo = logs
        .iter()
        .copied()
        .filter(|l| l.is_finite())
        .fold(0.0_f64, f64::min);
    let mut rgb = Vec::with_capacity(grid.len() * 3);
    for (k, &l) in logs.iter().enumerate() {
        // A reachable cell at `W = 0` lies deeper than its run needed it solved (see
        // `HarmonicField::solve_among`): it takes the deepest colour.
        let colour = if field.blocked[k] {
            BLOCKED
        } else if l.is_nan() {
            UNREACHABLE
        } else if l == f64::NEG_INFINITY {
            viridis(0.0)
        } else {
            let t = if lo < 0.0 { 1.0 - l / lo } else { 1.0 };
            viridis(t)
        };
        rgb.extend_from_slice(&colour);
    }
    (rgb, [grid.nx as u32, grid.ny as u32])
}

/// The slice of a shaped agent's field that holds `theta`, as `potential_image` draws a
/// plane field (colours scaled to the deepest cell of the whole field, so that slices compare).
pub fn pose_slice_image(field: &PoseField, theta: f64, deepest: f64) -> (Vec<u8>, [u32; 2]) {
    let grid = *field.grid();
    let k = field.mask.slice_of(theta);
    let logs = field.slice_log10(theta);
    let mut rgb = Vec::with_capacity(grid.len() * 3);
    for (c, &l) in logs.iter().enumerate() {
        let colour = if field.mask.blocked[k * grid.len() + c] {
            BLOCKED
        } else if !l.is_finite() {
            UNREACHABLE
        } else {
            let t = if deepest < 0.0 {
                1.0 - l / deepest
            } else {
                1.0
            };
            viridis(t)
        };
        rgb.extend_from_slice(&colour);
    }
    (rgb, [grid.nx as u32, grid.ny as u32])
}

/// The deepest `log10(1 − V)` of a shaped agent's field (0 if it is 1 everywhere).
pub fn deepest(field: &PoseField) -> f64 {
    deepest_of(&field.w, &field.reachable)
}

/// The deepest `log10(1 − V)` of an arm's joint-space field (0 if it is 1 everywhere).
pub fn joint_deepest(field: &JointField) -> f64 {
    deepest_of(&field.w, &field.reachable)
}

/// The deepest `log10 W` over the `reachable` cells.
fn deepest_of(w: &ScaledW, reachable: &[bool]) -> f64 {
    (0..w.len())
        .filter(|&c| reachable[c])
        .map(|c| w.log10(c))
        .filter(|l| l.is_finite())
        .fold(0.0, f64::min)
}

/// The joints an arm's joint-space picture shows: both of two joints; the last two of three
/// (a slice at the first joint's angle).
pub fn joint_plane(field: &JointField) -> [usize; 2] {
    let n = field.mask.axes.len();
    [n - 2, n - 1]
}

/// An arm's joint-space field as RGB bytes over [`joint_plane`]'s joints, at the first
/// joint's cell `slice` for three joints (ignored for two), and the image's `[width, height]`:
/// pixel `(i, j)` is the cell of those joints' cells `i, j` (the first of them along the row),
/// coloured as `potential_image` does, scaled to `deepest` (so that slices compare).
pub fn joint_image(field: &JointField, slice: usize, deepest: f64) -> (Vec<u8>, [u32; 2]) {
    let [a, b] = joint_plane(field);
    let (wide, high) = (field.mask.axes[a].cells, field.mask.axes[b].cells);
    let mut rgb = Vec::with_capacity(wide * high * 3);
    for j in 0..high {
        for i in 0..wide {
            let c = if field.mask.axes.len() == 3 {
                field.mask.index(&[slice, i, j])
            } else {
                field.mask.index(&[i, j])
            };
            let colour = if field.mask.blocked[c] {
                BLOCKED
            } else if !field.reachable[c] {
                UNREACHABLE
            } else {
                let l = field.w.log10(c);
                viridis(if deepest < 0.0 {
                    1.0 - l / deepest
                } else {
                    1.0
                })
            };
            rgb.extend_from_slice(&colour);
        }
    }
    (rgb, [wide as u32, high as u32])
}

/// The viridis colour map at `t ∈ [0, 1]` (piecewise linear through 9 of its stops).
pub fn viridis(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    let mix = |c: usize| (STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f).round() as u8;
    [mix(0), mix(1), mix(2)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_clamps() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(7.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
    }
}
