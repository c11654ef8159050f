//! The static geometry: the box, the walls and a map (one image, not thousands of outlines),
//! drawn y-up (the `world` and `agents` roots carry a transform that flips Rerun's y-down 2-D
//! views about the box).

use rerun::RecordingStream;

use super::names::{AGENTS, BOX, MAP, WALLS, WORLD};
use super::palette;
use crate::world::map::{CellState, Occupancy};
use crate::world::{Wall, World, drawn_walls};

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
        )])
        .with_colors([palette::rerun(palette::BOX)]),
    )?;
    let walls: Vec<Vec<[f32; 2]>> = drawn_walls(world).iter().map(outline).collect();
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

/// The closed outline of a rotated box.
fn outline_box(center: [f64; 2], half: [f64; 2], angle: f64) -> Vec<[f32; 2]> {
    let (s, c) = angle.sin_cos();
    [
        [-1.0, -1.0],
        [1.0, -1.0],
        [1.0, 1.0],
        [-1.0, 1.0],
        [-1.0, -1.0],
    ]
    .iter()
    .map(|[sx, sy]| {
        let (x, y) = (sx * half[0], sy * half[1]);
        f32x2([center[0] + c * x - s * y, center[1] + s * x + c * y])
    })
    .collect()
}

/// The closed outline of a wall.
fn outline(wall: &Wall) -> Vec<[f32; 2]> {
    const ARC: usize = 16;
    let arc = |center: [f64; 2], r: f64, from: f64, to: f64| -> Vec<[f32; 2]> {
        (0..=ARC)
            .map(|k| {
                let a = from + (to - from) * k as f64 / ARC as f64;
                f32x2([center[0] + r * a.cos(), center[1] + r * a.sin()])
            })
            .collect()
    };
    match wall {
        Wall::Box {
            center,
            half_extents,
            angle,
        } => outline_box(*center, *half_extents, *angle),
        Wall::Disc { center, radius } => arc(*center, *radius, 0.0, std::f64::consts::TAU),
        Wall::Segment { a, b, thickness } => {
            let r = thickness / 2.0;
            let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
            let half_turn = std::f64::consts::FRAC_PI_2;
            let mut points = arc(*b, r, heading - half_turn, heading + half_turn);
            points.extend(arc(*a, r, heading + half_turn, heading + 3.0 * half_turn));
            points.push(points[0]);
            points
        }
        Wall::Polygon { points } => {
            let mut out: Vec<[f32; 2]> = points.iter().map(|p| f32x2(*p)).collect();
            out.push(out[0]);
            out
        }
    }
}
