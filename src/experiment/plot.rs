//! The picture of an experiment's summary: per group (its values on the axis; the grouping
//! keys are in the title), the success rate with its 95 % Wilson
//! interval, and the settling time's median with its 90th percentile.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::results::Group;
use crate::chart::{PALETTE, register_font};

/// Picture size, pixels.
const SIZE: (u32, u32) = (900, 800);

/// The summary's plot as PNG bytes, titled `title`.
pub fn plot(groups: &[Group], title: &str) -> Result<Vec<u8>, String> {
    register_font();
    let n = groups.len().max(1) as f64;
    let x = |i: usize| i as f64 + 0.5;
    let labels: Vec<String> = groups.iter().map(|g| g.values.clone()).collect();
    let label_of = |v: &f64| {
        let i = v.floor();
        (i >= 0.0 && (v - i - 0.5).abs() < 1e-6)
            .then(|| labels.get(i as usize).cloned())
            .flatten()
            .unwrap_or_default()
    };
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(title, ("sans-serif", 22))
            .map_err(|e| e.to_string())?;
        let panels = root.split_evenly((2, 1));

        let mut chart = panel(
            &panels[0],
            n,
            105.0,
            "reached (%), 95 % interval",
            &label_of,
        )?;
        let colour = PALETTE[0];
        for (i, g) in groups.iter().enumerate() {
            let (lo, hi) = (100.0 * g.interval.0, 100.0 * g.interval.1);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x(i) - 0.3, 0.0), (x(i) + 0.3, 100.0 * g.success())],
                    colour.mix(0.5).filled(),
                )))
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x(i), lo), (x(i), hi)],
                    BLACK.stroke_width(2),
                )))
                .map_err(|e| e.to_string())?;
        }

        let top = (groups.iter())
            .filter_map(|g| g.settling.map(|s| s.1))
            .fold(1.0, f64::max)
            * 1.1;
        let mut chart = panel(
            &panels[1],
            n,
            top,
            "settling time (s): median, 90th percentile",
            &label_of,
        )?;
        for (i, g) in groups.iter().enumerate() {
            if let Some((p50, p90)) = g.settling {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(x(i), p50), (x(i), p90)],
                        PALETTE[1].stroke_width(2),
                    )))
                    .map_err(|e| e.to_string())?;
                chart
                    .draw_series(std::iter::once(Circle::new(
                        (x(i), p50),
                        5,
                        PALETTE[1].filled(),
                    )))
                    .map_err(|e| e.to_string())?;
            }
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(crate::field::export::png(&rgb, w, h))
}

/// A panel of `n` groups along x (labelled by `label_of` at their centres) and `0..top` up,
/// with its mesh drawn and its y axis described by `y_desc`.
fn panel<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>,
    n: f64,
    top: f64,
    y_desc: &str,
    label_of: &dyn Fn(&f64) -> String,
) -> Result<ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String>
{
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..n, 0.0..top)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(2 * n as usize + 1)
        .x_label_formatter(label_of)
        .y_desc(y_desc)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(chart)
}
