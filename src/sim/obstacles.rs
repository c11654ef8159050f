//! Moving obstacles in the simulation: each `[[obstacles]]` entry is a Rapier kinematic body
//! that follows its script ([`super::motion`]) and plans nothing. Rapier moves it to the pose
//! set before each step and pushes whatever it meets; the agents see it through their lidar, or,
//! without one, as neighbours ([`ObstacleRun::neighbours`]) in their replans and ORCA.

use nalgebra::Vector2;
use rapier2d::prelude::*;

use super::motion::{Motion, PathMode, Script};
use super::physics::to_rapier;
use crate::control::Neighbour;
use crate::world::{Obstacle, ObstacleMode, WallShape, World, wall_shape};

/// The most discs that cover one obstacle's shape for the agents that see it as neighbours.
const MAX_COVER: usize = 16;

/// One moving obstacle being simulated.
pub struct ObstacleRun {
    /// Its entry in the world file.
    pub obstacle: Obstacle,
    /// Its name (`obstacle-N` when the file gives none).
    pub name: String,
    motion: Motion,
    angle: f64,
    velocity: Vector2<f64>,
    /// Its shape in its own frame.
    local: WallShape,
    /// Discs about the moving point's frame that hold the shape: `(offset, radius)`, m.
    cover: Vec<(Vector2<f64>, f64)>,
    body: RigidBodyHandle,
    collider: ColliderHandle,
}

impl ObstacleRun {
    /// Puts obstacle `index` of `world` into `physics` at its start (validation has checked
    /// its shape and motion). A wander draws from its own stream of the world's seed.
    pub(super) fn new(world: &World, index: usize, physics: &mut PhysicsWorld) -> Self {
        let obstacle = world.obstacles[index].clone();
        let local = wall_shape(&obstacle.local_shape()).expect("validated shape");
        let seed = world.seed ^ (index as u64 + 1).wrapping_mul(0xA076_1D64_78BD_642F);
        let start = Vector2::from(obstacle.start());
        let motion = Motion::starting_at(script(&obstacle), start, seed);
        let pose = Pose::new(to_rapier(start), obstacle.angle);
        let body = physics.insert_body(RigidBodyBuilder::kinematic_position_based().pose(pose));
        let collider = ColliderBuilder::new(local.shape.clone())
            .friction(0.0)
            .restitution(0.0);
        let collider = physics.insert_collider(collider, Some(body));
        Self {
            name: obstacle.name_or(index),
            cover: cover(&obstacle),
            angle: obstacle.angle,
            velocity: Vector2::zeros(),
            obstacle,
            motion,
            local,
            body,
            collider,
        }
    }

    /// Sets where Rapier moves it in the next step of `dt` (s): its script's next pose.
    pub(super) fn advance(&mut self, physics: &mut PhysicsWorld, dt: f64) {
        let from = self.motion.position();
        let to = self.motion.advance(dt);
        self.velocity = (to - from) / dt;
        self.angle = self.obstacle.angle + self.obstacle.angular_speed * self.motion.time();
        if let Some(body) = physics.bodies.get_mut(self.body) {
            body.set_next_kinematic_position(Pose::new(to_rapier(to), self.angle));
        }
    }

    /// Where its moving point is, m.
    pub fn position(&self) -> Vector2<f64> {
        self.motion.position()
    }

    /// Its rotation, rad.
    pub fn angle(&self) -> f64 {
        self.angle
    }

    /// Its velocity over the last step, m/s.
    pub fn velocity(&self) -> Vector2<f64> {
        self.velocity
    }

    /// Its collider.
    pub fn collider(&self) -> ColliderHandle {
        self.collider
    }

    /// Its shape where it is now.
    pub fn shape(&self) -> WallShape {
        let p = self.position();
        let pose = Pose::new(Vector::new(p.x, p.y), self.angle);
        WallShape::new(pose * self.local.pose, self.local.shape.clone())
    }

    /// The discs that hold its shape where it is now, each with the velocity of its centre
    /// (the obstacle's, plus its turn's `ω × r`): how an agent without a lidar sees it, as it
    /// sees another agent, except that it does not give way (ORCA leaves all the avoiding to
    /// the agent).
    pub fn neighbours(&self) -> impl Iterator<Item = Neighbour> + '_ {
        let (s, c) = self.angle.sin_cos();
        let omega = self.obstacle.angular_speed;
        self.cover.iter().map(move |&(offset, radius)| {
            let r = Vector2::new(c * offset.x - s * offset.y, s * offset.x + c * offset.y);
            Neighbour {
                position: self.position() + r,
                velocity: self.velocity + omega * Vector2::new(-r.y, r.x),
                radius,
                reciprocal: false,
            }
        })
    }
}

impl ObstacleRun {
    /// [`neighbours`](Self::neighbours) and where they will be if they keep their velocities
    /// for `horizon` seconds: discs along each one's straight path, no farther apart than its
    /// radius, so that a field solved on them leaves the agent the way behind a crossing
    /// obstacle rather than the one ahead of it. (What a robot sensing the obstacle can know:
    /// where it is and how it moves now, not its script.)
    pub fn neighbours_ahead(&self, horizon: f64) -> impl Iterator<Item = Neighbour> + '_ {
        self.neighbours().flat_map(move |n| {
            let reach = n.velocity.norm() * horizon;
            let count = if n.radius > 0.0 && reach > 0.0 {
                (reach / n.radius).ceil().min(64.0) as usize
            } else {
                0
            };
            (0..=count).map(move |k| Neighbour {
                position: n.position + n.velocity * (horizon * k as f64 / count.max(1) as f64),
                ..n
            })
        })
    }
}

/// The script of an obstacle's entry.
fn script(o: &Obstacle) -> Script {
    let mode = match o.mode {
        Some(ObstacleMode::Bounce) => PathMode::Bounce,
        Some(ObstacleMode::Once) => PathMode::Once,
        _ => PathMode::Loop,
    };
    match (&o.path, o.mode) {
        (Some(points), _) => Script::Path {
            points: points.iter().map(|p| Vector2::from(*p)).collect(),
            speed: o.speed.unwrap_or(0.0),
            mode,
        },
        (None, Some(ObstacleMode::Wander)) => {
            let [lo, hi] = o.region.unwrap_or([o.start(); 2]);
            Script::Wander {
                speed: o.speed.unwrap_or(0.0),
                region: [Vector2::from(lo), Vector2::from(hi)],
                turn: o.turn,
            }
        }
        (None, _) => Script::Velocity(Vector2::from(o.velocity.unwrap_or([0.0, 0.0]))),
    }
}

/// Discs about the obstacle's frame that hold its shape, `(offset, radius)`: a disc itself; a
/// box as a row of discs along its longer side, each holding its slice of the box (a door is a
/// row of small discs, not one disc as wide as the door); a polygon as the disc about the mean
/// of its vertices through the farthest one.
fn cover(o: &Obstacle) -> Vec<(Vector2<f64>, f64)> {
    match (o.radius, o.half_extents, &o.points) {
        (Some(r), _, _) => vec![(Vector2::zeros(), r)],
        (_, Some([a, b]), _) => {
            let (long, short, along) = if a >= b {
                (a, b, Vector2::x())
            } else {
                (b, a, Vector2::y())
            };
            let n = ((long / short).ceil() as usize).clamp(1, MAX_COVER);
            let slice = long / n as f64;
            (0..n)
                .map(|k| {
                    let at = -long + (2 * k + 1) as f64 * slice;
                    (along * at, slice.hypot(short))
                })
                .collect()
        }
        (_, _, Some(points)) if !points.is_empty() => {
            let mean = points
                .iter()
                .map(|p| Vector2::from(*p))
                .sum::<Vector2<f64>>()
                / points.len() as f64;
            let r = (points.iter())
                .map(|p| (Vector2::from(*p) - mean).norm())
                .fold(0.0, f64::max);
            vec![(mean, r)]
        }
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn obstacle(text: &str) -> Obstacle {
        toml::from_str(text).unwrap()
    }

    /// Every point of a box is inside one of its cover's discs, and the discs are no wider
    /// than the box is thick by more than √2 (a door stays a thin row).
    #[test]
    fn a_box_is_covered_by_a_row_of_discs_its_own_thickness() {
        let door = obstacle("shape = \"box\"\nhalf_extents = [1.0, 0.05]\ncenter = [0.0, 0.0]\n");
        let discs = cover(&door);
        assert_eq!(discs.len(), MAX_COVER);
        for (_, r) in &discs {
            assert!(*r <= 0.05 * 2f64.sqrt() + 0.02, "{r}");
        }
        for i in 0..=200 {
            for j in 0..=10 {
                let p = Vector2::new(-1.0 + i as f64 * 0.01, -0.05 + j as f64 * 0.01);
                assert!(
                    discs.iter().any(|(c, r)| (p - c).norm() <= r + 1e-12),
                    "{p}"
                );
            }
        }
        let post = obstacle("shape = \"box\"\nhalf_extents = [0.2, 0.3]\ncenter = [0.0, 0.0]\n");
        // Taller than wide: two discs up its height, each holding a 0.4 m × 0.3 m half.
        let discs = cover(&post);
        assert_eq!(discs.len(), 2);
        assert!((discs[1].0 - Vector2::new(0.0, 0.15)).norm() < 1e-12);
        assert!((discs[1].1 - 0.25).abs() < 1e-12);
    }

    /// A bar turning about its centre: its cover turns with it, and the disc at its end (the
    /// centre of the last of its 8 slices, 0.7 m out) moves at `ω r` across the bar.
    #[test]
    fn a_turning_shape_is_seen_where_it_is_and_at_the_speed_of_its_parts() {
        let text = "shape = \"box\"\nhalf_extents = [0.8, 0.1]\ncenter = [5.0, 5.0]\nangular_speed = 1.0\n";
        let world = format!(
            "size = [10.0, 10.0]\n[[agents]]\nname = \"a\"\nstart = [1.0, 1.0]\ntarget = [9.0, 1.0]\n\
             controller = {{ kind = \"nadf\", b = 5.0 }}\n[[obstacles]]\n{text}"
        );
        let world = crate::world::load_str(&world, std::path::Path::new("w.toml"), &[]).unwrap();
        let mut physics = super::super::physics::empty_world(world.dt, [0.0, 0.0]);
        let mut run = ObstacleRun::new(&world, 0, &mut physics);
        let steps = (std::f64::consts::FRAC_PI_2 / world.dt).round() as usize;
        for _ in 0..steps {
            run.advance(&mut physics, world.dt);
            physics.step();
        }
        // A quarter turn (to within a step): the bar is upright.
        assert!(
            (run.angle() - std::f64::consts::FRAC_PI_2).abs() < world.dt,
            "{}",
            run.angle()
        );
        let end = run.neighbours().last().unwrap();
        assert!(
            (end.position - Vector2::new(5.0, 5.7)).norm() < 0.01,
            "{}",
            end.position
        );
        assert!(
            (end.velocity - Vector2::new(-0.7, 0.0)).norm() < 0.01,
            "{}",
            end.velocity
        );
        assert!(!end.reciprocal);
        // Rapier's body is where the script put it.
        let body = &physics.bodies[run.body];
        assert!((body.rotation().angle() - run.angle()).abs() < 1e-5);
        let shape = run.shape();
        assert!(shape.distance_to_point(5.0, 5.75) < 1e-4);
        assert!(shape.distance_to_point(5.75, 5.0) > 0.6);
    }
}
