//! The clearance envelope: a body never moves faster than it can stop in the room it has
//! ahead, so it touches no static wall and no other body that keeps the same envelope, at
//! any `dt` (issue "never a touch").
//!
//! **Why a body with mass touches.** NADF leaves motion along the guidance undamped, so on a
//! long streamline the body builds up speed, and a body at speed `v` strays about `m v/B_d`
//! from its path before the damping brings it back (Proposition 2's `δ_m`). Through a door
//! with less room than that beside the path, it touches. No gain or margin fixes this for
//! every map: the speed has to follow the room.
//!
//! **How Rapier moves a body.** Rapier's step is `N` substeps (its solver iterations, 4 by
//! default), each adding `1/N` of the step's change of velocity, so a body whose velocity goes
//! from `v` to `v⁺` over a step moves by `dt (v + c (v⁺ − v))` with `c = (N + 1)/(2N)`, on a
//! slightly bent path (no further than `|v⁺ − v| dt/8` from the chord) ([`Step`]).
//!
//! **The braking.** The envelope brakes by damping the whole velocity with `B_e` (N·s/m, by
//! default the controller's own damping, `B_d` for NADF: the force NADF already applies to
//! the motion it damps), integrated exactly over a step: the velocity keeps the fraction
//! `ρ = e^{−B_e dt/m}` of itself each step and its direction. From speed `s` the body then
//! moves on a straight line and stops within the *stopping distance*
//! `S(s) = s dt (1/(1 − ρ) − c)` (the sum of its braked steps, never more than `m s/B_e + s dt`).
//!
//! **The sweep.** Each step the body commits to a velocity `v⁺`. Its *sweep* ([`Sweep`]) is its
//! disc moved along the step's chord (grown by the bend) and then, braking from `v⁺`, along
//! `v⁺` until it stops: where it goes in this step and, if it brakes from then on, after. The
//! envelope keeps every sweep clear of the walls and of every other body's sweep by at least
//! [`MARGIN`].
//!
//! **The argument.** Invariant: after each step, the body's remaining sweep (its disc moved
//! along its velocity `v` for `S(|v|)`) is clear. Each step the law's force gives a candidate
//! `v⁺`; the envelope keeps the force when its sweep is clear, else takes, along the same
//! direction or one turned from it by up to a right angle, the fastest velocity whose sweep is
//! clear and that makes the most headway along `v⁺` (a body blocked head-on slides along what
//! blocks it), or brakes. Every sweep it takes is tested clear. Braking keeps the invariant
//! without a new test: the braked body stays on the line of its remaining sweep, and what is
//! left of that sweep after the step is exactly the sweep of the new state
//! (`S(|v|) − (1 − c(1 − ρ))|v| dt = ρ S(|v|) = S(ρ|v|)`). A cut speed of zero is clear for the
//! same reason (the body moves `(1 − c)|v| dt ≤ S(|v|)` along its old line), so a clear choice
//! always exists. So by induction every sweep is clear at every step, and the body, which
//! never leaves its sweep, never touches a wall. Nothing in this depends on `dt`: the
//! stopping distance is that of the discrete steps themselves.
//!
//! **Other bodies.** Agents decide in a fixed order within a step. Agent `i`'s sweep must be
//! clear of the sweeps that agents before it have just committed to and of the remaining
//! sweeps of those after it. An agent after it can always brake: its braked sweep lies in its
//! remaining one, which `i` kept clear of. So all sweeps stay pairwise disjoint and no two
//! bodies that keep the envelope ever touch, however dense the crowd. This needs each body's
//! position and velocity every step (what ORCA reads of its neighbours too), not the field's
//! replans: the field routes around the others at its own rate, the envelope keeps the bodies
//! apart at every step. A body that does not keep the envelope is taken as its disc moved for
//! one step; against it there is no guarantee.
//!
//! **What it assumes.** The force the envelope asks for is no larger than the law's own or the
//! braking's (it picks whichever choice is within that); the world's external acceleration is
//! known and compensated; the walls stand still; the body starts at rest or within its
//! envelope. A body that starts too fast for the room it has brakes at once and may still
//! touch.

use nalgebra::Vector2;

/// How far from walls and other capsules a capsule must stay, m: twice the contact tolerance
/// (an active contact within 1 mm counts as a touch), so that the room a body keeps is
/// measured in millimetres, not in the solver's rounding or its contact tolerance.
pub const MARGIN: f64 = 2e-3;

/// How Rapier moves a body over one step: from velocity `v` to `v⁺`, by
/// `dt (v + blend (v⁺ − v))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// The step, s.
    pub dt: f64,
    /// `c = (N + 1)/(2N)` for `N` substeps (1 for plain symplectic Euler, 5/8 for Rapier's
    /// default 4).
    pub blend: f64,
}

impl Step {
    /// Where a body at `x` goes over the step from velocity `v` to `next`, m.
    pub fn moved(&self, x: Vector2<f64>, v: Vector2<f64>, next: Vector2<f64>) -> Vector2<f64> {
        x + (v + (next - v) * self.blend) * self.dt
    }
}

/// The envelope of one body: its braking, its mass and its disc.
///
/// ```
/// use nadf::control::{Envelope, Step};
/// let envelope = Envelope { damping: 10.0, mass: 1.0, radius: 0.3 };
/// let step = Step { dt: 0.01, blend: 0.625 };
/// // At 8 m/s a 1 kg body damped with 10 N·s/m stops within about m·v/B = 0.8 m.
/// let stop = envelope.stopping_distance(8.0, step);
/// assert!(stop < 0.8 && stop > 0.75, "{stop}");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    /// The braking damping `B_e`, N·s/m (> 0): the envelope stops the body by damping its
    /// whole velocity with it. Typical: the controller's damping (NADF's `B_d` = 3–30 for a
    /// 1 kg body); larger brakes harder and binds less.
    pub damping: f64,
    /// The body's mass `m`, kg.
    pub mass: f64,
    /// The body's disc, m.
    pub radius: f64,
}

/// The force for the next step, after the envelope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Enveloped {
    /// The force to apply, N.
    pub force: Vector2<f64>,
    /// The velocity the body will have after the step, m/s.
    pub velocity: Vector2<f64>,
    /// Where the body goes in the step and, braking, after it.
    pub sweep: Sweep,
    /// Whether the envelope changed the law's force.
    pub bound: bool,
}

impl Envelope {
    /// The fraction `ρ = e^{−B_e dt/m}` of its velocity the braked body keeps over a step.
    pub fn retention(&self, step: Step) -> f64 {
        (-self.damping * step.dt / self.mass).exp()
    }

    /// How far the body moves from speed `speed` (m/s) once it brakes: `s dt (1/(1 − ρ) − c)`,
    /// m.
    pub fn stopping_distance(&self, speed: f64, step: Step) -> f64 {
        speed * step.dt * (1.0 / (1.0 - self.retention(step)) - step.blend)
    }

    /// The sweep of a body at `x` that goes from velocity `v` to `next` over the step and
    /// brakes from then on.
    pub fn sweep(&self, x: Vector2<f64>, v: Vector2<f64>, next: Vector2<f64>, step: Step) -> Sweep {
        let moved = step.moved(x, v, next);
        let speed = next.norm();
        let stop = if speed > 0.0 {
            moved + next * (self.stopping_distance(speed, step) / speed)
        } else {
            moved
        };
        // The substeps bend the path off the chord by at most |Δv| dt/8; none when the change
        // is along the chord (braking).
        let chord = moved - x;
        let change = next - v;
        let across = if chord.norm() > 0.0 {
            (change - chord * (change.dot(&chord) / chord.norm_squared())).norm()
        } else {
            change.norm()
        };
        Sweep {
            points: [x, moved, stop],
            radius: self.radius + across * step.dt / 8.0,
        }
    }

    /// The remaining sweep of a body at `x` moving at `v`: braking, it stays on the line
    /// along `v` for the stopping distance.
    pub fn remaining(&self, x: Vector2<f64>, v: Vector2<f64>, step: Step) -> Sweep {
        let speed = v.norm();
        let stop = if speed > 0.0 && speed.is_finite() {
            x + v * (self.stopping_distance(speed, step) / speed)
        } else {
            x
        };
        Sweep {
            points: [x, x, stop],
            radius: self.radius,
        }
    }

    /// The force `force` (N) the law asks for, for a body at `x` moving at `v` (m/s) under
    /// the external acceleration `external` (m/s²), after the envelope, for one `step`.
    /// `clear(sweep)` says whether a sweep keeps [`MARGIN`] from the walls and the other
    /// bodies' sweeps.
    pub fn filter(
        &self,
        force: Vector2<f64>,
        (x, v): (Vector2<f64>, Vector2<f64>),
        external: Vector2<f64>,
        step: Step,
        mut clear: impl FnMut(&Sweep) -> bool,
    ) -> Enveloped {
        let (m, dt) = (self.mass, step.dt);
        let next = v + (force / m + external) * dt;
        let speed = next.norm();
        let sweep = self.sweep(x, v, next, step);
        if !(speed > 0.0 && speed.is_finite()) || clear(&sweep) {
            return Enveloped {
                force,
                velocity: next,
                sweep,
                bound: false,
            };
        }
        // As fast as the room allows along the law's direction or one turned from it by up to
        // a right angle (zero is always clear), making the most headway along the law's...
        // The force that takes the body from `v` to `u` over the step.
        let force_to = |u: Vector2<f64>| m * ((u - v) / dt - external);
        let braked = v * self.retention(step);
        let brake_force = force_to(braked);
        let budget = force.norm().max(brake_force.norm());
        let direction = next / speed;
        let mut best: Option<(f64, Vector2<f64>, Vector2<f64>)> = None;
        for turn in TURNS {
            let (sin, cos) = turn.sin_cos();
            let d = Vector2::new(
                direction.x * cos - direction.y * sin,
                direction.x * sin + direction.y * cos,
            );
            let (mut lo, mut hi) = (0.0, speed);
            for _ in 0..BISECTIONS {
                let s = 0.5 * (lo + hi);
                if clear(&self.sweep(x, v, d * s, step)) {
                    lo = s;
                } else {
                    hi = s;
                }
            }
            let (cut, headway) = (d * lo, lo * cos);
            let cut_force = force_to(cut);
            if cut_force.norm() <= budget && best.is_none_or(|(h, ..)| headway > h) {
                best = Some((headway, cut, cut_force));
            }
        }
        // ...or the braking, when no such turn is within the force.
        let (force, velocity) = match best {
            Some((headway, cut, cut_force)) if headway > 0.0 || brake_force.norm() >= budget => {
                (cut_force, cut)
            }
            _ => (brake_force, braked),
        };
        Enveloped {
            force,
            velocity,
            sweep: self.sweep(x, v, velocity, step),
            bound: true,
        }
    }
}

/// Halvings of the speed when the envelope cuts it: the cut speed is within 2⁻¹⁴ of the
/// fastest clear one.
const BISECTIONS: usize = 14;

/// The turns from the law's direction the envelope tries when that direction has no room, rad
/// (the law's first): a body blocked head-on slides along what blocks it instead of stopping,
/// which is what keeps a dense crowd from jamming.
const TURNS: [f64; 7] = [
    0.0,
    std::f64::consts::FRAC_PI_6,
    -std::f64::consts::FRAC_PI_6,
    std::f64::consts::FRAC_PI_3,
    -std::f64::consts::FRAC_PI_3,
    std::f64::consts::FRAC_PI_2,
    -std::f64::consts::FRAC_PI_2,
];

/// A body's disc moved along a path of two segments: the step's chord, then the straight
/// line on which it brakes to a stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// Where the disc is, where the step takes it, and where it stops braking, m.
    pub points: [Vector2<f64>; 3],
    /// The disc's radius, grown by how far the substeps bend the step off its chord, m.
    pub radius: f64,
}

impl Sweep {
    /// The segments of its path, `(from, to)`.
    pub fn segments(&self) -> [(Vector2<f64>, Vector2<f64>); 2] {
        let [a, b, c] = self.points;
        [(a, b), (b, c)]
    }

    /// The distance between the two swept areas, m (0 when they overlap).
    ///
    /// ```
    /// use nadf::control::Sweep;
    /// use nalgebra::Vector2;
    /// let still = |x: f64| Sweep { points: [Vector2::new(x, 0.0); 3], radius: 0.5 };
    /// let moving = Sweep {
    ///     points: [Vector2::zeros(), Vector2::new(0.1, 0.0), Vector2::new(1.0, 0.0)],
    ///     radius: 0.5,
    /// };
    /// assert!((moving.distance(&still(3.0)) - 1.0).abs() < 1e-12);
    /// assert_eq!(moving.distance(&still(1.5)), 0.0);
    /// ```
    pub fn distance(&self, other: &Sweep) -> f64 {
        let mut d = f64::INFINITY;
        for (a, b) in self.segments() {
            for (c, e) in other.segments() {
                d = d.min(segment_distance((a, b), (c, e)));
            }
        }
        (d - self.radius - other.radius).max(0.0)
    }

    /// Whether it could come within `margin` of `other` at all (a cheap test on bounding
    /// circles, to skip the far ones).
    pub fn near(&self, other: &Sweep, margin: f64) -> bool {
        let (c1, r1) = self.bound();
        let (c2, r2) = other.bound();
        (c1 - c2).norm() <= r1 + r2 + margin
    }

    /// A circle around it: the centre of its points and the farthest point's distance plus
    /// the radius.
    fn bound(&self) -> (Vector2<f64>, f64) {
        let [a, b, c] = self.points;
        let centre = (a + b + c) / 3.0;
        let far = [a, b, c]
            .iter()
            .map(|p| (p - centre).norm())
            .fold(0.0, f64::max);
        (centre, far + self.radius)
    }
}

/// The distance between the segments `a`–`b` and `c`–`d`, m.
fn segment_distance(
    (a, b): (Vector2<f64>, Vector2<f64>),
    (c, d): (Vector2<f64>, Vector2<f64>),
) -> f64 {
    let cross = |u: Vector2<f64>, v: Vector2<f64>| u.x * v.y - u.y * v.x;
    let (r, s) = (b - a, d - c);
    let denom = cross(r, s);
    if denom != 0.0 {
        let t = cross(c - a, s) / denom;
        let u = cross(c - a, r) / denom;
        if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u) {
            return 0.0;
        }
    }
    [
        point_segment(a, (c, d)),
        point_segment(b, (c, d)),
        point_segment(c, (a, b)),
        point_segment(d, (a, b)),
    ]
    .into_iter()
    .fold(f64::INFINITY, f64::min)
}

/// The distance from `p` to the segment `a`–`b`, m.
fn point_segment(p: Vector2<f64>, (a, b): (Vector2<f64>, Vector2<f64>)) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    const STEP: Step = Step {
        dt: 0.01,
        blend: 0.625,
    };
    const ENVELOPE: Envelope = Envelope {
        damping: 10.0,
        mass: 1.0,
        radius: 0.3,
    };

    /// Rapier's substeps: `N` updates of `v` by `Δv/N`, each followed by `x += v dt/N`.
    fn substeps(x: &mut Vector2<f64>, v: &mut Vector2<f64>, next: Vector2<f64>, dt: f64, n: usize) {
        let change = (next - *v) / n as f64;
        for _ in 0..n {
            *v += change;
            *x += *v * (dt / n as f64);
        }
    }

    /// The blend is what N substeps do, and the stopping distance is the braked steps' sum.
    #[test]
    fn the_stopping_distance_is_the_braked_steps_sum() {
        for n in [1, 4, 8] {
            let step = Step {
                blend: (n as f64 + 1.0) / (2.0 * n as f64),
                ..STEP
            };
            let (mut x, mut v) = (Vector2::zeros(), Vector2::new(8.0, 0.0));
            let moved = step.moved(x, v, Vector2::new(6.0, 1.0));
            substeps(&mut x, &mut v, Vector2::new(6.0, 1.0), step.dt, n);
            assert!((x - moved).norm() < 1e-12, "{n}: {x} vs {moved}");
            let (mut x, mut v) = (0.0, 8.0);
            let rho = ENVELOPE.retention(step);
            for _ in 0..100_000 {
                let (mut p, mut u) = (Vector2::new(x, 0.0), Vector2::new(v, 0.0));
                substeps(&mut p, &mut u, Vector2::new(v * rho, 0.0), step.dt, n);
                (x, v) = (p.x, u.x);
            }
            let s = ENVELOPE.stopping_distance(8.0, step);
            assert!((x - s).abs() < 1e-9, "{n}: {x} {s}");
            assert!(s < 8.0 * ENVELOPE.mass / ENVELOPE.damping + 8.0 * step.dt);
        }
    }

    /// A wall at x = `wall`: a sweep is clear when every point of it keeps the margin.
    fn before(wall: f64) -> impl Fn(&Sweep) -> bool {
        move |s: &Sweep| s.points.iter().all(|p| p.x + s.radius <= wall - MARGIN)
    }

    /// A body pushed straight at a wall (by a law that never brakes) stops short of it by the
    /// margin at most, at every dt, and gets there.
    #[test]
    fn a_body_pushed_at_a_wall_never_reaches_it() {
        for dt in [0.001, 0.01, 0.05, 0.2] {
            let step = Step { dt, ..STEP };
            let wall = 2.3;
            let (mut x, mut v) = (Vector2::zeros(), Vector2::zeros());
            for _ in 0..20_000 {
                let out = ENVELOPE.filter(
                    Vector2::new(5.0, 0.0),
                    (x, v),
                    Vector2::zeros(),
                    step,
                    before(wall),
                );
                substeps(&mut x, &mut v, out.velocity, dt, 4);
                assert!(x.x + 0.3 <= wall - MARGIN + 1e-12, "dt {dt}: {x}");
            }
            assert!(x.x + 0.3 > wall - MARGIN - 1e-3, "dt {dt}: {x}");
        }
    }

    /// Clear ahead: the law's force is kept to the bit.
    #[test]
    fn clear_ahead_nothing_changes() {
        let f = Vector2::new(1.0, -2.0);
        let out = ENVELOPE.filter(
            f,
            (Vector2::zeros(), Vector2::new(3.0, 0.0)),
            Vector2::zeros(),
            STEP,
            |_| true,
        );
        assert_eq!((out.force, out.bound), (f, false));
    }

    /// The distance between segments, against a brute-force sampling of both.
    #[test]
    fn segment_distances_agree_with_sampling() {
        let cases = [
            ((0.0, 0.0, 2.0, 0.0), (1.0, 1.0, 1.0, 3.0)),
            ((0.0, 0.0, 2.0, 0.0), (1.0, -1.0, 1.0, 3.0)),
            ((0.0, 0.0, 2.0, 2.0), (3.0, 0.0, 4.0, 1.0)),
            ((0.0, 0.0, 0.0, 0.0), (1.0, 1.0, 2.0, 1.0)),
        ];
        for ((ax, ay, bx, by), (cx, cy, dx, dy)) in cases {
            let (a, b) = (Vector2::new(ax, ay), Vector2::new(bx, by));
            let (c, d) = (Vector2::new(cx, cy), Vector2::new(dx, dy));
            let mut sampled = f64::INFINITY;
            for i in 0..=400 {
                for j in 0..=400 {
                    let p = a + (b - a) * (i as f64 / 400.0);
                    let q = c + (d - c) * (j as f64 / 400.0);
                    sampled = sampled.min((p - q).norm());
                }
            }
            let exact = segment_distance((a, b), (c, d));
            assert!(
                (exact - sampled).abs() < 1e-2 && exact <= sampled + 1e-12,
                "{exact} {sampled}"
            );
        }
    }

    /// Two bodies driven head-on at each other, deciding in turn and moved by substeps: they
    /// never touch, at any dt.
    #[test]
    fn two_bodies_head_on_never_touch() {
        for dt in [0.002, 0.01, 0.1] {
            let step = Step { dt, ..STEP };
            let mut x = [Vector2::new(-3.0, 0.0), Vector2::new(3.0, 0.01)];
            let mut v = [Vector2::zeros(); 2];
            let push = [Vector2::new(4.0, 0.0), Vector2::new(-4.0, 0.0)];
            for _ in 0..5000 {
                let mut sweeps: Vec<Sweep> = (0..2)
                    .map(|i| ENVELOPE.remaining(x[i], v[i], step))
                    .collect();
                let mut next = v;
                for i in 0..2 {
                    let other = sweeps[1 - i];
                    let out = ENVELOPE.filter(push[i], (x[i], v[i]), Vector2::zeros(), step, |s| {
                        s.distance(&other) > MARGIN
                    });
                    next[i] = out.velocity;
                    sweeps[i] = out.sweep;
                }
                for i in 0..2 {
                    substeps(&mut x[i], &mut v[i], next[i], dt, 4);
                }
                let separation = (x[0] - x[1]).norm() - 0.6;
                assert!(separation >= MARGIN - 1e-9, "dt {dt}: {separation}");
            }
        }
    }
}
