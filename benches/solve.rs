//! The harmonic field solve: multigrid-preconditioned CG with nested deep-region solves
//! (`harmonic::solve_w`; `first-solve` is its first solve alone) against the red-black SOR
//! reference, on the room with two dividers at
//! 256² to 2048² cells and on the maze; and a warm-started re-solve after one divider moves by
//! one cell; and the solve with its AVX2 fast path switched off (`kernels`), which shows
//! whether that path is there (see `src/field/multigrid/kernels.rs`: on an AVX2 machine the
//! `portable` time must be clearly longer). Single-threaded. Run with `cargo bench --bench solve`.

use std::path::Path;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nadf::field::FreeSpace;
use nadf::field::solvers::{MAX_ITERATIONS, set_portable, solve, solve_sor, solve_w};
use nadf::world::{Override, load};

/// The free space of the first agent of a shipped world, with overrides.
fn space(world: &str, overrides: &[String]) -> FreeSpace {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("worlds")
        .join(world);
    let overrides: Vec<Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    let world = load(&path, &overrides).unwrap();
    FreeSpace::of(&world, &world.agents[0]).unwrap()
}

fn room(cells: usize, extra: &[String]) -> FreeSpace {
    let mut overrides = vec![format!("field.cell={}", 10.0 / cells as f64)];
    overrides.extend_from_slice(extra);
    space("room-two-dividers.toml", &overrides)
}

fn solves(c: &mut Criterion) {
    let mut group = c.benchmark_group("room");
    group.sample_size(10);
    for cells in [256, 512, 1024, 2048] {
        let s = room(cells, &[]);
        group.bench_with_input(BenchmarkId::new("multigrid", cells), &s, |b, s| {
            b.iter(|| solve_w(&s.grid, &s.reachable, &s.target_cells, 1e-10, None))
        });
        // The first solve alone (to the relative residual of 1e-10 the target names),
        // without the nested solves that restore relative precision in the deep regions.
        group.bench_with_input(BenchmarkId::new("first-solve", cells), &s, |b, s| {
            let t = s.grid.index(s.target_cell.0, s.target_cell.1);
            let mut unknown = s.reachable.clone();
            unknown[t] = false;
            b.iter(|| {
                let mut w = vec![0.0; s.grid.len()];
                w[t] = 1.0;
                solve(&s.grid, &unknown, &mut w, 1e-10, MAX_ITERATIONS)
            })
        });
        // The reference only where it finishes in reasonable time.
        if cells <= 512 {
            group.bench_with_input(BenchmarkId::new("sor", cells), &s, |b, s| {
                b.iter(|| solve_sor(&s.grid, &s.reachable, s.target_cell, 1e-9, 1_000_000).unwrap())
            });
        }
    }
    group.finish();

    let mut group = c.benchmark_group("maze");
    group.sample_size(10);
    let s = space("maze.toml", &[]);
    group.bench_function("multigrid", |b| {
        b.iter(|| solve_w(&s.grid, &s.reachable, &s.target_cells, 1e-10, None))
    });
    group.finish();

    // One divider moves by one cell: a cold solve of the new field against one warm-started
    // from the old field.
    let mut group = c.benchmark_group("re-solve-512");
    group.sample_size(10);
    let before = room(512, &[]);
    let old = solve_w(
        &before.grid,
        &before.reachable,
        &before.target_cells,
        1e-10,
        None,
    )
    .w
    .to_plain();
    let after = room(512, &[format!("walls.1.center.0={}", 6.75 + 10.0 / 512.0)]);
    for (name, warm) in [("cold", None), ("warm", Some(old.as_slice()))] {
        group.bench_function(name, |b| {
            b.iter(|| {
                solve_w(
                    &after.grid,
                    &after.reachable,
                    &after.target_cells,
                    1e-10,
                    warm,
                )
            })
        });
    }
    group.finish();
}

/// The first solve at 512² with the AVX2 path and with it switched off: the same results,
/// and on an AVX2 machine a clearly longer time without it. Equal times mean the fast path was
/// lost (a closure or function in a row loop that is no longer inlined).
fn kernels(c: &mut Criterion) {
    let mut group = c.benchmark_group("kernels");
    group.sample_size(10);
    let s = room(512, &[]);
    let t = s.grid.index(s.target_cell.0, s.target_cell.1);
    let mut unknown = s.reachable.clone();
    unknown[t] = false;
    for (name, portable) in [("avx2", false), ("portable", true)] {
        set_portable(portable);
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut w = vec![0.0; s.grid.len()];
                w[t] = 1.0;
                solve(&s.grid, &unknown, &mut w, 1e-10, MAX_ITERATIONS)
            })
        });
    }
    set_portable(false);
    group.finish();
}

criterion_group!(benches, solves, kernels);
criterion_main!(benches);
