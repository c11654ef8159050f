//! What one run of an experiment produced ([`Record`]), and its line in a shard's progress
//! file (`runs.jsonl`): written as each run ends, read back exactly (reals in shortest
//! round-trip form, as strings that parse back to the same bits), so results built from a
//! resumed or merged set of lines are the results of one uninterrupted run.

use serde_json::{Value as Json, json};

use super::sample::{Column, Sampled};
use crate::metrics::{Kind, Metric, Summary, Value, metrics_of};

/// One agent's summary in a run, as measured values in the order of the summary's metrics.
#[derive(Debug, Clone, PartialEq)]
pub struct AgentRecord {
    /// The agent's name.
    pub name: String,
    /// Its values, in the order of [`metrics_of::<Summary>`].
    pub values: Vec<Value>,
}

/// One run: its index, seed, sampled values (`None` where a run failed before drawing one),
/// and its agents' summaries or why it could not be run.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// The run's index.
    pub run: u64,
    /// Its seed.
    pub seed: u64,
    /// Its values of the sampled keys, in the experiment's order.
    pub values: Vec<Option<Sampled>>,
    /// Its agents' summaries, or the error.
    pub outcome: Result<Vec<AgentRecord>, String>,
}

/// A real as JSON text of its shortest round-trip form (`"0.1"`, `"inf"`, `"NaN"`): read back
/// by Rust's correctly rounded parser, it is the same `f64` to the bit (a JSON number would go
/// through serde_json's faster, inexact one).
fn real(x: f64) -> Json {
    Json::String(format!("{x:?}"))
}

fn read_real(j: &Json) -> Option<f64> {
    j.as_str()?.parse().ok()
}

impl Record {
    /// The record as one line of JSON (no newline).
    pub fn to_line(&self) -> String {
        let values: Vec<Json> = (self.values.iter())
            .map(|v| match v {
                None => Json::Null,
                Some(Sampled::Real(x)) => real(*x),
                Some(Sampled::Int(n)) => json!(n),
                Some(Sampled::Flag(b)) => json!(b),
                Some(Sampled::Text(s) | Sampled::Other(s)) => json!(s),
                Some(Sampled::Point([x, y])) => json!([real(*x), real(*y)]),
            })
            .collect();
        let (agents, error) = match &self.outcome {
            Ok(agents) => {
                let agents: Vec<Json> = (agents.iter())
                    .map(|a| {
                        let values: Vec<Json> = (a.values.iter())
                            .map(|v| match v {
                                Value::Flag(b) => json!(b),
                                Value::Count(n) => json!(n),
                                Value::Real(x) => real(*x),
                                Value::Missing => Json::Null,
                            })
                            .collect();
                        json!({ "name": a.name, "values": values })
                    })
                    .collect();
                (agents, Json::Null)
            }
            Err(e) => (Vec::new(), json!(e)),
        };
        json!({ "run": self.run, "seed": self.seed, "values": values, "agents": agents, "error": error })
            .to_string()
    }

    /// The record of a line written by [`Record::to_line`] for sampled keys of `columns`;
    /// `None` for a line that is not one (a line cut short by a kill).
    pub fn from_line(line: &str, columns: &[Column]) -> Option<Self> {
        let j: Json = serde_json::from_str(line).ok()?;
        let run = j.get("run")?.as_u64()?;
        let seed = j.get("seed")?.as_u64()?;
        let raw = j.get("values")?.as_array()?;
        if raw.len() != columns.len() {
            return None;
        }
        let mut values = Vec::with_capacity(raw.len());
        for (v, column) in raw.iter().zip(columns) {
            values.push(match (v, column) {
                (Json::Null, _) => None,
                (v, Column::Real) => Some(Sampled::Real(read_real(v)?)),
                (v, Column::Int) => Some(Sampled::Int(v.as_i64()?)),
                (v, Column::Flag) => Some(Sampled::Flag(v.as_bool()?)),
                (v, Column::Text) => {
                    let s = v.as_str()?.to_string();
                    // A choice of non-strings is TOML text; a string choice the string.
                    Some(Sampled::Text(s))
                }
                (Json::Array(xy), Column::Point) if xy.len() == 2 => {
                    Some(Sampled::Point([read_real(&xy[0])?, read_real(&xy[1])?]))
                }
                _ => return None,
            });
        }
        let metrics = metrics_of::<Summary>();
        let outcome = match j.get("error")? {
            Json::String(e) => Err(e.clone()),
            Json::Null => {
                let mut agents = Vec::new();
                for a in j.get("agents")?.as_array()? {
                    let name = a.get("name")?.as_str()?.to_string();
                    let raw = a.get("values")?.as_array()?;
                    if raw.len() != metrics.len() {
                        return None;
                    }
                    let values = (raw.iter().zip(&metrics))
                        .map(|(v, m)| read_value(v, m))
                        .collect::<Option<Vec<_>>>()?;
                    agents.push(AgentRecord { name, values });
                }
                Ok(agents)
            }
            _ => return None,
        };
        Some(Self {
            run,
            seed,
            values,
            outcome,
        })
    }
}

fn read_value(v: &Json, metric: &Metric) -> Option<Value> {
    Some(match (metric.kind, v) {
        (Kind::OptionalReal, Json::Null) => Value::Missing,
        (Kind::Flag, v) => Value::Flag(v.as_bool()?),
        (Kind::Count, v) => Value::Count(usize::try_from(v.as_u64()?).ok()?),
        (Kind::Real | Kind::OptionalReal, v) => Value::Real(read_real(v)?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_reads_back_exactly() {
        let metrics = metrics_of::<Summary>();
        let values: Vec<Value> = (metrics.iter().enumerate())
            .map(|(i, m)| match m.kind {
                Kind::Flag => Value::Flag(i % 2 == 0),
                Kind::Count => Value::Count(i * 7),
                Kind::Real => Value::Real(if i == 3 {
                    f64::INFINITY
                } else {
                    0.1 + i as f64 / 3.0
                }),
                Kind::OptionalReal => Value::Missing,
            })
            .collect();
        let record = Record {
            run: 41,
            seed: u64::MAX - 3,
            values: vec![
                Some(Sampled::Real(1.0 / 3.0)),
                Some(Sampled::Int(-4)),
                Some(Sampled::Text("viscous".into())),
                Some(Sampled::Point([0.1, f64::NEG_INFINITY])),
                None,
            ],
            outcome: Ok(vec![AgentRecord {
                name: "robot".into(),
                values,
            }]),
        };
        let columns = [
            Column::Real,
            Column::Int,
            Column::Text,
            Column::Point,
            Column::Flag,
        ];
        let line = record.to_line();
        assert!(!line.contains('\n'));
        assert_eq!(Record::from_line(&line, &columns), Some(record.clone()));
        let failed = Record {
            outcome: Err("cannot reach".into()),
            ..record
        };
        assert_eq!(Record::from_line(&failed.to_line(), &columns), Some(failed));
        // A line cut short is no record.
        assert_eq!(Record::from_line(&line[..line.len() / 2], &columns), None);
    }
}
