//! The cost of a recording: the room with two dividers (60 s simulated, 6000 steps) run with a
//! recording written to a temporary file and without one. Run with `cargo bench --bench record`;
//! the ratio of the two is what a user pays for the `.rrd`. On a shared machine the two
//! criterion measurements drift apart between their runs, so the bench also times 41 pairs of
//! runs, one of each, back to back, and prints the median of their ratios.

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
    let time = |options: &RunOptions| {
        let _ = std::fs::remove_file(dir.join("room.rrd"));
        let started = std::time::Instant::now();
        run(&world, options).unwrap();
        started.elapsed().as_secs_f64()
    };
    let mut ratios: Vec<f64> = (0..41)
        .map(|_| time(&options) / time(&RunOptions::default()))
        .collect();
    ratios.sort_by(f64::total_cmp);
    println!(
        "room-60s: with recording / without, 41 pairs back to back: median {:.2}x (quartiles {:.2}x-{:.2}x)",
        ratios[20], ratios[10], ratios[30]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group!(benches, record);
criterion_main!(benches);
