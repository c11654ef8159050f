//! The iterative bias converges for every settling threshold α (eq. 50 iterated, paper figure
//! 55; issue "the paper's own law", item 4): on the drift world and on the pendulum the error
//! left is below 1 mm and 1 mrad for α from 0.01 to 0.5, in a few updates, which the summary
//! reports.

mod common;

use nadf::run::{RunOptions, run};

const ALPHAS: [f64; 4] = [0.01, 0.05, 0.2, 0.5];

#[test]
fn the_drift_world_ends_within_a_millimetre_for_every_alpha() {
    for alpha in ALPHAS {
        let s = common::summary(
            "room-drift-bias.toml",
            &[&format!("agents.0.controller.bias.alpha={alpha}")],
        );
        // Measured: 0.52–0.53 mm for every α, the floor the one-cell target of the 5 cm grid
        // leaves (the room without drift ends 0.53 mm off too). Before the holding force was
        // measured over the dwell and re-measured while slow: 2.5, 0.98, 9.1 and 13 mm.
        assert!(s.final_error < 1e-3, "α = {alpha}: {s:?}");
        assert!(
            s.contacts == 0 && (1..=4).contains(&s.bias_updates),
            "α = {alpha}: {s:?}"
        );
    }
}

#[test]
fn the_pendulum_ends_within_a_milliradian_for_every_alpha() {
    for alpha in ALPHAS {
        let world = common::world(
            "pendulum-bias.toml",
            &[&format!("pendulums.0.controller.bias.alpha={alpha}")],
        );
        let p = run(&world, &RunOptions::default())
            .unwrap()
            .pendulums
            .remove(0);
        // Measured: 1–5 µrad in 3–4 updates (before, with one sample of the control per
        // rest: 0.45, 0.39, 8.8 and 6.5 mrad).
        assert!(p.final_error.abs() < 1e-3, "α = {alpha}: {p:?}");
        assert!(
            (1..=6).contains(&p.bias_updates.len()),
            "α = {alpha}: {p:?}"
        );
        // β ends at the weight's torque at θ_T = π/2, M g L = 9.81 N·m.
        assert!(
            (p.bias_updates.last().unwrap().beta - 9.81).abs() < 0.01,
            "{p:?}"
        );
    }
}
