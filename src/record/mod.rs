//! The Rerun recording of a run (`.rrd`), what users open in the Rerun viewer.
//!
//! Entity paths:
//! - `world/box`, `world/walls`: the geometry (static).
//! - `agents/NAME/field/potential`: `log10(1 - V)` of the agent's field as an image (static);
//!   the log scale shows how flat the potential is far from the target. Blocked cells are dark
//!   grey, free cells the target cannot be reached from are black.
//! - `agents/NAME/field/guidance`: a sparse arrow field of the unit guidance `-∇V/|∇V|` (static).
//! - `agents/NAME/kinematic_path`, `agents/NAME/target` (static).
//! - `agents/NAME/body`, `…/trail`, `…/velocity`, `…/force`, `…/contacts`: per step.
//! - `agents/NAME/events`: numerical faults as they start (text log, level WARN), bias updates
//!   and sensing problems (level INFO).
//! - `agents/NAME/sensed_walls`: with a noisy sensor, the outline of the configuration-space
//!   obstacles of each reading (the walls as the agent sensed them, grown by its radius).
//! - `plots/NAME/{distance, speed, radial_speed, force, force_x, force_y, potential}`: scalars.
//! - `plots/NAME/{clamping, speed_limited}` (0 or 1) and `plots/NAME/{beta_x, beta_y}` (N):
//!   when the agent's controller has a clamp, a speed limit or a bias.
//!
//! - `world/pendulums/NAME/{pivot, target, rod, bob}`: a pendulum; `…/events` its bias updates
//!   (INFO); `plots/NAME/{theta, target, torque, beta}`: θ(t), θ_T, u(t) and β(t).
//!
//! Time is the `sim_time` timeline, in seconds. The world is y-up while Rerun's 2D views are
//! y-down, so `world` and `agents` carry a static transform that flips y about the box.
//!
//! The recording is written to `OUT.rrd.partial` and renamed to `OUT.rrd` once complete, so an
//! existing recording is never replaced by a broken one.

mod blueprint;
mod colormap;
mod picture;

pub use picture::field_picture;

use std::path::{Path, PathBuf};

use rerun::{RecordingStream, RecordingStreamBuilder};

use crate::sim::{AgentState, Simulation};
use crate::world::{Wall, World, all_walls};

/// Steps between two updates of the trail (which is re-logged whole).
const TRAIL_EVERY: usize = 25;
/// Most points in a logged trail: a longer one is thinned evenly (its last point kept), so a
/// long run's recording grows linearly, not quadratically.
const TRAIL_POINTS: usize = 2000;
/// Wall-clock time between two flushes of the file, so that a run killed outright still leaves
/// a `.partial` file that decodes up to its last few seconds.
const FLUSH_EVERY: std::time::Duration = std::time::Duration::from_secs(1);
/// Arrows shown per side of the box in the guidance arrow field.
const GUIDANCE_ARROWS: usize = 24;
/// Length of a velocity arrow per m/s, m.
const VELOCITY_SCALE: f32 = 0.5;
/// Length of a force arrow per N, m.
const FORCE_SCALE: f32 = 0.5;

/// Why a recording could not be written.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// Rerun could not create or write the stream.
    #[error("cannot write the recording {path}: {source}")]
    Stream {
        /// The file.
        path: PathBuf,
        /// Rerun's error.
        source: rerun::RecordingStreamError,
    },
    /// The stream could not be flushed to the file.
    #[error("cannot flush the recording {path}: {message}")]
    Flush {
        /// The file.
        path: PathBuf,
        /// Rerun's error.
        message: String,
    },
    /// The finished file could not be moved into place.
    #[error("cannot move the finished recording to {path}: {source}")]
    Rename {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// Streams a run into an `.rrd` file.
pub struct Recorder {
    stream: RecordingStream,
    partial: PathBuf,
    path: PathBuf,
    trails: Vec<Vec<[f32; 2]>>,
    steps: usize,
    last_flush: std::time::Instant,
}

impl Recorder {
    /// Starts the recording of `world` that will end up at `path`.
    pub fn create(path: &Path, world: &World) -> Result<Self, RecordError> {
        let mut partial = path.as_os_str().to_owned();
        partial.push(".partial");
        let partial = PathBuf::from(partial);
        let stream = RecordingStreamBuilder::new("nadf")
            .recording_name(world.name())
            .with_blueprint(blueprint::layout(world))
            .save(&partial)
            .map_err(|source| RecordError::Stream {
                path: partial.clone(),
                source,
            })?;
        Ok(Self {
            stream,
            partial,
            path: path.to_path_buf(),
            trails: Vec::new(),
            steps: 0,
            last_flush: std::time::Instant::now(),
        })
    }

    /// Logs everything that does not change during the run: geometry, fields, kinematic paths.
    pub fn log_setup(&mut self, sim: &Simulation) -> Result<(), rerun::RecordingStreamError> {
        let rec = &self.stream;
        let [w, h] = sim.world.size;
        let flip = rerun::Transform3D::from_translation_scale(
            [0.0, h as f32, 0.0],
            rerun::Scale3D::from([1.0, -1.0, 1.0]),
        );
        rec.log_static("world", &flip)?;
        rec.log_static("agents", &flip)?;
        rec.log_static(
            "world/box",
            &rerun::LineStrips2D::new([outline_box([w / 2.0, h / 2.0], [w / 2.0, h / 2.0], 0.0)])
                .with_colors([rerun::Color::from_rgb(120, 120, 120)]),
        )?;
        let walls: Vec<Vec<[f32; 2]>> = all_walls(&sim.world).iter().map(outline).collect();
        rec.log_static(
            "world/walls",
            &rerun::LineStrips2D::new(walls)
                .with_colors([rerun::Color::from_rgb(230, 230, 230)])
                .with_radii([0.02]),
        )?;
        for p in &sim.pendulums {
            let name = &p.pendulum.name;
            rec.log_static(
                format!("world/pendulums/{name}/pivot"),
                &rerun::Points2D::new([f32x2(p.pendulum.pivot)])
                    .with_radii([0.04])
                    .with_colors([rerun::Color::from_rgb(230, 230, 230)]),
            )?;
            let target = p.pendulum.target;
            let [px, py] = p.pendulum.pivot;
            let l = p.pendulum.length;
            rec.log_static(
                format!("world/pendulums/{name}/target"),
                &rerun::LineStrips2D::new([[
                    f32x2([px, py]),
                    f32x2([px + l * target.sin(), py - l * target.cos()]),
                ]])
                .with_colors([rerun::Color::from_rgb(80, 255, 120)])
                .with_radii([0.01]),
            )?;
            for (series, label) in [
                ("theta", "θ (rad)"),
                ("target", "θ_T (rad)"),
                ("torque", "u (N·m)"),
                ("beta", "β (N·m)"),
            ] {
                rec.log_static(
                    format!("plots/{name}/{series}"),
                    &rerun::SeriesLines::new().with_names([label]),
                )?;
            }
        }
        self.trails = vec![Vec::new(); sim.agents.len()];
        for run in &sim.agents {
            let name = &run.agent.name;
            if let Some(field) = run.field.harmonic() {
                let grid = *field.grid();
                let (image, resolution) = colormap::potential_image(field);
                rec.log_static(
                    format!("agents/{name}/field/potential"),
                    &rerun::Transform3D::from_translation_scale(
                        [grid.origin[0] as f32, grid.origin[1] as f32, 0.0],
                        rerun::Scale3D::from([grid.cell as f32, grid.cell as f32, 1.0]),
                    ),
                )?;
                rec.log_static(
                    format!("agents/{name}/field/potential"),
                    &rerun::Image::from_rgb24(image, resolution).with_draw_order(-10.0),
                )?;
            }
            let (origins, vectors) = guidance_arrows(sim, run);
            rec.log_static(
                format!("agents/{name}/field/guidance"),
                &rerun::Arrows2D::from_vectors(vectors)
                    .with_origins(origins)
                    .with_colors([rerun::Color::from_unmultiplied_rgba(255, 255, 255, 110)]),
            )?;
            let path: Vec<[f32; 2]> = run.kinematic.points.iter().map(|p| f32x2(*p)).collect();
            rec.log_static(
                format!("agents/{name}/kinematic_path"),
                &rerun::LineStrips2D::new([path])
                    .with_colors([rerun::Color::from_rgb(80, 200, 255)])
                    .with_radii([0.02]),
            )?;
            rec.log_static(
                format!("agents/{name}/target"),
                &rerun::Points2D::new([f32x2(run.agent.target)])
                    .with_radii([0.1])
                    .with_colors([rerun::Color::from_rgb(80, 255, 120)]),
            )?;
            rec.log_static(
                format!("agents/{name}/start"),
                &rerun::Points2D::new([f32x2(run.agent.start)])
                    .with_radii([0.06])
                    .with_colors([rerun::Color::from_rgb(255, 255, 255)]),
            )?;
            for (series, label) in [
                ("distance", "distance to target (m)"),
                ("speed", "speed (m/s)"),
                ("radial_speed", "speed along the guidance (m/s)"),
                ("force", "|F| (N)"),
                ("force_x", "Fx (N)"),
                ("force_y", "Fy (N)"),
                ("potential", "V"),
            ] {
                rec.log_static(
                    format!("plots/{name}/{series}"),
                    &rerun::SeriesLines::new().with_names([label]),
                )?;
            }
            let c = &run.agent.controller;
            for (series, label, present) in [
                ("clamping", "clamping active", c.clamp.is_some()),
                (
                    "speed_limited",
                    "speed limit active",
                    c.speed_limit.is_some(),
                ),
                ("beta_x", "β x (N)", c.bias.is_some()),
                ("beta_y", "β y (N)", c.bias.is_some()),
            ] {
                if present {
                    rec.log_static(
                        format!("plots/{name}/{series}"),
                        &rerun::SeriesLines::new().with_names([label]),
                    )?;
                }
            }
        }
        Ok(())
    }

    /// Logs the state of every agent at simulated time `t`.
    pub fn log_step(
        &mut self,
        sim: &Simulation,
        states: &[AgentState],
    ) -> Result<(), rerun::RecordingStreamError> {
        let rec = &self.stream;
        rec.set_duration_secs("sim_time", sim.time());
        self.steps += 1;
        for p in &sim.pendulums {
            let name = &p.pendulum.name;
            let s = &p.state;
            rec.log(
                format!("world/pendulums/{name}/rod"),
                &rerun::LineStrips2D::new([[f32x2(p.pendulum.pivot), f32x2(s.bob)]])
                    .with_colors([rerun::Color::from_rgb(200, 200, 200)])
                    .with_radii([0.015]),
            )?;
            rec.log(
                format!("world/pendulums/{name}/bob"),
                &rerun::Points2D::new([f32x2(s.bob)])
                    .with_radii([0.08])
                    .with_colors([rerun::Color::from_rgb(255, 170, 40)]),
            )?;
            for (series, value) in [
                ("theta", s.theta),
                ("target", p.pendulum.target),
                ("torque", s.torque),
                ("beta", s.beta),
            ] {
                rec.log(
                    format!("plots/{name}/{series}"),
                    &rerun::Scalars::single(value),
                )?;
            }
            if let Some(note) = &s.note {
                rec.log(
                    format!("world/pendulums/{name}/events"),
                    &rerun::TextLog::new(note.as_str()).with_level(rerun::TextLogLevel::INFO),
                )?;
            }
        }
        for ((run, state), trail) in sim.agents.iter().zip(states).zip(&mut self.trails) {
            let name = &run.agent.name;
            let p = [state.position.x as f32, state.position.y as f32];
            let colour = if state.contact_points.is_empty() {
                rerun::Color::from_rgb(255, 170, 40)
            } else {
                rerun::Color::from_rgb(255, 40, 40)
            };
            rec.log(
                format!("agents/{name}/body"),
                &rerun::Points2D::new([p])
                    .with_radii([run.agent.radius as f32])
                    .with_colors([colour]),
            )?;
            for (what, vector, scale, colour) in [
                ("velocity", state.velocity, VELOCITY_SCALE, [80, 200, 255]),
                ("force", state.force, FORCE_SCALE, [255, 90, 200]),
            ] {
                rec.log(
                    format!("agents/{name}/{what}"),
                    &rerun::Arrows2D::from_vectors([[
                        vector.x as f32 * scale,
                        vector.y as f32 * scale,
                    ]])
                    .with_origins([p])
                    .with_colors([rerun::Color::from_rgb(colour[0], colour[1], colour[2])]),
                )?;
            }
            let contacts: Vec<[f32; 2]> = state
                .contact_points
                .iter()
                .map(|c| [c.x as f32, c.y as f32])
                .collect();
            rec.log(
                format!("agents/{name}/contacts"),
                &rerun::Points2D::new(contacts)
                    .with_radii([0.06])
                    .with_colors([rerun::Color::from_rgb(255, 0, 0)]),
            )?;
            for event in &state.events {
                rec.log(
                    format!("agents/{name}/events"),
                    &rerun::TextLog::new(event.as_str()).with_level(rerun::TextLogLevel::WARN),
                )?;
            }
            for note in &state.notes {
                rec.log(
                    format!("agents/{name}/events"),
                    &rerun::TextLog::new(note.as_str()).with_level(rerun::TextLogLevel::INFO),
                )?;
            }
            if let Some(sensed) = &state.sensed_walls {
                rec.log(
                    format!("agents/{name}/sensed_walls"),
                    &rerun::Points2D::new(sensed.iter().map(|p| f32x2(*p)))
                        .with_radii([0.025])
                        .with_colors([rerun::Color::from_unmultiplied_rgba(255, 80, 80, 160)]),
                )?;
            }
            let c = &run.agent.controller;
            let flag = |on: bool| if on { 1.0 } else { 0.0 };
            let mut extra = Vec::new();
            if c.clamp.is_some() {
                extra.push(("clamping", flag(state.clamping)));
            }
            if c.speed_limit.is_some() {
                extra.push(("speed_limited", flag(state.speed_limited)));
            }
            if let Some(beta) = state.beta {
                extra.extend([("beta_x", beta.x), ("beta_y", beta.y)]);
            }
            for (series, value) in extra {
                rec.log(
                    format!("plots/{name}/{series}"),
                    &rerun::Scalars::single(value),
                )?;
            }
            trail.push(p);
            if self.steps % TRAIL_EVERY == 1 || sim.finished() {
                let stride = trail.len().div_ceil(TRAIL_POINTS);
                let mut points: Vec<[f32; 2]> = trail.iter().step_by(stride).copied().collect();
                if (trail.len() - 1) % stride != 0 {
                    points.push(p);
                }
                rec.log(
                    format!("agents/{name}/trail"),
                    &rerun::LineStrips2D::new([points])
                        .with_colors([rerun::Color::from_rgb(255, 170, 40)])
                        .with_radii([0.015]),
                )?;
            }
            for (series, value) in [
                ("distance", state.distance),
                ("speed", state.velocity.norm()),
                ("radial_speed", state.radial_speed),
                ("force", state.force.norm()),
                ("force_x", state.force.x),
                ("force_y", state.force.y),
                ("potential", state.potential),
            ] {
                rec.log(
                    format!("plots/{name}/{series}"),
                    &rerun::Scalars::single(value),
                )?;
            }
        }
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            // A failed flush is not fatal here: the next one, or the footer, retries.
            let _ = self.stream.flush_blocking();
            self.last_flush = std::time::Instant::now();
        }
        Ok(())
    }

    /// Closes the stream (which writes the file's footer) and moves the file into place.
    pub fn finish(self) -> Result<PathBuf, RecordError> {
        let Self {
            stream,
            partial,
            path,
            ..
        } = self;
        if let Err(e) = stream.flush_blocking() {
            drop(stream);
            let _ = std::fs::remove_file(&partial);
            return Err(RecordError::Flush {
                path: partial,
                message: e.to_string(),
            });
        }
        // The footer is written when the last handle to the stream is dropped.
        drop(stream);
        std::fs::rename(&partial, &path).map_err(|source| RecordError::Rename {
            path: path.clone(),
            source,
        })?;
        Ok(path)
    }

    /// Drops the stream and deletes the partial file (a failed run leaves nothing behind).
    pub fn abandon(self) {
        let partial = self.partial.clone();
        drop(self.stream);
        let _ = std::fs::remove_file(partial);
    }
}

fn f32x2(p: [f64; 2]) -> [f32; 2] {
    [p[0] as f32, p[1] as f32]
}

/// The closed outline of a rotated box.
fn outline_box(center: [f64; 2], half: [f64; 2], angle: f64) -> Vec<[f32; 2]> {
    let (s, c) = angle.sin_cos();
    [
        [-1.0, -1.0],
        [1.0, -1.0],
        [1.0, 1.0],
        [-1.0, 1.0],
        [-1.0, -1.0],
    ]
    .iter()
    .map(|[sx, sy]| {
        let (x, y) = (sx * half[0], sy * half[1]);
        f32x2([center[0] + c * x - s * y, center[1] + s * x + c * y])
    })
    .collect()
}

/// The closed outline of a wall.
fn outline(wall: &Wall) -> Vec<[f32; 2]> {
    const ARC: usize = 16;
    let arc = |center: [f64; 2], r: f64, from: f64, to: f64| -> Vec<[f32; 2]> {
        (0..=ARC)
            .map(|k| {
                let a = from + (to - from) * k as f64 / ARC as f64;
                f32x2([center[0] + r * a.cos(), center[1] + r * a.sin()])
            })
            .collect()
    };
    match wall {
        Wall::Box {
            center,
            half_extents,
            angle,
        } => outline_box(*center, *half_extents, *angle),
        Wall::Disc { center, radius } => arc(*center, *radius, 0.0, std::f64::consts::TAU),
        Wall::Segment { a, b, thickness } => {
            let r = thickness / 2.0;
            let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
            let half_turn = std::f64::consts::FRAC_PI_2;
            let mut points = arc(*b, r, heading - half_turn, heading + half_turn);
            points.extend(arc(*a, r, heading + half_turn, heading + 3.0 * half_turn));
            points.push(points[0]);
            points
        }
        Wall::Polygon { points } => {
            let mut out: Vec<[f32; 2]> = points.iter().map(|p| f32x2(*p)).collect();
            out.push(out[0]);
            out
        }
    }
}

/// A sparse field of unit guidance arrows `-∇V/|∇V|`: at reachable cells of a harmonic field,
/// at the free points of a regular lattice for an attractive-repulsive one.
fn guidance_arrows(sim: &Simulation, run: &crate::sim::AgentRun) -> (Vec<[f32; 2]>, Vec<[f32; 2]>) {
    let [w, h] = sim.world.size;
    let spacing = (w.max(h) / GUIDANCE_ARROWS as f64).min(w.min(h) / 4.0);
    let length = 0.6 * spacing;
    let free = |c: [f64; 2]| match run.field.harmonic() {
        Some(field) => field
            .grid()
            .cell_of(c)
            .is_some_and(|(i, j)| field.sampler.reachable_cells()[field.grid().index(i, j)]),
        None => {
            crate::sim::signed_clearance(&sim.walls, nalgebra::Vector2::from(c), run.agent.radius)
                > 0.0
        }
    };
    let (mut origins, mut vectors) = (Vec::new(), Vec::new());
    let (nx, ny) = ((w / spacing) as usize, (h / spacing).max(1.0) as usize);
    for j in 0..ny {
        for i in 0..nx {
            let c = [(i as f64 + 0.5) * spacing, (j as f64 + 0.5) * spacing];
            if !free(c) {
                continue;
            }
            if let Some(u) = run.field.gradient(c).and_then(|g| crate::control::unit(&g)) {
                origins.push(f32x2(c));
                vectors.push(f32x2([-u.x * length, -u.y * length]));
            }
        }
    }
    (origins, vectors)
}
