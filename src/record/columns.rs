//! What an agent logs every step — where its body is, its velocity and force arrows, its
//! contacts, its plots and its trail — kept in columns and sent with `send_columns` every
//! [`COLUMN_STEPS`] steps, every second of wall-clock time (so that a viewer follows a slow run)
//! and when the recording ends: one chunk per entity and batch of steps instead of one log call
//! per entity and step, which is what made a recording cost ten times the run.
//!
//! A recording's size is mostly rows (a row id and a time per entity and step), so a step
//! writes as few as it can, and nothing a viewer would show differently is left out:
//! - The body is a frame: its translation is the row; the disc sits at its origin and the
//!   arrows are drawn in it, so they need no positions of their own.
//! - A plot's series share one row (`names::Plot`).
//! - The trail is logged a segment of [`TRAIL_EVERY`] steps at a time, each point once; the
//!   layout shows all of its segments up to the time cursor.
//! - What often stays the same — the body's colour, its contacts, every plot — keeps only the
//!   rows that start or end a run of equal values ([`Runs`]): the viewer shows the latest row
//!   at any instant and draws straight lines between a plot's rows, so the rows left out change
//!   nothing on screen (a flag that is 0 for a minute is two rows, not 6000).
//!
//! What does not change at all (the disc, the arrows' colours, the contacts' size) is logged
//! once, static. Rare things (events, sensed walls, lidar scans) are logged as they happen.

use rerun::{RecordingStream, TimeColumn};

use super::names::{AGENT_PLOTS, AgentPaths, SIM_TIME, plot};
use super::palette::{self, size};
use super::world::f32x2;
use crate::sim::{AgentRun, AgentState};
use crate::world::Agent;

/// The most steps kept before they are sent (41 s at the default 10 ms step; the viewer's own
/// chunk size): a fast run sends few large chunks, which cost less to make, write and index
/// than many small ones. A slower run sends what it has every second (`record::FLUSH_EVERY`).
pub const COLUMN_STEPS: usize = 4096;
/// Length of a velocity arrow per m/s, m.
pub const VELOCITY_SCALE: f32 = 0.5;
/// Length of a force arrow per N, m.
pub const FORCE_SCALE: f32 = 0.5;
/// Steps per segment of the trail. The trail is logged a segment at a time, each segment
/// once, and the layout shows every segment up to the time cursor (a visible time range on the
/// trail), so the trail up to any instant shows and costs one point per step.
pub const TRAIL_EVERY: usize = 25;
/// The most series a plot has (the force: |F|, Fx, Fy).
const MOST_SERIES: usize = 3;

/// The body frame's flip: Rerun's 2-D views are y-down, the world y-up (see `world.rs`), so
/// the frame is turned over about its x axis and a view rooted at it shows the world upright.
pub const BODY_FLIP: [f32; 3] = [1.0, -1.0, 1.0];

/// Rows of a value that often stays the same, keeping only those that start or end a run of
/// equal values (the rows in between add nothing to what the viewer shows).
#[derive(Debug)]
pub struct Runs<T> {
    /// The rows kept and not sent yet.
    times: Vec<f64>,
    values: Vec<T>,
    /// The latest row of the current run, and whether it is also the run's first (kept).
    held: Option<(f64, T, bool)>,
}

impl<T> Default for Runs<T> {
    fn default() -> Self {
        Self {
            times: Vec::new(),
            values: Vec::new(),
            held: None,
        }
    }
}

impl<T: PartialEq + Clone> Runs<T> {
    /// Adds the row `value` at `time` (times increasing).
    ///
    /// ```
    /// # use nadf::record::Runs;
    /// let mut flag = Runs::default();
    /// for (k, v) in [0, 0, 0, 1, 1, 0].into_iter().enumerate() {
    ///     flag.push(k as f64, v);
    /// }
    /// flag.end();
    /// let (times, values) = flag.take();
    /// assert_eq!(times, [0.0, 2.0, 3.0, 4.0, 5.0]);
    /// assert_eq!(values, [0, 0, 1, 1, 0]);
    /// ```
    pub fn push(&mut self, time: f64, value: T) {
        match &mut self.held {
            Some((held_time, held, first)) if *held == value => {
                // The row held before, unless it was the run's first, is inside the run now.
                *held_time = time;
                *first = false;
            }
            _ => {
                self.release();
                self.times.push(time);
                self.values.push(value.clone());
                self.held = Some((time, value, true));
            }
        }
    }

    /// Ends the rows: the last one is kept.
    pub fn end(&mut self) {
        self.release();
    }

    /// The rows kept since the last call, to send.
    pub fn take(&mut self) -> (Vec<f64>, Vec<T>) {
        (
            std::mem::take(&mut self.times),
            std::mem::take(&mut self.values),
        )
    }

    /// Keeps the held row, the last of its run, unless it is the run's first (kept already).
    fn release(&mut self) {
        if let Some((time, value, first)) = self.held.take()
            && !first
        {
            self.times.push(time);
            self.values.push(value);
        }
    }
}

/// One agent's per-step values not sent yet.
pub struct AgentColumns {
    name: String,
    paths: AgentPaths,
    times: Vec<f64>,
    /// Where the body's frame is, per step (the world's x, y and 0).
    translations: Vec<[f32; 3]>,
    /// The arrows in the body's frame (y turned over, see [`BODY_FLIP`]).
    velocities: Vec<[f32; 2]>,
    forces: Vec<[f32; 2]>,
    /// With wheels: the footprint's frame per step (the axle's centre, the heading).
    footprint: Vec<([f32; 3], f32)>,
    /// The body's colour: touching something or not.
    colours: Runs<rerun::Color>,
    contacts: Runs<Vec<[f32; 2]>>,
    plots: Vec<PlotColumn>,
    /// The trail's segment being drawn: the last point of the segment before, then the
    /// positions since (`new_points` of them).
    segment: Vec<[f32; 2]>,
    new_points: usize,
    /// The time of the segment's last point, s.
    segment_time: f64,
    /// The trail's segments not sent yet, each with the time of its last point.
    trail: Vec<(f64, Vec<[f32; 2]>)>,
}

/// One plot of an agent: its entity name, the values of the series the agent has, its rows.
struct PlotColumn {
    key: &'static str,
    values: Vec<fn(&Agent, &AgentState) -> f64>,
    rows: Runs<[f64; MOST_SERIES]>,
}

impl AgentColumns {
    /// Empty columns for `run`, and its static parts logged: the body's disc and flip, the
    /// arrows' and contacts' colours, the plots' labels.
    pub fn new(rec: &RecordingStream, run: &AgentRun) -> Result<Self, rerun::RecordingStreamError> {
        let paths = AgentPaths::of(&run.agent.name);
        // A robot on wheels: the body frame is its look-ahead point, drawn as a dot; the robot
        // is its footprint.
        let dot = match &run.agent.drive {
            Some(_) => size::points(size::CONTACT),
            None => (run.agent.radius as f32).into(),
        };
        rec.log_static(
            paths.body.as_str(),
            &[
                &rerun::Transform3D::update_fields().with_scale(BODY_FLIP)
                    as &dyn rerun::AsComponents,
                &rerun::Points2D::new([[0.0, 0.0]]).with_radii([dot]),
            ],
        )?;
        if let Some(drive) = &run.agent.drive {
            rec.log_static(
                paths.footprint.as_str(),
                &rerun::LineStrips2D::new(footprint(drive))
                    .with_colors([palette::rerun(palette::BODY)])
                    .with_radii([size::points(size::PATH)]),
            )?;
        }
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
            paths.trail.as_str(),
            &rerun::LineStrips2D::update_fields()
                .with_colors([palette::rerun(palette::BODY)])
                .with_radii([size::points(size::PATH)]),
        )?;
        rec.log_static(
            paths.contacts.as_str(),
            &rerun::Points2D::update_fields()
                .with_radii([size::points(size::CONTACT)])
                .with_colors([palette::rerun(palette::CONTACT)]),
        )?;
        let mut plots = Vec::new();
        for p in AGENT_PLOTS {
            let series: Vec<_> = p.series_of(&run.agent).collect();
            if series.is_empty() {
                continue;
            }
            rec.log_static(plot(&run.agent.name, p.key), &p.lines(&run.agent))?;
            plots.push(PlotColumn {
                key: p.key,
                values: series.iter().map(|s| s.value).collect(),
                rows: Runs::default(),
            });
        }
        Ok(Self {
            name: run.agent.name.clone(),
            paths,
            times: Vec::new(),
            translations: Vec::new(),
            velocities: Vec::new(),
            forces: Vec::new(),
            footprint: Vec::new(),
            colours: Runs::default(),
            contacts: Runs::default(),
            plots,
            segment: Vec::new(),
            new_points: 0,
            segment_time: 0.0,
            trail: Vec::new(),
        })
    }

    /// The agent's entities.
    pub fn paths(&self) -> &AgentPaths {
        &self.paths
    }

    /// Keeps `run`'s state after the step that ended at `time`, s.
    pub fn push(&mut self, time: f64, run: &AgentRun, state: &AgentState) {
        self.times.push(time);
        let [x, y] = f32x2(state.position.into());
        self.translations.push([x, y, 0.0]);
        self.segment.push([x, y]);
        self.segment_time = time;
        self.new_points += 1;
        if self.new_points == TRAIL_EVERY {
            self.end_segment();
        }
        let arrow = |v: nalgebra::Vector2<f64>, scale: f32| {
            [
                v.x as f32 * scale * BODY_FLIP[0],
                v.y as f32 * scale * BODY_FLIP[1],
            ]
        };
        if let Some((axle, heading)) = state.axle {
            let [x, y] = f32x2(axle.into());
            self.footprint.push(([x, y, 0.0], heading as f32));
        }
        self.velocities.push(arrow(state.velocity, VELOCITY_SCALE));
        self.forces.push(arrow(state.force, FORCE_SCALE));
        let touching = !state.contact_points.is_empty();
        self.colours.push(
            time,
            palette::rerun(if touching {
                palette::TOUCHING
            } else {
                palette::BODY
            }),
        );
        self.contacts.push(
            time,
            state
                .contact_points
                .iter()
                .map(|c| f32x2((*c).into()))
                .collect(),
        );
        for p in &mut self.plots {
            let mut row = [0.0; MOST_SERIES];
            for (slot, value) in row.iter_mut().zip(&p.values) {
                *slot = value(&run.agent, state);
            }
            p.rows.push(time, row);
        }
    }

    /// Ends the trail's segment (a new one starts at its last point).
    fn end_segment(&mut self) {
        if self.new_points == 0 {
            return;
        }
        let last = *self.segment.last().expect("new points");
        let segment = std::mem::replace(&mut self.segment, vec![last]);
        self.trail.push((self.segment_time, segment));
        self.new_points = 0;
    }

    /// Whether [`COLUMN_STEPS`] steps are waiting.
    pub fn full(&self) -> bool {
        self.times.len() >= COLUMN_STEPS
    }

    /// Sends the rows kept so far, one chunk per entity, and forgets them; with `end` (the
    /// recording ends), the rows held back to see whether a run goes on too.
    pub fn send(
        &mut self,
        rec: &RecordingStream,
        end: bool,
    ) -> Result<(), rerun::RecordingStreamError> {
        if end {
            self.end_segment();
            self.colours.end();
            self.contacts.end();
            self.plots.iter_mut().for_each(|p| p.rows.end());
        }
        let times = std::mem::take(&mut self.times);
        send(
            rec,
            &self.paths.body,
            &times,
            rerun::Transform3D::update_fields()
                .with_many_translation(std::mem::take(&mut self.translations))
                .columns_of_unit_batches()?,
        )?;
        let footprint = std::mem::take(&mut self.footprint);
        if footprint.len() == times.len() {
            send_poses(rec, &self.paths.footprint, &times, footprint)?;
        }
        for (path, vectors) in [
            (&self.paths.velocity, std::mem::take(&mut self.velocities)),
            (&self.paths.force, std::mem::take(&mut self.forces)),
        ] {
            let arrows = rerun::Arrows2D::update_fields().with_vectors(vectors);
            send(rec, path, &times, arrows.columns_of_unit_batches()?)?;
        }
        let (times, colours) = self.colours.take();
        let colours = rerun::Points2D::update_fields().with_colors(colours);
        send(
            rec,
            &self.paths.body,
            &times,
            colours.columns_of_unit_batches()?,
        )?;
        let (times, contacts) = self.contacts.take();
        let counts: Vec<usize> = contacts.iter().map(Vec::len).collect();
        let contacts =
            rerun::Points2D::update_fields().with_positions(contacts.into_iter().flatten());
        send(rec, &self.paths.contacts, &times, contacts.columns(counts)?)?;
        for p in &mut self.plots {
            let (times, rows) = p.rows.take();
            let n = p.values.len();
            let scalars = rerun::Scalars::new(rows.iter().flat_map(|r| r[..n].iter().copied()));
            let columns = scalars.columns(std::iter::repeat_n(n, rows.len()))?;
            send(rec, &plot(&self.name, p.key), &times, columns)?;
        }
        let (times, segments): (Vec<f64>, Vec<_>) =
            std::mem::take(&mut self.trail).into_iter().unzip();
        let trail = rerun::LineStrips2D::update_fields().with_strips(segments);
        send(
            rec,
            &self.paths.trail,
            &times,
            trail.columns_of_unit_batches()?,
        )?;
        Ok(())
    }
}

/// A robot on wheels' footprint in its own frame (the axle's centre at the origin, heading
/// along x): its disc, a line from the centre to the front, and its two wheels.
fn footprint(drive: &crate::world::DriveSettings) -> Vec<Vec<[f32; 2]>> {
    let r = drive.body_radius as f32;
    let circle = (0..=48)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 48.0;
            [r * a.cos(), r * a.sin()]
        })
        .collect();
    let half = 0.5 * drive.wheel_separation as f32;
    let wheel = 0.3 * r;
    vec![
        circle,
        vec![[0.0, 0.0], [r, 0.0]],
        vec![[-wheel, half], [wheel, half]],
        vec![[-wheel, -half], [wheel, -half]],
    ]
}

/// Sends planar `poses` (a translation and a turn about z, rad), one per time of `times`, to
/// `entity` as the columns of its transform.
pub(super) fn send_poses(
    rec: &RecordingStream,
    entity: &str,
    times: &[f64],
    poses: Vec<([f32; 3], f32)>,
) -> Result<(), rerun::RecordingStreamError> {
    let (at, angles): (Vec<[f32; 3]>, Vec<f32>) = poses.into_iter().unzip();
    let turns = (angles.into_iter())
        .map(|a| rerun::RotationAxisAngle::new([0.0, 0.0, 1.0], rerun::Angle::from_radians(a)));
    send(
        rec,
        entity,
        times,
        rerun::Transform3D::update_fields()
            .with_many_translation(at)
            .with_many_rotation_axis_angle(turns)
            .columns_of_unit_batches()?,
    )
}

/// Sends `columns` of `entity`, one row per time of `times` (s on `sim_time`), unless there
/// are none.
pub(super) fn send(
    rec: &RecordingStream,
    entity: &str,
    times: &[f64],
    columns: impl IntoIterator<Item = rerun::SerializedComponentColumn>,
) -> Result<(), rerun::RecordingStreamError> {
    if times.is_empty() {
        return Ok(());
    }
    let times = TimeColumn::new_duration_secs(SIM_TIME, times.iter().copied());
    rec.send_columns(entity, [times], columns)
}

#[cfg(test)]
mod tests {
    use super::Runs;

    #[test]
    fn runs_keep_the_first_and_last_row_of_every_run_across_sends() {
        let mut runs = Runs::default();
        let values = [1, 1, 2, 2, 2, 2, 3, 1, 1, 1];
        let (mut times, mut kept) = (Vec::new(), Vec::new());
        for (k, v) in values.into_iter().enumerate() {
            runs.push(k as f64, v);
            if k % 3 == 2 {
                let (t, v) = runs.take();
                times.extend(t);
                kept.extend(v);
            }
        }
        runs.end();
        let (t, v) = runs.take();
        times.extend(t);
        kept.extend(v);
        assert_eq!(times, [0.0, 1.0, 2.0, 5.0, 6.0, 7.0, 9.0]);
        assert_eq!(kept, [1, 1, 2, 2, 3, 1, 1]);
        // Every row left out has the value of the kept row before it (what the viewer shows
        // at its time), and lies on the line between its kept neighbours.
        for (k, v) in values.into_iter().enumerate() {
            let before = times.iter().rposition(|&t| t <= k as f64).unwrap();
            assert_eq!(kept[before], v, "row {k}");
        }
    }

    #[test]
    fn a_single_row_and_no_row_are_kept_as_they_are() {
        let mut runs = Runs::default();
        runs.end();
        assert_eq!(runs.take(), (vec![], Vec::<u8>::new()));
        runs.push(0.5, 7u8);
        runs.end();
        assert_eq!(runs.take(), (vec![0.5], vec![7]));
    }
}
