//! Running a world headlessly: simulate to the world's duration, record, summarize.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::field::{FieldError, FreeSpace};
use crate::metrics::{self, Summary};
use crate::output::{self, OutputError};
use crate::record::{RecordError, Recorder, Viewer};
use crate::sim::Simulation;
use crate::sim::arm_run::ArmSummary;
use crate::sim::drive::DriveSummary;
use crate::sim::pendulum::PendulumSummary;
use crate::sim::shaped::ShapedSummary;
use crate::world::World;

/// What a run writes.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Where to write the recording; `None` writes no file.
    pub recording: Option<PathBuf>,
    /// A Rerun viewer to stream the run into as it goes, if any (besides the file, if any).
    pub viewer: Option<Viewer>,
    /// Where to write the JSON summary; `None` writes none.
    pub json: Option<PathBuf>,
    /// Show a progress bar on standard error.
    pub progress: bool,
    /// Set (e.g. by a Ctrl-C handler) to stop the run after the current step. The recording is
    /// then closed properly, so it holds the run up to that moment; the JSON summary is not
    /// written (it would look like a finished run's).
    pub interrupt: Option<Arc<AtomicBool>>,
}

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// Some agents' tasks are intractable on their grids: found before anything is solved.
    #[error("{}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n"))]
    Intractable(Vec<FieldError>),
    /// An agent's field could not be built.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// An output cannot be written (found before the run, or when writing it).
    #[error(transparent)]
    Output(#[from] OutputError),
    /// The recording could not be written.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// Writing to the recording failed mid-run.
    #[error("writing the recording failed: {0}")]
    Stream(#[from] rerun::RecordingStreamError),
}

/// The outcome of a run.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The world's name.
    pub world: String,
    /// One summary per agent, in the world file's order.
    pub agents: Vec<Summary>,
    /// One summary per pendulum, in the world file's order (left out of the JSON when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pendulums: Vec<PendulumSummary>,
    /// One summary per shaped agent, in the world file's order (left out of the JSON when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub shaped: Vec<ShapedSummary>,
    /// One summary per arm, in the world file's order (left out of the JSON when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub arms: Vec<ArmSummary>,
    /// The wheels of each agent on wheels, in the world file's order (left out of the JSON
    /// when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub drives: Vec<DriveSummary>,
    /// Wall-clock time of the whole run (fields, simulation, recording).
    #[serde(skip)]
    pub wall_time: Duration,
    /// The recording written, if any.
    #[serde(skip)]
    pub recording: Option<PathBuf>,
    /// How each agent's harmonic field was first solved (none for attractive-repulsive fields).
    #[serde(skip)]
    pub fields: Vec<FieldStats>,
    /// The simulated time at which the run was interrupted, if it was.
    #[serde(skip)]
    pub interrupted_at: Option<f64>,
}

/// How one agent's field was solved.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldStats {
    /// The agent.
    pub agent: String,
    /// Grid cells along x and y.
    pub cells: [usize; 2],
    /// Conjugate gradient iterations over all solves.
    pub iterations: usize,
    /// Solves (the first plus the nested ones for deep regions).
    pub solves: usize,
    /// The worst final relative residual.
    pub relative_residual: f64,
    /// Wall-clock time of the solve.
    pub solve_time: Duration,
    /// For a shaped agent: the heading cells of its (x, y, θ) grid and the time its mask took.
    pub headings: Option<(usize, Duration)>,
    /// For an arm: its joint-space grid, cells per joint from the base out, and the time its
    /// mask took (`cells` is then its last joint's and, with three, the second's).
    pub joints: Option<(Vec<usize>, Duration)>,
}

/// Simulates `world` to its duration.
///
/// Before anything is solved, it checks that every output can be written and that every
/// agent's start connects to its target ([`FreeSpace::intractable`]), so a typo or an
/// impossible task fails at once.
///
/// ```
/// let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
/// let world = nadf::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
/// let report = nadf::run::run(&world, &nadf::run::RunOptions::default()).unwrap();
/// let robot = &report.agents[0];
/// assert!(robot.reached && robot.contacts == 0);
/// assert!(nadf::expect::failures(&world, &report.agents).is_empty());
/// ```
pub fn run(world: &World, options: &RunOptions) -> Result<Report, RunError> {
    let started = Instant::now();
    for path in options.recording.iter().chain(&options.json) {
        output::check_file(path)?;
    }
    let intractable = FreeSpace::intractable(world);
    if !intractable.is_empty() {
        return Err(RunError::Intractable(intractable));
    }
    let mut sim = Simulation::new(world)?;
    let fields = sim
        .agents
        .iter()
        .filter_map(|a| {
            let field = a.field.harmonic()?;
            Some(FieldStats {
                agent: a.agent.name.clone(),
                cells: [field.grid().nx, field.grid().ny],
                iterations: field.iterations,
                solves: field.solves,
                relative_residual: field.relative_residual,
                solve_time: field.solve_time,
                headings: None,
                joints: None,
            })
        })
        .chain(sim.arms.iter().map(|a| FieldStats {
            agent: a.settings.name.clone(),
            cells: [a.field.lattice.dims.nx, a.field.lattice.dims.ny],
            iterations: a.field.iterations,
            solves: a.field.solves,
            relative_residual: a.field.relative_residual,
            solve_time: a.field.solve_time,
            headings: None,
            joints: Some((
                a.field.mask.axes.iter().map(|x| x.cells).collect(),
                a.mask_time,
            )),
        }))
        .chain(sim.shaped.iter().map(|s| FieldStats {
            agent: s.agent.name.clone(),
            cells: [s.field.grid().nx, s.field.grid().ny],
            iterations: s.field.iterations,
            solves: s.field.solves,
            relative_residual: s.field.relative_residual,
            solve_time: s.field.solve_time,
            headings: Some((s.field.mask.headings, s.field.mask_time)),
            joints: None,
        }))
        .collect();
    let mut recorder = match (&options.recording, &options.viewer) {
        (None, None) => None,
        (path, viewer) => {
            let mut r = Recorder::create(path.as_deref(), viewer.as_ref(), world)?;
            if let Err(e) = r.log_setup(&sim) {
                r.abandon();
                return Err(e.into());
            }
            Some(r)
        }
    };
    let bar = options.progress.then(|| {
        let bar = indicatif::ProgressBar::new(world.steps() as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} steps ({eta})")
                .expect("a valid template")
                .progress_chars("=> "),
        );
        bar.set_message(format!("simulating {}", world.name()));
        bar
    });
    let interrupted = || {
        options
            .interrupt
            .as_ref()
            .is_some_and(|i| i.load(Ordering::Relaxed))
    };
    let mut interrupted_at = None;
    while !sim.finished() {
        if interrupted() {
            interrupted_at = Some(sim.time());
            break;
        }
        let states = sim.step();
        if let Some(r) = &mut recorder
            && let Err(e) = r.log_step(&sim, &states)
        {
            recorder.take().expect("present").abandon();
            return Err(e.into());
        }
        if let Some(bar) = &bar {
            bar.inc(1);
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    if let Some(r) = &mut recorder {
        let markdown = verdict(world, &sim, interrupted_at);
        if let Err(e) = r.log_summary(&markdown) {
            recorder.take().expect("present").abandon();
            return Err(e.into());
        }
    }
    let recording = recorder.map(Recorder::finish).transpose()?.flatten();
    let report = Report {
        world: world.name().to_string(),
        agents: sim.summaries(),
        pendulums: sim.pendulum_summaries(),
        shaped: sim.shaped_summaries(),
        arms: sim.arm_summaries(),
        drives: sim.drive_summaries(),
        wall_time: started.elapsed(),
        recording,
        fields,
        interrupted_at,
    };
    if let Some(path) = options.json.as_ref().filter(|_| interrupted_at.is_none()) {
        output::write_atomically(path, report.to_json().as_bytes())?;
    }
    Ok(report)
}

/// The run's verdict as markdown, for the recording: the summary tables of `sim` so far and
/// the expectations of `world` that failed (or that the run was interrupted at the time given).
pub fn verdict(world: &World, sim: &Simulation, interrupted_at: Option<f64>) -> String {
    let summaries = sim.summaries();
    let shaped = sim.shaped_summaries();
    let arms = sim.arm_summaries();
    let mut failures = crate::expect::failures(world, &summaries);
    failures.extend(crate::expect::shaped_failures(world, &shaped));
    failures.extend(crate::expect::arm_failures(world, &arms));
    let mut markdown = format!(
        "```\n{}{}{}{}```\n\n",
        metrics::table(&summaries),
        shaped_table(&shaped),
        arm_table(&arms),
        drive_table(&sim.drive_summaries())
    );
    markdown += &match (interrupted_at, failures.is_empty()) {
        (Some(t), _) => format!("**Interrupted** at {t:.2} s.\n"),
        (None, true) => "No expectation failed.\n".to_string(),
        (None, false) => format!(
            "**{} expectation(s) failed:**\n\n{}\n",
            failures.len(),
            failures
                .iter()
                .map(|f| format!("- {f}"))
                .collect::<Vec<_>>()
                .join("\n")
        ),
    };
    markdown
}

/// The wheels' summaries as a table.
fn drive_table(drives: &[DriveSummary]) -> String {
    let rows: Vec<(&str, &DriveSummary)> = drives.iter().map(|d| (d.name.as_str(), d)).collect();
    metrics::rows_table("wheels", &rows)
}

/// The arms' summaries as a table.
fn arm_table(arms: &[ArmSummary]) -> String {
    let rows: Vec<(&str, &ArmSummary)> = arms.iter().map(|a| (a.name.as_str(), a)).collect();
    metrics::rows_table("arm", &rows)
}

/// The shaped agents' summaries as a table (the disc's columns), and one line each for the
/// heading.
fn shaped_table(shaped: &[ShapedSummary]) -> String {
    if shaped.is_empty() {
        return String::new();
    }
    let summaries: Vec<Summary> = shaped.iter().map(|s| s.summary.clone()).collect();
    let mut out = metrics::table(&summaries);
    for s in shaped {
        out += &format!(
            "{}: final heading {:.4} rad, heading error {}, peak angular speed {:.2} rad/s\n",
            s.summary.name,
            s.final_heading,
            s.heading_error
                .map_or_else(|| "- (any heading)".to_string(), |e| format!("{e:.4} rad")),
            s.peak_angular_speed
        );
    }
    out
}

impl Report {
    /// `{"world": NAME, "agents": [{"name": …, "reached": …, …}]}`, pretty-printed.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("summaries are plain data") + "\n"
    }

    /// The summary as a plain-text table, one row per agent, after one line per field solve.
    pub fn table(&self) -> String {
        let mut out = String::new();
        for f in &self.fields {
            let mask = |t: &Duration| format!(", mask {:.0} ms", t.as_secs_f64() * 1e3);
            let grid = match (&f.headings, &f.joints) {
                (Some((n, t)), _) => format!(
                    "{} x {} cells x {n} headings{}",
                    f.cells[0],
                    f.cells[1],
                    mask(t)
                ),
                (None, Some((cells, t))) => {
                    let cells: Vec<String> = cells.iter().map(ToString::to_string).collect();
                    format!("{} joint cells{}", cells.join(" x "), mask(t))
                }
                (None, None) => format!("{} x {} cells", f.cells[0], f.cells[1]),
            };
            out += &format!(
                "field of {}: {grid}, {} solve(s), {} iterations, relative residual {:.1e}, {:.0} ms\n",
                f.agent,
                f.solves,
                f.iterations,
                f.relative_residual,
                f.solve_time.as_secs_f64() * 1e3
            );
        }
        out += &metrics::table(&self.agents);
        out += &shaped_table(&self.shaped);
        out += &arm_table(&self.arms);
        out += &drive_table(&self.drives);
        if !self.pendulums.is_empty() {
            out += &format!(
                "{:<12} {:>12} {:>9} {:>12} {:>8} {:>7}\n",
                "pendulum", "error_rad", "settle_s", "static_rad", "peak_Nm", "updates"
            );
        }
        for p in &self.pendulums {
            out += &format!(
                "{:<12} {:>12.6} {:>9} {:>12} {:>8.2} {:>7}\n",
                p.name,
                p.final_error,
                p.settling_time
                    .map_or_else(|| "never".to_string(), |t| format!("{t:.2}")),
                p.static_error
                    .map_or_else(|| "-".to_string(), |e| format!("{e:.6}")),
                p.peak_torque,
                p.bias_updates.len()
            );
            for (i, u) in p.bias_updates.iter().enumerate() {
                out += &format!(
                    "  update {} at {:.2} s: error {:.6} rad, β = {:.4} N·m\n",
                    i + 1,
                    u.time,
                    u.error,
                    u.beta
                );
            }
        }
        out
    }
}
