//! `nadf sweep`: run a world for every combination of swept values and write a CSV and a plot.

use std::path::PathBuf;

use super::{BatchArgs, Console, Failure, bad_input, write_all};
use crate::output;
use crate::sweep::{self, Range, SweepError};

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
    /// The overrides, output directory and threads.
    #[command(flatten)]
    pub batch: BatchArgs,
}

/// Loads every combination, runs them in parallel with a progress bar, and writes
/// `DIR/sweep.csv` and `DIR/sweep.png`.
pub fn sweep(args: &SweepArgs, console: &Console) -> Result<(), Failure> {
    let path = &args.world;
    let dir = args.batch.dir(path, "sweep");
    output::check_dir(&dir).map_err(|e| bad_input(path, e))?;
    let (file, cases) =
        sweep::cases(path, &args.ranges, &args.batch.overrides).map_err(|e| bad_input(path, e))?;
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
    let jobs = args.batch.threads();
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
    write_all(
        path,
        vec![
            (dir.join("sweep.csv"), done.csv().into_bytes()),
            (dir.join("sweep.png"), picture),
        ],
    )?;
    say!(
        "{} runs on {} thread(s) in {:.2} s",
        done.runs.len(),
        done.threads,
        done.wall_time.as_secs_f64()
    );
    Ok(())
}
