//! The pendulum of the paper's §VI.8 on a Rapier revolute joint: the steady-state error the
//! weight leaves under `u = K e − B θ̇`, and its removal by the iterative bias (eq. 48–50,
//! figures 54–56).

mod common;

use nadf::run::{RunOptions, run};
use nadf::sim::pendulum::PendulumSummary;

fn pendulum(world: &str, overrides: &[&str]) -> PendulumSummary {
    let world = common::world(world, overrides);
    run(&world, &RunOptions::default())
        .unwrap()
        .pendulums
        .into_iter()
        .next()
        .unwrap()
}

#[test]
fn without_bias_the_weight_leaves_the_static_error() {
    for k in [20.0, 50.0, 200.0] {
        let p = pendulum("pendulum.toml", &[&format!("pendulums.0.controller.k={k}")]);
        let e = p.static_error.unwrap();
        // The exact rest point of u = K e - B θ̇ at θ_T = π/2: K e = M g L cos e.
        assert!((k * e - 9.81 * e.cos()).abs() < 1e-9, "{e}");
        // The simulated pendulum comes to rest there (Rapier's bob adds 0.1 % of inertia,
        // which moves no equilibrium).
        assert!((p.final_error - e).abs() < 1e-3, "K = {k}: {p:?}");
        assert!(p.bias_updates.is_empty());
        // For a small error, M g L sin θ_T / K.
        if k >= 200.0 {
            let small = 9.81 / k;
            assert!((p.final_error - small).abs() < 0.01 * small, "{p:?}");
        }
    }
}

#[test]
fn the_bias_removes_the_error_in_a_few_updates_for_several_thresholds() {
    // β is the torque measured while |θ̇| < α, damping torque included, so the error left
    // after the last update is up to B·α/K: K = 50 keeps it under 1 mrad for α up to 0.05.
    for alpha in [0.01, 0.02, 0.05] {
        let p = pendulum(
            "pendulum-bias.toml",
            &[
                "pendulums.0.controller.k=50",
                "pendulums.0.controller.b=8.5",
                &format!("pendulums.0.controller.bias.alpha={alpha}"),
            ],
        );
        eprintln!("α = {alpha}: {:?}", p.bias_updates);
        assert!(p.final_error.abs() < 1e-3, "α = {alpha}: {p:?}");
        assert!(
            (1..=4).contains(&p.bias_updates.len()),
            "α = {alpha}: {p:?}"
        );
        // The first update is made at the static error, and each one shrinks the error.
        let first = &p.bias_updates[0];
        assert!(
            (first.error - p.static_error.unwrap()).abs() < 0.01,
            "{p:?}"
        );
        for pair in p.bias_updates.windows(2) {
            assert!(pair[1].error.abs() < 0.2 * pair[0].error.abs(), "{p:?}");
        }
        // β converges to the weight's torque at θ_T = π/2: M g L.
        assert!(
            (p.bias_updates.last().unwrap().beta - 9.81).abs() < 0.1,
            "{p:?}"
        );
    }
}

#[test]
fn a_higher_gain_converges_in_fewer_updates() {
    let updates = |k: f64| {
        // About 0.6 of critical damping for each gain.
        let b = 1.2 * k.sqrt();
        let p = pendulum(
            "pendulum-bias.toml",
            &[
                &format!("pendulums.0.controller.k={k}"),
                &format!("pendulums.0.controller.b={b}"),
                "pendulums.0.controller.bias.alpha=0.02",
                "duration=30",
            ],
        );
        assert!(p.final_error.abs() < 2e-3, "K = {k}: {p:?}");
        p.bias_updates.len()
    };
    let (low, mid, high) = (updates(10.0), updates(20.0), updates(100.0));
    eprintln!("updates: K = 10: {low}, K = 20: {mid}, K = 100: {high}");
    assert!(low > mid && mid > high, "{low} {mid} {high}");
}
