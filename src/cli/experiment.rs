//! `nadf experiment`: run a world many times with sampled values (all of it, or one shard),
//! resumably; and `nadf merge`: combine complete shards into the results of the whole.

use std::path::PathBuf;

use super::{Console, Failure, bad_input};
use crate::experiment::batch::write_results;
use crate::experiment::{Experiment, Shard, shard};
use crate::world::Override;

/// The arguments of `nadf experiment`.
#[derive(Debug, Clone, clap::Args)]
pub struct ExperimentArgs {
    /// The experiment file (TOML, an `[experiment]` table).
    pub experiment: PathBuf,
    /// The directory to write into [default: EXPERIMENT_STEM-experiment].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Run only the runs k with k mod N = I (0 ≤ I < N), into DIR/shard-I-of-N; `nadf merge`
    /// combines the shards.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Continue an interrupted run: keep the runs already done in DIR and run the others.
    #[arg(long)]
    pub resume: bool,
    /// Override a world value for every run, after the experiment's own `set`. Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<Override>,
    /// Threads to run on [default: one per core].
    #[arg(long, short = 'j', value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
}

/// The arguments of `nadf merge`.
#[derive(Debug, Clone, clap::Args)]
pub struct MergeArgs {
    /// Shard directories, or directories holding `shard-I-of-N` directories.
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// The directory to write the merged results into.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Runs the experiment (or its shard) with a progress bar; an unsharded experiment then
/// writes `runs.arrow`, `summary.csv` and `summary.png` and prints the summary.
pub fn experiment(args: &ExperimentArgs, console: &Console) -> Result<(), Failure> {
    let path = &args.experiment;
    let exp =
        Experiment::load(path, &args.overrides).map_err(|e| Failure::BadInput(e.to_string()))?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}-experiment", exp.name)));
    let shard = args.shard.unwrap_or(Shard::WHOLE);
    let bar = console.bar(
        shard.runs(exp.runs).count() as u64,
        "{bar:40} {pos}/{len} runs, {elapsed} (eta {eta})",
    );
    let jobs = args.jobs.map(usize::from);
    let done = exp
        .run_shard(
            shard,
            &out,
            (args.resume, jobs),
            &|_, _| bar.inc(1),
            Some(&console.interrupt),
        )
        .map_err(|e| bad_input(path, e))?;
    bar.finish_and_clear();
    let dir = shard.dir(&out);
    if !done.complete {
        return Err(Failure::Interrupted(format!(
            "interrupted: {} of {} runs of shard {shard} are in {}; `--resume` runs the rest",
            done.records.len(),
            shard.runs(exp.runs).count(),
            dir.join(shard::PROGRESS).display()
        )));
    }
    let rate = done.ran as f64 / done.wall_time.as_secs_f64().max(1e-9);
    say!(
        "{} runs on {} thread(s) in {:.2} s ({rate:.2} runs/s){}",
        done.ran,
        done.threads,
        done.wall_time.as_secs_f64(),
        if done.resumed > 0 {
            format!("; {} done before, kept", done.resumed)
        } else {
            String::new()
        }
    );
    if shard != Shard::WHOLE {
        say!(
            "shard {shard} complete in {}; `nadf merge {} --out DIR` combines the shards",
            dir.display(),
            out.display()
        );
        return Ok(());
    }
    let manifest = exp.manifest(shard, true);
    let (files, groups) =
        write_results(&dir, &manifest, &done.records).map_err(|e| bad_input(path, e))?;
    super::say_block(&crate::experiment::results::groups_table(&groups));
    for f in files {
        say!("wrote {}", f.display());
    }
    Ok(())
}

/// Merges complete shards into `--out`: the same `runs.arrow` (byte for byte), summary and
/// plot an unsharded run writes; refuses a set that is incomplete, mixed or has a shard twice.
pub fn merge(args: &MergeArgs) -> Result<(), Failure> {
    let merged = crate::experiment::batch::merge(&args.dirs, &args.out)
        .map_err(|e| Failure::BadInput(format!("error: nadf merge: {e}")))?;
    say!(
        "merged {} shard(s) of experiment `{}`: {} runs",
        merged.shards,
        merged.experiment,
        merged.runs
    );
    super::say_block(&crate::experiment::results::groups_table(&merged.groups));
    for f in merged.files {
        say!("wrote {}", f.display());
    }
    Ok(())
}
