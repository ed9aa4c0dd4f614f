//! The discretisation in space: the Crouzeix–Raviart space V_h ([`space`]), quadrature rules
//! ([`quadrature`]), the one elasticity law ([`elasticity`]), the stiffness a_h ([`assemble`]) and loads
//! lⁿ ([`loads`]), the exact solution at quadrature points ([`exact`]) and true-error norms ([`norms`]) and the prolongation between nested meshes ([`prolong`]).

pub mod assemble;
pub mod elasticity;
pub mod exact;
pub mod forms;
pub mod lifting;
pub mod loads;
pub mod norms;
pub mod prolong;
pub mod quadrature;
pub mod singular;
pub mod space;
pub mod williams;
