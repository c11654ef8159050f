//! `nadf reproduce`: run the paper's experiments and write the report, claim by claim.

use std::path::PathBuf;
use std::time::Instant;

use super::{Console, Failure, write_all};
use crate::output;
use crate::reproduce::{self, ReproduceError, figure, report};

/// The arguments of `nadf reproduce`.
#[derive(Debug, Clone, clap::Args)]
pub struct ReproduceArgs {
    /// The directory to write `report.md`, `report.json` and the figures into.
    #[arg(long, value_name = "DIR", default_value = "reproduction")]
    pub out: PathBuf,
    /// Only these figures or claims (ids as in the report). Repeatable.
    #[arg(long, value_name = "ID", num_args = 1..)]
    pub only: Vec<String>,
    /// Threads to run on [default: one per core].
    #[arg(long, short = 'j', value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub jobs: Option<u16>,
}

/// Runs the experiments in parallel with a progress bar, checks every claim, draws the figures
/// and writes the report; prints the verdicts' count and the wall time.
pub fn reproduce(args: &ReproduceArgs, console: &Console) -> Result<(), Failure> {
    let dir = &args.out;
    let bad = |e: &dyn std::fmt::Display| Failure::BadInput(format!("error: {e}"));
    output::check_dir(dir).map_err(|e| bad(&e))?;
    let (claims, figures) = reproduce::select(&args.only).map_err(|e| bad(&e))?;
    let experiments = reproduce::needed(&claims, &figures);
    let bar = console.bar(
        experiments.len() as u64,
        "{bar:40} {pos}/{len} runs, {elapsed} (eta {eta})",
    );
    let started = Instant::now();
    let outcomes = reproduce::run_all(
        &experiments,
        args.jobs.map(usize::from),
        &|| bar.inc(1),
        Some(&console.interrupt),
    );
    bar.finish_and_clear();
    let outcomes = match outcomes {
        Ok(o) => o,
        Err(e @ ReproduceError::Interrupted { .. }) => {
            return Err(Failure::Interrupted(format!("{e}; nothing written")));
        }
        Err(e) => return Err(bad(&e)),
    };
    let wall_time = started.elapsed();
    let checked = reproduce::check(&claims, &outcomes);
    let report = report::build(&claims, &checked, &outcomes, experiments.len(), wall_time);
    let mut files = Vec::new();
    for f in &figures {
        let png = figure::draw(f, &outcomes)
            .map_err(|e| bad(&format!("cannot draw figure {}: {e}", f.id)))?;
        files.push((dir.join(format!("{}.png", f.id)), png));
    }
    let json = serde_json::to_vec_pretty(&report).map_err(|e| bad(&e))?;
    files.push((dir.join("report.json"), json));
    let md = report::markdown(&report, &figures, &outcomes);
    files.push((dir.join("report.md"), md.into_bytes()));
    std::fs::create_dir_all(dir)
        .map_err(|e| bad(&format!("cannot create {}: {e}", dir.display())))?;
    write_all(dir, files)?;
    say!(
        "{} claims. {} {} runs in {:.1} s",
        checked.len(),
        report::counts_line(&report),
        experiments.len(),
        wall_time.as_secs_f64()
    );
    Ok(())
}
