//! The Rerun recording of a run (`.rrd`), what users open in the Rerun viewer.
//!
//! Entity paths:
//! - `world/box`, `world/walls`: the geometry (static).
//! - `agents/NAME/field/potential`: `log10(1 - V)` of the agent's field as an image (static);
//!   the log scale shows how flat the potential is far from the target. Blocked cells are dark
//!   grey, free cells the target cannot be reached from are black.
//! - `agents/NAME/field/guidance`: a sparse arrow field of the unit guidance `-∇V/|∇V|` (static).
//! - `agents/NAME/kinematic_path`, `agents/NAME/target` (static).
//! - `agents/NAME/body`: a frame that moves with the agent (its translation per step is the
//!   agent's position, turned y-down so a view rooted there shows the world upright) with the
//!   disc at its origin (its colour changes while it touches something); `…/body/velocity`,
//!   `…/body/force`: the arrows, in that frame; `agents/NAME/contacts`: where it touches; all
//!   per step, sent as columns (`columns.rs`).
//! - `agents/NAME/trail`: the path so far, a segment of 25 steps at a time (the layout shows
//!   every segment up to the time cursor).
//! - `agents/NAME/events`: numerical faults and contacts as they start (text log, level WARN),
//!   bias updates and sensing problems (level INFO).
//! - `agents/NAME/sensed_walls`: with a noisy sensor, the outline of the configuration-space
//!   obstacles of each reading (the walls as the agent sensed them, grown by its radius).
//! - `agents/NAME/lidar/scan` (every scan, some of its rays) and `agents/NAME/lidar/map` (once a
//!   second at 10 Hz: occupied black, free translucent white, unknown clear): with a lidar; its
//!   `field/potential` is then re-logged with the map, as the field is re-solved on it.
//! - `plots/NAME/KEY`: one entity per plot, with one scalar per series, in order: `distance`;
//!   `speed` (speed, speed along the guidance, m/s); `force` (|F|, Fx, Fy, N); `potential`;
//!   `limits` (clamping active, speed limit active: 0 or 1, those the controller has); `bias`
//!   (β x, β y, N; with a bias). A plot keeps only the rows that start or end a run of equal
//!   values (`columns::Runs`): a flag's plot is a few rows, not one a step.
//!
//! - A shaped agent (`[agents.shape]`), under `agents/NAME/` too: `body` is a frame with its pose
//!   per step (translation and rotation) and `body/shape` its outline in that frame (static);
//!   `kinematic_path` and `kinematic_poses` (the shape every 0.5 m along it: the heading marks),
//!   `start` and `target` (the shape at those poses; the target disc without a target
//!   heading), `field/potential` (the slice of its (x, y, θ) field at its current heading,
//!   logged again whenever it turns into another slice), `trail`, `contacts`, `events`; and
//!   `plots/NAME/{distance, heading, speed, control, clearance}`.
//!
//! - An arm: `world/arms/NAME/{base, target}` (static), `…/links` (the capsules from joint to
//!   joint, per step, red while touching), `…/trail` (the tip's), `…/events`; and
//!   `plots/NAME/{joints, torques}`.
//!
//! - `world/obstacles/NAME/body`: a moving obstacle's frame, its pose per step (in columns),
//!   with `…/body/shape` its outline in that frame (static); `…/path` its waypoints, or the
//!   region a wanderer stays in (static). An agent's `field/guidance` arrows are then logged
//!   on the timeline, again once a second as its field is re-solved around the obstacles (and
//!   with `replan = "full"` its `field/potential` too: the whole field is re-solved).
//! - `summary`: the run's verdict (the summary table and the expectations), a text document.
//! - `world/pendulums/NAME/{pivot, target, rod, bob}`: a pendulum; `…/events` its bias updates
//!   (INFO); `plots/NAME/{theta, torque, bias}`: (θ(t), θ_T), u(t) and β(t).
//!
//! Time is the `sim_time` timeline, in seconds. The world is y-up while Rerun's 2D views are
//! y-down, so `world` and `agents` carry a static transform that flips y about the box.
//!
//! The recording is written to `OUT.rrd.partial` and renamed to `OUT.rrd` once complete, so an
//! existing recording is never replaced by a broken one.
//!
//! The files: `world.rs` (the geometry), `agents.rs`, `obstacles.rs`, `pendulums.rs`,
//! `blueprint.rs` (the layout), with every entity and series name in one table (`names.rs`) and
//! every colour in one palette (`palette.rs`); `colormap.rs` and `picture.rs` draw a field as an
//! image.

mod agents;
mod arms;
mod blueprint;
mod colormap;
mod columns;
mod names;
mod obstacles;
mod palette;
mod pendulums;
mod picture;
mod shaped;
mod world;

pub use colormap::{deepest, joint_deepest, joint_image, joint_plane, pose_slice_image};
pub use columns::Runs;
pub use picture::field_picture;

use std::path::{Path, PathBuf};

use rerun::{RecordingStream, RecordingStreamBuilder};

/// A Rerun viewer to stream a run into as it goes, with Rerun's own conventions
/// (`rerun::clap::RerunArgs`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Viewer {
    /// Start a viewer (the `rerun` executable on the `PATH`) and stream into it.
    Spawn,
    /// Stream to a running viewer or gRPC server at this URL
    /// (`rerun+http://HOST:PORT/proxy`; Rerun's default is [`DEFAULT_VIEWER_URL`]).
    Connect(String),
}

impl Viewer {
    /// The viewer of `--spawn` and `--connect URL` (`connect` wins when both are given), if any.
    ///
    /// ```
    /// # use nadf::record::Viewer;
    /// assert_eq!(Viewer::from_flags(true, None), Some(Viewer::Spawn));
    /// assert_eq!(Viewer::from_flags(false, None), None);
    /// ```
    pub fn from_flags(spawn: bool, connect: Option<String>) -> Option<Self> {
        match (connect, spawn) {
            (Some(url), _) => Some(Self::Connect(url)),
            (None, true) => Some(Self::Spawn),
            (None, false) => None,
        }
    }
}

/// Where `--connect` streams without a URL: Rerun's default.
pub const DEFAULT_VIEWER_URL: &str = rerun::DEFAULT_CONNECT_URL;

use crate::sim::{AgentState, Simulation};
use crate::world::World;

/// Wall-clock time between two flushes of the stream (the steps kept in columns are sent
/// first), so that a viewer shows a run as it goes and a run killed outright still leaves a
/// `.partial` file that decodes up to its last second.
const FLUSH_EVERY: std::time::Duration = std::time::Duration::from_secs(1);

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
    /// No Rerun viewer could be started.
    #[error(
        "cannot start a Rerun viewer: {0}\ninstall the viewer that matches this build with `pip install rerun-sdk=={version}` (it provides the `rerun` executable), or stream to a running one with --connect",
        version = rerun::build_info().version
    )]
    Spawn(String),
    /// Nothing listens at the viewer's URL.
    #[error(
        "no Rerun viewer is listening at {url}: start one first (`rerun`), or let the run start one with --spawn"
    )]
    NoViewer {
        /// The URL given.
        url: String,
    },
    /// The viewer URL is not a Rerun gRPC proxy URL.
    #[error("cannot stream to `{url}`: {message} (a viewer's URL looks like {DEFAULT_VIEWER_URL})")]
    Url {
        /// The URL given.
        url: String,
        /// Why it is not one.
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

/// Streams a run into an `.rrd` file, a Rerun viewer, or both.
pub struct Recorder {
    stream: RecordingStream,
    /// The layout, made while the recording is set up (sent at the end of [`Self::log_setup`]).
    layout: Option<blueprint::Prepared>,
    /// The file being written and where it goes when it is complete, if any.
    file: Option<(PathBuf, PathBuf)>,
    steps: agents::Steps,
    shaped: shaped::ShapedSteps,
    arms: arms::ArmSteps,
    obstacles: obstacles::ObstacleSteps,
    last_flush: std::time::Instant,
}

impl Recorder {
    /// Starts the recording of `world` into the file `path` (if any) and the `viewer` (if
    /// any; with neither, nothing is recorded): a viewer is started, or its URL checked, before
    /// anything is simulated.
    pub fn create(
        path: Option<&Path>,
        viewer: Option<&Viewer>,
        world: &World,
    ) -> Result<Self, RecordError> {
        let layout = (path.is_some() || viewer.is_some()).then(|| blueprint::prepare(world));
        let file = path.map(|p| (crate::output::partial_path(p), p.to_path_buf()));
        let builder = RecordingStreamBuilder::new("nadf").recording_name(world.name());
        let stream_error = |path: &Path| {
            let path = path.to_path_buf();
            move |source| RecordError::Stream { path, source }
        };
        let stream = match (viewer, &file) {
            (None, Some((partial, _))) => builder.save(partial).map_err(stream_error(partial))?,
            (None, None) => RecordingStream::disabled(),
            (Some(viewer), file) => {
                let url = match viewer {
                    Viewer::Spawn => {
                        rerun::spawn(&rerun::SpawnOptions::default())
                            .map_err(|e| RecordError::Spawn(e.to_string()))?;
                        DEFAULT_VIEWER_URL.to_string()
                    }
                    Viewer::Connect(url) => url.clone(),
                };
                let uri = proxy_uri(&url)?;
                if matches!(viewer, Viewer::Connect(_)) && !listening(&uri) {
                    return Err(RecordError::NoViewer { url });
                }
                // Buffered until the sinks are set.
                let stream = builder.buffered().map_err(stream_error(Path::new(&url)))?;
                let grpc = rerun::sink::GrpcSink::new(uri);
                match file {
                    Some((partial, _)) => {
                        let sink = rerun::sink::FileSink::new(partial).map_err(|e| {
                            RecordError::Flush {
                                path: partial.clone(),
                                message: e.to_string(),
                            }
                        })?;
                        stream.set_sinks((grpc, sink));
                    }
                    None => stream.set_sinks((grpc,)),
                }
                stream
            }
        };
        Ok(Self {
            stream,
            layout,
            file,
            steps: agents::Steps::default(),
            shaped: shaped::ShapedSteps::default(),
            arms: arms::ArmSteps::default(),
            obstacles: obstacles::ObstacleSteps::default(),
            last_flush: std::time::Instant::now(),
        })
    }

    /// Logs everything that does not change during the run: geometry, fields, kinematic paths.
    pub fn log_setup(&mut self, sim: &Simulation) -> Result<(), rerun::RecordingStreamError> {
        world::log_setup(&self.stream, &sim.world)?;
        pendulums::log_setup(&self.stream, &sim.pendulums)?;
        agents::log_setup(&self.stream, sim)?;
        self.steps = agents::Steps::new(&self.stream, sim)?;
        self.shaped = shaped::log_setup(&self.stream, sim)?;
        self.arms = arms::log_setup(&self.stream, &sim.arms)?;
        self.obstacles = obstacles::log_setup(&self.stream, &sim.obstacles)?;
        if let Some(layout) = self.layout.take() {
            blueprint::send(&self.stream, layout)?;
        }
        // On to the file now, not at the batcher's next tick (200 ms for a file, longer than
        // many runs): the file's writer encodes the set-up while the run goes, rather than all
        // of it once the run has ended.
        let _ = self.stream.flush_async();
        Ok(())
    }

    /// Logs the state of every body after a step, at the simulation's time. (What is logged
    /// every step goes in columns with their own times; the stream's time is set only before
    /// the rare things logged as they happen, as setting it costs more than keeping a row.)
    pub fn log_step(
        &mut self,
        sim: &Simulation,
        states: &[AgentState],
    ) -> Result<(), rerun::RecordingStreamError> {
        let rec = &self.stream;
        pendulums::log_step(rec, sim.time(), &sim.pendulums)?;
        self.shaped
            .log_step(rec, sim.time(), &sim.shaped, sim.finished())?;
        self.arms
            .log_step(rec, sim.time(), &sim.arms, sim.finished())?;
        self.steps.log_step(rec, sim, states, sim.finished())?;
        (self.obstacles).log_step(rec, sim.time(), &sim.obstacles, sim.finished())?;
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.steps.send(rec, false)?;
            self.obstacles.send(rec)?;
            // A failed flush is not fatal here: the next one, or the footer, retries.
            let _ = self.stream.flush_blocking();
            self.last_flush = std::time::Instant::now();
        }
        Ok(())
    }

    /// Logs the run's verdict (markdown: the summary table, the expectations' results) as a
    /// static text document, shown in the layout under the plots: someone who has only the
    /// `.rrd` sees how the run ended.
    pub fn log_summary(&mut self, markdown: &str) -> Result<(), rerun::RecordingStreamError> {
        self.stream.log_static(
            names::SUMMARY,
            &rerun::TextDocument::from_markdown(markdown),
        )
    }

    /// Closes the stream (which writes the file's footer, and sends everything to a viewer)
    /// and moves the file into place; returns the file, if there is one.
    pub fn finish(self) -> Result<Option<PathBuf>, RecordError> {
        let Self {
            stream,
            file,
            mut steps,
            mut obstacles,
            ..
        } = self;
        let flushed = steps
            .send(&stream, true)
            .and_then(|()| obstacles.send(&stream))
            .map_err(|e| e.to_string())
            .and_then(|()| stream.flush_blocking().map_err(|e| e.to_string()));
        if let Err(message) = flushed {
            drop(stream);
            if let Some((partial, _)) = &file {
                let _ = std::fs::remove_file(partial);
            }
            return Err(RecordError::Flush {
                path: file.map_or_else(|| PathBuf::from("(the viewer)"), |(partial, _)| partial),
                message,
            });
        }
        // The footer is written when the last handle to the stream is dropped.
        drop(stream);
        let Some((partial, path)) = file else {
            return Ok(None);
        };
        std::fs::rename(&partial, &path).map_err(|source| RecordError::Rename {
            path: path.clone(),
            source,
        })?;
        Ok(Some(path))
    }

    /// Drops the stream and deletes the partial file (a failed run leaves nothing behind).
    pub fn abandon(self) {
        let file = self.file.clone();
        drop(self.stream);
        if let Some((partial, _)) = file {
            let _ = std::fs::remove_file(partial);
        }
    }
}

/// Whether something accepts connections at `uri`'s host and port (within 3 s): checked
/// before a run that streams to it, rather than found out when the run ends.
fn listening(uri: &rerun::external::re_uri::ProxyUri) -> bool {
    use std::net::ToSocketAddrs;
    let address = format!("{}:{}", uri.origin.format_host(), uri.origin.port);
    address.to_socket_addrs().is_ok_and(|mut addresses| {
        addresses.any(|a| {
            std::net::TcpStream::connect_timeout(&a, std::time::Duration::from_secs(3)).is_ok()
        })
    })
}

/// The gRPC proxy URI of a viewer's `url`.
fn proxy_uri(url: &str) -> Result<rerun::external::re_uri::ProxyUri, RecordError> {
    let bad = |message: String| RecordError::Url {
        url: url.to_string(),
        message,
    };
    match url.parse::<rerun::external::re_uri::RedapUri>() {
        Ok(rerun::external::re_uri::RedapUri::Proxy(uri)) => Ok(uri),
        Ok(_) => Err(bad("not a viewer's proxy endpoint".into())),
        Err(e) => Err(bad(e.to_string())),
    }
}
