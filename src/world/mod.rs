//! The world file: its schema, loading (with `--set` overrides) and validation.
//!
//! A world is a box with walls and one or more agents, each a disc with a start, a target and
//! a controller. See `worlds/README.md` for the format.

pub(crate) mod arm;
mod body;
mod error;
mod load;
pub mod map;
mod obstacle;
mod schema;
mod shapes;
pub(crate) mod suggest;
mod validate;

pub use arm::{Chain, Link};
pub use body::BodyShape;
pub use error::{WorldError, WorldErrors, line_column};
pub use load::{Override, WorldFile, load, load_str};
pub use obstacle::{Obstacle, ObstacleMode, ObstacleShape};
pub use schema::{
    Agent, AgentShape, ArmSettings, Attraction, BiasSettings, ClampSettings, ControllerKind,
    ControllerSettings, DEFAULT_K, DriveKind, DriveSettings, Expect, ExpectValue, FieldKind,
    FieldSettings, GuidanceKind, Integration, LinkSettings, LoadedMap, MAX_CELLS, MapSettings,
    OUTER_WALL_THICKNESS, OrcaSettings, Pendulum, PendulumController, PendulumExpect, Replan,
    SensorKind, SensorSettings, UnknownCells, Wall, World,
};
pub use shapes::{
    WallShape, all_wall_shapes, all_walls, drawn_walls, named_walls, outer_walls, outline_box,
    wall_outline, wall_shape,
};
pub use validate::validate;

/// The unlocated form of [`WorldFile::warnings`], for a world built in code.
pub use validate::warnings as settings_warnings;

impl World {
    /// The world's name (the file stem unless the file sets one).
    pub fn name(&self) -> &str {
        self.name.as_deref().unwrap_or("world")
    }

    /// The box's lower-left and upper-right corners, m.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let [ox, oy] = self.origin;
        (self.origin, [ox + self.size[0], oy + self.size[1]])
    }

    /// Number of physics steps in a run.
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round() as usize
    }
}
