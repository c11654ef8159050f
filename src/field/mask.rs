//! Rasterizing the walls into a configuration-space mask: a cell is blocked when its centre is
//! closer than the agent's radius to a wall (or to the edge of the box), i.e. when a disc of
//! that radius centred there would overlap something.

use super::grid::Grid;
use crate::world::WallShape;

/// `blocked[grid.index(i, j)]` for every cell, for a disc of `radius` metres in a box of `size`.
pub fn rasterize(grid: &Grid, size: [f64; 2], walls: &[WallShape], radius: f64) -> Vec<bool> {
    rasterize_sensed(grid, size, walls, radius, &[])
}

/// Like [`rasterize`], with wall `k`'s boundary moved out by `offsets[k]` metres (in where
/// negative; missing offsets are zero): the mask of walls sensed with errors. A cell is blocked
/// when its signed distance to a wall is below `radius + offset`.
pub fn rasterize_sensed(
    grid: &Grid,
    size: [f64; 2],
    walls: &[WallShape],
    radius: f64,
    offsets: &[f64],
) -> Vec<bool> {
    let mut blocked = vec![false; grid.len()];
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let [x, y] = grid.center(i, j);
            if x < radius || y < radius || x > size[0] - radius || y > size[1] - radius {
                blocked[grid.index(i, j)] = true;
            }
        }
    }
    for (n, wall) in walls.iter().enumerate() {
        let offset = offsets.get(n).copied().unwrap_or(0.0);
        let reach = radius + offset;
        // Only the cells near the wall's bounding box can be within `reach` of it.
        let radius = reach.max(0.0);
        let aabb = wall.shape.compute_aabb(&wall.pose);
        let lo = [
            f64::from(aabb.mins.x) - radius,
            f64::from(aabb.mins.y) - radius,
        ];
        let hi = [
            f64::from(aabb.maxs.x) + radius,
            f64::from(aabb.maxs.y) + radius,
        ];
        let (ir, jr) = grid.cells_in(lo, hi);
        for j in jr {
            for i in ir.clone() {
                let k = grid.index(i, j);
                if !blocked[k] {
                    let [x, y] = grid.center(i, j);
                    // The sensed case needs the signed distance (a thinner wall shrinks
                    // inside); the exact case keeps parry's solid distance query, which
                    // differs from the projection in the last f32 bits at the mask's edge.
                    blocked[k] = if offset == 0.0 {
                        wall.distance_to_point(x, y) < reach
                    } else {
                        wall.signed_distance_to_point(x, y) < reach
                    };
                }
            }
        }
    }
    blocked
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Wall, wall_shape};

    #[test]
    fn sensed_offsets_grow_and_shrink_a_wall() {
        let size = [4.0, 4.0];
        let grid = Grid::covering(size, 0.05);
        let wall = wall_shape(&Wall::Box {
            center: [2.0, 2.0],
            half_extents: [0.5, 0.5],
            angle: 0.0,
        })
        .unwrap();
        let count = |offset: f64| {
            let blocked =
                rasterize_sensed(&grid, size, std::slice::from_ref(&wall), 0.2, &[offset]);
            // Only the cells around the wall, not the box edges.
            (0..grid.len())
                .filter(|&k| {
                    let [x, y] = grid.center(k % grid.nx, k / grid.nx);
                    blocked[k] && (x - 2.0).abs() < 1.5 && (y - 2.0).abs() < 1.5
                })
                .count()
        };
        let (exact, grown, shrunk) = (count(0.0), count(0.3), count(-0.5));
        assert!(grown > exact && exact > shrunk, "{grown} {exact} {shrunk}");
        // Shrunk by 0.5 with a 0.2 disc: the blocked square is 0.4 m across inside the wall.
        assert!(
            (shrunk as f64 * 0.05 * 0.05 - 0.16).abs() < 0.05,
            "{shrunk}"
        );
    }

    #[test]
    fn a_disc_wall_blocks_exactly_the_cells_within_radius_plus_wall_radius() {
        let size = [2.0, 2.0];
        let grid = Grid::covering(size, 0.05);
        let wall = wall_shape(&Wall::Disc {
            center: [1.0, 1.0],
            radius: 0.3,
        })
        .unwrap();
        let blocked = rasterize(&grid, size, &[wall], 0.2);
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let [x, y] = grid.center(i, j);
                let near_edge = x < 0.2 || y < 0.2 || x > 1.8 || y > 1.8;
                let near_disc = (x - 1.0).hypot(y - 1.0) < 0.5;
                // Away from the exact boundary (f32 geometry), the mask is the analytic one.
                if ((x - 1.0).hypot(y - 1.0) - 0.5).abs() > 1e-4 {
                    assert_eq!(
                        blocked[grid.index(i, j)],
                        near_edge || near_disc,
                        "cell {i},{j}"
                    );
                }
            }
        }
    }
}
