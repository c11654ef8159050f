//! Long runs are precious: Ctrl-C leaves a complete recording of the run so far and prints the
//! summary so far; a run killed outright leaves a `.partial` recording that still decodes; a
//! failed run never replaces an existing output.

mod common;

use std::io::BufReader;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{nadf_bin, world_path};

/// Starts a run of the room that would take minutes, recording to `dir/long.rrd`.
fn start_long_run(dir: &Path) -> Child {
    Command::new(nadf_bin())
        .current_dir(dir)
        .arg("run")
        .arg(world_path("room-two-dividers.toml"))
        .args(["-o", "long.rrd", "--set", "duration=100000"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until the partial recording holds a few flushes' worth of data.
fn wait_for_data(partial: &Path) {
    let started = Instant::now();
    while std::fs::metadata(partial).map_or(0, |m| m.len()) < 2_000_000 {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no recording data after 60 s"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Decodes messages until the end or the first error; returns how many decoded and whether
/// any was a scalar of the distance plot.
fn decode_prefix(path: &Path) -> (usize, bool) {
    let file = BufReader::new(std::fs::File::open(path).unwrap());
    let (mut count, mut has_plot) = (0, false);
    for msg in re_log_encoding::DecoderApp::decode_lazy(file) {
        let Ok(msg) = msg else { break };
        if let re_log_types::LogMsg::ArrowMsg(_, arrow) = msg {
            let chunk = re_chunk::Chunk::from_arrow_msg(&arrow).unwrap();
            has_plot |= chunk.entity_path().to_string() == "/plots/robot/distance";
        }
        count += 1;
    }
    (count, has_plot)
}

#[test]
fn ctrl_c_closes_the_recording_prints_the_summary_so_far_and_exits_130() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = start_long_run(dir.path());
    wait_for_data(&dir.path().join("long.rrd.partial"));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "still running 30 s after SIGINT"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stdout.contains("robot") && stdout.contains("reached"),
        "{stdout}"
    );
    assert!(stderr.contains("interrupted at t ="), "{stderr}");

    // The whole file decodes, footer included, and nothing partial is left.
    let rrd = dir.path().join("long.rrd");
    let file = BufReader::new(std::fs::File::open(&rrd).unwrap());
    let all: Result<Vec<_>, _> = re_log_encoding::DecoderApp::decode_eager(file)
        .unwrap()
        .collect();
    assert!(all.unwrap().len() > 10);
    assert!(decode_prefix(&rrd).1);
    assert!(!dir.path().join("long.rrd.partial").exists());
}

#[test]
fn a_killed_run_leaves_a_partial_recording_that_decodes_up_to_its_last_flush() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = start_long_run(dir.path());
    let partial = dir.path().join("long.rrd.partial");
    wait_for_data(&partial);
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!dir.path().join("long.rrd").exists());
    let (count, has_plot) = decode_prefix(&partial);
    assert!(count > 10 && has_plot, "{count} messages decoded");
}

#[test]
fn a_failed_run_leaves_an_existing_recording_and_summary_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let rrd = dir.path().join("out.rrd");
    let json = dir.path().join("out.json");
    std::fs::write(&rrd, b"an earlier recording").unwrap();
    std::fs::write(&json, b"an earlier summary").unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/enclosed.toml");
    let out = Command::new(nadf_bin())
        .current_dir(dir.path())
        .arg("run")
        .arg(fixture)
        .args(["-o", "out.rrd", "--json", "out.json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read(&rrd).unwrap(), b"an earlier recording");
    assert_eq!(std::fs::read(&json).unwrap(), b"an earlier summary");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}
