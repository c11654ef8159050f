//! Scenario batches (`nadf scen`): a world on a Moving AI map run once per scenario of the
//! map's `.map.scen` file, the first agent moved to each scenario's start and goal, in
//! parallel; a CSV of every run and a plot of success and path length against the optimal one.
//!
//! A scenario names cells, x right and y down from the map's top row; the agent starts and
//! aims at their centres (y flipped to the world's y-up). A scenario the agent's disc cannot do
//! (its start or goal in or too near a wall for the disc, the two on separate islands, start
//! and goal the same cell) is reported as skipped, with the reason, not run and not counted as
//! a failure. Runs are deterministic, so the CSV does not depend on the threads.

mod plot;

use std::path::{Path, PathBuf};

pub use plot::plot;

use crate::field::FreeSpace;
use crate::metrics::{Summary, Value, csv_field, metrics_of, values_of};
use crate::sweep::{self, Case, SweepError};
use crate::world::map::{Scenario, read_scenarios};
use crate::world::{World, validate};

/// One scenario of the batch: what it is, and its world or why it is skipped.
#[derive(Debug, Clone)]
pub struct Entry {
    /// The scenario.
    pub scenario: Scenario,
    /// The optimal length, m.
    pub optimal: f64,
    /// The world to run, or why the scenario is skipped.
    pub world: Result<World, String>,
}

/// One scenario's outcome.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The scenario.
    pub scenario: Scenario,
    /// The optimal length, m.
    pub optimal: f64,
    /// The first agent's summary, or why the scenario was skipped.
    pub summary: Result<Summary, String>,
}

impl Outcome {
    /// The path length over the optimal length (of a run that reached its goal).
    pub fn path_ratio(&self) -> Option<f64> {
        let s = self.summary.as_ref().ok().filter(|s| s.reached)?;
        (self.optimal > 0.0).then(|| s.path_length / self.optimal)
    }
}

/// Why a batch cannot start.
#[derive(Debug, thiserror::Error)]
pub enum ScenError {
    /// The world has no Moving AI map.
    #[error("a scenario batch needs a world whose [map] is a Moving AI `.map`")]
    NoMap,
    /// The world has no agent to move.
    #[error("a scenario batch moves the world's first agent, and it has none")]
    NoAgent,
    /// The scenarios cannot be read.
    #[error(transparent)]
    Scenarios(#[from] crate::world::map::MapError),
    /// The scenarios are for another map.
    #[error("{file}: line {line} is for the map `{theirs}`, the world's map is `{ours}`")]
    OtherMap {
        /// The scenario file.
        file: PathBuf,
        /// The line.
        line: usize,
        /// The map the scenario names.
        theirs: String,
        /// The world's map.
        ours: String,
    },
    /// No scenario is left after the filters.
    #[error("no scenario left to run (buckets {0:?})")]
    Empty(Vec<u32>),
}

/// The scenarios of `file` for `world`'s map: those in `buckets` (all when empty), at most
/// `count` of them spread evenly over the list (all when `None`), each with its world or the
/// reason it is skipped.
pub fn entries(
    world: &World,
    file: &Path,
    buckets: &[u32],
    count: Option<usize>,
) -> Result<Vec<Entry>, ScenError> {
    let map = &world.loaded_map.as_ref().ok_or(ScenError::NoMap)?.occupancy;
    let is_moving_ai = map.file.extension().is_some_and(|e| e == "map");
    if !is_moving_ai {
        return Err(ScenError::NoMap);
    }
    if world.agents.is_empty() {
        return Err(ScenError::NoAgent);
    }
    let ours = map
        .file
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let mut scenarios = read_scenarios(file)?;
    if let Some(s) = scenarios.iter().find(|s| s.map != ours) {
        return Err(ScenError::OtherMap {
            file: file.to_path_buf(),
            line: s.line,
            theirs: s.map.clone(),
            ours,
        });
    }
    scenarios.retain(|s| buckets.is_empty() || buckets.contains(&s.bucket));
    if let Some(n) = count
        && n < scenarios.len()
    {
        let total = scenarios.len();
        scenarios = (0..n).map(|i| scenarios[i * total / n].clone()).collect();
    }
    if scenarios.is_empty() {
        return Err(ScenError::Empty(buckets.to_vec()));
    }
    Ok(scenarios
        .into_iter()
        .map(|scenario| {
            let optimal = scenario.optimal * map.cell;
            let world = scenario_world(world, &scenario);
            Entry {
                scenario,
                optimal,
                world,
            }
        })
        .collect())
}

/// The world with its first agent at the scenario's start, aiming at its goal; or why the
/// scenario cannot be run.
fn scenario_world(world: &World, s: &Scenario) -> Result<World, String> {
    let map = &world.loaded_map.as_ref().expect("checked").occupancy;
    let [w, h] = [map.width, map.height];
    if s.size != [w, h] {
        return Err(format!(
            "the scenario is for a {} × {} map, the map is {w} × {h}",
            s.size[0], s.size[1]
        ));
    }
    let centre = |[x, y]: [usize; 2], what: &str| {
        if x >= w || y >= h {
            return Err(format!("its {what} ({x}, {y}) is off the map"));
        }
        // Scenario y grows down from the top row.
        Ok(map.center(x, h - 1 - y))
    };
    if s.start == s.goal {
        return Err("its start and goal are the same cell".into());
    }
    let mut world = world.clone();
    world.agents[0].start = centre(s.start, "start")?;
    world.agents[0].target = centre(s.goal, "goal")?;
    let problems = validate(&world);
    if let Some((key, message)) = problems.first() {
        return Err(format!("`{key}`: {message}"));
    }
    if let Some(e) = FreeSpace::intractable(&world).first() {
        return Err(e.to_string());
    }
    Ok(world)
}

/// Runs every entry that is not skipped on `threads` threads (all cores when `None`), calling
/// `progress` after each, stopping early when `interrupt` is set.
pub fn run_all(
    entries: &[Entry],
    threads: Option<usize>,
    progress: &(dyn Fn() + Sync),
    interrupt: Option<&std::sync::atomic::AtomicBool>,
) -> Result<Vec<Outcome>, SweepError> {
    let cases: Vec<Case> = entries
        .iter()
        .enumerate()
        .filter_map(|(i, e)| {
            let world = e.world.as_ref().ok()?.clone();
            Some(Case {
                values: vec![i as f64],
                world,
            })
        })
        .collect();
    let done = sweep::run_all(&["scenario".into()], &cases, threads, progress, interrupt)?;
    let mut summaries: Vec<Option<Summary>> = vec![None; entries.len()];
    for (values, mut agents) in done.runs {
        summaries[values[0] as usize] = Some(agents.swap_remove(0));
    }
    Ok(entries
        .iter()
        .zip(summaries)
        .map(|(e, s)| Outcome {
            scenario: e.scenario.clone(),
            optimal: e.optimal,
            summary: match (&e.world, s) {
                (Ok(_), Some(s)) => Ok(s),
                (Err(why), _) => Err(why.clone()),
                (Ok(_), None) => Err("not run".into()),
            },
        })
        .collect())
}

/// The CSV of a batch: per scenario its line, bucket, cells, optimal length (m), why it was
/// skipped (empty if it ran), the path over the optimal length, then every summary metric
/// (empty for a skipped one).
pub fn csv(outcomes: &[Outcome]) -> String {
    let mut header: Vec<String> = [
        "line",
        "bucket",
        "start_x",
        "start_y",
        "goal_x",
        "goal_y",
        "optimal_m",
        "skipped",
        "path_ratio",
    ]
    .map(String::from)
    .to_vec();
    let metrics = metrics_of::<Summary>();
    header.extend(metrics.iter().map(|m| m.key.to_string()));
    let mut out = header.join(",") + "\n";
    for o in outcomes {
        let s = &o.scenario;
        let mut row = vec![
            s.line.to_string(),
            s.bucket.to_string(),
            s.start[0].to_string(),
            s.start[1].to_string(),
            s.goal[0].to_string(),
            s.goal[1].to_string(),
            format!("{}", o.optimal),
            csv_field(o.summary.as_ref().err().map_or("", String::as_str)),
            o.path_ratio().map_or_else(String::new, |r| format!("{r}")),
        ];
        match &o.summary {
            Ok(summary) => row.extend(values_of(summary).iter().map(Value::to_string)),
            Err(_) => row.extend(std::iter::repeat_n(String::new(), metrics.len())),
        }
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// What a batch came to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Totals {
    /// Scenarios run.
    pub run: usize,
    /// Scenarios skipped.
    pub skipped: usize,
    /// Runs that reached their goal.
    pub reached: usize,
    /// Contacts over all runs.
    pub contacts: usize,
    /// The mean path over optimal length of the runs that reached their goal.
    pub mean_path_ratio: Option<f64>,
}

/// The batch's totals.
pub fn totals(outcomes: &[Outcome]) -> Totals {
    let runs: Vec<&Summary> = outcomes
        .iter()
        .filter_map(|o| o.summary.as_ref().ok())
        .collect();
    let ratios: Vec<f64> = outcomes.iter().filter_map(Outcome::path_ratio).collect();
    Totals {
        run: runs.len(),
        skipped: outcomes.len() - runs.len(),
        reached: runs.iter().filter(|s| s.reached).count(),
        contacts: runs.iter().map(|s| s.contacts).sum(),
        mean_path_ratio: (!ratios.is_empty())
            .then(|| ratios.iter().sum::<f64>() / ratios.len() as f64),
    }
}
