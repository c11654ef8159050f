//! `nadf check`: validate world files without running them.

use std::path::PathBuf;

use super::{Failure, load};
use crate::field::FreeSpace;
use crate::sim::Simulation;
use nalgebra::Vector2;

/// A passage on an agent's kinematic path is narrow when it leaves the body's centre less than
/// twice this many field cells of free configuration space across the path (measured on the
/// rooms map: its one-cell doors leave 0.4 m free to a 0.3 m robot, two cells at 0.2 m, and
/// NADF crosses them only by touching without the envelope).
pub const NARROW_CELLS: f64 = 1.5;

/// The arguments of `nadf check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// The world files.
    #[arg(required = true)]
    pub worlds: Vec<PathBuf>,
}

/// Checks every file: its problems, each with its file, line and key, its warnings, whether
/// every agent's task is tractable on its grid, and (solving the fields) whether the field
/// guides every agent from its start. Fails when any file has a problem.
pub fn check(args: &CheckArgs) -> Result<(), Failure> {
    let mut problems = Vec::new();
    for path in &args.worlds {
        let world = match load(path, &[]) {
            Ok(world) => world,
            Err(failure) => {
                problems.push(failure.to_string());
                continue;
            }
        };
        let mut intractable = FreeSpace::intractable(&world);
        let mut narrow = Vec::new();
        if intractable.is_empty() {
            match Simulation::new(&world) {
                Ok(sim) => narrow = narrow_passages(&sim),
                Err(e) => intractable.push(e),
            }
        }
        if intractable.is_empty() {
            // The bodies it holds, by kind (agents, discs or shapes, always).
            let mut bodies = format!("{} agent(s)", world.agents.len() + world.shaped.len());
            for (n, kind) in [
                (world.arms.len(), "arm"),
                (world.pendulums.len(), "pendulum"),
            ] {
                if n > 0 {
                    bodies += &format!(", {n} {kind}(s)");
                }
            }
            say!(
                "{}: ok ({}, {bodies}, {} wall(s))",
                path.display(),
                world.name(),
                world.walls.len()
            );
            for warning in &narrow {
                say!("{}: warning: {warning}", path.display());
            }
            // A lidar agent is not refused (it must find out online), but the user is told.
            for agent in world.agents.iter().filter(|a| a.has_lidar()) {
                if let Err(e) = FreeSpace::of(&world, agent) {
                    say!(
                        "{}: note: with full knowledge of the walls, {e}; `{}` plans on what its lidar sees and will find out online",
                        path.display(),
                        agent.name
                    );
                }
            }
        } else {
            problems.extend(
                intractable
                    .iter()
                    .map(|e| format!("error: {}: {e}", path.display())),
            );
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(Failure::BadInput(problems.join("\n")))
    }
}

/// The narrow passages on each disc agent's kinematic path ([`NARROW_CELLS`]), one message per
/// passage at its narrowest point: where, and how much free configuration space it leaves
/// across the path (the room the body's centre has to either side of it, out to a few cells).
/// Robots on wheels are left out: their path is their look-ahead point's, not their footprint's.
pub fn narrow_passages(sim: &Simulation) -> Vec<String> {
    let cell = sim.world.field.cell;
    let index = sim.wall_index();
    let limit = 2.0 * NARROW_CELLS * cell;
    let mut out = Vec::new();
    for run in sim.agents.iter().filter(|a| a.agent.drive.is_none()) {
        let r = run.agent.radius;
        let free = |p: Vector2<f64>| index.signed_clearance(&sim.walls, p, r) > 0.0;
        // How far the centre can move from `p` along `n` and stay free, up to the limit.
        let room = |p: Vector2<f64>, n: Vector2<f64>| {
            let steps = 8.0 * 2.0 * NARROW_CELLS;
            let h = limit / steps;
            let last = (1..=steps as usize)
                .map(|k| k as f64 * h)
                .take_while(|&s| free(p + n * s))
                .last()
                .unwrap_or(0.0);
            if last + h > limit {
                return last;
            }
            // The wall is within the next step: found to a thousandth of it.
            let (mut lo, mut hi) = (last, last + h);
            for _ in 0..10 {
                let mid = 0.5 * (lo + hi);
                if free(p + n * mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        };
        // Each run of narrow points along the path, by its narrowest point.
        let mut passages: Vec<([f64; 2], f64)> = Vec::new();
        let mut current: Option<([f64; 2], f64)> = None;
        for pair in run.kinematic.points.windows(2) {
            let (a, b) = (Vector2::from(pair[0]), Vector2::from(pair[1]));
            let Some(t) = (b - a).try_normalize(0.0) else {
                continue;
            };
            let n = Vector2::new(-t.y, t.x);
            let width = room(a, n) + room(a, -n);
            if width < limit && free(a) {
                if current.is_none_or(|(_, narrowest)| width < narrowest) {
                    current = Some((pair[0], width));
                }
            } else if let Some(found) = current.take() {
                passages.push(found);
            }
        }
        passages.extend(current);
        let Some(&(at, width)) = passages.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
            continue;
        };
        let more = match passages.len() {
            1 => String::new(),
            n => format!(" (the narrowest of {n} such stretches)"),
        };
        out.push(format!(
            "a narrow passage: `{}`'s kinematic path passes [{:.2}, {:.2}] m with {:.3} m of free configuration space across it{more}, {:.1} field cells of {cell} m, which the field resolves coarsely and a body crosses with little room; a `field.cell` of {:.3} m resolves it in {} cells",
            run.agent.name,
            at[0],
            at[1],
            width,
            width / cell,
            width / (2.0 * NARROW_CELLS),
            2.0 * NARROW_CELLS
        ));
    }
    out
}
