//! Experiments (`nadf experiment EXP.toml`): a world run many times, each run with its values
//! of the sampled keys drawn from its own stream, seeded by the experiment's seed and the run's
//! index, so run `k` is the same whatever runs beside it — on one machine, in shards, or on a
//! cluster.
//!
//! ```toml
//! [experiment]
//! world = "room-two-dividers.toml"   # relative to this file
//! runs = 200
//! seed = 0
//! set = ["field.cell=0.1"]           # fixed overrides of every run (optional)
//! group = ["agents.0.controller.kind"] # the summary's groups (optional)
//! [experiment.sample]
//! "agents.0.start" = { free_point = { clearance = 0.5 } }
//! "agents.0.controller.b" = { uniform = [3.0, 30.0] }
//! "agents.0.controller.kind" = { choice = ["nadf", "viscous"] }
//! ```
//!
//! A run's world is the world file with the fixed overrides, then the sampled values as
//! overrides (in key order), and its `seed` set to the run's seed (unless `seed` is sampled).
//! A free point is drawn last, in the world the other values make, until it is clear of the
//! walls by its clearance and connected to the agent's target. A run whose values make no valid
//! world, or that cannot be run, is a row with its error, not the end of the experiment.
//! [`records`] holds what a run produced, [`results`] the columnar file and the summary.

pub mod batch;
pub mod plot;
pub mod records;
pub mod results;
pub mod sample;
pub mod shard;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::field::FreeSpace;
use crate::metrics::values_of;
use crate::random::SplitMix;
use crate::run::{RunOptions, run};
use crate::world::{Override, WorldError, WorldErrors, WorldFile, line_column};

pub use records::{AgentRecord, Record};
pub use sample::{Column, Sampled, Sampler};
pub use shard::Shard;

/// The most runs an experiment may have.
pub const MAX_RUNS: u64 = 100_000_000;

/// Free-point draws (each a whole set of points) before a run gives up finding its points
/// connected to their targets.
pub const CONNECTED_TRIES: usize = 1000;

/// The `[experiment]` table as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    experiment: toml::Spanned<Spec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    world: toml::Spanned<PathBuf>,
    runs: toml::Spanned<u64>,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    set: Vec<toml::Spanned<String>>,
    #[serde(default)]
    group: Vec<toml::Spanned<String>>,
    #[serde(default)]
    sample: BTreeMap<String, toml::Spanned<Sampler>>,
}

/// A loaded experiment: its world file, runs, seed and samplers.
#[derive(Debug, Clone)]
pub struct Experiment {
    /// The experiment file.
    pub path: PathBuf,
    /// Its name: the file's stem.
    pub name: String,
    /// The world file, read once.
    pub world: WorldFile,
    /// Runs in all.
    pub runs: u64,
    /// The base seed.
    pub seed: u64,
    /// The fixed overrides of every run: the file's `set`, then the command line's.
    pub overrides: Vec<Override>,
    /// The sampled keys, in order, with their samplers.
    pub samplers: Vec<(String, Sampler)>,
    /// The keys the summary groups the runs by.
    pub group: Vec<String>,
    /// A digest of everything that decides the runs (the two files' texts, the overrides):
    /// shards of different experiments are never merged.
    pub digest: String,
}

/// `error`s located in the experiment file `path` of `text` at byte `at`.
fn located(
    path: &Path,
    text: &str,
    at: Option<usize>,
    key: Option<String>,
    message: String,
) -> WorldErrors {
    WorldErrors(vec![WorldError {
        file: path.to_path_buf(),
        location: at.map(|at| line_column(text, at)),
        key,
        message,
    }])
}

impl Experiment {
    /// Reads the experiment file at `path` and its world file, with the command line's extra
    /// `overrides`; every problem is located (file, line, key).
    pub fn load(path: &Path, overrides: &[Override]) -> Result<Self, WorldErrors> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            located(
                path,
                "",
                None,
                None,
                format!("cannot read the experiment: {e}"),
            )
        })?;
        let spec: FileSpec = toml::from_str(&text).map_err(|e| {
            let at = e.span().map(|s| s.start);
            located(path, &text, at, None, e.message().to_string())
        })?;
        let at = |span: std::ops::Range<usize>| Some(span.start);
        let spec = spec.experiment.into_inner();
        let runs = *spec.runs.get_ref();
        if runs == 0 || runs > MAX_RUNS {
            return Err(located(
                path,
                &text,
                at(spec.runs.span()),
                Some("experiment.runs".into()),
                format!("must be from 1 to {MAX_RUNS}, got {runs}"),
            ));
        }
        let mut errors = Vec::new();
        let mut samplers = Vec::new();
        for (key, sampler) in &spec.sample {
            let where_ = (
                at(sampler.span()),
                Some(format!("experiment.sample.\"{key}\"")),
            );
            if let Err(message) = sampler.get_ref().check() {
                errors.extend(located(path, &text, where_.0, where_.1.clone(), message).0);
            }
            if let Sampler::FreePoint(_) = sampler.get_ref()
                && point_agent(key).is_none()
            {
                let message =
                    "a free point is sampled for `agents.N.start` or `agents.N.target`".into();
                errors.extend(located(path, &text, where_.0, where_.1.clone(), message).0);
            }
            samplers.push((key.clone(), sampler.get_ref().clone()));
        }
        let mut fixed = Vec::new();
        for s in &spec.set {
            match s.get_ref().parse::<Override>() {
                Ok(o) => fixed.push(o),
                Err(message) => errors.extend(
                    located(
                        path,
                        &text,
                        at(s.span()),
                        Some("experiment.set".into()),
                        message,
                    )
                    .0,
                ),
            }
        }
        fixed.extend_from_slice(overrides);
        let group: Vec<String> = spec.group.iter().map(|g| g.get_ref().clone()).collect();
        for g in &spec.group {
            let sampled = spec.sample.get(g.get_ref());
            let discrete = sampled
                .is_some_and(|s| matches!(s.get_ref(), Sampler::Choice(_) | Sampler::Int(_)));
            if !discrete {
                let message = format!(
                    "`{}` must be a sampled key with a `choice` or `int` sampler to group by",
                    g.get_ref()
                );
                errors.extend(
                    located(
                        path,
                        &text,
                        at(g.span()),
                        Some("experiment.group".into()),
                        message,
                    )
                    .0,
                );
            }
        }
        if !errors.is_empty() {
            return Err(WorldErrors::in_file_order(errors));
        }
        let relative = spec.world.get_ref();
        let world_path = path.parent().unwrap_or(Path::new(".")).join(relative);
        let world = WorldFile::read(&world_path)?;
        // The world and the fixed overrides must make a world before any run is planned.
        world.load(&fixed)?;
        let overrides_text: Vec<String> = fixed.iter().map(ToString::to_string).collect();
        let digest = format!(
            "{:016x}",
            fnv1a(&[
                text.as_bytes(),
                world.text().as_bytes(),
                overrides_text.join("\n").as_bytes()
            ])
        );
        let name = path
            .file_stem()
            .map_or_else(|| "experiment".into(), |s| s.to_string_lossy().into_owned());
        Ok(Self {
            path: path.to_path_buf(),
            name,
            world,
            runs,
            seed: spec.seed,
            overrides: fixed,
            samplers,
            group,
            digest,
        })
    }

    /// The seed of run `k` (63 bits: a TOML integer) and the stream its values are drawn
    /// from.
    pub fn stream(&self, k: u64) -> (u64, SplitMix) {
        let mut rng = SplitMix::new(self.seed ^ k.wrapping_mul(0xD1B5_4A32_D192_ED03));
        let seed = rng.next_u64() >> 1;
        (seed, rng)
    }

    /// Run `k`: its world planned (the values drawn, the world loaded) and run to its
    /// duration; a world that cannot be made or run is the record's error.
    pub fn run(&self, k: u64) -> Record {
        let (seed, mut rng) = self.stream(k);
        let planned = self.plan(seed, &mut rng);
        let (values, outcome) = match planned {
            Ok((values, world)) => {
                let outcome = run(&world, &RunOptions::default())
                    .map(|report| {
                        (report.agents.iter())
                            .map(|s| AgentRecord {
                                name: s.name.clone(),
                                values: values_of(s),
                            })
                            .collect()
                    })
                    .map_err(|e| e.to_string());
                (values, outcome)
            }
            Err((values, message)) => (values, Err(message)),
        };
        Record {
            run: k,
            seed,
            values,
            outcome,
        }
    }

    /// The values of a run with `seed` drawn from `rng`, and its world; or the values drawn so
    /// far (`None` for the ones not drawn) and why there is no world.
    #[allow(clippy::type_complexity)]
    fn plan(
        &self,
        seed: u64,
        rng: &mut SplitMix,
    ) -> Result<(Vec<Option<Sampled>>, crate::world::World), (Vec<Option<Sampled>>, String)> {
        let mut values: Vec<Option<Sampled>> =
            self.samplers.iter().map(|(_, s)| s.draw(rng)).collect();
        let seeded = self.samplers.iter().any(|(k, _)| k == "seed");
        let overrides = |values: &[Option<Sampled>]| {
            let mut all = self.overrides.clone();
            if !seeded {
                all.push(Override {
                    path: "seed".into(),
                    value: seed.to_string(),
                });
            }
            all.extend(
                self.samplers
                    .iter()
                    .zip(values)
                    .filter_map(|((key, _), v)| {
                        v.as_ref().map(|v| Override {
                            path: key.clone(),
                            value: v.toml(),
                        })
                    }),
            );
            all
        };
        let points: Vec<usize> = (self.samplers.iter().enumerate())
            .filter(|(_, (_, s))| matches!(s, Sampler::FreePoint(_)))
            .map(|(i, _)| i)
            .collect();
        let base = self
            .world
            .load(&overrides(&values))
            .map_err(|e| (values.clone(), one_line(&e)))?;
        if points.is_empty() {
            return Ok((values, base));
        }
        let walls = sample::walls_of(&base);
        for _ in 0..CONNECTED_TRIES {
            for &i in &points {
                let (key, sampler) = &self.samplers[i];
                let Sampler::FreePoint(p) = sampler else {
                    continue;
                };
                let agent = point_agent(key).and_then(|n| base.agents.get(n));
                let Some(agent) = agent else {
                    return Err((values, format!("`{key}`: the world has no such agent")));
                };
                let point =
                    sample::free_point(&base, (&walls.0, &walls.1), agent.radius, p.clearance, rng);
                let Some(point) = point else {
                    return Err((
                        values,
                        format!(
                            "`{key}`: no point of the box keeps {} m from the walls for a disc of {} m in {} draws",
                            p.clearance,
                            agent.radius,
                            sample::FREE_POINT_TRIES
                        ),
                    ));
                };
                values[i] = Some(Sampled::Point(point));
            }
            let world = match self.world.load(&overrides(&values)) {
                Ok(world) => world,
                // A start or target on another agent's, say: draw again.
                Err(_) => continue,
            };
            if FreeSpace::intractable(&world).is_empty() {
                return Ok((values, world));
            }
        }
        Err((
            values,
            format!("no free points connected to their targets in {CONNECTED_TRIES} draws"),
        ))
    }

    /// The sampled keys' column types, in order.
    pub fn columns(&self) -> Vec<(String, Column)> {
        (self.samplers.iter())
            .map(|(k, s)| (k.clone(), s.column()))
            .collect()
    }
}

/// The agent index `N` of a key `agents.N.start` or `agents.N.target`.
fn point_agent(key: &str) -> Option<usize> {
    let rest = key.strip_prefix("agents.")?;
    let (n, field) = rest.split_once('.')?;
    matches!(field, "start" | "target").then_some(())?;
    n.parse().ok()
}

/// The errors of a world as one line each, joined (a record's error).
fn one_line(errors: &WorldErrors) -> String {
    (errors.0.iter())
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("; ")
}

/// The 64-bit FNV-1a hash of the `parts`, each followed by a zero byte.
fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &b in part.iter().chain(&[0u8]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}
