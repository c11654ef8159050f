//! The one pseudo-random generator of the sandbox: SplitMix64 (Steele, Lea and Flood 2014),
//! small, fast and the same on every platform, so a run is reproducible to the bit for a given
//! world file and seed. Each user (a sensor, a lidar, a maze) seeds its own stream.

/// A SplitMix64 stream.
///
/// ```
/// # use nadf::random::SplitMix;
/// let (mut a, mut b) = (SplitMix::new(7), SplitMix::new(7));
/// assert_eq!(a.next_u64(), b.next_u64());
/// assert!((0.0..1.0).contains(&a.uniform()));
/// ```
#[derive(Debug, Clone)]
pub struct SplitMix {
    state: u64,
}

impl SplitMix {
    /// The stream whose state is `state` (its first draw is the one after it).
    pub fn new(state: u64) -> Self {
        Self { state }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform draw in `[0, 1)` (the top 53 bits of the next draw).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A standard normal draw (Box–Muller, from two uniform draws).
    pub fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first outputs of SplitMix64 seeded with 1234567, as an independent transcription
    /// of the reference C code (`splitmix64.c`, Vigna) computes them.
    #[test]
    fn the_stream_is_splitmix64() {
        let mut r = SplitMix::new(1234567);
        let first = [
            6457827717110365317u64,
            3203168211198807973,
            9817491932198370423,
        ];
        for expected in first {
            assert_eq!(r.next_u64(), expected);
        }
    }

    #[test]
    fn normal_draws_have_unit_variance() {
        let mut r = SplitMix::new(3);
        let draws: Vec<f64> = (0..20_000).map(|_| r.normal()).collect();
        let mean = draws.iter().sum::<f64>() / draws.len() as f64;
        let var = draws.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / draws.len() as f64;
        assert!(
            mean.abs() < 0.03 && (var - 1.0).abs() < 0.03,
            "{mean} {var}"
        );
    }
}
