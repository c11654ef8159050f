//! The harmonic guidance field of one agent (paper §II, eq. 3–4).
//!
//! The walls are rasterized into a configuration-space mask for the agent's radius, with the
//! other agents as discs ([`FreeSpace`], `mask.rs`); Laplace's equation is solved on the free
//! cells connected to the target ([`HarmonicField`], `harmonic.rs`: multigrid-preconditioned CG,
//! `multigrid/`, with nested solves of the deep regions; `laplace.rs` keeps a plain SOR solver as
//! the reference the tests compare with); the result is sampled smoothly anywhere in the box
//! ([`Sampler`]), and the kinematic path is the streamline of the normalized guidance from the
//! start ([`Streamline`]). [`export`] writes a solved field for other tools.
//!
//! Khatib's attractive-repulsive potential ([`AttractiveRepulsive`], `firas.rs`) is the
//! baseline of the narrow corridor; [`GuidanceField`] holds either kind.
//!
//! ```
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("worlds/room-two-dividers.toml");
//! let world = nadf::world::load(&path, &["field.cell=0.1".parse().unwrap()]).unwrap();
//! let agent = &world.agents[0];
//! let field = nadf::field::HarmonicField::solve(&world, agent).unwrap();
//! // Far from the target V is within 1e-6 of 1, yet the guidance is well defined.
//! assert!(field.one_minus_potential(agent.start) < 1e-3);
//! assert!(field.streamline(agent.start).reached);
//! ```

mod banded;
mod bounds;
pub mod export;
mod firas;
mod grid;
mod guidance_field;
mod harmonic;
mod heading_mask;
mod joint_field;
mod joint_mask;
mod known;
mod laplace;
mod mask;
mod multigrid;
mod nested;
mod pose;
mod sample;
mod scaled;
mod segment_tree;
mod space;
mod streamline;
mod window;
mod yielding;

pub use firas::AttractiveRepulsive;
pub use grid::Grid;
pub use guidance_field::GuidanceField;
pub use harmonic::{GRADIENT_FLOOR, HarmonicField};
pub use heading_mask::{HeadingMask, ShapeError};
pub use joint_field::{JointField, JointTarget};
pub use joint_mask::{JointAxis, JointMask, segment_distance};
pub use known::{Beam, KnownMap};
pub use mask::{CellCounts, Disc, FreeSpace};
pub use nested::{BELOW_AGENT, LevelStats};
pub use pose::{Pose, PoseField, angle_difference};
pub use sample::Sampler;
pub use scaled::ScaledW;
pub use space::ConfigurationSpace;
pub use streamline::Streamline;
pub use window::{Reach, Window};
pub use yielding::{CLEAR_OF_WAY, IN_THE_WAY, STEP_ASIDE, WAY_AHEAD, Way};

/// `a` and `b`, at once when `parallel` (see `rayon::join`), else one after the other: for
/// work that pays for handing half of it to another thread only when it is large. The results
/// are the same either way.
fn join_if<A: Send, B: Send>(
    parallel: bool,
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    if parallel {
        rayon::join(a, b)
    } else {
        (a(), b())
    }
}

/// The solver's internals, public for the benchmarks only: not part of the crate's API.
#[doc(hidden)]
pub mod solvers {
    pub use super::harmonic::{solve_w, solve_w_for};
    pub use super::laplace::solve_sor;
    pub use super::multigrid::{Rows, set_portable, solve, solve_rows};
    pub use super::nested::{MAX_ITERATIONS, Stop};
    pub use super::pose::multigrid::{Dims, Lattice, solve as solve_pose};
}

/// Why a field could not be built for an agent.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    /// The target lies in a blocked cell.
    #[error(
        "agent `{agent}`: its target is within its radius of a wall on the {cell} m grid; move the target away from the wall or use a smaller field.cell"
    )]
    TargetBlocked {
        /// The agent's name.
        agent: String,
        /// The grid cell size, m.
        cell: f64,
    },
    /// No free path connects the start to the target.
    #[error(
        "agent `{agent}`: its target cannot be reached from its start (no free path for a disc of radius {radius} m); the task is intractable"
    )]
    Unreachable {
        /// The agent's name.
        agent: String,
        /// The agent's radius, m.
        radius: f64,
    },
    /// No configuration of an arm's target set is free on its joint-space grid.
    #[error(
        "arm `{arm}`: no configuration of its target set is free on its joint-space grid ({cells} cells per joint, each cell blocked when a link comes within {margin:.3} m of a wall anywhere in it); move the target away from the walls, or use more cells"
    )]
    ArmTargetBlocked {
        /// The arm's name.
        arm: String,
        /// Cells per joint (the first joint's).
        cells: usize,
        /// The last link's margin over a cell, m.
        margin: f64,
    },
    /// No sequence of free poses connects a shaped agent's start pose to its target.
    #[error(
        "agent `{agent}`: no sequence of poses of its shape connects its start (at its heading) to its target on the (x, y, θ) grid: the task is intractable (a wider passage, a smaller shape, or a finer field.cell or more field.headings may make it tractable)"
    )]
    PoseUnreachable {
        /// The agent's name.
        agent: String,
    },
    /// The field gives no direction at the agent's start.
    #[error(
        "agent `{agent}`: the field gives no direction at its start [{}, {}] (a critical point of the field, or off it): it cannot be guided from there; move the start",
        start[0], start[1]
    )]
    NoGuidance {
        /// The agent's name.
        agent: String,
        /// Its start, m.
        start: [f64; 2],
    },
    /// The solver did not reach the tolerance.
    #[error(
        "agent `{agent}`: the Laplace solver stopped at a relative residual of {relative_residual:e} after {iterations} iterations, above field.tolerance"
    )]
    Solver {
        /// The agent's name.
        agent: String,
        /// Iterations performed.
        iterations: usize,
        /// The residual reached.
        relative_residual: f64,
    },
}
