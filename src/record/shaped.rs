//! The shaped agents: the shape in its body frame (a frame that moves and turns with it), the
//! kinematic path with the shape drawn along it (its heading marks), the start and target
//! poses, the slice of the field at the body's current heading (re-logged when the body turns
//! into another slice), the trail, contacts, events, and the time series (distance, heading,
//! speeds, control, clearance).

use rerun::RecordingStream;

use super::colormap;
use super::names::{
    SHAPED_PLOTS, SIM_TIME, ShapedPaths, TRAIL_EVERY, Trail, log_plot_labels, log_plot_rows,
};
use super::palette;
use super::world::f32x2;
use crate::sim::Simulation;
use crate::sim::shaped::ShapedRun;
use crate::world::BodyShape;

/// Distance along the kinematic path between two of its heading marks, m.
const MARK_EVERY: f64 = 0.5;

/// What the step logging keeps per shaped agent.
#[derive(Default)]
pub struct ShapedSteps {
    /// The slice of the field last logged, per agent.
    slices: Vec<Option<usize>>,
    /// The deepest `log10(1 − V)` of each field (the colour scale of its slices).
    deepest: Vec<f64>,
    /// The trail of each agent.
    trails: Vec<Trail>,
    /// Whether each agent's contacts were drawn at the last step (to clear them once).
    touching: Vec<bool>,
    steps: usize,
}

/// The outlines of `shape`'s parts at `pose`, closed, for a `LineStrips2D`.
fn outlines(shape: &BodyShape, pose: [f64; 3]) -> Vec<Vec<[f32; 2]>> {
    shape
        .placed(pose)
        .into_iter()
        .map(|part| {
            let mut strip: Vec<[f32; 2]> = part.iter().map(|p| f32x2(*p)).collect();
            strip.push(strip[0]);
            strip
        })
        .collect()
}

/// Logs what does not change: the kinematic path and its marks, the start and target poses,
/// the shape in its frame, the field image's placement and the plots' labels.
pub fn log_setup(
    rec: &RecordingStream,
    sim: &Simulation,
) -> Result<ShapedSteps, rerun::RecordingStreamError> {
    let mut steps = ShapedSteps::default();
    for run in &sim.shaped {
        let (agent, paths) = (&run.agent, ShapedPaths::of(&run.agent.name));
        let grid = *run.field.grid();
        rec.log_static(
            paths.potential.as_str(),
            &rerun::Transform3D::from_translation_scale(
                [grid.origin[0] as f32, grid.origin[1] as f32, 0.0],
                rerun::Scale3D::from([grid.cell as f32, grid.cell as f32, 1.0]),
            ),
        )?;
        let path: Vec<[f32; 2]> = run.kinematic.iter().map(|p| f32x2([p[0], p[1]])).collect();
        rec.log_static(
            paths.kinematic_path.as_str(),
            &rerun::LineStrips2D::new([path])
                .with_colors([palette::rerun(palette::KINEMATIC)])
                .with_radii([0.01]),
        )?;
        let mut marks = Vec::new();
        let mut since = f64::INFINITY;
        for pair in run.kinematic.windows(2) {
            since += (pair[1][0] - pair[0][0]).hypot(pair[1][1] - pair[0][1]);
            if since >= MARK_EVERY {
                marks.extend(outlines(&run.shape, pair[0]));
                since = 0.0;
            }
        }
        if let Some(last) = run.kinematic.last() {
            marks.extend(outlines(&run.shape, *last));
        }
        rec.log_static(
            paths.kinematic_poses.as_str(),
            &rerun::LineStrips2D::new(marks)
                .with_colors([palette::rerun_alpha(palette::KINEMATIC, 90)])
                .with_radii([0.005]),
        )?;
        let start = [agent.start[0], agent.start[1], agent.heading];
        rec.log_static(
            paths.start.as_str(),
            &rerun::LineStrips2D::new(outlines(&run.shape, start))
                .with_colors([palette::rerun(palette::START)])
                .with_radii([0.008]),
        )?;
        let target = agent.target_heading.map_or_else(
            || vec![circle(agent.target, run.field.target_radius)],
            |t| outlines(&run.shape, [agent.target[0], agent.target[1], t]),
        );
        rec.log_static(
            paths.target.as_str(),
            &rerun::LineStrips2D::new(target)
                .with_colors([palette::rerun(palette::TARGET)])
                .with_radii([0.01]),
        )?;
        rec.log_static(
            paths.shape.as_str(),
            &rerun::LineStrips2D::new(outlines(&run.shape, [0.0, 0.0, 0.0]))
                .with_colors([palette::rerun(palette::BODY)])
                .with_radii([0.015]),
        )?;
        log_plot_labels(rec, SHAPED_PLOTS, &agent.name, agent)?;
        steps.slices.push(None);
        steps.deepest.push(colormap::deepest(&run.field));
        steps.trails.push(Trail::from(f32x2(agent.start)));
        steps.touching.push(false);
    }
    Ok(steps)
}

/// A circle of `radius` about `center`, as a closed strip.
fn circle(center: [f64; 2], radius: f64) -> Vec<[f32; 2]> {
    (0..=48)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 48.0;
            f32x2([center[0] + radius * a.cos(), center[1] + radius * a.sin()])
        })
        .collect()
}

impl ShapedSteps {
    /// Logs every shaped agent's state after the step that ended at `time`, s (`last`: the
    /// run's last step, which closes the trails).
    pub fn log_step(
        &mut self,
        rec: &RecordingStream,
        time: f64,
        runs: &[ShapedRun],
        last: bool,
    ) -> Result<(), rerun::RecordingStreamError> {
        if runs.is_empty() {
            return Ok(());
        }
        rec.set_duration_secs(SIM_TIME, time);
        self.steps += 1;
        for (n, run) in runs.iter().enumerate() {
            let (paths, s) = (ShapedPaths::of(&run.agent.name), run.state());
            let [x, y, theta] = s.pose;
            rec.log(
                paths.body.as_str(),
                &rerun::Transform3D::from_translation_rotation(
                    [x as f32, y as f32, 0.0],
                    rerun::RotationAxisAngle::new(
                        [0.0, 0.0, 1.0],
                        rerun::Angle::from_radians(theta as f32),
                    ),
                ),
            )?;
            let slice = run.field.mask.slice_of(theta);
            if self.slices[n] != Some(slice) {
                self.slices[n] = Some(slice);
                let (image, size) = colormap::pose_slice_image(&run.field, theta, self.deepest[n]);
                rec.log(
                    paths.potential.as_str(),
                    &rerun::Image::from_rgb24(image, size).with_draw_order(-10.0),
                )?;
            }
            let due = self.steps.is_multiple_of(TRAIL_EVERY) || last;
            if let Some(segment) = self.trails[n].push(f32x2([x, y]), due) {
                rec.log(
                    paths.trail.as_str(),
                    &rerun::LineStrips2D::new([segment])
                        .with_colors([palette::rerun(palette::BODY)])
                        .with_radii([0.01]),
                )?;
            }
            let touching = !s.contact_points.is_empty();
            if touching || self.touching[n] {
                let points: Vec<[f32; 2]> =
                    s.contact_points.iter().map(|p| f32x2([p.x, p.y])).collect();
                rec.log(
                    paths.contacts.as_str(),
                    &rerun::Points2D::new(points)
                        .with_colors([palette::rerun(palette::CONTACT)])
                        .with_radii([0.04]),
                )?;
            }
            self.touching[n] = touching;
            for event in &s.events {
                rec.log(
                    paths.events.as_str(),
                    &rerun::TextLog::new(event.as_str()).with_level(rerun::TextLogLevel::WARN),
                )?;
            }
            log_plot_rows(rec, SHAPED_PLOTS, &run.agent.name, (&run.agent, s))?;
        }
        Ok(())
    }
}
