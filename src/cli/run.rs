//! `nadf run`: simulate a world headlessly, write its recording, print its summary, check its
//! expectations.

use std::path::PathBuf;

use super::{Console, Failure, bad_input, load};
use crate::record::Viewer;
use crate::run::RunOptions;
use crate::world::Override;

/// The arguments of `nadf run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// The world file (TOML).
    pub world: PathBuf,
    /// The recording to write [default: WORLD_STEM.rrd in the current directory].
    #[arg(short, long, value_name = "OUT.rrd")]
    pub output: Option<PathBuf>,
    /// Do not write a recording.
    #[arg(long, conflicts_with = "output")]
    pub no_record: bool,
    /// Start a Rerun viewer (the `rerun` executable on the PATH) and stream the run into it as
    /// it goes; no file is written unless -o is given too.
    #[arg(long, conflicts_with = "connect")]
    pub spawn: bool,
    /// Stream the run as it goes to a running Rerun viewer at URL [default URL:
    /// rerun+http://127.0.0.1:9876/proxy]; no file is written unless -o is given too.
    #[arg(long, value_name = "URL", num_args = 0..=1, default_missing_value = crate::record::DEFAULT_VIEWER_URL)]
    pub connect: Option<String>,
    /// Also write the summary as JSON to this file.
    #[arg(long, value_name = "SUMMARY.json")]
    pub json: Option<PathBuf>,
    /// Override a world value by dotted path, array items by index
    /// (e.g. --set agents.0.controller.b=0.7). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<Override>,
}

/// Runs the world to its duration and prints the summary; fails with the missed expectations.
pub fn run(args: &RunArgs, console: &Console) -> Result<(), Failure> {
    let path = &args.world;
    let world = load(path, &args.overrides)?;
    let viewer = Viewer::from_flags(args.spawn, args.connect.clone());
    // Streaming to a viewer replaces the default file; -o saves one too.
    let recording = match (&args.output, args.no_record, &viewer) {
        (Some(out), _, _) => Some(out.clone()),
        (None, true, _) | (None, false, Some(_)) => None,
        (None, false, None) => {
            let stem = path
                .file_stem()
                .map_or_else(|| "world".into(), |s| s.to_owned());
            Some(PathBuf::from(stem).with_extension("rrd"))
        }
    };
    let streamed = viewer.as_ref().map(|v| match v {
        Viewer::Spawn => format!(
            "streamed to a new viewer at {}",
            crate::record::DEFAULT_VIEWER_URL
        ),
        Viewer::Connect(url) => format!("streamed to {url}"),
    });
    let options = RunOptions {
        recording,
        viewer,
        json: args.json.clone(),
        progress: console.progress,
        interrupt: Some(console.interrupt.clone()),
    };
    let report = crate::run::run(&world, &options).map_err(|e| bad_input(path, e))?;
    super::say_block(&report.table());
    let wall = report.wall_time.as_secs_f64();
    match &report.recording {
        Some(rrd) => say!(
            "wall time {wall:.2} s; recording: {} (open it with `rerun {}`)",
            rrd.display(),
            rrd.display()
        ),
        None => say!("wall time {wall:.2} s; no recording"),
    }
    if let Some(streamed) = streamed {
        say!("{streamed}");
    }
    if let Some(t) = report.interrupted_at {
        return Err(Failure::Interrupted(format!(
            "interrupted at t = {t:.2} s of {} s: the summary and the recording cover the run so far",
            world.duration
        )));
    }
    let mut failures = crate::expect::failures(&world, &report.agents);
    failures.extend(crate::expect::pendulum_failures(&world, &report.pendulums));
    failures.extend(crate::expect::shaped_failures(&world, &report.shaped));
    failures.extend(crate::expect::arm_failures(&world, &report.arms));
    if failures.is_empty() {
        return Ok(());
    }
    let mut message = format!(
        "{}: {} expectation(s) failed:",
        path.display(),
        failures.len()
    );
    for f in &failures {
        message += &format!("\n  {f}");
    }
    Err(Failure::Expectations(message))
}
