//! Perfect mazes in the Moving AI format, for deep-field tests and benchmarks: one path between
//! any two cells, corridors one map cell wide between walls one cell thick (like the Moving AI
//! `maze512-1-*` maps), carved by a randomized depth-first search from a seed, so a maze is
//! the same every time.

use crate::random::SplitMix;

/// A `(2n + 1) × (2n + 1)` perfect maze of `n × n` rooms, padded with walls to `size × size`
/// when `size` is larger, as the text of a Moving AI `.map` (`type octile`). The rooms are the
/// cells at odd coordinates; the entrance room is `(1, 1)` in the text (the top left), so
/// routes run from corner to corner.
pub fn perfect_maze(n: usize, size: usize, seed: u64) -> String {
    let side = 2 * n + 1;
    let size = size.max(side);
    let mut open = vec![false; side * side];
    let mut rng = SplitMix::new(seed);
    let room = |i: usize, j: usize| (2 * j + 1) * side + 2 * i + 1;
    let mut stack = vec![(0usize, 0usize)];
    let mut visited = vec![false; n * n];
    visited[0] = true;
    open[room(0, 0)] = true;
    while let Some(&(i, j)) = stack.last() {
        let mut next = Vec::with_capacity(4);
        if i > 0 && !visited[j * n + i - 1] {
            next.push((i - 1, j));
        }
        if i + 1 < n && !visited[j * n + i + 1] {
            next.push((i + 1, j));
        }
        if j > 0 && !visited[(j - 1) * n + i] {
            next.push((i, j - 1));
        }
        if j + 1 < n && !visited[(j + 1) * n + i] {
            next.push((i, j + 1));
        }
        if next.is_empty() {
            stack.pop();
            continue;
        }
        let (a, b) = next[(rng.next_u64() % next.len() as u64) as usize];
        visited[b * n + a] = true;
        open[room(a, b)] = true;
        // The wall between the two rooms.
        open[(j + b + 1) * side + i + a + 1] = true;
        stack.push((a, b));
    }
    let mut text = format!("type octile\nheight {size}\nwidth {size}\nmap\n");
    for y in 0..size {
        for x in 0..size {
            let free = x < side && y < side && open[y * side + x];
            text.push(if free { '.' } else { '@' });
        }
        text.push('\n');
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every room is reachable and the passages form a tree: rooms − 1 openings between rooms.
    #[test]
    fn a_perfect_maze_connects_every_room_with_no_loop() {
        let n = 12;
        let text = perfect_maze(n, 26, 7);
        let m = super::super::movingai::parse(&text, std::path::Path::new("m.map"), 1.0).unwrap();
        assert_eq!((m.width, m.height), (26, 26));
        let free: usize = (0..m.height)
            .flat_map(|j| (0..m.width).map(move |i| (i, j)))
            .filter(|&(i, j)| !m.blocked(i, j))
            .count();
        // n² rooms and n² − 1 passages.
        assert_eq!(free, 2 * n * n - 1);
        assert_eq!(text, perfect_maze(n, 26, 7));
        assert_ne!(text, perfect_maze(n, 26, 8));
    }
}
