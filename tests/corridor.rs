//! The narrow corridor of the paper's §VI.6 under Khatib's attractive-repulsive potential:
//! viscous damping oscillates once an obstruction is in the way (B = 0.3) or crawls (B = 3); NADF
//! keeps going without oscillating, however large B_d; a barrier is braked for; noisy walls
//! never make NADF touch anything.

mod common;

use nadf::metrics::Summary;

fn corridor(world: &str, kind: &str, b: f64) -> Summary {
    common::summary(
        world,
        &[
            &format!("agents.0.controller.kind=\"{kind}\""),
            &format!("agents.0.controller.b={b}"),
            // The paper's laws bare: the clearance envelope is the sandbox's, not the paper's.
            "agents.0.controller.envelope=false",
        ],
    )
}

fn covered(s: &Summary) -> f64 {
    s.distance_covered
        .expect("the corridor worlds set distance_at")
}

#[test]
fn an_obstruction_makes_khatib_oscillate_under_viscous_damping_but_not_under_nadf() {
    let empty = corridor("corridor.toml", "viscous", 0.3);
    let light = corridor("corridor-obstruction.toml", "viscous", 0.3);
    let heavy = corridor("corridor-obstruction.toml", "viscous", 3.0);
    let nadf5 = corridor("corridor-obstruction.toml", "nadf", 5.0);
    let nadf30 = corridor("corridor-obstruction.toml", "nadf", 30.0);
    for s in [&empty, &light, &heavy, &nadf5, &nadf30] {
        eprintln!(
            "covered {:6.2} m  lateral rms {:.3} m/s  reversals {:2}  contacts {}",
            covered(s),
            s.lateral_speed_rms,
            s.lateral_reversals,
            s.contacts
        );
    }
    // The empty corridor: straight down the middle.
    assert_eq!(empty.lateral_reversals, 0, "{empty:?}");
    // B = 0.3: sideways oscillation once past the block (figure 38), about the paper's 25 m in
    // 10 s (measured 20.2 m). The corridor is 102 m long, so no run is capped by its target at
    // 10 s (NADF B_d = 5 would cover 50 m in it without the block).
    assert!(light.lateral_reversals >= 6, "{light:?}");
    assert!(
        light.lateral_speed_rms > 0.2 && light.lateral_speed_rms > 100.0 * empty.lateral_speed_rms,
        "{light:?}"
    );
    assert!((18.0..28.0).contains(&covered(&light)), "{light:?}");
    // B = 3: far slower (figure 39: 4 m in 10 s).
    assert!(covered(&heavy) < 0.5 * covered(&light), "{heavy:?}");
    // NADF B_d = 5: no sustained oscillation, and farther than B = 0.3 (figure 40). The paper
    // says more than twice as far; measured 26.4 m against 20.2 m (1.31×): NADF damps the
    // motion that climbs into the block's repulsion, and the body meets it at 3 m/s and
    // leaves it at 0.6 m/s (B_d = 30: 39.5 m, 1.96×).
    assert!(nadf5.lateral_reversals <= 3, "{nadf5:?}");
    assert!(
        nadf5.lateral_speed_rms < 0.5 * light.lateral_speed_rms,
        "{nadf5:?}"
    );
    assert!(covered(&nadf5) > covered(&light), "{nadf5:?}");
    // NADF B_d = 30: no slower (figure 41; measured 50 % farther).
    assert!(covered(&nadf30) >= 0.9 * covered(&nadf5), "{nadf30:?}");
    for s in [&nadf5, &nadf30] {
        assert_eq!(s.contacts, 0, "{s:?}");
        assert!(s.reached, "{s:?}");
    }
}

#[test]
fn nadf_never_touches_a_corridor_wall_with_or_without_noise() {
    for world in [
        "corridor",
        "corridor-obstruction",
        "corridor-barrier",
        "corridor-obstacles",
    ] {
        for b in [5.0, 30.0] {
            let s = corridor(&format!("{world}.toml"), "nadf", b);
            assert_eq!(s.contacts, 0, "{world} B_d = {b}: {s:?}");
        }
        for seed in 0..3 {
            let s = common::summary(&format!("{world}-noise.toml"), &[&format!("seed={seed}")]);
            assert_eq!(s.contacts, 0, "{world}-noise seed {seed}: {s:?}");
            assert!(
                s.min_clearance.is_some_and(|c| c > 0.1),
                "{world}-noise seed {seed}: {s:?}"
            );
        }
    }
}

#[test]
fn nadf_brakes_to_a_stop_before_a_barrier() {
    let world = common::world("corridor-barrier.toml", &[]);
    let (states, s) = common::trace(&world);
    assert_eq!(s.contacts, 0, "{s:?}");
    assert!(!s.reached, "{s:?}");
    assert!(s.final_speed < 0.01, "{s:?}");
    let end = states.last().unwrap().1.position;
    // Stopped short of the barrier's face (x = 19.9), by more than the robot's radius.
    assert!(end.x < 19.9 - 0.2, "{end}");
    // It was moving fast before it braked: an emergency stop, not a crawl.
    let fastest = states
        .iter()
        .map(|(_, a)| a.velocity.norm())
        .fold(0.0, f64::max);
    assert!(fastest > 3.0, "{fastest}");
}

/// The paper's B = 0.3 oscillation is "sustained" (figure 38). In the sandbox it decays: the
/// lateral RMS speed over the three thirds of a 60 s run is 0.45, 0.025 and 0.002 m/s (the body
/// reaches the target at about 40 s). The test states what is measured, and fails if the
/// oscillation stops decaying.
#[test]
fn the_viscous_oscillation_past_the_block_decays() {
    let world = common::world(
        "corridor-obstruction.toml",
        &[
            "agents.0.controller.kind=\"viscous\"",
            "agents.0.controller.b=0.3",
            "agents.0.controller.envelope=false",
            "duration=60",
        ],
    );
    let (states, s) = common::trace(&world);
    assert_eq!(s.contacts, 0, "{s:?}");
    let third = states.len() / 3;
    let rms = |part: &[(f64, nadf::sim::AgentState)]| {
        (part.iter().map(|(_, a)| a.velocity.y.powi(2)).sum::<f64>() / part.len() as f64).sqrt()
    };
    let (first, last) = (rms(&states[..third]), rms(&states[2 * third..]));
    assert!(first > 0.3, "{first}");
    assert!(last < 0.05 * first, "{first} then {last}");
}

/// Figure 42: "the travel distance is unaffected" by sensor noise. Without a force cap, walls
/// sensed up to 0.1 m off (10 Hz) and a position estimate up to 0.05 m off (10 Hz) both cover
/// over 95 % of the 50 m the noiseless robot covers in 10 s (measured 48.6 and 49.5 m). Walls
/// off by up to 0.5 m do not (5 m, with a 10 N cap; see the worlds' comments).
#[test]
fn moderate_sensor_noise_leaves_the_distance_unaffected_without_a_force_cap() {
    let clean = corridor("corridor.toml", "nadf", 30.0);
    for world in ["corridor-noise.toml", "corridor-position-noise.toml"] {
        let w = common::world(world, &[]);
        assert_eq!(w.agents[0].controller.max_force, None);
        let s = common::summary_of(&w);
        assert!(s.contacts == 0 && s.reached, "{world}: {s:?}");
        assert!(
            covered(&s) > 0.95 * covered(&clean),
            "{world}: {s:?} vs {clean:?}"
        );
    }
}
