//! An experiment's results: `runs.arrow`, one row per run and agent (the run, its seed, its
//! sampled values, the agent, the error of a run that could not be done, and every summary
//! metric), an Arrow IPC file (Feather v2) that pandas (`pd.read_feather`) and polars
//! (`pl.read_ipc`) open; and the summary per group of runs (`summary.csv`).
//!
//! Arrow IPC rather than Parquet: the arrow crates are already in the build (Rerun's), a
//! Parquet writer would add a large one, and both readers take either. The file is
//! deterministic: the same records give the same bytes, however they were run.

use std::collections::BTreeMap;
use std::collections::HashMap;
use std::sync::Arc;

use arrow::array::{ArrayRef, BooleanArray, Float64Array, Int64Array, StringArray, UInt64Array};
use arrow::datatypes::{DataType, Field, Schema};
use arrow::ipc::writer::FileWriter;
use arrow::record_batch::RecordBatch;

use super::records::Record;
use super::sample::{Column, Sampled};
use crate::metrics::{Kind, Summary, Value, metrics_of};

/// One row: a run's record and one of its agents (`None`: a run with an error).
struct Row<'a> {
    record: &'a Record,
    agent: Option<(&'a str, &'a [Value])>,
}

fn rows(records: &[Record]) -> Vec<Row<'_>> {
    let mut out = Vec::new();
    for record in records {
        match &record.outcome {
            Ok(agents) if !agents.is_empty() => out.extend(agents.iter().map(|a| Row {
                record,
                agent: Some((a.name.as_str(), a.values.as_slice())),
            })),
            _ => out.push(Row {
                record,
                agent: None,
            }),
        }
    }
    out
}

/// The Arrow IPC file of `records` (sorted by run) of an experiment named `name` with `digest`
/// whose sampled keys are `columns`.
pub fn arrow_file(
    records: &[Record],
    columns: &[(String, Column)],
    (name, digest): (&str, &str),
) -> Result<Vec<u8>, String> {
    let rows = rows(records);
    let mut fields = vec![
        Field::new("run", DataType::UInt64, false),
        Field::new("seed", DataType::UInt64, false),
    ];
    let mut arrays: Vec<ArrayRef> = vec![
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.record.run),
        )),
        Arc::new(UInt64Array::from_iter_values(
            rows.iter().map(|r| r.record.seed),
        )),
    ];
    for (i, (key, column)) in columns.iter().enumerate() {
        let value = |r: &Row| r.record.values[i].clone();
        match column {
            Column::Real => {
                fields.push(Field::new(key, DataType::Float64, true));
                arrays.push(Arc::new(Float64Array::from_iter(rows.iter().map(
                    |r| match value(r) {
                        Some(Sampled::Real(x)) => Some(x),
                        _ => None,
                    },
                ))));
            }
            Column::Int => {
                fields.push(Field::new(key, DataType::Int64, true));
                arrays.push(Arc::new(Int64Array::from_iter(rows.iter().map(
                    |r| match value(r) {
                        Some(Sampled::Int(n)) => Some(n),
                        _ => None,
                    },
                ))));
            }
            Column::Flag => {
                fields.push(Field::new(key, DataType::Boolean, true));
                arrays.push(Arc::new(BooleanArray::from_iter(rows.iter().map(
                    |r| match value(r) {
                        Some(Sampled::Flag(b)) => Some(b),
                        _ => None,
                    },
                ))));
            }
            Column::Text => {
                fields.push(Field::new(key, DataType::Utf8, true));
                arrays.push(Arc::new(StringArray::from_iter(rows.iter().map(
                    |r| match value(r) {
                        Some(Sampled::Text(s) | Sampled::Other(s)) => Some(s),
                        _ => None,
                    },
                ))));
            }
            Column::Point => {
                for (axis, c) in [("x", 0), ("y", 1)] {
                    fields.push(Field::new(format!("{key}.{axis}"), DataType::Float64, true));
                    arrays.push(Arc::new(Float64Array::from_iter(rows.iter().map(
                        |r| match value(r) {
                            Some(Sampled::Point(p)) => Some(p[c]),
                            _ => None,
                        },
                    ))));
                }
            }
        }
    }
    fields.push(Field::new("agent", DataType::Utf8, true));
    arrays.push(Arc::new(StringArray::from_iter(
        rows.iter().map(|r| r.agent.map(|(name, _)| name)),
    )));
    fields.push(Field::new("error", DataType::Utf8, true));
    arrays
        .push(Arc::new(StringArray::from_iter(rows.iter().map(|r| {
            r.record.outcome.as_ref().err().map(String::as_str)
        }))));
    for (m, metric) in metrics_of::<Summary>().iter().enumerate() {
        let value = |r: &Row| r.agent.map(|(_, v)| v[m]);
        let (data_type, array): (DataType, ArrayRef) = match metric.kind {
            Kind::Flag => (
                DataType::Boolean,
                Arc::new(BooleanArray::from_iter(rows.iter().map(|r| {
                    match value(r) {
                        Some(Value::Flag(b)) => Some(b),
                        _ => None,
                    }
                }))),
            ),
            Kind::Count => (
                DataType::UInt64,
                Arc::new(UInt64Array::from_iter(rows.iter().map(|r| {
                    match value(r) {
                        Some(Value::Count(n)) => Some(n as u64),
                        _ => None,
                    }
                }))),
            ),
            Kind::Real | Kind::OptionalReal => (
                DataType::Float64,
                Arc::new(Float64Array::from_iter(rows.iter().map(|r| {
                    match value(r) {
                        Some(Value::Real(x)) => Some(x),
                        _ => None,
                    }
                }))),
            ),
        };
        fields.push(Field::new(metric.key, data_type, true));
        arrays.push(array);
    }
    // One metadata entry: a map of several would be written in a hash map's order.
    let about = serde_json::json!({ "experiment": name, "digest": digest }).to_string();
    let metadata = HashMap::from([("nadf".to_string(), about)]);
    let schema = Arc::new(Schema::new_with_metadata(fields, metadata));
    let batch = RecordBatch::try_new(Arc::clone(&schema), arrays).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    {
        let mut writer = FileWriter::try_new(&mut bytes, &schema).map_err(|e| e.to_string())?;
        writer.write(&batch).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())?;
    }
    Ok(bytes)
}

/// The summary of one group of runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Group {
    /// The group's values of the grouping keys (`key=value, ...`; `all` without grouping).
    pub label: String,
    /// The same values without their keys (`all` without grouping), for a plot's axis.
    pub values: String,
    /// Runs in it.
    pub runs: usize,
    /// Runs that could not be done (their agents count as not reached).
    pub failed: usize,
    /// Agent rows (one per agent of a run done; one per failed run).
    pub agents: usize,
    /// Agents that reached their targets.
    pub reached: usize,
    /// The 95 % Wilson score interval of the success rate.
    pub interval: (f64, f64),
    /// Contact starts per run (all its agents').
    pub contacts_per_run: f64,
    /// The median and 90th percentile of the settling time of the agents that reached, s.
    pub settling: Option<(f64, f64)>,
    /// The median and 90th percentile of the path length over the kinematic path's, of the
    /// agents that reached.
    pub path_ratio: Option<(f64, f64)>,
}

impl Group {
    /// The success rate.
    pub fn success(&self) -> f64 {
        self.reached as f64 / self.agents.max(1) as f64
    }
}

/// The 95 % Wilson score interval of `k` successes in `n` trials.
///
/// ```
/// let (lo, hi) = nadf::experiment::results::wilson(8, 10);
/// assert!((lo - 0.490).abs() < 1e-3 && (hi - 0.943).abs() < 1e-3);
/// ```
pub fn wilson(k: usize, n: usize) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let z = 1.959_963_984_540_054_f64;
    let (n, p) = (n as f64, k as f64 / n as f64);
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z / (1.0 + z * z / n) * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    // Exact at the ends, where rounding would leave the rate itself outside.
    let lo = if k == 0 {
        0.0
    } else {
        (centre - half).max(0.0)
    };
    let hi = if k as f64 == n {
        1.0
    } else {
        (centre + half).min(1.0)
    };
    (lo, hi)
}

/// The `q`-quantile of `xs` (linear between order statistics); `None` when empty.
pub fn quantile(xs: &mut [f64], q: f64) -> Option<f64> {
    if xs.is_empty() {
        return None;
    }
    xs.sort_by(f64::total_cmp);
    let h = q * (xs.len() - 1) as f64;
    let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
    Some(xs[lo] + (h - lo as f64) * (xs[hi] - xs[lo]))
}

/// The summary of `records` per group of the values of the keys at `group` (indices into the
/// sampled keys `columns`), in the groups' order.
pub fn groups(records: &[Record], columns: &[(String, Column)], group: &[usize]) -> Vec<Group> {
    let metrics = metrics_of::<Summary>();
    let at = |key: &str| {
        metrics
            .iter()
            .position(|m| m.key == key)
            .expect("a summary metric")
    };
    let (reached, contacts, settling, path, kinematic) = (
        at("reached"),
        at("contacts"),
        at("settling_time"),
        at("path_length"),
        at("kinematic_length"),
    );
    let mut by: BTreeMap<(String, String), Vec<&Record>> = BTreeMap::new();
    for r in records {
        let values: Vec<(String, String)> = (group.iter())
            .map(|&i| {
                let v = r.values[i].as_ref().map_or("-".into(), |v| match v {
                    Sampled::Text(s) | Sampled::Other(s) => s.clone(),
                    other => other.toml(),
                });
                (format!("{}={v}", columns[i].0), v)
            })
            .collect();
        let key = if values.is_empty() {
            ("all".to_string(), "all".to_string())
        } else {
            let (labelled, bare): (Vec<_>, Vec<_>) = values.into_iter().unzip();
            (labelled.join(", "), bare.join(" · "))
        };
        by.entry(key).or_default().push(r);
    }
    by.into_iter()
        .map(|((label, values), records)| {
            let mut g = Group {
                label,
                values,
                runs: records.len(),
                failed: 0,
                agents: 0,
                reached: 0,
                interval: (0.0, 1.0),
                contacts_per_run: 0.0,
                settling: None,
                path_ratio: None,
            };
            let (mut settle, mut ratio, mut touches) = (Vec::new(), Vec::new(), 0usize);
            for r in &records {
                match &r.outcome {
                    Err(_) => {
                        g.failed += 1;
                        g.agents += 1;
                    }
                    Ok(agents) => {
                        for a in agents {
                            g.agents += 1;
                            let v = &a.values;
                            if let Value::Count(n) = v[contacts] {
                                touches += n;
                            }
                            if v[reached] != Value::Flag(true) {
                                continue;
                            }
                            g.reached += 1;
                            if let Value::Real(t) = v[settling] {
                                settle.push(t);
                            }
                            if let (Value::Real(p), Value::Real(k)) = (v[path], v[kinematic])
                                && k > 0.0
                            {
                                ratio.push(p / k);
                            }
                        }
                    }
                }
            }
            g.interval = wilson(g.reached, g.agents);
            g.contacts_per_run = touches as f64 / g.runs.max(1) as f64;
            let pair = |xs: &mut Vec<f64>| Some((quantile(xs, 0.5)?, quantile(xs, 0.9)?));
            g.settling = pair(&mut settle);
            g.path_ratio = pair(&mut ratio);
            g
        })
        .collect()
}

/// The groups as CSV.
pub fn groups_csv(groups: &[Group]) -> String {
    let mut out = String::from(
        "group,runs,failed,agents,reached,success,success_lo95,success_hi95,contacts_per_run,settling_p50_s,settling_p90_s,path_ratio_p50,path_ratio_p90\n",
    );
    let opt = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x}"));
    for g in groups {
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            crate::metrics::csv_field(&g.label),
            g.runs,
            g.failed,
            g.agents,
            g.reached,
            g.success(),
            g.interval.0,
            g.interval.1,
            g.contacts_per_run,
            opt(g.settling.map(|s| s.0)),
            opt(g.settling.map(|s| s.1)),
            opt(g.path_ratio.map(|s| s.0)),
            opt(g.path_ratio.map(|s| s.1)),
        ));
    }
    out
}

/// The groups as a table to print (the group column as wide as its longest label).
pub fn groups_table(groups: &[Group]) -> String {
    let width = groups
        .iter()
        .map(|g| g.label.chars().count())
        .fold(5, usize::max);
    let mut out = format!(
        "{:<width$} {:>6} {:>7} {:>20} {:>9} {:>17} {:>12}\n",
        "group", "runs", "reached", "success (95 %)", "contacts", "settle p50/p90", "path/opt p50"
    );
    for g in groups {
        let settle = g
            .settling
            .map_or("-".into(), |(a, b)| format!("{a:.2}/{b:.2} s"));
        let ratio = g.path_ratio.map_or("-".into(), |(a, _)| format!("{a:.3}"));
        let success = format!(
            "{:.1} % [{:.1}, {:.1}]",
            100.0 * g.success(),
            100.0 * g.interval.0,
            100.0 * g.interval.1
        );
        out.push_str(&format!(
            "{:<width$} {:>6} {:>7} {:>20} {:>9.3} {:>17} {:>12}\n",
            g.label, g.runs, g.reached, success, g.contacts_per_run, settle, ratio
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_interpolate_and_the_interval_holds_the_rate() {
        let mut xs = vec![4.0, 1.0, 3.0, 2.0];
        assert_eq!(quantile(&mut xs, 0.5), Some(2.5));
        assert_eq!(quantile(&mut xs, 1.0), Some(4.0));
        assert_eq!(quantile(&mut [], 0.5), None);
        for (k, n) in [(0, 10), (10, 10), (37, 200)] {
            let (lo, hi) = wilson(k, n);
            let p = k as f64 / n as f64;
            assert!(
                lo <= p && p <= hi && lo >= 0.0 && hi <= 1.0,
                "{k}/{n}: {lo} {hi}"
            );
        }
        // All ten reached: the interval still admits failure.
        assert!(wilson(10, 10).0 < 0.75);
    }
}
