//! Proposition 1 (eq. 13, 19): with the paper's own guidance `F = -K ∇V`, no external force and
//! no speed limit, NADF never lets `Ξ = K·V + ½ m |v|²` grow beyond integration error.

mod common;

use nadf::sim::Simulation;

#[test]
fn nadf_energy_never_increases_with_gradient_guidance() {
    let world = common::world("open-room-gradient.toml", &[]);
    let agent = &world.agents[0];
    let (k, m) = (agent.controller.k(), agent.mass);
    let mut sim = Simulation::new(&world).unwrap();
    // Within the rim of the target disc the guidance is the bowl that brings the body to the
    // target point, not −K∇V of the harmonic field (V = 0 on the disc).
    let rim = sim.agents[0].field.harmonic().unwrap().rim();
    let energy0 = k * sim.agents[0].field.potential(agent.start);
    let mut last = (energy0, f64::INFINITY);
    let mut checked = 0;
    while !sim.finished() {
        let state = sim.step().remove(0);
        let energy = k * state.potential + 0.5 * m * state.velocity.norm_squared();
        // The proposition is checked on every step that starts and ends outside the disc's rim.
        if state.distance > rim && last.1 > rim {
            assert!(
                energy <= last.0 + 1e-4,
                "Ξ grew from {} to {energy} at t = {}",
                last.0,
                sim.time()
            );
            checked += 1;
        }
        last = (energy, state.distance);
    }
    let summary = &sim.summaries()[0];
    assert!(summary.reached && summary.contacts == 0, "{summary:?}");
    assert!(checked > 200, "only {checked} steps checked");
    assert!(
        last.0 < 0.01 * energy0,
        "Ξ went from {energy0} to {}",
        last.0
    );
}
