//! Running a shard of an experiment on one machine's threads, resumably, and writing the
//! results of a complete set of records.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::shard::{self, Manifest, Progress, Shard};
use super::{Experiment, Record, plot, results};

/// What a shard's run did.
#[derive(Debug)]
pub struct Done {
    /// Runs done now.
    pub ran: usize,
    /// Runs found done in the progress file (`--resume`).
    pub resumed: usize,
    /// Whether the shard is complete (not interrupted).
    pub complete: bool,
    /// Every record of the shard so far, sorted by run.
    pub records: Vec<Record>,
    /// The wall time of the runs done now.
    pub wall_time: Duration,
    /// Threads used.
    pub threads: usize,
}

impl Experiment {
    /// The manifest of its `shard`, complete or not.
    pub fn manifest(&self, shard: Shard, complete: bool) -> Manifest {
        Manifest {
            experiment: self.name.clone(),
            digest: self.digest.clone(),
            shard: shard.index,
            of: shard.count,
            runs: self.runs,
            columns: (self.columns().into_iter())
                .map(|(k, c)| (k, shard::column_name(c).to_string()))
                .collect(),
            group: self.group.clone(),
            complete,
        }
    }

    /// Runs `shard` of the experiment into its directory under `out` on `threads` threads
    /// (all cores when `None`), calling `progress` after each run and stopping early once
    /// `interrupt` is set. With `resume`, the runs already in the shard's progress file are
    /// kept and skipped; without it, a directory that holds a shard already is refused.
    pub fn run_shard(
        &self,
        shard: Shard,
        out: &Path,
        (resume, threads): (bool, Option<usize>),
        progress: &(dyn Fn(usize, usize) + Sync),
        interrupt: Option<&AtomicBool>,
    ) -> Result<Done, String> {
        let dir = shard.dir(out);
        match Manifest::read(&dir)? {
            Some(m) if m.digest != self.digest || m.shard() != shard => {
                return Err(format!(
                    "{} holds shard {} of experiment `{}` ({}), not shard {shard} of this one ({}): choose another --out",
                    dir.display(),
                    m.shard(),
                    m.experiment,
                    m.digest,
                    self.digest
                ));
            }
            Some(_) if !resume => {
                return Err(format!(
                    "{} holds this shard's runs already: --resume continues it (the runs done are kept), or choose another --out",
                    dir.display()
                ));
            }
            Some(_) => {}
            None if dir.join(shard::PROGRESS).exists() => {
                return Err(format!(
                    "{}: a progress file without its manifest",
                    dir.display()
                ));
            }
            None => {}
        }
        std::fs::create_dir_all(&dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        self.manifest(shard, false).write(&dir)?;
        let columns: Vec<_> = self.columns().into_iter().map(|(_, c)| c).collect();
        let mut records = shard::read_progress(&dir, &columns)?;
        records.retain(|r| r.run < self.runs && r.run % shard.count == shard.index);
        let done: HashSet<u64> = records.iter().map(|r| r.run).collect();
        let todo: Vec<u64> = shard
            .runs(self.runs)
            .filter(|k| !done.contains(k))
            .collect();
        let resumed = done.len();
        let file = Mutex::new(Progress::open(&dir)?);
        let mut builder = rayon::ThreadPoolBuilder::new();
        if let Some(n) = threads {
            builder = builder.num_threads(n);
        }
        let pool = builder
            .build()
            .map_err(|e| format!("cannot start the threads: {e}"))?;
        let started = Instant::now();
        let total = todo.len();
        let count = std::sync::atomic::AtomicUsize::new(0);
        let stopped = || interrupt.is_some_and(|i| i.load(Ordering::Relaxed));
        let ran: Vec<Result<Option<Record>, String>> = pool.install(|| {
            todo.par_iter()
                .map(|&k| {
                    if stopped() {
                        return Ok(None);
                    }
                    let record = self.run(k);
                    file.lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .append(&record)?;
                    progress(count.fetch_add(1, Ordering::Relaxed) + 1, total);
                    Ok(Some(record))
                })
                .collect()
        });
        let wall_time = started.elapsed();
        let mut fresh = Vec::new();
        for r in ran {
            if let Some(record) = r? {
                fresh.push(record);
            }
        }
        let complete = fresh.len() == total;
        let ran = fresh.len();
        records.extend(fresh);
        records.sort_by_key(|r| r.run);
        if complete {
            self.manifest(shard, true).write(&dir)?;
        }
        Ok(Done {
            ran,
            resumed,
            complete,
            records,
            wall_time,
            threads: pool.current_num_threads(),
        })
    }
}

/// The results of the complete `records` (sorted by run) of the experiment `manifest`
/// describes, written into `dir`: `runs.arrow`, `summary.csv` and `summary.png`. Returns the
/// files written and the summary's groups.
pub fn write_results(
    dir: &Path,
    manifest: &Manifest,
    records: &[Record],
) -> Result<(Vec<PathBuf>, Vec<results::Group>), String> {
    let columns = manifest.columns()?;
    let group: Vec<usize> = (manifest.group.iter())
        .filter_map(|g| columns.iter().position(|(k, _)| k == g))
        .collect();
    let arrow = results::arrow_file(records, &columns, (&manifest.experiment, &manifest.digest))?;
    let groups = results::groups(records, &columns, &group);
    let by = if manifest.group.is_empty() {
        String::new()
    } else {
        format!(", by {}", manifest.group.join(", "))
    };
    let title = format!("{}: {} runs{by}", manifest.experiment, manifest.runs);
    let picture =
        plot::plot(&groups, &title).map_err(|e| format!("cannot draw the summary: {e}"))?;
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let files = vec![
        (dir.join("runs.arrow"), arrow),
        (
            dir.join("summary.csv"),
            results::groups_csv(&groups).into_bytes(),
        ),
        (dir.join("summary.png"), picture),
    ];
    let mut written = Vec::new();
    for (path, bytes) in files {
        crate::output::write_atomically(&path, &bytes).map_err(|e| e.to_string())?;
        written.push(path);
    }
    Ok((written, groups))
}

/// What [`merge`] did.
#[derive(Debug)]
pub struct Merged {
    /// Shards merged.
    pub shards: usize,
    /// The experiment's name.
    pub experiment: String,
    /// Runs in all.
    pub runs: usize,
    /// The files written.
    pub files: Vec<PathBuf>,
    /// The summary's groups.
    pub groups: Vec<results::Group>,
}

/// Merges the complete shards found in `dirs` (see [`shard::find`]) into `out`: the results
/// an unsharded run writes, byte for byte; refuses a set that is incomplete, mixed or has a
/// shard twice, writing nothing.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<Merged, String> {
    let shards = shard::find(dirs)?;
    let (manifest, records) = shard::gather(&shards)?;
    let whole = Manifest {
        shard: 0,
        of: 1,
        ..manifest
    };
    let (files, groups) = write_results(out, &whole, &records)?;
    Ok(Merged {
        shards: shards.len(),
        experiment: whole.experiment,
        runs: records.len(),
        files,
        groups,
    })
}
