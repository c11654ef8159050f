//! The picture of a scenario batch: the share of scenarios reached, and the path length over
//! the optimal one, against the optimal length, per bucket of ten metres of it (the runs as
//! dots, the bucket's mean as a line).

use std::collections::BTreeMap;

use plotters::prelude::*;

use super::Outcome;
use crate::chart::{PALETTE, padded, register_font};

/// Picture size, pixels.
const SIZE: (u32, u32) = (900, 800);

/// The batch's plot as PNG bytes, titled `title`.
pub fn plot(outcomes: &[Outcome], title: &str) -> Result<Vec<u8>, String> {
    register_font();
    let runs: Vec<&Outcome> = outcomes.iter().filter(|o| o.summary.is_ok()).collect();
    // Optimal length, binned: reached share and mean path ratio per bin.
    let width = bin_width(&runs);
    let mut bins: BTreeMap<i64, (usize, usize, Vec<f64>)> = BTreeMap::new();
    for o in &runs {
        let bin = bins.entry((o.optimal / width).floor() as i64).or_default();
        bin.0 += 1;
        if let Some(r) = o.path_ratio() {
            bin.1 += 1;
            bin.2.push(r);
        }
    }
    let centre = |b: i64| (b as f64 + 0.5) * width;
    let (x0, x1) = padded(0.0, runs.iter().map(|o| o.optimal).fold(1.0, f64::max));
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(title, ("sans-serif", 22))
            .map_err(|e| e.to_string())?;
        let panels = root.split_evenly((2, 1));
        let x_desc = format!("optimal length (m), bins of {width} m");

        let mut chart = ChartBuilder::on(&panels[0])
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, 0.0..105.0)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(x_desc.as_str())
            .y_desc("reached (%)")
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(|e| e.to_string())?;
        let success: Vec<(f64, f64)> = bins
            .iter()
            .map(|(&b, (n, reached, _))| (centre(b), 100.0 * *reached as f64 / *n as f64))
            .collect();
        let colour = PALETTE[0];
        chart
            .draw_series(LineSeries::new(success.clone(), colour.stroke_width(2)))
            .map_err(|e| e.to_string())?;
        chart
            .draw_series(success.iter().map(|p| Circle::new(*p, 4, colour.filled())))
            .map_err(|e| e.to_string())?;

        let ratios: Vec<(f64, f64)> = runs
            .iter()
            .filter_map(|o| Some((o.optimal, o.path_ratio()?)))
            .collect();
        let top = ratios.iter().map(|p| p.1).fold(1.2, f64::max) * 1.05;
        let mut chart = ChartBuilder::on(&panels[1])
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, 0.9..top)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc(x_desc.as_str())
            .y_desc("path / optimal")
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .draw()
            .map_err(|e| e.to_string())?;
        let dots = PALETTE[3];
        chart
            .draw_series(
                ratios
                    .iter()
                    .map(|p| Circle::new(*p, 2, dots.mix(0.6).filled())),
            )
            .map_err(|e| e.to_string())?;
        let means: Vec<(f64, f64)> = bins
            .iter()
            .filter(|(_, (_, _, r))| !r.is_empty())
            .map(|(&b, (_, _, r))| (centre(b), r.iter().sum::<f64>() / r.len() as f64))
            .collect();
        chart
            .draw_series(LineSeries::new(means, PALETTE[1].stroke_width(2)))
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(crate::field::export::png(&rgb, w, h))
}

/// A bin width that gives about ten bins, rounded to 1, 2 or 5 times a power of ten, m.
fn bin_width(runs: &[&Outcome]) -> f64 {
    let longest = runs.iter().map(|o| o.optimal).fold(0.0, f64::max);
    let raw = (longest / 10.0).max(1e-3);
    let power = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|&w| w >= raw)
        .unwrap_or(10.0 * power)
}
