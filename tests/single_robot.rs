//! The paper's single-robot experiments beyond the plain room (§V, §VI.2–VI.5): the speed limit,
//! a constant drift with and without clamping, the iterative bias, the sliding-mode baseline and
//! sensor noise, each on its world in `worlds/`.

mod common;

use common::{summary_of, trace, world};

/// The drift of eq. 71 on a 1 kg body, N.
const DRIFT: f64 = 5.656854249492381;

#[test]
fn the_speed_limit_caps_the_speed_and_trades_settling_time_for_control_effort() {
    let limited = world("room-speed-limit.toml", &[]);
    let mut free = limited.clone();
    free.agents[0].controller.speed_limit = None;
    let (with, without) = (summary_of(&limited), summary_of(&free));
    // Without the limit this world's NADF run is faster than 5 m/s.
    assert!(without.peak_speed > 6.0, "{without:?}");
    assert!(with.peak_speed <= 5.05, "{with:?}");
    assert_eq!((with.contacts, without.contacts), (0, 0));
    assert!(with.reached, "{with:?}");
    assert!(
        with.settling_time.unwrap() > without.settling_time.unwrap(),
        "{with:?}\n{without:?}"
    );
    assert!(
        with.peak_force < without.peak_force,
        "{with:?}\n{without:?}"
    );
}

#[test]
fn the_speed_limit_shows_in_the_state_and_holds_at_5_m_per_s() {
    let (states, _) = trace(&world("room-speed-limit.toml", &[]));
    let limited: Vec<_> = states.iter().filter(|(_, s)| s.speed_limited).collect();
    assert!(limited.len() > 20, "{}", limited.len());
    // While the limit acts, the radial speed sits at the limit (paper figure 21).
    for (t, s) in &limited {
        let v = s.velocity.norm();
        assert!((4.95..=5.05).contains(&v), "t = {t}: {v}");
    }
}

#[test]
fn under_drift_nadf_alone_reaches_the_target_then_rests_off_it_where_the_drift_wins() {
    let w = world("room-drift.toml", &[]);
    let (states, s) = trace(&w);
    assert_eq!(s.contacts, 0, "{s:?}");
    let closest = states
        .iter()
        .map(|(_, a)| a.distance)
        .fold(f64::INFINITY, f64::min);
    assert!(closest < 0.1, "closest {closest}");
    // It drifts away to where the tapered guidance K·d/r_c balances the drift.
    let c = &w.agents[0].controller;
    let hold_off = c.capture_radius * DRIFT / c.k();
    assert!(
        (s.final_error - hold_off).abs() < 0.01,
        "{} vs {hold_off}",
        s.final_error
    );
    assert!(s.final_error > 3.0 * closest);
}

#[test]
fn clamping_traps_the_body_inside_sigma_at_the_rest_point_of_eq_47() {
    let w = world("room-drift-clamp.toml", &[]);
    let c = &w.agents[0].controller;
    let clamp = c.clamp.unwrap();
    let (states, s) = trace(&w);
    assert_eq!(s.contacts, 0, "{s:?}");
    assert!(s.final_error < clamp.sigma, "{s:?}");
    // Eq. 47 with normalized guidance tapered inside r_c: G + (K/r_c) e + K_c e = 0.
    let rest = DRIFT / (c.k() / c.capture_radius + clamp.kc);
    assert!(
        (s.final_error - rest).abs() < 0.005,
        "{} vs {rest}",
        s.final_error
    );
    let unclamped = summary_of(&world("room-drift.toml", &[]));
    assert!(s.final_error < unclamped.final_error - 0.1);

    // Trapped: once inside σ it never leaves.
    let first = states
        .iter()
        .position(|(_, a)| a.distance < clamp.sigma)
        .unwrap();
    let after = &states[first..];
    assert!(after.iter().all(|(_, a)| a.distance < clamp.sigma));
    // No oscillation: the body arrives fast (about 7 m/s), overshoots the target once and then
    // closes on its rest point without ever moving away from it again by more than 2 cm.
    let rest_point = after.last().unwrap().1.position;
    let to_rest: Vec<f64> = after
        .iter()
        .map(|(_, a)| (a.position - rest_point).norm())
        .collect();
    let peak = to_rest
        .iter()
        .enumerate()
        .skip(1)
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i);
    let mut lowest = f64::INFINITY;
    for &d in &to_rest[peak..] {
        lowest = lowest.min(d);
        assert!(
            d <= lowest + 0.02,
            "moved away from the rest point again: {d} after {lowest}"
        );
    }
    // The clamp shows in the state: active while it holds the body at the end.
    assert!(states.last().unwrap().1.clamping);
}

#[test]
fn the_bias_removes_the_offset_the_clamp_leaves() {
    let (states, s) = trace(&world("room-drift-bias.toml", &[]));
    assert_eq!(s.contacts, 0, "{s:?}");
    assert!(s.final_error < 0.01, "{s:?}");
    // β converged to the holding force against the drift, −G = [4, 4] N.
    let beta = states.last().unwrap().1.beta.unwrap();
    assert!(
        (beta.x - 4.0).abs() < 0.05 && (beta.y - 4.0).abs() < 0.05,
        "{beta}"
    );
    let updates: Vec<_> = states.iter().filter(|(_, a)| !a.notes.is_empty()).collect();
    assert!(
        !updates.is_empty() && updates.len() <= 3,
        "{}",
        updates.len()
    );
    assert!(
        updates[0].1.notes[0].contains("β ← holding force"),
        "{:?}",
        updates[0].1.notes
    );
}

#[test]
fn sliding_mode_at_the_same_settling_time_chatters_far_more_than_nadf_with_clamping() {
    let sliding = summary_of(&world("room-drift-sliding.toml", &[]));
    let nadf = summary_of(&world("room-drift-clamp.toml", &[]));
    assert_eq!((sliding.contacts, nadf.contacts), (0, 0));
    let (ts, tn) = (sliding.settling_time.unwrap(), nadf.settling_time.unwrap());
    assert!((ts - tn).abs() < 0.25 * tn, "sliding {ts} s, NADF {tn} s");
    assert!(
        sliding.control_variation >= 10.0 * nadf.control_variation,
        "sliding {} N, NADF {} N",
        sliding.control_variation,
        nadf.control_variation
    );
}

#[test]
fn with_sensor_noise_it_still_reaches_without_contact_and_the_seed_fixes_the_run() {
    let w = world("room-drift-noise.toml", &[]);
    let (states, s) = trace(&w);
    assert_eq!(s.contacts, 0, "{s:?}");
    assert!(s.reached && s.final_error < 0.5, "{s:?}");
    // The sensor really read the walls, ten times a second, differently each time.
    let readings: Vec<_> = states
        .iter()
        .filter_map(|(_, a)| a.sensed_walls.as_ref())
        .collect();
    assert!(
        readings.len() >= (w.duration * 10.0) as usize - 1,
        "{}",
        readings.len()
    );
    assert!(readings.windows(2).any(|p| p[0] != p[1]));
    // Same seed, same run; another seed, another run.
    assert_eq!(summary_of(&w), s);
    let other = summary_of(&world("room-drift-noise.toml", &["seed=1"]));
    assert_ne!(other, s);
    assert_eq!(other.contacts, 0, "{other:?}");
}

#[test]
fn a_guidance_too_weak_for_the_drift_is_warned_about() {
    let w = world("room-drift.toml", &["agents.0.controller.k=5"]);
    let warnings = nadf::world::settings_warnings(&w);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert_eq!(warnings[0].0, "agents.0.controller.k");
    assert!(warnings[0].1.contains("condition 40"), "{warnings:?}");
    for name in [
        "room-drift.toml",
        "room-drift-clamp.toml",
        "room-drift-sliding.toml",
        "room-drift-noise.toml",
    ] {
        assert!(
            nadf::world::settings_warnings(&world(name, &[])).is_empty(),
            "{name}"
        );
    }
    let w = world("room-drift-sliding.toml", &["agents.0.controller.f0=5"]);
    assert_eq!(
        nadf::world::settings_warnings(&w)[0].0,
        "agents.0.controller.f0"
    );
}
