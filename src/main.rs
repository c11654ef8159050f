//! The `nadf` command line: parses arguments and calls the library.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};

use nadf::field::{FreeSpace, HarmonicField, export};
use nadf::record::field_picture;
use nadf::run::{RunError, RunOptions, run};
use nadf::world::{FieldKind, Override, load};

/// Exit status for bad input (a world file, an override or an intractable task).
const BAD_INPUT: u8 = 2;
/// Exit status for a run that finished but missed an `[expect]`ation, or could not write an
/// output.
const FAILED: u8 = 1;
/// Exit status for a run stopped by Ctrl-C (128 + SIGINT).
const INTERRUPTED: u8 = 130;

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
    Run {
        /// The world file (TOML).
        world: PathBuf,
        /// The recording to write [default: WORLD_STEM.rrd in the current directory].
        #[arg(short, long, value_name = "OUT.rrd")]
        output: Option<PathBuf>,
        /// Do not write a recording.
        #[arg(long, conflicts_with = "output")]
        no_record: bool,
        /// Also write the summary as JSON to this file.
        #[arg(long, value_name = "SUMMARY.json")]
        json: Option<PathBuf>,
        /// Override a world value by dotted path, array items by index
        /// (e.g. --set agents.0.controller.b=0.7). Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<Override>,
    },
    /// Solve one agent's harmonic field and export it: NumPy arrays and a picture.
    Field {
        /// The world file (TOML).
        world: PathBuf,
        /// The agent whose field to solve [default: the first].
        #[arg(long)]
        agent: Option<String>,
        /// Write V as a float64 array of shape [nx, ny] (x index first) to this file, W = 1 - V
        /// to FILE.w.npy and the cell mask (0 reachable, 1 blocked, 2 unreachable) to
        /// FILE.mask.npy.
        #[arg(long, value_name = "FILE.npy")]
        npy: Option<PathBuf>,
        /// Write a picture of the field (log10(1 - V), streamlines, start, target).
        #[arg(long, value_name = "FILE.png")]
        png: Option<PathBuf>,
        /// Override a world value by dotted path (see `run`). Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<Override>,
    },
    /// Run a world for every combination of swept values, in parallel, and write `sweep.csv`
    /// (every summary metric per run and agent) and `sweep.png` (settling time, δ_m and
    /// contacts against the first swept value).
    Sweep {
        /// The world file (TOML).
        world: PathBuf,
        /// A swept value: COUNT evenly spaced values from START to END, both included
        /// (e.g. --set-range agents.0.controller.b=0.1:3.0:30). Repeatable: the runs are the
        /// Cartesian product, plotted against the first.
        #[arg(
            long = "set-range",
            value_name = "KEY=START:END:COUNT",
            required = true
        )]
        ranges: Vec<nadf::sweep::Range>,
        /// Override a world value for every run (see `run`). Repeatable.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<Override>,
        /// The directory to write into [default: WORLD_STEM-sweep].
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Threads to run on [default: one per core].
        #[arg(long, short = 'j', value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
        jobs: Option<u16>,
    },
    /// Validate world files and print every problem found (file, line, key).
    Check {
        /// The world files.
        #[arg(required = true)]
        worlds: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    match Cli::parse().command {
        Command::Run {
            world,
            output,
            no_record,
            json,
            overrides,
        } => run_command(&world, output, no_record, json, &overrides),
        Command::Check { worlds } => check_command(&worlds),
        Command::Sweep {
            world,
            ranges,
            overrides,
            out,
            jobs,
        } => sweep_command(&world, &ranges, &overrides, out, jobs.map(usize::from)),
        Command::Field {
            world,
            agent,
            npy,
            png,
            overrides,
        } => field_command(
            &world,
            agent.as_deref(),
            npy.as_deref(),
            png.as_deref(),
            &overrides,
        ),
    }
}

/// Loads a world, or prints every problem in it and gives the bad-input status. Prints the
/// world's warnings.
fn load_world(path: &Path, overrides: &[Override]) -> Result<nadf::world::World, ExitCode> {
    let world = load(path, overrides).map_err(|errors| {
        eprintln!("{errors}");
        ExitCode::from(BAD_INPUT)
    })?;
    print_warnings(path, &world);
    Ok(world)
}

fn print_warnings(path: &Path, world: &nadf::world::World) {
    for w in nadf::world::warnings(path, world) {
        eprintln!("warning: {w}");
    }
}

fn run_command(
    path: &Path,
    output: Option<PathBuf>,
    no_record: bool,
    json: Option<PathBuf>,
    overrides: &[Override],
) -> ExitCode {
    let world = match load_world(path, overrides) {
        Ok(world) => world,
        Err(code) => return code,
    };
    let recording = (!no_record).then(|| {
        output.unwrap_or_else(|| {
            let stem = path
                .file_stem()
                .map_or_else(|| "world".into(), |s| s.to_owned());
            PathBuf::from(stem).with_extension("rrd")
        })
    });
    // Ctrl-C stops the run after the current step; the recording is closed properly.
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&interrupt);
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
        eprintln!("warning: Ctrl-C will not stop the run cleanly: {e}");
    }
    let options = RunOptions {
        recording,
        json,
        progress: std::io::stderr().is_terminal() && std::env::var_os("CI").is_none(),
        interrupt: Some(interrupt),
    };
    match run(&world, &options) {
        Ok(report) => {
            print!("{}", report.table());
            match &report.recording {
                Some(rrd) => println!(
                    "wall time {:.2} s; recording: {} (open it with `rerun {}`)",
                    report.wall_time.as_secs_f64(),
                    rrd.display(),
                    rrd.display()
                ),
                None => println!(
                    "wall time {:.2} s; no recording",
                    report.wall_time.as_secs_f64()
                ),
            }
            if let Some(t) = report.interrupted_at {
                eprintln!(
                    "interrupted at t = {t:.2} s of {} s: the summary and the recording cover the run so far",
                    world.duration
                );
                return ExitCode::from(INTERRUPTED);
            }
            let mut failures = nadf::expect::failures(&world, &report.agents);
            failures.extend(nadf::expect::pendulum_failures(&world, &report.pendulums));
            if failures.is_empty() {
                ExitCode::SUCCESS
            } else {
                eprintln!(
                    "{}: {} expectation(s) failed:",
                    path.display(),
                    failures.len()
                );
                for f in &failures {
                    eprintln!("  {f}");
                }
                ExitCode::from(FAILED)
            }
        }
        Err(e @ RunError::Field(_)) => {
            eprintln!("error: {}: {e}", path.display());
            ExitCode::from(BAD_INPUT)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(FAILED)
        }
    }
}

fn field_command(
    path: &Path,
    agent: Option<&str>,
    npy: Option<&Path>,
    png: Option<&Path>,
    overrides: &[Override],
) -> ExitCode {
    let world = match load_world(path, overrides) {
        Ok(world) => world,
        Err(code) => return code,
    };
    let Some(agent) = (match agent {
        Some(name) => world.agents.iter().find(|a| a.name == name),
        None => world.agents.first(),
    }) else {
        let names: Vec<&str> = world.agents.iter().map(|a| a.name.as_str()).collect();
        eprintln!(
            "error: {}: no agent `{}`; the agents are: {}",
            path.display(),
            agent.unwrap_or_default(),
            names.join(", ")
        );
        return ExitCode::from(BAD_INPUT);
    };
    if world.field.kind != FieldKind::Harmonic {
        eprintln!(
            "note: {} guides its agents with field.kind = \"attractive-repulsive\"; this is the harmonic field of the same walls, for comparison",
            path.display()
        );
    }
    let field = match HarmonicField::solve(&world, agent) {
        Ok(field) => field,
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            return ExitCode::from(BAD_INPUT);
        }
    };
    let grid = field.grid();
    let reachable = field
        .sampler
        .reachable_cells()
        .iter()
        .filter(|r| **r)
        .count();
    let blocked = field.blocked.iter().filter(|b| **b).count();
    println!(
        "field of {}: {} x {} cells of {} m ({reachable} reachable, {blocked} blocked, {} unreachable)",
        agent.name,
        grid.nx,
        grid.ny,
        grid.cell,
        grid.len() - reachable - blocked
    );
    println!(
        "solve: {:.1} ms, {} solve(s), {} CG iterations, relative residual {:.1e}",
        field.solve_time.as_secs_f64() * 1e3,
        field.solves,
        field.iterations,
        field.relative_residual
    );
    println!(
        "1 - V at the start: {:.3e}",
        field.one_minus_potential(agent.start)
    );
    let mut outputs: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if let Some(npy) = npy {
        let [v, w, mask] = export::npy_paths(npy);
        outputs.push((v, export::potential_npy(&field)));
        outputs.push((w, export::one_minus_potential_npy(&field)));
        outputs.push((mask, export::mask_npy(&field)));
    }
    if let Some(png) = png {
        let (rgb, width, height) = field_picture(&field, agent);
        outputs.push((png.to_path_buf(), export::png(&rgb, width, height)));
    }
    for (out, bytes) in outputs {
        if let Err(e) = export::write(&out, &bytes) {
            eprintln!("error: cannot write {}: {e}", out.display());
            return ExitCode::from(FAILED);
        }
        println!("wrote {}", out.display());
    }
    ExitCode::SUCCESS
}

fn sweep_command(
    path: &Path,
    ranges: &[nadf::sweep::Range],
    overrides: &[Override],
    out: Option<PathBuf>,
    jobs: Option<usize>,
) -> ExitCode {
    use nadf::sweep::{self, SweepError};

    let cases = match sweep::cases(path, ranges, overrides) {
        Ok(cases) => cases,
        Err(e) => {
            eprintln!("error: {}: {e}", path.display());
            return ExitCode::from(BAD_INPUT);
        }
    };
    if let Some(first) = cases.first() {
        print_warnings(path, &first.world);
    }
    let keys: Vec<String> = ranges.iter().map(|r| r.path.clone()).collect();
    let bar = if std::io::stderr().is_terminal() && std::env::var_os("CI").is_none() {
        indicatif::ProgressBar::new(cases.len() as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs, {elapsed} (eta {eta})")
            .expect("a valid template"),
    );
    let interrupt = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&interrupt);
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
        eprintln!("warning: Ctrl-C will not stop the sweep cleanly: {e}");
    }
    let result = sweep::run_all(&keys, &cases, jobs, &|| bar.inc(1), Some(&interrupt));
    bar.finish_and_clear();
    let done = match result {
        Ok(done) => done,
        Err(e @ SweepError::Interrupted { .. }) => {
            eprintln!("{e}; nothing written");
            return ExitCode::from(INTERRUPTED);
        }
        Err(e @ SweepError::Run { .. }) => {
            eprintln!("error: {}: {e}", path.display());
            return ExitCode::from(BAD_INPUT);
        }
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(FAILED);
        }
    };
    let dir = out.unwrap_or_else(|| sweep::default_out(path));
    let title = format!("{}: sweep of {}", cases[0].world.name(), keys.join(" × "));
    let picture = match sweep::plot(&done, &title) {
        Ok(png) => png,
        Err(e) => {
            eprintln!("error: cannot draw the sweep's plot: {e}");
            return ExitCode::from(FAILED);
        }
    };
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("error: cannot create {}: {e}", dir.display());
        return ExitCode::from(FAILED);
    }
    for (name, bytes) in [
        ("sweep.csv", done.csv().into_bytes()),
        ("sweep.png", picture),
    ] {
        let file = dir.join(name);
        if let Err(e) = export::write(&file, &bytes) {
            eprintln!("error: cannot write {}: {e}", file.display());
            return ExitCode::from(FAILED);
        }
        println!("wrote {}", file.display());
    }
    println!(
        "{} runs on {} thread(s) in {:.2} s",
        done.runs.len(),
        done.threads,
        done.wall_time.as_secs_f64()
    );
    ExitCode::SUCCESS
}

fn check_command(paths: &[PathBuf]) -> ExitCode {
    let mut ok = true;
    for path in paths {
        let world = match load(path, &[]) {
            Ok(world) => world,
            Err(errors) => {
                ok = false;
                eprintln!("{errors}");
                continue;
            }
        };
        print_warnings(path, &world);
        // The file is well formed; is every agent's task tractable on its grid? (An
        // attractive-repulsive field has no grid and no such guarantee: it is the baseline.)
        let harmonic = world.field.kind == FieldKind::Harmonic;
        let problems: Vec<String> = world
            .agents
            .iter()
            .filter(|_| harmonic)
            .filter_map(|agent| FreeSpace::of(&world, agent).err())
            .map(|e| format!("error: {}: {e}", path.display()))
            .collect();
        if problems.is_empty() {
            println!(
                "{}: ok ({}, {} agent(s), {} wall(s))",
                path.display(),
                world.name(),
                world.agents.len(),
                world.walls.len()
            );
        } else {
            ok = false;
            eprintln!("{}", problems.join("\n"));
        }
    }
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(BAD_INPUT)
    }
}
