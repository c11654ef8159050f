//! Shards of an experiment: `--shard I/N` runs the runs `k` with `k mod N = I` into
//! `DIR/shard-I-of-N/` (its progress file `runs.jsonl`, a line per finished run, and its
//! manifest `shard.json`); an unsharded experiment is the one shard `0/1`, written in `DIR`
//! itself. `nadf merge` combines complete shards into the results an unsharded run writes.

use std::fmt;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::records::Record;
use super::sample::Column;

/// The progress file of a shard.
pub const PROGRESS: &str = "runs.jsonl";
/// The manifest of a shard.
pub const MANIFEST: &str = "shard.json";

/// One shard `index` of `count` (`0 ≤ index < count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Shard {
    /// Its index, from 0.
    pub index: u64,
    /// How many shards there are.
    pub count: u64,
}

impl Shard {
    /// The whole experiment as one shard.
    pub const WHOLE: Self = Self { index: 0, count: 1 };

    /// Its runs among `runs`.
    pub fn runs(&self, runs: u64) -> impl Iterator<Item = u64> + use<> {
        (self.index..runs).step_by(self.count as usize)
    }

    /// Where it writes under the output directory `dir`.
    pub fn dir(&self, dir: &Path) -> PathBuf {
        if *self == Self::WHOLE {
            dir.to_path_buf()
        } else {
            dir.join(format!("shard-{}-of-{}", self.index, self.count))
        }
    }
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "`{s}` is not I/N with 0 ≤ I < N (e.g. 0/4; Slurm: $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT)"
            )
        };
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (u64, u64) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count || count > usize::MAX as u64 {
            return Err(bad());
        }
        Ok(Self { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// A shard's manifest: which experiment, which shard, its columns, whether it is complete.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The experiment's name.
    pub experiment: String,
    /// The experiment's digest ([`super::Experiment::digest`]).
    pub digest: String,
    /// The shard's index.
    pub shard: u64,
    /// How many shards.
    pub of: u64,
    /// Runs in the whole experiment.
    pub runs: u64,
    /// The sampled keys and their columns (`real`, `int`, `flag`, `text`, `point`).
    pub columns: Vec<(String, String)>,
    /// The keys the summary groups by.
    pub group: Vec<String>,
    /// Whether every run of the shard is in its progress file.
    pub complete: bool,
}

/// A column's name in a manifest.
pub fn column_name(c: Column) -> &'static str {
    match c {
        Column::Real => "real",
        Column::Int => "int",
        Column::Flag => "flag",
        Column::Text => "text",
        Column::Point => "point",
    }
}

fn column_of(name: &str) -> Option<Column> {
    Some(match name {
        "real" => Column::Real,
        "int" => Column::Int,
        "flag" => Column::Flag,
        "text" => Column::Text,
        "point" => Column::Point,
        _ => return None,
    })
}

impl Manifest {
    /// The shard it describes.
    pub fn shard(&self) -> Shard {
        Shard {
            index: self.shard,
            count: self.of,
        }
    }

    /// The sampled keys' columns; an error for a manifest this version cannot read.
    pub fn columns(&self) -> Result<Vec<(String, Column)>, String> {
        (self.columns.iter())
            .map(|(k, c)| {
                column_of(c)
                    .map(|c| (k.clone(), c))
                    .ok_or_else(|| format!("unknown column type `{c}` of `{k}`"))
            })
            .collect()
    }

    /// Reads the manifest in `dir`, if there is one.
    pub fn read(dir: &Path) -> Result<Option<Self>, String> {
        let path = dir.join(MANIFEST);
        match fs::read_to_string(&path) {
            Ok(text) => serde_json::from_str(&text)
                .map(Some)
                .map_err(|e| format!("{}: not a shard manifest: {e}", path.display())),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(format!("cannot read {}: {e}", path.display())),
        }
    }

    /// Writes it into `dir` (whole: never a half-written manifest).
    pub fn write(&self, dir: &Path) -> Result<(), String> {
        let text = serde_json::to_string_pretty(self).expect("plain data") + "\n";
        crate::output::write_atomically(&dir.join(MANIFEST), text.as_bytes())
            .map_err(|e| e.to_string())
    }
}

/// The records in the progress file of `dir` (none if there is none), in the file's order,
/// for sampled keys of `columns`. A last line cut short by a kill is cut off the file, so
/// that appending goes on from a whole line; any other line that is not a record is an error.
pub fn read_progress(dir: &Path, columns: &[Column]) -> Result<Vec<Record>, String> {
    let path = dir.join(PROGRESS);
    let text = match fs::read_to_string(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
    };
    let mut records = Vec::new();
    let mut whole = 0;
    for (n, line) in text.split_inclusive('\n').enumerate() {
        let Some(body) = line.strip_suffix('\n') else {
            break; // the last line, unfinished
        };
        let record = Record::from_line(body, columns)
            .ok_or_else(|| format!("{}:{}: not a run's record", path.display(), n + 1))?;
        records.push(record);
        whole += line.len();
    }
    if whole < text.len() {
        let file = fs::OpenOptions::new()
            .write(true)
            .open(&path)
            .map_err(|e| format!("cannot open {}: {e}", path.display()))?;
        file.set_len(whole as u64)
            .map_err(|e| format!("cannot cut {}: {e}", path.display()))?;
    }
    Ok(records)
}

/// Appends finished runs to a shard's progress file, a whole line at a time.
pub struct Progress {
    file: fs::File,
    path: PathBuf,
}

impl Progress {
    /// Opens the progress file of `dir` for appending (created if missing).
    pub fn open(dir: &Path) -> Result<Self, String> {
        let path = dir.join(PROGRESS);
        let file = fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| format!("cannot open {}: {e}", path.display()))?;
        Ok(Self { file, path })
    }

    /// Appends `record` and flushes it to the file.
    pub fn append(&mut self, record: &Record) -> Result<(), String> {
        let line = record.to_line() + "\n";
        (self.file.write_all(line.as_bytes()))
            .and_then(|()| self.file.flush())
            .map_err(|e| format!("cannot write {}: {e}", self.path.display()))
    }
}

/// The shard directories given to `nadf merge`: each of `dirs` that holds a manifest, and the
/// `shard-*-of-*` directories inside each that does not.
pub fn find(dirs: &[PathBuf]) -> Result<Vec<(PathBuf, Manifest)>, String> {
    let mut out = Vec::new();
    for dir in dirs {
        if let Some(m) = Manifest::read(dir)? {
            out.push((dir.clone(), m));
            continue;
        }
        let entries =
            fs::read_dir(dir).map_err(|e| format!("cannot read {}: {e}", dir.display()))?;
        let mut inside: Vec<PathBuf> = entries
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| {
                p.is_dir()
                    && p.file_name()
                        .is_some_and(|n| n.to_string_lossy().starts_with("shard-"))
            })
            .collect();
        inside.sort();
        if inside.is_empty() {
            return Err(format!(
                "{}: no shard in it (no {MANIFEST}, no shard-I-of-N directory)",
                dir.display()
            ));
        }
        for d in inside {
            match Manifest::read(&d)? {
                Some(m) => out.push((d, m)),
                None => return Err(format!("{}: no {MANIFEST} in it", d.display())),
            }
        }
    }
    Ok(out)
}

/// The records of a complete, consistent set of `shards`, sorted by run, with the manifest of
/// the experiment; an error naming what is missing, mixed or incomplete.
pub fn gather(shards: &[(PathBuf, Manifest)]) -> Result<(Manifest, Vec<Record>), String> {
    let Some((_, first)) = shards.first() else {
        return Err("no shards to merge".into());
    };
    for (dir, m) in shards {
        if m.digest != first.digest || m.of != first.of {
            return Err(format!(
                "{} is shard {} of experiment `{}` ({}), not of `{}` ({}) in {} shards like {}: a mixed set",
                dir.display(),
                m.shard(),
                m.experiment,
                m.digest,
                first.experiment,
                first.digest,
                first.of,
                shards[0].0.display()
            ));
        }
        if !m.complete {
            return Err(format!(
                "{}: shard {} is not complete (run it again with --resume)",
                dir.display(),
                m.shard()
            ));
        }
    }
    let mut seen = vec![None; first.of as usize];
    for (dir, m) in shards {
        if let Some(other) = seen[m.shard as usize].replace(dir) {
            return Err(format!(
                "shard {} twice: {} and {}",
                m.shard(),
                other.display(),
                dir.display()
            ));
        }
    }
    let missing: Vec<String> = (seen.iter().enumerate())
        .filter(|(_, d)| d.is_none())
        .map(|(i, _)| format!("{i}/{}", first.of))
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "missing shard(s) {} of experiment `{}`",
            missing.join(", "),
            first.experiment
        ));
    }
    let columns: Vec<Column> = first.columns()?.into_iter().map(|(_, c)| c).collect();
    let mut records = Vec::new();
    for (dir, m) in shards {
        let mut got = read_progress(dir, &columns)?;
        got.sort_by_key(|r| r.run);
        got.dedup_by_key(|r| r.run);
        let expected: Vec<u64> = m.shard().runs(m.runs).collect();
        let have: Vec<u64> = got.iter().map(|r| r.run).collect();
        if have != expected {
            return Err(format!(
                "{}: shard {} holds {} of its {} runs",
                dir.display(),
                m.shard(),
                have.len(),
                expected.len()
            ));
        }
        records.extend(got);
    }
    records.sort_by_key(|r| r.run);
    Ok((first.clone(), records))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_cover_every_run_once() {
        assert_eq!("2/5".parse::<Shard>(), Ok(Shard { index: 2, count: 5 }));
        for bad in ["5/5", "1/0", "a/3", "3", "-1/4"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let mut all: Vec<u64> = (0..4)
            .flat_map(|i| Shard { index: i, count: 4 }.runs(10))
            .collect();
        all.sort();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
    }
}
