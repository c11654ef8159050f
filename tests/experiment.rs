//! `nadf experiment` and `nadf merge` end to end: runs seeded by their index (a shard's run
//! is the unsharded run's), merged shards byte-identical to the unsharded results, refused
//! merges, a resumed kill, sampled free points, failed runs as rows, located errors.

mod common;

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{assert_success, nadf_bin, world_path};
use nadf::experiment::{Experiment, Sampled};

fn nadf(args: &[&str]) -> Output {
    Command::new(nadf_bin()).args(args).output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// An experiment file in a fresh directory of `name` whose `[experiment]` body is `body`
/// (the world is the paper's room, coarse and short).
fn experiment(name: &str, body: &str) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("nadf-exp-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    let file = dir.join("exp.toml");
    let text = format!(
        "[experiment]\nworld = {:?}\nset = [\"field.cell=0.1\", \"duration=6\"]\n{body}",
        world_path("room-two-dividers.toml").display().to_string()
    );
    fs::write(&file, text).unwrap();
    (dir, file)
}

const SAMPLED: &str = r#"runs = 9
seed = 5
group = ["agents.0.controller.kind"]
[experiment.sample]
"agents.0.start" = { free_point = { clearance = 0.4 } }
"agents.0.controller.b" = { uniform = [5.0, 20.0] }
"agents.0.controller.kind" = { choice = ["nadf", "viscous"] }
"#;

/// Whether the files `a` and `b` hold the same bytes (a message on the first difference).
fn same_bytes(a: &Path, b: &Path) {
    let (x, y) = (fs::read(a).unwrap(), fs::read(b).unwrap());
    let first = x.iter().zip(&y).position(|(p, q)| p != q);
    assert!(
        x == y,
        "{} ({} bytes) and {} ({} bytes) differ, first at byte {first:?}",
        a.display(),
        x.len(),
        b.display(),
        y.len()
    );
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn shards_merge_into_the_unsharded_results_byte_for_byte() {
    let (dir, file) = experiment("shards", SAMPLED);
    let whole = dir.join("whole");
    let out = nadf(&["experiment", s(&file), "--out", s(&whole), "-j", "2"]);
    assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("9 runs on 2 thread(s)"), "{stdout}");
    assert!(stdout.contains("agents.0.controller.kind=nadf"), "{stdout}");
    let sharded = dir.join("sharded");
    for i in 0..3 {
        let shard = format!("{i}/3");
        assert_success(&nadf(&[
            "experiment",
            s(&file),
            "--out",
            s(&sharded),
            "--shard",
            &shard,
            "-j",
            "1",
        ]));
    }
    let merged = dir.join("merged");
    let out = nadf(&["merge", s(&sharded), "--out", s(&merged)]);
    assert_success(&out);
    for f in ["runs.arrow", "summary.csv"] {
        same_bytes(&whole.join(f), &merged.join(f));
    }
    let arrow = fs::read(whole.join("runs.arrow")).unwrap();
    assert_eq!(&arrow[..6], b"ARROW1");
    let csv = fs::read_to_string(whole.join("summary.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");

    // Refused: a missing shard, a shard twice, another experiment's shard, an incomplete one.
    let one = sharded.join("shard-1-of-3");
    let out = nadf(&[
        "merge",
        s(&sharded.join("shard-0-of-3")),
        s(&sharded.join("shard-2-of-3")),
        "--out",
        s(&dir.join("m1")),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("missing shard(s) 1/3"),
        "{}",
        stderr(&out)
    );
    let out = nadf(&["merge", s(&sharded), s(&one), "--out", s(&dir.join("m2"))]);
    assert!(stderr(&out).contains("shard 1/3 twice"), "{}", stderr(&out));
    let (other_dir, other) = experiment("other", &SAMPLED.replace("seed = 5", "seed = 6"));
    let foreign = other_dir.join("sharded");
    assert_success(&nadf(&[
        "experiment",
        s(&other),
        "--out",
        s(&foreign),
        "--shard",
        "1/3",
    ]));
    let out = nadf(&[
        "merge",
        s(&sharded.join("shard-0-of-3")),
        s(&foreign.join("shard-1-of-3")),
        s(&sharded.join("shard-2-of-3")),
        "--out",
        s(&dir.join("m3")),
    ]);
    assert!(stderr(&out).contains("a mixed set"), "{}", stderr(&out));
    let manifest = one.join("shard.json");
    let text = fs::read_to_string(&manifest).unwrap();
    fs::write(
        &manifest,
        text.replace("\"complete\": true", "\"complete\": false"),
    )
    .unwrap();
    let out = nadf(&["merge", s(&sharded), "--out", s(&dir.join("m4"))]);
    assert!(stderr(&out).contains("not complete"), "{}", stderr(&out));
    for d in [
        &dir.join("m1"),
        &dir.join("m2"),
        &dir.join("m3"),
        &dir.join("m4"),
    ] {
        assert!(
            !d.join("runs.arrow").exists(),
            "a refused merge wrote {}",
            d.display()
        );
    }
    let _ = fs::remove_dir_all(&dir);
    let _ = fs::remove_dir_all(&other_dir);
}

/// A batch killed mid-way loses only the runs in flight: its progress file, cut in the middle
/// of a line, is resumed into the results of an uninterrupted run; without `--resume` the
/// directory is refused.
#[test]
fn a_killed_batch_resumes_to_the_same_results() {
    let (dir, file) = experiment("resume", SAMPLED);
    let whole = dir.join("whole");
    assert_success(&nadf(&["experiment", s(&file), "--out", s(&whole)]));
    let killed = dir.join("killed");
    assert_success(&nadf(&["experiment", s(&file), "--out", s(&killed)]));
    // As a kill leaves it: four whole lines, half of a fifth, the manifest not complete.
    let progress = killed.join("runs.jsonl");
    let lines: Vec<String> = fs::read_to_string(&progress)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    assert_eq!(lines.len(), 9);
    let cut = format!(
        "{}\n{}",
        lines[..4].join("\n"),
        &lines[4][..lines[4].len() / 2]
    );
    fs::write(&progress, cut).unwrap();
    let manifest = killed.join("shard.json");
    let text = fs::read_to_string(&manifest).unwrap();
    fs::write(
        &manifest,
        text.replace("\"complete\": true", "\"complete\": false"),
    )
    .unwrap();
    fs::remove_file(killed.join("runs.arrow")).unwrap();

    let out = nadf(&["experiment", s(&file), "--out", s(&killed)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--resume"), "{}", stderr(&out));
    let out = nadf(&["experiment", s(&file), "--out", s(&killed), "--resume"]);
    assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("5 runs on") && stdout.contains("4 done before, kept"),
        "{stdout}"
    );
    same_bytes(&whole.join("runs.arrow"), &killed.join("runs.arrow"));
    let _ = fs::remove_dir_all(&dir);
}

/// Run k is the same whatever runs beside it, its free start keeps its clearance and connects
/// to the target, and a run whose values make no world is a row with its error.
#[test]
fn runs_are_seeded_by_their_index_and_free_points_are_free() {
    let (dir, file) = experiment(
        "seeded",
        r#"runs = 30
[experiment.sample]
"agents.0.start" = { free_point = { clearance = 0.5 } }
"agents.0.mass" = { uniform = [-2.0, 2.0] }
"#,
    );
    let exp = Experiment::load(&file, &[]).unwrap();
    let again = Experiment::load(&file, &[]).unwrap();
    let world = nadf::world::load(&world_path("room-two-dividers.toml"), &[]).unwrap();
    let walls = nadf::world::all_wall_shapes(&world);
    let (mut failed, mut ran) = (0, 0);
    for k in [17, 3, 29, 0, 3, 11, 22, 8, 5, 14] {
        let record = exp.run(k);
        assert_eq!(record, again.run(k), "run {k}");
        match &record.outcome {
            Err(e) => {
                failed += 1;
                assert!(e.contains("agents.0.mass"), "{e}");
            }
            Ok(agents) => {
                ran += 1;
                let Some(Sampled::Point(p)) = record.values[1] else {
                    panic!("{:?}", record.values)
                };
                let c = nadf::sim::signed_clearance(&walls, nalgebra::Vector2::from(p), 0.2);
                assert!(c >= 0.5, "run {k}: start {p:?} clearance {c}");
                assert_eq!(agents.len(), 1);
            }
        }
    }
    assert!(failed > 0 && ran > 0, "{failed} failed, {ran} ran");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_experiment_is_located() {
    let cases = [
        (
            "runs = 0\n",
            "exp.toml:4:8: `experiment.runs`: must be from 1",
        ),
        (
            "runs = 3\n[experiment.sample]\n\"agents.0.controller.b\" = { uniform = [30.0, 3.0] }\n",
            "exp.toml:6:27: `experiment.sample.\"agents.0.controller.b\"`: uniform = [30, 3]: the low end",
        ),
        (
            "runs = 3\n[experiment.sample]\n\"agents.0.mass\" = { free_point = {} }\n",
            "a free point is sampled for `agents.N.start`",
        ),
        (
            "runs = 3\ngroup = [\"agents.0.mass\"]\n",
            "`experiment.group`: `agents.0.mass` must be a sampled key",
        ),
        ("runs = 3\nrunz = 4\n", "exp.toml:5:1: unknown field `runz`"),
        (
            "runs = 3\n[experiment.sample]\n\"agents.0.mass\" = { gauss = [1.0, 2.0] }\n",
            "unknown variant `gauss`",
        ),
    ];
    for (i, (body, says)) in cases.iter().enumerate() {
        let (dir, file) = experiment(&format!("bad{i}"), body);
        let out = nadf(&["experiment", s(&file), "--out", s(&dir.join("out"))]);
        assert_eq!(out.status.code(), Some(2), "{body}");
        assert!(stderr(&out).contains(says), "{body}: {}", stderr(&out));
        assert!(!dir.join("out").exists(), "{body}: wrote an output");
        let _ = fs::remove_dir_all(&dir);
    }
}

/// Every shipped experiment loads; the small ones' first run makes a world that runs (the
/// rooms map's field alone takes seconds).
#[test]
fn the_shipped_experiments_load() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    let mut count = 0;
    for entry in fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let exp = Experiment::load(&path, &["duration=0.5".parse().unwrap()])
            .unwrap_or_else(|e| panic!("{e}"));
        count += 1;
        if path.to_string_lossy().contains("rooms") {
            continue;
        }
        let record = exp.run(0);
        assert!(
            record.outcome.is_ok(),
            "{}: {:?}",
            path.display(),
            record.outcome
        );
    }
    assert!(count >= 3);
}
