//! Shaped agents (issue 26): bodies of convex polygons planned in (x, y, θ) with a harmonic
//! field, steered by NADF in position and heading, on the shipped worlds; Proposition 1's energy
//! in the metric `(x, y, ρθ)`; and the located errors of bad shapes.

mod common;

use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

use nadf::field::angle_difference;
use nadf::run::{RunOptions, run};
use nadf::sim::Simulation;
use nadf::sim::shaped::ShapedSummary;
use nadf::world::{Override, World, load_str};

/// Runs `world` step by step: the first shaped agent's heading after every step, and its
/// summary.
fn headings(world: &World) -> (Vec<f64>, ShapedSummary) {
    let mut sim = Simulation::new(world).unwrap();
    let mut headings = Vec::new();
    while !sim.finished() {
        sim.step();
        headings.push(sim.shaped[0].state().pose[2]);
    }
    (headings, sim.shaped_summaries().remove(0))
}

fn assert_clean(s: &ShapedSummary) {
    let d = &s.summary;
    assert!(d.reached, "{s:?}");
    assert_eq!(d.contacts, 0, "{s:?}");
    assert!(d.min_clearance.is_some_and(|c| c > 0.0), "{s:?}");
    assert!(d.faults.is_clean(), "{s:?}");
}

/// The piano mover: the board goes round the corner only by turning a quarter turn, never
/// touching the corridor's walls; its enclosing disc cannot even be placed in the corridor.
#[test]
fn the_board_turns_the_corner_of_the_l_without_a_touch() {
    let world = common::world("piano-mover.toml", &[]);
    let (headings, s) = headings(&world);
    assert_clean(&s);
    // It ends standing in the vertical arm (the corridor is narrower than the board is long).
    let turned = angle_difference(s.final_heading, FRAC_PI_2).abs();
    let turned_back = angle_difference(s.final_heading, -FRAC_PI_2).abs();
    assert!(turned.min(turned_back) < 0.05, "{s:?}");
    // It turned while it went round: half-way through the run it is still lying along x,
    // then the heading passes π/4 at some step.
    assert!(headings.iter().any(|h| (h.abs() - PI / 4.0).abs() < 0.05));
    assert!(s.summary.settling_time.is_some_and(|t| t < 20.0), "{s:?}");
    // The board's enclosing disc (half its diagonal: 0.752 m) does not fit.
    let disc = common::world_path("piano-mover.toml");
    let text = std::fs::read_to_string(&disc).unwrap();
    let sets: Vec<Override> = ["agents.0.shape.kind=disc", "agents.0.radius=0.752"]
        .iter()
        .map(|o| o.parse().unwrap())
        .collect();
    let error = load_str(&text, &disc, &sets).unwrap_err().to_string();
    assert!(
        error.contains("agents.0.start") && error.contains("disc (radius 0.752 m)"),
        "{error}"
    );
}

/// The couch reaches its target heading after turning to pass the door lengthwise.
#[test]
fn the_couch_turns_through_the_door_and_back_to_its_target_heading() {
    let world = common::world("couch-door.toml", &[]);
    let (headings, s) = headings(&world);
    assert_clean(&s);
    assert!(s.heading_error.is_some_and(|e| e.abs() < 0.05), "{s:?}");
    // The speed limit holds in the metric, |q̇|² = |v|² + ρ²ω², so on the centroid's speed too.
    assert!(s.summary.peak_speed <= 0.5 + 1e-3, "{s:?}");
    // Through the door it lay along x (heading 0 or π, within 0.3 rad); it started and ends
    // across.
    let lengthwise = |h: f64| {
        angle_difference(h, 0.0)
            .abs()
            .min(angle_difference(h, PI).abs())
    };
    let closest = headings
        .iter()
        .map(|&h| lengthwise(h))
        .fold(f64::INFINITY, f64::min);
    assert!(
        closest < 0.3,
        "the couch never turned lengthwise: {closest}"
    );
}

/// A box robot crosses the paper's room (2.6 million cells of (x, y, θ)); the L among clutter
/// reaches its target heading.
#[test]
fn a_box_crosses_the_paper_room_and_an_l_the_clutter() {
    let report = run(&common::world("box-room.toml", &[]), &RunOptions::default()).unwrap();
    let s = &report.shaped[0];
    assert_clean(s);
    assert!(report.agents.is_empty());
    let f = &report.fields[0];
    assert_eq!((f.cells, f.headings.map(|h| h.0)), ([201, 201], Some(64)));
    let (_, s) = headings(&common::world("compound-clutter.toml", &[]));
    assert_clean(&s);
    assert!(s.heading_error.is_some_and(|e| e.abs() < 0.05), "{s:?}");
}

/// The same world twice gives the same run, to the bit (the solver's parallel passes included).
#[test]
fn a_shaped_run_is_deterministic() {
    let world = common::world("couch-door.toml", &["duration=4"]);
    let a = run(&world, &RunOptions::default()).unwrap().to_json();
    let b = run(&world, &RunOptions::default()).unwrap().to_json();
    assert_eq!(a, b);
    assert!(
        a.contains("\"shaped\"") && a.contains("\"heading_error\""),
        "{a}"
    );
}

/// Proposition 1 in (x, y, θ): with the paper's `F = −K∇V` in the metric `q = (x, y, ρθ)`,
/// where `D = diag(m, m, I) = m I₃`, NADF never lets `K·V + ½ m |v|² + ½ I ω²` grow outside the
/// target's rim (beyond integration error), and the body reaches the target pose.
#[test]
fn the_energy_of_a_shaped_body_never_increases() {
    let text = r#"
        size = [4.0, 4.0]
        dt = 0.005
        duration = 25.0
        [field]
        cell = 0.05
        headings = 48
        guidance = "gradient"
        [[agents]]
        name = "slab"
        start = [1.0, 1.0]
        heading = 0.0
        target = [3.0, 2.5]
        target_heading = 1.5707963
        target_radius = 0.3
        mass = 1.0
        [agents.shape]
        kind = "box"
        half_extents = [0.3, 0.1]
        [agents.controller]
        kind = "nadf"
        k = 20.0
        b = 10.0
    "#;
    let world = load_str(text, Path::new("energy.toml"), &[]).unwrap();
    let agent = &world.shaped[0];
    let k = agent.controller.k();
    let mut sim = Simulation::new(&world).unwrap();
    let (m, inertia, rim) = {
        let run = &sim.shaped[0];
        (run.agent.mass, run.inertia, run.field.rim())
    };
    let energy = |sim: &Simulation| {
        let run = &sim.shaped[0];
        let s = run.state();
        let offset = run.field.offset(s.pose).norm();
        let e = k * run.field.potential(s.pose)
            + 0.5 * m * s.velocity.norm_squared()
            + 0.5 * inertia * s.angular_velocity.powi(2);
        (e, offset)
    };
    let (energy0, _) = energy(&sim);
    let mut last = energy(&sim);
    let (mut checked, mut worst) = (0, 0.0_f64);
    while !sim.finished() {
        sim.step();
        let now = energy(&sim);
        if now.1 > rim && last.1 > rim {
            worst = worst.max(now.0 - last.0);
            checked += 1;
        }
        last = now;
    }
    let s = &sim.shaped_summaries()[0];
    assert!(s.summary.reached && s.summary.contacts == 0, "{s:?}");
    assert!(s.heading_error.is_some_and(|e| e.abs() < 0.05), "{s:?}");
    println!("{checked} steps checked, largest rise {worst:e} of {energy0}");
    assert!(checked > 200, "only {checked} steps checked");
    assert!(
        worst <= 1e-5 * energy0,
        "the energy grew by {worst} in a step (of {energy0})"
    );
    assert!(last.0 < 0.01 * energy0, "{} of {energy0} left", last.0);
}

const SHAPED: &str = r#"size = [4.0, 3.0]

[field]
headings = 32

[[agents]]
name = "r"
start = [1.0, 1.0]
target = [3.0, 2.0]

[agents.shape]
kind = "polygon"
points = [[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]

[agents.controller]
kind = "nadf"
b = 5.0
"#;

/// Each bad shape or pose is an error at its line, naming what is wrong.
#[test]
fn bad_shapes_and_poses_are_located_errors() {
    let points =
        |p: &str| SHAPED.replace("[[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]", p);
    let cases = [
        (
            points("[[0.0, 0.0], [1.0, 0.0]]"),
            "w.toml:13:",
            "at least 3",
        ),
        (
            points("[[-0.3, -0.2], [-0.3, 0.2], [0.3, 0.2], [0.3, -0.2]]"),
            "w.toml:13:",
            "counter-clockwise",
        ),
        (
            points("[[-0.3, -0.2], [0.3, -0.2], [0.0, 0.0], [0.3, 0.2], [-0.3, 0.2]]"),
            "w.toml:13:",
            "convex",
        ),
        (
            points("[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]"),
            "w.toml:13:",
            "zero area",
        ),
        (
            SHAPED.replace("headings = 32", "headings = 7"),
            "w.toml:4:",
            "even",
        ),
        (
            SHAPED.replace("headings = 32", "headings = 6"),
            "w.toml:4:",
            "at least 8",
        ),
        (
            SHAPED.replace("start = [1.0, 1.0]", "start = [1.0, 0.1]"),
            "w.toml:8:",
            "outside the box",
        ),
        (
            SHAPED.replace(
                "target = [3.0, 2.0]",
                "target = [3.0, 2.0]\ntarget_heading = nan",
            ),
            "w.toml:10:",
            "finite",
        ),
    ];
    for (text, at, what) in cases {
        let e = common::load_errors(&text, &[]);
        assert!(e.contains(at) && e.contains(what), "{what}: {e}");
    }
    // A start over a wall names the wall.
    let walled = SHAPED.replace(
        "[[agents]]",
        "[[walls]]\nshape = \"disc\"\ncenter = [1.2, 1.2]\nradius = 0.1\n\n[[agents]]",
    );
    let e = common::load_errors(&walled, &[]);
    assert!(e.contains("agents.0.start") && e.contains("walls.0"), "{e}");
    // More (x, y, θ) cells than allowed.
    let e = common::load_errors(SHAPED, &["field.max_cells=100000"]);
    assert!(
        e.contains("field.headings") && e.contains("max_cells"),
        "{e}"
    );
    // A heading for a disc.
    let disc = SHAPED.replace("kind = \"polygon\"", "kind = \"disc\"");
    let disc = disc.replace(
        "points = [[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]\n",
        "",
    );
    let e = common::load_errors(&disc, &["agents.0.target_heading=1.0"]);
    assert!(e.contains("target_heading") && e.contains("disc"), "{e}");
    // What a shaped agent does not have yet.
    let e = common::load_errors(SHAPED, &["agents.0.controller.kind=orca"]);
    assert!(
        e.contains("agents.0.controller.kind") && e.contains("shaped"),
        "{e}"
    );
}

/// An intractable pose task is found before anything is solved, and says so.
#[test]
fn a_shape_that_cannot_pass_is_intractable() {
    // A 1.9 m board cannot turn the corner of the L: a board 0.1 m wide must be shorter than
    // 2√2 · 0.7 − 0.2 = 1.78 m.
    let world = common::world(
        "piano-mover.toml",
        &[
            "agents.0.shape.half_extents=[0.95, 0.05]",
            "agents.0.start=[1.2, 0.45]",
            "agents.0.target=[3.55, 2.9]",
        ],
    );
    let error = match Simulation::new(&world) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a 1.9 m board passed the corner"),
    };
    assert!(error.contains("intractable"), "{error}");
}
