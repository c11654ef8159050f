//! Helpers shared by the integration tests.

#![allow(dead_code)]

use std::path::PathBuf;

use nadf::metrics::Summary;
use nadf::run::{RunOptions, run};
use nadf::world::{Override, World, load};

/// A file under `worlds/`.
pub fn world_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("worlds")
        .join(name)
}

/// Loads a world from `worlds/` with `--set`-style overrides.
pub fn world(name: &str, overrides: &[&str]) -> World {
    let overrides: Vec<Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    load(&world_path(name), &overrides).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs a world without recording and returns its first agent's summary.
pub fn summary(name: &str, overrides: &[&str]) -> Summary {
    let report = run(&world(name, overrides), &RunOptions::default()).unwrap();
    report.agents.into_iter().next().unwrap()
}

/// The errors loading `text` (as `w.toml`, with `--set`-style overrides) reports, as printed.
pub fn load_errors(text: &str, overrides: &[&str]) -> String {
    let overrides: Vec<Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    nadf::world::load_str(text, std::path::Path::new("w.toml"), &overrides)
        .unwrap_err()
        .to_string()
}

/// The path of the built `nadf` binary.
pub fn nadf_bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_nadf"))
}

/// Asserts that a run of the binary succeeded, showing its standard error if not.
pub fn assert_success(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Runs a world already loaded (and perhaps edited) and returns its first agent's summary.
pub fn summary_of(world: &World) -> Summary {
    let report = run(world, &RunOptions::default()).unwrap();
    report.agents.into_iter().next().unwrap()
}

/// Runs a world step by step and returns its first agent's state after every step, with the
/// time, and the final summary.
pub fn trace(world: &World) -> (Vec<(f64, nadf::sim::AgentState)>, Summary) {
    let mut sim = nadf::sim::Simulation::new(world).unwrap();
    let mut states = Vec::with_capacity(world.steps());
    while !sim.finished() {
        let state = sim.step().into_iter().next().unwrap();
        states.push((sim.time(), state));
    }
    let summary = sim.summaries().into_iter().next().unwrap();
    (states, summary)
}
