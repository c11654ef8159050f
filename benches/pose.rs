//! The field of a shaped agent in (x, y, θ), as `nadf run` builds it before the first step
//! (`Simulation::new`: the configuration-space mask, the 3-D multigrid-preconditioned CG solve
//! periodic in θ with its nested levels, the kinematic path), on the shipped worlds:
//! `box-room` (the paper's 10 m room at 5 cm × 64 headings, 2.6 million cells; the issue's
//! target is under 2 s), `piano-mover` (2.5 cm × 96 headings) and `couch-door`. The solver's
//! passes run on rayon's threads (all cores). And the joint-space mask of a planar arm
//! (`field::JointMask`, the first part of issue 27): two links at 256² cells and three at 128³,
//! among a post, a shelf and a disc. Run with `cargo bench --bench pose`.

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use nadf::field::{JointAxis, JointMask};
use nadf::sim::Simulation;
use nadf::world::{Chain, Link, Wall, load, wall_shape};

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

fn joint_masks(c: &mut Criterion) {
    let mut group = c.benchmark_group("joint-mask");
    group.sample_size(10);
    let link = |length: f64| Link::rod(length, 1.0, 0.05);
    let walls: Vec<_> = [
        Wall::Box {
            center: [3.0, 2.4],
            half_extents: [0.1, 0.3],
            angle: 0.2,
        },
        Wall::Disc {
            center: [1.2, 1.3],
            radius: 0.2,
        },
        Wall::Segment {
            a: [1.0, 3.0],
            b: [2.6, 3.3],
            thickness: 0.08,
        },
    ]
    .iter()
    .map(|w| wall_shape(w).unwrap())
    .collect();
    let bounds = ([0.0, 0.0], [4.0, 4.0]);
    for (name, lengths, cells) in [
        ("two-links-256", vec![0.9, 0.7], 256),
        ("three-links-128", vec![0.8, 0.6, 0.4], 128),
    ] {
        let chain = Chain {
            base: [2.0, 2.0],
            links: lengths.into_iter().map(link).collect(),
        };
        let axes = vec![
            JointAxis {
                cells,
                limits: None
            };
            chain.links.len()
        ];
        group.bench_function(name, |b| {
            b.iter(|| JointMask::build(&chain, &axes, &walls, bounds))
        });
    }
    group.finish();
}

criterion_group!(benches, fields, joint_masks);
criterion_main!(benches);
