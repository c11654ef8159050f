//! Every world shipped in `worlds/` carries the expectations it meets, and `nadf run` checks
//! them; a missed expectation exits with status 1 and a readable list. And every world's JSON
//! summary is byte for byte the one saved in `tests/summaries/`: a change that should not
//! change behaviour (a restructuring) must leave them all identical. A change that is meant to
//! change a run re-saves them with `NADF_BLESS=1 cargo test --release --test worlds` and says
//! why in its commit.

mod common;

use std::path::Path;
use std::process::Command;

use common::{nadf_bin, world_path};

#[test]
fn every_shipped_world_meets_its_expectations() {
    let mut worlds: Vec<_> = std::fs::read_dir(world_path(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    worlds.sort();
    assert!(worlds.len() >= 3);
    for path in worlds {
        let world = nadf::world::load(&path, &[]).unwrap();
        let has_expectations = world.expect.is_some()
            || world
                .agents
                .iter()
                .chain(&world.shaped)
                .any(|a| a.expect.is_some())
            || world.pendulums.iter().any(|p| p.expect.is_some())
            || world.arms.iter().any(|a| a.expect.is_some());
        assert!(has_expectations, "{} has no [expect] table", path.display());
        let dir = tempfile::tempdir().unwrap();
        let json = dir.path().join("s.json");
        let out = Command::new(nadf_bin())
            .arg("run")
            .arg(&path)
            .arg("--no-record")
            .arg("--json")
            .arg(&json)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}: {}\n{}",
            path.display(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(&json).unwrap();
        let stem = path.file_stem().unwrap().to_str().unwrap();
        let saved = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/summaries")
            .join(format!("{stem}.json"));
        if std::env::var_os("NADF_BLESS").is_some() {
            std::fs::write(&saved, &text).unwrap();
        } else {
            let expected = std::fs::read_to_string(&saved)
                .unwrap_or_else(|e| panic!("{}: {e} (save it with NADF_BLESS=1)", saved.display()));
            assert!(
                text == expected,
                "{}: the summary differs from {}:\n{text}",
                path.display(),
                saved.display()
            );
        }
        // And no numerical fault along the way.
        let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
        let shaped = summary["shaped"].as_array().into_iter().flatten();
        for (agent, settings) in (summary["agents"].as_array().unwrap().iter())
            .chain(shaped)
            .zip(world.agents.iter().chain(&world.shaped))
        {
            let faults = &agent["faults"];
            for key in [
                "guidance_lost_steps",
                "rejected_forces",
                "penetrations",
                "left_box_steps",
            ] {
                // A field rebuilt from noisy sensing can put a sensed wall over the body for a
                // step: its guidance is then undefined, as a real robot's would be. Khatib's
                // potential has local minima (the barrier): a body resting in one has none. A
                // body waiting for a moving obstacle to pass sits where its field, re-solved
                // around the obstacle, has a saddle for a step or two.
                if key == "guidance_lost_steps"
                    && (settings.sensor.is_some()
                        || !world.obstacles.is_empty()
                        || world.field.kind == nadf::world::FieldKind::AttractiveRepulsive)
                {
                    continue;
                }
                assert_eq!(faults[key], 0, "{}: {faults}", path.display());
            }
            assert_eq!(faults["non_finite_state"], false);
            // A body at or inside a wall or another body touched it: counted, always.
            let touched = |key: &str| agent[key].as_f64().is_some_and(|d| d <= 0.0);
            if touched("min_clearance")
                || touched("min_separation")
                || touched("min_obstacle_distance")
            {
                assert!(
                    agent["contacts"].as_u64() > Some(0),
                    "{}: {agent}",
                    path.display()
                );
            }
        }
    }
}

#[test]
fn a_missed_expectation_exits_1_and_says_what_failed() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(nadf_bin())
        .current_dir(dir.path())
        .arg("run")
        .arg(world_path("room-two-dividers.toml"))
        .args([
            "--no-record",
            "--set",
            "expect.max_settling_time=3",
            "--set",
            "expect.contacts=2",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("2 expectation(s) failed"), "{stderr}");
    assert!(
        stderr.contains("robot: contacts = 0, expected 2"),
        "{stderr}"
    );
    assert!(
        stderr.contains("robot: settling_time = 4.850 s, expected ≤ 3 s"),
        "{stderr}"
    );
}
