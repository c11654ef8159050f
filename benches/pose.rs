//! The field of a shaped agent in (x, y, θ), as `nadf run` builds it before the first step
//! (`Simulation::new`: the configuration-space mask, the 3-D multigrid-preconditioned CG solve
//! periodic in θ with its nested levels, the kinematic path), on the shipped worlds:
//! `box-room` (the paper's 10 m room at 5 cm × 64 headings, 2.6 million cells; the issue's
//! target is under 2 s), `piano-mover` (2.5 cm × 96 headings) and `couch-door`. The solver's
//! passes run on rayon's threads (all cores). Run with `cargo bench --bench pose`.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use nadf::sim::Simulation;
use nadf::world::load;

fn fields(c: &mut Criterion) {
    let mut group = c.benchmark_group("pose");
    group.sample_size(10);
    for name in ["box-room", "piano-mover", "couch-door"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("worlds")
            .join(format!("{name}.toml"));
        let world = load(&path, &[]).unwrap();
        group.bench_function(name, |b| b.iter(|| Simulation::new(&world).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, fields);
criterion_main!(benches);
