//! The paper's room under the paper's own law, `F = −K∇V` (eq. 11, 34), with a target disc
//! (issue "the paper's own law", items 1 and 3): the relations of §II–III and §VI.1 measured
//! with K = 700 N·m, the default target disc (the agent's radius, 0.2 m) and dt = 5 ms.

mod common;

/// The paper's law bare: the clearance envelope is the sandbox's, not the paper's.
const BARE: &str = "agents.0.controller.envelope=false";

fn summary(world: &str, overrides: &[&str]) -> nadf::metrics::Summary {
    let overrides: Vec<&str> = overrides.iter().copied().chain([BARE]).collect();
    common::summary(world, &overrides)
}

const NADF: &str = "room-two-dividers-gradient.toml";
const VISCOUS: &str = "room-two-dividers-gradient-viscous.toml";

fn viscous(b: f64, extra: &[&str]) -> nadf::metrics::Summary {
    let b = format!("agents.0.controller.b={b}");
    let mut overrides = vec![b.as_str(), "duration=150"];
    overrides.extend_from_slice(extra);
    summary(VISCOUS, &overrides)
}

/// The paper: NADF settles 6× faster than viscous B = 0.7 (72 s). Measured: 25.2 s against
/// 103.0 s, 4.1× (an independent point-mass reference of the same room: 3.7×). The ratio falls
/// as K grows (K = 1000: 3.4×, K = 3000: 2.2×; K = 500: 4.7×): the viscous body crawls where
/// the field is faint, so what it loses depends on how faint; 3.5× is asserted.
#[test]
fn nadf_settles_at_least_3_5_times_faster_than_viscous_b_0_7_without_contact() {
    let nadf = summary(NADF, &[]);
    let slow = viscous(0.7, &[]);
    assert!(nadf.reached && nadf.contacts == 0, "{nadf:?}");
    assert!(slow.reached && slow.contacts == 0, "{slow:?}");
    let (tn, tv) = (nadf.settling_time.unwrap(), slow.settling_time.unwrap());
    assert!(tv >= 3.5 * tn, "NADF {tn} s, viscous {tv} s");
    // The bowl inside the target disc brings the body onto the target point.
    assert!(nadf.final_error < 1e-3 && slow.final_error < 1e-3);
}

/// The paper (figures 4–5): B = 0.1 collides, B = 0.15 has large transients without collision.
/// With the law integrated exactly neither collides: Proposition 1 (eq. 13, 19 with any
/// damping) keeps `K·V + ½m|v|²` from growing, so a body starting at rest never climbs to
/// V = 1 at the walls. Both swing wider than B = 0.7 (δ_m 1.02 and 0.97 m against 0.72 m). The
/// paper's collisions are the explicit step's: handed the force at the start of each step,
/// B = 0.1 touches the walls 37 times (and B = 0.7 4 times: the explicit step collides at every B).
#[test]
fn low_viscous_damping_swings_wide_and_collides_only_when_integrated_explicitly() {
    let reference = viscous(0.7, &[]);
    for b in [0.1, 0.15] {
        let s = viscous(b, &[]);
        assert!(s.reached && s.contacts == 0, "B = {b}: {s:?}");
        assert!(
            s.max_deviation > 1.2 * reference.max_deviation,
            "B = {b}: δ_m {} m, B = 0.7: {} m",
            s.max_deviation,
            reference.max_deviation
        );
    }
    let explicit = viscous(0.1, &["agents.0.controller.integration=explicit"]);
    assert!(explicit.contacts > 0, "{explicit:?}");
}

/// δ_m falls as B_d grows (paper §III, Proposition 2, figure 24). Measured: 0.664, 0.564, 0.409,
/// 0.273 m for B_d = 3, 10, 30, 100, with the settling time 25.0–25.3 s throughout.
#[test]
fn delta_m_falls_as_b_d_grows() {
    let runs: Vec<_> = [3.0, 10.0, 30.0, 100.0]
        .iter()
        .map(|b| summary(NADF, &[&format!("agents.0.controller.b={b}")]))
        .collect();
    for pair in runs.windows(2) {
        assert!(pair[1].contacts == 0 && pair[1].reached, "{:?}", pair[1]);
        assert!(
            pair[1].max_deviation < pair[0].max_deviation,
            "{:?} then {:?}",
            pair[0],
            pair[1]
        );
    }
}

/// With the target disc the run no longer depends on the grid: halving the cell changes the
/// settling time and δ_m by less than 10 % (measured: 25.17 → 27.38 s, 8.8 %; 0.565 → 0.525 m,
/// 7.1 %; with a one-cell target the reference found 35 s against never settling). What is
/// left is the field's discretization behind the dividers: `1 − V` at the start converges as
/// 9.6e-6, 8.2e-6, 7.8e-6 for cells of 5, 2.5 and 1.25 cm.
#[test]
fn the_run_is_the_same_on_a_grid_twice_as_fine() {
    let coarse = summary(NADF, &[]);
    let fine = summary(NADF, &["field.cell=0.025"]);
    assert!(fine.reached && fine.contacts == 0, "{fine:?}");
    let change = |a: f64, b: f64| (a - b).abs() / a;
    let (tc, tf) = (coarse.settling_time.unwrap(), fine.settling_time.unwrap());
    assert!(change(tc, tf) < 0.1, "settling time {tc} s, then {tf} s");
    let (dc, df) = (coarse.max_deviation, fine.max_deviation);
    assert!(change(dc, df) < 0.1, "δ_m {dc} m, then {df} m");
}
