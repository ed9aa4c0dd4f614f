//! Solving with the stiffness K, which never changes in time: the sparse Cholesky factor made once
//! ([`factor`]) and its condition estimate ([`condition`]), the condensation onto the contact unknowns ([`condense`]), superposed load patterns
//! ([`superpose`]) and the free response u_f = K⁻¹lⁿ of every step ([`free`]).

mod block;
pub mod condense;
pub mod condition;
pub mod dissect;
pub mod etree;
pub mod factor;
pub mod free;
pub mod ordering;
pub mod pages;
mod subtrees;
pub mod superpose;
pub mod symbolic;
