//! The reproduction's figures, in the paper's style: the paths over the world's walls for the
//! trajectory figures (to scale: one metre is as long on both axes), the time series the paper
//! plots for the others, and the calibration's curves over the gain. Drawn with plotters and
//! the bundled font, like the sweep's plot.

use plotters::prelude::*;

use super::{Outcome, Outcomes};
use crate::chart::{PALETTE, padded, register_font};
use crate::world::wall_outline;

/// Picture size, pixels.
const SIZE: (u32, u32) = (1000, 700);
/// The chart's margin and the heights of its label areas, pixels.
const MARGIN: f64 = 16.0;
const X_LABELS: f64 = 45.0;
const Y_LABELS: f64 = 70.0;

/// What a figure plots, for the experiments it names.
#[derive(Debug, Clone, PartialEq)]
pub enum Panel {
    /// The paths of every agent over the walls, to scale.
    Paths(Vec<String>),
    /// The lateral position against the distance along a corridor (the lateral axis stretched).
    Lateral(Vec<String>),
    /// The distance to the target against time.
    Distance(Vec<String>),
    /// The speed against time.
    Speed(Vec<String>),
    /// The radial speed (along the guidance) against time.
    Radial(Vec<String>),
    /// The control force's magnitude against time.
    Force(Vec<String>),
    /// A pendulum's error `θ_T − θ` against time.
    Angle(Vec<String>),
    /// The settling time against the damping coefficient, one point per run (never settled:
    /// the run's duration).
    Settling(Vec<String>),
    /// The settling times of NADF and viscous damping and their ratio against the gain K (log
    /// scales), the calibrated K and the paper's numbers marked.
    OverGain {
        /// `(K, NADF run, viscous run)`, in increasing K.
        pairs: Vec<(f64, String, String)>,
        /// The legends of the NADF and the viscous settling times.
        names: (String, String),
        /// The calibrated gain.
        calibrated: f64,
        /// The paper's ratio.
        paper_ratio: f64,
        /// The paper's settling times, NADF and viscous, s.
        paper_times: (f64, f64),
    },
}

/// One figure.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Its id: the file is `ID.png`.
    pub id: String,
    /// Its title.
    pub title: String,
    /// What it plots.
    pub panel: Panel,
}

impl Figure {
    /// The experiments it plots.
    pub fn runs(&self) -> Vec<String> {
        match &self.panel {
            Panel::Paths(r)
            | Panel::Lateral(r)
            | Panel::Distance(r)
            | Panel::Speed(r)
            | Panel::Radial(r)
            | Panel::Force(r)
            | Panel::Angle(r)
            | Panel::Settling(r) => r.clone(),
            Panel::OverGain { pairs, .. } => pairs
                .iter()
                .flat_map(|(_, a, b)| [a.clone(), b.clone()])
                .collect(),
        }
    }
}

/// Every `n`-th sample, so a line has at most about 2000 points.
fn thin(outcome: &Outcome) -> usize {
    (outcome.trace.len() / 2000).max(1)
}

/// A line of a figure: its legend, its colour's index, its points, and whether it is a
/// reference (a paper's number or a marked gain: drawn thin) rather than a measurement.
type Line = (String, usize, Vec<(f64, f64)>, bool);

/// One line per run (and agent) of the figure's time series or paths.
fn lines(figure: &Figure, outcomes: &Outcomes) -> Vec<Line> {
    let mut out = Vec::new();
    if let Panel::Settling(runs) = &figure.panel {
        let points = runs
            .iter()
            .map(|id| {
                let o = &outcomes[id];
                let b = o.world.agents[0].controller.b.unwrap_or(0.0);
                (b, o.summary().settling_time.unwrap_or(o.world.duration))
            })
            .collect();
        return vec![("settling time".into(), 0, points, false)];
    }
    if let Panel::OverGain {
        pairs,
        names,
        paper_ratio,
        paper_times,
        calibrated,
    } = &figure.panel
    {
        let settle = |id: &str| super::settle(outcomes, id);
        let nadf: Vec<(f64, f64)> = pairs.iter().map(|(k, a, _)| (*k, settle(a))).collect();
        let viscous: Vec<(f64, f64)> = pairs.iter().map(|(k, _, b)| (*k, settle(b))).collect();
        let ratio: Vec<(f64, f64)> = pairs
            .iter()
            .map(|(k, a, b)| (*k, settle(b) / settle(a)))
            .collect();
        let (k0, k1) = (pairs[0].0, pairs[pairs.len() - 1].0);
        let log = |points: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
            points
                .into_iter()
                .map(|(x, y)| (x.log10(), y.log10()))
                .collect()
        };
        let marked = |k: f64| vec![(k, 1.0), (k, 300.0)];
        let level = |y: f64| vec![(k0, y), (k1, y)];
        let (tn, tv) = *paper_times;
        let lines: Vec<Line> = vec![
            (format!("T_S, {} (s)", names.0), 0, nadf, false),
            (format!("T_S, {} (s)", names.1), 1, viscous, false),
            ("ratio viscous / NADF".into(), 2, ratio, false),
            (
                format!("the paper's ratio, {paper_ratio}"),
                2,
                level(*paper_ratio),
                true,
            ),
            (format!("the paper's T_S, {tn} s"), 0, level(tn), true),
            (format!("the paper's T_S, {tv} s"), 1, level(tv), true),
            ("the calibrated K".into(), 5, marked(*calibrated), true),
        ];
        return lines
            .into_iter()
            .map(|(name, colour, points, thin)| (name, colour, log(points), thin))
            .collect();
    }
    for (colour, id) in figure.runs().iter().enumerate() {
        let o = &outcomes[id];
        let step = thin(o);
        let samples = o.trace.iter().step_by(step);
        if let Panel::Angle(_) = figure.panel {
            let target = o.world.pendulums[0].target;
            let points = samples.map(|s| (s.time, target - s.pendulums[0])).collect();
            out.push((o.label.clone(), colour, points, false));
            continue;
        }
        for (a, agent) in o.world.agents.iter().enumerate() {
            let [tx, ty] = agent.target;
            let point = |s: &super::Sample| {
                let [x, y, vx, vy, fx, fy, radial, _] = s.agents[a];
                match figure.panel {
                    Panel::Paths(_) | Panel::Lateral(_) => (x, y),
                    Panel::Distance(_) => (s.time, (x - tx).hypot(y - ty)),
                    Panel::Speed(_) => (s.time, vx.hypot(vy)),
                    Panel::Radial(_) => (s.time, radial),
                    Panel::Force(_) => (s.time, fx.hypot(fy)),
                    Panel::Angle(_) | Panel::Settling(_) | Panel::OverGain { .. } => {
                        unreachable!("handled above")
                    }
                }
            };
            let mut points: Vec<(f64, f64)> = vec![];
            if matches!(figure.panel, Panel::Paths(_) | Panel::Lateral(_)) {
                // Paths are thinned by distance, not by step: a body at 40 m/s crosses metres
                // in the steps a count would skip.
                let ([lx, ly], [hx, hy]) = o.world.bounds();
                let spacing = (hx - lx).hypot(hy - ly) / 2000.0;
                points.push((agent.start[0], agent.start[1]));
                for s in &o.trace {
                    let p = point(s);
                    let last = points[points.len() - 1];
                    if (p.0 - last.0).hypot(p.1 - last.1) >= spacing {
                        points.push(p);
                    }
                }
            } else {
                points.extend(samples.clone().map(point));
            }
            let name = if o.world.agents.len() > 1 {
                format!("{} ({})", o.label, agent.name)
            } else {
                o.label.clone()
            };
            out.push((name, colour, points, false));
        }
    }
    out
}

/// The range of width `span` about the middle of `[lo, hi]` (a plot drawn to scale).
fn widen(lo: f64, hi: f64, span: f64) -> (f64, f64) {
    let middle = 0.5 * (lo + hi);
    (middle - 0.5 * span, middle + 0.5 * span)
}

/// Draws `figure` from `outcomes` (which must hold its runs) as PNG bytes.
pub fn draw(figure: &Figure, outcomes: &Outcomes) -> Result<Vec<u8>, String> {
    register_font();
    let lines = lines(figure, outcomes);
    let first = &outcomes[&figure.runs()[0]];
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(&figure.title, ("sans-serif", 22))
            .map_err(|e| e.to_string())?;
        let e = |e: DrawingAreaErrorKind<_>| e.to_string();
        let (xs, ys): (Vec<f64>, Vec<f64>) = lines.iter().flat_map(|l| l.2.iter().copied()).unzip();
        let range = |v: &[f64]| {
            padded(
                v.iter().copied().fold(f64::INFINITY, f64::min),
                v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            )
        };
        // The plot's area, pixels: the drawing area less the margins and the label areas.
        let (pw, ph) = root.dim_in_pixel();
        let (plot_w, plot_h) = (
            f64::from(pw) - 2.0 * MARGIN - Y_LABELS,
            f64::from(ph) - 2.0 * MARGIN - X_LABELS,
        );
        let ((x0, x1), (y0, y1), (x_desc, y_desc)) = match figure.panel {
            Panel::Paths(_) => {
                // To scale: a metre is as many pixels on both axes.
                let ([lx, ly], [hx, hy]) = first.world.bounds();
                let scale = ((hx - lx) / plot_w).max((hy - ly) / plot_h);
                (
                    widen(lx, hx, scale * plot_w),
                    widen(ly, hy, scale * plot_h),
                    ("x (m)", "y (m)"),
                )
            }
            Panel::Lateral(_) => {
                let ([lx, ly], [hx, hy]) = first.world.bounds();
                // The corridor's part the runs cover, not its 110 m.
                let x1 = xs.iter().copied().fold(lx, f64::max).min(hx) + 1.0;
                ((lx, x1), (ly, hy), ("x (m)", "y (m), stretched"))
            }
            Panel::Radial(_) => (
                (0.0, first.world.duration),
                range(&ys),
                ("t (s)", "radial speed −uᵀv (m/s)"),
            ),
            Panel::OverGain { .. } => (range(&xs), range(&ys), ("log₁₀ K", "log₁₀ (s, or ratio)")),
            Panel::Distance(_) => (
                (0.0, first.world.duration),
                range(&ys),
                ("t (s)", "distance to the target (m)"),
            ),
            Panel::Speed(_) => (
                (0.0, first.world.duration),
                range(&ys),
                ("t (s)", "speed (m/s)"),
            ),
            Panel::Force(_) => (
                (0.0, first.world.duration),
                range(&ys),
                ("t (s)", "|F| (N)"),
            ),
            Panel::Angle(_) => (
                (0.0, first.world.duration),
                range(&ys),
                ("t (s)", "error θ_T − θ (rad)"),
            ),
            Panel::Settling(_) => (range(&xs), range(&ys), ("B (N·s/m)", "settling time (s)")),
        };
        let mut chart = ChartBuilder::on(&root)
            .margin(MARGIN as u32)
            .x_label_area_size(X_LABELS as u32)
            .y_label_area_size(Y_LABELS as u32)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(e)?;
        if matches!(figure.panel, Panel::Paths(_) | Panel::Lateral(_)) {
            let grey = RGBColor(150, 150, 150);
            for wall in &first.world.walls {
                chart
                    .draw_series(std::iter::once(Polygon::new(
                        wall_outline(wall)
                            .into_iter()
                            .map(|[x, y]| (x, y))
                            .collect::<Vec<_>>(),
                        grey.filled(),
                    )))
                    .map_err(e)?;
            }
            for agent in &first.world.agents {
                let t = (agent.target[0], agent.target[1]);
                chart
                    .draw_series(std::iter::once(Cross::new(t, 8, BLACK.stroke_width(2))))
                    .map_err(e)?;
            }
        }
        for (name, colour, points, thin) in lines {
            let colour = PALETTE[colour % PALETTE.len()];
            let style = if thin {
                colour.mix(0.6).stroke_width(1)
            } else {
                colour.stroke_width(2)
            };
            chart
                .draw_series(LineSeries::new(points, style))
                .map_err(e)?
                .label(name)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(e)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(crate::field::export::png(&rgb, w, h))
}
