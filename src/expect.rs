//! Checking a run against the world's `[expect]` tables: how a user writes a collision test
//! without Rust. `nadf run` exits with status 1 and lists what failed.

use crate::metrics::Summary;
use crate::world::{Expect, World};

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

/// Every `[pendulums.expect]` of `world` that these pendulum summaries miss.
pub fn pendulum_failures(
    world: &World,
    summaries: &[crate::sim::pendulum::PendulumSummary],
) -> Vec<String> {
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

/// The expectations in `e` that `s` misses.
pub fn check(e: &Expect, s: &Summary) -> Vec<String> {
    let mut failed = Vec::new();
    if let Some(reached) = e.reached
        && s.reached != reached
    {
        failed.push(format!("reached = {}, expected {reached}", s.reached));
    }
    if let Some(n) = e.contacts
        && s.contacts != n
    {
        failed.push(format!("contacts = {}, expected {n}", s.contacts));
    }
    if let Some(n) = e.min_contacts
        && s.contacts < n
    {
        failed.push(format!("contacts = {}, expected at least {n}", s.contacts));
    }
    if let Some(n) = e.max_contacts
        && s.contacts > n
    {
        failed.push(format!("contacts = {}, expected at most {n}", s.contacts));
    }
    if let Some(limit) = e.max_settling_time {
        match s.settling_time {
            None => failed.push(format!("never settled, expected settling_time ≤ {limit} s")),
            Some(t) if t > limit => {
                failed.push(format!("settling_time = {t:.3} s, expected ≤ {limit} s"))
            }
            Some(_) => {}
        }
    }
    let mut at_least = |name: &str, value: f64, bound: Option<f64>, unit: &str| {
        if let Some(b) = bound
            && value < b
        {
            failed.push(format!("{name} = {value:.4} {unit}, expected ≥ {b} {unit}"));
        }
    };
    at_least("min_clearance", s.min_clearance, e.min_clearance, "m");
    if e.min_distance_covered.is_some() || e.max_distance_covered.is_some() {
        match s.distance_covered {
            None => failed.push(
                "distance_covered was not measured (set distance_at within the duration)"
                    .to_string(),
            ),
            Some(d) => {
                at_least("distance_covered", d, e.min_distance_covered, "m");
                if let Some(b) = e.max_distance_covered
                    && d > b
                {
                    failed.push(format!("distance_covered = {d:.4} m, expected ≤ {b} m"));
                }
            }
        }
    }
    if let Some(n) = e.max_lateral_reversals
        && s.lateral_reversals > n
    {
        failed.push(format!(
            "lateral_reversals = {}, expected at most {n}",
            s.lateral_reversals
        ));
    }
    for (name, value, bound, unit) in [
        ("final_error", s.final_error, e.max_final_error, "m"),
        ("max_deviation", s.max_deviation, e.max_deviation, "m"),
        ("peak_speed", s.peak_speed, e.max_peak_speed, "m/s"),
        ("peak_force", s.peak_force, e.max_peak_force, "N"),
        ("final_speed", s.final_speed, e.max_final_speed, "m/s"),
    ] {
        if let Some(b) = bound
            && (value > b || value.is_nan())
        {
            failed.push(format!("{name} = {value:.4} {unit}, expected ≤ {b} {unit}"));
        }
    }
    failed
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
            min_clearance: 0.3,
            max_deviation: 0.2,
            path_length: 10.0,
            peak_force: 30.0,
            control_variation: 100.0,
            peak_speed: 4.0,
            final_speed: 0.01,
            distance_covered: Some(20.0),
            lateral_speed_rms: 0.1,
            lateral_reversals: 3,
            faults: crate::metrics::Faults::default(),
        }
    }

    #[test]
    fn met_expectations_pass_and_missed_ones_are_listed() {
        let ok = Expect {
            reached: Some(true),
            contacts: Some(0),
            max_settling_time: Some(6.0),
            min_clearance: Some(0.25),
            max_final_error: Some(0.05),
            max_deviation: Some(0.25),
            max_peak_speed: Some(5.0),
            max_peak_force: Some(40.0),
            ..Expect::default()
        };
        assert!(check(&ok, &summary()).is_empty());

        let strict = Expect {
            min_contacts: Some(1),
            max_settling_time: Some(4.0),
            min_clearance: Some(0.5),
            max_peak_speed: Some(3.0),
            ..Expect::default()
        };
        let failed = check(&strict, &summary());
        assert_eq!(failed.len(), 4, "{failed:?}");
        assert!(failed[0].contains("expected at least 1"));
        assert!(failed[1].contains("settling_time = 5.000 s, expected ≤ 4 s"));
    }

    #[test]
    fn an_agent_that_never_settles_misses_a_settling_time() {
        let s = Summary {
            settling_time: None,
            reached: false,
            ..summary()
        };
        let e = Expect {
            max_settling_time: Some(60.0),
            ..Expect::default()
        };
        assert_eq!(
            check(&e, &s),
            ["never settled, expected settling_time ≤ 60 s"]
        );
    }

    #[test]
    fn distance_covered_stopping_and_sideways_reversals_are_checked() {
        let e = Expect {
            min_distance_covered: Some(25.0),
            max_final_speed: Some(0.001),
            max_lateral_reversals: Some(2),
            ..Expect::default()
        };
        let failed = check(&e, &summary());
        assert_eq!(failed.len(), 3, "{failed:?}");
        assert!(failed[0].contains("distance_covered = 20.0000 m, expected ≥ 25 m"));
        assert!(failed[1].contains("lateral_reversals = 3"));
        assert!(failed[2].contains("final_speed = 0.0100 m/s"));
        let mut unmeasured = summary();
        unmeasured.distance_covered = None;
        let e = Expect {
            max_distance_covered: Some(30.0),
            ..Expect::default()
        };
        assert!(check(&e, &unmeasured)[0].contains("not measured"));
    }
}
