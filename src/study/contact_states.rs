//! The contact states a run went through, per boundary vertex of Γ_C: over all its steps, whether an edge
//! of Γ_C at the vertex stuck, slipped or separated. The planner reads them at the scene's contact
//! corners (`plan::corners`): a corner whose edges only ever slipped has the exponent of a sliding side,
//! not the conservative bound over stick and slip.

use crate::fem::space::CrSpace;
use crate::friction::EdgeState;
use crate::mesh::Mesh;
use crate::stepping::StepResult;

/// Bit of [`Seen`]: stuck (in contact).
pub const STICK: u8 = 1;
/// Bit of [`Seen`]: slipped (in contact).
pub const SLIP: u8 = 2;
/// Bit of [`Seen`]: separated (unilateral contact only).
pub const SEPARATED: u8 = 4;

/// The states seen per Γ_C edge (indices of `CrSpace::contact`), accumulated step by step.
#[derive(Clone, Debug, Default)]
pub struct Seen {
    per_edge: Vec<u8>,
}

impl Seen {
    /// Add one step's states (step 0, u⁰ given, and a step without contact states add nothing: step 0
    /// is marked stick by convention, no friction law decided it).
    pub fn record(&mut self, space: &CrSpace, r: &StepResult) {
        if r.n == 0 || r.state.is_empty() {
            return;
        }
        self.per_edge.resize(space.contact.len(), 0);
        let mut separated = vec![false; space.contact.len()];
        for (&j, &sep) in space.normal_edges().iter().zip(&r.normal.separated) {
            separated[j] = sep;
        }
        for ((bits, s), sep) in self.per_edge.iter_mut().zip(&r.state).zip(separated) {
            // a separated edge's stick/slip flag carries no condition: it is free
            *bits |= match (sep, s) {
                (true, _) => SEPARATED,
                (false, EdgeState::Stick) => STICK,
                (false, EdgeState::Slip) => SLIP,
            };
        }
    }

    /// The states seen at every vertex of a Γ_C edge (the union over its Γ_C edges), in vertex order.
    pub fn at_vertices(&self, mesh: &Mesh, space: &CrSpace) -> Vec<([f64; 2], u8)> {
        let mut at: Vec<u8> = vec![0; mesh.points.len()];
        for (c, &bits) in space.contact.iter().zip(&self.per_edge) {
            for v in mesh.edges[c.edge] {
                at[v] |= bits;
            }
        }
        at.iter().enumerate().filter(|(_, &b)| b != 0).map(|(v, &b)| (mesh.points[v], b)).collect()
    }
}
