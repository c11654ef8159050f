//! The world file: its schema, loading (with `--set` overrides) and validation.
//!
//! A world is a box with walls and one or more agents, each a disc with a start, a target and
//! a controller. See `worlds/README.md` for the format.

mod error;
mod load;
mod schema;
mod shapes;
pub(crate) mod suggest;
mod validate;

pub use error::{WorldError, WorldErrors};
pub use load::{Override, WorldFile, load, load_str};
pub use schema::{
    Agent, Attraction, BiasSettings, ClampSettings, ControllerKind, ControllerSettings, DEFAULT_K,
    Expect, ExpectValue, FieldKind, FieldSettings, GuidanceKind, MAX_CELLS, OUTER_WALL_THICKNESS,
    Pendulum, PendulumController, PendulumExpect, SensorSettings, Wall, World,
};
pub use shapes::{WallShape, all_wall_shapes, all_walls, named_walls, outer_walls, wall_shape};
pub use validate::validate;

/// The unlocated form of [`WorldFile::warnings`], for a world built in code.
pub use validate::warnings as settings_warnings;

impl World {
    /// The world's name (the file stem unless the file sets one).
    pub fn name(&self) -> &str {
        self.name.as_deref().unwrap_or("world")
    }

    /// Number of physics steps in a run.
    pub fn steps(&self) -> usize {
        (self.duration / self.dt).round() as usize
    }
}
