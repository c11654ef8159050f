//! Maps as worlds: ROS `map_server` occupancy grids and Moving AI grid maps load into walls that
//! agree with their cells, malformed map files are located errors, a corner target is reached
//! without a touch only with the braking envelope, and a generated perfect maze whose field
//! goes far below f64 still guides from everywhere.

mod common;

use std::path::Path;

use nadf::field::HarmonicField;
use nadf::world::map::perfect_maze;
use nadf::world::{all_walls, load, wall_shape};

/// Every map cell's centre is inside one of the map's walls exactly when the map says the cell
/// is blocked; and those walls are among the world's colliders.
fn colliders_agree_with_cells(world: &nadf::world::World) {
    let loaded = world.loaded_map.as_ref().expect("a map");
    let map = &loaded.occupancy;
    let walls: Vec<_> = loaded.walls.iter().filter_map(wall_shape).collect();
    assert!(all_walls(world).len() >= walls.len() && !walls.is_empty());
    for j in 0..map.height {
        for i in 0..map.width {
            let [x, y] = map.center(i, j);
            let inside = walls
                .iter()
                .any(|w| w.signed_distance_to_point(x, y) < -1e-4);
            assert_eq!(inside, map.blocked(i, j), "cell ({i}, {j}) at ({x}, {y})");
        }
    }
}

#[test]
fn a_moving_ai_map_becomes_walls_that_agree_with_its_cells() {
    let world = common::world("map-arena.toml", &[]);
    assert_eq!((world.size, world.origin), ([48.0, 48.0], [0.0, 0.0]));
    let map = &world.loaded_map.as_ref().unwrap();
    // Merged: far fewer boxes than blocked cells.
    let blocked = (0..48)
        .flat_map(|j| (0..48).map(move |i| (i, j)))
        .filter(|&(i, j)| map.occupancy.blocked(i, j))
        .count();
    assert!(map.walls.len() * 3 < blocked, "{} boxes", map.walls.len());
    colliders_agree_with_cells(&world);
}

#[test]
fn a_ros_map_keeps_its_origin_and_its_unknown_space_is_blocked_by_default() {
    let world = common::world("map-office.toml", &[]);
    assert_eq!(world.origin, [-2.0, -1.0]);
    assert!((world.size[0] - 12.0).abs() < 1e-12 && (world.size[1] - 8.0).abs() < 1e-12);
    colliders_agree_with_cells(&world);
    // Outside the building the map is unknown: a wall by default, free space when asked.
    let outside = [-1.5, -0.5];
    let map = &world.loaded_map.as_ref().unwrap().occupancy;
    let (i, j) = map.cell_of(outside).unwrap();
    assert!(map.blocked(i, j));
    let free = common::world("map-office.toml", &["map.unknown=free"]);
    let map = &free.loaded_map.as_ref().unwrap().occupancy;
    assert!(!map.blocked(i, j));
    colliders_agree_with_cells(&free);
}

/// The measured problem: NADF alone crosses the arena at speed and overshoots the corner target
/// into the walls; the clearance envelope keeps it off them, and the braking envelope stops it
/// on the target.
#[test]
fn a_corner_target_is_reached_without_a_touch_only_with_an_envelope() {
    let mut world = common::world("map-arena.toml", &["agents.0.controller.envelope=false"]);
    world.agents[0].controller.brake = None;
    let without = common::summary_of(&world);
    assert!(without.contacts > 0, "{without:?}");
    assert!(without.peak_speed > 8.0, "{without:?}");
    world.agents[0].controller.envelope = true;
    let clear = common::summary_of(&world);
    assert!(clear.reached && clear.contacts == 0, "{clear:?}");
    assert!(clear.envelope_time > 0.0, "{clear:?}");
    assert!(clear.min_clearance.is_some_and(|c| c > 0.0), "{clear:?}");
    let with = common::summary("map-arena.toml", &[]);
    assert!(with.reached, "{with:?}");
    assert_eq!(with.contacts, 0, "{with:?}");
    assert!(with.final_speed < 0.1, "{with:?}");
}

/// Writes a world with `[map]` and the map's files into a temporary directory.
fn world_with_map(dir: &Path, map_key: &str, files: &[(&str, &[u8])]) -> std::path::PathBuf {
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let world = dir.join("w.toml");
    std::fs::write(
        &world,
        format!(
            "duration = 1.0\n\n[map]\nfile = \"{map_key}\"\n\n[[agents]]\nname = \"r\"\nstart = [1.5, 1.5]\ntarget = [2.5, 1.5]\nradius = 0.3\n\n[agents.controller]\nkind = \"nadf\"\nb = 5.0\n"
        ),
    )
    .unwrap();
    world
}

#[test]
fn malformed_maps_are_errors_that_name_the_world_line_and_the_map_file() {
    let dir = tempfile::tempdir().unwrap();
    let short = b"type octile\nheight 4\nwidth 4\nmap\n@@@@\n@..\n@..@\n@@@@\n";
    let world = world_with_map(dir.path(), "short.map", &[("short.map", short)]);
    let e = load(&world, &[]).unwrap_err().to_string();
    assert!(e.contains("w.toml:4:1: `map.file`"), "{e}");
    assert!(e.contains("short.map:6:4: row 2 has 3 cells"), "{e}");

    let mut pgm = b"P5\n4 4\n255\n".to_vec();
    pgm.extend_from_slice(&[254; 12]);
    let yaml = b"image: m.pgm\nresolution: 1.0\norigin: [0.0, 0.0, 0.0]\n";
    let world = world_with_map(dir.path(), "m.yaml", &[("m.pgm", &pgm), ("m.yaml", yaml)]);
    let e = load(&world, &[]).unwrap_err().to_string();
    assert!(e.contains("m.pgm") && e.contains("truncated"), "{e}");

    let no_resolution = b"image: m.pgm\norigin: [0.0, 0.0, 0.0]\n";
    let world = world_with_map(dir.path(), "r.yaml", &[("r.yaml", no_resolution)]);
    let e = load(&world, &[]).unwrap_err().to_string();
    assert!(
        e.contains("r.yaml") && e.contains("missing key `resolution`"),
        "{e}"
    );

    let world = world_with_map(dir.path(), "none.map", &[]);
    let e = load(&world, &[]).unwrap_err().to_string();
    assert!(e.contains("none.map") && e.contains("cannot read"), "{e}");

    // A start in a blocked cell is named as the map's.
    let maze = perfect_maze(2, 5, 1);
    let world = world_with_map(dir.path(), "maze.map", &[("maze.map", maze.as_bytes())]);
    let text = std::fs::read_to_string(&world)
        .unwrap()
        .replace("[2.5, 1.5]", "[2.5, 2.5]");
    std::fs::write(&world, text).unwrap();
    let e = load(&world, &[]).unwrap_err().to_string();
    assert!(
        e.contains("agents.0.target") && e.contains("the map"),
        "{e}"
    );
}

/// A 64 × 64 perfect maze (1 m corridors) at 0.2 m cells for a 0.3 m robot: its route is long
/// enough that `1 − V` at the far corner is far below f64's 1e-308. The field is still solved
/// to every cell, and the streamline from any reachable cell reaches the target.
#[test]
fn a_generated_maze_deeper_than_f64_guides_from_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    let maze = perfect_maze(31, 64, 11);
    let world = world_with_map(dir.path(), "maze.map", &[("maze.map", maze.as_bytes())]);
    let text = std::fs::read_to_string(&world)
        .unwrap()
        .replace("target = [2.5, 1.5]", "target = [61.5, 2.5]\n");
    // The entrance room, (1, 1) in the text, is at (1.5, 62.5) y-up.
    let text = text.replace("start = [1.5, 1.5]", "start = [1.5, 62.5]");
    std::fs::write(&world, text + "\n[field]\ncell = 0.2\n").unwrap();
    let world = load(&world, &[]).unwrap();
    let agent = &world.agents[0];
    let field = HarmonicField::solve(&world, agent).unwrap();
    let depth = field.log10_one_minus_potential(agent.start);
    assert!(depth < -308.0, "log10(1 - V) at the start: {depth}");
    assert_eq!(field.one_minus_potential(agent.start), 0.0);
    field.check_start(agent).unwrap();
    let grid = *field.grid();
    let reachable = field.sampler.reachable_cells();
    let cells: Vec<usize> = (0..grid.len()).filter(|&k| reachable[k]).collect();
    let mut checked = 0;
    for &k in cells.iter().step_by(cells.len() / 300) {
        let from = grid.center(k % grid.nx, k / grid.nx);
        let path = field.streamline(from);
        assert!(
            path.reached,
            "from {from:?}: stops at {:?}",
            path.points.last()
        );
        checked += 1;
    }
    assert!(checked >= 300, "{checked}");
}
