//! The kinematic path: the streamline of `ẋ = -∇V/|∇V|` (eq. 4, normalized) from a start point.
//! It is the path the dynamic trajectory should follow; `δ_m` is measured against it.

use nalgebra::Vector2;

use super::sample::Sampler;

/// A polyline from the start towards the target.
#[derive(Debug, Clone, PartialEq)]
pub struct Streamline {
    /// Points along the path, m, starting at the start point.
    pub points: Vec<[f64; 2]>,
    /// Whether the path came within one cell of the target.
    pub reached: bool,
}

/// Integrates the streamline with the midpoint rule at steps of half a cell until it is within
/// one cell of `target`, the guidance vanishes, or it has walked `max_length` metres.
pub fn streamline(
    sampler: &Sampler,
    start: [f64; 2],
    target: [f64; 2],
    max_length: f64,
) -> Streamline {
    let cell = sampler.grid().cell;
    // ∇W = -∇V: the direction of descent, at the cells' scale (its size does not matter).
    integrate(
        |p| sampler.grad_w_scaled(p).map(|(g, _)| g),
        start,
        target,
        0.5 * cell,
        cell,
        max_length,
    )
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
        let p = Vector2::from(p);
        if self.points.len() == 1 {
            return (p - Vector2::from(self.points[0])).norm();
        }
        self.points
            .windows(2)
            .map(|s| {
                let (a, b) = (Vector2::from(s[0]), Vector2::from(s[1]));
                let ab = b - a;
                let t =
                    ((p - a).dot(&ab) / ab.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
                (p - (a + ab * t)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Length of the polyline, m.
    pub fn length(&self) -> f64 {
        self.points
            .windows(2)
            .map(|s| (s[1][0] - s[0][0]).hypot(s[1][1] - s[0][1]))
            .sum()
    }
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
