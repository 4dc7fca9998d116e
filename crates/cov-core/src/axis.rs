//! Axes and layouts (docs/physics.md section 1).
//!
//! The axis order is always `x, y, u, v, t`; a layout of size `N` keeps a subset of them:
//!
//! | N | axes | use |
//! |---|---|---|
//! | 2 | x, u | flatland |
//! | 3 | x, u, t | flatland with time |
//! | 4 | x, y, u, v | 3D, static |
//! | 5 | x, y, u, v, t | 3D with motion |

use std::fmt;

use crate::CovError;

/// One axis of the local light field.
///
/// Units: `X`, `Y` metres; `U`, `V` tangent of the angular offset (dimensionless);
/// `T` seconds. Frequencies along an axis are in cycles per that unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// Horizontal position in the plane orthogonal to the ray (m).
    X,
    /// Vertical position in the plane orthogonal to the ray (m).
    Y,
    /// Horizontal direction, tangent of the angular offset (dimensionless).
    U,
    /// Vertical direction, tangent of the angular offset (dimensionless).
    V,
    /// Time (s).
    T,
}

impl Axis {
    /// All axes in canonical order.
    pub const ALL: [Axis; 5] = [Axis::X, Axis::Y, Axis::U, Axis::V, Axis::T];

    /// Lower-case name as used in tables and RON files (`"x"`, `"y"`, `"u"`, `"v"`, `"t"`).
    pub fn name(self) -> &'static str {
        ["x", "y", "u", "v", "t"][self as usize]
    }

    /// Parses a lower- or upper-case axis name.
    pub fn from_name(name: &str) -> Option<Axis> {
        Axis::ALL
            .into_iter()
            .find(|a| a.name().eq_ignore_ascii_case(name))
    }

    /// Unit of the primal coordinate along this axis.
    pub fn unit(self) -> &'static str {
        match self {
            Axis::X | Axis::Y => "m",
            Axis::U | Axis::V => "tan",
            Axis::T => "s",
        }
    }

    fn bit(self) -> u8 {
        1 << (self as u8)
    }
}

impl fmt::Display for Axis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A set of axes, used by operators to declare what they need.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct AxisSet(u8);

impl AxisSet {
    /// The empty set.
    pub const EMPTY: AxisSet = AxisSet(0);
    /// The flatland axes `x, u`: what every operator needs at least.
    pub const FLAT: AxisSet = AxisSet(0b00101);
    /// The flatland axes with time: `x, u, t`.
    pub const FLAT_TIME: AxisSet = AxisSet(0b10101);
    /// The 3D static axes `x, y, u, v`.
    pub const SPACE: AxisSet = AxisSet(0b01111);
    /// All five axes.
    pub const ALL: AxisSet = AxisSet(0b11111);

    /// Builds a set from a list of axes.
    pub fn of(axes: &[Axis]) -> AxisSet {
        AxisSet(axes.iter().fold(0, |m, a| m | a.bit()))
    }

    /// Whether `axis` is in the set.
    pub fn contains(self, axis: Axis) -> bool {
        self.0 & axis.bit() != 0
    }

    /// Union of two sets.
    pub fn union(self, other: AxisSet) -> AxisSet {
        AxisSet(self.0 | other.0)
    }

    /// Adds an axis.
    pub fn with(self, axis: Axis) -> AxisSet {
        AxisSet(self.0 | axis.bit())
    }

    /// The axes of the set in canonical order.
    pub fn iter(self) -> impl Iterator<Item = Axis> {
        Axis::ALL.into_iter().filter(move |a| self.contains(*a))
    }

    /// The smallest layout size (2, 3, 4 or 5) that contains every axis of the set.
    pub fn smallest_layout(self) -> usize {
        let spatial = self.contains(Axis::Y) || self.contains(Axis::V);
        2 + 2 * usize::from(spatial) + usize::from(self.contains(Axis::T))
    }
}

impl fmt::Display for AxisSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.iter().map(Axis::name).collect();
        write!(f, "{{{}}}", names.join(","))
    }
}

/// The axes of the layout of size `n`, or `None` if `n` is not 2, 3, 4 or 5.
pub fn layout_axes(n: usize) -> Option<&'static [Axis]> {
    match n {
        2 => Some(&[Axis::X, Axis::U]),
        3 => Some(&[Axis::X, Axis::U, Axis::T]),
        4 => Some(&[Axis::X, Axis::Y, Axis::U, Axis::V]),
        5 => Some(&[Axis::X, Axis::Y, Axis::U, Axis::V, Axis::T]),
        _ => None,
    }
}

/// The set of axes of the layout of size `n` (empty if `n` is not a layout).
pub fn layout_set(n: usize) -> AxisSet {
    layout_axes(n).map(AxisSet::of).unwrap_or(AxisSet::EMPTY)
}

/// Index of `axis` in the layout of size `n`.
///
/// # Errors
/// [`CovError::MissingAxis`] when the layout has no such axis.
#[inline(always)]
pub fn axis_index(n: usize, axis: Axis) -> Result<usize, CovError> {
    let i = match (n, axis) {
        (2 | 3, Axis::X) | (4 | 5, Axis::X) => Some(0),
        (2 | 3, Axis::U) => Some(1),
        (3, Axis::T) => Some(2),
        (4 | 5, Axis::Y) => Some(1),
        (4 | 5, Axis::U) => Some(2),
        (4 | 5, Axis::V) => Some(3),
        (5, Axis::T) => Some(4),
        _ => None,
    };
    // Not `ok_or(error)`: the error built eagerly is dropped on every successful lookup
    // (40 instructions per kernel call, measured with callgrind).
    match i {
        Some(i) => Ok(i),
        None => Err(CovError::MissingAxis { axis, layout: n }),
    }
}
