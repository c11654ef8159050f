//! A still picture of an agent's field (`nadf field --png`): the potential `log10(1 − V)` as
//! colour, streamlines of the guidance from a lattice of seeds, the kinematic path from the
//! start, and the start and target. No fonts needed.

use super::colormap::potential_image;
use super::palette;
use crate::field::HarmonicField;
use crate::world::Agent;

/// The picture's longer side, in pixels (at least one pixel per cell).
const SIDE: usize = 900;
/// Seeds per side of the box for the streamlines.
const SEEDS: usize = 14;

/// RGB bytes, top row first, and the picture's `(width, height)`.
pub fn field_picture(field: &HarmonicField, agent: &Agent) -> (Vec<u8>, u32, u32) {
    let grid = *field.grid();
    let scale = (SIDE / grid.nx.max(grid.ny)).max(1);
    let (width, height) = (grid.nx * scale, grid.ny * scale);
    let (cells, _) = potential_image(field);
    let mut rgb = vec![0u8; width * height * 3];
    for y in 0..height {
        let j = grid.ny - 1 - y / scale;
        for x in 0..width {
            let k = grid.index(x / scale, j) * 3;
            rgb[(y * width + x) * 3..][..3].copy_from_slice(&cells[k..k + 3]);
        }
    }
    let pixel = |p: [f64; 2]| -> Option<(usize, usize)> {
        let fx = (p[0] - grid.origin[0]) / grid.cell * scale as f64;
        let fy = height as f64 - (p[1] - grid.origin[1]) / grid.cell * scale as f64;
        (fx >= 0.0 && fy >= 0.0 && fx < width as f64 && fy < height as f64)
            .then_some((fx as usize, fy as usize))
    };
    let mut dot = |p: [f64; 2], radius: isize, colour: [u8; 3]| {
        if let Some((cx, cy)) = pixel(p) {
            for dy in -radius..=radius {
                for dx in -radius..=radius {
                    let (x, y) = (cx as isize + dx, cy as isize + dy);
                    if dx * dx + dy * dy <= radius * radius
                        && (0..width as isize).contains(&x)
                        && (0..height as isize).contains(&y)
                    {
                        rgb[(y as usize * width + x as usize) * 3..][..3].copy_from_slice(&colour);
                    }
                }
            }
        }
    };
    let reachable = field.sampler.reachable_cells();
    let stride = (grid.nx.max(grid.ny) / SEEDS).max(1);
    let max_length = 4.0 * (grid.nx + grid.ny) as f64 * grid.cell;
    for j in (stride / 2..grid.ny).step_by(stride) {
        for i in (stride / 2..grid.nx).step_by(stride) {
            if reachable[grid.index(i, j)] {
                let line = field.streamline_within(grid.center(i, j), max_length);
                for p in &line.points {
                    dot(*p, 0, palette::STREAMLINE);
                }
            }
        }
    }
    for p in &field.streamline(agent.start).points {
        dot(*p, 1, palette::KINEMATIC);
    }
    dot(agent.start, 5, palette::START);
    dot(agent.target, 5, palette::TARGET);
    (rgb, width as u32, height as u32)
}
