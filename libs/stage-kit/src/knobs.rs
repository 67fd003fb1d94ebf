//! Knobs declared once.
//!
//! A stage's parameters are one [`knobs!`](crate::knobs!) declaration: per
//! knob its name, type, default, unit, kind (with its valid range) and a
//! doc comment. From it come the `Params` struct (serde, strict, every
//! field defaulted, so a `--params` file may name only some), its
//! `Default`, the range check with a one-line error naming the knob and the
//! bad value, one command-line flag per knob named for it (`leaf_size` is
//! `--leaf-size`; a boolean has `--x` and `--no-x`) whose help shows the
//! declared default, the overlay of the given flags onto the parameters
//! read from `--params`, and the markdown knob table (`--print-knobs`,
//! the README's "Stage knobs").
//!
//! ```
//! use stage_kit::knobs::Knobs;
//! stage_kit::knobs! {
//!     /// Knobs of a toy stage.
//!     pub struct Params {
//!         /// Most triangles in a leaf.
//!         leaf_size: u32 = 8, "triangles", value(1..=255);
//!         /// Image width.
//!         width: Option<u32> = None, "pixels", optional(1..=16384);
//!         /// Blend across material seams.
//!         seams: bool = true, "", switch;
//!     }
//! }
//! let p = Params { leaf_size: 0, ..Params::default() };
//! assert_eq!(p.check("").unwrap_err().to_string(), "parameters: leaf_size must be in 1..=255, not 0");
//! assert!(stage_kit::knobs::table::<Params>().contains("| `leaf_size` | `--leaf-size` | Most triangles in a leaf. | triangles | in 1..=255 | 8 |"));
//! ```
//!
//! The kinds: `value` (the field's type is the flag's), `optional`
//! (`Option<T>`: the flag takes a `T`, `None` is "not given"), `list`
//! (`Vec<T>`: the flag takes comma-separated `T`s), `switch` (`bool`:
//! `--x` sets it, `--no-x` clears it) and `group` (`Option<G>` where `G` is
//! itself declared with `knobs!`: `--x` turns it on with `G`'s defaults,
//! and `G`'s knobs get flags `--x-<knob>`, any of which turns it on too).
//! `value`, `optional` and `list` take a range in parentheses, any
//! [`Check`]: an inclusive range `1..=255`, or one of [`checks`]
//! (`positive()`, `at_least(1)`, `open(0.0, 1.0)`, `left_open(0.0, 1.0)`,
//! `custom("text", |v| ...)`), in scope inside the parentheses.
//! A value type must implement [`Show`] (how its value is written on the
//! command line); an enum deriving `clap::ValueEnum` gets it from
//! [`show_by_name!`](crate::show_by_name!).

use crate::run::bad_parameter;
use clap::builder::ValueParser;
use clap::parser::ValueSource;
use clap::{Arg, ArgAction, ArgMatches, Command};
use schemas::error::Result;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt::{Debug, Display};

/// A stage's parameters, as [`knobs!`](crate::knobs!) declares them. Every
/// method takes the `prefix` of a nested group (`""` at the top,
/// `"adaptive."` inside the group `adaptive`).
pub trait Knobs: Serialize + DeserializeOwned + Default + Clone + Debug + Send + Sync + 'static {
    /// Adds one flag per knob to `cmd`.
    fn flags(cmd: Command, prefix: &str) -> Command;
    /// Sets each knob whose flag `given` holds; whether any was given.
    fn overlay(&mut self, given: &ArgMatches, prefix: &str) -> bool;
    /// Checks every knob's range; the error names the first knob out of
    /// range and its value (`parameters: NAME must be RANGE, not VALUE`).
    fn check(&self, prefix: &str) -> Result<()>;
    /// One row per knob for the knob table, in declaration order.
    fn rows(prefix: &str) -> Vec<Spec>;
}

/// What [`Knobs::check`] returns (named here for the macro's use).
pub type Checked = Result<()>;

/// The markdown table of `P`'s knobs: knob, flag, meaning, unit, range,
/// default; one row per knob, a header and its rule first.
pub fn table<P: Knobs>() -> String {
    let mut table = String::from("| knob | flag | meaning | unit | range | default |\n|---|---|---|---|---|---|\n");
    for spec in P::rows("") {
        let cells = [format!("`{}`", spec.name), spec.flags(), spec.doc.clone(), spec.unit.to_string(), spec.range.clone(), spec.default.clone()];
        let cells: Vec<String> = cells.iter().map(|c| c.replace('|', "\\|")).collect();
        table.push_str(&format!("| {} |\n", cells.join(" | ")));
    }
    table
}

/// One knob as its flags, its help and its table row show it.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// Its name in `--params` files and messages, with its group's prefix
    /// (`adaptive.lower`); also the id of its flag.
    pub name: String,
    /// Its long flag without the dashes (`adaptive-lower`).
    pub flag: String,
    /// The placeholder of its value in `--help` (`LOWER`).
    pub value_name: String,
    /// Its doc comment on one line.
    pub doc: String,
    /// Its unit, or empty.
    pub unit: &'static str,
    /// Its valid range in words, or empty.
    pub range: String,
    /// Its default as written on the command line.
    pub default: String,
    /// Whether it is a switch (`--x` / `--no-x`).
    pub switch: bool,
}

impl Spec {
    /// The knob `field` of the group `prefix`; `doc` are the lines of its
    /// doc comment.
    pub fn new(prefix: &str, field: &str, doc: &[&str], unit: &'static str, range: String, default: String) -> Spec {
        let name = format!("{prefix}{field}");
        let doc = doc.iter().map(|l| l.trim()).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ");
        Spec { flag: name.replace(['_', '.'], "-"), value_name: field.to_uppercase(), name, doc, unit, range, default, switch: false }
    }

    /// The id of the flag that clears a switch.
    fn no_id(&self) -> String {
        format!("no-{}", self.name)
    }

    /// The table's flag cell.
    fn flags(&self) -> String {
        if self.switch {
            format!("`--{0}`, `--no-{0}`", self.flag)
        } else {
            format!("`--{}`", self.flag)
        }
    }

    /// The `--help` text: doc, unit and range, and the default.
    fn help(&self) -> String {
        let about: Vec<&str> = [self.unit, self.range.as_str()].into_iter().filter(|s| !s.is_empty()).collect();
        let about = if about.is_empty() { String::new() } else { format!(" ({})", about.join("; ")) };
        format!("{}{about} [default: {}]", self.doc.trim_end_matches('.'), self.default)
    }

    /// The flag of a knob that takes a value parsed by `parser`.
    fn valued(&self, parser: ValueParser) -> Arg {
        Arg::new(self.name.clone()).long(self.flag.clone()).value_name(self.value_name.clone()).help(self.help()).value_parser(parser).action(ArgAction::Set)
    }
}

/// The knob `field` of the group `prefix`, by name.
pub fn name(prefix: &str, field: &str) -> String {
    format!("{prefix}{field}")
}

/// Whether the flag `id` was given on the command line.
fn given(m: &ArgMatches, id: &str) -> bool {
    m.value_source(id) == Some(ValueSource::CommandLine)
}

/// The error for knob `name` holding `value` outside `check`.
fn out_of_range<T: Show>(name: &str, value: &T, check: &impl Describe) -> schemas::Error {
    bad_parameter(format!("{name} must be {}, not {}", check.text(), value.show()))
}

/// How a knob's value is written on the command line, in `--help`'s
/// defaults, the knob table and the range errors.
pub trait Show {
    /// The value as the flag takes it.
    fn show(&self) -> String;
}

macro_rules! show_by_display {
    ($($t:ty),*) => {$(
        impl Show for $t {
            fn show(&self) -> String {
                self.to_string()
            }
        }
    )*};
}
show_by_display!(u8, u16, u32, u64, usize, i32, i64, f32, f64, bool, String);

impl<T: Show> Show for Option<T> {
    fn show(&self) -> String {
        self.as_ref().map_or_else(|| "none".to_string(), Show::show)
    }
}

impl<T: Show> Show for Vec<T> {
    fn show(&self) -> String {
        self.iter().map(Show::show).collect::<Vec<_>>().join(",")
    }
}

/// Implements [`Show`] for enums deriving `clap::ValueEnum`: a value shows
/// as the name its flag takes (`Hemicube` as `hemicube`).
#[macro_export]
macro_rules! show_by_name {
    ($($t:ty),* $(,)?) => {$(
        impl $crate::knobs::Show for $t {
            fn show(&self) -> String {
                $crate::clap::ValueEnum::to_possible_value(self).map_or_else(String::new, |v| v.get_name().to_string())
            }
        }
    )*};
}

/// A range in words, as the table and the errors write it ("in 1..=255").
pub trait Describe {
    /// The words; empty for no range.
    fn text(&self) -> String;
}

/// A valid range of a knob's values of type `T`.
pub trait Check<T>: Describe {
    /// Whether `value` lies in the range.
    fn admits(&self, value: &T) -> bool;
}

/// A number a range can bound: ordered, shown, and finite or not.
pub trait Number: PartialOrd + Display + Copy {
    /// Whether the value is finite (every integer is).
    fn finite(self) -> bool;
}

macro_rules! integer {
    ($($t:ty),*) => {$(
        impl Number for $t {
            fn finite(self) -> bool {
                true
            }
        }
    )*};
}
integer!(u8, u16, u32, u64, usize, i32, i64);

impl Number for f64 {
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl Number for f32 {
    fn finite(self) -> bool {
        self.is_finite()
    }
}

impl<N: Display> Describe for std::ops::RangeInclusive<N> {
    fn text(&self) -> String {
        format!("in {}..={}", self.start(), self.end())
    }
}

impl<N: Number> Check<N> for std::ops::RangeInclusive<N> {
    fn admits(&self, value: &N) -> bool {
        value.finite() && self.contains(value)
    }
}

/// The ranges a knob declaration may name (each admits finite values only).
pub mod checks {
    use super::{Check, Describe, Number};
    use std::fmt::Display;

    /// Any value.
    pub struct Any;

    impl Describe for Any {
        fn text(&self) -> String {
            String::new()
        }
    }

    impl<T> Check<T> for Any {
        fn admits(&self, _value: &T) -> bool {
            true
        }
    }

    /// Finite and > 0: "a positive number".
    pub fn positive() -> Positive {
        Positive
    }

    /// See [`positive`].
    pub struct Positive;

    impl Describe for Positive {
        fn text(&self) -> String {
            "a positive number".into()
        }
    }

    impl<N: Number + Default> Check<N> for Positive {
        fn admits(&self, value: &N) -> bool {
            value.finite() && *value > N::default()
        }
    }

    /// At least `low`: "at least 1".
    pub fn at_least<N>(low: N) -> AtLeast<N> {
        AtLeast(low)
    }

    /// See [`at_least`].
    pub struct AtLeast<N>(N);

    impl<N: Display> Describe for AtLeast<N> {
        fn text(&self) -> String {
            format!("at least {}", self.0)
        }
    }

    impl<N: Number> Check<N> for AtLeast<N> {
        fn admits(&self, value: &N) -> bool {
            value.finite() && *value >= self.0
        }
    }

    /// Strictly between `low` and `high`: "in (0, 1)".
    pub fn open<N>(low: N, high: N) -> Interval<N> {
        Interval { low, high, high_included: false }
    }

    /// Above `low`, at most `high`: "in (0, 1]".
    pub fn left_open<N>(low: N, high: N) -> Interval<N> {
        Interval { low, high, high_included: true }
    }

    /// See [`open`] and [`left_open`].
    pub struct Interval<N> {
        low: N,
        high: N,
        high_included: bool,
    }

    impl<N: Display> Describe for Interval<N> {
        fn text(&self) -> String {
            format!("in ({}, {}{}", self.low, self.high, if self.high_included { "]" } else { ")" })
        }
    }

    impl<N: Number> Check<N> for Interval<N> {
        fn admits(&self, value: &N) -> bool {
            value.finite() && *value > self.low && (*value < self.high || (self.high_included && *value == self.high))
        }
    }

    /// A range no other check says: `text` in words, `admits` the test.
    pub fn custom<F>(text: &'static str, admits: F) -> Custom<F> {
        Custom { text, admits }
    }

    /// See [`custom`].
    pub struct Custom<F> {
        text: &'static str,
        admits: F,
    }

    impl<F> Describe for Custom<F> {
        fn text(&self) -> String {
            self.text.into()
        }
    }

    impl<T, F: Fn(&T) -> bool> Check<T> for Custom<F> {
        fn admits(&self, value: &T) -> bool {
            (self.admits)(value)
        }
    }
}

/// The element type of an `Option` or `Vec` knob, which its flag takes.
pub trait Inner {
    /// The element type.
    type Of;
}

impl<T> Inner for Option<T> {
    type Of = T;
}

impl<T> Inner for Vec<T> {
    type Of = T;
}

/// A knob whose flag takes a value of the field's type.
pub mod value {
    use super::*;

    /// Adds `--flag VALUE`.
    pub fn flags(cmd: Command, spec: Spec, parser: ValueParser) -> Command {
        cmd.arg(spec.valued(parser))
    }

    /// Sets `field` to the given value.
    pub fn overlay<T: Clone + Send + Sync + 'static>(field: &mut T, m: &ArgMatches, name: &str) -> bool {
        m.get_one::<T>(name).cloned().map(|v| *field = v).is_some()
    }

    /// Checks `field` against `check`.
    pub fn check<T: Show>(field: &T, check: &impl Check<T>, name: &str) -> Result<()> {
        if check.admits(field) {
            Ok(())
        } else {
            Err(out_of_range(name, field, check))
        }
    }

    /// Its table row.
    pub fn rows(spec: Spec) -> Vec<Spec> {
        vec![spec]
    }
}

/// An `Option<T>` knob: the flag takes a `T`; `None` means "not set".
pub mod optional {
    use super::*;
    pub use super::value::{flags, rows};

    /// Sets `field` to the given value.
    pub fn overlay<T: Clone + Send + Sync + 'static>(field: &mut Option<T>, m: &ArgMatches, name: &str) -> bool {
        m.get_one::<T>(name).cloned().map(|v| *field = Some(v)).is_some()
    }

    /// Checks a set value against `check`.
    pub fn check<T: Show>(field: &Option<T>, check: &impl Check<T>, name: &str) -> Result<()> {
        field.as_ref().map_or(Ok(()), |v| super::value::check(v, check, name))
    }
}

/// A `Vec<T>` knob: the flag takes comma-separated `T`s.
pub mod list {
    use super::*;
    pub use super::value::rows;

    /// Adds `--flag A,B,...`.
    pub fn flags(cmd: Command, spec: Spec, parser: ValueParser) -> Command {
        cmd.arg(spec.valued(parser).value_delimiter(','))
    }

    /// Sets `field` to the given values.
    pub fn overlay<T: Clone + Send + Sync + 'static>(field: &mut Vec<T>, m: &ArgMatches, name: &str) -> bool {
        m.get_many::<T>(name).map(|v| *field = v.cloned().collect()).is_some()
    }

    /// Checks every element against `check`.
    pub fn check<T: Show>(field: &[T], check: &impl Check<T>, name: &str) -> Result<()> {
        field.iter().try_for_each(|v| super::value::check(v, check, name))
    }
}

/// A `bool` knob: `--flag` sets it, `--no-flag` clears it (the last given
/// wins).
pub mod switch {
    use super::*;

    /// Adds `--flag` and `--no-flag`.
    pub fn flags(cmd: Command, spec: Spec) -> Command {
        let no = spec.no_id();
        let on = Arg::new(spec.name.clone()).long(spec.flag.clone()).help(spec.help()).action(ArgAction::SetTrue).overrides_with(no.clone());
        let off = Arg::new(no).long(format!("no-{}", spec.flag)).help(format!("Clears --{}", spec.flag)).action(ArgAction::SetTrue).overrides_with(spec.name);
        cmd.arg(on).arg(off)
    }

    /// Sets or clears `field` as the last of its two flags says.
    pub fn overlay(field: &mut bool, m: &ArgMatches, name: &str) -> bool {
        let (on, off) = (given(m, name), given(m, &format!("no-{name}")));
        if on || off {
            *field = on;
        }
        on || off
    }

    /// Every value is valid.
    pub fn check(_field: &bool, _check: &checks::Any, _name: &str) -> Result<()> {
        Ok(())
    }

    /// Its table row.
    pub fn rows(spec: Spec) -> Vec<Spec> {
        vec![Spec { switch: true, ..spec }]
    }
}

/// An `Option<G>` knob where `G` is a [`Knobs`] group: `--flag` turns it
/// on with `G`'s defaults, `--flag-KNOB` sets one of `G`'s knobs (and turns
/// it on).
pub mod group {
    use super::*;

    /// The prefix of the group's knobs.
    fn prefix(spec: &Spec) -> String {
        format!("{}.", spec.name)
    }

    /// Adds `--flag` and `G`'s flags.
    pub fn flags<G: Knobs>(cmd: Command, spec: Spec) -> Command {
        let on = Arg::new(spec.name.clone()).long(spec.flag.clone()).help(spec.help()).action(ArgAction::SetTrue);
        G::flags(cmd.arg(on), &prefix(&spec))
    }

    /// Turns the group on if its flag or any of its knobs' was given.
    pub fn overlay<G: Knobs>(field: &mut Option<G>, m: &ArgMatches, name: &str) -> bool {
        let mut group = field.clone().unwrap_or_default();
        let on = group.overlay(m, &format!("{name}.")) | given(m, name);
        if on {
            *field = Some(group);
        }
        on
    }

    /// Checks the group's knobs when it is on.
    pub fn check<G: Knobs>(field: &Option<G>, _check: &checks::Any, name: &str) -> Result<()> {
        field.as_ref().map_or(Ok(()), |g| g.check(&format!("{name}.")))
    }

    /// Its row, then its knobs'.
    pub fn rows<G: Knobs>(spec: Spec) -> Vec<Spec> {
        let inner = G::rows(&prefix(&spec));
        std::iter::once(spec).chain(inner).collect()
    }
}

/// Declares a stage's parameters once; see the [module](mod@crate::knobs).
///
/// ```text
/// stage_kit::knobs! {
///     /// Doc of the struct.
///     pub struct Params {
///         /// One-line doc of the knob (the table's "meaning").
///         #[serde(...)]                 // optional, passed to the field
///         name: Type = default, "unit", kind(range);
///     }
/// }
/// ```
#[macro_export]
macro_rules! knobs {
    (
        $(#[$meta:meta])*
        $vis:vis struct $Params:ident {
            $(
                $(#[doc = $doc:literal])*
                $(#[serde($($serde:tt)*)])*
                $field:ident : $ty:ty = $default:expr, $unit:literal, $kind:ident $(($check:expr))? ;
            )*
        }
    ) => {
        $(#[$meta])*
        #[derive(::serde::Serialize, ::serde::Deserialize, Clone, Debug, PartialEq)]
        #[serde(deny_unknown_fields, default)]
        $vis struct $Params {
            $(
                $(#[doc = $doc])*
                $(#[serde($($serde)*)])*
                pub $field: $ty,
            )*
        }

        impl ::core::default::Default for $Params {
            fn default() -> Self {
                Self { $($field: $default,)* }
            }
        }

        impl $crate::knobs::Show for $Params {
            fn show(&self) -> String {
                "on".to_string()
            }
        }

        impl $crate::knobs::Knobs for $Params {
            fn flags(cmd: $crate::clap::Command, prefix: &str) -> $crate::clap::Command {
                let defaults = <Self as ::core::default::Default>::default();
                $(
                    let spec = $crate::__knob_spec!(prefix, defaults, $field, [$($doc),*], $unit, $($check)?);
                    let cmd = $crate::__knob_flags!($kind, cmd, spec, $ty);
                )*
                let _ = defaults;
                cmd
            }

            fn overlay(&mut self, given: &$crate::clap::ArgMatches, prefix: &str) -> bool {
                let mut any = false;
                $(
                    any |= $crate::knobs::$kind::overlay(&mut self.$field, given, &$crate::knobs::name(prefix, stringify!($field)));
                )*
                any
            }

            fn check(&self, prefix: &str) -> $crate::knobs::Checked {
                $(
                    $crate::knobs::$kind::check(&self.$field, &$crate::__knob_check!($($check)?), &$crate::knobs::name(prefix, stringify!($field)))?;
                )*
                Ok(())
            }

            fn rows(prefix: &str) -> Vec<$crate::knobs::Spec> {
                let defaults = <Self as ::core::default::Default>::default();
                let mut rows = Vec::new();
                $(
                    let spec = $crate::__knob_spec!(prefix, defaults, $field, [$($doc),*], $unit, $($check)?);
                    rows.extend($crate::__knob_rows!($kind, spec, $ty));
                )*
                let _ = defaults;
                rows
            }
        }
    };
}

/// A knob's [`Spec`] (for [`knobs!`](crate::knobs!)).
#[doc(hidden)]
#[macro_export]
macro_rules! __knob_spec {
    ($prefix:ident, $defaults:ident, $field:ident, [$($doc:literal),*], $unit:literal, $($check:expr)?) => {
        $crate::knobs::Spec::new(
            $prefix,
            stringify!($field),
            &[$($doc),*],
            $unit,
            $crate::knobs::Describe::text(&$crate::__knob_check!($($check)?)),
            $crate::knobs::Show::show(&$defaults.$field),
        )
    };
}

/// A knob's range, [`checks::Any`] if none is declared (for
/// [`knobs!`](crate::knobs!)); the [`checks`] are in scope.
#[doc(hidden)]
#[macro_export]
macro_rules! __knob_check {
    () => {
        $crate::knobs::checks::Any
    };
    ($check:expr) => {{
        #[allow(unused_imports)]
        use $crate::knobs::checks::*;
        $check
    }};
}

/// A knob's flags by kind (for [`knobs!`](crate::knobs!)): the value
/// parser is clap's for the flag's type.
#[doc(hidden)]
#[macro_export]
macro_rules! __knob_flags {
    (value, $cmd:ident, $spec:ident, $ty:ty) => {
        $crate::knobs::value::flags($cmd, $spec, $crate::clap::value_parser!($ty).into())
    };
    (optional, $cmd:ident, $spec:ident, $ty:ty) => {
        $crate::knobs::optional::flags($cmd, $spec, $crate::clap::value_parser!(<$ty as $crate::knobs::Inner>::Of).into())
    };
    (list, $cmd:ident, $spec:ident, $ty:ty) => {
        $crate::knobs::list::flags($cmd, $spec, $crate::clap::value_parser!(<$ty as $crate::knobs::Inner>::Of).into())
    };
    (switch, $cmd:ident, $spec:ident, $ty:ty) => {
        $crate::knobs::switch::flags($cmd, $spec)
    };
    (group, $cmd:ident, $spec:ident, $ty:ty) => {
        $crate::knobs::group::flags::<<$ty as $crate::knobs::Inner>::Of>($cmd, $spec)
    };
}

/// A knob's table rows by kind (for [`knobs!`](crate::knobs!)).
#[doc(hidden)]
#[macro_export]
macro_rules! __knob_rows {
    (group, $spec:ident, $ty:ty) => {
        $crate::knobs::group::rows::<<$ty as $crate::knobs::Inner>::Of>($spec)
    };
    ($kind:ident, $spec:ident, $ty:ty) => {
        $crate::knobs::$kind::rows($spec)
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::StageArgs;
    use clap::{Args, FromArgMatches};

    /// How a toy stage sees rays.
    #[derive(clap::ValueEnum, serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
    enum Visibility {
        Hemicube,
        Stereographic,
    }
    crate::show_by_name!(Visibility);

    crate::knobs! {
        /// A nested group.
        struct Adaptive {
            /// Lower bound.
            lower: f64 = 0.05, "", value(open(0.0, 1.0));
            /// Most splits.
            levels: u32 = 3, "", value(at_least(1));
        }
    }

    crate::knobs! {
        /// Every kind of knob.
        struct Toy {
            /// Most triangles
            /// in a leaf.
            leaf_size: u32 = 8, "triangles", value(1..=255);
            /// Visibility | method.
            visibility: Visibility = Visibility::Hemicube, "", value;
            /// Error bound.
            eps: f64 = 2e-4, "W/m^2", value(positive());
            /// Width.
            width: Option<u32> = None, "pixels", optional(1..=16384);
            /// Thresholds.
            tau: Vec<f64> = vec![0.01, 0.1], "", list(left_open(0.0, 1.0));
            /// Seams.
            seams: bool = true, "", switch;
            /// Adaptive subdivision.
            #[serde(skip_serializing_if = "Option::is_none")]
            adaptive: Option<Adaptive> = None, "", group;
        }
    }

    /// The effective knobs of the command line `args` (no `--params`).
    fn parse(args: &[&str]) -> std::result::Result<Toy, String> {
        let cmd = StageArgs::<Toy>::augment_args(Command::new("toy").no_binary_name(true)).allow_negative_numbers(true);
        let m = cmd.try_get_matches_from(args).map_err(|e| format!("clap: {:?}", e.kind()))?;
        StageArgs::<Toy>::from_arg_matches(&m).unwrap().knobs().map_err(|e| e.to_string())
    }

    #[test]
    fn flags_set_their_knobs_and_nothing_else() {
        assert_eq!(parse(&[]).unwrap(), Toy::default());
        let toy = parse(&["--leaf-size", "4", "--visibility", "stereographic", "--eps", "1e-3", "--width", "64", "--tau", "0.5,1", "--no-seams"]).unwrap();
        let want = Toy { leaf_size: 4, visibility: Visibility::Stereographic, eps: 1e-3, width: Some(64), tau: vec![0.5, 1.0], seams: false, adaptive: None };
        assert_eq!(toy, want);
        // The last of --x / --no-x wins.
        assert!(parse(&["--no-seams", "--seams"]).unwrap().seams);
        assert!(!parse(&["--seams", "--no-seams"]).unwrap().seams);
        // A group: its flag turns it on with its defaults, a knob of it too.
        assert_eq!(parse(&["--adaptive"]).unwrap().adaptive, Some(Adaptive { lower: 0.05, levels: 3 }));
        assert_eq!(parse(&["--adaptive-levels", "5"]).unwrap().adaptive, Some(Adaptive { lower: 0.05, levels: 5 }));
    }

    #[test]
    fn flags_override_the_params_file_knob_by_knob() {
        let file = std::env::temp_dir().join(format!("knobs-{}.ron", std::process::id()));
        std::fs::write(&file, "(leaf_size: 4, seams: false, adaptive: Some((levels: 2)))").unwrap();
        let path = file.to_str().unwrap();
        let toy = parse(&["--params", path, "--seams", "--adaptive-lower", "0.5"]).unwrap();
        std::fs::remove_file(&file).unwrap();
        let want = Toy { leaf_size: 4, seams: true, adaptive: Some(Adaptive { lower: 0.5, levels: 2 }), ..Toy::default() };
        assert_eq!(toy, want, "the file's leaf_size and levels kept, the flags' seams and lower over them");
    }

    #[test]
    fn a_value_out_of_range_is_one_line_naming_the_knob_and_value() {
        let refused = |args: &[&str]| parse(args).unwrap_err();
        assert_eq!(refused(&["--leaf-size", "0"]), "parameters: leaf_size must be in 1..=255, not 0");
        assert_eq!(refused(&["--eps", "-1"]), "parameters: eps must be a positive number, not -1");
        assert_eq!(refused(&["--eps", "inf"]), "parameters: eps must be a positive number, not inf");
        assert_eq!(refused(&["--width", "0"]), "parameters: width must be in 1..=16384, not 0");
        assert_eq!(refused(&["--tau", "0.5,2"]), "parameters: tau must be in (0, 1], not 2");
        assert_eq!(refused(&["--adaptive-lower", "1"]), "parameters: adaptive.lower must be in (0, 1), not 1");
        assert_eq!(refused(&["--adaptive-levels", "0"]), "parameters: adaptive.levels must be at least 1, not 0");
        // clap refuses what does not parse as the knob's type.
        assert_eq!(refused(&["--leaf-size", "x"]), "clap: ValueValidation");
        assert_eq!(refused(&["--visibility", "x"]), "clap: InvalidValue");
    }

    #[test]
    fn the_serialised_form_is_the_plain_struct() {
        let text = schemas::ron_io::to_ron_text(&Toy::default());
        assert_eq!(text, "Toy(\n  leaf_size: 8,\n  visibility: Hemicube,\n  eps: 0.0002,\n  width: None,\n  tau: [\n    0.01,\n    0.1,\n  ],\n  seams: true,\n)");
        let parsed: Toy = ron::from_str("(adaptive: Some((levels: 2)))").unwrap();
        assert_eq!(parsed.adaptive, Some(Adaptive { lower: 0.05, levels: 2 }));
        assert!(ron::from_str::<Toy>("(leaf_sise: 2)").is_err(), "unknown fields are refused");
    }

    #[test]
    fn the_table_has_one_row_per_knob_from_the_declaration() {
        let want = "| knob | flag | meaning | unit | range | default |
|---|---|---|---|---|---|
| `leaf_size` | `--leaf-size` | Most triangles in a leaf. | triangles | in 1..=255 | 8 |
| `visibility` | `--visibility` | Visibility \\| method. |  |  | hemicube |
| `eps` | `--eps` | Error bound. | W/m^2 | a positive number | 0.0002 |
| `width` | `--width` | Width. | pixels | in 1..=16384 | none |
| `tau` | `--tau` | Thresholds. |  | in (0, 1] | 0.01,0.1 |
| `seams` | `--seams`, `--no-seams` | Seams. |  |  | true |
| `adaptive` | `--adaptive` | Adaptive subdivision. |  |  | none |
| `adaptive.lower` | `--adaptive-lower` | Lower bound. |  | in (0, 1) | 0.05 |
| `adaptive.levels` | `--adaptive-levels` | Most splits. |  | at least 1 | 3 |
";
        assert_eq!(table::<Toy>(), want);
    }

    #[test]
    fn the_help_shows_each_default_from_the_declaration() {
        let help = StageArgs::<Toy>::augment_args(Command::new("toy")).render_long_help().to_string();
        for line in ["Most triangles in a leaf (triangles; in 1..=255) [default: 8]", "Seams [default: true]", "Clears --seams", "Lower bound (in (0, 1)) [default: 0.05]"] {
            assert!(help.contains(line), "{line} missing from\n{help}");
        }
        assert!(help.contains("--leaf-size <LEAF_SIZE>") && help.contains("--adaptive-lower <LOWER>"), "{help}");
    }
}
