//! `nadf._nadf`: the extension module behind the Python package `nadf` (`python/nadf/`).
//!
//! Everything here calls the crate: a world is loaded by `nadf::world::load`, run by
//! `nadf::run::run` (so a summary is the CLI's `--json`, byte for byte before parsing), stepped
//! by `nadf::sim::Simulation`, and a field is exported by `nadf::field::export` (the `.npy`
//! bytes `nadf field --npy` writes). The Python package turns lists and `.npy` bytes into
//! NumPy arrays; no law, field or metric is computed twice.

use std::path::PathBuf;
use std::sync::Mutex;

use pyo3::create_exception;
use pyo3::exceptions::{PyIndexError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use nadf::field::export;
use nadf::record::{Recorder, Viewer};
use nadf::sim::{AgentRun, AgentState};
use nadf::world::Override;

create_exception!(
    _nadf,
    WorldError,
    PyValueError,
    "A world file that does not load: its message names the file, the line and the key, as \
     `nadf check` does."
);
create_exception!(
    _nadf,
    RunError,
    PyRuntimeError,
    "A run that cannot be done: a target no path reaches, a field that cannot be built, an \
     output that cannot be written."
);

/// The `--set KEY=VALUE` overrides `set`, parsed.
fn overrides(set: Option<Vec<String>>) -> PyResult<Vec<Override>> {
    (set.unwrap_or_default().iter())
        .map(|s| {
            s.parse::<Override>()
                .map_err(|e| WorldError::new_err(format!("--set {s}: {e}")))
        })
        .collect()
}

/// A world file loaded (with its overrides) and checked.
#[pyclass(module = "nadf._nadf", frozen)]
struct World {
    world: nadf::world::World,
    path: PathBuf,
}

#[pymethods]
impl World {
    /// The world's name.
    #[getter]
    fn name(&self) -> String {
        self.world.name().to_string()
    }

    /// The file it was loaded from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// Physics step, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.world.dt
    }

    /// Simulated time of a run, s.
    #[getter]
    fn duration(&self) -> f64 {
        self.world.duration
    }

    /// Physics steps in a run.
    #[getter]
    fn steps(&self) -> usize {
        self.world.steps()
    }

    /// The seed of everything random in a run.
    #[getter]
    fn seed(&self) -> u64 {
        self.world.seed
    }

    /// The box's lower-left and upper-right corners, m.
    #[getter]
    fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        self.world.bounds()
    }

    /// The disc agents' names, in the file's order (the rows of a simulation's arrays).
    #[getter]
    fn agents(&self) -> Vec<String> {
        self.world.agents.iter().map(|a| a.name.clone()).collect()
    }

    /// The moving obstacles' names.
    #[getter]
    fn obstacles(&self) -> Vec<String> {
        (self.world.obstacles.iter().enumerate())
            .map(|(i, o)| o.name_or(i))
            .collect()
    }

    /// The world as JSON: every value as it runs, after the overrides and the defaults (two
    /// worlds that run alike have the same text).
    fn to_json(&self) -> String {
        serde_json::to_string(&self.world).expect("plain data")
    }

    /// The same world with its seed `seed` (everything random in a run drawn anew).
    fn reseeded(&self, seed: u64) -> World {
        let mut world = self.world.clone();
        world.seed = seed;
        World {
            world,
            path: self.path.clone(),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "World({:?}: {} agent(s), {} s at dt = {} s)",
            self.world.name(),
            self.world.agents.len(),
            self.world.duration,
            self.world.dt
        )
    }
}

/// Loads the world file at `path` with the overrides `set` (`["field.cell=0.1", ...]`).
#[pyfunction]
#[pyo3(signature = (path, set = None))]
fn load(path: PathBuf, set: Option<Vec<String>>) -> PyResult<World> {
    let sets = overrides(set)?;
    let world = nadf::world::load(&path, &sets).map_err(|e| WorldError::new_err(e.to_string()))?;
    Ok(World { world, path })
}

/// Runs the world file at `path` to its duration, as `nadf run` does, and returns its summary
/// as the JSON text `nadf run --json` writes. As the CLI's options: the recording `record` (a
/// file), `spawn` (start a Rerun viewer and stream into it), `connect` (stream to the viewer
/// at that URL). The run releases the GIL.
#[pyfunction]
#[pyo3(signature = (path, set = None, record = None, spawn = false, connect = None))]
fn run_json(
    py: Python<'_>,
    path: PathBuf,
    set: Option<Vec<String>>,
    record: Option<PathBuf>,
    spawn: bool,
    connect: Option<String>,
) -> PyResult<String> {
    let World { world, .. } = load(path, set)?;
    let options = nadf::run::RunOptions {
        recording: record,
        viewer: Viewer::from_flags(spawn, connect),
        ..Default::default()
    };
    let report = py
        .detach(|| nadf::run::run(&world, &options))
        .map_err(|e| RunError::new_err(e.to_string()))?;
    Ok(report.to_json())
}

/// A running simulation of a world's disc agents.
#[pyclass(module = "nadf._nadf", frozen)]
struct Simulation {
    inner: Mutex<Running>,
}

/// The simulation, each agent's state after the last step (none before the first), and the
/// recording being written or streamed, if any.
struct Running {
    sim: nadf::sim::Simulation,
    states: Vec<AgentState>,
    recorder: Option<Recorder>,
}

impl Running {
    /// Ends the recording, if any: the verdict so far logged (interrupted, if the run has not
    /// reached its duration), the file moved into place; returns the file.
    fn close(&mut self) -> PyResult<Option<PathBuf>> {
        let Some(mut recorder) = self.recorder.take() else {
            return Ok(None);
        };
        let world = &self.sim.world;
        let at = (!self.sim.finished()).then(|| self.sim.time());
        if let Err(e) = recorder.log_summary(&nadf::run::verdict(world, &self.sim, at)) {
            recorder.abandon();
            return Err(RunError::new_err(format!(
                "writing the recording failed: {e}"
            )));
        }
        recorder
            .finish()
            .map_err(|e| RunError::new_err(e.to_string()))
    }
}

impl Drop for Running {
    /// A simulation dropped with its recording open still leaves a complete file (up to where
    /// it was stepped), never a `.partial` one.
    fn drop(&mut self) {
        let _ = self.close();
    }
}

impl Simulation {
    fn with<T>(&self, f: impl FnOnce(&mut Running) -> T) -> T {
        let mut running = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut running)
    }

    /// `f` of each agent and its state after the last step (none before the first), in order.
    fn per_agent<T>(&self, f: impl Fn(&AgentRun, Option<&AgentState>) -> T) -> Vec<T> {
        self.with(|r| {
            (r.sim.agents.iter().enumerate())
                .map(|(i, a)| f(a, r.states.get(i)))
                .collect()
        })
    }
}

#[pymethods]
impl Simulation {
    /// Builds the world's Rapier world and solves every agent's field; with `record`, `spawn`
    /// or `connect` (as `run_json`'s), every step is recorded until `close`.
    #[new]
    #[pyo3(signature = (world, record = None, spawn = false, connect = None))]
    fn new(
        py: Python<'_>,
        world: &World,
        record: Option<PathBuf>,
        spawn: bool,
        connect: Option<String>,
    ) -> PyResult<Self> {
        let world = &world.world;
        let viewer = Viewer::from_flags(spawn, connect);
        if let Some(path) = &record {
            nadf::output::check_file(path).map_err(|e| RunError::new_err(e.to_string()))?;
        }
        let intractable = nadf::field::FreeSpace::intractable(world);
        if !intractable.is_empty() {
            let messages: Vec<String> = intractable.iter().map(ToString::to_string).collect();
            return Err(RunError::new_err(messages.join("\n")));
        }
        let sim = py
            .detach(|| nadf::sim::Simulation::new(world))
            .map_err(|e| RunError::new_err(e.to_string()))?;
        let recorder = match (&record, &viewer) {
            (None, None) => None,
            (path, viewer) => {
                let mut r = Recorder::create(path.as_deref(), viewer.as_ref(), world)
                    .map_err(|e| RunError::new_err(e.to_string()))?;
                if let Err(e) = r.log_setup(&sim) {
                    r.abandon();
                    return Err(RunError::new_err(format!(
                        "writing the recording failed: {e}"
                    )));
                }
                Some(r)
            }
        };
        Ok(Self {
            inner: Mutex::new(Running {
                sim,
                states: Vec::new(),
                recorder,
            }),
        })
    }

    /// Advances `n` physics steps (the GIL released while they run), recording each if the
    /// simulation records; returns the time, s.
    #[pyo3(signature = (n = 1))]
    fn step(&self, py: Python<'_>, n: usize) -> PyResult<f64> {
        py.detach(|| {
            self.with(|r| {
                for _ in 0..n {
                    r.states = r.sim.step();
                    if let Some(recorder) = &mut r.recorder
                        && let Err(e) = recorder.log_step(&r.sim, &r.states)
                    {
                        if let Some(recorder) = r.recorder.take() {
                            recorder.abandon();
                        }
                        return Err(RunError::new_err(format!(
                            "writing the recording failed: {e}"
                        )));
                    }
                }
                Ok(r.sim.time())
            })
        })
    }

    /// Commands the force applied to agent `agent` from the next step on, N (`None`: its law
    /// drives it again); see `AgentRun::command`.
    #[pyo3(signature = (agent, force = None))]
    fn command(&self, agent: usize, force: Option<[f64; 2]>) -> PyResult<()> {
        self.with(|r| {
            let count = r.sim.agents.len();
            let run = (r.sim.agents.get_mut(agent)).ok_or_else(|| no_such_agent(agent, count))?;
            if run.command(force.map(nalgebra::Vector2::from)) {
                Ok(())
            } else {
                Err(PyValueError::new_err(format!(
                    "agent `{}` cannot be commanded {force:?} N: a force must be finite, and a robot under the unicycle law commands its wheels itself",
                    run.agent.name
                )))
            }
        })
    }

    /// Ends the recording, if any (its verdict logged, the file moved into place) and returns
    /// the file; the simulation may step on, unrecorded.
    fn close(&self, py: Python<'_>) -> PyResult<Option<PathBuf>> {
        py.detach(|| self.with(Running::close))
    }

    /// Simulated time, s.
    #[getter]
    fn time(&self) -> f64 {
        self.with(|r| r.sim.time())
    }

    /// Whether the run has reached the world's duration.
    #[getter]
    fn finished(&self) -> bool {
        self.with(|r| r.sim.finished())
    }

    /// Each agent's position, m (its start before the first step).
    fn positions(&self) -> Vec<[f64; 2]> {
        self.per_agent(|a, s| motion(a, s).0)
    }

    /// Each agent's velocity, m/s.
    fn velocities(&self) -> Vec<[f64; 2]> {
        self.per_agent(|a, s| motion(a, s).1)
    }

    /// The control force each agent applied in the last step, N (zero before the first).
    fn forces(&self) -> Vec<[f64; 2]> {
        self.per_agent(|_, s| s.map_or([0.0, 0.0], |s| s.force.into()))
    }

    /// Each agent's heading, rad: a robot on wheels' own, another's the direction of its
    /// velocity (0 at rest).
    fn headings(&self) -> Vec<f64> {
        self.per_agent(|a, s| match s {
            Some(AgentState {
                axle: Some((_, heading)),
                ..
            }) => *heading,
            Some(s) if s.velocity.norm() > 0.0 => s.velocity.y.atan2(s.velocity.x),
            Some(_) => 0.0,
            None => a.agent.heading,
        })
    }

    /// Contact starts of each agent so far (against anything).
    fn contacts(&self) -> Vec<usize> {
        self.with(|r| r.sim.agents.iter().map(|a| a.metrics.contacts()).collect())
    }

    /// Whether each agent touches something now.
    fn touching(&self) -> Vec<bool> {
        self.per_agent(|_, s| s.is_some_and(|s| !s.contact_points.is_empty()))
    }

    /// Each agent's summary so far, as the JSON text of a summary's `agents` (a list).
    fn summaries_json(&self) -> String {
        self.with(|r| serde_json::to_string(&r.sim.summaries()).expect("plain data"))
    }

    /// The `.npy` files of agent `agent`'s current harmonic field, as `nadf field --npy`
    /// writes them: `V`, `1 − V`, `log10(1 − V)` and the mask, each `[nx, ny]`, and the grid's
    /// origin and cell, m.
    #[allow(clippy::type_complexity)]
    fn field_npy<'py>(
        &self,
        py: Python<'py>,
        agent: usize,
    ) -> PyResult<([Bound<'py, PyBytes>; 4], [f64; 2], f64)> {
        self.with(|r| {
            let count = r.sim.agents.len();
            let (world, run) = (&r.sim.world, r.sim.agents.get_mut(agent));
            let run = run.ok_or_else(|| no_such_agent(agent, count))?;
            // A commanded lidar agent's field as the law would read it now.
            run.bring_up_to_date(world);
            let field = run.field.harmonic().ok_or_else(|| {
                PyValueError::new_err(format!(
                    "agent `{}` has no harmonic field (an attractive-repulsive potential has no grid)",
                    run.agent.name
                ))
            })?;
            let arrays = [
                export::potential_npy(field),
                export::one_minus_potential_npy(field),
                export::log10_one_minus_potential_npy(field),
                export::mask_npy(field),
            ]
            .map(|bytes| PyBytes::new(py, &bytes));
            Ok((arrays, field.grid().origin, field.grid().cell))
        })
    }

    /// What an environment needs to know of agent `agent` once: its target (m), radius (m),
    /// mass (kg), `max_force` (N, if any), the half-width of its settling band (m, where
    /// `reached` is judged), and its lidar's rays and range (m), if it has one.
    #[allow(clippy::type_complexity)]
    fn agent_info(
        &self,
        agent: usize,
    ) -> PyResult<([f64; 2], f64, f64, Option<f64>, f64, Option<(usize, f64)>)> {
        self.with(|r| {
            let run = agent_of(&r.sim, agent)?;
            let a = &run.agent;
            let lidar = run.lidar.as_ref().map(|l| {
                let s = &l.lidar.settings;
                let rays = s.rays.unwrap_or(nadf::sim::lidar::DEFAULT_RAYS).max(1) as usize;
                (rays, s.range.unwrap_or(0.0))
            });
            let band = run.metrics.band();
            Ok((
                a.target,
                a.radius,
                a.mass,
                a.controller.max_force,
                band,
                lidar,
            ))
        })
    }

    /// Agent `agent`'s state for an observation, in one call: its position (m), velocity
    /// (m/s), the angle of its body frame (rad: a robot on wheels' heading, 0 for a disc,
    /// which has no orientation), the unit direction of steepest descent of its field at its
    /// position (`None` where the field has none), its lidar's last ranges as little-endian
    /// `f32` bytes (`None` without a lidar; empty before the first scan), and its contact
    /// starts so far.
    #[allow(clippy::type_complexity)]
    fn observation<'py>(
        &self,
        py: Python<'py>,
        agent: usize,
    ) -> PyResult<(
        [f64; 2],
        [f64; 2],
        f64,
        Option<[f64; 2]>,
        Option<Bound<'py, PyBytes>>,
        usize,
    )> {
        self.with(|r| {
            let run = agent_of(&r.sim, agent)?;
            let state = r.states.get(agent);
            let (position, velocity) = motion(run, state);
            let frame = match state {
                Some(AgentState {
                    axle: Some((_, heading)),
                    ..
                }) => *heading,
                _ if run.agent.drive.is_some() => run.agent.heading,
                _ => 0.0,
            };
            let guidance = (run.field.gradient(position))
                .and_then(|g| nadf::control::unit(&-g))
                .map(Into::into);
            let ranges = run.lidar.as_ref().map(|l| {
                let bytes: Vec<u8> = (l.lidar.ranges().iter())
                    .flat_map(|r| (*r as f32).to_le_bytes())
                    .collect();
                PyBytes::new(py, &bytes)
            });
            Ok((
                position,
                velocity,
                frame,
                guidance,
                ranges,
                run.metrics.contacts(),
            ))
        })
    }

    /// The force agent `agent`'s law would apply in the next step from the state it is in
    /// now, N, computed without changing the run (`Simulation::law_force`): the expert's
    /// action. The field is the current one (a replan or a scan due in the next step is not
    /// anticipated); for a commanded lidar agent, the walls it has seen since its field was
    /// last solved are solved for first (with the GIL released).
    fn law_force(&self, py: Python<'_>, agent: usize) -> PyResult<[f64; 2]> {
        py.detach(|| {
            self.with(|r| {
                agent_of(&r.sim, agent)?;
                Ok(r.sim.law_force(agent).map_or([0.0; 2], Into::into))
            })
        })
    }
}

/// An agent's position (m) and velocity (m/s) after the last step `state`; its start and
/// initial velocity before the first.
fn motion(run: &AgentRun, state: Option<&AgentState>) -> ([f64; 2], [f64; 2]) {
    state.map_or((run.agent.start, run.agent.initial_velocity), |s| {
        (s.position.into(), s.velocity.into())
    })
}

/// Agent `agent` of `sim`, or an `IndexError` naming how many there are.
fn agent_of(sim: &nadf::sim::Simulation, agent: usize) -> PyResult<&AgentRun> {
    (sim.agents.get(agent)).ok_or_else(|| no_such_agent(agent, sim.agents.len()))
}

/// The `IndexError` for agent `agent` of a simulation of `count` agents.
fn no_such_agent(agent: usize, count: usize) -> PyErr {
    PyIndexError::new_err(format!("agent {agent}: the world has {count} agent(s)"))
}

/// Runs shard `index` of `count` of the experiment file at `path` (with the overrides `set`)
/// into its directory under `out` on `threads` threads (all cores when `None`), as `nadf
/// experiment --shard` does, keeping the runs already done with `resume`; the GIL released.
/// Returns the shard's directory and the runs done now and before.
#[pyfunction]
#[pyo3(signature = (path, out, index = 0, count = 1, resume = false, threads = None, set = None))]
#[allow(clippy::too_many_arguments)]
fn experiment_shard(
    py: Python<'_>,
    path: PathBuf,
    out: PathBuf,
    index: u64,
    count: u64,
    resume: bool,
    threads: Option<usize>,
    set: Option<Vec<String>>,
) -> PyResult<(PathBuf, usize, usize)> {
    let sets = overrides(set)?;
    let shard: nadf::experiment::Shard = format!("{index}/{count}")
        .parse()
        .map_err(|e: String| PyValueError::new_err(e))?;
    let exp = nadf::experiment::Experiment::load(&path, &sets)
        .map_err(|e| WorldError::new_err(e.to_string()))?;
    let done = py
        .detach(|| exp.run_shard(shard, &out, (resume, threads), &|_, _| {}, None))
        .map_err(RunError::new_err)?;
    if !done.complete {
        return Err(RunError::new_err(format!("shard {shard} did not complete")));
    }
    Ok((shard.dir(&out), done.ran, done.resumed))
}

/// The experiment file at `path` (with the overrides `set`) loaded and checked: its name, its
/// digest (what its shards' manifests must carry) and its runs.
#[pyfunction]
#[pyo3(signature = (path, set = None))]
fn experiment_info(path: PathBuf, set: Option<Vec<String>>) -> PyResult<(String, String, u64)> {
    let sets = overrides(set)?;
    let exp = nadf::experiment::Experiment::load(&path, &sets)
        .map_err(|e| WorldError::new_err(e.to_string()))?;
    Ok((exp.name, exp.digest, exp.runs))
}

/// Merges the complete shards in `dirs` into `out`, as `nadf merge` does; returns the
/// summary's table as text. The GIL released.
#[pyfunction]
fn merge(py: Python<'_>, dirs: Vec<PathBuf>, out: PathBuf) -> PyResult<String> {
    py.detach(|| nadf::experiment::batch::merge(&dirs, &out))
        .map(|merged| nadf::experiment::results::groups_table(&merged.groups))
        .map_err(RunError::new_err)
}

/// The extension module.
#[pymodule]
fn _nadf(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(run_json, m)?)?;
    m.add_function(wrap_pyfunction!(experiment_shard, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(experiment_info, m)?)?;
    m.add_class::<World>()?;
    m.add_class::<Simulation>()?;
    m.add("WorldError", m.py().get_type::<WorldError>())?;
    m.add("RunError", m.py().get_type::<RunError>())?;
    Ok(())
}
