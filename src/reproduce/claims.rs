//! The table: the runs ([`experiments`]), the paper's claims measured on them ([`claims`]) and
//! the figures drawn from them ([`figures`]). Every number in a claim's text was measured with
//! this code; the relations are what the tests assert.

use std::fmt;

use serde::Serialize;

use super::Outcomes;
use super::figure::{Figure, Panel};

/// One run: a shipped world with overrides.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Experiment {
    /// Its id, used by claims and figures.
    pub id: &'static str,
    /// The shipped world's file name.
    pub world: &'static str,
    /// `--set` overrides.
    pub overrides: &'static [&'static str],
    /// The legend of its line in a figure.
    pub label: &'static str,
    /// Simulated steps, thousands, roughly: the longest runs start first.
    pub cost: u32,
}

/// A relation a measured quantity must satisfy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Relation {
    /// At least this.
    AtLeast(f64),
    /// At most this.
    AtMost(f64),
    /// Within this closed range.
    Within(f64, f64),
}

impl Relation {
    /// Whether `x` satisfies it (never for NaN).
    pub fn holds(&self, x: f64) -> bool {
        match *self {
            Self::AtLeast(a) => x >= a,
            Self::AtMost(b) => x <= b,
            Self::Within(a, b) => (a..=b).contains(&x),
        }
    }
}

impl fmt::Display for Relation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = super::report::number;
        match *self {
            Self::AtLeast(a) => write!(f, "≥ {}", n(a)),
            Self::AtMost(b) => write!(f, "≤ {}", n(b)),
            Self::Within(a, b) => write!(f, "in [{}, {}]", n(a), n(b)),
        }
    }
}

/// How a claim came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// The paper's relation holds.
    Reproduced,
    /// The same direction as the paper, less strength.
    Weaker,
    /// Not the paper's result.
    Differs,
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Reproduced => "reproduced",
            Self::Weaker => "weaker",
            Self::Differs => "differs",
        })
    }
}

/// What the sandbox is held to when the paper's relation does not hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Check {
    /// The expected verdict: `Reproduced` (the paper's relation is asserted), or `Weaker` or
    /// `Differs` (then `relation` is asserted).
    pub verdict: Verdict,
    /// The relation the sandbox reaches instead.
    pub relation: Relation,
    /// Why, in one line.
    pub reason: &'static str,
}

/// The claim is reproduced: the tests assert the paper's relation.
const REPRODUCED: Check = Check {
    verdict: Verdict::Reproduced,
    relation: Relation::AtLeast(f64::NEG_INFINITY),
    reason: "",
};

/// One claim of the paper.
#[derive(Clone)]
pub struct Claim {
    /// Its id.
    pub id: &'static str,
    /// The figure it belongs to (an id of [`figures`]).
    pub figure: &'static str,
    /// What the paper states.
    pub statement: &'static str,
    /// The paper's number, as the paper gives it.
    pub paper_number: &'static str,
    /// The paper's number as a value of the measured quantity, where it gives one.
    pub paper_value: Option<f64>,
    /// What is measured, with its unit.
    pub quantity: &'static str,
    /// The experiments it reads.
    pub runs: &'static [&'static str],
    /// The measurement.
    pub measure: fn(&Outcomes) -> f64,
    /// The relation the paper's statement asks of the measurement.
    pub paper: Relation,
    /// What the sandbox reaches where the paper's relation does not hold.
    pub otherwise: Check,
}

impl fmt::Debug for Claim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Claim")
            .field("id", &self.id)
            .finish_non_exhaustive()
    }
}

const ROOM: &str = "room-two-dividers.toml";
const GRADIENT: &str = "room-two-dividers-gradient.toml";
const GRADIENT_VISCOUS: &str = "room-two-dividers-gradient-viscous.toml";

/// Every run of the reproduction.
pub fn experiments() -> Vec<Experiment> {
    let e = |id, world, overrides, label, cost| Experiment {
        id,
        world,
        overrides,
        label,
        cost,
    };
    vec![
        // §II–III, figures 4–8, 24: the room, normalized guidance (K = 1 N).
        e("room-nadf", ROOM, &["duration=120"], "NADF B_d = 10", 12),
        e(
            "room-nadf-1",
            ROOM,
            &["duration=120", "agents.0.controller.b=1"],
            "NADF B_d = 1",
            12,
        ),
        e(
            "room-nadf-3",
            ROOM,
            &["duration=120", "agents.0.controller.b=3"],
            "NADF B_d = 3",
            12,
        ),
        e(
            "room-nadf-30",
            ROOM,
            &["duration=120", "agents.0.controller.b=30"],
            "NADF B_d = 30",
            12,
        ),
        e(
            "room-viscous-0.1",
            ROOM,
            &[
                "duration=120",
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0.1",
            ],
            "viscous B = 0.1",
            12,
        ),
        e(
            "room-viscous-0.15",
            ROOM,
            &[
                "duration=120",
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0.15",
            ],
            "viscous B = 0.15",
            12,
        ),
        e(
            "room-viscous-0.7",
            ROOM,
            &[
                "duration=120",
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0.7",
            ],
            "viscous B = 0.7",
            12,
        ),
        e(
            "room-viscous-0.3",
            ROOM,
            &[
                "duration=120",
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0.3",
            ],
            "viscous B = 0.3",
            12,
        ),
        e(
            "room-viscous-1",
            ROOM,
            &[
                "duration=120",
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=1",
            ],
            "viscous B = 1",
            12,
        ),
        e(
            "room-viscous-3",
            ROOM,
            &[
                "duration=120",
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=3",
            ],
            "viscous B = 3",
            12,
        ),
        // The same under the paper's own law, F = −K∇V (K = 700 N·m, target disc, dt 5 ms).
        e("gradient-nadf", GRADIENT, &[], "NADF B_d = 10", 12),
        e(
            "gradient-nadf-3",
            GRADIENT,
            &["agents.0.controller.b=3"],
            "NADF B_d = 3",
            12,
        ),
        e(
            "gradient-nadf-30",
            GRADIENT,
            &["agents.0.controller.b=30"],
            "NADF B_d = 30",
            12,
        ),
        e(
            "gradient-nadf-100",
            GRADIENT,
            &["agents.0.controller.b=100"],
            "NADF B_d = 100",
            12,
        ),
        e(
            "gradient-viscous-0.7",
            GRADIENT_VISCOUS,
            &[],
            "viscous B = 0.7",
            30,
        ),
        e(
            "gradient-viscous-0.15",
            GRADIENT_VISCOUS,
            &["agents.0.controller.b=0.15"],
            "viscous B = 0.15",
            30,
        ),
        e(
            "gradient-viscous-0.1",
            GRADIENT_VISCOUS,
            &["agents.0.controller.b=0.1"],
            "viscous B = 0.1",
            30,
        ),
        e(
            "gradient-viscous-0.1-explicit",
            GRADIENT_VISCOUS,
            &[
                "agents.0.controller.b=0.1",
                "agents.0.controller.integration=\"explicit\"",
            ],
            "viscous B = 0.1, explicit step",
            30,
        ),
        // Eq. 2: a body launched at 8 m/s towards the first divider.
        e(
            "launch-nadf",
            "room-initial-velocity.toml",
            &[],
            "NADF B_d = 10",
            6,
        ),
        e(
            "launch-viscous",
            "room-initial-velocity.toml",
            &[
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0.7",
            ],
            "viscous B = 0.7",
            6,
        ),
        e(
            "launch-gradient-nadf",
            "room-initial-velocity.toml",
            &[
                "field.guidance=\"gradient\"",
                "agents.0.controller.k=700",
                "dt=0.005",
            ],
            "NADF B_d = 10, F = −K∇V",
            12,
        ),
        e(
            "launch-gradient-viscous",
            "room-initial-velocity.toml",
            &[
                "field.guidance=\"gradient\"",
                "agents.0.controller.k=700",
                "dt=0.005",
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0.7",
            ],
            "viscous B = 0.7, F = −K∇V",
            12,
        ),
        // §VI.2, figures 19–22: the speed limit (K = 3 N).
        e(
            "speed-limit",
            "room-speed-limit.toml",
            &[],
            "v_max = 5 m/s",
            6,
        ),
        e(
            "speed-unlimited",
            "room-speed-limit.toml",
            &["agents.0.controller.speed_limit=1e9"],
            "no limit",
            6,
        ),
        // §V, §VI.4: a constant drift, the clamp, the bias, the sliding mode.
        e(
            "clamp",
            "room-drift-clamp.toml",
            &[],
            "NADF + clamp K_c = 10",
            2,
        ),
        e(
            "clamp-stiff",
            "room-drift-clamp.toml",
            &["agents.0.controller.clamp.kc=10000"],
            "NADF + clamp K_c = 10⁴",
            2,
        ),
        e(
            "bias",
            "room-drift-bias.toml",
            &[],
            "NADF + clamp + bias",
            2,
        ),
        e("sliding", "room-drift-sliding.toml", &[], "sliding mode", 2),
        e(
            "drift-noise",
            "room-drift-noise.toml",
            &[],
            "walls sensed ±0.5 m",
            2,
        ),
        // §VI.6, figures 37–45: the corridor under Khatib's potential.
        e(
            "corridor-viscous-0.3",
            "corridor-obstruction.toml",
            &[
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0.3",
                "duration=60",
            ],
            "viscous B = 0.3",
            6,
        ),
        e(
            "corridor-viscous-3",
            "corridor-obstruction.toml",
            &[
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=3",
            ],
            "viscous B = 3",
            3,
        ),
        e(
            "corridor-nadf-5",
            "corridor-obstruction.toml",
            &[],
            "NADF B_d = 5",
            3,
        ),
        e(
            "corridor-nadf-30",
            "corridor-obstruction.toml",
            &["agents.0.controller.b=30"],
            "NADF B_d = 30",
            3,
        ),
        e(
            "corridor-clean-30",
            "corridor.toml",
            &["agents.0.controller.b=30"],
            "no noise",
            3,
        ),
        e(
            "corridor-noise",
            "corridor-noise.toml",
            &[],
            "walls ±0.1 m",
            3,
        ),
        e(
            "corridor-position-noise",
            "corridor-position-noise.toml",
            &[],
            "position ±0.05 m",
            3,
        ),
        e(
            "corridor-barrier",
            "corridor-barrier.toml",
            &[],
            "NADF B_d = 30",
            3,
        ),
        e(
            "corridor-obstacles",
            "corridor-obstacles.toml",
            &[],
            "NADF B_d = 5",
            3,
        ),
        // §VI.7, figures 47–52: two robots swap places.
        e("swap-nadf", "swap.toml", &[], "NADF B_d = 10", 4),
        e("swap-viscous", "swap-viscous.toml", &[], "viscous B = 1", 4),
        // The swap under the paper's own law (K = 100 N·m, dt 5 ms).
        e(
            "swap-gradient-nadf",
            "swap.toml",
            &[
                "field.guidance=\"gradient\"",
                "agents.0.controller.k=100",
                "agents.1.controller.k=100",
                "dt=0.005",
            ],
            "NADF B_d = 10, F = −K∇V",
            8,
        ),
        e(
            "swap-gradient-viscous",
            "swap-viscous.toml",
            &[
                "field.guidance=\"gradient\"",
                "agents.0.controller.k=100",
                "agents.1.controller.k=100",
                "dt=0.005",
                "duration=40",
            ],
            "viscous B = 1, F = −K∇V",
            16,
        ),
        // Figure 47: massless agents following their streamlines, the limit B → ∞ with K/B
        // fixed (1 m/s): the exact integration brings each body to K/B along the guidance in
        // one step.
        e(
            "swap-kinematic",
            "swap.toml",
            &[
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=1e4",
                "agents.0.controller.k=1e4",
                "agents.1.controller.kind=\"viscous\"",
                "agents.1.controller.b=1e4",
                "agents.1.controller.k=1e4",
            ],
            "massless, 1 m/s",
            4,
        ),
        // Figure 48: the same planner on 1 kg bodies with no damping.
        e(
            "swap-undamped",
            "swap.toml",
            &[
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=0",
                "agents.1.controller.kind=\"viscous\"",
                "agents.1.controller.b=0",
            ],
            "1 kg, no damping",
            4,
        ),
        // Figure 46: a decentralized planner of kinematic agents self-organizes: the crowd of
        // eight, massless (B → ∞ with K/B = 1 m/s).
        e(
            "crowd-kinematic",
            "crowd.toml",
            &[
                "agents.0.controller.kind=\"viscous\"",
                "agents.0.controller.b=1e4",
                "agents.0.controller.k=1e4",
                "agents.1.controller.kind=\"viscous\"",
                "agents.1.controller.b=1e4",
                "agents.1.controller.k=1e4",
                "agents.2.controller.kind=\"viscous\"",
                "agents.2.controller.b=1e4",
                "agents.2.controller.k=1e4",
                "agents.3.controller.kind=\"viscous\"",
                "agents.3.controller.b=1e4",
                "agents.3.controller.k=1e4",
                "agents.4.controller.kind=\"viscous\"",
                "agents.4.controller.b=1e4",
                "agents.4.controller.k=1e4",
                "agents.5.controller.kind=\"viscous\"",
                "agents.5.controller.b=1e4",
                "agents.5.controller.k=1e4",
                "agents.6.controller.kind=\"viscous\"",
                "agents.6.controller.b=1e4",
                "agents.6.controller.k=1e4",
                "agents.7.controller.kind=\"viscous\"",
                "agents.7.controller.b=1e4",
                "agents.7.controller.k=1e4",
            ],
            "massless, 1 m/s",
            8,
        ),
        // §VI.8, figures 53–56: the pendulum.
        e("pendulum", "pendulum.toml", &[], "u = K e − B θ̇", 2),
        e(
            "pendulum-bias",
            "pendulum-bias.toml",
            &[],
            "with the bias",
            2,
        ),
    ]
}

fn summary<'a>(o: &'a Outcomes, id: &str) -> &'a crate::metrics::Summary {
    o[id].summary()
}

/// The settling time of `id`'s first agent, s (the run's duration when it never settles: a
/// lower bound).
fn settle(o: &Outcomes, id: &str) -> f64 {
    let out = &o[id];
    out.summary().settling_time.unwrap_or(out.world.duration)
}

fn contacts(o: &Outcomes, id: &str) -> f64 {
    summary(o, id).contacts as f64
}

fn deviation(o: &Outcomes, id: &str) -> f64 {
    summary(o, id).max_deviation
}

/// The contacts of `touching`, or −1 when `clean` touched anything too.
fn only_first_touches(o: &Outcomes, touching: &str, clean: &str) -> f64 {
    if contacts(o, clean) > 0.0 {
        return -1.0;
    }
    contacts(o, touching)
}

/// How many times longer `slow` takes to settle than `fast`, or 0 when either touched anything.
fn slower_without_contact(o: &Outcomes, slow: &str, fast: &str) -> f64 {
    if contacts(o, slow) + contacts(o, fast) > 0.0 {
        return 0.0;
    }
    settle(o, slow) / settle(o, fast)
}

/// How many of `id`'s agents reach their targets without any contact.
fn arrived(o: &Outcomes, id: &str) -> f64 {
    (o[id].agents.iter())
        .filter(|s| s.reached && s.contacts == 0)
        .count() as f64
}

fn covered(o: &Outcomes, id: &str) -> f64 {
    summary(o, id).distance_covered.unwrap_or(f64::NAN)
}

/// The lateral RMS speed of `id`'s first agent over the last third of the run, m/s.
fn late_lateral_rms(o: &Outcomes, id: &str) -> f64 {
    let trace = &o[id].trace;
    let late = &trace[2 * trace.len() / 3..];
    (late.iter().map(|s| s.agents[0][3].powi(2)).sum::<f64>() / late.len() as f64).sqrt()
}

/// How far the body moves away from the target again after its first approach inside `sigma`
/// turned (a local minimum of the distance), beyond where it ends, m; 0 for an approach that
/// never turns back (overdamped).
fn rebound(o: &Outcomes, id: &str, sigma: f64) -> f64 {
    let out = &o[id];
    let [tx, ty] = out.world.agents[0].target;
    let d: Vec<f64> = (out.trace.iter())
        .map(|s| (s.agents[0][0] - tx).hypot(s.agents[0][1] - ty))
        .collect();
    let Some(turn) = (1..d.len()).find(|&i| d[i - 1] < sigma && d[i] > d[i - 1] + 1e-6) else {
        return 0.0;
    };
    let end = *d.last().unwrap_or(&0.0);
    d[turn..].iter().fold(0.0_f64, |m, &x| m.max(x - end))
}

/// Every claim, in the paper's order.
pub fn claims() -> Vec<Claim> {
    use Relation::*;
    vec![
        Claim {
            id: "viscous-0.1-collides",
            figure: "room",
            statement: "Viscous damping B = 0.1: the robot collides with the walls (figure 4)",
            paper_number: "collision",
            paper_value: None,
            quantity: "contacts, normalized guidance",
            runs: &["room-viscous-0.1"],
            measure: |o| contacts(o, "room-viscous-0.1"),
            paper: AtLeast(1.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "viscous-0.15-no-collision",
            figure: "room",
            statement: "Viscous damping B = 0.15: large transients, but no collision (figure 5)",
            paper_number: "0 contacts",
            paper_value: None,
            quantity: "contacts, normalized guidance",
            runs: &["room-viscous-0.15"],
            measure: |o| contacts(o, "room-viscous-0.15"),
            paper: AtMost(0.0),
            otherwise: Check {
                verdict: Verdict::Differs,
                relation: AtLeast(1.0),
                reason: "with constant thrust K = 1 N the body still builds up too much speed at B = 0.15 to turn at a divider",
            },
        },
        Claim {
            id: "viscous-0.7-no-collision",
            figure: "room",
            statement: "Viscous damping B = 0.7: no collision, but slow (figures 6–8)",
            paper_number: "0 contacts",
            paper_value: None,
            quantity: "contacts, normalized guidance",
            runs: &["room-viscous-0.7"],
            measure: |o| contacts(o, "room-viscous-0.7"),
            paper: AtMost(0.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "nadf-6x-faster",
            figure: "room",
            statement: "NADF B_d = 10 settles about 6 times faster than viscous B = 0.7, without collision (figures 8–9)",
            paper_number: "6×",
            paper_value: Some(6.0),
            quantity: "settling time viscous B = 0.7 / NADF, normalized guidance",
            runs: &["room-nadf", "room-viscous-0.7"],
            measure: |o| settle(o, "room-viscous-0.7") / settle(o, "room-nadf"),
            paper: AtLeast(6.0),
            otherwise: Check {
                verdict: Verdict::Weaker,
                relation: AtLeast(2.0),
                reason: "constant thrust (normalized guidance) lets the viscous body cross the faint field behind the dividers at full speed; the paper's law widens the gap (next claim)",
            },
        },
        Claim {
            id: "viscous-settling-convex",
            figure: "room-viscous-b",
            statement: "The settling time under viscous damping is convex in B: too little swings, too much crawls (figure 23)",
            paper_number: "a minimum inside the range",
            paper_value: None,
            quantity: "best settling time at B = 0.7 or 1 / best at B = 0.3 or 3",
            runs: &[
                "room-viscous-0.3",
                "room-viscous-0.7",
                "room-viscous-1",
                "room-viscous-3",
            ],
            measure: |o| {
                let inner = settle(o, "room-viscous-0.7").min(settle(o, "room-viscous-1"));
                inner / settle(o, "room-viscous-0.3").min(settle(o, "room-viscous-3"))
            },
            paper: AtMost(0.9),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "gradient-nadf-faster",
            figure: "room-gradient",
            statement: "The same under the paper's own law F = −K∇V (K = 700 N·m, target disc 0.2 m)",
            paper_number: "6×",
            paper_value: Some(6.0),
            quantity: "settling time viscous B = 0.7 / NADF, gradient guidance",
            runs: &["gradient-nadf", "gradient-viscous-0.7"],
            measure: |o| settle(o, "gradient-viscous-0.7") / settle(o, "gradient-nadf"),
            paper: AtLeast(6.0),
            otherwise: Check {
                verdict: Verdict::Weaker,
                relation: AtLeast(3.5),
                reason: "the ratio depends on K (500: 4.7×, 700: 4.1×, 1000: 3.4×); an independent point-mass reference gives 3.7×",
            },
        },
        Claim {
            id: "gradient-viscous-0.1-collides",
            figure: "room-gradient",
            statement: "Viscous damping B = 0.1 collides (figure 4), under the paper's own law",
            paper_number: "collision",
            paper_value: None,
            quantity: "contacts, gradient guidance, integrated exactly",
            runs: &["gradient-viscous-0.1"],
            measure: |o| contacts(o, "gradient-viscous-0.1"),
            paper: AtLeast(1.0),
            otherwise: Check {
                verdict: Verdict::Differs,
                relation: AtMost(0.0),
                reason: "Proposition 1 holds for any damping: K·V + ½m|v|² never grows, so a body starting at rest cannot climb to V = 1 at a wall",
            },
        },
        Claim {
            id: "gradient-viscous-0.1-explicit-collides",
            figure: "room-gradient",
            statement: "… and with the explicit step of a textbook simulation",
            paper_number: "collision",
            paper_value: None,
            quantity: "contacts, gradient guidance, explicit step",
            runs: &["gradient-viscous-0.1-explicit"],
            measure: |o| contacts(o, "gradient-viscous-0.1-explicit"),
            paper: AtLeast(1.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "gradient-viscous-0.15-transients",
            figure: "room-gradient",
            statement: "B = 0.15 has large transients without collision (figure 5), paper's law",
            paper_number: "larger than B = 0.7",
            paper_value: None,
            quantity: "δ_m at B = 0.15 / δ_m at B = 0.7",
            runs: &["gradient-viscous-0.15", "gradient-viscous-0.7"],
            measure: |o| {
                if contacts(o, "gradient-viscous-0.15") > 0.0 {
                    return 0.0;
                }
                deviation(o, "gradient-viscous-0.15") / deviation(o, "gradient-viscous-0.7")
            },
            paper: AtLeast(1.2),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "delta-m-falls",
            figure: "room-b-d",
            statement: "δ_m falls as B_d grows: it can be made arbitrarily small (Proposition 2, figure 24)",
            paper_number: "falls",
            paper_value: None,
            quantity: "δ_m(B_d = 30) / δ_m(B_d = 3), normalized guidance",
            runs: &["room-nadf-3", "room-nadf-30"],
            measure: |o| deviation(o, "room-nadf-30") / deviation(o, "room-nadf-3"),
            paper: AtMost(0.9),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "gradient-delta-m-falls",
            figure: "room-b-d",
            statement: "… under the paper's own law",
            paper_number: "falls",
            paper_value: None,
            quantity: "δ_m(B_d = 100) / δ_m(B_d = 3), gradient guidance",
            runs: &["gradient-nadf-3", "gradient-nadf-100"],
            measure: |o| deviation(o, "gradient-nadf-100") / deviation(o, "gradient-nadf-3"),
            paper: AtMost(0.9),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "settling-falls",
            figure: "room-b-d",
            statement: "The settling time falls as B_d grows (figure 24)",
            paper_number: "falls",
            paper_value: None,
            quantity: "settling time B_d = 30 / B_d = 1, normalized guidance",
            runs: &["room-nadf-1", "room-nadf-30"],
            measure: |o| settle(o, "room-nadf-30") / settle(o, "room-nadf-1"),
            paper: AtMost(0.95),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "launch",
            figure: "launch",
            statement: "Viscous damping keeps a body off the walls only below an admissible initial speed (eq. 2); NADF from any",
            paper_number: "viscous hits, NADF does not",
            paper_value: None,
            quantity: "contacts viscous B = 0.7 − contacts NADF, from 8 m/s at a divider",
            runs: &["launch-viscous", "launch-nadf"],
            measure: |o| only_first_touches(o, "launch-viscous", "launch-nadf"),
            paper: AtLeast(1.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "launch-gradient",
            figure: "launch",
            statement: "… under the paper's own law (K = 700 N·m)",
            paper_number: "viscous hits, NADF does not",
            paper_value: None,
            quantity: "contacts viscous B = 0.7 − contacts NADF, gradient guidance",
            runs: &["launch-gradient-viscous", "launch-gradient-nadf"],
            measure: |o| only_first_touches(o, "launch-gradient-viscous", "launch-gradient-nadf"),
            paper: AtLeast(1.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "speed-limit-cost",
            figure: "speed-limit",
            statement: "A 5 m/s speed limit costs settling time: 12 s → 16 s (figures 19–22)",
            paper_number: "+33 %",
            paper_value: Some(16.0 / 12.0),
            quantity: "settling time with / without the limit",
            runs: &["speed-limit", "speed-unlimited"],
            measure: |o| settle(o, "speed-limit") / settle(o, "speed-unlimited"),
            paper: AtLeast(1.25),
            otherwise: Check {
                verdict: Verdict::Weaker,
                relation: AtLeast(1.0),
                reason: "in this room the unlimited body peaks at 6.2 m/s, so a 5 m/s cap bites only briefly",
            },
        },
        Claim {
            id: "speed-limit-effort",
            figure: "speed-limit",
            statement: "… and lowers the control effort (figures 19–22)",
            paper_number: "lower peak force",
            paper_value: None,
            quantity: "peak control force with / without the limit",
            runs: &["speed-limit", "speed-unlimited"],
            measure: |o| {
                summary(o, "speed-limit").peak_force / summary(o, "speed-unlimited").peak_force
            },
            paper: AtMost(0.9),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "drift-noise",
            figure: "clamp",
            statement: "With the walls sensed through noise the robot still reaches its target without collision (figures 34–36)",
            paper_number: "no collision",
            paper_value: None,
            quantity: "contacts, walls sensed ±0.5 m at 10 Hz, drift and clamp",
            runs: &["drift-noise"],
            measure: |o| {
                if summary(o, "drift-noise").reached {
                    contacts(o, "drift-noise")
                } else {
                    f64::INFINITY
                }
            },
            paper: AtMost(0.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "clamp-rest",
            figure: "clamp",
            statement: "Under a constant external force the clamp holds the body at the rest point of eq. 47",
            paper_number: "m|a|/(K/r_c + K_c) = 0.2176 m",
            paper_value: Some(0.2176),
            quantity: "final distance to the target, m",
            runs: &["clamp"],
            measure: |o| summary(o, "clamp").final_error,
            paper: Within(0.2176 * 0.98, 0.2176 * 1.02),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "clamp-overdamped",
            figure: "clamp",
            statement: "The clamped approach is overdamped: no overshoot (figures 27–29)",
            paper_number: "no overshoot",
            paper_value: None,
            quantity: "rebound after the first turn inside σ, m",
            runs: &["clamp"],
            measure: |o| rebound(o, "clamp", 0.5),
            paper: AtMost(0.01),
            otherwise: Check {
                verdict: Verdict::Differs,
                relation: AtLeast(0.01),
                reason: "the body enters σ at 10 m/s; the clamp acts only while it moves away, so it passes the rest point and swings back once",
            },
        },
        Claim {
            id: "clamp-proposition-3",
            figure: "clamp",
            statement: "K_c ≥ F_max/ε keeps the error under ε (Proposition 3): K_c = 10⁴ against 5.66 N",
            paper_number: "≤ 0.57 mm",
            paper_value: Some(0.5657),
            quantity: "final distance to the target, mm",
            runs: &["clamp-stiff"],
            measure: |o| 1e3 * summary(o, "clamp-stiff").final_error,
            paper: AtMost(1e3 * 32f64.sqrt() / 1e4),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "bias-cancels",
            figure: "clamp",
            statement: "The iterative bias cancels the error the external force leaves (eq. 48–50)",
            paper_number: "error → 0",
            paper_value: None,
            quantity: "final distance to the target, mm",
            runs: &["bias"],
            measure: |o| 1e3 * summary(o, "bias").final_error,
            paper: AtMost(1.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "sliding-chatters",
            figure: "sliding",
            statement: "Sliding mode at the same settling time chatters far more than NADF with clamping (figures 30–33)",
            paper_number: "chatter",
            paper_value: None,
            quantity: "control variation sliding / NADF",
            runs: &["sliding", "clamp"],
            measure: |o| {
                summary(o, "sliding").control_variation / summary(o, "clamp").control_variation
            },
            paper: AtLeast(10.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "corridor-viscous-distance",
            figure: "corridor",
            statement: "Viscous B = 0.3 covers about 25 m in 10 s past the block (figure 38)",
            paper_number: "25 m",
            paper_value: Some(25.0),
            quantity: "distance at 10 s, m",
            runs: &["corridor-viscous-0.3"],
            measure: |o| covered(o, "corridor-viscous-0.3"),
            paper: Within(20.0, 30.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "corridor-viscous-sustained",
            figure: "corridor",
            statement: "… and oscillates between the walls, sustained (figure 38)",
            paper_number: "sustained",
            paper_value: None,
            quantity: "lateral RMS speed over the last third of 60 s, m/s",
            runs: &["corridor-viscous-0.3"],
            measure: |o| late_lateral_rms(o, "corridor-viscous-0.3"),
            paper: AtLeast(0.1),
            otherwise: Check {
                verdict: Verdict::Differs,
                relation: AtMost(0.05),
                reason: "the oscillation decays (0.45, 0.025, 0.002 m/s over the thirds): the walls' repulsion and B = 0.3 damp it",
            },
        },
        Claim {
            id: "corridor-viscous-crawls",
            figure: "corridor",
            statement: "Viscous B = 3 crawls: about 4 m in 10 s (figure 39)",
            paper_number: "4 m",
            paper_value: Some(4.0),
            quantity: "distance at 10 s, m",
            runs: &["corridor-viscous-3"],
            measure: |o| covered(o, "corridor-viscous-3"),
            paper: Within(2.0, 6.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "corridor-nadf-twice",
            figure: "corridor",
            statement: "NADF B_d = 5 travels more than twice as far as viscous B = 0.3 (figure 40)",
            paper_number: "> 2×",
            paper_value: Some(2.0),
            quantity: "distance at 10 s, NADF B_d = 5 / viscous B = 0.3",
            runs: &["corridor-nadf-5", "corridor-viscous-0.3"],
            measure: |o| covered(o, "corridor-nadf-5") / covered(o, "corridor-viscous-0.3"),
            paper: AtLeast(2.0),
            otherwise: Check {
                verdict: Verdict::Weaker,
                relation: AtLeast(1.2),
                reason: "NADF damps the motion into the block's repulsion: the body meets it at 3 m/s and leaves at 0.6 m/s",
            },
        },
        Claim {
            id: "corridor-nadf-30-same",
            figure: "corridor",
            statement: "NADF B_d = 30 travels as far as B_d = 5 (figure 41)",
            paper_number: "the same",
            paper_value: Some(1.0),
            quantity: "distance at 10 s, B_d = 30 / B_d = 5",
            runs: &["corridor-nadf-30", "corridor-nadf-5"],
            measure: |o| covered(o, "corridor-nadf-30") / covered(o, "corridor-nadf-5"),
            paper: Within(0.9, 1.1),
            otherwise: Check {
                verdict: Verdict::Differs,
                relation: AtLeast(1.1),
                reason: "B_d = 30 goes farther (1.5×): stronger sideways damping deflects it less at the block",
            },
        },
        Claim {
            id: "corridor-noise",
            figure: "corridor-noise",
            statement: "With noisy wall readings the travel distance is unaffected (figure 42)",
            paper_number: "unaffected",
            paper_value: Some(1.0),
            quantity: "distance at 10 s, walls ±0.1 m / no noise",
            runs: &["corridor-noise", "corridor-clean-30"],
            measure: |o| covered(o, "corridor-noise") / covered(o, "corridor-clean-30"),
            paper: AtLeast(0.95),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "corridor-position-noise",
            figure: "corridor-noise",
            statement: "… and with a noisy estimate of the robot's position",
            paper_number: "unaffected",
            paper_value: Some(1.0),
            quantity: "distance at 10 s, position ±0.05 m / no noise",
            runs: &["corridor-position-noise", "corridor-clean-30"],
            measure: |o| covered(o, "corridor-position-noise") / covered(o, "corridor-clean-30"),
            paper: AtLeast(0.95),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "corridor-barrier",
            figure: "corridor-barrier",
            statement: "Before a barrier NADF brakes to a stop without touching it (figures 43–44)",
            paper_number: "stops, no contact",
            paper_value: None,
            quantity: "contacts + final speed (m/s)",
            runs: &["corridor-barrier"],
            measure: |o| {
                contacts(o, "corridor-barrier") + summary(o, "corridor-barrier").final_speed
            },
            paper: AtMost(0.01),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "corridor-obstacles",
            figure: "corridor-barrier",
            statement: "NADF weaves through alternating obstructions without contact (figure 45)",
            paper_number: "no contact",
            paper_value: None,
            quantity: "contacts",
            runs: &["corridor-obstacles"],
            measure: |o| contacts(o, "corridor-obstacles"),
            paper: AtMost(0.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "crowd-kinematic",
            figure: "crowd-kinematic",
            statement: "A decentralized planner of kinematic agents, each with the others as obstacles, self-organizes (figure 46)",
            paper_number: "all arrive, no contact",
            paper_value: Some(8.0),
            quantity: "agents of 8 crossing a room that arrive without contact",
            runs: &["crowd-kinematic"],
            measure: |o| arrived(o, "crowd-kinematic"),
            paper: AtLeast(8.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "swap-kinematic",
            figure: "swap-kinematic",
            statement: "Massless agents following their harmonic streamlines swap places without contact (figure 47)",
            paper_number: "both arrive, no contact",
            paper_value: Some(2.0),
            quantity: "agents that arrive without contact (of 2)",
            runs: &["swap-kinematic"],
            measure: |o| arrived(o, "swap-kinematic"),
            paper: AtLeast(2.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "swap-undamped-fails",
            figure: "swap-kinematic",
            statement: "Give the agents 1 kg and no damping, and the kinematic planner fails (figure 48)",
            paper_number: "fails",
            paper_value: None,
            quantity: "agents that arrive without contact (of 2)",
            runs: &["swap-undamped"],
            measure: |o| arrived(o, "swap-undamped"),
            paper: AtMost(1.0),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "swap-faster",
            figure: "swap",
            statement: "Two robots swap places without contact, NADF about 6.5 times faster than viscous damping (figures 49–52)",
            paper_number: "6.5×",
            paper_value: Some(6.5),
            quantity: "settling time of robot 1, viscous / NADF",
            runs: &["swap-nadf", "swap-viscous"],
            measure: |o| slower_without_contact(o, "swap-viscous", "swap-nadf"),
            paper: AtLeast(6.5),
            otherwise: Check {
                verdict: Verdict::Weaker,
                relation: AtLeast(2.0),
                reason: "the viscous B = 1 robots are not slowed by a faint field here: the room is open",
            },
        },
        Claim {
            id: "swap-gradient-faster",
            figure: "swap",
            statement: "… under the paper's own law (K = 100 N·m)",
            paper_number: "6.5×",
            paper_value: Some(6.5),
            quantity: "settling time of robot 1, viscous / NADF, gradient guidance",
            runs: &["swap-gradient-nadf", "swap-gradient-viscous"],
            measure: |o| slower_without_contact(o, "swap-gradient-viscous", "swap-gradient-nadf"),
            paper: AtLeast(6.5),
            otherwise: Check {
                verdict: Verdict::Weaker,
                relation: AtLeast(3.5),
                reason: "as in the room, the ratio falls as K grows (K = 100: 4.1×, 300: 2.4×, 1000: 1.5×); at K = 30 the viscous robots do not arrive in 60 s",
            },
        },
        Claim {
            id: "pendulum-static-error",
            figure: "pendulum",
            statement: "Under gravity u = K e − B θ̇ leaves a steady-state error (figure 54)",
            paper_number: "K e = M g L cos e: 0.4435 rad",
            paper_value: Some(0.4435),
            quantity: "final error, rad",
            runs: &["pendulum"],
            measure: |o| o["pendulum"].pendulums[0].final_error,
            paper: Within(0.4435 - 0.001, 0.4435 + 0.001),
            otherwise: REPRODUCED,
        },
        Claim {
            id: "pendulum-bias",
            figure: "pendulum",
            statement: "The iterative bias removes it (figures 55–56)",
            paper_number: "error → 0",
            paper_value: None,
            quantity: "|final error|, mrad",
            runs: &["pendulum-bias"],
            measure: |o| 1e3 * o["pendulum-bias"].pendulums[0].final_error.abs(),
            paper: AtMost(1.0),
            otherwise: REPRODUCED,
        },
    ]
}

/// Every figure, in the paper's order.
pub fn figures() -> Vec<Figure> {
    let f = |id, title, panel| Figure { id, title, panel };
    vec![
        f(
            "room",
            "Figures 4–9: the room, normalized guidance (K = 1 N)",
            Panel::Paths(&[
                "room-viscous-0.1",
                "room-viscous-0.15",
                "room-viscous-0.7",
                "room-nadf",
            ]),
        ),
        f(
            "room-viscous-b",
            "Figure 23: settling time against viscous damping B (normalized guidance)",
            Panel::Settling(&[
                "room-viscous-0.1",
                "room-viscous-0.15",
                "room-viscous-0.3",
                "room-viscous-0.7",
                "room-viscous-1",
                "room-viscous-3",
            ]),
        ),
        f(
            "room-gradient",
            "The room under the paper's own law F = −K∇V (K = 700 N·m)",
            Panel::Paths(&[
                "gradient-viscous-0.1-explicit",
                "gradient-viscous-0.1",
                "gradient-viscous-0.7",
                "gradient-nadf",
            ]),
        ),
        f(
            "room-b-d",
            "Figure 24: distance to the target as B_d grows (normalized guidance)",
            Panel::Distance(&["room-nadf-1", "room-nadf-3", "room-nadf", "room-nadf-30"]),
        ),
        f(
            "launch",
            "Eq. 2: launched at 8 m/s towards the first divider",
            Panel::Paths(&[
                "launch-viscous",
                "launch-nadf",
                "launch-gradient-viscous",
                "launch-gradient-nadf",
            ]),
        ),
        f(
            "speed-limit",
            "Figures 19–22: speed with and without a 5 m/s limit",
            Panel::Speed(&["speed-unlimited", "speed-limit"]),
        ),
        f(
            "clamp",
            "Figures 27–29: distance to the target under a constant drift",
            Panel::Distance(&["clamp", "clamp-stiff", "bias", "drift-noise"]),
        ),
        f(
            "sliding",
            "Figures 30–33: the control force, sliding mode against NADF with clamping",
            Panel::Force(&["sliding", "clamp"]),
        ),
        f(
            "corridor",
            "Figures 38–41: the corridor with a block (Khatib's potential)",
            Panel::Lateral(&[
                "corridor-viscous-0.3",
                "corridor-viscous-3",
                "corridor-nadf-5",
                "corridor-nadf-30",
            ]),
        ),
        f(
            "corridor-noise",
            "Figure 42: the empty corridor with sensor noise (NADF B_d = 30)",
            Panel::Lateral(&[
                "corridor-clean-30",
                "corridor-noise",
                "corridor-position-noise",
            ]),
        ),
        f(
            "corridor-barrier",
            "Figures 43–45: a barrier, and alternating obstructions",
            Panel::Lateral(&["corridor-barrier", "corridor-obstacles"]),
        ),
        f(
            "crowd-kinematic",
            "Figure 46: eight kinematic agents cross a room, each planning around the others",
            Panel::Paths(&["crowd-kinematic"]),
        ),
        f(
            "swap-kinematic",
            "Figures 47–48: the kinematic swap, and the same planner on 1 kg bodies without damping",
            Panel::Paths(&["swap-kinematic", "swap-undamped"]),
        ),
        f(
            "swap",
            "Figures 49–52: two robots swap places",
            Panel::Paths(&[
                "swap-viscous",
                "swap-nadf",
                "swap-gradient-viscous",
                "swap-gradient-nadf",
            ]),
        ),
        f(
            "pendulum",
            "Figures 54–56: the pendulum's error under gravity",
            Panel::Angle(&["pendulum", "pendulum-bias"]),
        ),
    ]
}
