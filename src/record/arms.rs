//! The arms: base and target (static), the links as capsules from joint to joint and the tip's
//! trail per step, contacts as events, and the joint angles and torques plotted.

use rerun::RecordingStream;

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
    /// Each two-link arm's joint angles since the last segment of its joint-space path.
    paths: Vec<Vec<[f32; 2]>>,
    steps: usize,
}

/// A two-link arm's joint-space field as an image: pixel `(k₁, k₂)` is the cell of joint
/// cells `k₁, k₂`, placed so that image coordinates are radians (`q₁` right, `q₂` down).
fn log_joint_field(
    rec: &RecordingStream,
    arm: &ArmRun,
    root: &str,
) -> Result<(), rerun::RecordingStreamError> {
    let field = &arm.field;
    let (a1, a2) = (field.mask.axes[0], field.mask.axes[1]);
    let deepest = (0..field.w.len())
        .filter(|&c| field.reachable[c])
        .map(|c| field.w.log10(c))
        .filter(|l| l.is_finite())
        .fold(0.0, f64::min);
    let mut rgb = Vec::with_capacity(a1.cells * a2.cells * 3);
    for k2 in 0..a2.cells {
        for k1 in 0..a1.cells {
            let c = field.mask.index(&[k1, k2]);
            let colour = if field.mask.blocked[c] {
                palette::BLOCKED
            } else if !field.reachable[c] {
                palette::UNREACHABLE
            } else {
                let l = field.w.log10(c);
                super::colormap::viridis(if deepest < 0.0 {
                    1.0 - l / deepest
                } else {
                    1.0
                })
            };
            rgb.extend_from_slice(&colour);
        }
    }
    let field_path = format!("{root}/field");
    let lo = |a: &crate::field::JointAxis| (a.center(0) - 0.5 * a.step()) as f32;
    rec.log_static(
        field_path.as_str(),
        &rerun::Transform3D::from_translation_scale(
            [lo(&a1), lo(&a2), 0.0],
            rerun::Scale3D::from([a1.step() as f32, a2.step() as f32, 1.0]),
        ),
    )?;
    rec.log_static(
        field_path.as_str(),
        &rerun::Image::from_rgb24(rgb, [a1.cells as u32, a2.cells as u32]).with_draw_order(-10.0),
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
        if arm.chain.links.len() == 2 {
            log_joint_field(rec, arm, &paths.joint_space)?;
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
            if arm.chain.links.len() == 2 {
                // The angles on the field's axes (a free joint wraps into [−π, π)).
                let onto = |a: &crate::field::JointAxis, q: f64| {
                    if a.periodic() {
                        (q + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI
                    } else {
                        q
                    }
                };
                let axes = &arm.field.mask.axes;
                self.paths[n].push([onto(&axes[0], s.q[0]) as f32, onto(&axes[1], s.q[1]) as f32]);
                if self.steps.is_multiple_of(TRAIL_EVERY) || last {
                    let points = std::mem::take(&mut self.paths[n]);
                    rec.log(
                        format!("{}/path", paths.joint_space),
                        &rerun::Points2D::new(points)
                            .with_colors([palette::rerun(palette::BODY)])
                            .with_radii([palette::size::points(palette::size::PATH)]),
                    )?;
                }
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
