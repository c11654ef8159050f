//! Running a world headlessly: simulate to the world's duration, record, summarize.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use serde::Serialize;

use crate::field::FieldError;
use crate::metrics::Summary;
use crate::record::{RecordError, Recorder};
use crate::sim::Simulation;
use crate::sim::pendulum::PendulumSummary;
use crate::world::World;

/// What a run writes.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Where to write the recording; `None` records nothing.
    pub recording: Option<PathBuf>,
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
    /// An agent's field could not be built (bad input).
    #[error(transparent)]
    Field(#[from] FieldError),
    /// The recording could not be written.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// Writing to the recording failed mid-run.
    #[error("writing the recording failed: {0}")]
    Stream(#[from] rerun::RecordingStreamError),
    /// The JSON summary could not be written.
    #[error("cannot write the summary {path}: {source}")]
    Json {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
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
}

/// Simulates `world` to its duration.
pub fn run(world: &World, options: &RunOptions) -> Result<Report, RunError> {
    let started = Instant::now();
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
            })
        })
        .collect();
    let mut recorder = match &options.recording {
        Some(path) => {
            let mut r = Recorder::create(path, world)?;
            if let Err(e) = r.log_setup(&sim) {
                r.abandon();
                return Err(e.into());
            }
            Some(r)
        }
        None => None,
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
    let recording = recorder.map(Recorder::finish).transpose()?;
    let report = Report {
        world: world.name().to_string(),
        agents: sim.summaries(),
        pendulums: sim.pendulum_summaries(),
        wall_time: started.elapsed(),
        recording,
        fields,
        interrupted_at,
    };
    if let Some(path) = options.json.as_ref().filter(|_| interrupted_at.is_none()) {
        write_atomically(path, report.to_json().as_bytes()).map_err(|source| RunError::Json {
            path: path.clone(),
            source,
        })?;
    }
    Ok(report)
}

/// Writes `bytes` to a temporary file beside `path`, then renames it into place.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut partial = path.as_os_str().to_owned();
    partial.push(".partial");
    let partial = PathBuf::from(partial);
    let result = std::fs::File::create(&partial)
        .and_then(|mut f| f.write_all(bytes).and_then(|()| f.sync_all()))
        .and_then(|()| std::fs::rename(&partial, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&partial);
    }
    result
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
            out += &format!(
                "field of {}: {} x {} cells, {} solve(s), {} iterations, relative residual {:.1e}, {:.0} ms\n",
                f.agent,
                f.cells[0],
                f.cells[1],
                f.solves,
                f.iterations,
                f.relative_residual,
                f.solve_time.as_secs_f64() * 1e3
            );
        }
        if !self.agents.is_empty() {
            out += &format!(
                "{:<12} {:>7} {:>9} {:>9} {:>8} {:>9} {:>9} {:>8} {:>8} {:>9} {:>8}\n",
                "agent",
                "reached",
                "settle_s",
                "error_m",
                "contacts",
                "clear_m",
                "dev_m",
                "path_m",
                "peak_N",
                "var_N",
                "vmax"
            );
        }
        for s in &self.agents {
            let settle = s
                .settling_time
                .map_or_else(|| "never".to_string(), |t| format!("{t:.2}"));
            out += &format!(
                "{:<12} {:>7} {:>9} {:>9.3} {:>8} {:>9.3} {:>9.3} {:>8.2} {:>8.2} {:>9.2} {:>8.2}\n",
                s.name,
                if s.reached { "yes" } else { "no" },
                settle,
                s.final_error,
                s.contacts,
                s.min_clearance,
                s.max_deviation,
                s.path_length,
                s.peak_force,
                s.control_variation,
                s.peak_speed
            );
        }
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
        for s in self.agents.iter().filter(|s| !s.faults.is_clean()) {
            let f = &s.faults;
            out += &format!(
                "faults of {}: {} steps without guidance, {} rejected forces, {} penetrations, {} steps outside the box{}\n",
                s.name,
                f.guidance_lost_steps,
                f.rejected_forces,
                f.penetrations,
                f.left_box_steps,
                if f.non_finite_state {
                    ", non-finite state (frozen)"
                } else {
                    ""
                }
            );
        }
        out
    }
}
