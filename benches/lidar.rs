//! Unknown worlds on the spiral maze (`worlds/unknown-maze.toml`, 360 rays of 3 m at 10 Hz): one
//! lidar scan and one re-solve of the field on the map built so far (warm-started from the
//! field one scan before, as the run does it), 20 s into the run; and the first 10 s of the
//! run, which must take less than 10 s (faster than real time).
//! Run with `cargo bench --bench lidar`.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use nadf::field::HarmonicField;
use nadf::sim::Simulation;
use nadf::world::{World, load};

fn maze(duration: f64) -> World {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/unknown-maze.toml");
    load(&path, &[format!("duration={duration}").parse().unwrap()]).unwrap()
}

fn lidar(c: &mut Criterion) {
    let mut group = c.benchmark_group("unknown-maze");
    group.sample_size(10);
    // Twenty seconds into the run, deep in the maze: the field one scan ago, then the map
    // after one more scan, to re-solve on from that field (as the run does).
    let world = maze(60.0);
    let mut sim = Simulation::new(&world).unwrap();
    for _ in 0..1990 {
        sim.step();
    }
    let warm = sim.agents[0].field.harmonic().unwrap().clone();
    for _ in 0..10 {
        sim.step();
    }
    let agent = &sim.agents[0];
    let position: [f64; 2] = agent.metrics.path().last().copied().unwrap();
    let run = agent.lidar.as_ref().unwrap();
    group.bench_function("scan-360-rays", |b| {
        let mut lidar = run.lidar.clone();
        b.iter(|| lidar.scan(sim.physics(), position, 0.0, agent.collider()))
    });
    group.bench_function("re-solve", |b| {
        b.iter(|| {
            HarmonicField::solve_known(&world, &agent.agent, position, &run.map, &[], Some(&warm))
                .unwrap()
        })
    });
    let first = maze(10.0);
    group.bench_function("run-10s", |b| {
        b.iter(|| nadf::run::run(&first, &nadf::run::RunOptions::default()).unwrap())
    });
    group.finish();
}

criterion_group!(benches, lidar);
criterion_main!(benches);
