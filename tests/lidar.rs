//! Unknown worlds (issue "unknown worlds"): a lidar of Rapier ray casts, a map built online, the
//! harmonic field re-solved on what was seen, and intractability found online.

mod common;

use nadf::sim::Simulation;
use nadf::world::all_wall_shapes;

/// The room and the spiral maze, with a 3 m lidar in worlds of 10 m and 20 m: the robot reaches
/// its target without touching anything, on a path not much longer than with full knowledge.
#[test]
fn the_robot_reaches_its_target_in_unknown_worlds_without_contact() {
    for (world, longest) in [("unknown-room.toml", 1.2), ("unknown-maze.toml", 1.1)] {
        let w = common::world(world, &[]);
        let range = w.agents[0].sensor.unwrap().range.unwrap();
        assert!(range < 0.35 * w.size[0].min(w.size[1]), "{world}");
        let s = common::summary_of(&w);
        assert!(s.reached && s.contacts == 0, "{world}: {s:?}");
        assert_eq!(s.intractable, None, "{world}");
        // Measured: 12.10 m against 10.93 m (room), 105.1 m against 101.7 m (maze).
        let full = s.kinematic_length.unwrap();
        assert!(
            s.path_length < longest * full,
            "{world}: {} m vs {full} m",
            s.path_length
        );
        assert!(s.resolves > 10, "{world}: {s:?}");
        let seen = s.map_seen.unwrap();
        assert!(seen > 0.2 && seen < 1.0, "{world}: {seen}");
    }
}

/// The known map marks free only cells whose centres are outside the walls, but for what the
/// grid (a cell's centre can be up to a cell inside the face a ray stopped at) and the noise
/// (three standard deviations) explain.
#[test]
fn the_known_map_never_frees_a_wall_beyond_what_the_noise_explains() {
    for noise in [0.0, 0.03] {
        let world = common::world(
            "unknown-room.toml",
            &[&format!("agents.0.sensor.noise={noise}"), "duration=8"],
        );
        let mut sim = Simulation::new(&world).unwrap();
        while !sim.finished() {
            sim.step();
        }
        let map = &sim.agents[0].lidar.as_ref().unwrap().map;
        let grid = *map.grid();
        let walls = all_wall_shapes(&world);
        let mut free_seen = 0;
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let k = grid.index(i, j);
                if !map.seen()[k] || map.occupied()[k] {
                    continue;
                }
                free_seen += 1;
                let [x, y] = grid.center(i, j);
                let depth = walls
                    .iter()
                    .map(|w| -w.signed_distance_to_point(x, y))
                    .fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    depth <= grid.cell + 3.0 * noise,
                    "noise {noise}: cell at ({x:.2}, {y:.2}) is free but {depth:.3} m inside a wall"
                );
            }
        }
        assert!(free_seen > 1000, "{free_seen}");
    }
}

/// A target enclosed by walls is found intractable online: the run says when, the robot stops,
/// and nothing is touched. `nadf run` does not refuse the world beforehand.
#[test]
fn an_enclosed_target_is_found_intractable_online() {
    let s = common::summary("unknown-enclosed.toml", &[]);
    let at = s.intractable.expect("found intractable");
    // Measured: 7.3 s, after seeing 86 % of the room.
    assert!(at > 1.0 && at < 20.0, "{s:?}");
    assert!(
        !s.reached && s.contacts == 0 && s.final_speed < 1e-3,
        "{s:?}"
    );
    let run = std::process::Command::new(common::nadf_bin())
        .arg("run")
        .arg(common::world_path("unknown-enclosed.toml"))
        .arg("--no-record")
        .output()
        .unwrap();
    common::assert_success(&run);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("intractable"), "{stdout}");
    // `nadf check` accepts the world, and says what full knowledge would have shown.
    let check = std::process::Command::new(common::nadf_bin())
        .arg("check")
        .arg(common::world_path("unknown-enclosed.toml"))
        .output()
        .unwrap();
    common::assert_success(&check);
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert!(
        stdout.contains("note: with full knowledge") && stdout.contains("find out online"),
        "{stdout}"
    );
}

/// With range noise and dropouts, the same seed gives the same run and another seed another.
#[test]
fn a_noisy_lidar_is_reproducible_for_a_seed() {
    let noisy = ["agents.0.sensor.noise=0.02", "agents.0.sensor.dropout=0.1"];
    let a = common::summary("unknown-room.toml", &noisy);
    let b = common::summary("unknown-room.toml", &noisy);
    assert_eq!(a, b);
    let c = common::summary("unknown-room.toml", &[noisy[0], noisy[1], "seed=7"]);
    assert_ne!(a, c);
    assert!(
        a.reached && a.contacts == 0 && c.reached && c.contacts == 0,
        "{a:?} {c:?}"
    );
}

/// Bad lidar settings are located errors.
#[test]
fn bad_lidar_settings_are_located_errors() {
    for (set, key) in [
        ("agents.0.sensor.range=0", "agents.0.sensor.range"),
        ("agents.0.sensor.range=-3", "agents.0.sensor.range"),
        ("agents.0.sensor.rays=0", "agents.0.sensor.rays"),
        ("agents.0.sensor.rate=0", "agents.0.sensor.rate"),
        ("agents.0.sensor.fov=0", "agents.0.sensor.fov"),
        ("agents.0.sensor.fov=400", "agents.0.sensor.fov"),
        ("agents.0.sensor.dropout=1", "agents.0.sensor.dropout"),
        (
            "field.kind=\"attractive-repulsive\"",
            "agents.0.sensor.kind",
        ),
    ] {
        let path = common::world_path("unknown-room.toml");
        let e = nadf::world::load(&path, &[set.parse().unwrap()])
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("`{key}`")), "{set}: {e}");
    }
    // A walls sensor has no range.
    let e = nadf::world::load(
        &common::world_path("room-drift-noise.toml"),
        &["agents.0.sensor.range=3".parse().unwrap()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("only a lidar has `range`"), "{e}");
}

/// A lidar agent driven by a commanded force (a policy's, from Python) does not re-solve its
/// field at each change of its map: the change is solved for when the law's force is asked
/// for, or at the first step after control comes back. The law's force after the one put-off
/// solve is the one it is after solving at every change (to the solver's tolerance).
#[test]
fn a_commanded_lidar_agent_solves_its_field_only_when_it_is_read() {
    let world = common::world("unknown-room.toml", &["duration=3"]);
    let fields = |sim: &Simulation| sim.agents[0].lidar.as_ref().unwrap().fields;
    let seen = |sim: &Simulation| sim.agents[0].lidar.as_ref().unwrap().map.seen().to_vec();
    let mut eager = Simulation::new(&world).unwrap();
    let mut lazy = Simulation::new(&world).unwrap();
    // Towards the target at a quarter of the law's first force, held for 1.5 s.
    let force = eager.law_force(0).unwrap() * 0.25;
    for sim in [&mut eager, &mut lazy] {
        assert!(sim.agents[0].command(Some(force)));
    }
    let first = fields(&lazy);
    for _ in 0..150 {
        eager.step();
        lazy.step();
        eager.law_force(0).unwrap();
    }
    assert_eq!(seen(&eager), seen(&lazy), "the same scans");
    assert_ne!(seen(&lazy), {
        let fresh = Simulation::new(&world).unwrap();
        seen(&fresh)
    });
    assert!(fields(&eager) > first + 3, "{} fields", fields(&eager));
    assert_eq!(
        fields(&lazy),
        first,
        "nothing solved while commanded and unread"
    );
    let (a, b) = (eager.law_force(0).unwrap(), lazy.law_force(0).unwrap());
    assert_eq!(
        fields(&lazy),
        first + 1,
        "one solve for every change put off"
    );
    assert!((a - b).norm() < 1e-6 * a.norm(), "{a} vs {b}");
    // Control back: the first step solves for what was put off since.
    let mut back = Simulation::new(&world).unwrap();
    assert!(back.agents[0].command(Some(force)));
    for _ in 0..150 {
        back.step();
    }
    assert_eq!(fields(&back), first);
    assert!(back.agents[0].command(None));
    back.step();
    assert_eq!(fields(&back), first + 1);
}
