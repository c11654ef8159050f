//! `nadf reproduce`: the paper, claim by claim. One table in the code ([`claims`]) says, for
//! each claim of §II–§VI, which runs measure it, what the paper states, the quantity measured
//! and the relation the paper's statement asks of it; the command and the tests both read it,
//! so the report and CI can never disagree.
//!
//! A claim's verdict is *reproduced* when the paper's relation holds, and otherwise the weaker
//! or different relation the sandbox does reach, with the reason in one line: *weaker* (the
//! same direction, less strength) or *differs* (not the paper's result). The tests assert the
//! paper's relation where it is reproduced and the sandbox's where it is not, so a change
//! that loses a reproduced claim, or a weaker one, fails.
//!
//! - [`calibration`]: the one calibration every law's runs share, and how it is derived.
//! - [`experiments`], [`claims`], [`figures`]: the table.
//! - [`run_all`]: runs the experiments in parallel (each once, traced step by step).
//! - [`report`]: `report.md` and `report.json`; [`figure`]: one PNG per figure.

pub mod calibration;
mod claims;
pub mod figure;
pub mod report;

pub use claims::{
    Check, Claim, Experiment, Law, Relation, Verdict, calibrated_gain, calibration_curve, claims,
    experiments, figures, gain_of, gain_run, settle, sweep,
};

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::metrics::Summary;
use crate::sim::Simulation;
use crate::sim::pendulum::PendulumSummary;
use crate::world::{Override, World, load_str};

/// The shipped worlds the experiments use, compiled in so that `nadf reproduce` runs anywhere.
pub const WORLDS: &[(&str, &str)] = &[
    (
        "paper-room.toml",
        include_str!("../../worlds/paper-room.toml"),
    ),
    (
        "room-drift-sliding.toml",
        include_str!("../../worlds/room-drift-sliding.toml"),
    ),
    (
        "room-initial-velocity.toml",
        include_str!("../../worlds/room-initial-velocity.toml"),
    ),
    ("corridor.toml", include_str!("../../worlds/corridor.toml")),
    (
        "corridor-obstruction.toml",
        include_str!("../../worlds/corridor-obstruction.toml"),
    ),
    (
        "corridor-barrier.toml",
        include_str!("../../worlds/corridor-barrier.toml"),
    ),
    (
        "corridor-obstacles.toml",
        include_str!("../../worlds/corridor-obstacles.toml"),
    ),
    (
        "corridor-position-noise.toml",
        include_str!("../../worlds/corridor-position-noise.toml"),
    ),
    ("swap.toml", include_str!("../../worlds/swap.toml")),
    (
        "swap-viscous.toml",
        include_str!("../../worlds/swap-viscous.toml"),
    ),
    ("crowd.toml", include_str!("../../worlds/crowd.toml")),
    ("pendulum.toml", include_str!("../../worlds/pendulum.toml")),
    (
        "pendulum-bias.toml",
        include_str!("../../worlds/pendulum-bias.toml"),
    ),
];

/// One step of a traced run: the time and, per agent, position and velocity (m, m/s), the
/// control force (N), the radial speed (m/s) and the potential V; per pendulum, the angle (rad).
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Simulated time at the end of the step, s.
    pub time: f64,
    /// Per agent: `[x, y, vx, vy, fx, fy, radial speed, V]`.
    pub agents: Vec<[f64; 8]>,
    /// Per pendulum: θ, rad.
    pub pendulums: Vec<f64>,
}

/// What one experiment gave.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The legend of the experiment's line in a figure.
    pub label: String,
    /// The world as run (with the experiment's overrides).
    pub world: World,
    /// Each agent's summary.
    pub agents: Vec<Summary>,
    /// Each pendulum's summary.
    pub pendulums: Vec<PendulumSummary>,
    /// Every step.
    pub trace: Vec<Sample>,
    /// Wall-clock time of the run.
    pub wall_time: Duration,
}

impl Outcome {
    /// The first agent's summary.
    pub fn summary(&self) -> &Summary {
        &self.agents[0]
    }
}

/// The outcomes by experiment id.
pub type Outcomes = BTreeMap<String, Outcome>;

/// Why reproducing could not be done.
#[derive(Debug, thiserror::Error)]
pub enum ReproduceError {
    /// A world of the table does not load (a bug of the table: the worlds are compiled in).
    #[error("experiment `{id}`: {message}")]
    World {
        /// The experiment.
        id: String,
        /// What went wrong.
        message: String,
    },
    /// `--only` named no known figure or claim.
    #[error("--only {0}: no figure or claim of that name (figures: {1})")]
    Unknown(String, String),
    /// Stopped by the user.
    #[error("interrupted after {done} of {total} runs")]
    Interrupted {
        /// Runs finished.
        done: usize,
        /// Runs asked for.
        total: usize,
    },
    /// The thread pool could not be built.
    #[error("cannot start {0} threads: {1}")]
    Threads(usize, String),
}

/// The world of `experiment`, loaded from the compiled-in text with its overrides.
pub fn world_of(experiment: &Experiment) -> Result<World, ReproduceError> {
    let bad = |message: String| ReproduceError::World {
        id: experiment.id.clone(),
        message,
    };
    let text = WORLDS
        .iter()
        .find(|(name, _)| *name == experiment.world)
        .map(|(_, text)| *text)
        .ok_or_else(|| bad(format!("no compiled-in world {}", experiment.world)))?;
    let overrides = experiment
        .overrides
        .iter()
        .map(|o| o.parse::<Override>().map_err(|e| bad(e.to_string())))
        .collect::<Result<Vec<_>, _>>()?;
    let mut world = load_str(
        text,
        &Path::new("worlds").join(experiment.world),
        &overrides,
    )
    .map_err(|e| bad(e.to_string()))?;
    // The paper's laws bare: the clearance envelope is the sandbox's, not the paper's.
    for agent in &mut world.agents {
        agent.controller.envelope = false;
    }
    Ok(world)
}

/// Runs one experiment step by step, keeping every step.
pub fn run_one(experiment: &Experiment) -> Result<Outcome, ReproduceError> {
    let world = world_of(experiment)?;
    let started = Instant::now();
    let mut sim = Simulation::new(&world).map_err(|e| ReproduceError::World {
        id: experiment.id.clone(),
        message: e.to_string(),
    })?;
    let mut trace = Vec::with_capacity(world.steps());
    while !sim.finished() {
        let states = sim.step();
        trace.push(Sample {
            time: sim.time(),
            agents: states
                .iter()
                .map(|s| {
                    let (p, v, f) = (s.position, s.velocity, s.force);
                    [p.x, p.y, v.x, v.y, f.x, f.y, s.radial_speed, s.potential]
                })
                .collect(),
            pendulums: sim.pendulums.iter().map(|p| p.state.theta).collect(),
        });
    }
    Ok(Outcome {
        label: experiment.label.clone(),
        agents: sim.summaries(),
        pendulums: sim.pendulum_summaries(),
        world,
        trace,
        wall_time: started.elapsed(),
    })
}

/// The experiments the claims and figures named in `only` need (all when `only` is empty):
/// each name is a figure id or a claim id.
pub fn select(only: &[String]) -> Result<(Vec<Claim>, Vec<figure::Figure>), ReproduceError> {
    let (all_claims, all_figures) = (claims(), figures());
    if only.is_empty() {
        return Ok((all_claims, all_figures));
    }
    for name in only {
        let known =
            all_figures.iter().any(|f| &f.id == name) || all_claims.iter().any(|c| &c.id == name);
        if !known {
            let ids: Vec<&str> = all_figures.iter().map(|f| f.id.as_str()).collect();
            return Err(ReproduceError::Unknown(name.clone(), ids.join(", ")));
        }
    }
    let wanted = |id: &str, figure: &str| only.iter().any(|o| o == id || o == figure);
    let chosen: Vec<Claim> = all_claims
        .into_iter()
        .filter(|c| wanted(&c.id, &c.figure))
        .collect();
    let figures = all_figures
        .into_iter()
        .filter(|f| only.contains(&f.id) || chosen.iter().any(|c| c.figure == f.id))
        .collect();
    Ok((chosen, figures))
}

/// Every experiment `claims` and `figures` need, each once, in the table's order.
pub fn needed(claims: &[Claim], figures: &[figure::Figure]) -> Vec<Experiment> {
    experiments()
        .into_iter()
        .filter(|e| {
            claims.iter().any(|c| c.runs.contains(&e.id))
                || figures.iter().any(|f| f.runs().contains(&e.id))
        })
        .collect()
}

/// Runs `experiments` on `threads` threads (all cores when `None`), calling `progress` after
/// each; stops early when `interrupt` is set.
pub fn run_all(
    experiments: &[Experiment],
    threads: Option<usize>,
    progress: &(dyn Fn() + Sync),
    interrupt: Option<&AtomicBool>,
) -> Result<Outcomes, ReproduceError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n);
    }
    let pool = builder
        .build()
        .map_err(|e| ReproduceError::Threads(threads.unwrap_or(0), e.to_string()))?;
    // The longest runs first, so that two threads finish together.
    let mut order: Vec<&Experiment> = experiments.iter().collect();
    order.sort_by_key(|e| std::cmp::Reverse(e.cost));
    let results: Vec<Option<Result<Outcome, ReproduceError>>> = pool.install(|| {
        order
            .par_iter()
            .map(|e| {
                if interrupt.is_some_and(|i| i.load(Ordering::Relaxed)) {
                    return None;
                }
                let outcome = run_one(e);
                progress();
                Some(outcome)
            })
            .collect()
    });
    let done = results.iter().filter(|r| r.is_some()).count();
    if done < experiments.len() {
        return Err(ReproduceError::Interrupted {
            done,
            total: experiments.len(),
        });
    }
    let mut outcomes = Outcomes::new();
    for (e, result) in order.into_iter().zip(results) {
        outcomes.insert(e.id.clone(), result.expect("every experiment ran")?);
    }
    Ok(outcomes)
}

/// One claim checked against the outcomes.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    /// The claim's id.
    pub id: String,
    /// The measured quantity.
    pub measured: f64,
    /// The verdict.
    pub verdict: Verdict,
    /// Whether the relation the sandbox is held to (the paper's where it is reproduced) holds.
    pub holds: bool,
}

/// Checks every claim against `outcomes` (which must hold the claims' runs).
pub fn check(claims: &[Claim], outcomes: &Outcomes) -> Vec<Checked> {
    claims
        .iter()
        .map(|c| {
            let measured = (c.measure)(outcomes);
            // A claim the table expects reproduced that is not "differs" (and fails its test).
            let verdict = match (c.paper.holds(measured), c.otherwise.verdict) {
                (true, _) => Verdict::Reproduced,
                (false, Verdict::Reproduced) => Verdict::Differs,
                (false, v) => v,
            };
            let holds = match c.otherwise.verdict {
                Verdict::Reproduced => c.paper.holds(measured),
                _ => c.otherwise.relation.holds(measured),
            };
            Checked {
                id: c.id.clone(),
                measured,
                verdict,
                holds,
            }
        })
        .collect()
}
