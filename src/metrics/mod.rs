//! What a run reports per agent (design page, "Metrics"), accumulated step by step
//! ([`Metrics`]) into a [`Summary`], whose fields are declared once with their units
//! (`measure.rs`) and printed as a table or CSV from that declaration (`table.rs`).
//!
//! - `reached`: the final distance to the target is within the 5 % band of the initial one.
//! - `settling_time`: the time at which the distance last entered the 5 % band and stayed
//!   there (`None` if it ends outside).
//! - `contacts`: contact starts reported by Rapier's narrow phase, against anything.
//! - `min_clearance`: smallest parry distance from the agent's disc to any wall.
//! - `max_deviation` (`δ_m`): largest distance from the dynamic path to the kinematic path.
//! - `peak_force`, `control_variation` (`Σ|F_k − F_{k−1}|`), `peak_speed`, `path_length`.
//! - `final_speed`: the speed at the end (a body that braked and stopped short has
//!   `reached = false` and `final_speed` near zero).
//! - `distance_covered`: how far the body is from its start at the world's `distance_at` time
//!   (the paper's "25 metres in 10 seconds" along a corridor, §VI.6).
//! - Sideways oscillation, measured across the start-to-target line (the corridor's axis):
//!   `lateral_speed_rms`, the RMS of the velocity across that line over the run, and
//!   `lateral_reversals`, how often the motion across it reverses between excursions faster than
//!   [`LATERAL_REVERSAL_SPEED`] (the narrow corridor effect is a stream of such reversals).

mod measure;
mod table;

use nalgebra::Vector2;
use serde::Serialize;

pub use measure::{Kind, Measured, Metric, Value, measurements, metrics_of, values_of};
pub use table::{csv, field as csv_field, rows_table, table};

use crate::field::Streamline;

/// The width of the settling band, as a fraction of the initial distance to the target.
pub const SETTLING_BAND: f64 = 0.05;

/// An agent that has not come this much closer to its target (m) for [`DEADLOCK_AFTER`] seconds,
/// while another agent is next to it, is deadlocked.
pub const PROGRESS: f64 = 0.05;

/// How long without progress makes a blocked agent deadlocked, s.
pub const DEADLOCK_AFTER: f64 = 5.0;

/// An agent among others that has not come [`PROGRESS`] closer to its target for this long (s)
/// while it kept moving all the while, at least [`LIVELOCK_PATH`] of path in each third of it,
/// is livelocked: it goes round or back and forth instead of on. (A deadlock is the parked
/// case; a crowd milling about, each robot dodging the others, is this one, and neither
/// contacts nor `deadlocked` show it.) Three times [`DEADLOCK_AFTER`], so that a detour around
/// a jam, which gains no ground for a while, is not taken for one. Progress is counted in a
/// straight line to the target, as for a deadlock, so a detour that leads away from it for
/// longer than this is reported too: a flag to look at, not a fault.
pub const LIVELOCK_AFTER: f64 = 15.0;

/// The path (m) a livelocked agent covers in each third of [`LIVELOCK_AFTER`]: more than a
/// body length of shuffling. A robot driven back out of a corridor by another and parked there
/// moved, but not all the while, and is no livelock (`corridor-jam`).
pub const LIVELOCK_PATH: f64 = 1.0;

/// What [`Metrics::watch_progress`] found in a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stall {
    /// No progress for [`DEADLOCK_AFTER`] with another agent next to it.
    Deadlocked,
    /// No progress for [`LIVELOCK_AFTER`] while it kept moving ([`LIVELOCK_PATH`] in each
    /// third of it).
    Livelocked,
}

/// A reversal of the sideways motion counts only between excursions faster than this, m/s, so
/// that the jitter of a body moving straight is not counted as oscillation.
pub const LATERAL_REVERSAL_SPEED: f64 = 0.05;

crate::measured! {
    /// One agent's summary, with the key names of `--json`. Each field is declared once here,
    /// with its unit, the digits shown and its column in the printed table; the CSV of a sweep,
    /// the table and the expectations a world file may state all read this declaration.
    #[derive(Debug, Clone, PartialEq, Serialize)]
    pub struct Summary {
        /// The agent's name.
        pub name: String,
        /// Whether the final distance is within the settling band.
        pub reached: bool [column("reached")],
        /// Settling time, s; `None` if the agent never settled.
        pub settling_time: Option<f64> [unit("s"), column("settle_s"), missing("never")],
        /// Final distance to the target, m.
        pub final_error: f64 [unit("m"), column("error_m")],
        /// Number of contact starts.
        pub contacts: usize [column("contacts")],
        /// Smallest signed distance from the agent's shape to any wall after a step, m:
        /// negative by the depth when it overlapped one (always counted as a contact); `None`
        /// in a world without walls.
        pub min_clearance: Option<f64> [unit("m"), column("clear_m"), missing("no walls")],
        /// Contact starts with moving obstacles (counted in `contacts` too).
        pub obstacle_contacts: usize,
        /// Smallest signed distance from the agent's disc to any moving obstacle after a step,
        /// m (negative by the depth of an overlap); `None` in a world without obstacles.
        pub min_obstacle_distance: Option<f64> [unit("m"), missing("no obstacles")],
        /// `δ_m`: largest distance from the dynamic to the kinematic path, m.
        pub max_deviation: f64 [unit("m"), column("dev_m")],
        /// Length of the dynamic path, m.
        pub path_length: f64 [unit("m"), digits(2), column("path_m")],
        /// Largest control force magnitude, N.
        pub peak_force: f64 [unit("N"), digits(2), column("peak_N")],
        /// Total variation of the control force, N.
        pub control_variation: f64 [unit("N"), digits(2), column("var_N")],
        /// Largest speed, m/s.
        pub peak_speed: f64 [unit("m/s"), digits(2), column("vmax")],
        /// Speed at the end of the run, m/s.
        pub final_speed: f64 [unit("m/s")],
        /// Distance from the start at the world's `distance_at` time, m; `None` without
        /// `distance_at`, or when the run ended before it.
        pub distance_covered: Option<f64> [unit("m"), missing("not measured (set distance_at within the duration)")],
        /// RMS of the velocity across the start-to-target line over the run, m/s.
        pub lateral_speed_rms: f64 [unit("m/s")],
        /// Reversals of the motion across the start-to-target line (between excursions faster
        /// than [`LATERAL_REVERSAL_SPEED`]).
        pub lateral_reversals: usize,
        /// Updates of the iterative bias β (eq. 49) that changed it by more than
        /// `control::CONVERGED` of its size; zero without the bias option.
        pub bias_updates: usize [column("updates")],
        /// When the agent was found deadlocked, s: no progress of [`PROGRESS`] towards its
        /// target for [`DEADLOCK_AFTER`] seconds, outside the settling band, with another agent
        /// within its own diameter of it; `None` otherwise.
        pub deadlocked: Option<f64> [unit("s"), missing("no")],
        /// When the agent was found livelocked, s: among other agents, no progress of
        /// [`PROGRESS`] towards its target for [`LIVELOCK_AFTER`] seconds, outside the
        /// settling band, while it covered at least [`LIVELOCK_PATH`] in each third of that
        /// time (it moves but gets nowhere); `None` otherwise.
        pub livelocked: Option<f64> [unit("s"), missing("no")],
        /// Smallest gap between the agent's disc and another agent's over the run, m
        /// (negative: they overlapped); `None` for an agent alone.
        pub min_separation: Option<f64> [unit("m"), missing("alone")],
        /// Successful re-solves of the harmonic field (sensor readings, replans, lidar map
        /// changes); the first solve is not counted, nor a replan skipped because the crowd is
        /// parked on its targets and nothing moved since the last one (see `sim::agent::STILL`).
        pub resolves: usize [column("resolves")],
        /// Solves over the whole grid that the re-solves took (a replan may take two): a
        /// crowd's local replans that fell back to the whole field (cut off in the window, or
        /// turned back on the last field), fields that take it out of another's way, a lidar's
        /// map, global replanning; the work that grows with the map and the crowd, where a
        /// window's does not.
        pub whole_resolves: usize,
        /// With a lidar: when the map it built closed every route to the target, s; `None`
        /// otherwise.
        pub intractable: Option<f64> [unit("s"), missing("no")],
        /// With a lidar: the fraction of the grid's cells its scans have seen.
        pub map_seen: Option<f64> [missing("no lidar")],
        /// The length of the kinematic path (with full knowledge of the walls), m; `None` when
        /// it does not reach the target.
        pub kinematic_length: Option<f64> [unit("m"), digits(2), missing("no path")],
        /// How long the clearance envelope changed the control force, s (0 when it never
        /// bound, or the envelope is off).
        pub envelope_time: f64 [unit("s"), column("env_s")],
        /// Numerical faults met during the run (all zero in a healthy run).
        pub faults: Faults,
    }
}

crate::measured! {
    /// Numerical faults of one agent's run (see `sim::faults`).
    #[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
    pub struct Faults {
        /// Steps in which the guidance was undefined: the gradient vanished or reversed from
        /// one step to the next (the body is on a critical point, e.g. a saddle), the field was
        /// flat, or the body was off the field. Not counted within two cells of the target or
        /// within the rim of its disc (`HarmonicField::rim`).
        pub guidance_lost_steps: usize,
        /// Steps whose control force could not be given to Rapier or recorded (not finite in
        /// f32, the recording's precision); zero
        /// was applied instead.
        pub rejected_forces: usize,
        /// Times the body was pushed more than 1 cm into a wall.
        pub penetrations: usize,
        /// Steps with the body's centre outside the box.
        pub left_box_steps: usize,
        /// Whether Rapier's state of the body became non-finite (the body was then frozen).
        pub non_finite_state: bool,
    }
}

impl Faults {
    /// Whether nothing went wrong.
    pub fn is_clean(&self) -> bool {
        *self == Self::default()
    }
}

/// Accumulates one agent's metrics over a run.
#[derive(Debug, Clone)]
pub struct Metrics {
    name: String,
    target: Vector2<f64>,
    band: f64,
    last_outside: Option<f64>,
    settled_at: Option<f64>,
    final_distance: f64,
    contacts: usize,
    obstacle_contacts: usize,
    min_obstacle_distance: Option<f64>,
    min_clearance: f64,
    envelope_time: f64,
    path: Vec<[f64; 2]>,
    path_length: f64,
    peak_force: f64,
    control_variation: f64,
    last_force: Option<Vector2<f64>>,
    peak_speed: f64,
    final_speed: f64,
    start: Vector2<f64>,
    distance_at: Option<f64>,
    distance_covered: Option<f64>,
    bias_updates: usize,
    resolves: usize,
    whole_resolves: usize,
    closest: f64,
    closer_at: f64,
    /// `(t, path length)` about once a second over the last [`LIVELOCK_AFTER`] seconds.
    trail: std::collections::VecDeque<(f64, f64)>,
    deadlocked: Option<f64>,
    livelocked: Option<f64>,
    min_separation: Option<f64>,
    lateral_axis: Vector2<f64>,
    lateral_square_sum: f64,
    states: usize,
    lateral_sign: f64,
    lateral_reversals: usize,
}

impl Metrics {
    /// Starts the record of an agent at `start` heading for `target`; `distance_at` is the time
    /// (s) at which to measure the distance covered, if any.
    pub fn new(name: &str, start: [f64; 2], target: [f64; 2], distance_at: Option<f64>) -> Self {
        let (start, target) = (Vector2::from(start), Vector2::from(target));
        let d0 = (start - target).norm();
        // Across the start-to-target line: its normal (zero when start and target coincide).
        let axis = target - start;
        let lateral_axis = if d0 > 0.0 {
            Vector2::new(-axis.y, axis.x) / d0
        } else {
            Vector2::zeros()
        };
        Self {
            name: name.to_string(),
            target,
            band: SETTLING_BAND * d0,
            last_outside: (d0 > SETTLING_BAND * d0).then_some(0.0),
            settled_at: None,
            final_distance: d0,
            contacts: 0,
            obstacle_contacts: 0,
            min_obstacle_distance: None,
            min_clearance: f64::INFINITY,
            envelope_time: 0.0,
            path: vec![start.into()],
            path_length: 0.0,
            peak_force: 0.0,
            control_variation: 0.0,
            last_force: None,
            peak_speed: 0.0,
            final_speed: 0.0,
            start,
            distance_at,
            distance_covered: (distance_at == Some(0.0)).then_some(0.0),
            bias_updates: 0,
            resolves: 0,
            whole_resolves: 0,
            closest: d0,
            closer_at: 0.0,
            trail: [(0.0, 0.0)].into(),
            deadlocked: None,
            livelocked: None,
            min_separation: None,
            lateral_axis,
            lateral_square_sum: 0.0,
            states: 0,
            lateral_sign: 0.0,
            lateral_reversals: 0,
        }
    }

    /// The half-width of the settling band, m.
    pub fn band(&self) -> f64 {
        self.band
    }

    /// Records the control force applied during the step that starts now.
    pub fn record_force(&mut self, force: Vector2<f64>) {
        self.peak_force = self.peak_force.max(force.norm());
        if let Some(last) = self.last_force {
            self.control_variation += (force - last).norm();
        }
        self.last_force = Some(force);
    }

    /// Records the state at time `t` (s) after a step.
    pub fn record_state(
        &mut self,
        t: f64,
        position: Vector2<f64>,
        velocity: Vector2<f64>,
        clearance: f64,
    ) {
        let d = (position - self.target).norm();
        if d > self.band {
            self.last_outside = Some(t);
            self.settled_at = None;
        } else if self.settled_at.is_none() {
            self.settled_at = Some(t);
        }
        self.final_distance = d;
        self.min_clearance = self.min_clearance.min(clearance);
        let last = Vector2::from(*self.path.last().expect("the path starts with the start"));
        self.path_length += (position - last).norm();
        self.path.push(position.into());
        self.peak_speed = self.peak_speed.max(velocity.norm());
        self.final_speed = velocity.norm();
        if self.distance_covered.is_none() && self.distance_at.is_some_and(|at| t + 1e-9 >= at) {
            self.distance_covered = Some((position - self.start).norm());
        }
        let lateral = velocity.dot(&self.lateral_axis);
        self.lateral_square_sum += lateral * lateral;
        self.states += 1;
        if lateral.abs() > LATERAL_REVERSAL_SPEED {
            let sign = lateral.signum();
            if self.lateral_sign != 0.0 && sign != self.lateral_sign {
                self.lateral_reversals += 1;
            }
            self.lateral_sign = sign;
        }
    }

    /// Counts a step of `dt` (s) in which the clearance envelope changed the control force.
    pub fn record_envelope(&mut self, dt: f64) {
        self.envelope_time += dt;
    }

    /// Counts `n` new contact starts.
    pub fn record_contacts(&mut self, n: usize) {
        self.contacts += n;
    }

    /// Counts `n` new contact starts with moving obstacles (already counted as contacts).
    pub fn record_obstacle_contacts(&mut self, n: usize) {
        self.obstacle_contacts += n;
    }

    /// Records the signed distance from the agent's disc to the nearest moving obstacle after
    /// a step, m.
    pub fn record_obstacle_distance(&mut self, d: f64) {
        self.min_obstacle_distance = Some(self.min_obstacle_distance.map_or(d, |m| m.min(d)));
    }

    /// Records the gap between the agent's disc and the nearest other agent's after a step, m.
    pub fn record_separation(&mut self, gap: f64) {
        self.min_separation = Some(self.min_separation.map_or(gap, |s| s.min(gap)));
    }

    /// Watches an agent among others for a deadlock or a livelock after the state of time `t`
    /// (s) was recorded; `blocked` says whether another agent is next to this one. Returns what
    /// it was found to be now, the first time (a deadlock first, if both).
    ///
    /// ```
    /// use nadf::metrics::{Metrics, Stall};
    /// use nalgebra::Vector2;
    /// let mut m = Metrics::new("r", [0.0, 0.0], [10.0, 0.0], None);
    /// let mut found = None;
    /// // Back and forth across the line to the target at 1 m/s, never closer than 10 m.
    /// for k in 1..=2000 {
    ///     let t = k as f64 * 0.01;
    ///     let along = (k % 100) as f64 * 0.01;
    ///     let y = if (k / 100) % 2 == 0 { along } else { 1.0 - along };
    ///     m.record_state(t, Vector2::new(0.0, y), Vector2::zeros(), 1.0);
    ///     found = found.or(m.watch_progress(t, false).map(|s| (s, t)));
    /// }
    /// let (stall, at) = found.expect("found");
    /// assert_eq!(stall, Stall::Livelocked);
    /// assert!((at - 15.0).abs() < 1e-6, "{at}");
    /// ```
    pub fn watch_progress(&mut self, t: f64, blocked: bool) -> Option<Stall> {
        if self.final_distance < self.closest - PROGRESS {
            (self.closest, self.closer_at) = (self.final_distance, t);
        }
        if self
            .trail
            .back()
            .is_some_and(|&(at, _)| t >= at + 1.0 - 1e-9)
        {
            self.trail.push_back((t, self.path_length));
            // One sample older than the window is kept: the path at its start.
            while self
                .trail
                .get(1)
                .is_some_and(|&(at, _)| at <= t - LIVELOCK_AFTER + 1e-9)
            {
                self.trail.pop_front();
            }
        }
        let outside = self.final_distance > self.band;
        let still = t - self.closer_at;
        if self.deadlocked.is_none() && still >= DEADLOCK_AFTER && outside && blocked {
            self.deadlocked = Some(t);
            return Some(Stall::Deadlocked);
        }
        // The path's samples are searched last: every agent passes here at every step.
        if self.livelocked.is_none()
            && still >= LIVELOCK_AFTER - 1e-9
            && outside
            && self.moving_all_along(t)
        {
            self.livelocked = Some(t);
            return Some(Stall::Livelocked);
        }
        None
    }

    /// Whether the agent covered at least [`LIVELOCK_PATH`] in each third of the last
    /// [`LIVELOCK_AFTER`] seconds before `t` (measured on the trail's once-a-second samples).
    fn moving_all_along(&self, t: f64) -> bool {
        let path_at = |at: f64| {
            (self.trail.iter().rev())
                .find(|&&(sampled, _)| sampled <= at + 1e-9)
                .map(|&(_, path)| path)
        };
        let third = LIVELOCK_AFTER / 3.0;
        (0..3).all(|k| {
            let (from, to) = (t - third * (k + 1) as f64, t - third * k as f64);
            match (path_at(from), path_at(to)) {
                (Some(a), Some(b)) => b - a >= LIVELOCK_PATH,
                _ => false,
            }
        })
    }

    /// Counts a re-solve of the harmonic field, which took `whole` solves over the whole grid.
    pub fn record_resolve(&mut self, whole: usize) {
        self.resolves += 1;
        self.whole_resolves += whole;
    }

    /// Contact starts so far.
    pub fn contacts(&self) -> usize {
        self.contacts
    }

    /// Successful re-solves of the harmonic field so far.
    pub fn resolves(&self) -> usize {
        self.resolves
    }

    /// Counts an update of the bias β.
    pub fn record_bias_update(&mut self) {
        self.bias_updates += 1;
    }

    /// The dynamic path so far.
    pub fn path(&self) -> &[[f64; 2]] {
        &self.path
    }

    /// The summary, with `δ_m` measured against `kinematic`.
    pub fn summary(&self, kinematic: &Streamline, faults: &Faults) -> Summary {
        let reached = self.final_distance <= self.band;
        let max_deviation = kinematic.max_distance(&self.path);
        Summary {
            name: self.name.clone(),
            reached,
            settling_time: if reached { self.settled_at } else { None },
            final_error: self.final_distance,
            contacts: self.contacts,
            obstacle_contacts: self.obstacle_contacts,
            min_obstacle_distance: self.min_obstacle_distance,
            min_clearance: self.min_clearance.is_finite().then_some(self.min_clearance),
            envelope_time: self.envelope_time,
            max_deviation,
            path_length: self.path_length,
            peak_force: self.peak_force,
            control_variation: self.control_variation,
            peak_speed: self.peak_speed,
            final_speed: self.final_speed,
            distance_covered: self.distance_covered,
            bias_updates: self.bias_updates,
            resolves: self.resolves,
            whole_resolves: self.whole_resolves,
            deadlocked: self.deadlocked,
            livelocked: self.livelocked,
            min_separation: self.min_separation,
            intractable: None,
            map_seen: None,
            kinematic_length: kinematic.reached.then(|| kinematic.length()),
            lateral_speed_rms: if self.states > 0 {
                (self.lateral_square_sum / self.states as f64).sqrt()
            } else {
                0.0
            },
            lateral_reversals: self.lateral_reversals,
            faults: faults.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight() -> Streamline {
        Streamline {
            points: vec![[0.0, 0.0], [10.0, 0.0]],
            reached: true,
        }
    }

    #[test]
    fn settling_time_is_the_last_entry_into_the_band() {
        let mut m = Metrics::new("a", [0.0, 0.0], [10.0, 0.0], None);
        let v = Vector2::zeros();
        for (t, x) in [(1.0, 5.0), (2.0, 9.7), (3.0, 10.6), (4.0, 9.9), (5.0, 10.0)] {
            m.record_state(t, Vector2::new(x, 0.0), v, 1.0);
        }
        let s = m.summary(&straight(), &Faults::default());
        assert!(s.reached);
        assert_eq!(s.settling_time, Some(4.0));
        assert_eq!(s.final_error, 0.0);
        assert!((s.path_length - (5.0 + 4.7 + 0.9 + 0.7 + 0.1)).abs() < 1e-12);
    }

    #[test]
    fn an_agent_that_ends_outside_the_band_never_settled() {
        let mut m = Metrics::new("a", [0.0, 0.0], [10.0, 0.0], None);
        m.record_state(1.0, Vector2::new(9.9, 0.0), Vector2::zeros(), 1.0);
        m.record_state(2.0, Vector2::new(8.0, 1.0), Vector2::new(3.0, 4.0), 0.2);
        let s = m.summary(&straight(), &Faults::default());
        assert!(!s.reached);
        assert_eq!(s.settling_time, None);
        assert_eq!(s.max_deviation, 1.0);
        assert_eq!(s.peak_speed, 5.0);
        assert_eq!(s.min_clearance, Some(0.2));
    }

    #[test]
    fn control_variation_sums_force_changes() {
        let mut m = Metrics::new("a", [0.0, 0.0], [1.0, 0.0], None);
        for f in [[1.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 2.0]] {
            m.record_force(Vector2::from(f));
        }
        let s = m.summary(&straight(), &Faults::default());
        assert_eq!(s.control_variation, 3.0);
        assert_eq!(s.peak_force, 2.0);
    }

    #[test]
    fn distance_covered_is_taken_at_the_given_time() {
        let mut m = Metrics::new("a", [0.0, 0.0], [10.0, 0.0], Some(2.0));
        let v = Vector2::new(1.0, 0.0);
        m.record_state(1.0, Vector2::new(1.0, 0.0), v, 1.0);
        assert_eq!(
            m.summary(&straight(), &Faults::default()).distance_covered,
            None
        );
        m.record_state(2.0, Vector2::new(3.0, 4.0), v, 1.0);
        m.record_state(3.0, Vector2::new(9.0, 0.0), Vector2::zeros(), 1.0);
        let s = m.summary(&straight(), &Faults::default());
        assert_eq!(s.distance_covered, Some(5.0));
        assert_eq!(s.final_speed, 0.0);
    }

    /// Runs `m` for `seconds` at 100 steps a second along `at(t)` with nobody next to it, and
    /// returns when it was found livelocked, if it was.
    fn livelocked_along(seconds: f64, at: impl Fn(f64) -> [f64; 2]) -> Option<f64> {
        let mut m = Metrics::new("a", [0.0, 0.0], [10.0, 0.0], None);
        for k in 1..=(seconds * 100.0).round() as usize {
            let t = k as f64 * 0.01;
            m.record_state(t, Vector2::from(at(t)), Vector2::zeros(), 1.0);
            assert_ne!(m.watch_progress(t, false), Some(Stall::Deadlocked));
        }
        m.summary(&straight(), &Faults::default()).livelocked
    }

    /// Going round in a circle of 1 m behind the start at 1 m/s gets no closer to the target:
    /// livelocked at 15 s. Driven back 4 m and parked there (the robot a jam pushes out of a
    /// corridor), it moved without progress, but not all the while: no livelock. Nor is a
    /// detour that leads away from the target for 6 s and then comes closer, nor a crawl
    /// towards it at 1 cm/s.
    #[test]
    fn a_livelock_is_motion_without_progress_all_along() {
        let circling = livelocked_along(30.0, |t| [t.cos() - 1.0, t.sin()]);
        assert!(
            circling.is_some_and(|t| (t - 15.0).abs() < 0.02),
            "{circling:?}"
        );
        let driven_back = livelocked_along(30.0, |t| [-(t.min(4.0)), 0.0]);
        assert_eq!(driven_back, None);
        let detour = livelocked_along(30.0, |t| {
            if t < 6.0 {
                [-t, 0.0]
            } else {
                [(-6.0 + 2.0 * (t - 6.0)).min(10.0), 0.0]
            }
        });
        assert_eq!(detour, None);
        let crawl = livelocked_along(60.0, |t| [0.01 * t, (t * 3.0).sin()]);
        assert_eq!(crawl, None);
    }

    #[test]
    fn sideways_oscillation_counts_reversals_beyond_the_threshold() {
        // Going along +x: sideways is y.
        let mut m = Metrics::new("a", [0.0, 0.0], [10.0, 0.0], None);
        let p = Vector2::zeros();
        for (t, vy) in [0.3, 0.01, -0.01, -0.3, 0.02, -0.2, 0.4]
            .into_iter()
            .enumerate()
        {
            m.record_state(t as f64, p, Vector2::new(1.0, vy), 1.0);
        }
        let s = m.summary(&straight(), &Faults::default());
        // +0.3 → -0.3 → (-0.2 same side) → +0.4: two reversals; the small ones do not count.
        assert_eq!(s.lateral_reversals, 2);
        let rms = ((0.09 + 0.0001 + 0.0001 + 0.09 + 0.0004 + 0.04 + 0.16) / 7.0f64).sqrt();
        assert!((s.lateral_speed_rms - rms).abs() < 1e-12);
    }
}
