//! `nadf sweep`: the paper's figures 23 and 24 from coarse sweeps of the room world, and the
//! files the command writes.

mod common;

use std::process::Command;

use common::{nadf_bin, world_path};
use nadf::sweep::{Range, cases, run_all};
use nadf::world::Override;

fn sweep(kind: &str, range: &str) -> Vec<(f64, nadf::metrics::Summary)> {
    let ranges: Vec<Range> = vec![range.parse().unwrap()];
    let overrides: Vec<Override> = [
        format!("agents.0.controller.kind={kind}"),
        "duration=120".into(),
    ]
    .iter()
    .map(|o| o.parse().unwrap())
    .collect();
    let (_, cases) = cases(&world_path("room-two-dividers.toml"), &ranges, &overrides).unwrap();
    let keys = vec![ranges[0].path.clone()];
    let done = run_all(&keys, &cases, Some(2), &|| {}, None).unwrap();
    done.runs
        .into_iter()
        .map(|(v, mut s)| (v[0], s.remove(0)))
        .collect()
}

#[test]
fn viscous_settling_time_is_convex_in_b_with_an_interior_minimum() {
    // Paper figure 23.
    let runs = sweep("viscous", "agents.0.controller.b=0.1:3.1:7");
    let times: Vec<f64> = runs.iter().map(|(_, s)| s.settling_time.unwrap()).collect();
    let best = times
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .unwrap()
        .0;
    assert!(best > 0 && best < times.len() - 1, "{runs:?}");
    // Falling before the minimum, rising after it.
    assert!(times[..=best].windows(2).all(|p| p[1] < p[0]), "{times:?}");
    assert!(times[best..].windows(2).all(|p| p[1] > p[0]), "{times:?}");
}

#[test]
fn nadf_settling_time_falls_as_b_d_grows() {
    // Paper figure 24.
    let runs = sweep("nadf", "agents.0.controller.b=1:31:7");
    let times: Vec<f64> = runs.iter().map(|(_, s)| s.settling_time.unwrap()).collect();
    assert!(times.windows(2).all(|p| p[1] <= p[0]), "{times:?}");
    assert!(times[times.len() - 1] < 0.6 * times[0], "{times:?}");
    assert!(runs.iter().all(|(_, s)| s.contacts == 0));
}

#[test]
fn the_command_writes_a_csv_row_per_run_and_a_png_and_the_thread_count_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut csv = Vec::new();
    for jobs in ["1", "2"] {
        let out_dir = dir.path().join(format!("out{jobs}"));
        let out = Command::new(nadf_bin())
            .arg("sweep")
            .arg(world_path("room-two-dividers.toml"))
            .args([
                "--set-range",
                "agents.0.controller.b=2:10:3",
                "--set-range",
                "agents.0.controller.k=1:2:2",
                "--set",
                "duration=20",
                "-j",
                jobs,
                "--out",
            ])
            .arg(&out_dir)
            .output()
            .unwrap();
        common::assert_success(&out);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            stdout.contains(&format!("6 runs on {jobs} thread(s)")),
            "{stdout}"
        );
        let text = std::fs::read_to_string(out_dir.join("sweep.csv")).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 7, "{text}");
        assert!(lines[0].starts_with(
            "agents.0.controller.b,agents.0.controller.k,agent,reached,settling_time"
        ));
        assert!(lines[1].starts_with("2,1,robot,true,"), "{}", lines[1]);
        assert!(lines[6].starts_with("10,2,robot,true,"), "{}", lines[6]);
        let png = std::fs::read(out_dir.join("sweep.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        csv.push(text);
    }
    assert_eq!(csv[0], csv[1]);
}

#[test]
fn a_bad_range_or_a_bad_swept_value_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let run = |range: &str| {
        Command::new(nadf_bin())
            .current_dir(dir.path())
            .arg("sweep")
            .arg(world_path("room-two-dividers.toml"))
            .args(["--set-range", range])
            .output()
            .unwrap()
    };
    let out = run("agents.0.controller.b=1:2");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("START:END:COUNT"));
    // A value that makes an invalid world names the value and the key.
    let out = run("agents.0.mass=-1:1:3");
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("agents.0.mass=-1"), "{stderr}");
    assert!(
        stderr.contains("must be a positive finite number"),
        "{stderr}"
    );
    // Nothing was written.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
