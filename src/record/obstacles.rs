//! The moving obstacles: each one's shape in its own frame (static), the frame moved and turned
//! every step (kept in columns and sent with the agents'), and its path, or a wander's region,
//! drawn once (static).

use rerun::RecordingStream;

use super::columns::{COLUMN_STEPS, send_poses};
use super::names::ObstaclePaths;
use super::palette::{self, size};
use super::world::f32x2;
use crate::sim::obstacles::ObstacleRun;
use crate::world::{ObstacleMode, outline_box, wall_outline};

/// What the step logging keeps: the times of the steps not sent yet, and each obstacle's pose
/// at them (translation, rotation in rad).
#[derive(Default)]
pub struct ObstacleSteps {
    times: Vec<f64>,
    poses: Vec<Vec<([f32; 3], f32)>>,
    paths: Vec<ObstaclePaths>,
}

/// Logs each obstacle's shape in its frame and its path (or region), static.
pub fn log_setup(
    rec: &RecordingStream,
    obstacles: &[ObstacleRun],
) -> Result<ObstacleSteps, rerun::RecordingStreamError> {
    let mut steps = ObstacleSteps::default();
    for run in obstacles {
        let paths = ObstaclePaths::of(&run.name);
        let o = &run.obstacle;
        let outline: Vec<[f32; 2]> = wall_outline(&o.local_shape())
            .into_iter()
            .map(f32x2)
            .collect();
        rec.log_static(
            paths.shape.as_str(),
            &rerun::LineStrips2D::new([outline])
                .with_colors([palette::rerun(palette::OBSTACLE)])
                .with_radii([0.03]),
        )?;
        // Where it goes: its waypoints (a loop's closed), or the box a wanderer stays in.
        let route: Option<Vec<[f32; 2]>> = match (&o.path, o.mode, o.region) {
            (Some(points), mode, _) => {
                let mut route: Vec<[f32; 2]> = points.iter().map(|p| f32x2(*p)).collect();
                if matches!(mode, None | Some(ObstacleMode::Loop)) {
                    route.push(route[0]);
                }
                Some(route)
            }
            (None, Some(ObstacleMode::Wander), Some([lo, hi])) => {
                let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
                let half = [(hi[0] - lo[0]) / 2.0, (hi[1] - lo[1]) / 2.0];
                Some(
                    outline_box(centre, half, 0.0)
                        .into_iter()
                        .map(f32x2)
                        .collect(),
                )
            }
            _ => None,
        };
        if let Some(route) = route {
            rec.log_static(
                paths.path.as_str(),
                &rerun::LineStrips2D::new([route])
                    .with_colors([palette::rerun_alpha(palette::OBSTACLE, 90)])
                    .with_radii([size::points(size::PATH)]),
            )?;
        }
        steps.paths.push(paths);
        steps.poses.push(Vec::new());
    }
    Ok(steps)
}

impl ObstacleSteps {
    /// Keeps each obstacle's pose after the step that ended at `time`, s, and sends them when
    /// [`COLUMN_STEPS`] are waiting or `last` (the run's last step).
    pub fn log_step(
        &mut self,
        rec: &RecordingStream,
        time: f64,
        obstacles: &[ObstacleRun],
        last: bool,
    ) -> Result<(), rerun::RecordingStreamError> {
        if obstacles.is_empty() {
            return Ok(());
        }
        self.times.push(time);
        for (poses, run) in self.poses.iter_mut().zip(obstacles) {
            let p = run.position();
            poses.push(([p.x as f32, p.y as f32, 0.0], run.angle() as f32));
        }
        if self.times.len() >= COLUMN_STEPS || last {
            self.send(rec)?;
        }
        Ok(())
    }

    /// Sends the poses kept so far, one chunk per obstacle, and forgets them.
    pub fn send(&mut self, rec: &RecordingStream) -> Result<(), rerun::RecordingStreamError> {
        let times = std::mem::take(&mut self.times);
        for (paths, poses) in self.paths.iter().zip(&mut self.poses) {
            send_poses(rec, &paths.body, &times, std::mem::take(poses))?;
        }
        Ok(())
    }
}
