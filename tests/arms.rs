//! Arms (issue 27): planar links on Rapier's revolute multibody joints, planned in joint space
//! and steered by NADF with their own inertia `D(q)`; and the located errors of bad arms.

mod common;

use nadf::run::{RunOptions, run};
use nadf::sim::Simulation;

/// The two-link arm reaches round the post: its tip ends within the target disc, no link
/// touches anything, and the recording-free run's summary says so.
#[test]
fn a_two_link_arm_reaches_round_a_post() {
    let report = run(&common::world("arm-post.toml", &[]), &RunOptions::default()).unwrap();
    let arm = &report.arms[0];
    assert!(arm.reached && arm.contacts == 0, "{arm:?}");
    assert!(
        arm.final_tip_error < 0.05 && arm.min_clearance > 0.0,
        "{arm:?}"
    );
    assert!(arm.settling_time.is_some_and(|t| t < 5.0), "{arm:?}");
    assert_eq!(
        report.fields[0].joints.as_ref().map(|j| j.0.clone()),
        Some(vec![256, 256])
    );
    assert!(report.to_json().contains("\"arms\""));
}

/// The three-link arm reaches into the shelf, its last links level in the slot, touching
/// nothing (a 128³ joint space).
#[test]
fn a_three_link_arm_reaches_into_a_shelf() {
    let report = run(
        &common::world("arm-shelf.toml", &[]),
        &RunOptions::default(),
    )
    .unwrap();
    let arm = &report.arms[0];
    assert!(arm.reached && arm.contacts == 0, "{arm:?}");
    assert!(
        arm.final_tip_error < 0.06 && arm.min_clearance > 0.0,
        "{arm:?}"
    );
    assert_eq!(
        report.fields[0].joints.as_ref().map(|j| j.0.clone()),
        Some(vec![128; 3])
    );
}

/// A point the arm could reach in free space but not among the walls (a closed box around it)
/// is intractable before anything is simulated.
#[test]
fn a_target_the_arm_cannot_reach_is_intractable() {
    let world = common::world(
        "arm-post.toml",
        &[
            "walls.0.center=[2.6, 3.3]",
            "walls.0.radius=0.3",
            "arms.0.target_point=[2.6, 3.3]",
        ],
    );
    let error = match Simulation::new(&world) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("the arm reached into a wall"),
    };
    assert!(error.contains("arm") && error.contains("target"), "{error}");
}

const ARM: &str = r#"size = [4.0, 4.0]

[[arms]]
name = "arm"
base = [2.0, 2.0]
start = [0.0, 0.5]
target_point = [2.5, 3.0]

[[arms.links]]
length = 1.0

[[arms.links]]
length = 0.8
limits = [-2.0, 2.0]

[arms.controller]
kind = "nadf"
b = 5.0
"#;

/// Each bad arm is an error at its line, naming what is wrong.
#[test]
fn bad_arms_are_located_errors() {
    let cases: [(&[&str], &str, &str); 8] = [
        (
            &["arms.0.links.0.length=-1"],
            "arms.0.links.0.length",
            "positive",
        ),
        (
            &["arms.0.links.1.radius=0"],
            "arms.0.links.1.radius",
            "positive",
        ),
        (
            &["arms.0.links.1.limits=[1.0, 0.5]"],
            "arms.0.links.1.limits",
            "min < max",
        ),
        (
            &["arms.0.start=[0.0, 2.5]"],
            "arms.0.start",
            "outside its limits",
        ),
        (
            &["arms.0.target_point=[5.0, 2.0]"],
            "arms.0.target_point",
            "out of the arm's reach",
        ),
        (
            &["arms.0.target_joints=[0.1, 0.2]"],
            "arms.0.target_joints",
            "exactly one",
        ),
        (
            &["arms.0.start=[0.0]"],
            "arms.0.start",
            "expected 2 joint angles",
        ),
        (&["arms.0.cells=7"], "arms.0.cells", "even"),
    ];
    for (sets, key, what) in cases {
        let e = common::load_errors(ARM, sets);
        assert!(e.contains(key) && e.contains(what), "{sets:?}: {e}");
    }
    let e = common::load_errors(&ARM.replace("target_point = [2.5, 3.0]\n", ""), &[]);
    assert!(e.contains("w.toml:") && e.contains("exactly one"), "{e}");
    let one = ARM.replace("[[arms.links]]\nlength = 0.8\nlimits = [-2.0, 2.0]\n", "");
    let e = common::load_errors(&one, &["arms.0.start=[0.0]"]);
    assert!(e.contains("arms.0.links") && e.contains("pendulums"), "{e}");
    // A start over a wall names it.
    let walled = ARM.replace(
        "[[arms]]",
        "[[walls]]\nshape = \"disc\"\ncenter = [2.5, 2.0]\nradius = 0.1\n\n[[arms]]",
    );
    let e = common::load_errors(&walled, &[]);
    assert!(e.contains("arms.0.start") && e.contains("walls.0"), "{e}");
}
