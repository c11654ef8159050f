//! The `nadf` command line: parses the arguments and dispatches to [`nadf::cli`], which runs
//! the command and says how it ended; the exit status comes from that (see `nadf::cli`).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use nadf::cli::{
    self, CheckArgs, Console, ExperimentArgs, FieldArgs, MergeArgs, ReproduceArgs, RunArgs,
    ScenArgs, SweepArgs,
};

/// mimalloc rather than the system's allocator: a field solve allocates and frees buffers of
/// megabytes level after level, which glibc hands back to the kernel and faults in again (page
/// faults and cross-core TLB flushes in the profile). Measured on the paper's room at 1024²
/// (`nadf field`, ten runs each, 2 cores): 186–210 ms of solve against 236–249 ms; the crowds
/// and the rooms map as before (64 robots on the 1.8 m circle 27.1–27.2 s against 27.2–28.2 s).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

// mimalloc's C API (linked with the allocator), for the one option set in `main`.
unsafe extern "C" {
    fn mi_option_set(option: std::ffi::c_int, value: std::ffi::c_long);
}

/// `mi_option_purge_delay` in mimalloc 3's `mi_option_e` (`include/mimalloc.h` of the
/// `libmimalloc-sys` the lock file pins): how long freed memory waits before it is handed
/// back to the kernel, ms; -1 never.
const MI_OPTION_PURGE_DELAY: std::ffi::c_int = 15;

/// Keeps the memory a command frees for its next allocations instead of handing it back to
/// the kernel: the nested levels of a deep field allocate and free a part's buffers thousands
/// of times, and memory handed back is faulted in again as zeroed huge pages (`clear_page`
/// was a tenth of the rooms map's longest field). Measured there (`nadf field`, alternating
/// runs): 12.1–12.2 s against 13.8 s, half the system time; the process keeps its peak
/// memory until it exits.
fn keep_freed_memory() {
    // SAFETY: sets a plain integer option, before any other thread runs.
    unsafe { mi_option_set(MI_OPTION_PURGE_DELAY, -1) };
}

#[derive(Parser)]
#[command(
    name = "nadf",
    version,
    about = "Kinodynamic motion planning sandbox: harmonic potential fields and NADF on Rapier bodies, recorded for Rerun"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a world headlessly to its duration, write a Rerun recording and print a summary.
    Run(RunArgs),
    /// Solve one agent's harmonic field and export it: NumPy arrays and a picture.
    Field(FieldArgs),
    /// Run a world for every combination of swept values, in parallel, and write `sweep.csv`
    /// (every summary metric per run and agent) and `sweep.png` (settling time, δ_m and
    /// contacts against the first swept value).
    Sweep(SweepArgs),
    /// Run a world on a Moving AI map once per scenario of a `.map.scen` file, in parallel, and
    /// write `scen.csv` (every run's metrics, skipped scenarios with the reason) and `scen.png`
    /// (success and path / optimal against the optimal length).
    Scen(ScenArgs),
    /// Run a world many times with sampled values (`[experiment]`: runs, seed, samplers by
    /// dotted key), each run seeded by its index; all of it or one `--shard I/N`, resumably;
    /// write `runs.arrow` (one row per run and agent), `summary.csv` and `summary.png`.
    Experiment(ExperimentArgs),
    /// Combine the complete shards of an experiment into the results an unsharded run writes.
    Merge(MergeArgs),
    /// Validate world files and print every problem found (file, line, key).
    Check(CheckArgs),
    /// Run the paper's experiments in parallel and write `report.md` (per claim: the paper's
    /// statement and number, the measured number, the verdict), `report.json` and one PNG per
    /// figure.
    Reproduce(ReproduceArgs),
}

fn main() -> ExitCode {
    keep_freed_memory();
    let command = Cli::parse().command;
    let console = Console::new();
    let result = match &command {
        Command::Run(args) => cli::run(args, &console),
        Command::Field(args) => cli::field(args),
        Command::Sweep(args) => cli::sweep(args, &console),
        Command::Scen(args) => cli::scen(args, &console),
        Command::Experiment(args) => cli::experiment(args, &console),
        Command::Merge(args) => cli::merge(args),
        Command::Check(args) => cli::check(args),
        Command::Reproduce(args) => cli::reproduce(args, &console),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            eprintln!("{failure}");
            ExitCode::from(failure.exit_code())
        }
    }
}
