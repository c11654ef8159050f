//! # nadf — a physics sandbox for kinodynamic motion planning
//!
//! nadf steers bodies with mass through cluttered worlds with a harmonic potential field and
//! the nonlinear anisotropic damping force (NADF) of Masoud's paper "Kinodynamic Motion
//! Planning: A Novel Type of Nonlinear, Passive Damping Forces", on Rapier rigid bodies, and
//! records every run for the Rerun viewer.
//!
//! - [`world`]: the world file (TOML): schema, loading with `--set` overrides, validation.
//! - [`field`]: the configuration-space mask, the Laplace solver, gradient sampling and the
//!   kinematic streamline.
//! - [`control`]: the control laws behind one trait: guidance, viscous, NADF, sliding mode,
//!   clamping, the iterative bias and the speed limit.
//! - [`sim`]: the Rapier world, the step loop and the noisy wall sensor.
//! - [`metrics`]: what a run reports per agent; [`expect`]: checking it against `[expect]`.
//! - [`record`]: the Rerun recording.
//! - [`run`](mod@run): a whole headless run, as the `nadf run` command does it.
//! - [`sweep`]: parameter sweeps in parallel, with a CSV and a plot (`nadf sweep`).
//! - [`scen`]: Moving AI scenario batches on a map world (`nadf scen`).
//! - [`reproduce`]: the paper, claim by claim, with a verdict per claim (`nadf reproduce`).
//! - [`random`]: the one seeded generator, so a run is the same for a given seed.
//! - [`cli`]: the `nadf` commands (the binary only parses and dispatches); [`output`]: writing
//!   files whole or not at all, and checking outputs before a run.

mod buckets;
mod chart;
pub mod cli;
pub mod control;
pub mod expect;
pub mod experiment;
pub mod field;
pub mod metrics;
pub mod output;
pub mod random;
pub mod record;
pub mod reproduce;
pub mod run;
pub mod scen;
pub mod sim;
pub mod sweep;
pub mod world;
