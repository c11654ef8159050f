//! Property tests of the loader and validator: arbitrary text, mutated world files and hostile
//! values never panic; every rejection is an error value that names the file.

mod common;

use std::path::Path;

use nadf::field::FreeSpace;
use nadf::world::{Override, World, load_str};
use proptest::prelude::*;

/// The shipped worlds' texts.
fn shipped() -> Vec<String> {
    let mut texts: Vec<String> = std::fs::read_dir(common::world_path(""))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    texts.sort();
    texts
}

/// Fragments that make TOML and world files go wrong in interesting ways.
const TOKENS: &[&str] = &[
    "=",
    "[",
    "]",
    "[[",
    "]]",
    "\"",
    "'",
    ",",
    "\n",
    "#",
    ".",
    "-",
    "nan",
    "inf",
    "-inf",
    "0",
    "-1",
    "1e400",
    "1e-400",
    "1e40",
    "true",
    "\"box\"",
    "\"polygon\"",
    "shape",
    "[[walls]]",
    "[[agents]]",
    "[agents.controller]",
    "[field]",
    "[expect]",
    "mass",
    "radius",
    "cell",
    "points",
    "[[0.0, 0.0], [1.0, 0.0]]",
    "{}",
    "\u{0}",
    "é",
    "9999999999999999999999",
];

/// Loads `text` and, when it is valid and small, builds every agent's configuration space.
fn exercise(text: &str, overrides: &[Override]) {
    match load_str(text, Path::new("fuzz.toml"), overrides) {
        Ok(world) => free_spaces(&world),
        Err(errors) => {
            assert!(!errors.0.is_empty());
            for e in &errors.0 {
                assert_eq!(e.file, Path::new("fuzz.toml"));
                assert!(!e.message.is_empty());
            }
        }
    }
}

fn free_spaces(world: &World) {
    let cells = (world.size[0] / world.field.cell) * (world.size[1] / world.field.cell);
    if cells < 200_000.0 {
        for agent in &world.agents {
            let _ = FreeSpace::of(world, agent);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_text_never_panics(text in any::<String>()) {
        exercise(&text, &[]);
    }

    #[test]
    fn mutated_worlds_never_panic(
        world in 0usize..16,
        edits in prop::collection::vec((any::<prop::sample::Index>(), 0usize..3, 0usize..TOKENS.len(), 0usize..12), 1..6),
    ) {
        let texts = shipped();
        let mut text = texts[world % texts.len()].clone().into_bytes();
        for (at, kind, token, len) in edits {
            let i = at.index(text.len() + 1);
            match kind {
                // Insert a token.
                0 => { text.splice(i..i, TOKENS[token].bytes()); }
                // Delete a run of bytes.
                1 => { let end = (i + len).min(text.len()); text.drain(i..end); }
                // Replace a run of bytes with a token.
                _ => { let end = (i + len).min(text.len()); text.splice(i..end, TOKENS[token].bytes()); }
            }
        }
        exercise(&String::from_utf8_lossy(&text), &[]);
    }

    #[test]
    fn hostile_overrides_never_panic(
        key in prop::sample::select(vec![
            "size.0", "dt", "duration", "field.cell", "field.tolerance", "walls.0.center.1",
            "walls.0.half_extents.0", "walls.0.angle", "agents.0.start.0", "agents.0.target.1",
            "agents.0.radius", "agents.0.mass", "agents.0.controller.k", "agents.0.controller.b",
            "agents.0.controller.capture_radius", "expect.min_clearance", "agents.1.name",
            "walls.7.radius", "seed", "agents.0.controller.kind",
        ]),
        value in prop::sample::select(vec![
            "nan", "inf", "-inf", "0", "-1", "1e300", "1e-300", "\"x\"", "[1, 2, 3]", "true",
            "-9223372036854775808", "viscous", "{ a = 1 }",
        ]),
    ) {
        let text = std::fs::read_to_string(common::world_path("room-two-dividers.toml")).unwrap();
        let o: Override = format!("{key}={value}").parse().unwrap();
        exercise(&text, &[o]);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Every fixed-length array (positions, sizes, extents, accelerations) rejects any other
    /// length with an error that names it; none is cut to length or padded.
    #[test]
    fn fixed_length_arrays_reject_every_other_length(
        key in prop::sample::select(vec![
            "size", "external_acceleration", "walls.0.center", "walls.0.half_extents",
            "agents.0.start", "agents.0.target", "agents.0.initial_velocity", "origin",
        ]),
        len in prop_oneof![0usize..2, 3usize..6],
    ) {
        let text = std::fs::read_to_string(common::world_path("room-two-dividers.toml")).unwrap();
        let items: Vec<String> = (0..len).map(|i| format!("{}.5", i + 1)).collect();
        let o: Override = format!("{key}=[{}]", items.join(", ")).parse().unwrap();
        let errors = load_str(&text, Path::new("fuzz.toml"), &[o]).unwrap_err();
        let message = errors.to_string();
        prop_assert!(message.contains(key), "{}", message);
        prop_assert!(
            message.contains(&format!("exactly 2 numbers, got {len}"))
                || (len == 0 && message.contains("got 0")),
            "{}",
            message
        );
    }
}
