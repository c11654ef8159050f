//! `nadf scen`: Moving AI scenarios run in parallel on a map world, a CSV and a plot, skipped
//! scenarios reported with their reason, filters and bad input.

mod common;

use std::path::Path;
use std::process::Command;

use common::{nadf_bin, world_path};

fn scen(dir: &Path, args: &[&str]) -> std::process::Output {
    let world = world_path("map-arena.toml");
    let scen = world_path("maps/arena.map.scen");
    Command::new(nadf_bin())
        .current_dir(dir)
        .args(["scen", world.to_str().unwrap(), scen.to_str().unwrap()])
        .args(args)
        .output()
        .unwrap()
}

/// The CSV's rows as maps from header to cell.
fn rows(csv: &str) -> Vec<std::collections::HashMap<String, String>> {
    let mut lines = csv.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            header
                .iter()
                .cloned()
                .zip(l.split(',').map(String::from))
                .collect()
        })
        .collect()
}

#[test]
fn every_scenario_runs_or_is_skipped_with_its_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = scen(dir.path(), &["--out", "out", "-j", "2"]);
    common::assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("15 scenario(s) run, 1 skipped: 15 reached"),
        "{stdout}"
    );
    assert!(
        stdout.contains("skipped line 17: its start and goal are the same cell"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(dir.path().join("out/scen.csv")).unwrap();
    let rows = rows(&csv);
    assert_eq!(rows.len(), 16);
    for row in &rows[..15] {
        assert_eq!(row["skipped"], "");
        assert_eq!(row["reached"], "true", "{row:?}");
        assert_eq!(row["contacts"], "0", "{row:?}");
        let ratio: f64 = row["path_ratio"].parse().unwrap();
        // The field's paths cut corners an octile path cannot; none doubles back.
        assert!((0.9..1.5).contains(&ratio), "{row:?}");
    }
    assert!(rows[15]["skipped"].contains("same cell") && rows[15]["reached"].is_empty());
    let png = std::fs::read(dir.path().join("out/scen.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"));

    // The same scenarios on one thread give the same CSV.
    let out = scen(dir.path(), &["--out", "one", "-j", "1"]);
    common::assert_success(&out);
    assert_eq!(
        std::fs::read_to_string(dir.path().join("one/scen.csv")).unwrap(),
        csv
    );
}

#[test]
fn buckets_and_counts_select_scenarios() {
    let dir = tempfile::tempdir().unwrap();
    let out = scen(
        dir.path(),
        &["--out", "b", "--bucket", "10", "--bucket", "6"],
    );
    common::assert_success(&out);
    let picked = rows(&std::fs::read_to_string(dir.path().join("b/scen.csv")).unwrap());
    assert_eq!(picked.len(), 6);
    assert!(
        picked
            .iter()
            .all(|r| r["bucket"] == "10" || r["bucket"] == "6")
    );
    let out = scen(dir.path(), &["--out", "c", "--count", "4"]);
    common::assert_success(&out);
    let spread = rows(&std::fs::read_to_string(dir.path().join("c/scen.csv")).unwrap());
    // Spread over the file: its first line and later ones.
    let lines: Vec<&str> = spread.iter().map(|r| r["line"].as_str()).collect();
    assert_eq!(lines, ["2", "6", "10", "14"]);
}

#[test]
fn scenarios_the_disc_cannot_do_are_skipped_and_other_maps_refused() {
    let dir = tempfile::tempdir().unwrap();
    // A start in the pond (blocked), and a goal on the wall around.
    let scen = dir.path().join("bad.map.scen");
    std::fs::write(
        &scen,
        "version 1\n1\tarena.map\t48\t48\t10\t31\t20\t20\t15\n1\tarena.map\t48\t48\t20\t20\t0\t10\t25\n",
    )
    .unwrap();
    let world = world_path("map-arena.toml");
    let out = Command::new(nadf_bin())
        .current_dir(dir.path())
        .args([
            "scen",
            world.to_str().unwrap(),
            scen.to_str().unwrap(),
            "--out",
            "o",
        ])
        .output()
        .unwrap();
    common::assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("0 scenario(s) run, 2 skipped"), "{stdout}");
    assert!(
        stdout.contains("agents.0.start") && stdout.contains("the map"),
        "{stdout}"
    );

    std::fs::write(
        &scen,
        "version 1\n1\tmaps/other.map\t48\t48\t2\t2\t3\t3\t1\n",
    )
    .unwrap();
    let out = Command::new(nadf_bin())
        .current_dir(dir.path())
        .args(["scen", world.to_str().unwrap(), scen.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("`other.map`") && stderr.contains("`arena.map`"),
        "{stderr}"
    );
    assert!(!dir.path().join("map-arena-scen").exists());
}
