//! Steps a world from Rust and follows its first agent: once per simulated second, where it
//! is, how far it still has to go, how fast it moves and how close it passes to the walls.
//!
//! ```sh
//! cargo run --release --example follow [WORLD.toml]
//! ```

use std::path::PathBuf;

use nadf::sim::Simulation;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The world file: the paper's room with two dividers unless one is given.
    let path = std::env::args_os().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml"),
        PathBuf::from,
    );
    let world = nadf::world::load(&path, &[])?;

    // Solves every agent's harmonic field and builds the Rapier world.
    let mut sim = Simulation::new(&world)?;
    let agent = &world.agents[0];
    println!(
        "{} heads from {:?} to {:?}",
        agent.name, agent.start, agent.target
    );
    println!(
        "{:>6} {:>16} {:>10} {:>9} {:>11}",
        "t (s)", "position (m)", "to go (m)", "v (m/s)", "clear (m)"
    );

    // One physics step at a time: the controller reads the field, Rapier moves the body.
    let steps_per_second = (1.0 / world.dt).round() as usize;
    let mut closest_to_a_wall = f64::INFINITY;
    let mut step = 0;
    while !sim.finished() {
        let state = &sim.step()[0];
        step += 1;
        closest_to_a_wall = closest_to_a_wall.min(state.clearance);
        if !state.contact_points.is_empty() {
            println!(
                "t = {:.2} s: touching a wall at {:?}",
                sim.time(),
                state.contact_points
            );
        }
        if step % steps_per_second == 0 {
            let p = state.position;
            println!(
                "{:>6.1} {:>16} {:>10.3} {:>9.3} {:>11.3}",
                sim.time(),
                format!("({:.2}, {:.2})", p.x, p.y),
                state.distance,
                state.velocity.norm(),
                state.clearance
            );
        }
    }

    // The same summary `nadf run` prints.
    let summary = &sim.summaries()[0];
    println!(
        "reached: {}, settling time: {:?} s, contacts: {}, closest to a wall: {closest_to_a_wall:.3} m",
        summary.reached, summary.settling_time, summary.contacts
    );
    Ok(())
}
