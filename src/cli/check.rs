//! `nadf check`: validate world files without running them.

use std::path::PathBuf;

use super::{Failure, load};
use crate::field::FreeSpace;

/// The arguments of `nadf check`.
#[derive(Debug, Clone, clap::Args)]
pub struct CheckArgs {
    /// The world files.
    #[arg(required = true)]
    pub worlds: Vec<PathBuf>,
}

/// Checks every file: its problems, each with its file, line and key, its warnings, and
/// whether every agent's task is tractable on its grid. Fails when any file has a problem.
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
        let intractable = FreeSpace::intractable(&world);
        if intractable.is_empty() {
            println!(
                "{}: ok ({}, {} agent(s), {} wall(s))",
                path.display(),
                world.name(),
                world.agents.len(),
                world.walls.len()
            );
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
