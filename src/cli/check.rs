//! `nadf check`: validate world files without running them.

use std::path::PathBuf;

use super::{Failure, load};
use crate::field::FreeSpace;
use crate::sim::Simulation;
use crate::world::SensorKind;

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
        if intractable.is_empty()
            && let Err(e) = Simulation::new(&world)
        {
            intractable.push(e);
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
            println!(
                "{}: ok ({}, {bodies}, {} wall(s))",
                path.display(),
                world.name(),
                world.walls.len()
            );
            // A lidar agent is not refused (it must find out online), but the user is told.
            for agent in world
                .agents
                .iter()
                .filter(|a| a.sensor.is_some_and(|s| s.kind == SensorKind::Lidar))
            {
                if let Err(e) = FreeSpace::of(&world, agent) {
                    println!(
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
