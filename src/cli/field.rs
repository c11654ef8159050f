//! `nadf field`: solve one agent's (or arm's) harmonic field and export it.

use std::path::PathBuf;

use super::{Failure, bad_input, load, write_all};
use crate::field::export::FieldArray;
use crate::field::{HarmonicField, PoseField, export};
use crate::output::{self, Contents};
use crate::record::field_picture;
use crate::world::{BodyShape, FieldKind, Override};

/// The arguments of `nadf field`.
#[derive(Debug, Clone, clap::Args)]
pub struct FieldArgs {
    /// The world file (TOML).
    pub world: PathBuf,
    /// The agent or arm whose field to solve [default: the first agent, or the first arm in a
    /// world without agents].
    #[arg(long)]
    pub agent: Option<String>,
    /// Write V as a float64 array of shape [nx, ny] (x index first; [nx, ny, headings] for a
    /// shaped agent; one axis per joint for an arm) to this file, W = 1 - V to FILE.w.npy,
    /// log10 W to FILE.log10w.npy and the cell mask (0 reachable, 1 blocked, 2 unreachable) to
    /// FILE.mask.npy.
    #[arg(long, value_name = "FILE.npy")]
    pub npy: Option<PathBuf>,
    /// Write a picture of the field (log10(1 - V), streamlines, start, target; for a shaped
    /// agent, the slice of its (x, y, θ) field at its start heading; for an arm its joint space,
    /// the slice through its first joint's start angle for three links).
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
    let everyone = || world.agents.iter().chain(&world.shaped);
    let agent = match &args.agent {
        Some(name) => everyone().find(|a| &a.name == name),
        None => everyone().next(),
    };
    let arm = match (&args.agent, agent) {
        (Some(name), None) => world.arms.iter().find(|a| &a.name == name),
        (None, None) => world.arms.first(),
        (_, Some(_)) => None,
    };
    let npy = args.npy.as_deref().map(export::npy_paths);
    if agent.is_some() || arm.is_some() {
        let outputs = npy.iter().flatten().chain(&args.png);
        for out in outputs {
            output::check_file(out).map_err(|e| bad_input(path, e))?;
        }
    }
    if let Some(arm) = arm {
        return arm_field(path, &world, arm, npy, args.png.as_deref());
    }
    let Some(agent) = agent else {
        let names: Vec<&str> = (everyone().map(|a| a.name.as_str()))
            .chain(world.arms.iter().map(|a| a.name.as_str()))
            .collect();
        return Err(bad_input(
            path,
            match &args.agent {
                Some(name) => format!(
                    "no agent or arm `{name}`; the world has: {}",
                    names.join(", ")
                ),
                None => "the world has no agent and no arm: no field to solve".to_string(),
            },
        ));
    };
    if agent.is_shaped() {
        return pose_field(path, &world, agent, npy, args.png.as_deref());
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
    say!(
        "field of {}: {} x {} cells of {} m ({} reachable, {} blocked, {} unreachable)",
        agent.name,
        grid.nx,
        grid.ny,
        grid.cell,
        counts.reachable,
        counts.blocked,
        counts.unreachable
    );
    say!(
        "solve: {:.1} ms, {} solve(s), {} CG iterations, relative residual {:.1e}",
        field.solve_time.as_secs_f64() * 1e3,
        field.solves,
        field.iterations,
        field.relative_residual
    );
    if field.first_on_box {
        say!(
            "first solve: on the {} unknown cells of a box around the target",
            field.first_cells
        );
    }
    if field.nested.levels > 0 {
        say!(
            "nested: {} level(s), {} cells solved in {} part(s)",
            field.nested.levels,
            field.nested.cells_solved,
            field.nested.solves
        );
    }
    say!(
        "1 - V at the start: {}",
        scientific(field.log10_one_minus_potential(agent.start))
    );
    let mut files: Vec<(PathBuf, Contents)> = Vec::new();
    if let Some(paths) = npy {
        // Each array written a few columns at a time as its file goes out (see `write_all`).
        let field = &field;
        files.extend(paths.into_iter().zip(FieldArray::ALL).map(|(path, array)| {
            let write = move |out: &mut dyn std::io::Write| export::write_array(field, array, out);
            (path, Contents::Stream(Box::new(write)))
        }));
    }
    if let Some(png) = &args.png {
        let (rgb, width, height) = field_picture(&field, agent);
        files.push((png.clone(), export::png(&rgb, width, height).into()));
    }
    write_all(path, files)
}

/// `nadf field` for a shaped agent: its (x, y, θ) field, the arrays `[nx, ny, headings]`, and
/// the picture of the slice at its start heading.
fn pose_field(
    path: &std::path::Path,
    world: &crate::world::World,
    agent: &crate::world::Agent,
    npy: Option<[PathBuf; 4]>,
    png: Option<&std::path::Path>,
) -> Result<(), Failure> {
    let shape = BodyShape::of_agent(agent)
        .map_err(|e| bad_input(path, e))?
        .expect("a shaped agent");
    let inertia = agent.inertia.unwrap_or_else(|| shape.inertia(agent.mass));
    let rho = (inertia / agent.mass).sqrt();
    let field = PoseField::solve(world, agent, &shape, rho).map_err(|e| bad_input(path, e))?;
    let (grid, d) = (field.grid(), field.dims());
    let reachable = field.reachable.iter().filter(|r| **r).count();
    let blocked = field.mask.blocked.iter().filter(|b| **b).count();
    say!(
        "field of {}: {} x {} cells of {} m x {} headings ({reachable} reachable, {blocked} blocked, {} unreachable); ρ = {rho:.4} m",
        agent.name,
        grid.nx,
        grid.ny,
        grid.cell,
        d.nt,
        d.len() - reachable - blocked
    );
    say!(
        "mask: {:.1} ms (margin {:.4} m); solve: {:.1} ms, {} solve(s), {} CG iterations, relative residual {:.1e}",
        field.mask_time.as_secs_f64() * 1e3,
        field.mask.margin,
        field.solve_time.as_secs_f64() * 1e3,
        field.solves,
        field.iterations,
        field.relative_residual
    );
    let start = [agent.start[0], agent.start[1], agent.heading];
    say!(
        "1 - V at the start: {}",
        scientific(field.log10_one_minus_potential(start))
    );
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if let Some(paths) = npy {
        files.extend(paths.into_iter().zip(export::pose_arrays(&field)));
    }
    if let Some(png) = png {
        let deepest = crate::record::deepest(&field);
        let (rgb, [w, h]) = crate::record::pose_slice_image(&field, agent.heading, deepest);
        // Row 0 of the image is the grid's bottom row: flipped so that y is up in the picture.
        let row = 3 * w as usize;
        let flipped: Vec<u8> = rgb.chunks(row).rev().flatten().copied().collect();
        files.push((png.to_path_buf(), export::png(&flipped, w, h)));
    }
    write_all(path, files)
}

/// `nadf field` for an arm: its joint-space field, the arrays with one axis per joint, and the
/// picture of its joint space (for three links, the slice through the first joint's start
/// angle), the second of the pictured joints up.
fn arm_field(
    path: &std::path::Path,
    world: &crate::world::World,
    arm: &crate::world::ArmSettings,
    npy: Option<[PathBuf; 4]>,
    png: Option<&std::path::Path>,
) -> Result<(), Failure> {
    let walls = crate::world::all_wall_shapes(world);
    let (field, mask_time) =
        crate::sim::arm_run::solve_field(world, arm, &walls).map_err(|e| bad_input(path, e))?;
    let cells: Vec<String> = (field.mask.axes.iter())
        .map(|a| a.cells.to_string())
        .collect();
    let reachable = field.reachable.iter().filter(|r| **r).count();
    let blocked = field.mask.blocked.iter().filter(|b| **b).count();
    say!(
        "field of {}: {} joint cells ({reachable} reachable, {blocked} blocked, {} unreachable, {} in the target set)",
        arm.name,
        cells.join(" x "),
        field.reachable.len() - reachable - blocked,
        field.target_cells.len()
    );
    say!(
        "mask: {:.1} ms; solve: {:.1} ms, {} solve(s), {} CG iterations, relative residual {:.1e}",
        mask_time.as_secs_f64() * 1e3,
        field.solve_time.as_secs_f64() * 1e3,
        field.solves,
        field.iterations,
        field.relative_residual
    );
    say!(
        "1 - V at the start: {}",
        scientific(field.log10_one_minus_potential(&arm.start))
    );
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    if let Some(paths) = npy {
        files.extend(paths.into_iter().zip(export::joint_arrays(&field)));
    }
    if let Some(png) = png {
        let slice = field.mask.axes[0].cell_of(arm.start[0]).unwrap_or(0);
        let deepest = crate::record::joint_deepest(&field);
        let (rgb, [w, h]) = crate::record::joint_image(&field, slice, deepest);
        // Row 0 of the image is the second joint's first cell: flipped so that it grows up,
        // and each cell drawn as a square of pixels, so that the picture is about 512 wide.
        let scale = (512 / w.max(h)).max(1) as usize;
        let (wide, high) = (w as usize * scale, h as usize * scale);
        let mut picture = Vec::with_capacity(wide * high * 3);
        for y in 0..high {
            let j = h as usize - 1 - y / scale;
            for x in 0..wide {
                let at = 3 * (j * w as usize + x / scale);
                picture.extend_from_slice(&rgb[at..at + 3]);
            }
        }
        files.push((
            png.to_path_buf(),
            export::png(&picture, wide as u32, high as u32),
        ));
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
