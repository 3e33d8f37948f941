//! The estimators of the pipeline, one folder each: the registry entry, the estimator's
//! state and its push at the folder's root (`mod.rs`), each job of the estimator in a
//! file of its own beside it.

pub(crate) mod constrained;
pub(crate) mod discrete_momentum;
pub(crate) mod equation_error;
pub(crate) mod momentum_rls;
