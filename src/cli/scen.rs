//! `nadf scen`: run a map world once per Moving AI scenario and write a CSV and a plot.

use std::path::PathBuf;

use super::{BatchArgs, Console, Failure, bad_input, load, write_all};
use crate::output;
use crate::scen;
use crate::sweep::SweepError;

/// The arguments of `nadf scen`.
#[derive(Debug, Clone, clap::Args)]
pub struct ScenArgs {
    /// The world file (TOML), with a Moving AI `[map]`; its first agent is moved to each
    /// scenario's start and goal.
    pub world: PathBuf,
    /// The scenario file (`.map.scen`).
    pub scenarios: PathBuf,
    /// Run at most this many scenarios, spread evenly over the file [default: all].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    pub count: Option<u32>,
    /// Run only the scenarios of these buckets. Repeatable.
    #[arg(long = "bucket", value_name = "B")]
    pub buckets: Vec<u32>,
    /// The overrides, output directory and threads.
    #[command(flatten)]
    pub batch: BatchArgs,
}

/// Runs the scenarios in parallel with a progress bar and writes `DIR/scen.csv` and
/// `DIR/scen.png`.
pub fn scen(args: &ScenArgs, console: &Console) -> Result<(), Failure> {
    let path = &args.world;
    let dir = args.batch.dir(path, "scen");
    output::check_dir(&dir).map_err(|e| bad_input(path, e))?;
    let world = load(path, &args.batch.overrides)?;
    let count = args.count.map(|n| n as usize);
    let entries = scen::entries(&world, &args.scenarios, &args.buckets, count)
        .map_err(|e| bad_input(path, e))?;
    let to_run = entries.iter().filter(|e| e.world.is_ok()).count();
    let bar = console.bar(
        to_run as u64,
        "{bar:40} {pos}/{len} scenarios, {elapsed} (eta {eta})",
    );
    let result = scen::run_all(
        &entries,
        args.batch.threads(),
        &|| bar.inc(1),
        Some(&console.interrupt),
    );
    bar.finish_and_clear();
    let outcomes = match result {
        Ok(outcomes) => outcomes,
        Err(e @ SweepError::Interrupted { .. }) => {
            return Err(Failure::Interrupted(format!("{e}; nothing written")));
        }
        Err(e) => return Err(bad_input(path, e)),
    };
    let title = format!("{}: {}", world.name(), args.scenarios.display());
    let picture =
        scen::plot(&outcomes, &title).map_err(|e| bad_input(path, format!("cannot draw: {e}")))?;
    std::fs::create_dir_all(&dir)
        .map_err(|e| bad_input(path, format!("cannot create {}: {e}", dir.display())))?;
    write_all(
        path,
        vec![
            (dir.join("scen.csv"), scen::csv(&outcomes).into_bytes()),
            (dir.join("scen.png"), picture),
        ],
    )?;
    for o in outcomes.iter().filter(|o| o.summary.is_err()) {
        if let Err(why) = &o.summary {
            say!("skipped line {}: {why}", o.scenario.line);
        }
    }
    let t = scen::totals(&outcomes);
    say!(
        "{} scenario(s) run, {} skipped: {} reached ({:.0} %), {} contact(s), mean path / optimal {}",
        t.run,
        t.skipped,
        t.reached,
        100.0 * t.reached as f64 / t.run.max(1) as f64,
        t.contacts,
        t.mean_path_ratio
            .map_or_else(|| "-".to_string(), |r| format!("{r:.3}"))
    );
    Ok(())
}
