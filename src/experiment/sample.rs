//! Samplers of world values (`[experiment.sample]`): each draws one value of its key per run
//! from the run's own stream, so run `k` is the same whatever runs beside it.

use nalgebra::Vector2;
use serde::Deserialize;

use crate::random::SplitMix;
use crate::sim::WallIndex;
use crate::world::{World, all_wall_shapes};

/// How one key is sampled, as the experiment file writes it (one key per inline table).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Sampler {
    /// `uniform = [low, high]`: a real uniformly in `[low, high)`.
    Uniform(Vec<f64>),
    /// `normal = [mean, sd]`: a real from a normal distribution.
    Normal(Vec<f64>),
    /// `int = [low, high]`: an integer uniformly in `low..=high`.
    Int(Vec<i64>),
    /// `choice = [a, b, ...]`: one of the values, each equally likely.
    Choice(Vec<toml::Value>),
    /// `free_point = { clearance = c }`: a point where the agent's disc keeps `c` metres from
    /// every wall and the box's edges, connected to the agent's target (for `agents.N.start`
    /// and `agents.N.target`).
    FreePoint(FreePoint),
}

/// The parameters of [`Sampler::FreePoint`].
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FreePoint {
    /// The least gap between the agent's disc and any wall, m.
    #[serde(default)]
    pub clearance: f64,
}

/// One sampled value.
#[derive(Debug, Clone, PartialEq)]
pub enum Sampled {
    /// A real number.
    Real(f64),
    /// An integer.
    Int(i64),
    /// Yes or no.
    Flag(bool),
    /// Text.
    Text(String),
    /// A point, m.
    Point([f64; 2]),
    /// Any other TOML value (a choice of arrays or tables), as TOML text.
    Other(String),
}

impl Sampled {
    /// The value as the TOML text of a `--set` override (`{:?}` keeps a real's decimal point).
    pub fn toml(&self) -> String {
        match self {
            Self::Real(x) => format!("{x:?}"),
            Self::Int(n) => n.to_string(),
            Self::Flag(b) => b.to_string(),
            Self::Text(s) => toml::Value::String(s.clone()).to_string(),
            Self::Point([x, y]) => format!("[{x:?}, {y:?}]"),
            Self::Other(text) => text.clone(),
        }
    }

    /// The value of a TOML `value` (a choice).
    fn of(value: &toml::Value) -> Self {
        match value {
            toml::Value::Float(x) => Self::Real(*x),
            toml::Value::Integer(n) => Self::Int(*n),
            toml::Value::Boolean(b) => Self::Flag(*b),
            toml::Value::String(s) => Self::Text(s.clone()),
            other => Self::Other(other.to_string()),
        }
    }
}

/// The column type of a sampler's values in the results.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Column {
    /// Reals (a choice of numbers mixing integers and reals too).
    Real,
    /// Integers.
    Int,
    /// Yes or no.
    Flag,
    /// Text (a choice of strings, or of values of mixed kinds as TOML text).
    Text,
    /// A point: two real columns, `KEY.x` and `KEY.y`.
    Point,
}

impl Sampler {
    /// What is wrong with the sampler's parameters, if anything.
    pub fn check(&self) -> Result<(), String> {
        let pair = |name: &str, v: &[f64]| match v {
            [a, b] if a.is_finite() && b.is_finite() => Ok((*a, *b)),
            _ => Err(format!(
                "`{name}` takes two finite numbers, got {} value(s)",
                v.len()
            )),
        };
        match self {
            Self::Uniform(v) => {
                let (a, b) = pair("uniform", v)?;
                (a < b).then_some(()).ok_or(format!(
                    "uniform = [{a}, {b}]: the low end must be below the high"
                ))
            }
            Self::Normal(v) => {
                let (_, sd) = pair("normal", v)?;
                (sd >= 0.0).then_some(()).ok_or(format!(
                    "normal = [mean, sd]: the standard deviation must be ≥ 0, got {sd}"
                ))
            }
            Self::Int(v) => match v.as_slice() {
                [a, b] if a <= b => Ok(()),
                [a, b] => Err(format!(
                    "int = [{a}, {b}]: the low end must not exceed the high"
                )),
                _ => Err(format!(
                    "`int` takes two integers, got {} value(s)",
                    v.len()
                )),
            },
            Self::Choice(v) if v.is_empty() => Err("`choice` needs at least one value".into()),
            Self::Choice(_) => Ok(()),
            Self::FreePoint(p) if !(p.clearance >= 0.0 && p.clearance.is_finite()) => Err(format!(
                "free_point: the clearance must be a finite number ≥ 0 m, got {}",
                p.clearance
            )),
            Self::FreePoint(_) => Ok(()),
        }
    }

    /// The column its values fill.
    pub fn column(&self) -> Column {
        match self {
            Self::Uniform(_) | Self::Normal(_) => Column::Real,
            Self::Int(_) => Column::Int,
            Self::FreePoint(_) => Column::Point,
            Self::Choice(values) => {
                let all = |f: fn(&toml::Value) -> bool| values.iter().all(f);
                if all(|v| v.is_integer()) {
                    Column::Int
                } else if all(|v| v.is_float() || v.is_integer()) {
                    Column::Real
                } else if all(|v| v.is_bool()) {
                    Column::Flag
                } else {
                    Column::Text
                }
            }
        }
    }

    /// A value drawn from `rng`; `None` for a free point, which is drawn in its world by
    /// [`free_point`].
    pub fn draw(&self, rng: &mut SplitMix) -> Option<Sampled> {
        Some(match self {
            Self::Uniform(v) => Sampled::Real(v[0] + (v[1] - v[0]) * rng.uniform()),
            Self::Normal(v) => Sampled::Real(v[0] + v[1] * rng.normal()),
            Self::Int(v) => {
                let span = v[1].abs_diff(v[0]).saturating_add(1);
                Sampled::Int(v[0].wrapping_add((rng.next_u64() % span) as i64))
            }
            Self::Choice(values) => {
                let value = &values[(rng.next_u64() % values.len() as u64) as usize];
                match (self.column(), value) {
                    (Column::Real, toml::Value::Integer(n)) => Sampled::Real(*n as f64),
                    (Column::Text, v) if !v.is_str() => Sampled::Other(v.to_string()),
                    (_, v) => Sampled::of(v),
                }
            }
            Self::FreePoint(_) => return None,
        })
    }
}

/// Tries for a free point before giving up.
pub const FREE_POINT_TRIES: usize = 100_000;

/// A point of `world`'s box drawn from `rng` where a disc of `radius` keeps `clearance` from
/// every wall and from the box's edges; `None` after [`FREE_POINT_TRIES`] draws that all miss.
pub fn free_point(
    world: &World,
    (walls, index): (&[crate::world::WallShape], &WallIndex),
    radius: f64,
    clearance: f64,
    rng: &mut SplitMix,
) -> Option<[f64; 2]> {
    let ([x0, y0], [x1, y1]) = world.bounds();
    let margin = radius + clearance;
    let (lo, hi) = ([x0 + margin, y0 + margin], [x1 - margin, y1 - margin]);
    if lo[0] >= hi[0] || lo[1] >= hi[1] {
        return None;
    }
    (0..FREE_POINT_TRIES).find_map(|_| {
        let p = [
            lo[0] + (hi[0] - lo[0]) * rng.uniform(),
            lo[1] + (hi[1] - lo[1]) * rng.uniform(),
        ];
        let clear = index.signed_clearance(walls, Vector2::from(p), radius) >= clearance;
        clear.then_some(p)
    })
}

/// The world's walls and their index, for [`free_point`].
pub fn walls_of(world: &World) -> (Vec<crate::world::WallShape>, WallIndex) {
    let walls = all_wall_shapes(world);
    let index = WallIndex::new(&walls);
    (walls, index)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_stay_in_their_ranges_and_choices_keep_their_kind() {
        let mut rng = SplitMix::new(3);
        for _ in 0..1000 {
            match Sampler::Uniform(vec![3.0, 30.0]).draw(&mut rng).unwrap() {
                Sampled::Real(x) => assert!((3.0..30.0).contains(&x)),
                other => panic!("{other:?}"),
            }
            match Sampler::Int(vec![-2, 2]).draw(&mut rng).unwrap() {
                Sampled::Int(n) => assert!((-2..=2).contains(&n)),
                other => panic!("{other:?}"),
            }
        }
        let mixed = Sampler::Choice(vec![toml::Value::Integer(1), toml::Value::Float(2.5)]);
        assert_eq!(mixed.column(), Column::Real);
        let drawn: Vec<_> = (0..50).map(|_| mixed.draw(&mut rng).unwrap()).collect();
        assert!(drawn.contains(&Sampled::Real(1.0)) && drawn.contains(&Sampled::Real(2.5)));
        let kinds = Sampler::Choice(vec!["nadf".into(), "viscous".into()]);
        assert_eq!(kinds.column(), Column::Text);
        assert_eq!(
            kinds.draw(&mut rng).unwrap().toml().chars().next(),
            Some('"')
        );
    }

    #[test]
    fn a_normal_draw_has_its_mean_and_spread() {
        let mut rng = SplitMix::new(11);
        let xs: Vec<f64> = (0..20_000)
            .map(
                |_| match Sampler::Normal(vec![5.0, 2.0]).draw(&mut rng).unwrap() {
                    Sampled::Real(x) => x,
                    other => panic!("{other:?}"),
                },
            )
            .collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64).sqrt();
        assert!(
            (mean - 5.0).abs() < 0.05 && (sd - 2.0).abs() < 0.05,
            "{mean} {sd}"
        );
    }

    #[test]
    fn bad_parameters_are_refused_with_the_reason() {
        let bad = [
            (Sampler::Uniform(vec![3.0]), "two finite numbers"),
            (Sampler::Uniform(vec![30.0, 3.0]), "low end"),
            (Sampler::Normal(vec![0.0, -1.0]), "standard deviation"),
            (Sampler::Int(vec![5, 1]), "low end"),
            (Sampler::Choice(vec![]), "at least one"),
            (
                Sampler::FreePoint(FreePoint { clearance: -1.0 }),
                "clearance",
            ),
        ];
        for (sampler, says) in bad {
            let e = sampler.check().unwrap_err();
            assert!(e.contains(says), "{e}");
        }
    }
}
