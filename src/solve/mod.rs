//! Solving with the stiffness K, which never changes in time. The general sparse Cholesky factorisation
//! ([`cholesky`]: ordering, symbolic and numeric factorisation, solves) and, on top of it, what is
//! specific to the contact problem:
//!
//! * [`condition`]: K's condition estimate (Lanczos on K and on K⁻¹ through the factor);
//! * [`condense`]: the condensation C = EᵀK⁻¹E onto the contact unknowns, from the factor's trailing block;
//! * [`superpose`]: the loads as a combination of fixed patterns, their responses K⁻¹b_j solved once;
//! * [`kernel`]: the rigid motions of a floating body and the generalized inverse K⁺ that solves with them;
//! * [`free`]: the free response u_f = K⁻¹lⁿ of every step, by blocks of steps (`block`: their columns).

mod block;
pub mod cholesky;
pub mod condense;
pub mod condition;
pub mod free;
pub mod kernel;
pub mod superpose;
