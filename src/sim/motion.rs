//! Scripted motion: how a body that does not plan moves (a person crossing a corridor, a cart
//! in an aisle, a sliding door, a wanderer), the law behind the moving obstacles of issue 31.
//!
//! A script is followed step by step ([`Motion::advance`]). A path and a constant velocity are
//! closed forms of the time, so a long run does not drift from the script; a wander is a seeded
//! random walk, so it is the same for a given seed whatever else the world holds.

use nalgebra::Vector2;

use crate::random::SplitMix;

/// What a path does at its last waypoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathMode {
    /// Goes on from the last waypoint back to the first, round and round (the path is closed).
    Loop,
    /// Turns back along the path, and again at the first waypoint (Flatland's "yoyo").
    Bounce,
    /// Stops at the last waypoint.
    Once,
}

/// How a scripted body moves.
#[derive(Debug, Clone, PartialEq)]
pub enum Script {
    /// Along the waypoints, m, at `speed`, m/s (positive), starting at the first.
    Path {
        /// The waypoints, m (at least two).
        points: Vec<Vector2<f64>>,
        /// Speed along the path, m/s.
        speed: f64,
        /// What it does at the end.
        mode: PathMode,
    },
    /// In a straight line at a constant velocity, m/s.
    Velocity(Vector2<f64>),
    /// A random walk at `speed`, m/s, inside the box `region` (`[min, max]` corners, m): the
    /// heading diffuses by `turn` rad/√s (a Brownian heading) and reflects at the box's sides.
    Wander {
        /// Speed, m/s.
        speed: f64,
        /// The box the body's centre stays in, `[min, max]`, m.
        region: [Vector2<f64>; 2],
        /// Standard deviation of the heading's change over one second, rad.
        turn: f64,
    },
}

/// A script being followed: where the body is and where it goes next.
///
/// ```
/// # use nadf::sim::motion::{Motion, PathMode, Script};
/// # use nalgebra::Vector2;
/// let points = vec![Vector2::new(0.0, 0.0), Vector2::new(2.0, 0.0)];
/// let mut m = Motion::new(Script::Path { points, speed: 1.0, mode: PathMode::Bounce }, 0);
/// for _ in 0..300 {
///     m.advance(0.01);
/// }
/// // 3 m along a 2 m path and back: 1 m from the start, on the way back.
/// assert!((m.position() - Vector2::new(1.0, 0.0)).norm() < 1e-9);
/// ```
#[derive(Debug, Clone)]
pub struct Motion {
    script: Script,
    /// A path's waypoints as followed (a loop's closed by its first waypoint again) and their
    /// length, m: laid out once, not at every step.
    route: (Vec<Vector2<f64>>, f64),
    start: Vector2<f64>,
    position: Vector2<f64>,
    time: f64,
    steps: u64,
    heading: f64,
    rng: SplitMix,
}

impl Motion {
    /// The script from its start (a path's first waypoint, else the origin: see
    /// [`Motion::starting_at`]), with the random stream of `seed` for a wander.
    pub fn new(script: Script, seed: u64) -> Self {
        Self::starting_at(script, Vector2::zeros(), seed)
    }

    /// The script from `start`, m (a path starts at its first waypoint whatever `start` is).
    pub fn starting_at(script: Script, start: Vector2<f64>, seed: u64) -> Self {
        let start = match &script {
            Script::Path { points, .. } => points[0],
            _ => start,
        };
        let route = match &script {
            Script::Path { points, mode, .. } => {
                let mut route = points.clone();
                if *mode == PathMode::Loop {
                    route.push(points[0]);
                }
                let length = route.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
                (route, length)
            }
            _ => (Vec::new(), 0.0),
        };
        let mut rng = SplitMix::new(seed ^ 0x5851_F42D_4C95_7F2D);
        let heading = rng.uniform() * std::f64::consts::TAU;
        Self {
            script,
            route,
            start,
            position: start,
            time: 0.0,
            steps: 0,
            heading,
            rng,
        }
    }

    /// Where the body is now, m.
    pub fn position(&self) -> Vector2<f64> {
        self.position
    }

    /// Time since the start, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Moves on by `dt` (s, positive) and returns the new position, m.
    pub fn advance(&mut self, dt: f64) -> Vector2<f64> {
        self.steps += 1;
        // The time as a multiple of steps, not a running sum: no drift over a long run.
        self.time = self.steps as f64 * dt;
        self.position = match &self.script {
            Script::Path { speed, mode, .. } => along(&self.route, *mode, speed * self.time),
            Script::Velocity(v) => self.start + v * self.time,
            Script::Wander {
                speed,
                region,
                turn,
            } => {
                let (speed, region, turn) = (*speed, *region, *turn);
                self.wander(dt, speed, region, turn)
            }
        };
        self.position
    }

    /// One step of the wander: the heading diffuses, the body moves, and a side of the region
    /// it would cross reflects both (the position mirrored back, the heading turned away).
    fn wander(
        &mut self,
        dt: f64,
        speed: f64,
        region: [Vector2<f64>; 2],
        turn: f64,
    ) -> Vector2<f64> {
        self.heading += turn * dt.sqrt() * self.rng.normal();
        let (sin, cos) = self.heading.sin_cos();
        let mut p = self.position + speed * dt * Vector2::new(cos, sin);
        let (mut dx, mut dy) = (cos, sin);
        for axis in 0..2 {
            let (lo, hi) = (region[0][axis], region[1][axis]);
            let d = if axis == 0 { &mut dx } else { &mut dy };
            if p[axis] < lo {
                p[axis] = (2.0 * lo - p[axis]).min(hi);
                *d = d.abs();
            } else if p[axis] > hi {
                p[axis] = (2.0 * hi - p[axis]).max(lo);
                *d = -d.abs();
            }
        }
        self.heading = dy.atan2(dx);
        p
    }
}

/// The point at arc length `s` (m) along `route` (its waypoints as followed and their length)
/// in `mode`.
fn along((points, length): &(Vec<Vector2<f64>>, f64), mode: PathMode, s: f64) -> Vector2<f64> {
    let length = *length;
    if length <= 0.0 {
        return points[0];
    }
    let s = match mode {
        PathMode::Loop => s.rem_euclid(length),
        PathMode::Bounce => {
            let s = s.rem_euclid(2.0 * length);
            if s > length { 2.0 * length - s } else { s }
        }
        PathMode::Once => s.min(length),
    };
    let mut left = s;
    for leg in points.windows(2) {
        let (a, b) = (leg[0], leg[1]);
        let l = (b - a).norm();
        if left <= l {
            return if l > 0.0 { a + (b - a) * (left / l) } else { a };
        }
        left -= l;
    }
    points[points.len() - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<Vector2<f64>> {
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
            .iter()
            .map(|p| Vector2::new(p[0], p[1]))
            .collect()
    }

    fn path(mode: PathMode, speed: f64) -> Motion {
        Motion::new(
            Script::Path {
                points: square(),
                speed,
                mode,
            },
            0,
        )
    }

    /// Every step moves it by its speed (less only where a corner cuts the chord), and a loop
    /// is back at its start after the closed path's 4 m.
    #[test]
    fn a_loop_goes_round_at_its_speed() {
        let (mut m, dt, speed) = (path(PathMode::Loop, 2.0), 0.01, 2.0);
        let mut last = m.position();
        let mut cut = 0;
        for _ in 0..200 {
            let p = m.advance(dt);
            let moved = (p - last).norm();
            assert!(moved <= speed * dt + 1e-12, "{moved}");
            cut += usize::from(moved < speed * dt - 1e-9);
            last = p;
        }
        assert!(cut <= 4, "{cut} steps across a corner");
        assert!(m.position().norm() < 1e-9, "{}", m.position());
        let p = m.advance(dt);
        assert!((p - Vector2::new(0.02, 0.0)).norm() < 1e-9, "{p}");
    }

    /// A bounce turns at the last waypoint (3 m along the open square) and is back at its
    /// start after 6 m; once stops at the last waypoint.
    #[test]
    fn a_bounce_turns_back_and_once_stops() {
        let (mut bounce, mut once) = (path(PathMode::Bounce, 1.0), path(PathMode::Once, 1.0));
        let at = |m: &mut Motion, steps: usize| {
            let mut p = m.position();
            for _ in 0..steps {
                p = m.advance(0.01);
            }
            p
        };
        assert!((at(&mut bounce, 300) - Vector2::new(0.0, 1.0)).norm() < 1e-9);
        assert!((at(&mut bounce, 50) - Vector2::new(0.5, 1.0)).norm() < 1e-9);
        assert!(at(&mut bounce, 250).norm() < 1e-9);
        assert!((at(&mut once, 1000) - Vector2::new(0.0, 1.0)).norm() < 1e-9);
    }

    #[test]
    fn a_velocity_is_a_straight_line_without_drift() {
        let v = Vector2::new(0.3, -1.2);
        let mut m = Motion::starting_at(Script::Velocity(v), Vector2::new(1.0, 2.0), 0);
        for _ in 0..100_000 {
            m.advance(0.001);
        }
        assert!((m.position() - (Vector2::new(1.0, 2.0) + v * 100.0)).norm() < 1e-9);
    }

    fn wander(seed: u64) -> Motion {
        let region = [Vector2::new(-2.0, -1.0), Vector2::new(2.0, 1.0)];
        let script = Script::Wander {
            speed: 1.2,
            region,
            turn: 1.0,
        };
        Motion::starting_at(script, Vector2::new(0.5, 0.0), seed)
    }

    /// A wander stays in its region at its speed, visits all of it, and is the same for a seed.
    #[test]
    fn a_wander_stays_in_its_region_and_is_seeded() {
        let (mut a, mut b, mut c) = (wander(4), wander(4), wander(5));
        let mut quadrants = [false; 4];
        let mut last = a.position();
        let mut differ = false;
        for _ in 0..20_000 {
            let p = a.advance(0.01);
            assert_eq!(p, b.advance(0.01));
            differ |= p != c.advance(0.01);
            assert!(
                (-2.0..=2.0).contains(&p.x) && (-1.0..=1.0).contains(&p.y),
                "{p}"
            );
            assert!((p - last).norm() <= 1.2 * 0.01 + 1e-12);
            quadrants[usize::from(p.x > 0.0) + 2 * usize::from(p.y > 0.0)] = true;
            last = p;
        }
        assert!(differ && quadrants.iter().all(|&q| q), "{quadrants:?}");
    }
}
