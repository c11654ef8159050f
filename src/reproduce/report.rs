//! The reproduction's report: `report.md` for people (the calibration and its derivation, the
//! counts per law, per claim the paper's statement and number, the measured number, the
//! relation and the verdict with its measured reason; the figures linked) and `report.json`
//! with the same numbers for scripts. `report.md` holds nothing that changes from run to run
//! (the wall time is in `report.json` only), so a test can hold the committed one to the code.

use std::fmt::Write;
use std::time::Duration;

use serde::Serialize;

use super::calibration::{self, K_NORMALIZED, K_PAPER, PULL};
use super::figure::Figure;
use super::{
    Checked, Claim, Law, Outcomes, Verdict, calibrated_gain, calibration_curve, gain_run, sweep,
};

/// One claim in `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct ClaimReport {
    /// The claim's id.
    pub id: String,
    /// Its figure's id.
    pub figure: String,
    /// The law it is measured under.
    pub law: Law,
    /// What the paper states.
    pub statement: String,
    /// The paper's number, or its words.
    pub paper: String,
    /// What is measured.
    pub quantity: String,
    /// The measured number.
    pub measured: f64,
    /// Measured over the paper's number, where the paper prints one.
    pub ratio: Option<f64>,
    /// The relation the paper's statement asks, as text.
    pub paper_relation: String,
    /// The verdict.
    pub verdict: Verdict,
    /// Why, where not reproduced, with the measured numbers it rests on.
    pub reason: String,
    /// The relation the sandbox is held to where not reproduced, as text.
    pub sandbox_relation: Option<String>,
}

/// The verdicts of one law.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Count {
    /// The law.
    pub law: Law,
    /// Claims reproduced.
    pub reproduced: usize,
    /// Claims weaker than the paper's.
    pub weaker: usize,
    /// Claims that differ.
    pub differs: usize,
    /// Claims the law cannot do here.
    pub not_applicable: usize,
}

impl Count {
    /// Every claim of the law.
    pub fn total(&self) -> usize {
        self.reproduced + self.weaker + self.differs + self.not_applicable
    }
}

/// One law's calibration, as measured.
#[derive(Debug, Clone, Serialize)]
pub struct Calibration {
    /// The law.
    pub law: Law,
    /// The declared gain (J for the paper's law, N for normalized guidance).
    pub declared: f64,
    /// The gain the sweep gives for figure 16's 12 s, by log-log interpolation.
    pub derived: Option<f64>,
    /// `(K, T_S NADF B_d = 10, T_S viscous B = 0.7)` over the sweep, the declared K among them.
    pub sweep: Vec<(f64, f64, f64)>,
}

/// `report.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The verdicts per law.
    pub counts: Vec<Count>,
    /// The calibrations, where the claims asked for them.
    pub calibration: Vec<Calibration>,
    /// Wall-clock time of the runs, s.
    pub wall_time: f64,
    /// Runs made.
    pub runs: usize,
    /// Every claim.
    pub claims: Vec<ClaimReport>,
}

/// The calibrations measured in `outcomes` (those whose sweeps were run).
pub fn calibrations(outcomes: &Outcomes) -> Vec<Calibration> {
    [Law::Paper, Law::Normalized]
        .into_iter()
        .filter(|&law| {
            sweep(law)
                .iter()
                .all(|&k| outcomes.contains_key(&gain_run(law, true, k)))
        })
        .map(|law| Calibration {
            law,
            declared: super::gain_of(law),
            derived: calibrated_gain(law, outcomes),
            sweep: calibration_curve(law, outcomes),
        })
        .collect()
}

/// The report of `claims` as `checked` on `outcomes`, with the runs' `wall_time`.
pub fn build(
    claims: &[Claim],
    checked: &[Checked],
    outcomes: &Outcomes,
    runs: usize,
    wall_time: Duration,
) -> Report {
    let counts = Law::ALL
        .into_iter()
        .map(|law| {
            let count = |v: Verdict| {
                claims
                    .iter()
                    .zip(checked)
                    .filter(|(c, k)| c.law == law && k.verdict == v)
                    .count()
            };
            Count {
                law,
                reproduced: count(Verdict::Reproduced),
                weaker: count(Verdict::Weaker),
                differs: count(Verdict::Differs),
                not_applicable: count(Verdict::NotApplicable),
            }
        })
        .collect();
    let claims = claims
        .iter()
        .zip(checked)
        .map(|(c, k)| ClaimReport {
            id: c.id.clone(),
            figure: c.figure.clone(),
            law: c.law,
            statement: c.statement.clone(),
            paper: c.paper_number.clone(),
            quantity: c.quantity.clone(),
            measured: k.measured,
            ratio: c.paper_value.map(|p| k.measured / p),
            paper_relation: c.paper.to_string(),
            verdict: k.verdict,
            reason: if k.verdict == Verdict::Reproduced {
                String::new()
            } else {
                (c.otherwise.reason)(outcomes)
            },
            sandbox_relation: (k.verdict != Verdict::Reproduced)
                .then(|| c.otherwise.relation.to_string()),
        })
        .collect();
    Report {
        counts,
        calibration: calibrations(outcomes),
        wall_time: wall_time.as_secs_f64(),
        runs,
        claims,
    }
}

/// A number with four significant digits (integers as they are).
pub fn number(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == x.round() && x.abs() < 1e6 {
        return format!("{x:.0}");
    }
    let digits = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let text = format!("{x:.digits$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

/// The counts as one sentence per law: the line the README quotes.
pub fn counts_line(report: &Report) -> String {
    (report.counts.iter())
        .filter(|c| c.total() > 0)
        .map(|c| {
            format!(
                "{}: {} claims, {} reproduced, {} weaker, {} differ, {} not applicable.",
                capitalized(c.law.title()),
                c.total(),
                c.reproduced,
                c.weaker,
                c.differs,
                c.not_applicable
            )
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn capitalized(s: &str) -> String {
    let mut chars = s.chars();
    chars
        .next()
        .map_or(String::new(), |c| c.to_uppercase().chain(chars).collect())
}

/// The calibration's derivation, measured.
fn calibration_section(md: &mut String, report: &Report) {
    let _ = writeln!(md, "## The calibration\n");
    let _ = writeln!(
        md,
        "The paper states no room size, no K for figures 4–24, no dt and no integrator, and its numbers \
         cannot hold literally (with K = 1 N·m and V ∈ [0, 1], Proposition 1 caps a 1 kg body at √2 m/s, \
         yet §VI.2 reaches a 5 m/s limit). Under the paper's law a room of size L and a gain K enter only \
         as K/(mL²); the damping rates and every speed, acceleration, force and distance the paper prints \
         in SI units fix the rest. So one number is free, fixed here from one of the paper's numbers, \
         **figure 16's settling time of 12 s** (NADF B_d = 10):\n"
    );
    let _ = writeln!(
        md,
        "- the sandbox's 10 m × 10 m room with two dividers (`worlds/paper-room.toml`); a **1 kg point \
         mass** (a 5 cm collider, one field cell); a target disc of 0.2 m (a point target has zero \
         capacity in 2-D); dt = 5 ms, integrated exactly (the explicit step is tested as a hypothesis, \
         at every B the paper reports);\n\
         - **K = {} J** in F = −K∇V: the K at which NADF B_d = 10 settles in 12 s, read off the sweep \
         below by log-log interpolation. The paper's K = 1 of figure 27 maps to the same K; its \
         K_c = 10 N/m and B_d = 10 N·s/m are rates per unit mass and keep their values. Every claim of \
         §VI under the paper's law uses this K (the swap too);\n\
         - normalized guidance, the sandbox's variant, gets **K = {} N** from the same 12 s;\n\
         - the corridor (§VI.6) is guided by Khatib's potential, whose pull is a force: **{} N** from \
         figure 38's 25 m in 10 s under viscous B = 0.3, by the free-running solution \
         x(t) = (K/B)[t − (m/B)(1 − e^(−Bt/m))] ({} m per newton). The pendulum (§VI.8) keeps the \
         sandbox's K = 20 N·m/rad, B = 5 N·m·s/rad: the paper gives neither, and no number of its to \
         fix them.\n",
        number(K_PAPER),
        number(K_NORMALIZED),
        PULL,
        number(calibration::free_run(0.3, 1.0, 10.0))
    );
    let _ = writeln!(
        md,
        "Every other number is a prediction. The sweeps (the ratio's dependence on K is the curve the \
         paper's 6× sits on):\n"
    );
    for c in &report.calibration {
        let unit = if c.law == Law::Normalized { "N" } else { "J" };
        let _ = writeln!(
            md,
            "{}: declared K = {} {unit}, derived from the sweep {} {unit}.\n",
            capitalized(c.law.title()),
            number(c.declared),
            c.derived.map_or("(not bracketed)".into(), number)
        );
        let _ = writeln!(
            md,
            "| K ({unit}) | T_S NADF B_d = 10 (s) | T_S viscous B = 0.7 (s) | ratio |\n|---|---|---|---|"
        );
        for (k, tn, tv) in &c.sweep {
            let mark = if *k == c.declared { " (declared)" } else { "" };
            let _ = writeln!(
                md,
                "| {}{mark} | {} | {} | {} |",
                number(*k),
                number(*tn),
                number(*tv),
                number(tv / tn)
            );
        }
        let _ = writeln!(md);
    }
}

/// `report.md`, linking `FIGURE.png` for each of `figures`.
pub fn markdown(report: &Report, figures: &[Figure], outcomes: &Outcomes) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# The paper, claim by claim\n");
    let _ = writeln!(
        md,
        "Generated by `nadf reproduce` ({} runs). *Reproduced*: the paper's relation holds, read as \
         strongly as its words (each quantity says how they are read). *Weaker*: the same direction, \
         less strength. *Differs*: not the paper's result. *Not applicable*: a precondition of the \
         paper's fails under this law, as measured. Each verdict that is not *reproduced* gives its \
         reason with the numbers it rests on. The tests assert the paper's relation where it is \
         reproduced and the sandbox's where it is not. A \"paper number\" is one the paper prints; \
         where it prints none its words stand in the column.\n",
        report.runs
    );
    let _ = writeln!(
        md,
        "| | claims | reproduced | weaker | differs | not applicable |\n|---|---|---|---|---|---|"
    );
    for c in report.counts.iter().filter(|c| c.total() > 0) {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} |",
            c.law.title(),
            c.total(),
            c.reproduced,
            c.weaker,
            c.differs,
            c.not_applicable
        );
    }
    let _ = writeln!(md);
    if !report.calibration.is_empty() {
        calibration_section(&mut md, report);
    }
    for law in Law::ALL {
        let claims: Vec<&ClaimReport> = report.claims.iter().filter(|c| c.law == law).collect();
        if claims.is_empty() {
            continue;
        }
        let _ = writeln!(md, "## Claims: {}\n", law.title());
        let _ = writeln!(
            md,
            "| claim | paper | measured | measured / paper | relation | verdict |\n|---|---|---|---|---|---|"
        );
        for c in claims {
            let verdict = match c.verdict {
                Verdict::Reproduced => "reproduced".to_string(),
                v => format!(
                    "**{v}**: {} (holds {})",
                    c.reason,
                    c.sandbox_relation.as_deref().unwrap_or("")
                ),
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} {} | {} | {} | {} |",
                c.statement,
                c.paper,
                number(c.measured),
                c.quantity,
                c.ratio.map_or("".into(), |r| format!("{r:.2}")),
                c.paper_relation,
                verdict
            );
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "## Figures");
    for figure in figures {
        let _ = writeln!(md, "\n### {}\n", figure.title);
        let _ = writeln!(md, "![{}]({}.png)\n", figure.title, figure.id);
        let runs: Vec<String> = figure
            .runs()
            .iter()
            .map(|id| {
                let o = &outcomes[id];
                match o.agents.first() {
                    Some(s) => format!(
                        "`{id}`: settles {}, {} contacts, δ_m {} m, peak {} m/s",
                        s.settling_time
                            .map_or("never".into(), |t| format!("in {t:.2} s")),
                        s.contacts,
                        number(s.max_deviation),
                        number(s.peak_speed)
                    ),
                    None => format!(
                        "`{id}`: final error {} rad, settles {}",
                        number(o.pendulums[0].final_error),
                        o.pendulums[0]
                            .settling_time
                            .map_or("never".into(), |t| format!("in {t:.2} s")),
                    ),
                }
            })
            .collect();
        let _ = writeln!(md, "{}", runs.join("; "));
        for c in report.claims.iter().filter(|c| c.figure == figure.id) {
            let _ = writeln!(
                md,
                "- {}: {} ({})",
                c.statement,
                number(c.measured),
                c.verdict
            );
        }
    }
    md
}
