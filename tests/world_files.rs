//! Loading world files: defaults, overrides, and errors that point at the line and key.

use std::path::Path;

use nadf::world::{ControllerKind, GuidanceKind, Override, Wall, load_str};

const MINIMAL: &str = r#"size = [4.0, 3.0]

[[agents]]
name = "r"
start = [1.0, 1.0]
target = [3.0, 2.0]

[agents.controller]
kind = "nadf"
b = 5.0
"#;

fn errors(text: &str, overrides: &[&str]) -> String {
    let overrides: Vec<Override> = overrides.iter().map(|o| o.parse().unwrap()).collect();
    load_str(text, Path::new("w.toml"), &overrides)
        .unwrap_err()
        .to_string()
}

#[test]
fn defaults_fill_in_what_the_file_leaves_out() {
    let w = load_str(MINIMAL, Path::new("dir/minimal.toml"), &[]).unwrap();
    assert_eq!(w.name(), "minimal");
    assert!(w.walls_around);
    assert_eq!((w.dt, w.duration, w.seed), (0.01, 60.0, 0));
    assert_eq!(w.field.cell, 0.05);
    assert_eq!(w.field.guidance, GuidanceKind::Normalized);
    let a = &w.agents[0];
    assert_eq!((a.radius, a.mass, a.controller.k()), (0.2, 1.0, 1.0));
    assert_eq!(a.controller.kind, ControllerKind::Nadf);
}

#[test]
fn overrides_set_values_index_arrays_and_create_tables() {
    let sets: Vec<Override> = [
        "agents.0.controller.kind=viscous",
        "agents.0.controller.b=0.7",
        "field.guidance=gradient",
        "agents.0.target.1=2.5",
        "name=renamed",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    let w = load_str(MINIMAL, Path::new("w.toml"), &sets).unwrap();
    assert_eq!(w.agents[0].controller.kind, ControllerKind::Viscous);
    assert_eq!(w.agents[0].controller.b, Some(0.7));
    assert_eq!(w.field.guidance, GuidanceKind::Gradient);
    assert_eq!(w.agents[0].target, [3.0, 2.5]);
    assert_eq!(w.name(), "renamed");
}

#[test]
fn syntax_errors_name_the_line() {
    let e = errors("size = [4.0, 3.0\n", &[]);
    assert!(e.starts_with("error: w.toml:1:"), "{e}");
    assert!(e.contains("syntax"), "{e}");
}

#[test]
fn unknown_keys_and_wrong_types_name_the_line_and_key() {
    let text = MINIMAL.replace("b = 5.0", "b = \"high\"");
    let e = errors(&text, &[]);
    assert!(e.contains("w.toml:10:5: `agents.0.controller.b`"), "{e}");

    let text = MINIMAL.replace("[agents.controller]", "colour = 1\n[agents.controller]");
    let e = errors(&text, &[]);
    assert!(e.contains("w.toml:8:1: `agents.0.colour`"), "{e}");
    assert!(e.contains("unknown field"), "{e}");

    let text = MINIMAL.replace("kind = \"nadf\"", "kind = \"nadv\"");
    let e = errors(&text, &[]);
    assert!(e.contains("w.toml:9:8: `agents.0.controller.kind`"), "{e}");
    assert!(e.contains("did you mean `nadf`?"), "{e}");
}

#[test]
fn missing_required_keys_are_named() {
    let text = MINIMAL.replace("target = [3.0, 2.0]\n", "");
    let e = errors(&text, &[]);
    assert!(e.contains("missing field `target`"), "{e}");
}

#[test]
fn every_semantic_problem_is_reported_at_its_line() {
    let text = r#"size = [4.0, 3.0]
dt = 0.0

[field]
cell = -0.05

[[walls]]
shape = "polygon"
points = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0]]

[[agents]]
name = "r"
start = [0.1, 1.0]
target = [3.0, nan]
mass = 0.0

[agents.controller]
kind = "nadf"
b = 5.0
"#;
    let e = errors(text, &[]);
    for expected in [
        "w.toml:2:1: `dt`",
        "w.toml:5:1: `field.cell`",
        "w.toml:9:1: `walls.0.points`: must be convex",
        "w.toml:13:1: `agents.0.start`",
        "w.toml:14:1: `agents.0.target`",
        "w.toml:15:1: `agents.0.mass`",
    ] {
        assert!(e.contains(expected), "no `{expected}` in\n{e}");
    }
}

#[test]
fn starts_inside_walls_and_overlapping_agents_are_rejected() {
    let text = format!(
        "{MINIMAL}\n[[walls]]\nshape = \"disc\"\ncenter = [3.0, 2.0]\nradius = 0.3\n\n[[agents]]\nname = \"s\"\nstart = [1.2, 1.0]\ntarget = [1.0, 2.0]\n[agents.controller]\nkind = \"viscous\"\nb = 1.0\n"
    );
    let e = errors(&text, &[]);
    assert!(
        e.contains("`agents.0.target`") && e.contains("walls.0"),
        "{e}"
    );
    assert!(
        e.contains("`agents.1.start`") && e.contains("overlaps the start of agents.0"),
        "{e}"
    );
}

#[test]
fn shapes_parse_with_their_own_keys() {
    let text = format!(
        "{MINIMAL}\n[[walls]]\nshape = \"segment\"\na = [2.0, 0.5]\nb = [2.0, 1.5]\nthickness = 0.1\n"
    );
    let w = load_str(&text, Path::new("w.toml"), &[]).unwrap();
    assert!(matches!(w.walls[0], Wall::Segment { thickness, .. } if thickness == 0.1));
    let e = errors(&text.replace("thickness", "radius"), &[]);
    assert!(e.contains("unknown field `radius`"), "{e}");
}

#[test]
fn an_override_that_breaks_the_world_is_named() {
    let e = errors(MINIMAL, &["agents.0.mass=0"]);
    assert!(e.contains("--set agents.0.mass=0"), "{e}");
    let e = errors(MINIMAL, &["agents.0.speed=3"]);
    assert!(
        e.contains("--set agents.0.speed=3") && e.contains("unknown field"),
        "{e}"
    );
    let e = errors(MINIMAL, &["size.x=3"]);
    assert!(e.contains("index it with a number"), "{e}");
}

#[test]
fn a_grid_over_the_limit_is_rejected_unless_the_limit_is_raised() {
    let e = errors(MINIMAL, &["field.cell=0.0005"]);
    assert!(e.contains("more than field.max_cells = 16777216"), "{e}");
    assert!(e.contains("raise field.max_cells"), "{e}");
    let sets: Vec<Override> = ["field.cell=0.0005", "field.max_cells=100000000"]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
    assert!(load_str(MINIMAL, Path::new("w.toml"), &sets).is_ok());
}

#[test]
fn non_finite_numbers_are_rejected_wherever_they_appear() {
    for (key, value) in [
        ("dt", "nan"),
        ("duration", "inf"),
        ("size.1", "-inf"),
        ("agents.0.controller.k", "nan"),
        ("agents.0.controller.b", "inf"),
        ("agents.0.radius", "nan"),
        ("field.tolerance", "nan"),
    ] {
        let e = errors(MINIMAL, &[&format!("{key}={value}")]);
        assert!(e.contains(&format!("`{key}`")), "{key}: {e}");
    }
}

/// A fixed-length array with too many or too few numbers is an error at its line and key,
/// never silently cut to length (`start = [8.5, 1.5, 3.0]` once ran as `[8.5, 1.5]`).
#[test]
fn fixed_length_arrays_of_the_wrong_length_are_rejected_at_their_line() {
    let text = MINIMAL.replace("start = [1.0, 1.0]", "start = [1.0, 1.0, 3.0]");
    let e = errors(&text, &[]);
    assert!(e.contains("w.toml:5:"), "{e}");
    assert!(e.contains("agents.0.start"), "{e}");
    assert!(e.contains("exactly 2 numbers, got 3"), "{e}");

    let walls = [
        (
            "shape = \"box\"\ncenter = [2.0, 2.0, 0.0]\nhalf_extents = [0.1, 0.1]",
            "center",
        ),
        (
            "shape = \"box\"\ncenter = [2.0, 2.0]\nhalf_extents = [0.1]",
            "half_extents",
        ),
        (
            "shape = \"segment\"\na = [2.0, 2.0]\nb = [2.5, 2.0, 1.0]\nthickness = 0.1",
            "b",
        ),
        ("shape = \"disc\"\ncenter = [2.0]\nradius = 0.1", "center"),
        (
            "shape = \"polygon\"\npoints = [[2.0, 0.5], [2.5, 0.5, 9.0], [2.2, 0.9]]",
            "points.1",
        ),
    ];
    for (wall, field) in walls {
        let text = format!("{MINIMAL}\n[[walls]]\n{wall}\n");
        let e = errors(&text, &[]);
        assert!(e.contains("exactly 2 numbers"), "{wall}: {e}");
        // At the field's own line (the wall's table starts on line 12).
        assert!(e.contains(&format!("`walls.0.{field}`")), "{wall}: {e}");
        assert!(
            e.contains("w.toml:14:") || e.contains("w.toml:15:"),
            "{wall}: {e}"
        );
    }
    let e = errors(MINIMAL, &["size=[4.0, 3.0, 1.0]"]);
    assert!(
        e.contains("--set size=[4.0, 3.0, 1.0]") && e.contains("got 3"),
        "{e}"
    );
    let e = errors(MINIMAL, &["external_acceleration=[1.0]"]);
    assert!(e.contains("got 1"), "{e}");
}

#[test]
fn a_target_disc_that_is_not_positive_reaches_the_start_or_a_wall_is_a_located_error() {
    let with = |r: &str, extra: &str| {
        let text = MINIMAL.replace(
            "target = [3.0, 2.0]\n",
            &format!("target = [3.0, 2.0]\ntarget_radius = {r}\n"),
        );
        errors(&format!("{text}{extra}"), &[])
    };
    for r in ["0.0", "-0.1", "nan", "inf"] {
        let e = with(r, "");
        assert!(
            e.contains("w.toml:7") && e.contains("`agents.0.target_radius`"),
            "{r}: {e}"
        );
    }
    // The start is 2.24 m from the target.
    let e = with("2.5", "");
    assert!(
        e.contains("`agents.0.target_radius`") && e.contains("reaches the start"),
        "{e}"
    );
    // A disc wall 0.8 m from the target: its edge 0.5 m away, the agent's radius 0.2 m.
    let wall = "\n[[walls]]\nshape = \"disc\"\ncenter = [3.0, 1.2]\nradius = 0.3\n";
    let e = with("0.4", wall);
    assert!(
        e.contains("`agents.0.target_radius`") && e.contains("walls.0") && e.contains("smaller"),
        "{e}"
    );
    let ok = MINIMAL.replace(
        "target = [3.0, 2.0]\n",
        "target = [3.0, 2.0]\ntarget_radius = 0.25\n",
    );
    let w = load_str(&format!("{ok}{wall}"), Path::new("w.toml"), &[]).unwrap();
    assert_eq!(w.agents[0].target_disc(), 0.25);
    // By default, the agent's radius.
    let w = load_str(MINIMAL, Path::new("w.toml"), &[]).unwrap();
    assert_eq!(
        (w.agents[0].target_radius, w.agents[0].target_disc()),
        (None, 0.2)
    );
}
