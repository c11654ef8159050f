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

/// The nested levels compose one field: at every reachable cell but the target disc's, `W` is the
/// average of its four neighbours to a relative 1e-5, at whatever depth, across the seams
/// between the levels' bands.
#[test]
fn the_maze_field_is_harmonic_at_every_cell_across_the_levels() {
    let world = common::world("maze.toml", &[]);
    let agent = &world.agents[0];
    let field = HarmonicField::solve(&world, agent).unwrap();
    let grid = *field.grid();
    let w = field.sampler.values();
    let reachable = field.sampler.reachable_cells();
    // The target disc (V = 0 there, see `FreeSpace::target_cells`) is not solved for.
    let in_disc = |i: usize, j: usize| {
        let [x, y] = grid.center(i, j);
        (x - agent.target[0]).hypot(y - agent.target[1]) <= field.target_radius + 0.5 * grid.cell
    };
    let mut worst: f64 = 0.0;
    let mut deepest = f64::INFINITY;
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            let k = grid.index(i, j);
            if !reachable[k] || in_disc(i, j) {
                continue;
            }
            let e = w.exponent[k];
            let sum: f64 = grid
                .neighbours(i, j)
                .map(|(a, b)| w.at_scale(grid.index(a, b), e))
                .sum();
            worst = worst.max((4.0 * w.mantissa[k] - sum).abs() / (4.0 * w.mantissa[k]));
            deepest = deepest.min(w.log10(k));
        }
    }
    assert!(worst < 1e-5, "largest relative residual {worst:e}");
    // Measured: −119.2 (the path runs 94 m through corridors 1.2 m wide).
    assert!(deepest < -110.0, "deepest log10 W {deepest}");
}
