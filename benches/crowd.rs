//! Crowds (`worlds/crowds/`, antipodal circles of robots replanning around each other at
//! 10 Hz): one replan of one robot 8 s into the 32-robot circle, local (the window and the
//! coarse window around it) and full (the whole field), in the 24 m room and in a 48 m room;
//! and one step of the whole crowd of 8 to 64 robots, 8 s into the run (the wall time of a
//! simulated second is 100 steps). Run with `cargo bench --bench crowd`.

use std::path::Path;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nadf::field::{Disc, HarmonicField};
use nadf::sim::Simulation;
use nadf::world::{World, load};

fn crowd(file: &str) -> World {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("worlds/crowds")
        .join(file);
    load(&path, &["duration=1000".parse().unwrap()]).unwrap()
}

/// The simulation `seconds` into the run.
fn after(world: &World, seconds: f64) -> Simulation {
    let mut sim = Simulation::new(world).unwrap();
    while sim.time() < seconds {
        sim.step();
    }
    sim
}

fn replan(c: &mut Criterion) {
    let mut group = c.benchmark_group("crowd-replan");
    group.sample_size(20);
    for (room, file) in [("24m", "circle-32.toml"), ("48m", "circle-32-room-48.toml")] {
        let world = crowd(file);
        let sim = after(&world, 8.0);
        let discs: Vec<Disc> = (sim.agents.iter())
            .map(|a| Disc {
                center: *a.metrics.path().last().unwrap(),
                radius: a.agent.radius,
            })
            .collect();
        let robot = &sim.agents[0];
        let position = discs[0].center;
        let others = &discs[1..];
        let field = robot.field.harmonic().unwrap();
        let walls = field.without_window();
        group.bench_function(BenchmarkId::new("local", room), |b| {
            b.iter(|| {
                walls
                    .with_window(&robot.agent, position, others, &world.field)
                    .unwrap()
            })
        });
        group.bench_function(BenchmarkId::new("full", room), |b| {
            b.iter(|| {
                HarmonicField::solve_among(&world, &robot.agent, position, &[], others, Some(field))
                    .unwrap()
            })
        });
    }
    group.finish();
}

fn step(c: &mut Criterion) {
    let mut group = c.benchmark_group("crowd-step");
    group.sample_size(10);
    for n in [8, 16, 32, 64] {
        let mut sim = after(&crowd(&format!("circle-{n}.toml")), 8.0);
        group.bench_function(BenchmarkId::from_parameter(n), |b| b.iter(|| sim.step()));
    }
    group.finish();
}

criterion_group!(benches, replan, step);
criterion_main!(benches);
