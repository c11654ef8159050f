//! How to write your own collision assertion as a Rust test against the library: run a world
//! (here the narrow corridor with an obstruction, under NADF), then assert on the summary and
//! on every step's state. `cargo test --release --example collision_test` runs the tests below
//! (`cargo test` does too: `Cargo.toml` marks this example `test = true`); `cargo run --release
//! --example collision_test` prints what they check.

use std::path::{Path, PathBuf};

use nadf::run::{RunOptions, run};
use nadf::sim::Simulation;
use nadf::world::{World, load};

/// The corridor with an obstruction, with `--set`-style overrides.
fn corridor(overrides: &[&str]) -> World {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("worlds/corridor-obstruction.toml");
    let overrides: Vec<_> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    load(Path::new(&path), &overrides).unwrap_or_else(|e| panic!("{e}"))
}

/// The smallest clearance over every step, checked step by step rather than from the summary.
fn smallest_clearance(world: &World) -> f64 {
    let mut sim = Simulation::new(world).unwrap();
    let mut smallest = f64::INFINITY;
    while !sim.finished() {
        let state = &sim.step()[0];
        assert!(
            state.contact_points.is_empty(),
            "touched at t = {:.2} s",
            sim.time()
        );
        smallest = smallest.min(state.clearance);
    }
    smallest
}

fn main() {
    let world = corridor(&[]);
    let report = run(&world, &RunOptions::default()).unwrap();
    let robot = &report.agents[0];
    println!(
        "{}: contacts {}, min clearance {:.3} m, settling time {:?} s",
        world.name(),
        robot.contacts,
        robot.min_clearance.unwrap_or(f64::INFINITY),
        robot.settling_time
    );
    let first_ten = corridor(&["duration=10"]);
    println!(
        "closest to a wall in the first 10 s, step by step: {:.3} m",
        smallest_clearance(&first_ten)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nadf_passes_the_obstruction_without_touching_anything() {
        let world = corridor(&["duration=20"]);
        let robot = &run(&world, &RunOptions::default()).unwrap().agents[0];
        assert_eq!(robot.contacts, 0);
        assert!(
            robot.min_clearance.is_some_and(|c| c > 0.05),
            "{:?}",
            robot.min_clearance
        );
        assert!(robot.faults.is_clean(), "{:?}", robot.faults);
    }

    #[test]
    fn no_step_comes_within_five_centimetres_of_a_wall() {
        assert!(smallest_clearance(&corridor(&["duration=10"])) > 0.05);
    }
}
