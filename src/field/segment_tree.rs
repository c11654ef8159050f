//! The nearest segment of a polyline to a point, for `δ_m` of a long run against a long path:
//! the segments in a binary tree of runs of consecutive segments, each node holding its run's
//! bounding box, searched nearest box first and pruned by the distance to a box.
//!
//! Why a tree and not buckets of a grid: a state metres off the path (a robot going round a
//! crowd) searched bucket by bucket visits every empty bucket within its distance, `(2d / s)²`
//! of them for buckets of side `s`; the tree reaches the nearest segments in about `log n` boxes
//! however far the point is. (128 robots on a circle spent 53 s of a 328 s run, on one thread,
//! measuring their `δ_m` ring by ring.)
//!
//! The distances are whatever the caller measures, and a box is pruned only when it is farther
//! than the best distance so far with a nanometre to spare, so the minimum is exactly the one a
//! scan of every segment finds.

/// Segments in a leaf: a run short enough that measuring them all costs less than more boxes.
const LEAF: usize = 8;

/// A box is pruned only when it is this much farther than the best distance so far, m: far
/// above the rounding of a distance, so no segment as near as the best is ever skipped.
const SPARE: f64 = 1e-9;

/// A polyline's segments (segment `k` from point `k` to point `k + 1`) in a tree of runs.
#[derive(Debug, Clone)]
pub(super) struct SegmentTree {
    /// The nodes, the root first.
    nodes: Vec<Node>,
}

/// A run of consecutive segments and its bounding box.
#[derive(Debug, Clone)]
struct Node {
    /// `[x0, y0, x1, y1]`.
    bounds: [f64; 4],
    /// The run's segments, `start..end`.
    start: usize,
    end: usize,
    /// The two halves of the run (node indices), or `None` for a leaf.
    halves: Option<[usize; 2]>,
}

impl SegmentTree {
    /// The tree of the segments of the polyline through `points` (none for fewer than two).
    pub(super) fn new(points: &[[f64; 2]]) -> Self {
        let mut tree = Self { nodes: Vec::new() };
        let segments = points.len().saturating_sub(1);
        if segments > 0 {
            tree.build(points, 0, segments);
        }
        tree
    }

    /// Adds the node of segments `start..end` and its halves; returns its index.
    fn build(&mut self, points: &[[f64; 2]], start: usize, end: usize) -> usize {
        let index = self.nodes.len();
        let mut bounds = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for p in &points[start..=end] {
            bounds = [
                bounds[0].min(p[0]),
                bounds[1].min(p[1]),
                bounds[2].max(p[0]),
                bounds[3].max(p[1]),
            ];
        }
        self.nodes.push(Node {
            bounds,
            start,
            end,
            halves: None,
        });
        if end - start > LEAF {
            let middle = start + (end - start) / 2;
            let first = self.build(points, start, middle);
            let second = self.build(points, middle, end);
            self.nodes[index].halves = Some([first, second]);
        }
        index
    }

    /// The smallest `distance(k)` over the segments `k`, for a point at `p`: `distance` must
    /// be at least the distance from `p` to segment `k`'s bounding box (the distance from `p`
    /// to the segment is). Infinite for no segments.
    pub(super) fn nearest(&self, p: [f64; 2], distance: impl Fn(usize) -> f64) -> f64 {
        let mut best = f64::INFINITY;
        let mut stack = Vec::with_capacity(64);
        if !self.nodes.is_empty() {
            stack.push(0);
        }
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if box_distance(&node.bounds, p) - SPARE > best {
                continue;
            }
            match node.halves {
                None => {
                    for k in node.start..node.end {
                        best = best.min(distance(k));
                    }
                }
                // The nearer half is searched first (pushed last), so that the farther one is
                // more often pruned.
                Some([a, b]) => {
                    let (da, db) = (
                        box_distance(&self.nodes[a].bounds, p),
                        box_distance(&self.nodes[b].bounds, p),
                    );
                    if da <= db {
                        stack.extend([b, a]);
                    } else {
                        stack.extend([a, b]);
                    }
                }
            }
        }
        best
    }
}

/// Distance from `p` to the box `[x0, y0, x1, y1]`, m (0 inside it).
fn box_distance(b: &[f64; 4], p: [f64; 2]) -> f64 {
    let dx = (b[0] - p[0]).max(p[0] - b[2]).max(0.0);
    let dy = (b[1] - p[1]).max(p[1] - b[3]).max(0.0);
    dx.hypot(dy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::streamline::segment_distance;
    use nalgebra::Vector2;

    /// Distance from `p` to the segment from `a` to `b` (the path's own measure).
    fn to_segment(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
        segment_distance(a, b, Vector2::from(p))
    }

    /// A long winding path that crosses itself, against points on it, near it and tens of
    /// metres off it: the tree's minimum is the scan's to the bit, and it measures far fewer
    /// segments than the scan.
    #[test]
    fn the_nearest_segment_is_the_scanned_one_to_the_bit() {
        let points: Vec<[f64; 2]> = (0..5000)
            .map(|k| {
                let t = k as f64 * 0.01;
                [
                    t * 2.0 + 3.0 * (1.3 * t).sin(),
                    4.0 * (0.9 * t).cos() + 0.2 * t,
                ]
            })
            .collect();
        let tree = SegmentTree::new(&points);
        let mut measured = 0;
        for k in 0..3000 {
            let p = [-40.0 + (k % 60) as f64 * 3.1, -30.0 + (k / 60) as f64 * 1.3];
            let distance = |s: usize| to_segment(points[s], points[s + 1], p);
            let scanned = (0..points.len() - 1)
                .map(distance)
                .fold(f64::INFINITY, f64::min);
            let counted = std::cell::Cell::new(0);
            let found = tree.nearest(p, |s| {
                counted.set(counted.get() + 1);
                distance(s)
            });
            assert_eq!(found.to_bits(), scanned.to_bits(), "at {p:?}");
            measured += counted.get();
        }
        let average = measured as f64 / 3000.0;
        assert!(average < 200.0, "{average} segments measured a point");
    }

    /// No segments: infinitely far; one segment: its distance.
    #[test]
    fn a_path_of_one_point_has_no_segments() {
        assert_eq!(
            SegmentTree::new(&[[1.0, 2.0]]).nearest([0.0, 0.0], |_| 0.0),
            f64::INFINITY
        );
        let tree = SegmentTree::new(&[[0.0, 0.0], [2.0, 0.0]]);
        assert_eq!(
            tree.nearest([1.0, 3.0], |_| to_segment(
                [0.0, 0.0],
                [2.0, 0.0],
                [1.0, 3.0]
            )),
            3.0
        );
    }
}
