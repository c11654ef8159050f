//! Rasterizing the walls into a configuration-space mask: a cell is blocked when its centre is
//! closer than the agent's radius to a wall (or to the edge of the box), i.e. when a disc of
//! that radius centred there would overlap something.

use super::grid::Grid;
use crate::world::WallShape;

/// `blocked[grid.index(i, j)]` for every cell, for a disc of `radius` metres in a box of `size`.
pub fn rasterize(grid: &Grid, size: [f64; 2], walls: &[WallShape], radius: f64) -> Vec<bool> {
    let mut blocked = vec![false; grid.len()];
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let [x, y] = grid.center(i, j);
            if x < radius || y < radius || x > size[0] - radius || y > size[1] - radius {
                blocked[grid.index(i, j)] = true;
            }
        }
    }
    for wall in walls {
        // Only the cells near the wall's bounding box can be within `radius` of it.
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
                    blocked[k] = wall.distance_to_point(x, y) < radius;
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
