//! The discretisation in space:
//!
//! * [`space`]: the Crouzeix–Raviart element and the space V_h (zero boundary values);
//! * [`lifting`]: nonzero boundary data u_D, g_n, added to V_h's unknowns by their lifting;
//! * [`gap`]: the gap ḡ_e(t) of the Γ_C edges with a normal unknown (unilateral or Coulomb scenes);
//! * [`quadrature`]: the quadrature rules on triangles and edges;
//! * [`elasticity`]: the one elasticity law (plane strain);
//! * [`assemble`]: the stiffness K of a_h; [`loads`]: the load functional lⁿ;
//! * [`exact`]: the exact solution at quadrature points; [`norms`]: true-error norms;
//! * [`forms`]: the energy audit's forms on full midpoint fields;
//! * [`prolong`]: the prolongation between nested meshes;
//! * [`validate`]: the validation of a scene's boundary parts and data that every command runs first.

pub mod assemble;
pub mod elasticity;
pub mod exact;
pub mod forms;
pub mod gap;
pub mod lifting;
pub mod loads;
pub mod norms;
pub mod prolong;
pub mod quadrature;
pub mod singular;
pub mod space;
pub mod validate;
pub mod williams;
