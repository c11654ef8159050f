//! The reproduction's figures, in the paper's style: the paths over the world's walls for the
//! trajectory figures, the time series the paper plots for the others. Drawn with plotters
//! and the bundled font, like the sweep's plot.

use plotters::prelude::*;

use super::{Outcome, Outcomes, experiments};
use crate::chart::{PALETTE, padded, register_font};
use crate::world::wall_outline;

/// Picture size, pixels.
const SIZE: (u32, u32) = (1000, 700);

/// What a figure plots, for the experiments it names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Panel {
    /// The paths of every agent over the walls, to scale.
    Paths(&'static [&'static str]),
    /// The lateral position against the distance along a corridor (not to scale).
    Lateral(&'static [&'static str]),
    /// The distance to the target against time.
    Distance(&'static [&'static str]),
    /// The speed against time.
    Speed(&'static [&'static str]),
    /// The control force's magnitude against time.
    Force(&'static [&'static str]),
    /// A pendulum's error `θ_T − θ` against time.
    Angle(&'static [&'static str]),
    /// The settling time against the damping coefficient, one point per run (never settled:
    /// the run's duration).
    Settling(&'static [&'static str]),
}

/// One figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figure {
    /// Its id: the file is `ID.png`.
    pub id: &'static str,
    /// Its title.
    pub title: &'static str,
    /// What it plots.
    pub panel: Panel,
}

impl Figure {
    /// The experiments it plots.
    pub fn runs(&self) -> &'static [&'static str] {
        match self.panel {
            Panel::Paths(r)
            | Panel::Lateral(r)
            | Panel::Distance(r)
            | Panel::Speed(r)
            | Panel::Force(r)
            | Panel::Angle(r)
            | Panel::Settling(r) => r,
        }
    }
}

/// The legend of experiment `id`.
fn label(id: &str) -> &'static str {
    experiments()
        .into_iter()
        .find(|e| e.id == id)
        .map_or("?", |e| e.label)
}

/// Every `n`-th sample, so a line has at most about 2000 points.
fn thin(outcome: &Outcome) -> usize {
    (outcome.trace.len() / 2000).max(1)
}

/// A line of a figure: its legend, its colour's index and its points.
type Line = (String, usize, Vec<(f64, f64)>);

/// One line per run (and agent) of the figure's time series or paths.
fn lines(figure: &Figure, outcomes: &Outcomes) -> Vec<Line> {
    let mut out = Vec::new();
    if let Panel::Settling(runs) = figure.panel {
        let points = runs
            .iter()
            .map(|id| {
                let o = &outcomes[id];
                let b = o.world.agents[0].controller.b.unwrap_or(0.0);
                (b, o.summary().settling_time.unwrap_or(o.world.duration))
            })
            .collect();
        return vec![("settling time".into(), 0, points)];
    }
    for (colour, id) in figure.runs().iter().enumerate() {
        let o = &outcomes[id];
        let step = thin(o);
        let samples = o.trace.iter().step_by(step);
        if let Panel::Angle(_) = figure.panel {
            let target = o.world.pendulums[0].target;
            let points = samples.map(|s| (s.time, target - s.pendulums[0])).collect();
            out.push((label(id).to_string(), colour, points));
            continue;
        }
        for (a, agent) in o.world.agents.iter().enumerate() {
            let [tx, ty] = agent.target;
            let point = |s: &super::Sample| {
                let [x, y, vx, vy, fx, fy] = s.agents[a];
                match figure.panel {
                    Panel::Paths(_) | Panel::Lateral(_) => (x, y),
                    Panel::Distance(_) => (s.time, (x - tx).hypot(y - ty)),
                    Panel::Speed(_) => (s.time, vx.hypot(vy)),
                    Panel::Force(_) => (s.time, fx.hypot(fy)),
                    Panel::Angle(_) | Panel::Settling(_) => unreachable!("handled above"),
                }
            };
            let mut points: Vec<(f64, f64)> = vec![];
            if matches!(figure.panel, Panel::Paths(_) | Panel::Lateral(_)) {
                points.push((agent.start[0], agent.start[1]));
            }
            points.extend(samples.clone().map(point));
            let name = if o.world.agents.len() > 1 {
                format!("{} ({})", label(id), agent.name)
            } else {
                label(id).to_string()
            };
            out.push((name, colour, points));
        }
    }
    out
}

/// Draws `figure` from `outcomes` (which must hold its runs) as PNG bytes.
pub fn draw(figure: &Figure, outcomes: &Outcomes) -> Result<Vec<u8>, String> {
    register_font();
    let lines = lines(figure, outcomes);
    let first = &outcomes[figure.runs()[0]];
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let root = root
            .titled(figure.title, ("sans-serif", 22))
            .map_err(|e| e.to_string())?;
        let e = |e: DrawingAreaErrorKind<_>| e.to_string();
        let (xs, ys): (Vec<f64>, Vec<f64>) = lines.iter().flat_map(|l| l.2.iter().copied()).unzip();
        let range = |v: &[f64]| {
            padded(
                v.iter().copied().fold(f64::INFINITY, f64::min),
                v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            )
        };
        let ((x0, x1), (y0, y1), (x_desc, y_desc)) = match figure.panel {
            Panel::Paths(_) | Panel::Lateral(_) => {
                let ([lx, ly], [hx, hy]) = first.world.bounds();
                let x1 = if let Panel::Lateral(_) = figure.panel {
                    // The corridor's part the runs cover, not its 110 m.
                    xs.iter().copied().fold(lx, f64::max).min(hx) + 1.0
                } else {
                    hx
                };
                ((lx, x1), (ly, hy), ("x (m)", "y (m)"))
            }
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
            .margin(16)
            .x_label_area_size(45)
            .y_label_area_size(70)
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
        for (name, colour, points) in lines {
            let style = PALETTE[colour % PALETTE.len()].stroke_width(2);
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
