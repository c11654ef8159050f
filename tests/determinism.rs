//! A run is deterministic: the same world file and seed give byte-identical JSON summaries, run
//! after run and whatever the number of threads.

mod common;

use std::process::Command;

use common::{nadf_bin, world_path};

fn summary_bytes(threads: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(nadf_bin())
        .current_dir(dir.path())
        .env("RAYON_NUM_THREADS", threads)
        .arg("run")
        .arg(world_path("room-two-dividers.toml"))
        .args(["--no-record", "--json", "s.json", "--set", "duration=20"])
        .output()
        .unwrap();
    common::assert_success(&out);
    std::fs::read(dir.path().join("s.json")).unwrap()
}

#[test]
fn the_same_world_gives_byte_identical_summaries_with_one_or_two_threads() {
    let first = summary_bytes("1");
    assert!(first.len() > 100);
    assert_eq!(first, summary_bytes("1"));
    assert_eq!(first, summary_bytes("2"));
}
