//! A run is deterministic: the same world file and seed give byte-identical JSON summaries, run
//! after run and whatever the number of threads.

mod common;

use std::process::Command;

use common::{nadf_bin, world_path};

fn summary_bytes(world: &str, threads: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(nadf_bin())
        .current_dir(dir.path())
        .env("RAYON_NUM_THREADS", threads)
        .arg("run")
        .arg(world_path(world))
        .args(["--no-record", "--json", "s.json", "--set", "duration=20"])
        .output()
        .unwrap();
    common::assert_success(&out);
    std::fs::read(dir.path().join("s.json")).unwrap()
}

#[test]
fn the_same_world_gives_byte_identical_summaries_with_one_or_two_threads() {
    let first = summary_bytes("room-two-dividers.toml", "1");
    assert!(first.len() > 100);
    assert_eq!(first, summary_bytes("room-two-dividers.toml", "1"));
    assert_eq!(first, summary_bytes("room-two-dividers.toml", "2"));
}

/// Two agents re-solve their fields at every replan, in parallel when there are threads for
/// it: the summaries do not depend on that.
#[test]
fn agents_replanning_in_parallel_give_the_same_summaries_as_one_after_another() {
    let first = summary_bytes("swap.toml", "1");
    assert!(first.len() > 200);
    assert_eq!(first, summary_bytes("swap.toml", "2"));
}
