//! The fast path of [`crate::Chain`] (`Direct`). Bodies written on `&mut dyn Spectrum`
//! run here on the forms' unchecked kernels ([`Kernels`]); typed bodies
//! ([`crate::typed!`]) get the concrete form and its checked kernels, inlined.

use crate::form::Kernels;
use crate::linalg::Small;
use crate::{AnyCov, AnySpectrum, Cov, CovError, CovFactor, Form, Spectrum};

/// [`Spectrum::concrete`] of a `Cov<N>` (a type check the compiler folds).
pub(crate) fn concrete_cov<const N: usize>(c: &mut Cov<N>) -> crate::Concrete<'_> {
    use crate::Concrete as C;
    let any = c as &mut dyn std::any::Any;
    let found = match N {
        2 => any.downcast_mut::<Cov<2>>().map(C::Cov2),
        3 => any.downcast_mut::<Cov<3>>().map(C::Cov3),
        4 => any.downcast_mut::<Cov<4>>().map(C::Cov4),
        _ => any.downcast_mut::<Cov<5>>().map(C::Cov5),
    };
    found.unwrap_or(C::Other)
}

/// [`Spectrum::concrete`] of a `CovFactor<N>`.
pub(crate) fn concrete_factor<const N: usize>(f: &mut CovFactor<N>) -> crate::Concrete<'_> {
    use crate::Concrete as C;
    let any = f as &mut dyn std::any::Any;
    let found = match N {
        2 => any.downcast_mut::<CovFactor<2>>().map(C::Factor2),
        3 => any.downcast_mut::<CovFactor<3>>().map(C::Factor3),
        4 => any.downcast_mut::<CovFactor<4>>().map(C::Factor4),
        _ => any.downcast_mut::<CovFactor<5>>().map(C::Factor5),
    };
    found.unwrap_or(C::Other)
}

/// A [`Spectrum`] that runs the unchecked kernels of a concrete form directly: the fast
/// path of [`crate::Chain`]. Operators validate their parameters and resolve their axes
/// as usual; the kernels then run without a check or a commit per call, and finiteness is
/// checked where a kernel could hide an ∞ (before a window or a multi-axis lobe, and
/// before a one-axis lobe unless the form's snap keeps an ∞ visible,
/// `Kernels::LOBE_1_KEEPS_NON_FINITE`) and, by the caller, at the end. Any error here
/// only means "not clean": the caller re-runs the operators in checked mode from the
/// start, which reports the failing step exactly.
#[derive(Debug)]
pub(crate) struct Direct<'a, K>(pub(crate) &'a mut K);

impl<K: Kernels> Direct<'_, K> {
    /// `Err` (never shown: the checked re-run reports) if Σ holds a non-finite entry.
    #[inline(always)]
    fn finite(&self, op: &str) -> Result<(), CovError> {
        if self.0.all_finite() {
            Ok(())
        } else {
            Err(CovError::overflow(op, (0, 0, f64::NAN)))
        }
    }
}

impl<K: Kernels> Spectrum for Direct<'_, K> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn form(&self) -> Form {
        self.0.form()
    }
    fn cov(&self) -> Result<AnyCov, CovError> {
        self.0.cov()
    }
    fn assign(&mut self, c: &AnyCov) -> Result<(), CovError> {
        self.0.assign(c)
    }
    fn snapshot(&self) -> AnySpectrum {
        self.0.snapshot()
    }
    fn restore(&mut self, s: &AnySpectrum) {
        self.0.restore(s)
    }
    fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        self.0.first_non_finite()
    }
    /// The concrete form itself: an operator written with [`crate::typed!`] then runs
    /// its body on the form's checked kernels, inlined with constant axes (measured
    /// cheaper than its body on these unchecked kernels through `dyn`); a body written on
    /// `&mut dyn Spectrum` runs on the unchecked kernels here.
    fn concrete(&mut self) -> crate::Concrete<'_> {
        self.0.concrete()
    }

    fn raw_congruence(&mut self, _op: &str, a: &Small) -> Result<(), CovError> {
        self.0.k_congruence(a);
        Ok(())
    }
    #[inline(always)]
    fn raw_shear(&mut self, _op: &str, i: usize, j: usize, s: f64) -> Result<(), CovError> {
        self.0.k_shear(i, j, s);
        Ok(())
    }
    #[inline(always)]
    fn raw_scale(&mut self, _op: &str, i: usize, c: f64) -> Result<(), CovError> {
        self.0.k_scale(i, c);
        Ok(())
    }
    #[inline(always)]
    fn raw_rotate(&mut self, _op: &str, planes: &[(usize, usize)], c: f64, s: f64) -> Result<(), CovError> {
        for &(i, j) in planes {
            self.0.k_rotate(i, j, c, s);
        }
        Ok(())
    }
    fn raw_add_window(&mut self, op: &str, p: &[usize], w: &Small) -> Result<(), CovError> {
        self.finite(op)?;
        self.0.k_add_window(p, w);
        Ok(())
    }
    #[inline(always)]
    fn raw_add_variance(&mut self, op: &str, i: usize, w: f64) -> Result<(), CovError> {
        // The square-root form folds with reflections, which would spread an ∞ as NaN:
        // the end check still sees it, but check first to keep the fold finite.
        if self.0.form() == Form::SquareRoot {
            self.finite(op)?;
        }
        self.0.k_add_variance(i, w);
        Ok(())
    }
    #[inline(always)]
    fn raw_lobe_1(&mut self, op: &str, p: usize, s: f64) -> Result<(), CovError> {
        if !K::LOBE_1_KEEPS_NON_FINITE {
            self.finite(op)?;
        }
        self.0.k_lobe_1(p, s);
        Ok(())
    }
    fn raw_lobe(&mut self, op: &str, p: &[usize], s: &Small) -> Result<(), CovError> {
        self.finite(op)?;
        self.0.k_lobe(p, s);
        Ok(())
    }
}
