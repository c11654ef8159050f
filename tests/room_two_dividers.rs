//! The paper's room with two dividers (§II–III, §VI.1, §VI.3) under viscous damping and NADF,
//! normalized guidance, K = 1: the relations of the foundation issue and the design page.

mod common;

use common::summary;

const WORLD: &str = "room-two-dividers.toml";

fn with(kind: &str, b: f64) -> nadf::metrics::Summary {
    summary(
        WORLD,
        &[
            &format!("agents.0.controller.kind={kind}"),
            &format!("agents.0.controller.b={b}"),
            // The paper's laws bare: the clearance envelope would keep even B = 0.1 clear.
            "agents.0.controller.envelope=false",
            // Long enough for the slowest viscous case to settle.
            "duration=120",
        ],
    )
}

#[test]
fn viscous_b_0_1_hits_a_wall() {
    let s = with("viscous", 0.1);
    assert!(s.contacts > 0, "{s:?}");
    // Rapier holds it off the wall, within the contact tolerance.
    let tolerance = nadf::sim::CONTACT_TOLERANCE;
    assert!(s.min_clearance.is_some_and(|c| c < tolerance), "{s:?}");
}

#[test]
fn viscous_b_0_7_reaches_the_target_without_contact() {
    let s = with("viscous", 0.7);
    assert_eq!(s.contacts, 0, "{s:?}");
    assert!(
        s.reached && s.min_clearance.is_some_and(|c| c > 0.0),
        "{s:?}"
    );
}

#[test]
fn nadf_b_d_10_reaches_without_contact_in_half_the_viscous_settling_time() {
    let nadf = with("nadf", 10.0);
    let viscous = with("viscous", 0.7);
    assert_eq!(nadf.contacts, 0, "{nadf:?}");
    assert!(nadf.reached, "{nadf:?}");
    let (tn, tv) = (nadf.settling_time.unwrap(), viscous.settling_time.unwrap());
    assert!(tn <= 0.5 * tv, "NADF {tn} s vs viscous {tv} s");
    // The body ends on the target, not beside it.
    assert!(nadf.final_error < 0.01, "{nadf:?}");
}

#[test]
fn nadf_settling_time_and_deviation_fall_as_b_d_grows() {
    let runs: Vec<_> = [1.0, 3.0, 10.0, 30.0]
        .iter()
        .map(|&b| with("nadf", b))
        .collect();
    for pair in runs.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        assert!(
            b.settling_time.unwrap() < a.settling_time.unwrap(),
            "settling time: {a:?} then {b:?}"
        );
        assert!(
            b.max_deviation < a.max_deviation,
            "deviation: {a:?} then {b:?}"
        );
    }
    for s in &runs {
        assert_eq!(s.contacts, 0, "{s:?}");
    }
    assert!(runs[3].max_deviation <= 0.25, "{:?}", runs[3]);
}

#[test]
fn viscous_settling_time_has_an_interior_minimum_twice_nadf_b_d_30() {
    let bs = [0.3, 0.5, 0.7, 1.0, 1.5, 3.0];
    let times: Vec<f64> = bs
        .iter()
        .map(|&b| with("viscous", b).settling_time.unwrap_or(f64::INFINITY))
        .collect();
    let (best, t_min) = times
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    assert!(
        best > 0 && best < bs.len() - 1,
        "minimum at the edge: {times:?}"
    );
    let nadf = with("nadf", 30.0).settling_time.unwrap();
    assert!(
        t_min >= 2.0 * nadf,
        "viscous best {t_min} s vs NADF B_d = 30 {nadf} s"
    );
}

/// The paper's motivation (eq. 2): viscous damping keeps the body off the walls only below an
/// admissible initial speed. Launched at 8 m/s towards the first divider, viscous B = 0.7 (which
/// crosses the room without contact from rest) hits it; NADF B_d = 10 does not. Both settle.
#[test]
fn from_8_m_s_towards_a_divider_viscous_damping_hits_it_and_nadf_does_not() {
    let launched = |kind: &str, b: f64| {
        summary(
            "room-initial-velocity.toml",
            &[
                &format!("agents.0.controller.kind={kind}"),
                &format!("agents.0.controller.b={b}"),
                "duration=120",
            ],
        )
    };
    let viscous = launched("viscous", 0.7);
    assert!(viscous.contacts > 0, "{viscous:?}");
    assert!(
        viscous.reached && viscous.settling_time.is_some(),
        "{viscous:?}"
    );
    let nadf = launched("nadf", 10.0);
    assert_eq!(nadf.contacts, 0, "{nadf:?}");
    assert!(nadf.reached && nadf.settling_time.is_some(), "{nadf:?}");
    assert!(nadf.peak_speed > 7.5, "launched at 8 m/s: {nadf:?}");
}

/// Every contact start is an event on the timeline (a WARN in the recording), one per contact
/// the summary counts.
#[test]
fn every_contact_is_an_event() {
    let world = common::world("room-two-dividers-viscous.toml", &[]);
    let (states, s) = common::trace(&world);
    let events = states
        .iter()
        .flat_map(|(_, a)| &a.events)
        .filter(|e| e.starts_with("contact at"))
        .count();
    assert!(
        s.contacts > 0 && events == s.contacts,
        "{events} events, {s:?}"
    );
}
