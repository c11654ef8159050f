//! The pendulums: pivot and target rod (static), rod and bob per step, bias updates as
//! events, and their time series.

use rerun::RecordingStream;

use super::names::{PENDULUM_PLOTS, PendulumPaths, SIM_TIME, log_plot_labels, log_plot_rows};
use super::palette;
use super::world::f32x2;
use crate::sim::pendulum::PendulumRun;

/// Logs each pendulum's pivot, the rod at its target angle and its series' labels (static).
pub fn log_setup(
    rec: &RecordingStream,
    pendulums: &[PendulumRun],
) -> Result<(), rerun::RecordingStreamError> {
    for p in pendulums {
        let (pendulum, paths) = (&p.pendulum, PendulumPaths::of(&p.pendulum.name));
        rec.log_static(
            paths.pivot,
            &rerun::Points2D::new([f32x2(pendulum.pivot)])
                .with_radii([0.04])
                .with_colors([palette::rerun(palette::WALL)]),
        )?;
        let [px, py] = pendulum.pivot;
        let (l, target) = (pendulum.length, pendulum.target);
        rec.log_static(
            paths.target,
            &rerun::LineStrips2D::new([[
                f32x2([px, py]),
                f32x2([px + l * target.sin(), py - l * target.cos()]),
            ]])
            .with_colors([palette::rerun(palette::TARGET)])
            .with_radii([0.01]),
        )?;
        log_plot_labels(rec, PENDULUM_PLOTS, &pendulum.name, pendulum)?;
    }
    Ok(())
}

/// Logs each pendulum's rod, bob, bias update and series after the step that ended at
/// `time`, s.
pub fn log_step(
    rec: &RecordingStream,
    time: f64,
    pendulums: &[PendulumRun],
) -> Result<(), rerun::RecordingStreamError> {
    if !pendulums.is_empty() {
        rec.set_duration_secs(SIM_TIME, time);
    }
    for p in pendulums {
        let (pendulum, paths, s) = (&p.pendulum, PendulumPaths::of(&p.pendulum.name), &p.state);
        rec.log(
            paths.rod,
            &rerun::LineStrips2D::new([[f32x2(pendulum.pivot), f32x2(s.bob)]])
                .with_colors([palette::rerun(palette::ROD)])
                .with_radii([0.015]),
        )?;
        rec.log(
            paths.bob,
            &rerun::Points2D::new([f32x2(s.bob)])
                .with_radii([0.08])
                .with_colors([palette::rerun(palette::BODY)]),
        )?;
        log_plot_rows(rec, PENDULUM_PLOTS, &pendulum.name, (pendulum, s))?;
        if let Some(note) = &s.note {
            rec.log(
                paths.events,
                &rerun::TextLog::new(note.as_str()).with_level(rerun::TextLogLevel::INFO),
            )?;
        }
    }
    Ok(())
}
