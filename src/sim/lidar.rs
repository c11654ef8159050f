//! A 2-D lidar of Rapier ray casts (issue "unknown worlds"): `rays` rays over a field of view
//! `fov` centred on the direction to the target, each cast from the agent's centre against the
//! walls and the other agents (the query pipeline Rapier maintains), the agent's own collider
//! excluded. Each range reading gets Gaussian noise of standard deviation `noise`, and is lost
//! with probability `dropout`. Scans come at `rate` Hz from `t = 0`. The draws come from a
//! SplitMix64 generator seeded by the world's seed and the agent's index, so a run is
//! reproducible to the bit.

use rapier2d::prelude::{ColliderHandle, PhysicsWorld, QueryFilter, Ray, Vector};

use crate::field::Beam;
use crate::random::SplitMix;
use crate::world::SensorSettings;

/// Rays per scan when the world file gives none.
pub const DEFAULT_RAYS: u32 = 360;

/// One agent's lidar.
#[derive(Debug, Clone)]
pub struct Lidar {
    /// Its settings (a lidar's: `range` is set).
    pub settings: SensorSettings,
    rng: SplitMix,
    /// Scans taken so far.
    pub scans: usize,
    /// The last scan's range along each ray, m, in the rays' order (empty before the first).
    ranges: Vec<f64>,
}

impl Lidar {
    /// The lidar of the agent at `index` in a world with `seed`.
    pub fn new(settings: SensorSettings, seed: u64, index: usize) -> Self {
        Self {
            settings,
            // Another stream than the walls sensor's for the same seed and agent.
            rng: SplitMix::new(seed ^ (index as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03)),
            scans: 0,
            ranges: Vec::new(),
        }
    }

    /// The last scan's reading along each of its rays, m, in the order they are cast (ray `k`
    /// at `heading − fov/2 + (k + ½) fov/rays`, the heading being the direction to the
    /// target): the distance to the hit, or the range where the ray hit nothing or was lost.
    /// Empty before the first scan.
    pub fn ranges(&self) -> &[f64] {
        &self.ranges
    }

    /// Whether a scan is due at simulated time `t`, s.
    pub fn due(&self, t: f64) -> bool {
        t + 1e-9 >= self.scans as f64 / self.settings.rate
    }

    /// Scans from `from` (m), facing `heading` (rad), excluding `own`: the rays that returned,
    /// each ending at its hit or at the end of the range.
    pub fn scan(
        &mut self,
        physics: &PhysicsWorld,
        from: [f64; 2],
        heading: f64,
        own: ColliderHandle,
    ) -> Vec<Beam> {
        self.scans += 1;
        let range = self.settings.range.unwrap_or(0.0);
        let rays = self.settings.rays.unwrap_or(DEFAULT_RAYS).max(1);
        let fov = self.settings.fov.unwrap_or(360.0).to_radians();
        let dropout = self.settings.dropout.unwrap_or(0.0);
        let filter = QueryFilter::default().exclude_collider(own);
        let origin = Vector::new(from[0], from[1]);
        let mut beams = Vec::with_capacity(rays as usize);
        self.ranges.clear();
        for k in 0..rays {
            let angle = heading - 0.5 * fov + (k as f64 + 0.5) * fov / rays as f64;
            let (sin, cos) = angle.sin_cos();
            let ray = Ray::new(origin, Vector::new(cos, sin));
            let hit = physics
                .cast_ray(&ray, range, true, filter)
                .map(|(_, toi)| toi);
            // Draw both every time, so that one ray's outcome does not shift the others' noise.
            let (lost, noise) = (self.rng.uniform() < dropout, self.rng.normal());
            if lost {
                self.ranges.push(range);
                continue;
            }
            let (distance, hit) = match hit {
                Some(d) => ((d + self.settings.noise * noise).clamp(0.0, range), true),
                None => (range, false),
            };
            self.ranges.push(distance);
            beams.push(Beam {
                from,
                to: [from[0] + distance * cos, from[1] + distance * sin],
                hit,
            });
        }
        beams
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::{Grid, KnownMap};
    use crate::world::SensorKind;
    use rapier2d::prelude::{ColliderBuilder, RigidBodyBuilder};

    fn lidar(noise: f64, dropout: f64) -> Lidar {
        Lidar::new(
            SensorSettings {
                kind: SensorKind::Lidar,
                range: Some(5.0),
                rays: Some(4),
                fov: None,
                dropout: Some(dropout),
                noise,
                position_noise: 0.0,
                rate: 10.0,
            },
            3,
            0,
        )
    }

    /// A wall 2 m to the right of the origin (its face at x = 1.9), nothing elsewhere.
    fn world() -> (PhysicsWorld, ColliderHandle) {
        let mut physics = PhysicsWorld::default();
        let ground = physics.insert_body(RigidBodyBuilder::fixed());
        let wall = ColliderBuilder::cuboid(0.1, 3.0).translation(Vector::new(2.0, 0.0));
        physics.insert_collider(wall, Some(ground));
        let (_, own) = physics.insert(RigidBodyBuilder::dynamic(), ColliderBuilder::ball(0.2));
        physics.step();
        (physics, own)
    }

    #[test]
    fn rays_end_at_the_wall_or_at_the_range_and_skip_the_agent_itself() {
        let (physics, own) = world();
        // Four rays over 360° facing +x: at 45°, 135°, 225°, 315°.
        let beams = lidar(0.0, 0.0).scan(&physics, [0.0, 0.0], 0.0, own);
        assert_eq!(beams.len(), 4);
        let hits: Vec<_> = beams.iter().filter(|b| b.hit).collect();
        assert_eq!(hits.len(), 2, "{beams:?}");
        for b in hits {
            assert!((b.to[0] - 1.9).abs() < 1e-4, "{b:?}");
        }
        for b in beams.iter().filter(|b| !b.hit) {
            assert!((b.to[0].hypot(b.to[1]) - 5.0).abs() < 1e-9, "{b:?}");
        }
    }

    /// The ranges hold every ray in order, a lost one reading as the range: as a policy's
    /// observation they keep their length whatever the dropout.
    #[test]
    fn ranges_have_one_reading_per_ray_in_order() {
        let (physics, own) = world();
        let mut scanner = lidar(0.0, 0.0);
        assert!(scanner.ranges().is_empty());
        scanner.scan(&physics, [0.0, 0.0], 0.0, own);
        // Facing +x, the rays go at −135°, −45°, 45° and 135°: the two towards the wall meet
        // its face 1.9·√2 away, the others see nothing in 5 m.
        let expected = [5.0, 1.9 * 2f64.sqrt(), 1.9 * 2f64.sqrt(), 5.0];
        for (r, e) in scanner.ranges().iter().zip(expected) {
            assert!((r - e).abs() < 1e-4, "{:?}", scanner.ranges());
        }
        let mut lossy = lidar(0.0, 0.5);
        for _ in 0..20 {
            let beams = lossy.scan(&physics, [0.0, 0.0], 0.0, own);
            assert_eq!(lossy.ranges().len(), 4);
            let hits = lossy.ranges().iter().filter(|r| **r < 5.0).count();
            assert_eq!(hits, beams.iter().filter(|b| b.hit).count());
        }
    }

    #[test]
    fn noise_and_dropout_are_seeded() {
        let (physics, own) = world();
        let a = lidar(0.05, 0.3).scan(&physics, [0.0, 0.0], 0.0, own);
        let b = lidar(0.05, 0.3).scan(&physics, [0.0, 0.0], 0.0, own);
        assert_eq!(a, b);
        let mut many = lidar(0.05, 0.3);
        let kept: usize = (0..500)
            .map(|_| many.scan(&physics, [0.0, 0.0], 0.0, own).len())
            .sum();
        // 2000 rays, 30 % lost.
        assert!((1300..1500).contains(&kept), "{kept}");
    }

    /// A moving body (a kinematic one, as a scripted obstacle is) is in the scans, and the
    /// map built from them forgets the cells it has left: the beams that now pass through
    /// them lower their log-odds until they read free again.
    #[test]
    fn the_map_sees_a_moving_body_and_forgets_where_it_was() {
        let mut physics = PhysicsWorld::default();
        let (_, own) = physics.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(2.0, 5.0)),
            ColliderBuilder::ball(0.2),
        );
        let (mover, _) = physics.insert(
            RigidBodyBuilder::kinematic_position_based().translation(Vector::new(4.0, 5.0)),
            ColliderBuilder::ball(0.3),
        );
        physics.step();
        let mut scanner = lidar(0.0, 0.0);
        scanner.settings.rays = Some(360);
        let mut map = KnownMap::new(Grid::covering([10.0, 10.0], 0.1));
        let occupied_near = |map: &KnownMap, c: [f64; 2]| {
            let grid = *map.grid();
            (0..grid.ny)
                .flat_map(|j| (0..grid.nx).map(move |i| (i, j)))
                .filter(|&(i, j)| map.occupied()[grid.index(i, j)])
                .filter(|&(i, j)| {
                    let p = grid.center(i, j);
                    (p[0] - c[0]).hypot(p[1] - c[1]) < 0.5
                })
                .count()
        };
        for _ in 0..20 {
            map.update(&scanner.scan(&physics, [2.0, 5.0], 0.0, own));
        }
        assert!(occupied_near(&map, [4.0, 5.0]) > 0);
        physics.bodies[mover].set_next_kinematic_translation(Vector::new(4.0, 8.5));
        physics.step();
        let mut scans = 0;
        while occupied_near(&map, [4.0, 5.0]) > 0 {
            scans += 1;
            assert!(scans <= 10, "the map still holds the body where it was");
            map.update(&scanner.scan(&physics, [2.0, 5.0], 0.0, own));
        }
        assert!(occupied_near(&map, [4.0, 8.5]) > 0);
    }
}
