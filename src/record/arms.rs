//! The arms: base and target (static), the links as capsules from joint to joint and the tip's
//! trail per step, contacts as events, the joint angles and torques plotted, and the joint
//! space: its field as an image with the arm's path on it (both joints of a two-link arm; for
//! three links the slice through the first joint's current angle, re-logged as it turns into
//! another cell, with the path's projection on the last two joints).

use rerun::RecordingStream;

use super::colormap::{joint_deepest, joint_image, joint_plane};
use super::names::{
    ARM_PLOTS, ArmPaths, SIM_TIME, TRAIL_EVERY, Trail, log_plot_labels, log_plot_rows,
};
use super::palette;
use super::world::f32x2;
use crate::sim::arm_run::ArmRun;

/// What the step logging keeps: each arm's trail since its last segment.
#[derive(Default)]
pub struct ArmSteps {
    trails: Vec<Trail>,
    /// Each arm's joint-space angles (on its image's axes) since the last segment of its path.
    paths: Vec<Vec<[f32; 2]>>,
    /// Each three-link arm's slice last logged (the first joint's cell).
    slices: Vec<Option<usize>>,
    /// The deepest `log10(1 − V)` of each arm's field (the colour scale of its images).
    deepest: Vec<f64>,
    steps: usize,
}

/// The static transform that puts [`joint_image`]'s pixels at their joint angles, rad.
fn log_joint_axes(
    rec: &RecordingStream,
    arm: &ArmRun,
    root: &str,
) -> Result<(), rerun::RecordingStreamError> {
    let [a, b] = joint_plane(&arm.field).map(|k| arm.field.mask.axes[k]);
    let lo = |a: &crate::field::JointAxis| (a.center(0) - 0.5 * a.step()) as f32;
    rec.log_static(
        format!("{root}/field"),
        &rerun::Transform3D::from_translation_scale(
            [lo(&a), lo(&b), 0.0],
            rerun::Scale3D::from([a.step() as f32, b.step() as f32, 1.0]),
        ),
    )
}

/// Logs each arm's base, its target and its plots' labels (static).
pub fn log_setup(
    rec: &RecordingStream,
    arms: &[ArmRun],
) -> Result<ArmSteps, rerun::RecordingStreamError> {
    let mut steps = ArmSteps::default();
    for arm in arms {
        let (settings, paths) = (&arm.settings, ArmPaths::of(&arm.settings.name));
        rec.log_static(
            paths.base.as_str(),
            &rerun::Points2D::new([f32x2(settings.base)])
                .with_radii([0.06])
                .with_colors([palette::rerun(palette::WALL)]),
        )?;
        let target = match (&settings.target_joints, settings.target_point) {
            (Some(q), _) => vec![arm.chain.joints(q).into_iter().map(f32x2).collect()],
            (None, Some(p)) => vec![
                (0..=48)
                    .map(|k| {
                        let a = k as f64 * std::f64::consts::TAU / 48.0;
                        let r = settings.target_radius;
                        f32x2([p[0] + r * a.cos(), p[1] + r * a.sin()])
                    })
                    .collect::<Vec<_>>(),
            ],
            (None, None) => Vec::new(),
        };
        rec.log_static(
            paths.target.as_str(),
            &rerun::LineStrips2D::new(target)
                .with_colors([palette::rerun(palette::TARGET)])
                .with_radii([0.01]),
        )?;
        log_plot_labels(rec, ARM_PLOTS, &settings.name, settings)?;
        steps
            .trails
            .push(Trail::from(f32x2(arm.chain.tip(&settings.start))));
        steps.paths.push(Vec::new());
        steps.slices.push(None);
        steps.deepest.push(joint_deepest(&arm.field));
        log_joint_axes(rec, arm, &paths.joint_space)?;
        if arm.chain.links.len() == 2 {
            let (image, size) = joint_image(&arm.field, 0, *steps.deepest.last().expect("pushed"));
            rec.log_static(
                format!("{}/field", paths.joint_space),
                &rerun::Image::from_rgb24(image, size).with_draw_order(-10.0),
            )?;
        }
    }
    Ok(steps)
}

impl ArmSteps {
    /// Logs each arm after the step that ended at `time`, s (`last`: the run's last step).
    pub fn log_step(
        &mut self,
        rec: &RecordingStream,
        time: f64,
        arms: &[ArmRun],
        last: bool,
    ) -> Result<(), rerun::RecordingStreamError> {
        if arms.is_empty() {
            return Ok(());
        }
        rec.set_duration_secs(SIM_TIME, time);
        self.steps += 1;
        for (n, arm) in arms.iter().enumerate() {
            let (paths, s) = (ArmPaths::of(&arm.settings.name), arm.state());
            let links: Vec<Vec<[f32; 2]>> = s
                .joints
                .windows(2)
                .map(|w| vec![f32x2(w[0]), f32x2(w[1])])
                .collect();
            let radii: Vec<f32> = arm.chain.links.iter().map(|l| l.radius as f32).collect();
            let colour = if s.events.is_empty() {
                palette::BODY
            } else {
                palette::TOUCHING
            };
            rec.log(
                paths.links.as_str(),
                &rerun::LineStrips2D::new(links)
                    .with_radii(radii)
                    .with_colors([palette::rerun(colour)]),
            )?;
            let due = self.steps.is_multiple_of(TRAIL_EVERY) || last;
            if let Some(segment) = self.trails[n].push(f32x2(*s.joints.last().expect("a tip")), due)
            {
                rec.log(
                    paths.trail.as_str(),
                    &rerun::LineStrips2D::new([segment])
                        .with_colors([palette::rerun(palette::KINEMATIC)])
                        .with_radii([0.008]),
                )?;
            }
            // The angles on the field's axes (a free joint wraps into [−π, π)).
            let axes = &arm.field.mask.axes;
            let onto = |k: usize| {
                let q = s.q[k];
                if axes[k].periodic() {
                    (q + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI
                } else {
                    q
                }
            };
            if axes.len() == 3
                && let Some(slice) = axes[0].cell_of(onto(0))
                && self.slices[n] != Some(slice)
            {
                // Three links: the slice through the first joint's current cell, re-logged
                // when the arm turns into another.
                self.slices[n] = Some(slice);
                let (image, size) = joint_image(&arm.field, slice, self.deepest[n]);
                rec.log(
                    format!("{}/field", paths.joint_space),
                    &rerun::Image::from_rgb24(image, size).with_draw_order(-10.0),
                )?;
            }
            let [a, b] = joint_plane(&arm.field);
            self.paths[n].push([onto(a) as f32, onto(b) as f32]);
            if self.steps.is_multiple_of(TRAIL_EVERY) || last {
                let points = std::mem::take(&mut self.paths[n]);
                rec.log(
                    format!("{}/path", paths.joint_space),
                    &rerun::Points2D::new(points)
                        .with_colors([palette::rerun(palette::BODY)])
                        .with_radii([palette::size::points(palette::size::PATH)]),
                )?;
            }
            for event in &s.events {
                rec.log(
                    paths.events.as_str(),
                    &rerun::TextLog::new(event.as_str()).with_level(rerun::TextLogLevel::WARN),
                )?;
            }
            log_plot_rows(rec, ARM_PLOTS, &arm.settings.name, (&arm.settings, s))?;
        }
        Ok(())
    }
}
