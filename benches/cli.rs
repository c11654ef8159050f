//! What users run, timed as they run it: the `nadf` binary itself (the one `cargo run
//! --release` builds), started as a process on the shipped worlds and maps, output and all.
//!
//! - `field`: `nadf field` on the paper's room at 1024² cells (the size pyamg is compared at,
//!   `scripts/pyamg_field.py`) and on the shared rooms map for its longest scenario (780 m
//!   through 40 one-cell doors, a field 1e-626 deep).
//! - `run`: `nadf run` on the paper's room, without and with its recording, and on the rooms
//!   map's own world.
//! - `scen`: `nadf scen` on 8 scenarios of the rooms map, spread over the file, on every core.
//! - `crowd`: `nadf run --no-record` on the antipodal circles of 64 robots (first 20 s) and 128
//!   robots (first 30 s) with 1.8 m of arc each: the simulated time covers the crossing at the
//!   centre, the densest part; a time under 20 s (30 s) is faster than real time.
//!
//! Run with `cargo bench --bench cli` (or `-- field` for one group). Each sample is one process.

use std::path::{Path, PathBuf};
use std::process::Command;

use criterion::{Criterion, criterion_group, criterion_main};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `nadf args…` from the repository's root and checks that it succeeded.
fn nadf(args: &[&str]) {
    nadf_ending(args, &[0]);
}

/// Runs `nadf args…` and checks that it exited with one of `statuses` (1: an expectation
/// failed, as a run cut short of its duration does).
fn nadf_ending(args: &[&str], statuses: &[i32]) {
    let out = Command::new(env!("CARGO_BIN_EXE_nadf"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("the nadf binary runs");
    assert!(
        out.status.code().is_some_and(|c| statuses.contains(&c)),
        "nadf {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A scratch path for outputs.
fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("nadf-bench-{}-{name}", std::process::id()))
}

fn field(c: &mut Criterion) {
    let mut group = c.benchmark_group("field");
    group.sample_size(10);
    group.bench_function("room-1024", |b| {
        b.iter(|| {
            nadf(&[
                "field",
                "worlds/room-two-dividers.toml",
                "--set",
                "field.cell=0.009765625",
            ])
        })
    });
    // The scenario file's longest: bucket 194, (447, 502) to (7, 59), 779.985 m optimal.
    group.bench_function("map-rooms-longest", |b| {
        b.iter(|| {
            nadf(&[
                "field",
                "worlds/map-rooms.toml",
                "--set",
                "agents.0.start=[447.5,9.5]",
                "--set",
                "agents.0.target=[7.5,452.5]",
            ])
        })
    });
    group.finish();
}

fn run(c: &mut Criterion) {
    let mut group = c.benchmark_group("run");
    group.sample_size(10);
    group.bench_function("room-two-dividers", |b| {
        b.iter(|| nadf(&["run", "worlds/room-two-dividers.toml", "--no-record"]))
    });
    let rrd = scratch("room.rrd");
    let rrd = rrd.to_str().unwrap();
    group.bench_function("room-two-dividers-recorded", |b| {
        b.iter(|| nadf(&["run", "worlds/room-two-dividers.toml", "-o", rrd]))
    });
    group.bench_function("map-rooms", |b| {
        b.iter(|| nadf(&["run", "worlds/map-rooms.toml", "--no-record"]))
    });
    group.finish();
    let _ = std::fs::remove_file(rrd);
}

fn scen(c: &mut Criterion) {
    let mut group = c.benchmark_group("scen");
    group.sample_size(10);
    let out = scratch("scen");
    let out = out.to_str().unwrap();
    group.bench_function("map-rooms-8", |b| {
        b.iter(|| {
            nadf(&[
                "scen",
                "worlds/map-rooms.toml",
                "worlds/maps/8room_000.map.scen",
                "--count",
                "8",
                "--out",
                out,
            ])
        })
    });
    group.finish();
    let _ = std::fs::remove_dir_all(out);
}

fn crowd(c: &mut Criterion) {
    let mut group = c.benchmark_group("crowd");
    group.sample_size(10);
    for (name, file, seconds) in [
        (
            "64-arc-1.8-20s",
            "worlds/crowds/circle-64-arc-1.8.toml",
            "20",
        ),
        (
            "128-arc-1.8-30s",
            "worlds/crowds/circle-128-arc-1.8.toml",
            "30",
        ),
    ] {
        let duration = format!("duration={seconds}");
        group.bench_function(name, |b| {
            b.iter(|| nadf_ending(&["run", file, "--no-record", "--set", &duration], &[0, 1]))
        });
    }
    group.finish();
}

criterion_group!(benches, field, run, scen, crowd);
criterion_main!(benches);
