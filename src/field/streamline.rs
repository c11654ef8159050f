//! The kinematic path: the streamline of `ẋ = -∇V/|∇V|` (eq. 4, normalized) from a start point.
//! It is the path the dynamic trajectory should follow; `δ_m` is measured against it.

use nalgebra::Vector2;

use super::segment_tree::SegmentTree;

/// A polyline from the start towards the target.
#[derive(Debug, Clone, PartialEq)]
pub struct Streamline {
    /// Points along the path, m, starting at the start point.
    pub points: Vec<[f64; 2]>,
    /// Whether the path came within one cell of the target.
    pub reached: bool,
}

/// Integrates `ẋ = f(x)/|f(x)|` with the midpoint rule at steps of `h` metres from `start` until
/// it is within `close` of `target` (reached), `f` vanishes or is undefined, the direction
/// reverses from one step to the next (a local minimum or a saddle: the path would only bounce
/// there), or it has walked `max_length` metres.
pub fn integrate(
    f: impl Fn([f64; 2]) -> Option<Vector2<f64>>,
    start: [f64; 2],
    target: [f64; 2],
    h: f64,
    close: f64,
    max_length: f64,
) -> Streamline {
    let direction = |p: [f64; 2]| -> Option<Vector2<f64>> {
        let g = f(p)?;
        let n = g.norm();
        (n > 0.0 && n.is_finite()).then(|| g / n)
    };
    let mut points = vec![start];
    let mut p = start;
    let mut walked = 0.0;
    let mut last: Option<Vector2<f64>> = None;
    let reached = loop {
        if (p[0] - target[0]).hypot(p[1] - target[1]) <= close {
            break true;
        }
        if walked > max_length {
            break false;
        }
        let Some(d1) = direction(p) else { break false };
        let mid = [p[0] + 0.5 * h * d1.x, p[1] + 0.5 * h * d1.y];
        let Some(d2) = direction(mid) else {
            break false;
        };
        if last.is_some_and(|l| l.dot(&d2) < 0.0) {
            break false;
        }
        last = Some(d2);
        p = [p[0] + h * d2.x, p[1] + h * d2.y];
        walked += h;
        points.push(p);
    };
    Streamline { points, reached }
}

impl Streamline {
    /// Distance from `p` to the polyline, m.
    pub fn distance_to(&self, p: [f64; 2]) -> f64 {
        polyline_distance(&self.points, p)
    }

    /// The largest distance from any of `points` to the polyline, m (0 for none): `δ_m` of a
    /// path. The same value as [`Streamline::distance_to`] at every point, but a long run
    /// against a long path (300,000 states against 44,000 segments through a maze) finds each
    /// point's nearest segments in a tree of the path's runs (`segment_tree.rs`).
    ///
    /// The distance to the polyline moves by at most as far as the point does (it is
    /// 1-Lipschitz), so a point nearer to the last one measured than that one's distance falls
    /// short of the largest so far is skipped: it cannot exceed it. The states of a run are a
    /// step apart, so most are: a crowd's summary no longer measures every state of every
    /// robot, metres off its path, ring by ring. The result is the scan's to the bit: a point
    /// is skipped only with a nanometre to spare, far above the rounding of a distance.
    pub fn max_distance(&self, points: &[[f64; 2]]) -> f64 {
        let tree =
            (self.points.len() >= 64 && points.len() >= 64).then(|| SegmentTree::new(&self.points));
        let measure = |p: &[f64; 2]| match &tree {
            Some(tree) => {
                let q = Vector2::from(*p);
                tree.nearest(*p, |s| self.segment_distance(s, q))
            }
            None => self.distance_to(*p),
        };
        let mut max = 0.0_f64;
        let mut last: Option<([f64; 2], f64)> = None;
        for p in points {
            if let Some((a, d)) = last
                && d + (p[0] - a[0]).hypot(p[1] - a[1]) + 1e-9 <= max
            {
                continue;
            }
            let d = measure(p);
            max = max.max(d);
            last = Some((*p, d));
        }
        max
    }

    /// Distance from `p` to segment `s` (from point `s` to point `s + 1`), m.
    fn segment_distance(&self, s: usize, p: Vector2<f64>) -> f64 {
        segment_distance(self.points[s], self.points[s + 1], p)
    }

    /// Length of the polyline, m.
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|s| (s[1][0] - s[0][0]).hypot(s[1][1] - s[0][1]))
            .sum()
    }
}

/// Distance from `p` to the polyline through `points`, m: to the point itself for one point,
/// infinite for none.
pub(super) fn polyline_distance(points: &[[f64; 2]], p: [f64; 2]) -> f64 {
    let p = Vector2::from(p);
    match points {
        [] => f64::INFINITY,
        [a] => (p - Vector2::from(*a)).norm(),
        // The least squared distance, square-rooted once: the same value as the least of the
        // segments' distances (the square root rounds monotonically), without a square root
        // per segment, which was 3 % of the time of 128 robots yielding to each other.
        _ => (points.windows(2))
            .map(|s| segment_distance_squared(s[0], s[1], p))
            .fold(f64::INFINITY, f64::min)
            .sqrt(),
    }
}

/// Distance from `p` to the segment from `a` to `b`, m.
pub(super) fn segment_distance(a: [f64; 2], b: [f64; 2], p: Vector2<f64>) -> f64 {
    segment_distance_squared(a, b, p).sqrt()
}

/// The square of [`segment_distance`], m².
fn segment_distance_squared(a: [f64; 2], b: [f64; 2], p: Vector2<f64>) -> f64 {
    let (a, b) = (Vector2::from(a), Vector2::from(b));
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm_squared()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_to_a_polyline_uses_the_nearest_segment() {
        let s = Streamline {
            points: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
            reached: true,
        };
        assert!((s.distance_to([0.5, 0.2]) - 0.2).abs() < 1e-12);
        assert!((s.distance_to([1.3, 0.5]) - 0.3).abs() < 1e-12);
        assert!((s.distance_to([-1.0, 0.0]) - 1.0).abs() < 1e-12);
        assert!((s.length() - 2.0).abs() < 1e-12);
    }
}

#[cfg(test)]
mod index {
    use super::*;

    /// A long winding path against points all around it: the tree's search gives every
    /// point's distance to the bit, so `δ_m` too.
    #[test]
    fn the_tree_searched_distance_is_the_scanned_one() {
        let points: Vec<[f64; 2]> = (0..3000)
            .map(|k| {
                let t = k as f64 * 0.01;
                [t * 3.0 + (7.0 * t).sin(), 2.0 * (3.0 * t).cos() + 0.3 * t]
            })
            .collect();
        let line = Streamline {
            points,
            reached: true,
        };
        let probes: Vec<[f64; 2]> = (0..4000)
            .map(|k| [-5.0 + (k % 80) as f64 * 1.4, -6.0 + (k / 80) as f64 * 0.37])
            .collect();
        let tree = SegmentTree::new(&line.points);
        for p in &probes {
            let scan = line.distance_to(*p);
            let q = Vector2::from(*p);
            let fast = tree.nearest(*p, |s| line.segment_distance(s, q));
            assert_eq!(scan.to_bits(), fast.to_bits(), "at {p:?}");
        }
        let scanned = probes
            .iter()
            .map(|p| line.distance_to(*p))
            .fold(0.0, f64::max);
        assert_eq!(line.max_distance(&probes), scanned);
    }

    /// A run's states a step apart, wandering off the path and back: the points skipped (no
    /// farther than the last one measured) change nothing, to the bit.
    #[test]
    fn skipping_the_states_near_the_last_measured_changes_nothing() {
        let line = Streamline {
            points: (0..500).map(|k| [k as f64 * 0.05, 0.0]).collect(),
            reached: true,
        };
        let run: Vec<[f64; 2]> = (0..20_000)
            .map(|k| {
                let t = k as f64 * 0.001;
                [t * 1.2 - 1.0, 3.0 * (0.7 * t).sin() * (0.13 * t).cos()]
            })
            .collect();
        let scanned = run.iter().map(|p| line.distance_to(*p)).fold(0.0, f64::max);
        assert!(scanned > 2.0, "{scanned}");
        assert_eq!(line.max_distance(&run).to_bits(), scanned.to_bits());
        for n in [1, 2, 63, 64, 65, 1000] {
            let scanned = run[..n]
                .iter()
                .map(|p| line.distance_to(*p))
                .fold(0.0, f64::max);
            assert_eq!(
                line.max_distance(&run[..n]).to_bits(),
                scanned.to_bits(),
                "{n}"
            );
        }
    }
}
