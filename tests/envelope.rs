//! Never a touch (issue "never a touch"): the clearance envelope keeps bodies off the walls
//! and off each other at any `dt`, and a touch is always counted.

mod common;

use std::fmt::Write;
use std::path::Path;

use nadf::run::{RunOptions, run};
use nadf::sim::CONTACT_TOLERANCE;
use nadf::world::{World, load_str};

fn world_of(text: &str, overrides: &[&str]) -> World {
    let overrides: Vec<_> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    load_str(text, Path::new("w.toml"), &overrides).unwrap_or_else(|e| panic!("{e}"))
}

/// A robot that crosses a 12 m room at 4.4 m/s to a target 0.4 m from the far wall: NADF
/// damps its overshoot within about m·v/B_d = 0.44 m, so it reaches the wall.
const ARRIVAL: &str = r#"
name = "arrival"
size = [12.0, 4.0]
walls_around = true
duration = 12.0

[[agents]]
name = "robot"
start = [1.5, 2.0]
target = [11.2, 2.0]
radius = 0.3

[agents.controller]
kind = "nadf"
b = 10.0
"#;

/// The arrival that overshoots into the wall: bare, it touches and the touch is counted; under
/// the envelope it arrives as fast and touches nothing.
#[test]
fn an_arrival_that_overshoots_into_a_wall_counts_its_touch_and_the_envelope_prevents_it() {
    let bare = common::summary_of(&world_of(ARRIVAL, &["agents.0.controller.envelope=false"]));
    assert!(bare.contacts >= 1, "{bare:?}");
    assert!(
        bare.min_clearance.is_some_and(|c| c < CONTACT_TOLERANCE),
        "{bare:?}"
    );
    let kept = common::summary_of(&world_of(ARRIVAL, &[]));
    assert!(kept.reached && kept.contacts == 0, "{kept:?}");
    assert!(
        kept.min_clearance.is_some_and(|c| c > CONTACT_TOLERANCE),
        "{kept:?}"
    );
    assert!(kept.envelope_time > 0.0, "{kept:?}");
    // It costs nothing here: the envelope brakes only the overshoot.
    assert_eq!(kept.settling_time, bare.settling_time, "{kept:?} {bare:?}");
}

/// The rooms map's campaign run 134 (`experiments/campaign-rooms.toml`): the robot comes down a
/// room at 5.6 m/s to a one-cell door, where the envelope lets it slide past the door's corner
/// only at a few mm/s. With Rapier's positions in f32 (a 3e-5 m spacing 464 m from the origin)
/// moves that slow were rounded away and it stood 2.05 mm from the corner from 11.4 s to the
/// 240 s clock. Without the envelope it arrives at 50.1 s; under it, it must arrive as well,
/// untouched, at little cost.
#[test]
fn the_rooms_campaigns_run_134_passes_its_doors_corner() {
    let run_134 = [
        "agents.0.start=[132.7105708894717,496.81761255157346]",
        "agents.0.target=[124.65984130192665,322.50071128496944]",
        "agents.0.controller={kind=\"nadf\",b=10.0}",
        "duration=120",
    ];
    let s = common::summary("map-rooms.toml", &run_134);
    assert!(s.reached && s.contacts == 0, "{s:?}");
    assert!(
        s.min_clearance.is_some_and(|c| c > CONTACT_TOLERANCE),
        "{s:?}"
    );
    assert!(s.settling_time.is_some_and(|t| t < 65.0), "{s:?}");
}

/// A clearance at or below zero is always a contact, in the step it happens: Rapier's narrow
/// phase runs at the start of a step, so it sees where a step ended only in the next one (and
/// not at all after the last). The arena without either envelope overshoots its corner target
/// at 9 m/s into the walls; the run is cut at the first step that ends inside a wall.
#[test]
fn a_step_that_ends_inside_a_wall_is_a_contact_in_that_step() {
    let mut world = common::world("map-arena.toml", &["agents.0.controller.envelope=false"]);
    world.agents[0].controller.brake = None;
    let (states, _) = common::trace(&world);
    let (at, first) = states
        .iter()
        .find(|(_, s)| s.clearance == 0.0)
        .expect("it overshoots into the walls");
    assert!(!first.contact_points.is_empty(), "at {at} s: {first:?}");
    // Cut there, the run still counts it.
    world.duration = *at;
    let (states, summary) = common::trace(&world);
    assert_eq!(states.last().unwrap().1.clearance, 0.0);
    assert!(summary.contacts >= 1, "{summary:?}");
    assert!(
        summary.min_clearance.is_some_and(|c| c <= 0.0),
        "{summary:?}"
    );
}

/// The paper's figure 4, viscous B = 0.1, crashes bare; under the envelope (which brakes with
/// the same weak damping, stopping within 10·v) it touches nothing at a step 25 times longer
/// or 5 times shorter, and keeps its margin.
#[test]
fn weak_viscous_damping_touches_nothing_under_the_envelope_at_any_dt() {
    for dt in ["0.002", "0.01", "0.05"] {
        let world = common::world(
            "room-two-dividers-viscous.toml",
            &["agents.0.controller.envelope=true", &format!("dt={dt}")],
        );
        let s = common::summary_of(&world);
        assert_eq!(s.contacts, 0, "dt {dt}: {s:?}");
        assert!(
            s.min_clearance.is_some_and(|c| c > CONTACT_TOLERANCE),
            "dt {dt}: {s:?}"
        );
        assert!(s.envelope_time > 0.0, "dt {dt}: {s:?}");
        assert!(s.reached, "dt {dt}: {s:?}");
    }
}

/// An antipodal circle denser than any shipped one: `n` robots with `arc` metres of the circle
/// each (the shipped ones have 2.16 m), targets turned 0.05 rad from the antipode.
fn dense_circle(n: usize, arc: f64, controller: &str) -> String {
    let radius = n as f64 * arc / std::f64::consts::TAU;
    let size = 2.0 * radius + 2.4;
    let c = 0.5 * size;
    let mut text = format!(
        "name = \"dense\"\nsize = [{size}, {size}]\nduration = {}\n[field]\ncell = 0.1\nreplan_hz = 10.0\n",
        (2.0 * radius + 40.0).ceil()
    );
    for k in 0..n {
        let jitter = 2.0 * ((k as f64 * 0.618_033_988_749_895).fract() - 0.5);
        let a = std::f64::consts::TAU * k as f64 / n as f64 + 0.01 * jitter;
        let b = a + std::f64::consts::PI + 0.05;
        write!(
            text,
            "[[agents]]\nname = \"r{k:02}\"\nstart = [{}, {}]\ntarget = [{}, {}]\nradius = 0.3\n\
             controller = {{ {controller}, speed_limit = 2.0 }}\n",
            c + radius * a.cos(),
            c + radius * a.sin(),
            c + radius * b.cos(),
            c + radius * b.sin(),
        )
        .unwrap();
    }
    text
}

/// 32 robots with 1.2 m of arc each. Bare, NADF touches (measured: 6 contacts) and ORCA far
/// more (180); under the envelope neither touches, every ORCA robot arrives, and a NADF robot
/// that does not is reported deadlocked (measured: 31 of 32 arrive).
#[test]
fn a_dense_circle_touches_nothing_under_the_envelope() {
    let options = RunOptions::default();
    let orca = world_of(&dense_circle(32, 1.2, "kind = \"orca\""), &[]);
    let nadf = world_of(
        &dense_circle(32, 1.2, "kind = \"nadf\", k = 1.0, b = 10.0"),
        &[],
    );
    for (name, world) in [("orca", orca), ("nadf", nadf)] {
        let report = run(&world, &options).unwrap();
        for s in &report.agents {
            assert_eq!(s.contacts, 0, "{name}: {s:?}");
            assert!(
                s.min_separation.is_some_and(|d| d > CONTACT_TOLERANCE),
                "{name}: {s:?}"
            );
            assert!(s.reached || s.deadlocked.is_some(), "{name}: {s:?}");
        }
        let reached = report.agents.iter().filter(|s| s.reached).count();
        let least = if name == "orca" { 32 } else { 30 };
        assert!(reached >= least, "{name}: {reached} of 32 arrive");
    }
}
