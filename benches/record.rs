//! The cost of a recording: the room with two dividers (60 s simulated, 6000 steps) run with a
//! recording written to a temporary file and without one. Run with `cargo bench --bench record`;
//! the ratio of the two is what a user pays for the `.rrd`.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use nadf::run::{RunOptions, run};
use nadf::world::load;

fn record(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
    let world = load(&path, &[]).unwrap();
    let dir = std::env::temp_dir().join(format!("nadf-bench-record-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut group = c.benchmark_group("room-60s");
    group.sample_size(20);
    group.bench_function("without-recording", |b| {
        b.iter(|| run(&world, &RunOptions::default()).unwrap())
    });
    let options = RunOptions {
        recording: Some(dir.join("room.rrd")),
        ..RunOptions::default()
    };
    group.bench_function("with-recording", |b| {
        b.iter(|| {
            let _ = std::fs::remove_file(dir.join("room.rrd"));
            run(&world, &options).unwrap()
        })
    });
    group.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, record);
criterion_main!(benches);
