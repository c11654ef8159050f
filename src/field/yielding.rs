//! Giving way in a crowd: an agent's [`Way`] (the next metres of its guidance) and the field
//! that takes an agent that blocks a way out of it ([`HarmonicField::yielding`]).
//!
//! **Why it is needed.** With local replanning each agent's field has the others as
//! obstacles. Two groups that meet in a door close it for each other: every field is
//! [`FieldError::Unreachable`](super::FieldError::Unreachable), every agent keeps its last
//! field, which leads into the door, and the clearance envelope (rightly) stops them short of
//! each other. Nobody touches, and nobody moves: a deadlock, not a collision.
//!
//! **The rule.** The agents have an order of way: first those that have not yet arrived at
//! their targets, in the world file's order, then those that have (once arrived, an agent
//! stays in the second group even if it is moved off again). At each replan an agent is
//! *stuck* when its field with all the others is unreachable, or when the way that field gives
//! it runs into a neighbour's disc (a neighbour at its skin, which a field cannot keep apart);
//! it is *overrun* when the way of an agent before it comes within the clearance envelope's
//! margin of its disc (that agent planned past it, or through a gap between two neighbours at
//! its skin narrower than the two discs: the envelope would stop it there for good). A stuck
//! or overrun agent that stands in the way of agents before it (its disc within
//! [`IN_THE_WAY`] of their ways) *yields*: its field leads, among the walls and all the others,
//! to the nearest free cells at least [`CLEAR_OF_WAY`] clear of those ways
//! ([`HarmonicField::yielding`]). An agent that has arrived only *steps aside*, to such cells
//! within [`STEP_ASIDE`] of its target; where there are none it keeps its place (first come,
//! first served: in a corridor one robot wide, leaving the way would mean being driven before
//! the other to the corridor's end). A stuck agent in no one's way plans among the agents
//! before it only (and the moving obstacles): the ones after it give way. Otherwise it keeps
//! the field it has (the one that took it out of the way, when it yielded). An agent that
//! yielded goes on yielding while it stands in the way of an agent before it, whether or not a
//! way still runs into it, and once out of the ways it waits there while its own target stands
//! in one: taking its own field back sooner would lead it back into the way.
//!
//! **Why the crowd then moves.** Take the first agent in the order that has not arrived. It
//! never yields: when it is stuck it plans among the moving obstacles alone, so its field leads
//! on while the walls leave a way, and every agent standing on that way is overrun or stuck
//! in its way and leaves it, if it has free space to leave into (one that has arrived, within
//! [`STEP_ASIDE`] of its target). So it arrives in finite time and drops to the second group;
//! the order changes at most once per agent, and the argument repeats for the next. The
//! clearance envelope holds under all of it (a yield is only another field), so no one touches
//! on the way. What the rule cannot do is make room where there is none: an agent with no free
//! cell clear of the ways that it can reach keeps its field and waits, and the run reports whom
//! that left short of the target.

use std::sync::Arc;

use super::bounds::Bounds;
use super::grid::Grid;
use super::laplace;
use super::mask::{Disc, FreeSpace};
use super::streamline::Streamline;
use super::{FieldError, HarmonicField};
use crate::world::{Agent, World};

/// How much of its guidance an agent publishes as its way, m: the next few seconds at a
/// walking robot's speed, enough to see a door ahead emptied before it is entered.
pub const WAY_AHEAD: f64 = 4.0;

/// How near a disc must come to a way to stand in it, m, beyond the two radii.
pub const IN_THE_WAY: f64 = 0.1;

/// How far clear of the ways, m beyond the two radii, a yielding agent goes: a margin
/// the envelope's stopping distance and the replan's horizon fit in at walking speed.
pub const CLEAR_OF_WAY: f64 = 0.5;

/// How far from its own target an agent that has arrived steps aside out of the ways of the
/// others, m: a few robots' widths, so parked robots make room at a door without being
/// driven off for good.
pub const STEP_ASIDE: f64 = 2.0;

/// The next metres of an agent's guidance: the streamline of its field from where it is,
/// at most [`WAY_AHEAD`] long, and the radius of the disc that follows it.
#[derive(Debug, Clone, PartialEq)]
pub struct Way {
    /// Points along the way, m, from the agent's position.
    points: Arc<[[f64; 2]]>,
    /// The agent's radius, m.
    pub radius: f64,
    /// The boxes of its points and of those after the first (see [`Way::near`]).
    bounds: [Bounds; 2],
}

/// How far beyond a way's box a point must lie for a nearness test to skip the way's
/// segments, m: far above the rounding of a segment's distance (1e-13 m on a map of a few
/// hundred metres), so a skipped way is one whose test the segments would have failed too.
const BOX_SLACK: f64 = 1e-9;

impl Way {
    /// The first [`WAY_AHEAD`] metres of `streamline` for a disc of `radius` m.
    ///
    /// ```
    /// use nadf::field::{Streamline, Way};
    /// let line = Streamline { points: (0..100).map(|i| [0.1 * i as f64, 0.0]).collect(), reached: true };
    /// let way = Way::new(&line, 0.3);
    /// assert!((way.points().last().unwrap()[0] - 4.0).abs() < 0.11);
    /// ```
    pub fn new(streamline: &Streamline, radius: f64) -> Self {
        let mut points = Vec::new();
        let mut walked = 0.0;
        for (k, p) in streamline.points.iter().enumerate() {
            if k > 0 {
                let q = streamline.points[k - 1];
                walked += (p[0] - q[0]).hypot(p[1] - q[1]);
            }
            points.push(*p);
            if walked >= WAY_AHEAD {
                break;
            }
        }
        let bounds = [
            Bounds::of(&points),
            Bounds::of(points.get(1..).unwrap_or_default()),
        ];
        Self {
            points: points.into(),
            radius,
            bounds,
        }
    }

    /// Points along the way, m, from the agent's position.
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// Distance from `p` to the way's polyline, m (infinite for a way with no points).
    pub fn distance(&self, p: [f64; 2]) -> f64 {
        super::streamline::polyline_distance(&self.points, p)
    }

    /// Whether `disc` stands in the way: within [`IN_THE_WAY`] of the disc that follows it.
    pub fn in_the_way(&self, disc: &Disc) -> bool {
        let within = self.radius + disc.radius + IN_THE_WAY;
        Self::near((&self.points, &self.bounds[0]), disc.center, within)
    }

    /// Whether the way runs into `disc`: the disc that follows it overlaps it by more than
    /// `slack` m somewhere (not counting its first point, where the agent is now); a negative
    /// `slack` counts a way that passes less than `−slack` m clear of the disc too.
    pub fn runs_into(&self, disc: &Disc, slack: f64) -> bool {
        let ahead = self.points.get(1..).unwrap_or_default();
        let within = self.radius + disc.radius - slack;
        Self::near((ahead, &self.bounds[1]), disc.center, within)
    }

    /// Whether `p` is less than `within` m from the polyline `points` (the way's, or its part
    /// after the first point), whose box is `bounds`. Every segment lies in the box, so a point
    /// farther than `within` from the box is farther from every segment, and is answered
    /// without them: in a crowd every replan tests every other agent's disc against its way
    /// and every way before it against its disc, and most are metres away (the segments'
    /// distances were 5 % of 128 robots' time on the 1.8 m circle).
    fn near((points, bounds): (&[[f64; 2]], &Bounds), p: [f64; 2], within: f64) -> bool {
        if bounds.distance(p) >= within + BOX_SLACK {
            return false;
        }
        super::streamline::polyline_distance(points, p) < within
    }

    /// Whether a disc of `radius` m centred at `p` is at least [`CLEAR_OF_WAY`] clear of the
    /// way.
    pub fn clear(&self, p: [f64; 2], radius: f64) -> bool {
        self.distance(p) >= self.radius + radius + CLEAR_OF_WAY
    }
}

impl FreeSpace {
    /// The free space of `agent` at `position` on the mask `blocked` (on `grid`, the walls
    /// and all the other agents) whose "target" is every cell connected to the agent and clear
    /// of the `ways` (see [`Way::clear`]): where a yielding agent goes; for an agent that has
    /// `arrived`, only the cells within [`STEP_ASIDE`] of its target. `None` when no such cell
    /// can be reached, or the agent's own cell is blocked.
    pub fn out_of_ways(
        grid: &Grid,
        blocked: &[bool],
        (agent, arrived): (&Agent, bool),
        position: [f64; 2],
        ways: &[&Way],
    ) -> Option<Self> {
        let here = grid
            .cell_of(position)
            .filter(|&(i, j)| !blocked[grid.index(i, j)])?;
        let connected = laplace::reachable_from(grid, blocked, here);
        // The cells not clear of a way: each way's own box, grown by how far its reach goes,
        // is searched (a cell outside it is farther than that from every point of the way),
        // not the whole grid against every way.
        let mut near = vec![false; grid.len()];
        for way in ways {
            let reach = way.radius + agent.radius + CLEAR_OF_WAY;
            let Bounds { lo, hi } = way.bounds[0].grown(reach);
            let (ir, jr) = grid.cells_in(lo, hi);
            for j in jr {
                for i in ir.clone() {
                    let k = grid.index(i, j);
                    near[k] = near[k] || !way.clear(grid.center(i, j), agent.radius);
                }
            }
        }
        let [tx, ty] = agent.target;
        let aside = |k: usize| {
            let [x, y] = grid.center(k % grid.nx, k / grid.nx);
            !arrived || (x - tx).hypot(y - ty) <= STEP_ASIDE
        };
        let target_cells: Vec<usize> = (0..grid.len())
            .filter(|&k| connected[k] && !near[k] && aside(k))
            .collect();
        let first = *target_cells.first()?;
        Some(Self {
            grid: *grid,
            blocked: blocked.to_vec(),
            target_cell: (first % grid.nx, first / grid.nx),
            target_cells,
            reachable: connected,
        })
    }
}

impl HarmonicField {
    /// The field that takes `agent` at `position` out of the `ways` of the agents it stands in
    /// the way of, among the walls and the `others` (all the other agents): `W = 1` on every
    /// free cell connected to it and clear of the ways (see [`FreeSpace::out_of_ways`]), so it
    /// leads to the nearest of them by the harmonic field's own argument (no local minimum).
    ///
    /// Its `target` is where that descent ends (its streamline from `position` to the first
    /// cells clear of the ways, where `W = 1` and the gradient vanishes), with no target disc:
    /// the control law's offset, and with it the guidance's taper, a brake and a clamp, is
    /// measured to where the field leads. Were it the agent's own target, an agent that had
    /// arrived there would yield with no force at all: the guidance tapers to zero on the
    /// target and the gradient is the target's bowl within its rim (measured: two groups of 8
    /// swapping through a door at 1.2 m of arc, the first arrivals parked a robot's width
    /// apart, overrun and yielding in name for 100 s; 6 of 16 robots reached).
    ///
    /// [`FieldError::Unreachable`] when there is nowhere to go (for an agent that has
    /// `arrived`, nowhere within [`STEP_ASIDE`] of its target).
    pub fn yielding(
        world: &World,
        (agent, arrived): (&Agent, bool),
        position: [f64; 2],
        (offsets, others): (&[f64], &[Disc]),
        ways: &[&Way],
    ) -> Result<Self, FieldError> {
        let started = std::time::Instant::now();
        let (grid, blocked) = FreeSpace::mask_among(world, agent, position, offsets, others);
        let space = FreeSpace::out_of_ways(&grid, &blocked, (agent, arrived), position, ways)
            .ok_or_else(|| FieldError::Unreachable {
                agent: agent.name.clone(),
                radius: agent.radius,
            })?;
        let mut field = Self::solve_space(world, agent, space, (None, None), started)?;
        // Its streamline with no target point (none to stop at, no target's bowl) is the plain
        // descent: where it ends, in the cells clear of the ways (`W = 1`, no gradient), is the
        // target; `position` itself when it is clear already.
        field.target = [f64::INFINITY; 2];
        field.target_radius = 0.0;
        field.target = *field
            .streamline(position)
            .points
            .last()
            .unwrap_or(&position);
        Ok(field)
    }
}

/// The cells of `grid` whose centres are within `radius` of `center`, reachable or not (for
/// tests: a way's neighbourhood).
#[cfg(test)]
fn cells_near(grid: &Grid, center: [f64; 2], radius: f64) -> Vec<usize> {
    super::mask::disc_cells(grid, &vec![true; grid.len()], center, radius)
}

#[cfg(test)]
mod tests {
    use super::super::streamline::polyline_distance;
    use super::*;
    use crate::random::SplitMix;

    fn straight(from: [f64; 2], to: [f64; 2], n: usize) -> Streamline {
        Streamline {
            points: (0..=n)
                .map(|k| {
                    let t = k as f64 / n as f64;
                    [
                        from[0] + t * (to[0] - from[0]),
                        from[1] + t * (to[1] - from[1]),
                    ]
                })
                .collect(),
            reached: true,
        }
    }

    #[test]
    fn a_way_is_the_first_metres_of_the_streamline() {
        let way = Way::new(&straight([0.0, 0.0], [10.0, 0.0], 100), 0.3);
        let end = way.points.last().unwrap();
        assert!((end[0] - WAY_AHEAD).abs() <= 0.1 + 1e-9, "{end:?}");
        assert_eq!(way.distance([2.0, 0.5]), 0.5);
        // Beyond its end the way is not there.
        assert!((way.distance([8.0, 0.0]) - (8.0 - end[0])).abs() < 1e-12);
    }

    /// The box that spares the segments answers as the segments do: random bent ways, discs
    /// anywhere around them (near the first segment, where the box of the points after the
    /// first does not reach, among them), and a way of one point and of none.
    #[test]
    fn the_box_answers_as_the_segments() {
        let mut rng = SplitMix::new(7);
        let mut random = move || rng.uniform();
        let mut checked = [0; 2];
        for case in 0..400 {
            let n = case % 7;
            let mut p = [10.0 * random(), 10.0 * random()];
            let mut points = vec![p];
            for _ in 0..n {
                p = [p[0] + random() - 0.3, p[1] + random() - 0.5];
                points.push(p);
            }
            let line = Streamline {
                points,
                reached: true,
            };
            let way = Way::new(&line, 0.3);
            for _ in 0..50 {
                let disc = Disc {
                    center: [p[0] + 6.0 * random() - 4.0, p[1] + 6.0 * random() - 3.0],
                    radius: 0.1 + 0.5 * random(),
                };
                let all = polyline_distance(way.points(), disc.center);
                let ahead =
                    polyline_distance(way.points().get(1..).unwrap_or_default(), disc.center);
                let in_the_way = all < way.radius + disc.radius + IN_THE_WAY;
                assert_eq!(way.in_the_way(&disc), in_the_way, "{way:?} {disc:?}");
                let slack = 0.2 * random() - 0.1;
                let runs_into = ahead < way.radius + disc.radius - slack;
                assert_eq!(way.runs_into(&disc, slack), runs_into, "{way:?} {disc:?}");
                checked[usize::from(in_the_way || runs_into)] += 1;
            }
        }
        // Both answers, many times each.
        assert!(checked.iter().all(|&c| c > 1000), "{checked:?}");
    }

    #[test]
    fn in_the_way_runs_into_and_clear() {
        let way = Way::new(&straight([0.0, 0.0], [4.0, 0.0], 40), 0.3);
        let disc = |y: f64| Disc {
            center: [2.0, y],
            radius: 0.3,
        };
        assert!(way.in_the_way(&disc(0.65)));
        assert!(!way.in_the_way(&disc(0.75)));
        assert!(way.runs_into(&disc(0.5), 0.05));
        assert!(!way.runs_into(&disc(0.58), 0.05));
        // A way that grazes the disc runs into it with a negative slack (a gap) only.
        assert!(!way.runs_into(&disc(0.601), 0.0));
        assert!(way.runs_into(&disc(0.601), -0.002) && !way.runs_into(&disc(0.603), -0.002));
        // At the agent itself (the way's first point) nothing is run into.
        let at_start = Disc {
            center: [-0.5, 0.0],
            radius: 0.3,
        };
        assert!(!way.runs_into(&at_start, 0.0));
        assert!(!way.clear([2.0, 1.0], 0.3) && way.clear([2.0, 1.2], 0.3));
    }

    #[test]
    fn the_space_out_of_a_way_is_the_free_cells_clear_of_it() {
        let grid = Grid::covering([4.0, 4.0], 0.1);
        let blocked = vec![false; grid.len()];
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/swap.toml");
        let world = crate::world::load(&path, &[]).unwrap();
        let agent = Agent {
            radius: 0.3,
            ..world.agents[0].clone()
        };
        let way = Way::new(&straight([0.0, 2.0], [4.0, 2.0], 40), 0.3);
        let space =
            FreeSpace::out_of_ways(&grid, &blocked, (&agent, false), [2.0, 2.0], &[&way]).unwrap();
        // The target cells are exactly the cells clear of the way.
        let clear: Vec<usize> = (0..grid.len())
            .filter(|&k| way.clear(grid.center(k % grid.nx, k / grid.nx), agent.radius))
            .collect();
        assert_eq!(space.target_cells, clear);
        // Every target cell is clear of the way; the cells near it are not targets.
        for &k in &space.target_cells {
            let p = grid.center(k % grid.nx, k / grid.nx);
            assert!((p[1] - 2.0).abs() >= 1.1 - 1e-9, "{p:?}");
        }
        for k in cells_near(&grid, [2.0, 2.0], 1.0) {
            assert!(!space.target_cells.contains(&k));
        }
        assert!(!space.target_cells.is_empty());
        // An agent that has arrived only steps aside: the cells clear of the way within
        // STEP_ASIDE of its target, and none when they are all farther.
        let parked = Agent {
            target: [0.5, 0.5],
            ..agent.clone()
        };
        let aside = FreeSpace::out_of_ways(&grid, &blocked, (&parked, true), [2.0, 2.0], &[&way]);
        let aside = aside.unwrap().target_cells;
        assert!(!aside.is_empty() && aside.len() < space.target_cells.len());
        for k in &aside {
            let [x, y] = grid.center(k % grid.nx, k / grid.nx);
            assert!(space.target_cells.contains(k));
            assert!((x - 0.5).hypot(y - 0.5) <= STEP_ASIDE, "{x} {y}");
        }
        let far = Agent {
            target: [2.0, -20.0],
            ..agent.clone()
        };
        assert!(
            FreeSpace::out_of_ways(&grid, &blocked, (&far, true), [2.0, 2.0], &[&way]).is_none()
        );
    }

    #[test]
    fn a_yield_leads_out_of_the_way_from_the_agents_own_target() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/swap.toml");
        let world = crate::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
        let agent = &world.agents[0];
        // Parked on its own target, with a way running past it.
        let parked = Agent {
            start: agent.target,
            ..agent.clone()
        };
        let at = parked.target;
        let way = Way::new(
            &straight([at[0] - 2.0, at[1] + 0.2], [at[0] + 2.0, at[1] + 0.2], 40),
            0.3,
        );
        let field =
            HarmonicField::yielding(&world, (&parked, true), at, (&[], &[]), &[&way]).unwrap();
        // Its target is where it goes, clear of the way, not its own target under the way:
        // there the guidance would taper to nothing and the target's bowl would hold it.
        let [x, y] = field.target;
        assert!(way.clear([x, y], parked.radius), "{:?}", field.target);
        assert!((x - at[0]).hypot(y - at[1]) <= STEP_ASIDE);
        assert_eq!(field.target_radius, 0.0);
        let g = field.gradient(at).unwrap();
        assert!(g.norm() > 0.0 && g.y > 0.0, "{g:?}");
    }
}
