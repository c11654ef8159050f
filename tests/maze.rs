//! The spiral maze: a field that a plain f64 `V` would leave flat still guides from everywhere.

mod common;

use nadf::field::HarmonicField;

#[test]
fn the_maze_is_flat_in_f64_v_yet_every_sampled_streamline_reaches_the_target() {
    let world = common::world("maze.toml", &[]);
    let agent = &world.agents[0];
    let field = HarmonicField::solve(&world, agent).unwrap();
    assert!(field.solves > 10, "{} solves", field.solves);

    // At the start, V = 1 - W is exactly 1 in f64: a solver of V would give no guidance here.
    let w = field.one_minus_potential(agent.start);
    assert!(w > 0.0 && 1.0 - w == 1.0, "W at the start is {w:e}");
    assert!(field.gradient(agent.start).is_some());

    // Streamlines from a dense sample of reachable cells all reach the target.
    let grid = *field.grid();
    let reachable = field.sampler.reachable_cells();
    let mut checked = 0;
    for j in (0..grid.ny).step_by(13) {
        for i in (0..grid.nx).step_by(13) {
            if !reachable[grid.index(i, j)] {
                continue;
            }
            let from = grid.center(i, j);
            let path = field.streamline_within(from, 300.0);
            assert!(
                path.reached,
                "the streamline from {from:?} stops at {:?}",
                path.points.last()
            );
            checked += 1;
        }
    }
    assert!(checked > 300, "only {checked} cells sampled");
}
