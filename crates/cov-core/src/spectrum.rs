//! [`Spectrum`]: the four rules as an interface, so that one operator body acts on Σ in
//! either form, the covariance [`Cov`] or the square-root [`CovFactor`].

use std::any::Any;
use std::fmt;

use nalgebra::SMatrix;

use crate::{Axis, Cov, CovError, CovFactor};

/// How a chain holds Σ while it is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Form {
    /// Σ itself ([`Cov`]): the cheapest kernels; a chain that moves Σ into a frame where
    /// one block dwarfs another and back loses the small block's digits like
    /// `ε · Σ_big/Σ_small` per event.
    Covariance,
    /// `Σ = L Lᵀ` ([`CovFactor`]), updated by Potter's and the array algorithms: the same
    /// loss is `ε · √(Σ_big/Σ_small)`, and Σ is PSD by construction. The default: on the
    /// stiff suite's 10⁴-operator bounce chains it reaches 4e-13 to 2.4e-12 where the
    /// covariance form reaches 4.1e-9 (README, "Numerical stability"), for 1.5× the
    /// cost of a path.
    #[default]
    SquareRoot,
}

/// A saved Σ, in the form it was held in ([`Spectrum::snapshot`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Snapshot<const N: usize> {
    /// Covariance form.
    Covariance(Cov<N>),
    /// Square-root form.
    SquareRoot(CovFactor<N>),
}

/// A [`Spectrum`] seen with its layout known: what an operator whose layout is chosen at
/// run time (a RON path) needs to call into a fixed-layout implementation.
pub enum SpectrumMut<'a> {
    /// `x, u`.
    Two(&'a mut dyn Spectrum<2>),
    /// `x, u, t`.
    Three(&'a mut dyn Spectrum<3>),
    /// `x, y, u, v`.
    Four(&'a mut dyn Spectrum<4>),
    /// `x, y, u, v, t`.
    Five(&'a mut dyn Spectrum<5>),
}

/// Σ in some form, with the four rules as in-place operations. [`crate::Operator`]s act
/// through this interface, so that a chain can run in the covariance or the square-root
/// form ([`Form`]) with the same operator code. The kernels mean exactly what the
/// [`Cov`] kernels of the same name mean (see `cov_core::kernels`).
///
/// An operator that needs something the kernels do not offer reads Σ with
/// [`Spectrum::cov`] and writes it back with [`Spectrum::assign`] (the square-root form
/// then refactors Σ, and its accuracy advantage is lost at that step only).
pub trait Spectrum<const N: usize>: fmt::Debug {
    /// The form Σ is held in.
    fn form(&self) -> Form;
    /// Σ now.
    ///
    /// # Errors
    /// [`CovError::Overflow`] if Σ exceeds the f64 range (possible in square-root form).
    fn cov(&self) -> Result<Cov<N>, CovError>;
    /// Replaces Σ.
    ///
    /// # Errors
    /// A non-finite entry.
    fn assign(&mut self, c: &Cov<N>) -> Result<(), CovError>;
    /// Saves Σ exactly as held.
    fn snapshot(&self) -> Snapshot<N>;
    /// Restores a [`Spectrum::snapshot`] (converting if it was taken in the other form).
    fn restore(&mut self, s: &Snapshot<N>);
    /// Checks every stored number is finite.
    ///
    /// # Errors
    /// [`CovError::Overflow`] naming `operator`.
    fn check_finite(&self, operator: &str) -> Result<(), CovError>;
    /// This Σ with its layout known ([`SpectrumMut`]).
    fn layout(&mut self) -> SpectrumMut<'_>;

    /// Rule 1 with a dense matrix, `Σ' = Aᵀ Σ A` ([`Cov::congruence`]).
    ///
    /// # Errors
    /// As [`Cov::congruence`].
    fn congruence(&mut self, a: &SMatrix<f64, N, N>) -> Result<(), CovError>;
    /// Rule 1, elementary shear ([`Cov::shear`]).
    ///
    /// # Errors
    /// As [`Cov::shear`].
    fn shear(&mut self, target: Axis, source: Axis, s: f64) -> Result<(), CovError>;
    /// Rule 1, scaling ([`Cov::scale`]).
    ///
    /// # Errors
    /// As [`Cov::scale`].
    fn scale(&mut self, axis: Axis, c: f64) -> Result<(), CovError>;
    /// Rule 1, rotation in the plane of two axes ([`Cov::rotate`]).
    ///
    /// # Errors
    /// As [`Cov::rotate`].
    fn rotate(&mut self, a: Axis, b: Axis, angle: f64) -> Result<(), CovError>;
    /// Rotation of the 3D tangent frame ([`Cov::rotate_frame`]).
    ///
    /// # Errors
    /// As [`Cov::rotate_frame`].
    fn rotate_frame(&mut self, angle: f64) -> Result<(), CovError>;
    /// Rule 2 on one axis ([`Cov::add_variance`]).
    ///
    /// # Errors
    /// As [`Cov::add_variance`].
    fn add_variance(&mut self, axis: Axis, w: f64) -> Result<(), CovError>;
    /// Rule 2 ([`Cov::add_window`]).
    ///
    /// # Errors
    /// As [`Cov::add_window`].
    fn add_window(&mut self, axes: &[Axis], w: &[f64]) -> Result<(), CovError>;
    /// Rule 3 ([`Cov::convolve`]).
    ///
    /// # Errors
    /// As [`Cov::convolve`].
    fn convolve(&mut self, axes: &[Axis], s: &[f64]) -> Result<(), CovError>;
    /// Rule 4 ([`Cov::integrate`]).
    ///
    /// # Errors
    /// As [`Cov::integrate`].
    fn integrate(&mut self, axes: &[Axis]) -> Result<(), CovError>;
}

/// The layout dispatch of [`Spectrum::layout`] for a concrete type family.
///
/// `Cov<N>` (and so `CovFactor<N>`) exists for N = 2..=5 only (a compile-time assertion
/// in `Cov`), so exactly one of the four type tests succeeds and the `expect`s cannot
/// fail: each runs right after the `is` test of the same type.
macro_rules! layout_arms {
    ($value:ident, $ty:ident) => {{
        let any: &mut dyn Any = $value;
        if any.is::<$ty<2>>() {
            SpectrumMut::Two(any.downcast_mut::<$ty<2>>().expect("tested by `is`"))
        } else if any.is::<$ty<3>>() {
            SpectrumMut::Three(any.downcast_mut::<$ty<3>>().expect("tested by `is`"))
        } else if any.is::<$ty<4>>() {
            SpectrumMut::Four(any.downcast_mut::<$ty<4>>().expect("tested by `is`"))
        } else {
            SpectrumMut::Five(any.downcast_mut::<$ty<5>>().expect("N is 2..=5"))
        }
    }};
}

macro_rules! delegate_kernels {
    () => {
        fn congruence(&mut self, a: &SMatrix<f64, N, N>) -> Result<(), CovError> {
            Self::congruence(self, a)
        }
        fn shear(&mut self, target: Axis, source: Axis, s: f64) -> Result<(), CovError> {
            Self::shear(self, target, source, s)
        }
        fn scale(&mut self, axis: Axis, c: f64) -> Result<(), CovError> {
            Self::scale(self, axis, c)
        }
        fn rotate(&mut self, a: Axis, b: Axis, angle: f64) -> Result<(), CovError> {
            Self::rotate(self, a, b, angle)
        }
        fn rotate_frame(&mut self, angle: f64) -> Result<(), CovError> {
            Self::rotate_frame(self, angle)
        }
        fn add_variance(&mut self, axis: Axis, w: f64) -> Result<(), CovError> {
            Self::add_variance(self, axis, w)
        }
        fn add_window(&mut self, axes: &[Axis], w: &[f64]) -> Result<(), CovError> {
            Self::add_window(self, axes, w)
        }
        fn convolve(&mut self, axes: &[Axis], s: &[f64]) -> Result<(), CovError> {
            Self::convolve(self, axes, s)
        }
        fn integrate(&mut self, axes: &[Axis]) -> Result<(), CovError> {
            Self::integrate(self, axes)
        }
        fn check_finite(&self, operator: &str) -> Result<(), CovError> {
            Self::check_finite(self, operator)
        }
    };
}

impl<const N: usize> Spectrum<N> for Cov<N> {
    fn form(&self) -> Form {
        Form::Covariance
    }
    fn cov(&self) -> Result<Cov<N>, CovError> {
        Ok(*self)
    }
    fn assign(&mut self, c: &Cov<N>) -> Result<(), CovError> {
        c.check_finite("assign")?;
        *self = *c;
        Ok(())
    }
    fn snapshot(&self) -> Snapshot<N> {
        Snapshot::Covariance(*self)
    }
    fn restore(&mut self, s: &Snapshot<N>) {
        match s {
            Snapshot::Covariance(c) => *self = *c,
            // A factor of a finite Σ: `to_cov` fails only on overflow, when Σ is left.
            Snapshot::SquareRoot(f) => {
                if let Ok(c) = f.to_cov() {
                    *self = c;
                }
            }
        }
    }
    fn layout(&mut self) -> SpectrumMut<'_> {
        layout_arms!(self, Cov)
    }
    delegate_kernels!();
}

impl<const N: usize> Spectrum<N> for CovFactor<N> {
    fn form(&self) -> Form {
        Form::SquareRoot
    }
    fn cov(&self) -> Result<Cov<N>, CovError> {
        self.to_cov()
    }
    fn assign(&mut self, c: &Cov<N>) -> Result<(), CovError> {
        c.check_finite("assign")?;
        *self = CovFactor::from_cov(c);
        Ok(())
    }
    fn snapshot(&self) -> Snapshot<N> {
        Snapshot::SquareRoot(*self)
    }
    fn restore(&mut self, s: &Snapshot<N>) {
        match s {
            Snapshot::Covariance(c) => *self = CovFactor::from_cov(c),
            Snapshot::SquareRoot(f) => *self = *f,
        }
    }
    fn layout(&mut self) -> SpectrumMut<'_> {
        layout_arms!(self, CovFactor)
    }
    delegate_kernels!();
}
