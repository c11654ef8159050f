//! One agent's configuration space on its grid ([`FreeSpace`]): the walls and the other agents
//! ([`Disc`]) rasterized into a mask — a cell is blocked when its centre is closer than the
//! agent's radius to a wall (or to the edge of the box), i.e. when a disc of that radius centred
//! there would overlap something — and the free cells connected to the target.

use super::FieldError;
use super::grid::Grid;
use super::known::KnownMap;
use super::laplace;
use crate::world::{Agent, FieldKind, WallShape, World, all_wall_shapes};

/// Another agent's disc, seen as an obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Disc {
    /// Centre, m.
    pub center: [f64; 2],
    /// Radius, m.
    pub radius: f64,
}

impl Disc {
    /// The disc grown by `by` metres, but no further than stays clear of `agent` at `position`
    /// on a grid of `cell` metres: a disc that comes nearer is shrunk in the agent's field
    /// (see `obstacle_discs`), and growing must not make it vanish.
    pub fn grown(self, by: f64, (agent, position): (&Agent, [f64; 2]), cell: f64) -> Self {
        let distance = (position[0] - self.center[0]).hypot(position[1] - self.center[1]);
        let room = distance - self.radius - clear_of(agent, cell);
        Self {
            radius: self.radius + by.min(room.max(0.0)),
            ..self
        }
    }

    /// The disc as a wall shape, for rasterizing.
    pub fn shape(&self) -> WallShape {
        WallShape::new(
            parry2d::math::Pose::from_translation(parry2d::math::Vector::new(
                self.center[0],
                self.center[1],
            )),
            parry2d::shape::SharedShape::ball(self.radius),
        )
    }
}

/// One agent's configuration space on its grid: where its centre may be, and which of those
/// cells connect to the target. Cheap (no solve), so `nadf check` builds it too.
#[derive(Debug, Clone)]
pub struct FreeSpace {
    /// The grid, anchored on the target.
    pub grid: Grid,
    /// `true` where the agent's centre cannot be.
    pub blocked: Vec<bool>,
    /// The target's cell.
    pub target_cell: (usize, usize),
    /// The target disc: the reachable cells whose centres are within the agent's target
    /// radius (plus half a cell) of the target, the target's cell among them, where `V = 0`.
    pub target_cells: Vec<usize>,
    /// `true` for the free cells connected to the target cell.
    pub reachable: Vec<bool>,
}

impl FreeSpace {
    /// Rasterizes the world for `agent` and checks that its start connects to its target.
    pub fn of(world: &World, agent: &Agent) -> Result<Self, FieldError> {
        Self::among(world, agent, agent.start, &[], &[])
    }

    /// Like [`FreeSpace::of`] with the agent at `position` instead of its start, walls sensed
    /// with errors (wall `k` of [`all_wall_shapes`] moved out by `offsets[k]` m, see
    /// `rasterize`), and the discs `others` (the other agents) as obstacles too.
    /// A disc that covers the agent's target is left out, and one at the agent's skin is
    /// shrunk to stay clear of its cell (`obstacle_discs`): an agent parked on another's
    /// target must not make that target unreachable for good, and two agents in contact must
    /// still each have a field (the contact is counted by the simulation).
    pub fn among(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        offsets: &[f64],
        others: &[Disc],
    ) -> Result<Self, FieldError> {
        let (grid, blocked) = Self::mask_among(world, agent, position, offsets, others);
        Self::from_mask(grid, blocked, agent, position)
    }

    /// The grid and mask of [`FreeSpace::among`], before anything is checked to connect: the
    /// walls sensed with `offsets` and the discs `others` that are obstacles for `agent` at
    /// `position` (see `obstacle_discs`).
    pub fn mask_among(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        offsets: &[f64],
        others: &[Disc],
    ) -> (Grid, Vec<bool>) {
        let grid = Grid::anchored_in(world.bounds(), world.field.cell, agent.target);
        let mut walls = all_wall_shapes(world);
        walls.extend(obstacle_discs(agent, position, grid.cell, others).map(|d| d.shape()));
        let blocked = rasterize(&grid, world.bounds(), &walls, agent.radius, offsets);
        (grid, blocked)
    }

    /// The free space of a lidar agent at `position`: the box's edges, the discs `others`, and
    /// the cells `known` believes occupied grown by the agent's radius (plus half a cell: an
    /// occupied cell's centre can be that far inside the wall it saw). Cells never seen are
    /// free. The cells under the agent itself are left free, so a reading that puts a wall
    /// at its skin cannot cut it off its own field.
    pub fn known(
        world: &World,
        agent: &Agent,
        position: [f64; 2],
        known: &KnownMap,
        others: &[Disc],
    ) -> Result<Self, FieldError> {
        let grid = *known.grid();
        let discs: Vec<_> = others.iter().map(Disc::shape).collect();
        let mut blocked = rasterize(&grid, world.bounds(), &discs, agent.radius, &[]);
        let grow = agent.radius + 0.5 * grid.cell;
        let reach = (grow / grid.cell).ceil() as isize;
        let stamp: Vec<(isize, isize)> = (-reach..=reach)
            .flat_map(|dj| (-reach..=reach).map(move |di| (di, dj)))
            .filter(|&(di, dj)| ((di * di + dj * dj) as f64).sqrt() * grid.cell <= grow)
            .collect();
        // The cells of the stamp around cell (i, j) that are on the grid.
        let around = |i: usize, j: usize| {
            stamp.iter().filter_map(move |&(di, dj)| {
                let (a, b) = (i as isize + di, j as isize + dj);
                (a >= 0 && b >= 0 && (a as usize) < grid.nx && (b as usize) < grid.ny)
                    .then(|| grid.index(a as usize, b as usize))
            })
        };
        let occupied = known.occupied();
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                if occupied[grid.index(i, j)] {
                    around(i, j).for_each(|k| blocked[k] = true);
                }
            }
        }
        if let Some((ci, cj)) = grid.cell_of(position) {
            for k in around(ci, cj) {
                let [x, y] = grid.center(k % grid.nx, k / grid.nx);
                if (x - position[0]).hypot(y - position[1]) < agent.radius {
                    blocked[k] = false;
                }
            }
        }
        Self::from_mask(grid, blocked, agent, position)
    }

    /// The free space of the mask `blocked` on `grid`: the target's cell, the cells connected
    /// to it and the target disc, checked to connect to `position`.
    fn from_mask(
        grid: Grid,
        blocked: Vec<bool>,
        agent: &Agent,
        position: [f64; 2],
    ) -> Result<Self, FieldError> {
        let target_cell = grid
            .cell_of(agent.target)
            .filter(|&(i, j)| !blocked[grid.index(i, j)])
            .ok_or_else(|| FieldError::TargetBlocked {
                agent: agent.name.clone(),
                cell: grid.cell,
            })?;
        let reachable = laplace::reachable_from(&grid, &blocked, target_cell);
        // The start is connected when a cell around it is: the cells the sampler interpolates.
        let near = |c: usize, n: usize| c.saturating_sub(1)..=(c + 1).min(n - 1);
        let start_connected = grid.cell_of(position).is_some_and(|(i, j)| {
            near(i, grid.nx).any(|a| near(j, grid.ny).any(|b| reachable[grid.index(a, b)]))
        });
        if !start_connected {
            return Err(FieldError::Unreachable {
                agent: agent.name.clone(),
                radius: agent.radius,
            });
        }
        // Cells within half a cell beyond the disc: the outermost nodes held at V = 0 then
        // straddle the circle, so the discrete disc has the disc's radius on average (with
        // the centres inside it only, it is half a cell smaller, and the field near it
        // depends on the grid).
        let target_cells = disc_cells(
            &grid,
            &reachable,
            agent.target,
            agent.target_disc() + 0.5 * grid.cell,
        );
        Ok(Self {
            grid,
            blocked,
            target_cell,
            target_cells,
            reachable,
        })
    }

    /// How many cells are reachable, blocked and unreachable.
    pub fn counts(&self) -> CellCounts {
        CellCounts::of(&self.blocked, &self.reachable)
    }

    /// Every agent of `world` whose task is intractable on its grid (the target blocked or
    /// unreachable from the start), checked without solving anything: what `nadf check`
    /// reports and what `nadf run` refuses before its first solve. An attractive-repulsive
    /// field has no grid and no such guarantee (it is the baseline), so nothing is checked.
    pub fn intractable(world: &World) -> Vec<FieldError> {
        if world.field.kind != FieldKind::Harmonic {
            return Vec::new();
        }
        // A lidar agent plans on what it sees: it finds an enclosed target out online.
        world
            .agents
            .iter()
            .filter(|a| !a.has_lidar())
            .filter_map(|agent| Self::of(world, agent).err())
            .collect()
    }
}

/// The discs of `others` that are obstacles for `agent` at `position` on a grid of `cell`
/// metres: all but those that cover its target (see [`FreeSpace::among`]). A disc that comes
/// nearer the agent than [`clear_of`] allows is shrunk to what stays that clear of it (and
/// left out when nothing is left): the agent's own cell stays free, and the neighbour at its
/// skin still blocks the way through it, so a field never leads straight into a neighbour.
pub fn obstacle_discs<'a>(
    agent: &Agent,
    position: [f64; 2],
    cell: f64,
    others: &'a [Disc],
) -> impl Iterator<Item = Disc> + 'a {
    let (margin, target) = (clear_of(agent, cell), agent.target);
    others.iter().filter_map(move |&d| {
        let from = |p: [f64; 2]| (p[0] - d.center[0]).hypot(p[1] - d.center[1]);
        if from(target) < d.radius + margin {
            return None;
        }
        let radius = d.radius.min(from(position) - margin);
        (radius > 0.0).then_some(Disc { radius, ..d })
    })
}

/// How far beyond its own radius a disc must stay from `agent`'s centre, on a grid of `cell`
/// metres, to be an obstacle in its field: the agent's radius and a cell diagonal.
fn clear_of(agent: &Agent, cell: f64) -> f64 {
    agent.radius + std::f64::consts::SQRT_2 * cell
}

/// The `reachable` cells whose centres are within `radius` of `center` (the cell of `center`
/// itself always, as a point target).
pub fn disc_cells(grid: &Grid, reachable: &[bool], center: [f64; 2], radius: f64) -> Vec<usize> {
    let mut cells = Vec::new();
    let reach = (radius / grid.cell).ceil() as i64 + 1;
    if let Some((ci, cj)) = grid.cell_of(center) {
        for dj in -reach..=reach {
            for di in -reach..=reach {
                let (i, j) = (ci as i64 + di, cj as i64 + dj);
                if i < 0 || j < 0 || i >= grid.nx as i64 || j >= grid.ny as i64 {
                    continue;
                }
                let (i, j) = (i as usize, j as usize);
                let [x, y] = grid.center(i, j);
                let inside = (di, dj) == (0, 0) || (x - center[0]).hypot(y - center[1]) <= radius;
                if inside && reachable[grid.index(i, j)] {
                    cells.push(grid.index(i, j));
                }
            }
        }
    }
    cells
}

/// How many cells of a free space are reachable, blocked, and free but unreachable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CellCounts {
    /// Free cells connected to the target.
    pub reachable: usize,
    /// Cells the agent's centre cannot be in.
    pub blocked: usize,
    /// Free cells no path connects to the target.
    pub unreachable: usize,
}

impl CellCounts {
    /// Counts the cells of a mask and its reachable set.
    pub fn of(blocked: &[bool], reachable: &[bool]) -> Self {
        let reachable = reachable.iter().filter(|r| **r).count();
        let blocked_count = blocked.iter().filter(|b| **b).count();
        Self {
            reachable,
            blocked: blocked_count,
            unreachable: blocked.len() - reachable - blocked_count,
        }
    }
}

/// How near a cell may be to the edge of a wall's configuration obstacle and still count as off
/// it (free), m. Worlds with round numbers put cells exactly on that edge (a 0.5 m disc at
/// (4, 2) and a 0.3 m robot: the cells at (4, 1.2) and (4, 2.8)), where the distance f64 gives
/// is a rounding either side of `radius`: 0.8 for one and 0.7999999999999998 for the other,
/// and a symmetric world got an asymmetric mask. The rule is that a cell is blocked when its
/// distance is *below* the radius, so a cell that near the edge is free on both sides. Far
/// below any cell, far above f64's rounding of coordinates.
pub const ON_THE_EDGE: f64 = 1e-9;

/// `blocked[grid.index(i, j)]` for every cell, for a disc of `radius` metres in the box
/// `[lo, hi]`, with wall `k`'s boundary moved out by `offsets[k]` metres (in where negative;
/// missing offsets are zero: the exact walls): the mask of walls sensed with errors. A cell is
/// blocked when its signed distance to a wall is below `radius + offset`, or its distance to
/// the box's edge below `radius`, by more than [`ON_THE_EDGE`].
pub fn rasterize(
    grid: &Grid,
    (lo, hi): ([f64; 2], [f64; 2]),
    walls: &[WallShape],
    radius: f64,
    offsets: &[f64],
) -> Vec<bool> {
    let mut blocked = vec![false; grid.len()];
    let inset = radius - ON_THE_EDGE;
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let [x, y] = grid.center(i, j);
            if x < lo[0] + inset || y < lo[1] + inset || x > hi[0] - inset || y > hi[1] - inset {
                blocked[grid.index(i, j)] = true;
            }
        }
    }
    for (n, wall) in walls.iter().enumerate() {
        let offset = offsets.get(n).copied().unwrap_or(0.0);
        let reach = radius + offset - ON_THE_EDGE;
        // Only the cells near the wall's bounding box can be within `reach` of it.
        let radius = reach.max(0.0);
        let aabb = wall.shape.compute_aabb(&wall.pose);
        let lo = [aabb.mins.x - radius, aabb.mins.y - radius];
        let hi = [aabb.maxs.x + radius, aabb.maxs.y + radius];
        let (ir, jr) = grid.cells_in(lo, hi);
        for j in jr {
            for i in ir.clone() {
                let k = grid.index(i, j);
                if !blocked[k] {
                    let [x, y] = grid.center(i, j);
                    // The sensed case needs the signed distance (a thinner wall shrinks
                    // inside); the exact case keeps parry's solid distance query, which
                    // differs from the projection in the last bits at the mask's edge.
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

    /// A symmetric world gets a symmetric mask: the cells exactly on the edge of the disc's
    /// configuration obstacle, above and below it, are both free (f64 puts one at 0.8 m and
    /// the other at 0.7999999999999998 m from the disc's centre).
    #[test]
    fn cells_on_the_edge_of_an_obstacle_are_free_on_both_sides() {
        let size = [8.0, 4.0];
        // Cells centred on the target (7, 2), as the field's grids are.
        let grid = Grid::anchored(size, 0.05, [7.0, 2.0]);
        let disc = wall_shape(&Wall::Disc {
            center: [4.0, 2.0],
            radius: 0.5,
        })
        .unwrap();
        let blocked = rasterize(&grid, ([0.0, 0.0], size), &[disc], 0.3, &[]);
        let at = |i: usize, j: usize| blocked[grid.index(i, j)];
        let cell = |p: [f64; 2]| grid.cell_of(p).unwrap();
        let ((i, below), (_, middle), (_, above)) =
            (cell([4.0, 1.2]), cell([4.0, 2.0]), cell([4.0, 2.8]));
        assert!((grid.center(i, below)[1] - 1.2).abs() < 1e-12);
        assert!(!at(i, below) && !at(i, above) && at(i, below + 1) && at(i, above - 1));
        for d in 0..=middle.min(grid.ny - 1 - middle) {
            for i in 0..grid.nx {
                assert_eq!(at(i, middle - d), at(i, middle + d), "{i} {d}");
            }
        }
    }

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
            let blocked = rasterize(
                &grid,
                ([0.0, 0.0], size),
                std::slice::from_ref(&wall),
                0.2,
                &[offset],
            );
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
        let blocked = rasterize(&grid, ([0.0, 0.0], size), &[wall], 0.2, &[]);
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
