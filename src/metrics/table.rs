//! Summaries as text, from their declaration: the table `nadf run` prints (the metrics that
//! have a column) and the CSV of a sweep (every metric).

use super::measure::{Measured, Value, measurements, metrics_of, values_of};
use super::{Faults, Summary};

/// Named summaries of any kind (`T`'s metrics declared with a column) as a plain-text table
/// whose first column is headed `label`; empty without rows.
pub fn rows_table<T: Measured>(label: &str, rows: &[(&str, &T)]) -> String {
    if rows.is_empty() {
        return String::new();
    }
    let metrics: Vec<_> = metrics_of::<T>()
        .into_iter()
        .enumerate()
        .filter_map(|(i, m)| Some((i, m.column?, m)))
        .collect();
    let mut header = vec![label.to_string()];
    header.extend(metrics.iter().map(|(_, column, _)| column.to_string()));
    let mut table = vec![header];
    for (name, s) in rows {
        let values = values_of(*s);
        let mut row = vec![name.to_string()];
        row.extend(metrics.iter().map(|(i, _, m)| m.show(values[*i])));
        table.push(row);
    }
    let widths: Vec<usize> = (0..table[0].len())
        .map(|c| {
            let widest = table.iter().map(|r| r[c].chars().count()).max();
            widest.unwrap_or(0).max(if c == 0 { 12 } else { 7 })
        })
        .collect();
    let mut out = String::new();
    for row in &table {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(c, (cell, w))| {
                if c == 0 {
                    format!("{cell:<w$}")
                } else {
                    format!("{cell:>w$}")
                }
            })
            .collect();
        out += cells.join(" ").trim_end();
        out.push('\n');
    }
    out
}

/// The summaries as a plain-text table: one row per agent, one column per metric declared
/// with a column, then one line per agent that met numerical faults.
pub fn table(summaries: &[Summary]) -> String {
    let rows: Vec<(&str, &Summary)> = summaries.iter().map(|s| (s.name.as_str(), s)).collect();
    let mut out = rows_table("agent", &rows);
    for s in summaries {
        if let Some(t) = s.deadlocked {
            out += &format!(
                "{}: deadlocked at {t:.2} s: no progress towards its target, another agent next to it\n",
                s.name
            );
        }
        if let Some(t) = s.livelocked {
            out += &format!(
                "{}: livelocked at {t:.2} s: no progress towards its target, moving all the while\n",
                s.name
            );
        }
        if let Some(t) = s.intractable {
            out += &format!(
                "{}: intractable at {t:.2} s: the walls it has seen close every route to its target\n",
                s.name
            );
        }
        if let Some(seen) = s.map_seen {
            let full = s
                .kinematic_length
                .map_or("no path with full knowledge".into(), |l| {
                    format!("{:.2} m with full knowledge", l)
                });
            out += &format!(
                "{}: lidar saw {:.0} % of the map; path {:.2} m, {full}\n",
                s.name,
                100.0 * seen,
                s.path_length
            );
        }
    }
    for s in summaries.iter().filter(|s| !s.faults.is_clean()) {
        out += &format!("faults of {}: {}\n", s.name, faults(&s.faults));
    }
    out
}

/// The faults met, as `guidance_lost_steps 12, penetrations 1`.
fn faults(f: &Faults) -> String {
    measurements(f)
        .filter(|(_, v)| !matches!(v, Value::Count(0) | Value::Flag(false)))
        .map(|(m, v)| match v {
            Value::Flag(true) => m.key.to_string(),
            _ => format!("{} {}", m.key, m.show(v)),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// A CSV table of `rows`: the `leading` columns (already CSV cells) of each row, then every
/// metric of its measured value, in full precision (an empty cell where a value is missing).
/// The header names the leading columns `keys`, then every metric.
pub fn csv<T: Measured>(keys: &[String], rows: &[(Vec<String>, &T)]) -> String {
    let mut header: Vec<String> = keys.iter().map(|k| field(k)).collect();
    header.extend(metrics_of::<T>().iter().map(|m| m.key.to_string()));
    let mut out = header.join(",") + "\n";
    for (leading, measured) in rows {
        let mut row = leading.clone();
        row.extend(values_of(*measured).iter().map(Value::to_string));
        out += &row.join(",");
        out.push('\n');
    }
    out
}

/// A CSV field, quoted when it needs to be (RFC 4180).
pub fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_are_quoted_when_needed() {
        assert_eq!(field("robot"), "robot");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }
}
