//! The static geometry: the box, the walls and a map (one image, not thousands of outlines),
//! drawn y-up (the `world` and `agents` roots carry a transform that flips Rerun's y-down 2-D
//! views about the box).

use rerun::RecordingStream;

use super::names::{AGENTS, BOX, MAP, WALLS, WORLD};
use super::palette;
use crate::world::map::{CellState, Occupancy};
use crate::world::{World, drawn_walls, outline_box, wall_outline};

/// Logs the flip, the box and the walls (static).
pub fn log_setup(rec: &RecordingStream, world: &World) -> Result<(), rerun::RecordingStreamError> {
    let ([x0, y0], [x1, y1]) = world.bounds();
    // y' = (y0 + y1) − y: the box stays where it is, upside down for Rerun's y-down views.
    let flip = rerun::Transform3D::from_translation_scale(
        [0.0, (y0 + y1) as f32, 0.0],
        rerun::Scale3D::from([1.0, -1.0, 1.0]),
    );
    rec.log_static(WORLD, &flip)?;
    rec.log_static(AGENTS, &flip)?;
    rec.log_static(
        BOX,
        &rerun::LineStrips2D::new([outline_box(
            [(x0 + x1) / 2.0, (y0 + y1) / 2.0],
            [(x1 - x0) / 2.0, (y1 - y0) / 2.0],
            0.0,
        )
        .into_iter()
        .map(f32x2)])
        .with_colors([palette::rerun(palette::BOX)]),
    )?;
    let walls: Vec<Vec<[f32; 2]>> = drawn_walls(world)
        .iter()
        .map(|w| wall_outline(w).into_iter().map(f32x2).collect())
        .collect();
    rec.log_static(
        WALLS,
        &rerun::LineStrips2D::new(walls)
            .with_colors([palette::rerun(palette::WALL)])
            .with_radii([0.02]),
    )?;
    if let Some(map) = &world.loaded_map {
        let m = &map.occupancy;
        rec.log_static(
            MAP,
            &rerun::Transform3D::from_translation_scale(
                [m.origin[0] as f32, m.origin[1] as f32, 0.0],
                rerun::Scale3D::from([m.cell as f32, m.cell as f32, 1.0]),
            ),
        )?;
        rec.log_static(
            MAP,
            &rerun::Image::from_rgba32(map_image(m), [m.width as u32, m.height as u32])
                .with_draw_order(-5.0),
        )?;
    }
    Ok(())
}

/// The map as RGBA, row `j` of the image being map row `j` (y up; the `world` transform puts
/// it the right way up): walls opaque, unknown cells half transparent, free cells clear (the
/// field image shows through).
fn map_image(m: &Occupancy) -> Vec<u8> {
    m.cells
        .iter()
        .flat_map(|c| match c {
            CellState::Blocked => palette::rgba(palette::MAP_WALL, 255),
            CellState::Unknown => palette::rgba(palette::MAP_UNKNOWN, 160),
            CellState::Free => [0, 0, 0, 0],
        })
        .collect()
}

/// A point in f32, for Rerun.
pub fn f32x2(p: [f64; 2]) -> [f32; 2] {
    [p[0] as f32, p[1] as f32]
}
