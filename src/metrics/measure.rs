//! A metric is declared once: the [`measured!`](crate::measured) macro declares a struct of
//! measured values together with, from the same lines, the description of each metric (its
//! key, unit, digits shown, and column of the printed table). Everything that lists metrics
//! reads that description: the CSV of a sweep, the table `nadf run` prints, the expectations a
//! world file may state (`max_<metric>`, `min_<metric>`, `<metric> = value`), and the test of
//! the JSON summary's keys.

use std::fmt;

/// What kind of value a metric holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Yes or no (`reached`).
    Flag,
    /// A whole number (`contacts`).
    Count,
    /// A real number (`min_clearance`).
    Real,
    /// A real number that may be missing (`settling_time`: never settled).
    OptionalReal,
}

/// The description of one metric.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Metric {
    /// Its key in the JSON summary, the CSV header and expectations.
    pub key: &'static str,
    /// What kind of value it holds.
    pub kind: Kind,
    /// Its unit, as printed after a value (`""` for none).
    pub unit: &'static str,
    /// Digits after the decimal point when a real value is printed.
    pub digits: usize,
    /// Its header in the table `nadf run` prints, if it has a column there.
    pub column: Option<&'static str>,
    /// What a missing value is printed as (an optional metric).
    pub missing: &'static str,
}

impl Metric {
    /// A metric with no unit, 3 digits, no column, printed `-` when missing.
    pub const fn new(key: &'static str, kind: Kind) -> Self {
        Self {
            key,
            kind,
            unit: "",
            digits: 3,
            column: None,
            missing: "-",
        }
    }

    /// With the unit `unit`.
    pub const fn unit(self, unit: &'static str) -> Self {
        Self { unit, ..self }
    }

    /// Printed with `digits` digits after the decimal point.
    pub const fn digits(self, digits: usize) -> Self {
        Self { digits, ..self }
    }

    /// With a column headed `header` in the printed table.
    pub const fn column(self, header: &'static str) -> Self {
        Self {
            column: Some(header),
            ..self
        }
    }

    /// A missing value printed as `missing`.
    pub const fn missing(self, missing: &'static str) -> Self {
        Self { missing, ..self }
    }

    /// `value` as a person reads it: `yes`/`no`, a whole number, a real with this metric's
    /// digits, or the missing text.
    pub fn show(&self, value: Value) -> String {
        match value {
            Value::Flag(b) => if b { "yes" } else { "no" }.to_string(),
            Value::Count(n) => n.to_string(),
            Value::Real(x) => format!("{x:.*}", self.digits),
            Value::Missing => self.missing.to_string(),
        }
    }

    /// `value` followed by the unit, if any.
    pub fn show_with_unit(&self, value: Value) -> String {
        let shown = match value {
            // An expectation reads `reached = false, expected true`.
            Value::Flag(b) => b.to_string(),
            other => self.show(other),
        };
        if self.unit.is_empty() || value == Value::Missing {
            shown
        } else {
            format!("{shown} {}", self.unit)
        }
    }
}

/// One measured value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// Of a [`Kind::Flag`] metric.
    Flag(bool),
    /// Of a [`Kind::Count`] metric.
    Count(usize),
    /// Of a [`Kind::Real`] or [`Kind::OptionalReal`] metric.
    Real(f64),
    /// An optional metric without a value.
    Missing,
}

impl Value {
    /// The value as a number (flags as 0 or 1), if it has one.
    pub fn number(self) -> Option<f64> {
        match self {
            Value::Flag(b) => Some(if b { 1.0 } else { 0.0 }),
            Value::Count(n) => Some(n as f64),
            Value::Real(x) => Some(x),
            Value::Missing => None,
        }
    }
}

/// A CSV cell: `true`/`false`, the number in full precision, or empty when missing.
impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Flag(b) => write!(f, "{b}"),
            Value::Count(n) => write!(f, "{n}"),
            Value::Real(x) => write!(f, "{x}"),
            Value::Missing => Ok(()),
        }
    }
}

/// A type whose values are metrics: a leaf (`bool`, `usize`, `f64`, `Option<f64>`), a label
/// that is not a metric (`String`), or a struct declared with [`measured!`](crate::measured),
/// whose fields' metrics it lists in order.
pub trait Measured {
    /// Appends the metrics of a field of this type, declared as `declared`.
    fn describe(declared: Metric, out: &mut Vec<Metric>);
    /// Appends this value's measurements, in the order of [`Measured::describe`].
    fn values(&self, out: &mut Vec<Value>);
}

/// Every metric of `T`, in order.
pub fn metrics_of<T: Measured>() -> Vec<Metric> {
    let mut out = Vec::new();
    T::describe(Metric::new("", Kind::Real), &mut out);
    out
}

/// Every measurement of `x`, in the order of [`metrics_of`].
pub fn values_of<T: Measured>(x: &T) -> Vec<Value> {
    let mut out = Vec::new();
    x.values(&mut out);
    out
}

/// Each metric of `x` with its value.
pub fn measurements<T: Measured>(x: &T) -> impl Iterator<Item = (Metric, Value)> {
    metrics_of::<T>().into_iter().zip(values_of(x))
}

macro_rules! leaf {
    ($ty:ty, $kind:expr, |$x:ident| $value:expr) => {
        impl Measured for $ty {
            fn describe(declared: Metric, out: &mut Vec<Metric>) {
                out.push(Metric {
                    kind: $kind,
                    ..declared
                });
            }
            fn values(&self, out: &mut Vec<Value>) {
                let $x = self;
                out.push($value);
            }
        }
    };
}

leaf!(bool, Kind::Flag, |b| Value::Flag(*b));
leaf!(usize, Kind::Count, |n| Value::Count(*n));
leaf!(f64, Kind::Real, |x| Value::Real(*x));
leaf!(Option<f64>, Kind::OptionalReal, |x| x
    .map_or(Value::Missing, Value::Real));

/// A label (an agent's name): not a metric.
impl Measured for String {
    fn describe(_: Metric, _: &mut Vec<Metric>) {}
    fn values(&self, _: &mut Vec<Value>) {}
}

/// Declares a struct of measured values and implements [`Measured`] for it from the same
/// lines: each field is a metric (its key is the field's name) described by the builder calls
/// in brackets after its type, `[unit("s"), digits(2), column("settle_s")]` (see
/// [`Metric`]'s methods). Adding a metric to a summary is adding a field here.
#[macro_export]
macro_rules! measured {
    (
        $(#[$attr:meta])*
        pub struct $name:ident {
            $(
                $(#[$field_attr:meta])*
                pub $field:ident: $ty:ty $([$($how:ident($arg:expr)),* $(,)?])?,
            )*
        }
    ) => {
        $(#[$attr])*
        pub struct $name {
            $( $(#[$field_attr])* pub $field: $ty, )*
        }

        impl $crate::metrics::Measured for $name {
            fn describe(
                _: $crate::metrics::Metric,
                out: &mut Vec<$crate::metrics::Metric>,
            ) {
                $(
                    <$ty as $crate::metrics::Measured>::describe(
                        $crate::metrics::Metric::new(
                            stringify!($field),
                            $crate::metrics::Kind::Real,
                        )$($(.$how($arg))*)?,
                        out,
                    );
                )*
            }

            fn values(&self, out: &mut Vec<$crate::metrics::Value>) {
                $( $crate::metrics::Measured::values(&self.$field, out); )*
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::measured! {
        /// A test struct.
        pub struct Inner {
            /// A count.
            pub hits: usize,
        }
    }

    crate::measured! {
        /// A test struct.
        pub struct Outer {
            /// A label.
            pub name: String,
            /// A time.
            pub time: Option<f64> [unit("s"), digits(2), column("t_s"), missing("never")],
            /// A flag.
            pub ok: bool [column("ok")],
            /// Nested.
            pub inner: Inner,
        }
    }

    #[test]
    fn a_declared_struct_lists_its_metrics_and_values_in_order() {
        let keys: Vec<&str> = metrics_of::<Outer>().iter().map(|m| m.key).collect();
        assert_eq!(keys, ["time", "ok", "hits"]);
        let o = Outer {
            name: "a".into(),
            time: None,
            ok: true,
            inner: Inner { hits: 3 },
        };
        let shown: Vec<String> = measurements(&o).map(|(m, v)| m.show(v)).collect();
        assert_eq!(shown, ["never", "yes", "3"]);
        let csv: Vec<String> = values_of(&o).iter().map(Value::to_string).collect();
        assert_eq!(csv, ["", "true", "3"]);
        let time = metrics_of::<Outer>()[0];
        assert_eq!(time.kind, Kind::OptionalReal);
        assert_eq!(time.show_with_unit(Value::Real(1.234)), "1.23 s");
        assert_eq!(time.column, Some("t_s"));
    }
}
