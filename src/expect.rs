//! Checking a run against the world's `[expect]` tables: how a user writes a collision test
//! without Rust. `nadf run` exits with status 1 and lists what failed.
//!
//! An expectation names a metric of the [`Summary`] and how it is bounded: `max_<metric>` (at
//! most), `min_<metric>` (at least), or `<metric>` itself (exactly: only for yes/no and
//! whole-number metrics). A metric whose name already says how it is bounded is expected by
//! its name: `min_clearance = 0.5` (the smallest clearance is at least 0.5 m), `max_deviation
//! = 0.3` (δ_m is at most 0.3 m). The metrics and their units come from the summary's declaration, so
//! a new metric can be expected without a change here.

use crate::metrics::{Kind, Measured, Metric, Summary, Value, metrics_of, values_of};
use crate::sim::arm_run::ArmSummary;
use crate::sim::pendulum::PendulumSummary;
use crate::sim::shaped::ShapedSummary;
use crate::world::suggest::closest;
use crate::world::{Expect, ExpectValue, World};

/// How an expectation bounds its metric.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Relation {
    /// `min_<metric>`: at least the value.
    AtLeast,
    /// `max_<metric>`: at most the value.
    AtMost,
    /// `<metric>`: exactly the value.
    Exactly,
}

/// One expectation, checked against its metric.
#[derive(Debug, Clone, PartialEq)]
pub struct Bound {
    /// The key it was given as.
    pub key: String,
    /// The metric's position in the summary's metrics.
    pub index: usize,
    /// The metric.
    pub metric: Metric,
    /// How it is bounded.
    pub relation: Relation,
    /// The bound.
    pub value: ExpectValue,
}

impl Bound {
    /// `None` when `measured` meets the bound, else why not (`contacts = 2, expected 0`).
    pub fn miss(&self, measured: Value) -> Option<String> {
        let m = &self.metric;
        let shown = m.show_with_unit(measured);
        let bound = if m.unit.is_empty() {
            self.value.to_string()
        } else {
            format!("{} {}", self.value, m.unit)
        };
        let holds = match (measured.number(), self.value) {
            (None, _) => false,
            (Some(x), ExpectValue::Flag(b)) => (x != 0.0) == b,
            (Some(x), ExpectValue::Integer(n)) => self.compare(x, n as f64),
            (Some(x), ExpectValue::Real(b)) => self.compare(x, b),
        };
        let relation = match self.relation {
            Relation::AtLeast => "≥ ",
            Relation::AtMost => "≤ ",
            Relation::Exactly => "",
        };
        (!holds).then(|| format!("{} = {shown}, expected {relation}{bound}", m.key))
    }

    fn compare(&self, x: f64, bound: f64) -> bool {
        match self.relation {
            Relation::AtLeast => x >= bound,
            Relation::AtMost => x <= bound,
            Relation::Exactly => x == bound,
        }
    }
}

/// The bounds of an `[expect]` table, in the order of the summary's metrics (at least, at
/// most, exactly), or every key that is not a valid expectation, as `(key, message)`.
pub fn bounds(e: &Expect) -> Result<Vec<Bound>, Vec<(String, String)>> {
    bounds_of::<Summary>(e)
}

/// [`bounds`] against the metrics of another summary (a shaped agent's, which has the heading's
/// metrics too).
pub fn bounds_of<T: Measured>(e: &Expect) -> Result<Vec<Bound>, Vec<(String, String)>> {
    let metrics = metrics_of::<T>();
    let mut bounds = Vec::new();
    let mut problems = Vec::new();
    for (key, value) in &e.0 {
        match bound(&metrics, key, *value) {
            Ok(b) => bounds.push(b),
            Err(message) => problems.push((key.clone(), message)),
        }
    }
    // At least and at most of the same metric must leave room between them.
    for lo in bounds.iter().filter(|b| b.relation == Relation::AtLeast) {
        let hi = bounds
            .iter()
            .find(|b| b.relation == Relation::AtMost && b.index == lo.index);
        if let Some(hi) = hi
            && number(lo.value) > number(hi.value)
        {
            problems.push((
                lo.key.clone(),
                format!("{} is more than {} = {}", lo.value, hi.key, hi.value),
            ));
        }
    }
    if !problems.is_empty() {
        return Err(problems);
    }
    bounds.sort_by_key(|b| (b.index, b.relation as u8));
    Ok(bounds)
}

fn number(v: ExpectValue) -> f64 {
    match v {
        ExpectValue::Flag(b) => f64::from(u8::from(b)),
        ExpectValue::Integer(n) => n as f64,
        ExpectValue::Real(x) => x,
    }
}

/// The bound `key = value` names, checked against the metrics' kinds.
fn bound(metrics: &[Metric], key: &str, value: ExpectValue) -> Result<Bound, String> {
    let metric_named = |name: &str| metrics.iter().enumerate().find(|(_, m)| m.key == name);
    let prefixed = [("min_", Relation::AtLeast), ("max_", Relation::AtMost)]
        .into_iter()
        .find_map(|(prefix, relation)| {
            let name = key.strip_prefix(prefix)?;
            Some((relation, name, metric_named(name)?))
        });
    // A metric whose own name says how it is bounded (`min_clearance = 0.5`: the smallest
    // clearance is at least 0.5 m; `max_deviation`: at most).
    let named = || {
        let found = metric_named(key)?;
        let relation = if key.starts_with("min_") {
            Relation::AtLeast
        } else if key.starts_with("max_") {
            Relation::AtMost
        } else {
            Relation::Exactly
        };
        Some((relation, key, found))
    };
    let Some((relation, name, (index, metric))) = prefixed.or_else(named) else {
        let keys = metrics.iter().flat_map(|m| match m.kind {
            Kind::Flag => vec![m.key.to_string()],
            Kind::Count => vec![
                m.key.to_string(),
                format!("min_{}", m.key),
                format!("max_{}", m.key),
            ],
            Kind::Real | Kind::OptionalReal => vec![
                m.key.to_string(),
                format!("min_{}", m.key),
                format!("max_{}", m.key),
            ],
        });
        let keys: Vec<String> = keys.collect();
        let hint = closest(key, keys.iter().map(String::as_str))
            .map(|k| format!("; did you mean `{k}`?"))
            .unwrap_or_default();
        return Err(format!(
            "unknown expectation `{key}`: expect `max_<metric>`, `min_<metric>` or `<metric>` for a metric of the summary (see `nadf run --json`){hint}"
        ));
    };
    let metric = *metric;
    let kind_error = match (metric.kind, relation) {
        (Kind::Flag, Relation::Exactly) => match value {
            ExpectValue::Flag(_) => None,
            other => Some(format!("must be true or false, got {other}")),
        },
        (Kind::Flag, _) => Some(format!(
            "`{name}` is yes or no: expect it with `{name} = true` or `{name} = false`"
        )),
        (Kind::Count, _) => match value {
            ExpectValue::Integer(n) if n >= 0 => None,
            other => Some(format!("must be a whole number ≥ 0, got {other}")),
        },
        (Kind::Real | Kind::OptionalReal, Relation::Exactly) => Some(format!(
            "`{name}` is a real number: bound it with `max_{name}` or `min_{name}`"
        )),
        (Kind::Real | Kind::OptionalReal, _) => match value {
            ExpectValue::Integer(n) if n >= 0 => None,
            ExpectValue::Real(x) if x.is_finite() && x >= 0.0 => None,
            other => Some(format!("must be a finite number ≥ 0, got {other}")),
        },
    };
    match kind_error {
        Some(message) => Err(message),
        None => Ok(Bound {
            key: key.to_string(),
            index,
            metric,
            relation,
            value,
        }),
    }
}

/// The expectations in `e` that `s` misses. (`e` was validated when the world was loaded; an
/// expectation that is not valid is reported as missed.)
pub fn check(e: &Expect, s: &Summary) -> Vec<String> {
    check_of(e, s)
}

/// [`check`] for any summary.
pub fn check_of<T: Measured>(e: &Expect, s: &T) -> Vec<String> {
    let bounds = match bounds_of::<T>(e) {
        Ok(bounds) => bounds,
        Err(problems) => {
            return problems
                .into_iter()
                .map(|(key, message)| format!("{key}: {message}"))
                .collect();
        }
    };
    let values = values_of(s);
    bounds
        .iter()
        .filter_map(|b| b.miss(values[b.index]))
        .collect()
}

/// Every expectation of `world` that a run with these summaries (in agent order) misses, as
/// readable lines (`robot: contacts = 2, expected 0`). Empty when all hold.
pub fn failures(world: &World, summaries: &[Summary]) -> Vec<String> {
    let mut out = Vec::new();
    for (agent, summary) in world.agents.iter().zip(summaries) {
        for expect in [&world.expect, &agent.expect].into_iter().flatten() {
            out.extend(
                check(expect, summary)
                    .into_iter()
                    .map(|m| format!("{}: {m}", summary.name)),
            );
        }
    }
    out
}

/// Every expectation of `world` (its `[expect]` and each shaped agent's) that these shaped
/// agents' summaries miss, as readable lines.
pub fn shaped_failures(world: &World, summaries: &[ShapedSummary]) -> Vec<String> {
    let mut out = Vec::new();
    for (agent, summary) in world.shaped.iter().zip(summaries) {
        for expect in [&world.expect, &agent.expect].into_iter().flatten() {
            out.extend(
                check_of(expect, summary)
                    .into_iter()
                    .map(|m| format!("{}: {m}", summary.summary.name)),
            );
        }
    }
    out
}

/// Every `[arms.expect]` of `world` that these arm summaries miss, as readable lines.
pub fn arm_failures(world: &World, summaries: &[ArmSummary]) -> Vec<String> {
    let mut out = Vec::new();
    for (arm, summary) in world.arms.iter().zip(summaries) {
        if let Some(expect) = &arm.expect {
            out.extend(
                check_of(expect, summary)
                    .into_iter()
                    .map(|m| format!("{}: {m}", summary.name)),
            );
        }
    }
    out
}

/// Every `[pendulums.expect]` of `world` that these pendulum summaries miss.
pub fn pendulum_failures(world: &World, summaries: &[PendulumSummary]) -> Vec<String> {
    let mut out = Vec::new();
    for (p, s) in world.pendulums.iter().zip(summaries) {
        let Some(e) = &p.expect else { continue };
        let error = s.final_error.abs();
        if let Some(b) = e.max_final_error
            && (error > b || error.is_nan())
        {
            out.push(format!(
                "{}: final_error = {error:.6} rad, expected ≤ {b} rad",
                s.name
            ));
        }
        if let Some(b) = e.min_final_error
            && (error < b || error.is_nan())
        {
            out.push(format!(
                "{}: final_error = {error:.6} rad, expected ≥ {b} rad",
                s.name
            ));
        }
        if let Some(n) = e.max_bias_updates
            && s.bias_updates.len() > n
        {
            out.push(format!(
                "{}: {} bias updates, expected at most {n}",
                s.name,
                s.bias_updates.len()
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary() -> Summary {
        Summary {
            name: "r".into(),
            reached: true,
            settling_time: Some(5.0),
            final_error: 0.01,
            contacts: 0,
            obstacle_contacts: 0,
            min_obstacle_distance: None,
            min_clearance: Some(0.3),
            max_deviation: 0.2,
            path_length: 10.0,
            peak_force: 30.0,
            control_variation: 100.0,
            peak_speed: 4.0,
            final_speed: 0.01,
            distance_covered: Some(20.0),
            lateral_speed_rms: 0.1,
            lateral_reversals: 3,
            bias_updates: 0,
            resolves: 0,
            whole_resolves: 0,
            deadlocked: None,
            livelocked: None,
            min_separation: None,
            intractable: None,
            map_seen: None,
            kinematic_length: None,
            envelope_time: 0.0,
            faults: crate::metrics::Faults::default(),
        }
    }

    fn expect(pairs: &[(&str, ExpectValue)]) -> Expect {
        Expect(pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect())
    }

    use ExpectValue::{Flag, Integer, Real};

    #[test]
    fn met_expectations_pass_and_missed_ones_are_listed_in_the_summary_order() {
        let ok = expect(&[
            ("reached", Flag(true)),
            ("contacts", Integer(0)),
            ("max_settling_time", Real(6.0)),
            ("min_clearance", Real(0.25)),
            ("max_final_error", Real(0.05)),
            ("max_deviation", Real(0.25)),
            ("max_peak_speed", Integer(5)),
            ("max_peak_force", Real(40.0)),
        ]);
        assert!(check(&ok, &summary()).is_empty());

        let strict = expect(&[
            ("max_peak_speed", Real(3.0)),
            ("min_contacts", Integer(1)),
            ("min_clearance", Real(0.5)),
            ("max_settling_time", Real(4.0)),
        ]);
        let failed = check(&strict, &summary());
        assert_eq!(
            failed,
            [
                "settling_time = 5.000 s, expected ≤ 4 s",
                "contacts = 0, expected ≥ 1",
                "min_clearance = 0.300 m, expected ≥ 0.5 m",
                "peak_speed = 4.00 m/s, expected ≤ 3 m/s",
            ]
        );
    }

    #[test]
    fn an_agent_that_never_settles_misses_a_settling_time() {
        let s = Summary {
            settling_time: None,
            reached: false,
            ..summary()
        };
        let e = expect(&[("max_settling_time", Real(60.0)), ("reached", Flag(true))]);
        assert_eq!(
            check(&e, &s),
            [
                "reached = false, expected true",
                "settling_time = never, expected ≤ 60 s"
            ]
        );
    }

    #[test]
    fn distance_covered_stopping_and_sideways_reversals_are_checked() {
        let e = expect(&[
            ("min_distance_covered", Real(25.0)),
            ("max_final_speed", Real(0.001)),
            ("max_lateral_reversals", Integer(2)),
        ]);
        let failed = check(&e, &summary());
        assert_eq!(
            failed,
            [
                "final_speed = 0.010 m/s, expected ≤ 0.001 m/s",
                "distance_covered = 20.000 m, expected ≥ 25 m",
                "lateral_reversals = 3, expected ≤ 2",
            ]
        );
        let mut unmeasured = summary();
        unmeasured.distance_covered = None;
        let e = expect(&[("max_distance_covered", Real(30.0))]);
        assert!(check(&e, &unmeasured)[0].contains("not measured"));
    }

    #[test]
    fn a_new_metric_of_the_summary_can_be_expected_and_faults_too() {
        let e = expect(&[
            ("max_penetrations", Integer(0)),
            ("non_finite_state", Flag(false)),
        ]);
        assert!(bounds(&e).is_ok());
        let mut s = summary();
        s.faults.penetrations = 2;
        assert_eq!(check(&e, &s), ["penetrations = 2, expected ≤ 0"]);
    }

    #[test]
    fn keys_that_name_no_metric_or_misuse_one_are_rejected() {
        let problems = bounds(&expect(&[
            ("max_setling_time", Real(1.0)),
            ("min_reached", Flag(true)),
            ("final_error", Real(0.1)),
            ("contacts", Real(1.5)),
            ("max_peak_speed", Real(-1.0)),
            ("reached", Integer(1)),
        ]))
        .unwrap_err();
        let message = |key: &str| &problems.iter().find(|(k, _)| k == key).unwrap().1;
        assert!(message("max_setling_time").contains("did you mean `max_settling_time`?"));
        assert!(message("min_reached").contains("`reached = true`"));
        assert!(message("final_error").contains("max_final_error"));
        assert!(message("contacts").contains("whole number"));
        assert!(message("max_peak_speed").contains("finite number ≥ 0"));
        assert!(message("reached").contains("true or false"));
        let crossed = bounds(&expect(&[
            ("min_contacts", Integer(3)),
            ("max_contacts", Integer(2)),
        ]))
        .unwrap_err();
        assert_eq!(crossed[0].0, "min_contacts");
    }
}
