//! The work of every shipped world's field solve, in counts (CG iterations, solves, nested
//! levels, cells solved by them, unknown cells of the first solve), never in times: a change
//! that makes a solve do more work fails here on any machine, however fast. The counts are
//! saved in `tests/summaries/solve-work.json`; a change meant to alter them re-saves it with
//! `NADF_BLESS=1 cargo test --release --test solve_work` and says why in its commit (the
//! crowds' counts, in `crowd-work.json`, alike). Besides the shipped worlds as they are (among
//! them the shared rooms map, whose field is solved 120 levels deep): the paper's room at
//! 1024² cells, the solver's benchmark size.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use common::world;
use nadf::field::HarmonicField;
use nadf::world::{FieldKind, SensorKind};

/// The counts of one solve.
fn work(field: &HarmonicField) -> serde_json::Value {
    serde_json::json!({
        "iterations": field.iterations,
        "solves": field.solves,
        "levels": field.nested.levels,
        "cells_solved": field.nested.cells_solved,
        "first_cells": field.first_cells,
    })
}

/// The first disc agent's field of `name` with `overrides`, if the world has one (an agent with
/// a lidar plans on the map it builds, not on the world's walls: its worlds are left out).
fn solve(name: &str, overrides: &[&str]) -> Option<serde_json::Value> {
    let world = world(name, overrides);
    if world.field.kind != FieldKind::Harmonic {
        return None;
    }
    let agent = world.agents.first()?;
    if agent
        .sensor
        .as_ref()
        .is_some_and(|s| s.kind == SensorKind::Lidar)
    {
        return None;
    }
    let field = HarmonicField::solve(&world, agent).unwrap_or_else(|e| panic!("{name}: {e}"));
    Some(work(&field))
}

#[test]
fn no_shipped_solve_does_more_work_than_saved() {
    let mut names: Vec<String> = std::fs::read_dir(common::world_path(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| p.file_name().unwrap().to_str().unwrap().to_string())
        .collect();
    names.sort();
    let mut counts = BTreeMap::new();
    for name in &names {
        if let Some(w) = solve(name, &[]) {
            counts.insert(name.trim_end_matches(".toml").to_string(), w);
        }
    }
    let extra: [(&str, &str, &[&str]); 2] = [
        (
            "room-two-dividers at 1024²",
            "room-two-dividers.toml",
            &["field.cell=0.009765625"],
        ),
        (
            "map-rooms, scenario 207 170 127 109 (123 m)",
            "map-rooms.toml",
            &[
                "agents.0.start=[207.5,341.5]",
                "agents.0.target=[127.5,402.5]",
            ],
        ),
    ];
    for (label, name, overrides) in extra {
        counts.insert(label.to_string(), solve(name, overrides).unwrap());
    }
    assert!(counts.len() >= 25, "{} solves", counts.len());
    check_saved(
        "solve-work.json",
        &counts,
        &[
            "iterations",
            "solves",
            "levels",
            "cells_solved",
            "first_cells",
        ],
    );
}

/// The crowds' replanning in counts: re-solves, and those over the whole grid (a window's
/// fallback to the whole field, a field that takes a robot out of another's way), summed over
/// the robots. A window's solve costs the same in any room; a whole one grows with the room
/// and, through the nested levels behind a dense crowd, with the crowd (measured: 64 robots on
/// a 1.8 m circle, 0.13-0.25 s each, 70 % of the run's time), so more of them is a slowdown
/// however fast the machine.
#[test]
fn no_shipped_crowd_replans_more_whole_fields_than_saved() {
    let mut counts = BTreeMap::new();
    for (name, overrides) in [
        ("crowd.toml", &[][..]),
        ("crowds/circle-16.toml", &[][..]),
        ("crowds/door-16.toml", &["duration=10"][..]),
    ] {
        let report = nadf::run::run(&world(name, overrides), &Default::default()).unwrap();
        let sum = |f: fn(&nadf::metrics::Summary) -> usize| -> usize {
            report.agents.iter().map(f).sum()
        };
        let label = format!("{name} {}", overrides.join(" "));
        counts.insert(
            label.trim().to_string(),
            serde_json::json!({
                "resolves": sum(|s| s.resolves),
                "whole_resolves": sum(|s| s.whole_resolves),
            }),
        );
    }
    check_saved("crowd-work.json", &counts, &["resolves", "whole_resolves"]);
}

/// Compares `counts` with the ones saved in `tests/summaries/FILE` (or saves them with
/// `NADF_BLESS=1`): fails when any of `keys` grew, or changed at all without being saved.
fn check_saved(file: &str, counts: &BTreeMap<String, serde_json::Value>, keys: &[&str]) {
    let text = serde_json::to_string_pretty(counts).unwrap() + "\n";
    let saved = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/summaries")
        .join(file);
    if std::env::var_os("NADF_BLESS").is_some() {
        std::fs::write(&saved, &text).unwrap();
        return;
    }
    let expected: BTreeMap<String, serde_json::Value> = serde_json::from_str(
        &std::fs::read_to_string(&saved)
            .unwrap_or_else(|e| panic!("{}: {e} (save it with NADF_BLESS=1)", saved.display())),
    )
    .unwrap();
    let mut grew = Vec::new();
    let mut changed = Vec::new();
    for (label, now) in counts {
        let Some(before) = expected.get(label) else {
            changed.push(format!("{label}: not saved yet"));
            continue;
        };
        for &key in keys {
            let (a, b) = (before[key].as_u64().unwrap(), now[key].as_u64().unwrap());
            if b > a {
                grew.push(format!("{label}: {key} {a} -> {b}"));
            } else if b < a {
                changed.push(format!("{label}: {key} {a} -> {b}"));
            }
        }
    }
    assert!(
        grew.is_empty(),
        "more work than saved in {}:\n{}",
        saved.display(),
        grew.join("\n")
    );
    // Less work is welcome, but saved, so that it cannot creep back unseen.
    assert!(
        changed.is_empty(),
        "work changed from {} (less work: re-save with NADF_BLESS=1 and say why):\n{}",
        saved.display(),
        changed.join("\n")
    );
}
