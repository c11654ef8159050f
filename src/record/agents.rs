//! The agents: each one's field, guidance arrows, kinematic path, start and target (static);
//! its body, velocity, force, contacts, trail, events and sensed walls per step; and its time
//! series.

use rerun::RecordingStream;

use super::colormap;
use super::columns::AgentColumns;
use super::names::{AgentPaths, SIM_TIME};
use super::palette::{self, size};
use super::world::f32x2;
use crate::sim::{AgentRun, AgentState, Simulation};

/// Arrows shown per side of the box in the guidance arrow field.
const GUIDANCE_ARROWS: usize = 24;

/// Logs each agent's field, guidance, kinematic path, start and target (static).
pub fn log_setup(
    rec: &RecordingStream,
    sim: &Simulation,
) -> Result<(), rerun::RecordingStreamError> {
    for (index, run) in sim.agents.iter().enumerate() {
        let paths = AgentPaths::of(&run.agent.name);
        if let Some(field) = run.field.harmonic() {
            let grid = *field.grid();
            // The layout shows the first agent's field; the others' (hidden, to switch on) are
            // kept small, so a crowd's recording is not dozens of full-size images.
            let stride = if index == 0 {
                1
            } else {
                thumbnail_stride(&grid)
            };
            let (image, resolution) = thinned(colormap::potential_image(field), stride);
            let scale = (grid.cell * stride as f64) as f32;
            rec.log_static(
                paths.potential.as_str(),
                &rerun::Transform3D::from_translation_scale(
                    [grid.origin[0] as f32, grid.origin[1] as f32, 0.0],
                    rerun::Scale3D::from([scale, scale, 1.0]),
                ),
            )?;
            if run.lidar.is_some() {
                // It changes as the map grows: logged on the timeline (log_lidar), with the
                // map, at the map's resolution.
                let step = thumbnail_stride(&grid);
                let scale = (grid.cell * step as f64) as f32;
                for path in [&paths.known_map, &paths.potential] {
                    rec.log_static(
                        path.as_str(),
                        &rerun::Transform3D::from_translation_scale(
                            [grid.origin[0] as f32, grid.origin[1] as f32, 0.0],
                            rerun::Scale3D::from([scale, scale, 1.0]),
                        ),
                    )?;
                }
            } else if replots_field(sim) {
                // Re-solved whole around the moving obstacles: on the timeline (log_replanned).
                rec.set_duration_secs(SIM_TIME, 0.0);
                rec.log(
                    paths.potential.as_str(),
                    &rerun::Image::from_rgb24(image, resolution).with_draw_order(-10.0),
                )?;
            } else {
                rec.log_static(
                    paths.potential.as_str(),
                    &rerun::Image::from_rgb24(image, resolution).with_draw_order(-10.0),
                )?;
            }
        }
        // A lidar agent's arrows change with its field: re-logged with it (log_lidar); so do
        // those of an agent that replans around moving obstacles (log_replanned).
        if run.lidar.is_none() && sim.obstacles.is_empty() {
            rec.log_static(paths.guidance, &arrows(sim, run))?;
        } else if run.lidar.is_none() {
            rec.set_duration_secs(SIM_TIME, 0.0);
            rec.log(paths.guidance, &arrows(sim, run))?;
        }
        let path: Vec<[f32; 2]> = run.kinematic.points.iter().map(|p| f32x2(*p)).collect();
        rec.log_static(
            paths.kinematic_path,
            &rerun::LineStrips2D::new([path])
                .with_colors([palette::rerun(palette::KINEMATIC)])
                .with_radii([size::points(size::PATH)]),
        )?;
        rec.log_static(
            paths.target,
            &rerun::Points2D::new([f32x2(run.agent.target)])
                .with_radii([size::points(size::MARKER)])
                .with_colors([palette::rerun(palette::TARGET)]),
        )?;
        rec.log_static(
            paths.start,
            &rerun::Points2D::new([f32x2(run.agent.start)])
                .with_radii([size::points(size::MARKER)])
                .with_colors([palette::rerun(palette::START)]),
        )?;
    }
    Ok(())
}

/// What the agents log every step: their columns, and which lidar field each last logged
/// (empty until the recording is set up).
#[derive(Default)]
pub struct Steps {
    columns: Vec<AgentColumns>,
    /// Per agent, the lidar field last logged (`LidarRun::fields`).
    fields_logged: Vec<usize>,
    /// Per agent that replans around moving obstacles without a lidar: when its guidance was
    /// last logged, s, and how many re-solves its field had then.
    replans_logged: Vec<(f64, usize)>,
}

impl Steps {
    /// Every agent's empty columns, their static parts logged.
    pub fn new(
        rec: &RecordingStream,
        sim: &Simulation,
    ) -> Result<Self, rerun::RecordingStreamError> {
        Ok(Self {
            columns: (sim.agents.iter())
                .map(|run| AgentColumns::new(rec, run))
                .collect::<Result<_, _>>()?,
            fields_logged: vec![0; sim.agents.len()],
            replans_logged: vec![(0.0, 0); sim.agents.len()],
        })
    }

    /// Logs each agent's state after a step; `last` is the run's last step (the columns are
    /// then sent whatever they hold).
    pub fn log_step(
        &mut self,
        rec: &RecordingStream,
        sim: &Simulation,
        states: &[AgentState],
        last: bool,
    ) -> Result<(), rerun::RecordingStreamError> {
        let mut sent = false;
        let agents = sim.agents.iter().zip(states);
        let logged = (self.fields_logged.iter_mut()).zip(&mut self.replans_logged);
        for (index, ((run, state), (columns, (field_logged, replan_logged)))) in
            agents.zip(self.columns.iter_mut().zip(logged)).enumerate()
        {
            log_events(rec, sim.time(), columns.paths(), state)?;
            if run.lidar.is_none() && !sim.obstacles.is_empty() {
                let (at, resolves) = *replan_logged;
                let now = run.metrics.resolves();
                if now != resolves && sim.time() >= at + REPLAN_IMAGE_EVERY {
                    *replan_logged = (sim.time(), now);
                    log_replanned(rec, columns.paths(), sim, (index, run))?;
                }
            }
            if let Some(lidar) = &run.lidar {
                let due = lidar.lidar.scans % LIDAR_IMAGE_EVERY == 1;
                let new = *field_logged != lidar.fields;
                if state.scan.is_some() && due && new {
                    *field_logged = lidar.fields;
                }
                log_lidar(rec, columns.paths(), sim, run, state, due && new)?;
            }
            columns.push(sim.time(), run, state);
            if columns.full() || last {
                columns.send(rec, last)?;
                sent = true;
            }
        }
        if sent {
            // On to the file's writer now, to be encoded while the run goes on.
            let _ = rec.flush_async();
        }
        Ok(())
    }

    /// Sends the per-step values waiting; with `end`, the recording ends here (the run was
    /// interrupted, or has ended).
    pub fn send(
        &mut self,
        rec: &RecordingStream,
        end: bool,
    ) -> Result<(), rerun::RecordingStreamError> {
        self.columns.iter_mut().try_for_each(|c| c.send(rec, end))
    }
}

/// Every `stride`-th pixel of an RGB `image` of `[width, height]` pixels along both axes.
fn thinned((image, [w, h]): (Vec<u8>, [u32; 2]), stride: usize) -> (Vec<u8>, [u32; 2]) {
    if stride <= 1 {
        return (image, [w, h]);
    }
    let (w, h) = (w as usize, h as usize);
    let mut small = Vec::with_capacity(w.div_ceil(stride) * h.div_ceil(stride) * 3);
    for j in (0..h).step_by(stride) {
        for i in (0..w).step_by(stride) {
            let k = 3 * (j * w + i);
            small.extend_from_slice(&image[k..k + 3]);
        }
    }
    let size = [w.div_ceil(stride) as u32, h.div_ceil(stride) as u32];
    (small, size)
}

/// Cells per pixel of a small image of `grid` (a lidar agent's map and field, another agent's
/// field than the first): at most [`LIDAR_IMAGE`] pixels a side.
fn thumbnail_stride(grid: &crate::field::Grid) -> usize {
    grid.nx.max(grid.ny).div_ceil(LIDAR_IMAGE).max(1)
}

/// Simulated time between two logs of the guidance of an agent that replans around moving
/// obstacles, s.
const REPLAN_IMAGE_EVERY: f64 = 1.0;

/// Whether the agents' field images are re-logged as their fields are re-solved: the whole
/// field is re-solved around moving obstacles (`replan = "full"`; a local replan re-solves a
/// window, which the image of the field of the walls does not show).
fn replots_field(sim: &Simulation) -> bool {
    !sim.obstacles.is_empty() && sim.world.field.replan == crate::world::Replan::Full
}

/// The guidance of agent `index`, `run`, which replans around moving obstacles without a lidar,
/// as its field is now (and the field's image, where the whole field is re-solved; a thumbnail
/// but for the first agent's, as at the set-up).
fn log_replanned(
    rec: &RecordingStream,
    paths: &AgentPaths,
    sim: &Simulation,
    (index, run): (usize, &AgentRun),
) -> Result<(), rerun::RecordingStreamError> {
    rec.set_duration_secs(SIM_TIME, sim.time());
    rec.log(paths.guidance.as_str(), &arrows(sim, run))?;
    if replots_field(sim)
        && let Some(field) = run.field.harmonic()
    {
        let stride = if index == 0 {
            1
        } else {
            thumbnail_stride(field.grid())
        };
        let (image, size) = thinned(colormap::potential_image(field), stride);
        rec.log(
            paths.potential.as_str(),
            &rerun::Image::from_rgb24(image, size).with_draw_order(-10.0),
        )?;
    }
    Ok(())
}

/// The largest side of a lidar agent's map image, pixels (the image is re-logged as the map
/// grows, so it is kept small).
const LIDAR_IMAGE: usize = 128;
/// Scans between two logs of the map and the field (at 10 Hz: once a second).
const LIDAR_IMAGE_EVERY: usize = 10;
/// Rays of a scan shown (evenly picked).
const LIDAR_RAYS_SHOWN: usize = 90;

/// A lidar agent's latest scan, and with `images` (every [`LIDAR_IMAGE_EVERY`] scans, when its
/// field has been re-solved since the last ones) its map (occupied black, free translucent
/// white, unknown clear), the field it now follows and its guidance arrows.
fn log_lidar(
    rec: &RecordingStream,
    paths: &AgentPaths,
    sim: &Simulation,
    run: &AgentRun,
    state: &AgentState,
    images: bool,
) -> Result<(), rerun::RecordingStreamError> {
    let (Some(lidar), Some(beams)) = (&run.lidar, &state.scan) else {
        return Ok(());
    };
    rec.set_duration_secs(SIM_TIME, sim.time());
    let every = beams.len().div_ceil(LIDAR_RAYS_SHOWN).max(1);
    let rays: Vec<[[f32; 2]; 2]> = beams
        .iter()
        .step_by(every)
        .map(|b| [f32x2(b.from), f32x2(b.to)])
        .collect();
    rec.log(
        paths.scan.as_str(),
        &rerun::LineStrips2D::new(rays)
            .with_radii([size::points(size::RAY)])
            .with_colors([palette::rerun_alpha(palette::SENSED, palette::SENSED_ALPHA)]),
    )?;
    if !images {
        return Ok(());
    }
    let grid = *lidar.map.grid();
    let step = thumbnail_stride(&grid);
    let (w, h) = (grid.nx.div_ceil(step), grid.ny.div_ceil(step));
    let mut rgba = Vec::with_capacity(w * h * 4);
    for j in (0..grid.ny).step_by(step) {
        for i in (0..grid.nx).step_by(step) {
            let k = grid.index(i, j);
            let pixel = if lidar.map.occupied()[k] {
                [0, 0, 0, 255]
            } else if lidar.map.seen()[k] {
                [255, 255, 255, 60]
            } else {
                [0, 0, 0, 0]
            };
            rgba.extend_from_slice(&pixel);
        }
    }
    rec.log(
        paths.known_map.as_str(),
        &rerun::Image::from_rgba32(rgba, [w as u32, h as u32]).with_draw_order(-5.0),
    )?;
    if let Some(field) = run.field.harmonic() {
        // At the map's resolution: this image is re-logged as the field is re-solved.
        let (small, size) = thinned(colormap::potential_image(field), step);
        rec.log(
            paths.potential.as_str(),
            &rerun::Image::from_rgb24(small, size).with_draw_order(-10.0),
        )?;
    }
    rec.log(paths.guidance.as_str(), &arrows(sim, run))?;
    Ok(())
}

/// The guidance arrows of `run`'s current field, drawn.
fn arrows(sim: &Simulation, run: &AgentRun) -> rerun::Arrows2D {
    let (origins, vectors) = guidance_arrows(sim, run);
    rerun::Arrows2D::from_vectors(vectors)
        .with_origins(origins)
        .with_colors([palette::rerun_alpha(
            palette::GUIDANCE,
            palette::GUIDANCE_ALPHA,
        )])
}

/// The agent's events of the step that ended at `time` (WARN) and notes (INFO), and the walls
/// its sensor saw.
fn log_events(
    rec: &RecordingStream,
    time: f64,
    paths: &AgentPaths,
    state: &AgentState,
) -> Result<(), rerun::RecordingStreamError> {
    if state.events.is_empty() && state.notes.is_empty() && state.sensed_walls.is_none() {
        return Ok(());
    }
    rec.set_duration_secs(SIM_TIME, time);
    for (messages, level) in [
        (&state.events, rerun::TextLogLevel::WARN),
        (&state.notes, rerun::TextLogLevel::INFO),
    ] {
        for message in messages {
            rec.log(
                paths.events.as_str(),
                &rerun::TextLog::new(message.as_str()).with_level(level),
            )?;
        }
    }
    if let Some(sensed) = &state.sensed_walls {
        rec.log(
            paths.sensed_walls.as_str(),
            &rerun::Points2D::new(sensed.iter().map(|p| f32x2(*p)))
                .with_radii([size::points(size::SENSED)])
                .with_colors([palette::rerun_alpha(palette::SENSED, palette::SENSED_ALPHA)]),
        )?;
    }
    Ok(())
}

/// A sparse field of unit guidance arrows `-∇V/|∇V|`: at reachable cells of a harmonic field,
/// at the free points of a regular lattice for an attractive-repulsive one.
fn guidance_arrows(sim: &Simulation, run: &AgentRun) -> (Vec<[f32; 2]>, Vec<[f32; 2]>) {
    let [w, h] = sim.world.size;
    let [x0, y0] = sim.world.origin;
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
            let c = [
                x0 + (i as f64 + 0.5) * spacing,
                y0 + (j as f64 + 0.5) * spacing,
            ];
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
