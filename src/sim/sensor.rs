//! Noisy sensing of the walls (paper §VI.5, figures 34–36, and the corridor of figure 42).
//!
//! At every reading, each wall's boundary is registered where it is plus an independent draw of
//! uniform noise in `[-noise, noise]`, m: out (the wall looks thicker) or in (thinner, the
//! dangerous case). The agent rebuilds its field from the sensed walls, as it would from raw
//! range data, without filtering. Readings come at `rate` Hz from `t = 0`. The noise comes from a
//! SplitMix64 generator seeded by the world's seed and the agent's index, so a run is
//! reproducible to the bit.
//!
//! With `position_noise` the agent's estimate of its own position is off too: each reading
//! draws an error uniform in `[-σ, σ]` per axis (after the walls' draws), held until the next.

use crate::random::SplitMix;
use crate::world::SensorSettings;

/// One agent's wall sensor.
#[derive(Debug, Clone)]
pub struct Sensor {
    /// The sensor's settings.
    pub settings: SensorSettings,
    rng: SplitMix,
    /// Readings taken so far.
    pub readings: usize,
}

impl Sensor {
    /// The sensor of the agent at `index` in a world with `seed`.
    pub fn new(settings: SensorSettings, seed: u64, index: usize) -> Self {
        // Distinct, well-mixed streams per agent for the same world seed.
        let mut sensor = Self {
            settings,
            rng: SplitMix::new(seed ^ (index as u64 + 1).wrapping_mul(0xA076_1D64_78BD_642F)),
            readings: 0,
        };
        sensor.rng.next_u64();
        sensor
    }

    /// Whether a reading is due at simulated time `t`, s.
    pub fn due(&self, t: f64) -> bool {
        t + 1e-9 >= self.readings as f64 / self.settings.rate
    }

    /// Takes a reading of `walls` walls: how far each one's boundary is registered outside its
    /// true position, m.
    pub fn read(&mut self, walls: usize) -> Vec<f64> {
        self.readings += 1;
        (0..walls)
            .map(|_| self.settings.noise * (2.0 * self.uniform() - 1.0))
            .collect()
    }

    /// The error of the position estimate for this reading, m (zero without position noise;
    /// call after [`Sensor::read`]).
    pub fn position_error(&mut self) -> [f64; 2] {
        let sigma = self.settings.position_noise;
        if sigma == 0.0 {
            return [0.0, 0.0];
        }
        [
            sigma * (2.0 * self.uniform() - 1.0),
            sigma * (2.0 * self.uniform() - 1.0),
        ]
    }

    /// A uniform draw in `[0, 1)`.
    fn uniform(&mut self) -> f64 {
        self.rng.uniform()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sensor(seed: u64, index: usize) -> Sensor {
        Sensor::new(
            SensorSettings {
                kind: crate::world::SensorKind::Walls,
                range: None,
                rays: None,
                fov: None,
                dropout: None,
                noise: 0.5,
                position_noise: 0.0,
                rate: 10.0,
            },
            seed,
            index,
        )
    }

    #[test]
    fn readings_are_uniform_in_the_noise_band_and_reproducible() {
        let mut a = sensor(7, 0);
        let draws: Vec<f64> = (0..2000).flat_map(|_| a.read(5)).collect();
        assert!(draws.iter().all(|d| (-0.5..0.5).contains(d)));
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        let var = draws.iter().map(|d| d * d).sum::<f64>() / draws.len() as f64;
        // Uniform on [-0.5, 0.5]: mean 0, variance 1/12.
        assert!(
            mean.abs() < 0.01 && (var - 1.0 / 12.0).abs() < 0.003,
            "{mean} {var}"
        );
        let mut b = sensor(7, 0);
        assert_eq!(b.read(5), sensor(7, 0).read(5));
        assert_ne!(b.read(5), sensor(7, 1).read(5));
        assert_ne!(sensor(7, 0).read(5), sensor(8, 0).read(5));
    }

    #[test]
    fn position_errors_are_in_the_band_and_zero_without_position_noise() {
        let mut s = sensor(3, 0);
        assert_eq!(s.position_error(), [0.0, 0.0]);
        s.settings.position_noise = 0.2;
        let draws: Vec<[f64; 2]> = (0..500).map(|_| s.position_error()).collect();
        assert!(draws.iter().flatten().all(|d| (-0.2..0.2).contains(d)));
        assert!(draws.iter().flatten().any(|d| d.abs() > 0.15));
    }

    #[test]
    fn readings_come_at_the_rate() {
        let mut s = sensor(0, 0);
        let dt = 0.01;
        let mut times = Vec::new();
        for step in 0..100 {
            let t = step as f64 * dt;
            if s.due(t) {
                s.read(1);
                times.push(step);
            }
        }
        assert_eq!(times, (0..10).map(|k| k * 10).collect::<Vec<_>>());
    }
}
