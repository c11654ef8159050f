//! Moving AI grid benchmarks (Sturtevant 2012): `.map` files (`type octile`, `height H`,
//! `width W`, `map`, then H rows of W characters; `.`, `G`, `S` passable, `@`, `O`, `T`, `W`
//! blocked) and their `.map.scen` scenario lists. CRLF line ends and a missing final newline
//! are accepted; rows are counted from the top of the map, so they are flipped to y-up here.

use std::path::Path;

use super::{CellState, MapError, Occupancy};

/// Reads a `.map` with `cell` metres per map cell, its origin at `[0, 0]`.
pub fn read(file: &Path, cell: f64) -> Result<Occupancy, MapError> {
    let text = std::fs::read(file)
        .map_err(|e| MapError::at(file, None, format!("cannot read the map: {e}")))?;
    let text = String::from_utf8_lossy(&text);
    parse(&text, file, cell)
}

/// Parses the text of a `.map`.
pub fn parse(text: &str, file: &Path, cell: f64) -> Result<Occupancy, MapError> {
    let error = |line: usize, column: usize, message: String| {
        MapError::at(file, Some((line, column)), message)
    };
    let mut lines = text
        .lines()
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .enumerate();
    let mut header = |expected: &str| -> Result<(usize, String), MapError> {
        match lines.next() {
            Some((n, line)) => {
                let mut words = line.split_whitespace();
                if words.next() != Some(expected) {
                    return Err(error(
                        n + 1,
                        1,
                        format!("expected `{expected}`, found `{line}`"),
                    ));
                }
                Ok((n + 1, words.collect::<Vec<_>>().join(" ")))
            }
            None => Err(error(
                text.lines().count() + 1,
                1,
                format!("the file ends before `{expected}`"),
            )),
        }
    };
    let (n, kind) = header("type")?;
    if kind != "octile" {
        return Err(error(
            n,
            6,
            format!("map type `{kind}`: only `octile` maps are read"),
        ));
    }
    let number = |(n, value): (usize, String), what: &str| -> Result<usize, MapError> {
        value
            .parse::<usize>()
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| {
                error(
                    n,
                    1,
                    format!("the {what} `{value}` is not a positive whole number"),
                )
            })
    };
    let height = number(header("height")?, "height")?;
    let width = number(header("width")?, "width")?;
    header("map")?;
    let mut cells = vec![CellState::Free; width * height];
    for row in 0..height {
        let Some((n, line)) = lines.next() else {
            return Err(error(
                text.lines().count() + 1,
                1,
                format!("the map has {row} rows, its header says height {height}"),
            ));
        };
        let chars: Vec<char> = line.chars().collect();
        if chars.len() < width {
            return Err(error(
                n + 1,
                chars.len() + 1,
                format!(
                    "row {} has {} cells, the header says width {width}",
                    row + 1,
                    chars.len()
                ),
            ));
        }
        if chars.len() > width && chars[width..].iter().any(|c| !c.is_whitespace()) {
            return Err(error(
                n + 1,
                width + 1,
                format!("row {} is longer than the width {width}", row + 1),
            ));
        }
        // The first row is the top of the map.
        let j = height - 1 - row;
        for (i, c) in chars[..width].iter().enumerate() {
            cells[j * width + i] = match c {
                '.' | 'G' | 'S' => CellState::Free,
                '@' | 'O' | 'T' | 'W' => CellState::Blocked,
                other => {
                    return Err(error(
                        n + 1,
                        i + 1,
                        format!(
                            "`{other}` is not a map cell (`.`, `G`, `S` passable; `@`, `O`, `T`, `W` blocked)"
                        ),
                    ));
                }
            };
        }
    }
    if let Some((n, extra)) = lines.find(|(_, l)| !l.trim().is_empty()) {
        return Err(error(
            n + 1,
            1,
            format!(
                "more rows than the height {height}: `{}`",
                extra.chars().take(20).collect::<String>()
            ),
        ));
    }
    Ok(Occupancy {
        file: file.to_path_buf(),
        width,
        height,
        cell,
        origin: [0.0, 0.0],
        cells,
        unknown_blocked: true,
    })
}

/// One Moving AI scenario: from a start cell to a goal cell, with the optimal octile length
/// (8-connected moves, no corner cutting).
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// The line in the `.scen` file.
    pub line: usize,
    /// The bucket (scenarios of similar length).
    pub bucket: u32,
    /// The map the scenario is for (its file name).
    pub map: String,
    /// The map's width and height, as the scenario gives them.
    pub size: [usize; 2],
    /// The start cell, x right and y down from the top row.
    pub start: [usize; 2],
    /// The goal cell, x right and y down from the top row.
    pub goal: [usize; 2],
    /// The optimal length, in map cells.
    pub optimal: f64,
}

/// Reads a `.map.scen` file (`version 1`, then one tab-separated scenario per line).
pub fn read_scenarios(file: &Path) -> Result<Vec<Scenario>, MapError> {
    let text = std::fs::read(file)
        .map_err(|e| MapError::at(file, None, format!("cannot read the scenarios: {e}")))?;
    let text = String::from_utf8_lossy(&text);
    let mut scenarios = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.strip_suffix('\r').unwrap_or(line);
        if line.trim().is_empty() || (n == 0 && line.starts_with("version")) {
            continue;
        }
        let fields: Vec<&str> = line.split('\t').collect();
        let bad = |what: &str| {
            MapError::at(
                file,
                Some((n + 1, 1)),
                format!(
                    "{what}: a scenario is `bucket map width height start_x start_y goal_x goal_y optimal`, tab-separated"
                ),
            )
        };
        if fields.len() != 9 {
            return Err(bad(&format!("{} fields", fields.len())));
        }
        let whole = |k: usize| {
            fields[k].trim().parse::<usize>().map_err(|_| {
                bad(&format!(
                    "field {} `{}` is not a whole number",
                    k + 1,
                    fields[k]
                ))
            })
        };
        let optimal: f64 = fields[8]
            .trim()
            .parse()
            .ok()
            .filter(|x: &f64| x.is_finite() && *x >= 0.0)
            .ok_or_else(|| {
                bad(&format!(
                    "the optimal length `{}` is not a number",
                    fields[8]
                ))
            })?;
        scenarios.push(Scenario {
            line: n + 1,
            bucket: u32::try_from(whole(0)?).map_err(|_| bad("the bucket is too large"))?,
            map: fields[1]
                .rsplit(['/', '\\'])
                .next()
                .unwrap_or(fields[1])
                .to_string(),
            size: [whole(2)?, whole(3)?],
            start: [whole(4)?, whole(5)?],
            goal: [whole(6)?, whole(7)?],
            optimal,
        });
    }
    Ok(scenarios)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ARENA: &str = "type octile\r\nheight 3\r\nwidth 4\r\nmap\r\n@@@@\r\n@.G@\r\n@TS.";

    #[test]
    fn a_map_reads_with_crlf_and_no_final_newline_and_flips_to_y_up() {
        let m = parse(ARENA, Path::new("a.map"), 2.0).unwrap();
        assert_eq!((m.width, m.height, m.cell), (4, 3, 2.0));
        // The first row is the top (j = 2); the last row is the bottom (j = 0).
        assert!((0..4).all(|i| m.blocked(i, 2)));
        assert!(!m.blocked(1, 1) && !m.blocked(2, 1) && m.blocked(0, 1));
        assert!(m.blocked(1, 0) && !m.blocked(2, 0) && !m.blocked(3, 0));
    }

    #[test]
    fn malformed_maps_are_located_errors() {
        let short = "type octile\nheight 3\nwidth 4\nmap\n@@@@\n@.@\n@@@@\n";
        let e = parse(short, Path::new("s.map"), 1.0).unwrap_err();
        assert_eq!(e.location, Some((6, 4)));
        assert!(e.message.contains("row 2 has 3 cells"), "{e}");
        let missing = "type octile\nheight 3\nwidth 4\nmap\n@@@@\n";
        let e = parse(missing, Path::new("m.map"), 1.0).unwrap_err();
        assert!(e.message.contains("has 1 rows"), "{e}");
        let odd = "type octile\nheight 1\nwidth 2\nmap\n@x\n";
        let e = parse(odd, Path::new("o.map"), 1.0).unwrap_err();
        assert_eq!(e.location, Some((5, 2)));
        assert!(
            e.to_string()
                .starts_with("o.map:5:2: `x` is not a map cell"),
            "{e}"
        );
        let e = parse("type tile\n", Path::new("t.map"), 1.0).unwrap_err();
        assert!(e.message.contains("only `octile`"), "{e}");
        let e = parse("type octile\nheight -3\n", Path::new("h.map"), 1.0).unwrap_err();
        assert!(e.message.contains("height `-3`"), "{e}");
    }
}
