//! The picture of a sweep: settling time, largest deviation from the kinematic path and contacts
//! against the first swept value, one line per agent and per combination of the other swept
//! values. Drawn with plotters into an RGB buffer with the DejaVu Sans font bundled in
//! `assets/fonts` (no system fonts needed) and encoded as PNG.

use std::collections::BTreeMap;

use plotters::prelude::*;

use super::Sweep;
use crate::chart::{PALETTE, padded, register_font};

/// Picture size, pixels.
const SIZE: (u32, u32) = (900, 1100);

/// One run on a line: the first swept value and the three plotted metrics (settling time,
/// δ_m, contacts; `None` where the run never settled).
type Point = (f64, [Option<f64>; 3]);

/// The sweep's plot as PNG bytes, titled `title`.
pub fn plot(sweep: &Sweep, title: &str) -> Result<Vec<u8>, String> {
    register_font();
    // One series per agent and combination of the other swept values.
    let mut series: BTreeMap<String, Vec<Point>> = BTreeMap::new();
    for (values, summaries) in &sweep.runs {
        let others: Vec<String> = sweep.keys[1..]
            .iter()
            .zip(&values[1..])
            .map(|(k, v)| format!("{}={v}", short(k)))
            .collect();
        for s in summaries {
            let mut label = others.clone();
            if summaries.len() > 1 {
                label.insert(0, s.name.clone());
            }
            series.entry(label.join(", ")).or_default().push((
                values[0],
                [
                    s.settling_time,
                    Some(s.max_deviation),
                    Some(s.contacts as f64),
                ],
            ));
        }
    }
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(title, ("sans-serif", 24))
            .map_err(|e| e.to_string())?;
        let panels = root.split_evenly((3, 1));
        let xs = sweep.runs.iter().map(|(v, _)| v[0]);
        let (x0, x1) = padded(
            xs.clone().fold(f64::INFINITY, f64::min),
            xs.fold(f64::NEG_INFINITY, f64::max),
        );
        let metrics = [
            ("settling time (s)", 0),
            ("max deviation δ_m (m)", 1),
            ("contacts", 2),
        ];
        for (panel, (label, m)) in panels.iter().zip(metrics) {
            let ys: Vec<f64> = series
                .values()
                .flat_map(|points| points.iter().filter_map(|p| p.1[m]))
                .collect();
            let top = ys.iter().copied().fold(0.0, f64::max);
            let y1 = if top > 0.0 { top * 1.1 } else { 1.0 };
            let mut chart = ChartBuilder::on(panel)
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(60)
                .build_cartesian_2d(x0..x1, 0.0..y1)
                .map_err(|e| e.to_string())?;
            chart
                .configure_mesh()
                .x_desc(short(&sweep.keys[0]))
                .y_desc(label)
                .label_style(("sans-serif", 14))
                .axis_desc_style(("sans-serif", 16))
                .draw()
                .map_err(|e| e.to_string())?;
            for (i, (name, points)) in series.iter().enumerate() {
                let colour = PALETTE[i % PALETTE.len()];
                // A run that never settled leaves a gap in its line.
                let mut segment: Vec<(f64, f64)> = Vec::new();
                let mut segments = Vec::new();
                for (x, ys) in points {
                    match ys[m] {
                        Some(y) => segment.push((*x, y)),
                        None => segments.push(std::mem::take(&mut segment)),
                    }
                }
                segments.push(segment);
                for (k, segment) in segments.into_iter().enumerate() {
                    let line = chart
                        .draw_series(LineSeries::new(segment.clone(), colour.stroke_width(2)))
                        .map_err(|e| e.to_string())?;
                    if k == 0 && !name.is_empty() {
                        line.label(name.as_str()).legend(move |(x, y)| {
                            PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2))
                        });
                    }
                    chart
                        .draw_series(segment.iter().map(|p| Circle::new(*p, 3, colour.filled())))
                        .map_err(|e| e.to_string())?;
                }
            }
            if series.len() > 1 {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .label_font(("sans-serif", 13))
                    .draw()
                    .map_err(|e| e.to_string())?;
            }
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(crate::field::export::png(&rgb, w, h))
}

/// `agents.0.controller.b` → `controller.b`: the last two parts of a key, for labels.
fn short(key: &str) -> &str {
    let mut dots = key.rmatch_indices('.');
    dots.next();
    match dots.next() {
        Some((i, _)) => &key[i + 1..],
        None => key,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_keep_the_last_two_parts_of_a_key() {
        assert_eq!(short("agents.0.controller.b"), "controller.b");
        assert_eq!(short("dt"), "dt");
        assert_eq!(short("field.cell"), "field.cell");
    }
}
