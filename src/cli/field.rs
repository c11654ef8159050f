//! `nadf field`: solve one agent's harmonic field and export it.

use std::path::PathBuf;

use super::{Failure, bad_input, load, write_all};
use crate::field::{HarmonicField, export};
use crate::output;
use crate::record::field_picture;
use crate::world::{FieldKind, Override};

/// The arguments of `nadf field`.
#[derive(Debug, Clone, clap::Args)]
pub struct FieldArgs {
    /// The world file (TOML).
    pub world: PathBuf,
    /// The agent whose field to solve [default: the first].
    #[arg(long)]
    pub agent: Option<String>,
    /// Write V as a float64 array of shape [nx, ny] (x index first) to this file, W = 1 - V
    /// to FILE.w.npy and the cell mask (0 reachable, 1 blocked, 2 unreachable) to
    /// FILE.mask.npy.
    #[arg(long, value_name = "FILE.npy")]
    pub npy: Option<PathBuf>,
    /// Write a picture of the field (log10(1 - V), streamlines, start, target).
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,
    /// Override a world value by dotted path (see `run`). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<Override>,
}

/// Solves the agent's field, prints how the solve went and writes the exports.
pub fn field(args: &FieldArgs) -> Result<(), Failure> {
    let path = &args.world;
    let world = load(path, &args.overrides)?;
    let agent = match &args.agent {
        Some(name) => world.agents.iter().find(|a| &a.name == name),
        None => world.agents.first(),
    };
    let Some(agent) = agent else {
        let names: Vec<&str> = world.agents.iter().map(|a| a.name.as_str()).collect();
        return Err(bad_input(
            path,
            format!(
                "no agent `{}`; the agents are: {}",
                args.agent.as_deref().unwrap_or_default(),
                names.join(", ")
            ),
        ));
    };
    let npy = args.npy.as_deref().map(export::npy_paths);
    let outputs = npy.iter().flatten().chain(&args.png);
    for out in outputs {
        output::check_file(out).map_err(|e| bad_input(path, e))?;
    }
    if world.field.kind != FieldKind::Harmonic {
        eprintln!(
            "note: {} guides its agents with field.kind = \"attractive-repulsive\"; this is the harmonic field of the same walls, for comparison",
            path.display()
        );
    }
    let field = HarmonicField::solve(&world, agent).map_err(|e| bad_input(path, e))?;
    let grid = field.grid();
    let counts = field.counts();
    println!(
        "field of {}: {} x {} cells of {} m ({} reachable, {} blocked, {} unreachable)",
        agent.name,
        grid.nx,
        grid.ny,
        grid.cell,
        counts.reachable,
        counts.blocked,
        counts.unreachable
    );
    println!(
        "solve: {:.1} ms, {} solve(s), {} CG iterations, relative residual {:.1e}",
        field.solve_time.as_secs_f64() * 1e3,
        field.solves,
        field.iterations,
        field.relative_residual
    );
    if field.nested.levels > 0 {
        println!(
            "nested: {} level(s), {} cells solved in {} part(s)",
            field.nested.levels, field.nested.cells_solved, field.nested.solves
        );
    }
    println!(
        "1 - V at the start: {}",
        scientific(field.log10_one_minus_potential(agent.start))
    );
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if let Some([v, w, log, mask]) = npy {
        files.push((v, export::potential_npy(&field)));
        files.push((w, export::one_minus_potential_npy(&field)));
        files.push((log, export::log10_one_minus_potential_npy(&field)));
        files.push((mask, export::mask_npy(&field)));
    }
    if let Some(png) = &args.png {
        let (rgb, width, height) = field_picture(&field, agent);
        files.push((png.clone(), export::png(&rgb, width, height)));
    }
    write_all(path, files)
}

/// `10^x` in scientific notation, for any `x` (`3.162e-7000`).
fn scientific(log10: f64) -> String {
    if !log10.is_finite() {
        return "0".into();
    }
    let exponent = log10.floor();
    let mantissa = 10f64.powf(log10 - exponent);
    // 9.9996 rounds to 10.000: carry into the exponent.
    let (mantissa, exponent) = if format!("{mantissa:.3}").starts_with("10") {
        (1.0, exponent + 1.0)
    } else {
        (mantissa, exponent)
    };
    format!("{mantissa:.3}e{exponent}")
}

#[cfg(test)]
mod tests {
    #[test]
    fn scientific_notation_reaches_below_f64() {
        assert_eq!(super::scientific(-7000.5), "3.162e-7001");
        assert_eq!(super::scientific(0.0), "1.000e0");
        assert_eq!(super::scientific(-5.00001), "1.000e-5");
        assert_eq!(super::scientific(f64::NEG_INFINITY), "0");
    }
}
