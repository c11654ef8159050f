//! Numerical faults never crash a run or put a NaN into Rapier: each is reported in the summary
//! (and logged as an event in the recording) instead.

mod common;

use std::path::PathBuf;

use nadf::metrics::Summary;
use nadf::run::{RunOptions, run};
use nadf::sim::Simulation;
use nadf::sim::faults::{FaultMonitor, Observation};
use nadf::world::{Override, load};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn run_file(path: &std::path::Path, overrides: &[&str], recording: Option<PathBuf>) -> Summary {
    let overrides: Vec<Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    let world = load(path, &overrides).unwrap();
    let options = RunOptions {
        recording,
        ..RunOptions::default()
    };
    let summary = run(&world, &options).unwrap().agents.remove(0);
    for value in [
        summary.final_error,
        summary.min_clearance.unwrap_or(0.0),
        summary.max_deviation,
        summary.path_length,
        summary.peak_force,
        summary.control_variation,
        summary.peak_speed,
    ] {
        assert!(value.is_finite(), "{summary:?}");
    }
    assert!(!summary.faults.non_finite_state, "{summary:?}");
    summary
}

#[test]
fn a_saddle_point_is_reported_as_lost_guidance() {
    let s = run_file(&fixture("saddle.toml"), &[], None);
    assert!(s.faults.guidance_lost_steps > 0, "{s:?}");
    assert_eq!(s.contacts, 0, "{s:?}");
}

/// A reversal of the guidance between two steps is a critical point only within one field:
/// across a re-solve the two directions are two fields' (a crowd's replanned field going round
/// a neighbour's other side), and that step is not counted.
#[test]
fn a_reversal_counts_within_one_field_not_across_a_resolve() {
    let world = load(&fixture("saddle.toml"), &[]).unwrap();
    let sim = Simulation::new(&world).unwrap();
    let field = &sim.agents[0].field;
    let at = |x: f64, replanned: bool| Observation {
        field,
        position: nalgebra::Vector2::new(x, 2.0),
        signed_clearance: 0.5,
        bounds: world.bounds(),
        giving_way: false,
        replanned,
    };
    // Along the axis the guidance points at the disc up to the saddle, away from it beyond.
    let towards = |x: f64| field.gradient([x, 2.0]).unwrap()[0] < 0.0;
    assert!(towards(1.0));
    let beyond = (0..60)
        .map(|k| 1.0 + 0.05 * k as f64)
        .find(|&x| !towards(x))
        .expect("a saddle in front of the disc");
    for (replanned, lost) in [(false, 1), (true, 0)] {
        let mut monitor = FaultMonitor::default();
        monitor.observe(&at(1.0, false));
        monitor.observe(&at(beyond + 0.1, replanned));
        assert_eq!(monitor.faults.guidance_lost_steps, lost, "at x = {beyond}");
    }
}

#[test]
fn a_body_leaving_the_box_is_reported_and_the_recording_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let rrd = dir.path().join("open-box.rrd");
    let s = run_file(&fixture("open-box.toml"), &[], Some(rrd.clone()));
    assert!(s.faults.left_box_steps > 0, "{s:?}");
    // Off the field there is no guidance: that is reported too.
    assert!(s.faults.guidance_lost_steps > 0, "{s:?}");

    let file = std::io::BufReader::new(std::fs::File::open(&rrd).unwrap());
    let events = re_log_encoding::DecoderApp::decode_eager(file)
        .unwrap()
        .filter_map(|m| match m.unwrap() {
            re_log_types::LogMsg::ArrowMsg(_, arrow) => {
                Some(re_chunk::Chunk::from_arrow_msg(&arrow).unwrap())
            }
            _ => None,
        })
        .filter(|c| c.entity_path().to_string() == "/agents/robot/events")
        .count();
    assert!(events > 0);
}

#[test]
fn a_force_beyond_f32_is_rejected_not_handed_to_rapier() {
    let world = common::world_path("room-two-dividers.toml");
    let s = run_file(&world, &["agents.0.controller.k=1e40", "duration=2"], None);
    assert_eq!(s.faults.rejected_forces, 200, "{s:?}");
    assert_eq!(s.peak_force, 0.0, "{s:?}");
}

#[test]
fn a_huge_force_slams_the_body_into_walls_without_pushing_it_through() {
    let world = common::world_path("room-two-dividers.toml");
    let s = run_file(
        &world,
        &[
            "agents.0.controller.kind=viscous",
            "agents.0.controller.b=0",
            "agents.0.controller.k=1e5",
            "duration=5",
        ],
        None,
    );
    assert!(s.contacts > 0, "{s:?}");
    assert_eq!(s.faults.left_box_steps, 0, "{s:?}");
    assert_eq!(s.faults.penetrations, 0, "{s:?}");
}

#[test]
fn the_monitor_counts_each_penetration_once_and_each_exit_from_the_box() {
    let world = load(&fixture("saddle.toml"), &[]).unwrap();
    let sim = Simulation::new(&world).unwrap();
    let field = &sim.agents[0].field;
    let mut monitor = FaultMonitor::default();
    let at = |x: f64, y: f64, signed_clearance: f64| Observation {
        field,
        position: nalgebra::Vector2::new(x, y),
        signed_clearance,
        bounds: world.bounds(),
        giving_way: false,
        replanned: false,
    };
    assert!(monitor.observe(&at(1.0, 1.0, 0.5)).is_empty());
    let events = monitor.observe(&at(3.2, 2.0, -0.05));
    assert!(
        events
            .iter()
            .any(|e| e.contains("pushed 0.050 m into a wall")),
        "{events:?}"
    );
    assert!(monitor.observe(&at(3.2, 2.0, -0.06)).is_empty());
    monitor.observe(&at(1.0, 1.0, 0.5));
    monitor.observe(&at(3.2, 2.0, -0.02));
    let events = monitor.observe(&at(-0.5, 2.0, 0.1));
    assert!(
        events.iter().any(|e| e.contains("left the box")),
        "{events:?}"
    );
    assert_eq!(monitor.faults.penetrations, 2);
    assert_eq!(monitor.faults.left_box_steps, 1);
}
