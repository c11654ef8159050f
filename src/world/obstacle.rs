//! A moving obstacle (`[[obstacles]]`): a shape like a wall's that moves by a script of its own
//! (a person crossing a corridor, a cart in an aisle, a sliding door, a wanderer) and plans
//! nothing. The simulation makes it a Rapier kinematic body (`sim::obstacles`); this file is
//! its schema and its checks.
//!
//! One table, not an enum tagged by the shape or the motion: serde locates an error in a plain
//! table at the field's line, and the checks below say which field a combination is missing.

use serde::{Deserialize, Deserializer, Serialize};

use super::schema::{Wall, World, fixed_length, optional_pair};
use super::shapes::wall_shape;
use super::validate::check_wall;

/// One moving obstacle. Its shape is given in its own frame, around the point that moves
/// (`path`'s or `center`'s), turned by `angle` at the start.
///
/// Exactly one motion: `path` (with `speed` and `mode` = `loop`, `bounce` or `once`), or
/// `center` alone (it stays there, turning if `angular_speed` is set), or `center` with a
/// constant `velocity`, or `center` with `mode = "wander"`, `speed` and `region`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Name, used in the recording and in messages (default `obstacle-N`).
    #[serde(default)]
    pub name: Option<String>,
    /// `box`, `disc` or `polygon`.
    pub shape: ObstacleShape,
    /// A disc's radius, m.
    #[serde(default)]
    pub radius: Option<f64>,
    /// A box's half width and half height, m.
    #[serde(default, deserialize_with = "optional_pair")]
    pub half_extents: Option<[f64; 2]>,
    /// A convex polygon's vertices, counter-clockwise, m, in the obstacle's frame.
    #[serde(default, deserialize_with = "optional_points")]
    pub points: Option<Vec<[f64; 2]>>,
    /// The shape's rotation at the start, rad (counter-clockwise).
    #[serde(default)]
    pub angle: f64,
    /// How fast it turns about the point that moves, rad/s (counter-clockwise).
    #[serde(default)]
    pub angular_speed: f64,
    /// Waypoints, m: it starts at the first and follows them at `speed`.
    #[serde(default, deserialize_with = "optional_points")]
    pub path: Option<Vec<[f64; 2]>>,
    /// Speed along the path or of the wander, m/s.
    #[serde(default)]
    pub speed: Option<f64>,
    /// What a path does at its end (`loop`, the default; `bounce`; `once`), or `wander`.
    #[serde(default)]
    pub mode: Option<ObstacleMode>,
    /// Where it starts without a path, m.
    #[serde(default, deserialize_with = "optional_pair")]
    pub center: Option<[f64; 2]>,
    /// A constant velocity from `center`, m/s.
    #[serde(default, deserialize_with = "optional_pair")]
    pub velocity: Option<[f64; 2]>,
    /// A wander's box `[[x0, y0], [x1, y1]]`, m: the moving point stays in it.
    #[serde(default, deserialize_with = "optional_region")]
    pub region: Option<[[f64; 2]; 2]>,
    /// A wander's heading diffusion, rad/√s: the standard deviation of its turn over 1 s.
    #[serde(default = "default_turn")]
    pub turn: f64,
}

/// The shape of an obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ObstacleShape {
    /// A rectangle of `half_extents`.
    Box,
    /// A disc of `radius`.
    Disc,
    /// A convex polygon of `points`.
    Polygon,
}

/// How an obstacle moves on (see [`Obstacle`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ObstacleMode {
    /// Along the path and from its last waypoint back to the first, round and round.
    Loop,
    /// Along the path and back, again and again.
    Bounce,
    /// Along the path once; then it stays at the end.
    Once,
    /// A seeded random walk in `region` at `speed`.
    Wander,
}

impl Obstacle {
    /// Its name: the given one, else `obstacle-N` for entry `index`.
    pub fn name_or(&self, index: usize) -> String {
        self.name
            .clone()
            .unwrap_or_else(|| format!("obstacle-{index}"))
    }

    /// Where the point that moves starts, m: the path's first waypoint, else `center`.
    pub fn start(&self) -> [f64; 2] {
        match (&self.path, self.center) {
            (Some(path), _) if !path.is_empty() => path[0],
            (_, Some(c)) => c,
            _ => [0.0, 0.0],
        }
    }

    /// Its shape in its own frame (the point that moves at the origin, not turned), as a wall.
    pub fn local_shape(&self) -> Wall {
        match self.shape {
            ObstacleShape::Box => Wall::Box {
                center: [0.0, 0.0],
                half_extents: self.half_extents.unwrap_or([0.0, 0.0]),
                angle: 0.0,
            },
            ObstacleShape::Disc => Wall::Disc {
                center: [0.0, 0.0],
                radius: self.radius.unwrap_or(0.0),
            },
            ObstacleShape::Polygon => Wall::Polygon {
                points: self.points.clone().unwrap_or_default(),
            },
        }
    }

    /// Its shape where it is at `position`, turned by `angle` (rad), as a wall.
    ///
    /// ```
    /// # use nadf::world::{Obstacle, ObstacleShape, Wall};
    /// let text = "shape = \"box\"\nhalf_extents = [1.0, 0.1]\ncenter = [3.0, 2.0]\n";
    /// let door: Obstacle = toml::from_str(text).unwrap();
    /// let Wall::Box { center, angle, .. } = door.shape_at([4.0, 2.0], 0.5) else { panic!() };
    /// assert_eq!((center, angle), ([4.0, 2.0], 0.5));
    /// ```
    pub fn shape_at(&self, position: [f64; 2], angle: f64) -> Wall {
        let (s, c) = angle.sin_cos();
        let turn = |p: &[f64; 2]| {
            [
                position[0] + c * p[0] - s * p[1],
                position[1] + s * p[0] + c * p[1],
            ]
        };
        match self.local_shape() {
            Wall::Box { half_extents, .. } => Wall::Box {
                center: position,
                half_extents,
                angle,
            },
            Wall::Polygon { points } => Wall::Polygon {
                points: points.iter().map(turn).collect(),
            },
            _ => Wall::Disc {
                center: position,
                radius: self.radius.unwrap_or(0.0),
            },
        }
    }

    /// The radius of the smallest disc about the point that moves that holds the shape, m.
    pub fn reach(&self) -> f64 {
        match self.shape {
            ObstacleShape::Disc => self.radius.unwrap_or(0.0),
            ObstacleShape::Box => self.half_extents.map_or(0.0, |[a, b]| a.hypot(b)),
            ObstacleShape::Polygon => (self.points.iter().flatten())
                .map(|p| p[0].hypot(p[1]))
                .fold(0.0, f64::max),
        }
    }
}

fn default_turn() -> f64 {
    1.0
}

fn optional_points<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f64; 2]>>, D::Error> {
    Option::<Vec<Vec<f64>>>::deserialize(d)?
        .map(|points| points.into_iter().map(|p| fixed_length(p, None)).collect())
        .transpose()
}

fn optional_region<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[[f64; 2]; 2]>, D::Error> {
    let Some(points) = optional_points(d)? else {
        return Ok(None);
    };
    let n = points.len();
    <[[f64; 2]; 2]>::try_from(points).map(Some).map_err(|_| {
        serde::de::Error::custom(format!(
            "expected two corners [[x0, y0], [x1, y1]], got {n} point(s)"
        ))
    })
}

/// The checks of obstacle `index` of `world` (its key `obstacles.N`): a shape with exactly its
/// own dimensions, exactly one motion with what it needs, and no overlap with an agent's start
/// or target at t = 0.
pub(super) fn check(bad: &mut impl FnMut(String, String), world: &World, index: usize) {
    let o = &world.obstacles[index];
    let key = |field: &str| format!("obstacles.{index}.{field}");
    if index == 0
        && (world.agents.iter().any(super::Agent::is_shaped)
            || !world.arms.is_empty()
            || !world.pendulums.is_empty())
    {
        // They would collide with it in Rapier but neither plan around it nor count it.
        bad(
            format!("obstacles.{index}"),
            "moving obstacles are for worlds of disc agents (with or without wheels): shaped agents, arms and pendulums do not see them yet".into(),
        );
    }
    let finite = |bad: &mut dyn FnMut(String, String), field: &str, x: f64| {
        if !x.is_finite() {
            bad(key(field), format!("must be finite, got {x}"));
        }
        x.is_finite()
    };
    let positive = |bad: &mut dyn FnMut(String, String), field: &str, x: Option<f64>, what| {
        match x {
            None => bad(key(field), format!("missing: {what}")),
            Some(x) if !(x.is_finite() && x > 0.0) => {
                bad(key(field), format!("must be a finite number > 0, got {x}"))
            }
            Some(_) => return true,
        }
        false
    };
    // The shape: its own dimension, none of the others'.
    let (needs, given) = match o.shape {
        ObstacleShape::Box => ("half_extents", o.half_extents.is_some()),
        ObstacleShape::Disc => ("radius", o.radius.is_some()),
        ObstacleShape::Polygon => ("points", o.points.is_some()),
    };
    let mut shape_ok = given;
    if !given {
        bad(
            key(needs),
            format!(
                "missing: a {} obstacle needs `{needs}`",
                shape_name(o.shape)
            ),
        );
    }
    for (field, present) in [
        ("half_extents", o.half_extents.is_some()),
        ("radius", o.radius.is_some()),
        ("points", o.points.is_some()),
    ] {
        if present && field != needs {
            shape_ok = false;
            bad(
                key(field),
                format!(
                    "a {} obstacle has `{needs}`, not `{field}`",
                    shape_name(o.shape)
                ),
            );
        }
    }
    if shape_ok {
        let mut count = 0;
        let mut inner = |k: String, m: String| {
            count += 1;
            bad(k, m);
        };
        check_wall(&mut inner, &format!("obstacles.{index}"), &o.local_shape());
        shape_ok = count == 0;
    }
    shape_ok &= finite(bad, "angle", o.angle);
    finite(bad, "angular_speed", o.angular_speed);

    // The motion: a path, or a centre (at rest, at a velocity, or wandering).
    let mut start_ok = true;
    match (&o.path, o.center) {
        (Some(_), Some(_)) => {
            start_ok = false;
            bad(
                key("center"),
                "give a `path` (it starts at its first waypoint) or a `center`, not both".into(),
            );
        }
        (None, None) => {
            start_ok = false;
            bad(
                key("path"),
                "missing: an obstacle needs a `path` (waypoints, m) or a `center`".into(),
            );
        }
        (Some(path), None) => {
            if path.len() < 2 {
                start_ok = false;
                bad(
                    key("path"),
                    format!("a path needs at least 2 points, got {}", path.len()),
                );
            }
            for (j, p) in path.iter().enumerate() {
                if !p.iter().all(|c| c.is_finite()) {
                    start_ok = false;
                    bad(
                        key(&format!("path.{j}")),
                        format!("must be finite, got {p:?}"),
                    );
                }
            }
            if path.len() >= 2 && path.windows(2).all(|w| w[0] == w[1]) {
                bad(
                    key("path"),
                    "the path's points are all the same point".into(),
                );
            }
            positive(
                bad,
                "speed",
                o.speed,
                "a path is followed at a `speed`, m/s",
            );
            if o.mode == Some(ObstacleMode::Wander) {
                bad(
                    key("mode"),
                    "`wander` is from a `center` in a `region`; a path's mode is `loop`, `bounce` or `once`".into(),
                );
            }
            for (field, present) in [
                ("velocity", o.velocity.is_some()),
                ("region", o.region.is_some()),
            ] {
                if present {
                    bad(key(field), format!("a path obstacle has no `{field}`"));
                }
            }
        }
        (None, Some(center)) => {
            if !center.iter().all(|c| c.is_finite()) {
                start_ok = false;
                bad(key("center"), format!("must be finite, got {center:?}"));
            }
            match o.mode {
                Some(ObstacleMode::Wander) => {
                    positive(bad, "speed", o.speed, "a wander moves at a `speed`, m/s");
                    if !(o.turn.is_finite() && o.turn >= 0.0) {
                        bad(
                            key("turn"),
                            format!("must be a finite number ≥ 0, got {}", o.turn),
                        );
                    }
                    if o.velocity.is_some() {
                        bad(
                            key("velocity"),
                            "a wander has a `speed`, not a `velocity`".into(),
                        );
                    }
                    match o.region {
                        None => bad(
                            key("region"),
                            "missing: a wander stays in a `region` = [[x0, y0], [x1, y1]]".into(),
                        ),
                        Some([lo, hi]) if !(lo[0] < hi[0] && lo[1] < hi[1]) => bad(
                            key("region"),
                            format!(
                                "its first corner must be below and left of its second, got {lo:?} and {hi:?}"
                            ),
                        ),
                        Some([lo, hi]) => {
                            let inside = (0..2).all(|k| lo[k] <= center[k] && center[k] <= hi[k]);
                            if !inside {
                                bad(
                                    key("region"),
                                    format!(
                                        "does not contain the obstacle's start, `center` = {center:?}"
                                    ),
                                );
                            }
                        }
                    }
                }
                Some(mode) => bad(
                    key("mode"),
                    format!(
                        "`{}` is a path's mode; an obstacle from a `center` has a `velocity`, or `mode = \"wander\"`",
                        mode_name(mode)
                    ),
                ),
                None => {
                    if let Some(v) = o.velocity
                        && !v.iter().all(|c| c.is_finite())
                    {
                        bad(key("velocity"), format!("must be finite, got {v:?}"));
                    }
                    for (field, present) in
                        [("speed", o.speed.is_some()), ("region", o.region.is_some())]
                    {
                        if present {
                            bad(
                                key(field),
                                format!(
                                    "`{field}` is for a path or a wander (`mode = \"wander\"`); an obstacle from a `center` moves at its `velocity`"
                                ),
                            );
                        }
                    }
                }
            }
        }
    }

    // Nothing of it where an agent starts or must arrive.
    if shape_ok && start_ok {
        let Some(shape) = wall_shape(&o.shape_at(o.start(), o.angle)) else {
            return;
        };
        let name = o.name_or(index);
        let at = if o.path.is_some() { "path" } else { "center" };
        for (j, agent) in world.agents.iter().enumerate() {
            for (what, p) in [("start", agent.start), ("target", agent.target)] {
                if shape.distance_to_point(p[0], p[1]) < agent.radius {
                    bad(
                        key(at),
                        format!(
                            "`{name}` overlaps the {what} of agents.{j} (`{}`) at t = 0",
                            agent.name
                        ),
                    );
                }
            }
        }
    }
}

fn shape_name(shape: ObstacleShape) -> &'static str {
    match shape {
        ObstacleShape::Box => "box",
        ObstacleShape::Disc => "disc",
        ObstacleShape::Polygon => "polygon",
    }
}

fn mode_name(mode: ObstacleMode) -> &'static str {
    match mode {
        ObstacleMode::Loop => "loop",
        ObstacleMode::Bounce => "bounce",
        ObstacleMode::Once => "once",
        ObstacleMode::Wander => "wander",
    }
}
