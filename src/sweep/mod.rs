//! Parameter sweeps: one world run for every combination of swept values, in parallel, with a
//! CSV of every summary metric and a plot of the main ones (`nadf sweep`).
//!
//! A range `KEY=START:END:COUNT` gives `COUNT` evenly spaced values from `START` to `END`
//! (both included); several ranges give their Cartesian product, the first varying slowest.
//! Every run is the world file with the fixed `--set` overrides and its swept values applied as
//! overrides too, so each goes through the same checks as a hand-written world; all are
//! loaded (and so validated) before any runs. Runs are independent and deterministic, so the
//! results do not depend on the number of threads.

mod plot;

use std::path::Path;
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;

pub use plot::plot;

use crate::metrics::{self, Summary, csv_field};
use crate::run::{RunError, RunOptions, run};
use crate::world::{Override, World, WorldErrors, WorldFile};

/// The most runs one sweep may have.
pub const MAX_RUNS: usize = 100_000;

/// One `--set-range KEY=START:END:COUNT`.
#[derive(Debug, Clone, PartialEq)]
pub struct Range {
    /// Dotted key path, as for `--set`.
    pub path: String,
    /// First value.
    pub start: f64,
    /// Last value.
    pub end: f64,
    /// Number of values (1 gives `start` alone).
    pub count: usize,
}

impl Range {
    /// The values, evenly spaced from `start` to `end`.
    pub fn values(&self) -> Vec<f64> {
        if self.count == 1 {
            return vec![self.start];
        }
        (0..self.count)
            .map(|i| {
                let s = i as f64 / (self.count - 1) as f64;
                // Exact end points; in between, rounded to 12 significant digits so that
                // 0.1:3.0:30 gives 0.2, not 0.20000000000000004.
                let v = self.start + (self.end - self.start) * s;
                if i + 1 == self.count {
                    self.end
                } else {
                    format!("{v:.12e}").parse().unwrap_or(v)
                }
            })
            .collect()
    }
}

impl FromStr for Range {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let form = "KEY=START:END:COUNT, e.g. agents.0.controller.b=0.1:3.0:30";
        let (path, spec) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}` is not {form}"))?;
        let path = path.trim();
        if path.is_empty() || path.split('.').any(str::is_empty) {
            return Err(format!("`{path}` is not a dotted key path ({form})"));
        }
        let parts: Vec<&str> = spec.split(':').map(str::trim).collect();
        let [start, end, count] = parts[..] else {
            return Err(format!("`{spec}` is not START:END:COUNT ({form})"));
        };
        let number = |what: &str, text: &str| {
            text.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("the {what} `{text}` is not a finite number"))
        };
        let count: usize = count
            .parse()
            .ok()
            .filter(|&c| (1..=MAX_RUNS).contains(&c))
            .ok_or_else(|| {
                format!("the count `{count}` is not a whole number from 1 to {MAX_RUNS}")
            })?;
        Ok(Self {
            path: path.to_string(),
            start: number("start", start)?,
            end: number("end", end)?,
            count,
        })
    }
}

/// One run of a sweep: its swept values (in the order of the ranges) and its world.
#[derive(Debug, Clone)]
pub struct Case {
    /// The swept values.
    pub values: Vec<f64>,
    /// The world with the overrides applied.
    pub world: World,
}

/// The finished runs of a sweep.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The swept keys, in order.
    pub keys: Vec<String>,
    /// One entry per run: the swept values and every agent's summary.
    pub runs: Vec<(Vec<f64>, Vec<Summary>)>,
    /// Wall-clock time of all the runs.
    pub wall_time: Duration,
    /// Threads used.
    pub threads: usize,
}

/// Why a sweep failed.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// No `--set-range` was given.
    #[error("a sweep needs at least one --set-range KEY=START:END:COUNT")]
    NoRange,
    /// Too many combinations.
    #[error("the ranges give {0} runs, more than the {MAX_RUNS} a sweep may have")]
    TooMany(usize),
    /// A combination does not make a valid world.
    #[error("with {values}:\n{errors}")]
    World {
        /// The swept values, as `key=value` pairs.
        values: String,
        /// What is wrong.
        errors: WorldErrors,
    },
    /// A run failed.
    #[error("the run with {values} failed: {source}")]
    Run {
        /// The swept values, as `key=value` pairs.
        values: String,
        /// Why.
        source: Box<RunError>,
    },
    /// The thread pool could not be built.
    #[error("cannot start {threads} threads: {message}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// Rayon's message.
        message: String,
    },
    /// The sweep was interrupted.
    #[error("interrupted after {done} of {total} runs")]
    Interrupted {
        /// Runs finished.
        done: usize,
        /// Runs planned.
        total: usize,
    },
}

/// `key=value, key=value` for messages.
fn describe(keys: &[String], values: &[f64]) -> String {
    keys.iter()
        .zip(values)
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Every combination of the ranges' values as a valid world, loaded from `path` (read once)
/// with the fixed `overrides` and the swept values; and the file, for its warnings.
pub fn cases(
    path: &Path,
    ranges: &[Range],
    overrides: &[Override],
) -> Result<(WorldFile, Vec<Case>), SweepError> {
    if ranges.is_empty() {
        return Err(SweepError::NoRange);
    }
    let file = WorldFile::read(path).map_err(|errors| SweepError::World {
        values: "no swept values".into(),
        errors,
    })?;
    let total = ranges
        .iter()
        .try_fold(1usize, |n, r| n.checked_mul(r.count))
        .unwrap_or(usize::MAX);
    if total > MAX_RUNS {
        return Err(SweepError::TooMany(total));
    }
    let keys: Vec<String> = ranges.iter().map(|r| r.path.clone()).collect();
    let mut combos: Vec<Vec<f64>> = vec![Vec::new()];
    for range in ranges {
        let values = range.values();
        combos = combos
            .into_iter()
            .flat_map(|c| {
                values.iter().map(move |v| {
                    let mut c = c.clone();
                    c.push(*v);
                    c
                })
            })
            .collect();
    }
    let cases = combos
        .into_iter()
        .map(|values| {
            let mut all = overrides.to_vec();
            all.extend(keys.iter().zip(&values).map(|(k, v)| Override {
                path: k.clone(),
                // `{:?}` keeps a decimal point, so TOML reads a float even for whole values.
                value: format!("{v:?}"),
            }));
            let world = file.load(&all).map_err(|errors| SweepError::World {
                values: describe(&keys, &values),
                errors,
            })?;
            Ok(Case { values, world })
        })
        .collect::<Result<_, _>>()?;
    Ok((file, cases))
}

/// Runs every case on `threads` threads (all cores when `None`), calling `progress` after each
/// run. Stops early, with [`SweepError::Interrupted`], once `interrupt` is set.
pub fn run_all(
    keys: &[String],
    cases: &[Case],
    threads: Option<usize>,
    progress: &(dyn Fn() + Sync),
    interrupt: Option<&AtomicBool>,
) -> Result<Sweep, SweepError> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        builder = builder.num_threads(n);
    }
    let pool = builder.build().map_err(|e| SweepError::Threads {
        threads: threads.unwrap_or(0),
        message: e.to_string(),
    })?;
    let started = Instant::now();
    let stopped = |i: &AtomicBool| i.load(Ordering::Relaxed);
    let results: Vec<Option<Result<Vec<Summary>, SweepError>>> = pool.install(|| {
        cases
            .par_iter()
            .map(|case| {
                if interrupt.is_some_and(stopped) {
                    return None;
                }
                let outcome = run(&case.world, &RunOptions::default())
                    .map(|report| report.agents)
                    .map_err(|source| SweepError::Run {
                        values: describe(keys, &case.values),
                        source: Box::new(source),
                    });
                progress();
                Some(outcome)
            })
            .collect()
    });
    let done = results.iter().filter(|r| r.is_some()).count();
    if done < cases.len() {
        return Err(SweepError::Interrupted {
            done,
            total: cases.len(),
        });
    }
    let mut runs = Vec::with_capacity(cases.len());
    for (case, result) in cases.iter().zip(results) {
        let summaries = result.expect("every case ran")?;
        runs.push((case.values.clone(), summaries));
    }
    Ok(Sweep {
        keys: keys.to_vec(),
        runs,
        wall_time: started.elapsed(),
        threads: pool.current_num_threads(),
    })
}

impl Sweep {
    /// The CSV table: one row per run and agent, the swept values first, then the agent and
    /// every summary metric (an empty cell where a metric has no value: never settled).
    pub fn csv(&self) -> String {
        let mut keys = self.keys.clone();
        keys.push("agent".into());
        let rows: Vec<(Vec<String>, &Summary)> = self
            .runs
            .iter()
            .flat_map(|(values, summaries)| {
                summaries.iter().map(move |s| {
                    let mut leading: Vec<String> = values.iter().map(|v| format!("{v}")).collect();
                    leading.push(csv_field(&s.name));
                    (leading, s)
                })
            })
            .collect();
        metrics::csv(&keys, &rows)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_space_their_values_evenly() {
        let r: Range = "agents.0.controller.b=0.1:3.0:30".parse().unwrap();
        let v = r.values();
        assert_eq!(v.len(), 30);
        assert_eq!((v[0], v[1], v[29]), (0.1, 0.2, 3.0));
        assert_eq!("x=2:2:1".parse::<Range>().unwrap().values(), [2.0]);
        for bad in [
            "b",
            "b=1:2",
            "b=1:2:0",
            "b=1:x:3",
            "b=nan:1:2",
            "=1:2:3",
            "a..b=1:2:3",
        ] {
            assert!(bad.parse::<Range>().is_err(), "{bad}");
        }
    }
}
