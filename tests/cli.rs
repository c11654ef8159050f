//! The `nadf` binary end to end: recordings that decode, `--no-record`, `--json`, `check`.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::io::BufReader;
use std::path::Path;
use std::process::Command;

use common::{nadf_bin, world_path};

/// Runs `nadf ARGS` in `dir`.
fn nadf(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(nadf_bin())
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// Runs `nadf run worlds/room-two-dividers.toml ARGS` in `dir`.
fn run_room(dir: &Path, args: &[&str]) -> std::process::Output {
    let world = world_path("room-two-dividers.toml");
    let mut all = vec!["run", world.to_str().unwrap()];
    all.extend_from_slice(args);
    nadf(dir, &all)
}

/// A file under `tests/fixtures/`.
fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

/// A recording read back with Rerun's own decoder.
struct Recording {
    /// Per entity, per component (`Archetype:field`), its rows on the `sim_time` timeline (0
    /// for a static one).
    rows: BTreeMap<String, BTreeMap<String, usize>>,
    timelines: BTreeSet<String>,
    /// The entity paths of its layout (its blueprint store).
    layout: BTreeSet<String>,
    /// The recording's chunks (not the layout's).
    chunks: Vec<re_chunk::Chunk>,
}

impl Recording {
    fn read(path: &Path) -> Self {
        let file = BufReader::new(std::fs::File::open(path).unwrap());
        let messages = re_log_encoding::DecoderApp::decode_eager(file).unwrap();
        let mut recording = Recording {
            rows: BTreeMap::new(),
            timelines: BTreeSet::new(),
            layout: BTreeSet::new(),
            chunks: Vec::new(),
        };
        for msg in messages {
            let re_log_types::LogMsg::ArrowMsg(store, arrow) = msg.unwrap() else {
                continue;
            };
            let chunk = re_chunk::Chunk::from_arrow_msg(&arrow).unwrap();
            let entity = chunk.entity_path().to_string();
            let entity = entity.trim_start_matches('/').to_string();
            if store.kind() == re_log_types::StoreKind::Blueprint {
                recording.layout.insert(entity);
                continue;
            }
            let timed = chunk.timelines().keys().any(|t| t.as_str() == "sim_time");
            let components = recording.rows.entry(entity).or_default();
            for component in chunk.components_identifiers() {
                *components.entry(component.to_string()).or_insert(0) +=
                    if timed { chunk.num_rows() } else { 0 };
            }
            recording
                .timelines
                .extend(chunk.timelines().keys().map(|t| t.as_str().to_string()));
            recording.chunks.push(chunk);
        }
        recording
    }

    /// The rows of `entity`'s `component` on `sim_time`.
    fn rows(&self, entity: &str, component: &str) -> usize {
        self.rows
            .get(entity)
            .and_then(|c| c.get(component))
            .copied()
            .unwrap_or(0)
    }

    /// Whether the recording has `what`: an entity, or `ENTITY[LABEL]`, a series of that plot.
    fn has(&self, what: &str) -> bool {
        match what.split_once('[') {
            Some((entity, label)) => self
                .labels(entity)
                .contains(&label.trim_end_matches(']').to_string()),
            None => self.rows.contains_key(what),
        }
    }

    /// Asserts that the recording has each of `entities` (see [`Self::has`]).
    fn assert_has(&self, entities: &[&str]) {
        for e in entities {
            assert!(self.has(e), "no `{e}` in {:?}", self.rows.keys());
        }
    }

    /// The labels of the series of the plot `entity`.
    fn labels(&self, entity: &str) -> Vec<String> {
        (self.chunks.iter())
            .filter(|c| c.entity_path().to_string().trim_start_matches('/') == entity)
            .flat_map(|c| {
                c.iter_slices::<String>("SeriesLines:names".into())
                    .flatten()
            })
            .map(|label| label.to_string())
            .collect()
    }

    /// The rows of `entity`'s `component` on `sim_time`, in time order: (time in ns, the row's
    /// numbers). `N` is 0 for a component of `f64`s, or the size of its `f32` arrays; `strips`
    /// reads a line strip's points (`[f32; 2]`).
    fn values<const N: usize>(
        &self,
        entity: &str,
        component: &'static str,
    ) -> Vec<(i64, Vec<f64>)> {
        let mut rows = Vec::new();
        for chunk in &self.chunks {
            if chunk.entity_path().to_string().trim_start_matches('/') != entity {
                continue;
            }
            let id = component.into();
            let times = chunk.iter_component_indices("sim_time".into(), id);
            let numbers: Vec<Vec<f64>> = if component.ends_with(":strips") {
                chunk
                    .iter_slices::<&[[f32; 2]]>(id)
                    .map(|strips| {
                        strips
                            .iter()
                            .flat_map(|s| s.iter().flatten())
                            .map(|&x| f64::from(x))
                            .collect()
                    })
                    .collect()
            } else if N == 0 {
                chunk
                    .iter_slices::<f64>(id)
                    .map(|row| row.to_vec())
                    .collect()
            } else {
                chunk
                    .iter_slices::<[f32; N]>(id)
                    .map(|row| row.iter().flatten().map(|&x| f64::from(x)).collect())
                    .collect()
            };
            rows.extend(times.map(|(t, _)| t.as_i64()).zip(numbers));
        }
        rows.sort_by_key(|r| r.0);
        rows
    }
}

#[test]
fn run_writes_a_recording_that_decodes_with_every_entity_and_a_json_summary() {
    let dir = tempfile::tempdir().unwrap();
    let rrd = dir.path().join("room.rrd");
    let json = dir.path().join("summary.json");
    let args = [
        "-o",
        "room.rrd",
        "--json",
        "summary.json",
        "--set",
        "duration=8",
    ];
    let out = run_room(dir.path(), &args);
    common::assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("robot") && stdout.contains("reached"),
        "{stdout}"
    );

    let recording = Recording::read(&rrd);
    recording.assert_has(&[
        "world/box",
        "world/walls",
        "agents/robot/field/potential",
        "agents/robot/field/guidance",
        "agents/robot/kinematic_path",
        "agents/robot/target",
        "agents/robot/body",
        "agents/robot/trail",
        "agents/robot/body/velocity",
        "agents/robot/body/force",
        "agents/robot/contacts",
        "plots/robot/distance",
        "plots/robot/speed",
        "plots/robot/force",
        "plots/robot/potential",
    ]);
    assert!(recording.timelines.contains("sim_time"));
    // Every step of the 8 s is there: where the body is and its arrows.
    for (e, component) in [
        ("agents/robot/body", "Transform3D:translation"),
        ("agents/robot/body/velocity", "Arrows2D:vectors"),
        ("agents/robot/body/force", "Arrows2D:vectors"),
    ] {
        assert_eq!(recording.rows(e, component), 800, "{e}");
    }
    let body = recording.values::<3>("agents/robot/body", "Transform3D:translation");
    // The trail: 32 segments of 25 steps, each starting where the one before ended, together
    // every position once.
    let segments = recording.values::<2>("agents/robot/trail", "LineStrips2D:strips");
    assert_eq!(segments.len(), 32);
    let mut trail: Vec<f64> = Vec::new();
    for (k, (_, points)) in segments.iter().enumerate() {
        if k > 0 {
            assert_eq!(
                points[..2],
                trail[trail.len() - 2..],
                "segment {k} is not joined"
            );
        }
        trail.extend_from_slice(&points[if k == 0 { 0 } else { 2 }..]);
    }
    let positions: Vec<f64> = body.iter().flat_map(|(_, p)| [p[0], p[1]]).collect();
    assert_eq!(trail, positions);
    // A plot keeps the rows where its value changes: at every step, its latest row is the
    // distance from where the body is to the target (f32 positions: within 1e-4 m).
    let distance = recording.values::<0>("plots/robot/distance", "Scalars:scalars");
    assert!(distance.len() > 1 && distance.len() <= 800);
    let world = nadf::world::load(&world_path("room-two-dividers.toml"), &[]).unwrap();
    let target = world.agents[0].target;
    for (t, p) in &body {
        let latest = distance.iter().rev().find(|(s, _)| s <= t).expect("a row");
        let d = (p[0] - target[0]).hypot(p[1] - target[1]);
        assert!(
            (latest.1[0] - d).abs() < 1e-4,
            "at {t} ns: {} against {d}",
            latest.1[0]
        );
    }
    // Only the finished files are left: no `.partial`.
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["room.rrd", "summary.json"]);

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(summary["world"], "room-two-dividers");
    let agent = summary["agents"][0].as_object().unwrap();
    // The keys are the summary's declared metrics (faults nested under `faults`), and its name.
    let mut keys = BTreeSet::new();
    for (key, value) in agent {
        match value.as_object() {
            Some(group) => keys.extend(group.keys().map(String::as_str)),
            None => {
                keys.insert(key.as_str());
            }
        }
    }
    let mut expected: BTreeSet<&str> = nadf::metrics::metrics_of::<nadf::metrics::Summary>()
        .iter()
        .map(|m| m.key)
        .collect();
    expected.insert("name");
    assert_eq!(keys, expected);
    assert!(agent["faults"].is_object());
    assert_eq!(agent["name"], "robot");
    assert_eq!(agent["contacts"], 0);
}

#[test]
fn no_record_writes_nothing_and_the_default_recording_is_named_after_the_world() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_room(dir.path(), &["--set", "duration=8", "--no-record"]);
    common::assert_success(&out);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

    let out = run_room(dir.path(), &["--set", "duration=8"]);
    common::assert_success(&out);
    let rrd = dir.path().join("room-two-dividers.rrd");
    assert!(rrd.is_file());
    assert!(Recording::read(&rrd).has("agents/robot/body"));
}

#[test]
fn check_accepts_every_shipped_world() {
    let worlds: Vec<_> = std::fs::read_dir(world_path(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    assert!(worlds.len() >= 3);
    let out = Command::new(nadf_bin())
        .arg("check")
        .args(&worlds)
        .output()
        .unwrap();
    common::assert_success(&out);
    // Each file's line counts its bodies by kind.
    let stdout = String::from_utf8_lossy(&out.stdout);
    for (world, bodies) in [
        ("arm-post.toml", "0 agent(s), 1 arm(s)"),
        ("pendulum.toml", "0 agent(s), 1 pendulum(s)"),
        ("couch-door.toml", "1 agent(s), 2 wall(s)"),
    ] {
        assert!(
            stdout
                .lines()
                .any(|l| l.contains(world) && l.contains(bodies)),
            "{world}: {stdout}"
        );
    }
}

/// A door 0.7 m wide for a 0.6 m robot leaves 0.1 m of free configuration space, two cells of
/// 0.05 m: `nadf check` warns of it, where it is; the paper's room has no such passage.
#[test]
fn check_warns_of_a_narrow_passage_on_the_kinematic_path_and_where_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let door = dir.path().join("door.toml");
    std::fs::write(
        &door,
        "size = [6.0, 4.0]\n\
         [[walls]]\nshape = \"box\"\ncenter = [3.0, 0.825]\nhalf_extents = [0.1, 0.825]\n\
         [[walls]]\nshape = \"box\"\ncenter = [3.0, 3.175]\nhalf_extents = [0.1, 0.825]\n\
         [[agents]]\nname = \"robot\"\nstart = [1.0, 2.0]\ntarget = [5.0, 2.0]\nradius = 0.3\n\
         controller = { kind = \"nadf\", b = 10.0 }\n",
    )
    .unwrap();
    let out = Command::new(nadf_bin())
        .arg("check")
        .arg(&door)
        .arg(world_path("room-two-dividers.toml"))
        .output()
        .unwrap();
    common::assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let warnings: Vec<&str> = stdout
        .lines()
        .filter(|l| l.contains("narrow passage"))
        .collect();
    assert_eq!(warnings.len(), 1, "{stdout}");
    assert!(warnings[0].contains("door.toml"), "{stdout}");
    // Where: in the door (its wall is 0.2 m thick at x = 3 m).
    let at = warnings[0].split("passes [").nth(1).unwrap();
    let (x, y) = at.split_once(", ").unwrap();
    let x: f64 = x.parse().unwrap();
    assert!(
        (2.8..=3.2).contains(&x) && y.starts_with("2.00] m"),
        "{stdout}"
    );
    assert!(warnings[0].contains("2.0 field cells"), "{stdout}");
}

#[test]
fn check_names_the_file_line_and_key_of_every_problem_and_fails() {
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.toml");
    std::fs::write(
        &broken,
        "size = [4.0, 4.0]\n\n[[agents]]\nname = \"r\"\nstart = [1.0, 1.0]\ntarget = [3.0, 3.0]\nmasss = 1.0\n\n[agents.controller]\nkind = \"nadf\"\nb = 1.0\n",
    )
    .unwrap();
    let out = nadf(dir.path(), &["check", "broken.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("broken.toml:7:1"), "{stderr}");
    assert!(
        stderr.contains("masss") && stderr.contains("did you mean `mass`?"),
        "{stderr}"
    );

    // Semantic problems: all of them, each at its line.
    std::fs::write(
        &broken,
        "size = [4.0, 4.0]\n\n[[agents]]\nname = \"r\"\nstart = [1.0, 1.0]\ntarget = [3.0, 3.0]\nmass = -1.0\nradius = 0.0\n\n[agents.controller]\nkind = \"nadf\"\nb = 1.0\n",
    )
    .unwrap();
    let out = nadf(dir.path(), &["check", "broken.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("broken.toml:7:1: `agents.0.mass`"),
        "{stderr}"
    );
    assert!(
        stderr.contains("broken.toml:8:1: `agents.0.radius`"),
        "{stderr}"
    );
}

#[test]
fn a_bad_override_is_named_and_fails_before_running() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_room(dir.path(), &["--set", "agents.3.controller.b=1"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("--set agents.3.controller.b=1"), "{stderr}");
    assert!(stderr.contains("no item 3"), "{stderr}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

    let out = run_room(dir.path(), &["--set", "agents.0.controller.b=-3"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--set agents.0.controller.b=-3"),
        "{stderr}"
    );
}

#[test]
fn an_intractable_task_is_bad_input_naming_the_agent() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(fixture("enclosed.toml"), dir.path().join("enclosed.toml")).unwrap();
    let out = nadf(dir.path(), &["run", "enclosed.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("`boxed-in`") && stderr.contains("cannot be reached"),
        "{stderr}"
    );
    assert!(!dir.path().join("enclosed.rrd").exists());
    assert!(!dir.path().join("enclosed.rrd.partial").exists());

    // `check` finds it without running.
    let out = nadf(dir.path(), &["check", "enclosed.toml"]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("enclosed.toml: agent `boxed-in`"),
        "{stderr}"
    );
}

/// An `.npy` file's header and its data's bytes.
fn read_npy(path: &Path) -> (String, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = String::from_utf8(bytes[10..10 + header_len].to_vec()).unwrap();
    (header, bytes[10 + header_len..].to_vec())
}

/// Checks an exported field's `W` (float64 bytes) against its mask (bytes): 1 on the target
/// set, in (0, 1) on the other reachable cells, 0 on the others; returns how many cells are in
/// the target set, the other reachable cells, and the rest.
fn w_classes(mask: &[u8], w: &[u8]) -> (usize, usize, usize) {
    let w = w
        .chunks(8)
        .map(|b| f64::from_le_bytes(b.try_into().unwrap()));
    let (mut target, mut inside, mut other) = (0, 0, 0);
    for (m, w) in mask.iter().zip(w) {
        match m {
            0 if w == 1.0 => target += 1,
            0 => {
                assert!(w > 0.0 && w < 1.0, "{w}");
                inside += 1;
            }
            _ => {
                assert_eq!(w, 0.0);
                other += 1;
            }
        }
    }
    (target, inside, other)
}

/// A reader that goes away (`nadf field … | head -1`) is not the command's failure: no panic,
/// the files written, exit status 0.
#[test]
fn a_closed_standard_output_is_no_panic() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("room-two-dividers.toml");
    let mut child = Command::new(nadf_bin())
        .current_dir(dir.path())
        .args(["field", world.to_str().unwrap(), "--npy", "room.npy"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Closed before the field is solved, so every line the command says meets a closed pipe.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(dir.path().join("room.mask.npy").is_file());
}

#[test]
fn field_exports_numpy_arrays_and_a_picture() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("room-two-dividers.toml");
    let world = world.to_str().unwrap();
    let out = nadf(
        dir.path(),
        &["field", world, "--npy", "room.npy", "--png", "room.png"],
    );
    common::assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("201 x 201 cells") && stdout.contains("CG iterations"),
        "{stdout}"
    );
    // A room this small is solved whole from the first solve on.
    assert!(!stdout.contains("box around the target"), "{stdout}");

    let npy = |name: &str| read_npy(&dir.path().join(name));
    let (header, v) = npy("room.npy");
    assert!(
        header.contains("'descr': '<f8'") && header.contains("'shape': (201, 201)"),
        "{header}"
    );
    assert_eq!(v.len(), 201 * 201 * 8);
    let (header, w) = npy("room.w.npy");
    assert!(header.contains("'<f8'"));
    let (header, mask) = npy("room.mask.npy");
    assert!(header.contains("'|u1'"), "{header}");
    // V + W = 1 where W is not tiny, and the mask says which cells are blocked.
    for k in (0..201 * 201).step_by(97) {
        let v = f64::from_le_bytes(v[8 * k..8 * k + 8].try_into().unwrap());
        let w = f64::from_le_bytes(w[8 * k..8 * k + 8].try_into().unwrap());
        assert!((v + w - 1.0).abs() < 1e-15);
        assert!(mask[k] <= 2);
        if mask[k] == 1 {
            assert_eq!(w, 0.0);
        }
    }
    assert!(mask.contains(&1) && mask.contains(&0));

    let png = std::fs::File::open(dir.path().join("room.png")).unwrap();
    let reader = png::Decoder::new(std::io::BufReader::new(png))
        .read_info()
        .unwrap();
    assert_eq!((reader.info().width, reader.info().height), (804, 804));

    let out = nadf(dir.path(), &["field", world, "--agent", "nobody"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("no agent or arm `nobody`; the world has: robot")
    );
}

#[test]
fn recordings_show_clamping_bias_speed_limit_and_sensed_walls() {
    let dir = tempfile::tempdir().unwrap();
    // An entity, or `ENTITY[LABEL]`: a series of that plot.
    let cases: [(&str, &[&str], &[&str]); 8] = [
        (
            "room-speed-limit.toml",
            &["plots/robot/limits[speed limit active]", "summary"],
            &["plots/robot/limits[clamping active]", "plots/robot/bias"],
        ),
        (
            "room-drift-bias.toml",
            &[
                "plots/robot/limits[clamping active]",
                "plots/robot/bias[β x (N)]",
                "plots/robot/bias[β y (N)]",
                "agents/robot/events",
            ],
            &[
                "plots/robot/limits[speed limit active]",
                "agents/robot/sensed_walls",
            ],
        ),
        (
            "room-drift-noise.toml",
            &[
                "plots/robot/limits[clamping active]",
                "agents/robot/sensed_walls",
            ],
            &["plots/robot/bias"],
        ),
        (
            "pendulum-bias.toml",
            &[
                "world/pendulums/pendulum/rod",
                "world/pendulums/pendulum/bob",
                "world/pendulums/pendulum/events",
                "plots/pendulum/theta[θ (rad)]",
                "plots/pendulum/theta[θ_T (rad)]",
                "plots/pendulum/torque",
                "plots/pendulum/bias",
            ],
            &["agents/robot/body"],
        ),
        (
            // Khatib's field has no grid: arrows, no potential image.
            "corridor-obstruction.toml",
            &["agents/robot/field/guidance", "agents/robot/kinematic_path"],
            &["agents/robot/field/potential"],
        ),
        (
            "swap.toml",
            &["agents/robot1/body", "agents/robot2/body"],
            &[],
        ),
        (
            // A lidar: its rays, its map and the field re-solved on it.
            "unknown-room.toml",
            &[
                "agents/robot/lidar/scan",
                "agents/robot/lidar/map",
                "agents/robot/field/potential",
            ],
            &["agents/robot/sensed_walls"],
        ),
        (
            // A map is one image; its walls are not outlined one by one.
            "map-office.toml",
            &["world/map", "world/walls", "agents/robot/body"],
            &[],
        ),
    ];
    for (world, present, absent) in cases {
        let path = world_path(world);
        // Long enough for each world's [expect] table to hold.
        let duration = if world.starts_with("corridor") {
            "duration=20"
        } else {
            "duration=8"
        };
        let out = nadf(
            dir.path(),
            &[
                "run",
                path.to_str().unwrap(),
                "-o",
                "r.rrd",
                "--set",
                duration,
            ],
        );
        common::assert_success(&out);
        let recording = Recording::read(&dir.path().join("r.rrd"));
        for e in present {
            assert!(
                recording.has(e),
                "{world}: no `{e}` in {:?}",
                recording.rows.keys()
            );
        }
        for e in absent {
            assert!(!recording.has(e), "{world}: unexpected `{e}`");
        }
        // The layout: every plot view shows the whole run (its time axis is set), every
        // agent's trail shows up to the cursor, and a world far longer than wide (the corridor)
        // has a second view that follows the agent, with its bounds; the room has not.
        let set = |suffix: &str| {
            (recording.layout.iter())
                .filter(|e| e.ends_with(suffix))
                .count()
        };
        // One view per plot, whoever has it.
        let plots = (recording.rows.keys())
            .filter_map(|e| {
                e.strip_prefix("plots/")?
                    .split_once('/')
                    .map(|(_, key)| key)
            })
            .collect::<BTreeSet<_>>()
            .len();
        assert_eq!(set("/TimeAxis"), plots, "{world}: {:?}", recording.layout);
        let trails = (recording.rows.keys())
            .filter(|e| e.ends_with("/trail"))
            .count();
        let follows = usize::from(world.starts_with("corridor"));
        assert_eq!(set("/trail/visualizers"), trails * (1 + follows), "{world}");
        assert_eq!(set("/VisualBounds2D"), follows, "{world}");
    }
}

/// Seven simulated minutes of a 192 m world (the arena at 4 m a cell, `worlds/map-arena-200.toml`)
/// record every step in under 10 MB, with a view that follows the robot.
#[test]
fn a_seven_minute_run_of_a_192_m_world_records_every_step_in_under_10_mb() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("map-arena-200.toml");
    let out = nadf(dir.path(), &["run", world.to_str().unwrap(), "-o", "a.rrd"]);
    common::assert_success(&out);
    let rrd = dir.path().join("a.rrd");
    let size = std::fs::metadata(&rrd).unwrap().len();
    assert!(size < 10_000_000, "{size} bytes");
    let recording = Recording::read(&rrd);
    for (e, component) in [
        ("agents/robot/body", "Transform3D:translation"),
        ("agents/robot/body/force", "Arrows2D:vectors"),
    ] {
        assert_eq!(recording.rows(e, component), 42_000, "{e}");
    }
    assert_eq!(
        recording
            .values::<2>("agents/robot/trail", "LineStrips2D:strips")
            .len(),
        42_000 / 25
    );
    assert!(
        recording
            .layout
            .iter()
            .any(|e| e.ends_with("/VisualBounds2D"))
    );
}

/// An output that cannot be written is bad input (exit 2), found before anything is solved or
/// simulated: nothing is printed on standard output and nothing is left behind.
#[test]
fn outputs_that_cannot_be_written_are_bad_input_found_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let long = ["--set", "duration=100000"];
    for args in [
        vec!["-o", "missing/x.rrd"],
        vec!["--no-record", "--json", "missing/s.json"],
        vec!["-o", "."],
    ] {
        let mut all = args.clone();
        all.extend_from_slice(&long);
        let out = run_room(dir.path(), &all);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("cannot write"), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}: the run started");
    }
    let world = world_path("room-two-dividers.toml");
    let world = world.to_str().unwrap();
    let out = nadf(dir.path(), &["field", world, "--png", "missing/f.png"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty(), "the field was solved");
    // A sweep's directory under a file.
    std::fs::write(dir.path().join("sweep.csv"), "").unwrap();
    let out = nadf(
        dir.path(),
        &[
            "sweep",
            world,
            "--set-range",
            "agents.0.controller.b=1:2:2",
            "--out",
            "sweep.csv/x",
        ],
    );
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty());
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["sweep.csv"]);
}

/// `--connect URL` streams a run, as it goes, to a running viewer: here a `rerun` process
/// listening on a free port and saving what it receives (`rerun --port P --save FILE`), whose
/// file then holds the run. With `-o` the file is written as well. Skipped, saying why, only
/// when no `rerun` executable is installed (`.ci/run` installs the matching one).
#[test]
fn connect_streams_the_run_to_a_running_viewer() {
    if Command::new("rerun").arg("--version").output().is_err() {
        eprintln!("skipped: no `rerun` executable on the PATH (pip install rerun-sdk==0.36.3)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let received = dir.path().join("received.rrd");
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut viewer = Command::new("rerun")
        .args(["--port", &port.to_string(), "--save"])
        .arg(&received)
        .env("RUST_LOG", "warn")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            started.elapsed().as_secs() < 30,
            "the viewer never listened"
        );
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let url = format!("rerun+http://127.0.0.1:{port}/proxy");
    let out = run_room(
        dir.path(),
        &["--connect", &url, "-o", "also.rrd", "--set", "duration=8"],
    );
    common::assert_success(&out);
    // The viewer writes what it receives as it comes: wait for the last step's columns.
    let has_run = |path: &Path| {
        path.exists()
            && Recording::read(path).rows("agents/robot/body", "Transform3D:translation") == 800
    };
    let started = std::time::Instant::now();
    while !has_run(&received) && started.elapsed().as_secs() < 30 {
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
    let _ = viewer.kill();
    let _ = viewer.wait();
    assert!(
        has_run(&received),
        "the viewer did not receive all 800 steps"
    );
    let recording = Recording::read(&received);
    recording.assert_has(&[
        "world/walls",
        "agents/robot/field/potential",
        "plots/robot/distance",
    ]);
    // The layout came too.
    assert!(recording.layout.iter().any(|e| e.ends_with("/TimeAxis")));
    assert!(has_run(&dir.path().join("also.rrd")));
}

/// `--spawn` without a viewer installed fails before anything is simulated, saying how to
/// install the matching one; `--connect` to something that is not a viewer's URL too.
#[test]
fn spawn_without_a_viewer_and_a_bad_url_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("room-two-dividers.toml");
    let out = Command::new(nadf_bin())
        .current_dir(dir.path())
        .args(["run", world.to_str().unwrap(), "--spawn"])
        .env("PATH", dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("cannot start a Rerun viewer")
            && stderr.contains("pip install rerun-sdk==0.36.3"),
        "{stderr}"
    );
    let out = run_room(
        dir.path(),
        &["--connect", "http://example.com/not-a-viewer"],
    );
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("cannot stream to `http://example.com/not-a-viewer`"),
        "{stderr}"
    );
    // Nothing listening there: said before the run (not as a failed flush when it ends).
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let url = format!("rerun+http://127.0.0.1:{port}/proxy");
    let out = run_room(dir.path(), &["--connect", &url]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("no Rerun viewer is listening at"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// A shaped agent's run (issue 26): its recording has the shape in its moving frame (a
/// transform per step), the kinematic path with its heading marks, the field's slice and the
/// heading plot; `nadf field` exports its (x, y, θ) field as `[nx, ny, headings]` arrays.
#[test]
fn a_shaped_agents_run_is_recorded_and_its_field_exported() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("couch-door.toml");
    let world = world.to_str().unwrap();
    let out = nadf(
        dir.path(),
        // Two seconds: on its way, not there yet.
        &[
            "run",
            world,
            "--set",
            "duration=2",
            "--set",
            "expect.reached=false",
            "-o",
            "couch.rrd",
        ],
    );
    common::assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("x 96 headings") && stdout.contains("couch"),
        "{stdout}"
    );
    let recording = Recording::read(&dir.path().join("couch.rrd"));
    recording.assert_has(&[
        "agents/couch/body/shape",
        "agents/couch/kinematic_path",
        "agents/couch/kinematic_poses",
        "agents/couch/target",
        "agents/couch/field/potential",
        "plots/couch/heading[θ (rad)]",
        "plots/couch/heading[θ − θ_T (rad)]",
    ]);
    // 2 s at 5 ms: a pose per step.
    assert_eq!(
        recording.rows("agents/couch/body", "Transform3D:rotation_axis_angle"),
        400
    );
    let out = nadf(
        dir.path(),
        &["field", world, "--npy", "couch.npy", "--png", "couch.png"],
    );
    common::assert_success(&out);
    let read = |name: &str| read_npy(&dir.path().join(name));
    let (header, mask) = read("couch.mask.npy");
    assert!(header.contains("'shape': (161, 101, 96)"), "{header}");
    let (_, w) = read("couch.w.npy");
    let (target, inside, _) = w_classes(&mask, &w);
    assert!(target > 0 && inside > 100_000, "{target} {inside}");
    assert!(dir.path().join("couch.png").is_file());
}

/// The recording of the first second of an arm world's run (its expectation of reaching
/// lifted).
fn arm_recording(name: &str) -> Recording {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path(name);
    let out = nadf(
        dir.path(),
        &[
            "run",
            world.to_str().unwrap(),
            "--set",
            "duration=1",
            "--set",
            "arms.0.expect.reached=false",
            "-o",
            "arm.rrd",
        ],
    );
    common::assert_success(&out);
    Recording::read(&dir.path().join("arm.rrd"))
}

/// An arm's run (issue 27) is recorded: its links per step, its tip's trail, its joint-space
/// field and path (two links), and its joint angles and torques.
#[test]
fn an_arms_run_is_recorded_with_its_joint_space() {
    let recording = arm_recording("arm-post.toml");
    recording.assert_has(&[
        "world/arms/arm/links",
        "world/arms/arm/trail",
        "world/arms/arm/target",
        "joint_space/arm/field",
        "joint_space/arm/path",
        "plots/arm/joints[q1 (rad)]",
        "plots/arm/torques[τ2 (N·m)]",
    ]);
    // One second at 2 ms: the links at every step.
    assert_eq!(
        recording.rows("world/arms/arm/links", "LineStrips2D:strips"),
        500
    );
}

/// A three-link arm's joint space is recorded as the slice through its first joint's angle,
/// re-logged as the arm turns into another cell of it (arm-shelf turns its first joint by
/// about 0.6 rad in its first second: several slices), with the path projected on it.
#[test]
fn a_three_link_arms_joint_space_is_the_slice_through_its_first_joint() {
    let recording = arm_recording("arm-shelf.toml");
    recording.assert_has(&["joint_space/arm/field", "joint_space/arm/path"]);
    let slices = recording.rows("joint_space/arm/field", "Image:buffer");
    println!("{slices} slices");
    assert!((3..500).contains(&slices), "{slices} slices");
}

/// `nadf field` on an arm world exports its joint-space field: one axis per joint, `W = 1` on the
/// target set and in (0, 1) elsewhere on the reachable cells, the post's configurations blocked,
/// and a picture of the joint space.
#[test]
fn field_exports_an_arms_joint_space() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("arm-post.toml");
    let world = world.to_str().unwrap();
    let out = nadf(
        dir.path(),
        &["field", world, "--npy", "arm.npy", "--png", "arm.png"],
    );
    common::assert_success(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("256 x 256 joint cells"), "{stdout}");
    let (header, mask) = read_npy(&dir.path().join("arm.mask.npy"));
    assert!(header.contains("'shape': (256, 256)"), "{header}");
    let (_, w) = read_npy(&dir.path().join("arm.w.npy"));
    let (target, inside, blocked) = w_classes(&mask, &w);
    assert!(
        target > 0 && inside > 50_000 && blocked > 1_000,
        "{target} {inside} {blocked}"
    );
    let png = std::fs::File::open(dir.path().join("arm.png")).unwrap();
    let reader = png::Decoder::new(std::io::BufReader::new(png))
        .read_info()
        .unwrap();
    assert_eq!((reader.info().width, reader.info().height), (512, 512));
    let out = nadf(dir.path(), &["field", world, "--agent", "nobody"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("no agent or arm `nobody`; the world has: arm")
    );
}

/// A robot on wheels is recorded with its footprint turned by its heading at every step, its
/// look-ahead point as the body, and its wheels' speeds and forces and its heading plotted.
#[test]
fn a_robot_on_wheels_is_recorded_with_its_footprint_and_wheels() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("burger-dead-end.toml");
    let out = nadf(
        dir.path(),
        &[
            "run",
            world.to_str().unwrap(),
            "--set",
            "duration=2",
            "--set",
            "expect.reached=false",
            "-o",
            "wheels.rrd",
        ],
    );
    common::assert_success(&out);
    let recording = Recording::read(&dir.path().join("wheels.rrd"));
    recording.assert_has(&[
        "agents/burger/footprint",
        "agents/burger/body",
        "plots/burger/wheel_speeds[left wheel (m/s)]",
        "plots/burger/wheel_forces[grip (N)]",
        "plots/burger/heading[heading (rad)]",
    ]);
    // Two seconds at 10 ms: the footprint's frame at every step.
    assert_eq!(
        recording.rows("agents/burger/footprint", "Transform3D:rotation_axis_angle"),
        200
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("wheel_mps") && stdout.contains("slip_mps"),
        "{stdout}"
    );
}

/// A moving obstacle is drawn where it is at each instant (its frame, a row a step, with its
/// shape in it), with its path; the robot's guidance is re-logged as it replans around it.
#[test]
fn the_recording_shows_the_obstacles_where_they_are_and_the_guidance_as_it_replans() {
    let dir = tempfile::tempdir().unwrap();
    let world = world_path("corridor-walker.toml");
    let args = ["run", world.to_str().unwrap(), "--set", "duration=3"];
    let out = nadf(
        dir.path(),
        &[&args[..], &["--set", "expect.reached=false", "-o", "w.rrd"]].concat(),
    );
    common::assert_success(&out);
    let recording = Recording::read(&dir.path().join("w.rrd"));
    recording.assert_has(&[
        "world/obstacles/person/body",
        "world/obstacles/person/body/shape",
        "world/obstacles/person/path",
    ]);
    // 3 s at 10 ms: a pose per step, on the script: up from (6, 1) at 1.2 m/s.
    let poses = recording.values::<3>("world/obstacles/person/body", "Transform3D:translation");
    assert_eq!(poses.len(), 300);
    for (ns, p) in &poses {
        let t = *ns as f64 * 1e-9;
        assert!(
            (p[0] - 6.0).abs() < 1e-6 && (p[1] - (1.0 + 1.2 * t)).abs() < 1e-4,
            "{t}: {p:?}"
        );
    }
    // The guidance at the start and then about once a second of replanning.
    let arrows = recording.rows("agents/robot/field/guidance", "Arrows2D:vectors");
    assert!((3..=4).contains(&arrows), "{arrows}");
}
