//! Operator lists inside an operator's parameters (`Moving(velocity: …, operators: […])`).

use std::cell::RefCell;

use cov_core::{AxisSet, CovError, Operator, Spectrum};
use serde::de::{Deserialize, DeserializeSeed, Deserializer, Error};

use crate::path::OpsSeed;
use crate::registry::{DynOperator, Registry};

thread_local! {
    static CURRENT: RefCell<Vec<Registry>> = const { RefCell::new(Vec::new()) };
}

/// While alive, nested [`Operators`] lists resolve names in this registry.
pub(crate) struct RegistryScope;

impl RegistryScope {
    pub(crate) fn enter(registry: &Registry) -> RegistryScope {
        CURRENT.with(|c| c.borrow_mut().push(registry.clone()));
        RegistryScope
    }
}

impl Drop for RegistryScope {
    fn drop(&mut self) {
        CURRENT.with(|c| {
            c.borrow_mut().pop();
        });
    }
}

/// A list of operators as a parameter of another operator, written like the path's own
/// list (`operators: [Window(std_x: 0.01), Brdf(lobe: Diffuse)]`). It deserialises only
/// inside [`crate::Path::parse`], which provides the registry.
#[derive(Clone, Debug, Default)]
pub struct Operators(pub Vec<DynOperator>);

impl Operators {
    /// Applies every operator in order.
    ///
    /// # Errors
    /// The first failing operator's error.
    pub fn apply<const N: usize>(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
        for op in &self.0 {
            Operator::<N>::apply(op, cov)?;
        }
        Ok(())
    }

    /// Union of what the operators need.
    pub fn requires(&self) -> AxisSet {
        self.0
            .iter()
            .fold(AxisSet::FLAT, |s, op| s.union(Operator::<5>::requires(op)))
    }

    /// Names joined with `+`, for the enclosing operator's name.
    pub fn names(&self) -> String {
        self.0
            .iter()
            .map(|op| Operator::<5>::name(op).to_string())
            .collect::<Vec<_>>()
            .join("+")
    }
}

impl<'de> Deserialize<'de> for Operators {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let registry = CURRENT.with(|c| c.borrow().last().cloned());
        let Some(registry) = registry else {
            return Err(D::Error::custom(
                "nested operator lists are only read by Path::parse",
            ));
        };
        OpsSeed {
            registry: &registry,
            layout: None,
        }
        .deserialize(d)
        .map(Operators)
    }
}
