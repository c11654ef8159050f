//! `nadf sweep`: run a world for every combination of swept values and write a CSV and a plot.

use std::path::PathBuf;

use super::{Console, Failure, bad_input};
use crate::output;
use crate::sweep::{self, Range, SweepError};
use crate::world::Override;

/// The arguments of `nadf sweep`.
#[derive(Debug, Clone, clap::Args)]
pub struct SweepArgs {
    /// The world file (TOML).
    pub world: PathBuf,
    /// A swept value: COUNT evenly spaced values from START to END, both included
    /// (e.g. --set-range agents.0.controller.b=0.1:3.0:30). Repeatable: the runs are the
    /// Cartesian product, plotted against the first.
    #[arg(
        long = "set-range",
        value_name = "KEY=START:END:COUNT",
        required = true
    )]
    pub ranges: Vec<Range>,
    /// Override a world value for every run (see `run`). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<Override>,
    /// The directory to write into [default: WORLD_STEM-sweep].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Threads to run on [default: one per core].
    #[arg(long, short = 'j', value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
}

/// Loads every combination, runs them in parallel with a progress bar, and writes
/// `DIR/sweep.csv` and `DIR/sweep.png`.
pub fn sweep(args: &SweepArgs, console: &Console) -> Result<(), Failure> {
    let path = &args.world;
    let dir = args.out.clone().unwrap_or_else(|| sweep::default_out(path));
    output::check_dir(&dir).map_err(|e| bad_input(path, e))?;
    let (file, cases) =
        sweep::cases(path, &args.ranges, &args.overrides).map_err(|e| bad_input(path, e))?;
    if let Some(first) = cases.first() {
        for w in file.warnings(&first.world) {
            eprintln!("warning: {w}");
        }
    }
    let keys: Vec<String> = args.ranges.iter().map(|r| r.path.clone()).collect();
    let bar = console.bar(
        cases.len() as u64,
        "{bar:40} {pos}/{len} runs, {elapsed} (eta {eta})",
    );
    let jobs = args.jobs.map(usize::from);
    let result = sweep::run_all(
        &keys,
        &cases,
        jobs,
        &|| bar.inc(1),
        Some(&console.interrupt),
    );
    bar.finish_and_clear();
    let done = match result {
        Ok(done) => done,
        Err(e @ SweepError::Interrupted { .. }) => {
            return Err(Failure::Interrupted(format!("{e}; nothing written")));
        }
        Err(e) => return Err(bad_input(path, e)),
    };
    let title = format!("{}: sweep of {}", cases[0].world.name(), keys.join(" × "));
    let picture = sweep::plot(&done, &title)
        .map_err(|e| bad_input(path, format!("cannot draw the sweep's plot: {e}")))?;
    std::fs::create_dir_all(&dir)
        .map_err(|e| bad_input(path, format!("cannot create {}: {e}", dir.display())))?;
    for (name, bytes) in [
        ("sweep.csv", done.csv().into_bytes()),
        ("sweep.png", picture),
    ] {
        let file = dir.join(name);
        output::write_atomically(&file, &bytes).map_err(|e| bad_input(path, e))?;
        println!("wrote {}", file.display());
    }
    println!(
        "{} runs on {} thread(s) in {:.2} s",
        done.runs.len(),
        done.threads,
        done.wall_time.as_secs_f64()
    );
    Ok(())
}
