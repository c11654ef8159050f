//! What an agent logs every step — its body, velocity and force arrows, contact points and time
//! series, and the updates of its trail — kept in columns and sent with `send_columns` every [`COLUMN_STEPS`] steps (and when
//! the recording ends): one chunk per entity and batch of steps instead of one log call per
//! entity and step, which is what made a recording cost ten times the run.
//!
//! What does not change from step to step (the body's radius, the arrows' and contacts'
//! colours and sizes) is logged once, static. Rare things (events, sensed walls, lidar scans)
//! are still logged as they happen.

use rerun::{RecordingStream, TimeColumn};

use super::names::{AGENT_SERIES, AgentPaths, Series, plot};
use super::palette::{self, size};
use super::world::f32x2;
use crate::sim::{AgentRun, AgentState};
use crate::world::Agent;

/// Steps kept before they are sent: 5 s at the default 10 ms step. A run killed outright
/// loses at most these from its `.partial` file.
pub const COLUMN_STEPS: usize = 500;
/// Length of a velocity arrow per m/s, m.
pub const VELOCITY_SCALE: f32 = 0.5;
/// Length of a force arrow per N, m.
pub const FORCE_SCALE: f32 = 0.5;

/// One agent's per-step values not sent yet.
pub struct AgentColumns {
    name: String,
    paths: AgentPaths,
    times: Vec<f64>,
    positions: Vec<[f32; 2]>,
    colours: Vec<rerun::Color>,
    velocities: Vec<[f32; 2]>,
    forces: Vec<[f32; 2]>,
    contacts: Vec<[f32; 2]>,
    contact_counts: Vec<usize>,
    /// Per time series the agent has: the series, and its values.
    series: Vec<(&'static Series<Agent, AgentState>, Vec<f64>)>,
    /// The trail's updates: the piece, the time and the piece's points so far.
    trail: Vec<(usize, f64, Vec<[f32; 2]>)>,
}

impl AgentColumns {
    /// Empty columns for `run`, and its static parts logged.
    pub fn new(rec: &RecordingStream, run: &AgentRun) -> Result<Self, rerun::RecordingStreamError> {
        let paths = AgentPaths::of(&run.agent.name);
        rec.log_static(
            paths.body.as_str(),
            &rerun::Points2D::update_fields().with_radii([run.agent.radius as f32]),
        )?;
        for (path, colour) in [
            (&paths.velocity, palette::VELOCITY),
            (&paths.force, palette::FORCE),
        ] {
            rec.log_static(
                path.as_str(),
                &rerun::Arrows2D::update_fields().with_colors([palette::rerun(colour)]),
            )?;
        }
        rec.log_static(
            paths.contacts.as_str(),
            &rerun::Points2D::update_fields()
                .with_radii([size::points(size::CONTACT)])
                .with_colors([palette::rerun(palette::CONTACT)]),
        )?;
        let series = AGENT_SERIES
            .iter()
            .filter(|s| (s.shown)(&run.agent))
            .map(|s| (s, Vec::new()))
            .collect();
        Ok(Self {
            name: run.agent.name.clone(),
            paths,
            times: Vec::new(),
            positions: Vec::new(),
            colours: Vec::new(),
            velocities: Vec::new(),
            forces: Vec::new(),
            contacts: Vec::new(),
            contact_counts: Vec::new(),
            series,
            trail: Vec::new(),
        })
    }

    /// Keeps `run`'s state after the step that ended at `time`, s.
    pub fn push(&mut self, time: f64, run: &AgentRun, state: &AgentState) {
        self.times.push(time);
        self.positions.push(f32x2(state.position.into()));
        self.colours
            .push(palette::rerun(if state.contact_points.is_empty() {
                palette::BODY
            } else {
                palette::TOUCHING
            }));
        let arrow =
            |v: nalgebra::Vector2<f64>, scale: f32| [v.x as f32 * scale, v.y as f32 * scale];
        self.velocities.push(arrow(state.velocity, VELOCITY_SCALE));
        self.forces.push(arrow(state.force, FORCE_SCALE));
        self.contacts
            .extend(state.contact_points.iter().map(|c| f32x2((*c).into())));
        self.contact_counts.push(state.contact_points.len());
        for (series, values) in &mut self.series {
            values.push((series.value)(&run.agent, state));
        }
    }

    /// Keeps an update of the trail's piece `piece` at `time` (s): its `points` so far.
    pub fn push_trail(&mut self, piece: usize, time: f64, points: Vec<[f32; 2]>) {
        self.trail.push((piece, time, points));
    }

    /// Whether [`COLUMN_STEPS`] steps are waiting.
    pub fn full(&self) -> bool {
        self.times.len() >= COLUMN_STEPS
    }

    /// Sends the steps kept so far, one chunk per entity, and forgets them.
    pub fn send(&mut self, rec: &RecordingStream) -> Result<(), rerun::RecordingStreamError> {
        if self.times.is_empty() {
            return Ok(());
        }
        let time = || {
            [TimeColumn::new_duration_secs(
                "sim_time",
                self.times.iter().copied(),
            )]
        };
        let positions = std::mem::take(&mut self.positions);
        rec.send_columns(
            self.paths.body.as_str(),
            time(),
            rerun::Points2D::update_fields()
                .with_positions(positions.iter().copied())
                .with_colors(std::mem::take(&mut self.colours))
                .columns_of_unit_batches()?,
        )?;
        for (path, vectors) in [
            (&self.paths.velocity, std::mem::take(&mut self.velocities)),
            (&self.paths.force, std::mem::take(&mut self.forces)),
        ] {
            rec.send_columns(
                path.as_str(),
                time(),
                rerun::Arrows2D::update_fields()
                    .with_vectors(vectors)
                    .with_origins(positions.iter().copied())
                    .columns_of_unit_batches()?,
            )?;
        }
        rec.send_columns(
            self.paths.contacts.as_str(),
            time(),
            rerun::Points2D::update_fields()
                .with_positions(std::mem::take(&mut self.contacts))
                .columns(std::mem::take(&mut self.contact_counts))?,
        )?;
        for (series, values) in &mut self.series {
            rec.send_columns(
                plot(&self.name, series.key),
                time(),
                rerun::Scalars::new(std::mem::take(values)).columns_of_unit_batches()?,
            )?;
        }
        self.times.clear();
        // The trail's updates, one chunk per piece.
        let updates = std::mem::take(&mut self.trail);
        for piece in updates.chunk_by(|a, b| a.0 == b.0) {
            let n = piece.len();
            rec.send_columns(
                format!("{}/{}", self.paths.trail, piece[0].0),
                [TimeColumn::new_duration_secs(
                    "sim_time",
                    piece.iter().map(|u| u.1),
                )],
                rerun::LineStrips2D::update_fields()
                    .with_strips(piece.iter().map(|u| u.2.clone()))
                    .with_colors(vec![palette::rerun(palette::BODY); n])
                    .with_radii(vec![size::points(size::PATH); n])
                    .columns_of_unit_batches()?,
            )?;
        }
        Ok(())
    }
}
