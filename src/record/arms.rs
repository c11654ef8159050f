//! The arms: base and target (static), the links as capsules from joint to joint and the tip's
//! trail per step, contacts as events, and the joint angles and torques plotted.

use rerun::RecordingStream;

use super::names::{ARM_PLOTS, ArmPaths, SIM_TIME, plot};
use super::palette;
use super::world::f32x2;
use crate::sim::arm_run::ArmRun;

/// Steps between two segments of a tip's trail.
const TRAIL_EVERY: usize = 25;

/// What the step logging keeps: each arm's trail since its last segment.
#[derive(Default)]
pub struct ArmSteps {
    trails: Vec<Vec<[f32; 2]>>,
    steps: usize,
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
        for p in ARM_PLOTS {
            rec.log_static(plot(&settings.name, p.key), &p.lines(settings))?;
        }
        steps
            .trails
            .push(vec![f32x2(arm.chain.tip(&settings.start))]);
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
            self.trails[n].push(f32x2(*s.joints.last().expect("a tip")));
            if self.steps.is_multiple_of(TRAIL_EVERY) || last {
                let segment = std::mem::take(&mut self.trails[n]);
                self.trails[n].push(*segment.last().expect("one point"));
                rec.log(
                    paths.trail.as_str(),
                    &rerun::LineStrips2D::new([segment])
                        .with_colors([palette::rerun(palette::KINEMATIC)])
                        .with_radii([0.008]),
                )?;
            }
            for event in &s.events {
                rec.log(
                    paths.events.as_str(),
                    &rerun::TextLog::new(event.as_str()).with_level(rerun::TextLogLevel::WARN),
                )?;
            }
            for p in ARM_PLOTS {
                rec.log(
                    plot(&arm.settings.name, p.key),
                    &rerun::Scalars::new(
                        p.series_of(&arm.settings)
                            .map(|x| (x.value)(&arm.settings, s)),
                    ),
                )?;
            }
        }
        Ok(())
    }
}
