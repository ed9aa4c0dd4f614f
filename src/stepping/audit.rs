//! The energy audit of every step (written to `/tresca/steps`, see `output::tresca`).
//!
//! From the step's variational inequality (test with v = uⁿ⁻¹ and v = 2uⁿ − uⁿ⁻¹), every backward-Euler
//! step satisfies, with δuⁿ = uⁿ − uⁿ⁻¹,
//!   a_h(uⁿ, δuⁿ) + j_h(δuⁿ) = (lⁿ, δuⁿ) + W_Γⁿ,
//! where W_Γ is the work of the boundary data (zero when u_D = 0 and g_n = 0). Everything is computed
//! on the full midpoint fields U (lifting included) with the matrix-free forms of `fem::forms`
//! (A, B, C; p = u_D at the data points), independently of K and of the solver's right-hand side:
//!
//! * `stored_energy` Eⁿ = E(Uⁿ, pⁿ) = ½A(U,U) − B(p,U) + ½C(p,p) (= ½a_h(uⁿ,uⁿ) without data);
//! * `external_work` (lⁿ, δuⁿ) = Σ_e lⁿ_e·δU_e, the loads f, g on the whole increment;
//! * `friction_dissipation` j_h(δuⁿ) = Σ_{e ⊂ Γ_C} |e| ḡ_e |δs_e| (on a Coulomb edge the threshold
//!   F̄_e |Pⁿ_e| in place of |e| ḡ_e);
//! * `euler_dissipation` ½Q(δX, δX) = ½A(δU,δU) − B(δp,δU) + ½C(δp,δp) (= ½a_h(δuⁿ,δuⁿ) without data);
//! * `boundary_work` W_Γ = Σ_c Rⁿ_c δU_c + ∂_pE·δp: the reactions Rⁿ = A Uⁿ − B(pⁿ,·) − lⁿ on the
//!   constrained components c (both axes of a Dirichlet edge with data, the normal of a Γ_C edge with a
//!   gap) times their increments, plus the work of the Dirichlet penalty on the moving data,
//!   ∂_pE·δp = C(pⁿ,δp) − B(δp,Uⁿ); with normal unknowns (`friction::normal`) also the work of the
//!   contact reaction −Pⁿ_e n_e on the normal increments, −Σ_e Pⁿ_e δu_n(m_e);
//! * `balance_residual` a_h(uⁿ,δuⁿ) + j_h(δuⁿ) − (lⁿ,δuⁿ) − W_Γ with a_h(uⁿ,δuⁿ) := Q(Xⁿ, δX)
//!   = A(Uⁿ,δU) − B(pⁿ,δU) − B(δp,Uⁿ) + C(pⁿ,δp). It equals Σ_free (AUⁿ − B(pⁿ,·) − lⁿ)_i δU_i + j_h(δuⁿ):
//!   zero exactly when the discrete equilibrium holds on the unknowns and the friction force does the
//!   work j_h on the slip increment (Tresca's law), so a wrong friction sign or slip direction shows.
//!
//! Since Q is a symmetric quadratic form, Q(Xⁿ,δX) = Eⁿ − Eⁿ⁻¹ + ½Q(δX,δX), so also
//!   balance_residual = Eⁿ − Eⁿ⁻¹ + euler_dissipation + friction_dissipation − external_work − boundary_work
//! up to rounding. Units: those of energy (force × length, per unit thickness in plane strain). Step 0
//! has δu = 0: every term but Eⁿ is 0.

use super::{Problem, StepResult};
use crate::error::Result;
use crate::fem::forms::{dot2, FullForm};
use crate::fem::lifting::DataValues;

/// The energy audit of one step (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Audit {
    pub external_work: f64,
    pub boundary_work: f64,
    pub stored_energy: f64,
    pub friction_dissipation: f64,
    pub euler_dissipation: f64,
    pub balance_residual: f64,
}

impl Audit {
    /// The six values in the order written: external work, boundary work, stored energy, friction
    /// dissipation, backward-Euler dissipation, balance residual.
    pub fn as_array(&self) -> [f64; 6] {
        [
            self.external_work,
            self.boundary_work,
            self.stored_energy,
            self.friction_dissipation,
            self.euler_dissipation,
            self.balance_residual,
        ]
    }
}

/// What the audit of step n + 1 needs of step n.
pub struct AuditState {
    n: usize,
    w: Vec<f64>,
    u: Vec<[f64; 2]>,
    au: Vec<[f64; 2]>,
    p: DataValues,
    slip: Vec<f64>,
}

impl Problem {
    /// The forms of the audit, made at the first use.
    fn forms(&self) -> &FullForm {
        self.forms.get_or_init(|| FullForm::new(&self.mesh, &self.space, self.data.as_ref(), &self.law, self.scene.rho))
    }

    /// `r` with its audit against `prev` (the state of step r.n − 1, if kept) and, with boundary data,
    /// its energy a_h(uⁿ,uⁿ) replaced by 2Eⁿ (the Dirichlet jump measured against u_D); the state for
    /// the next step. A step without u gets no audit and keeps no state.
    pub fn audited(&self, prev: Option<&AuditState>, r: &StepResult) -> Result<(StepResult, Option<AuditState>)> {
        let mut r = r.clone();
        if r.u.len() != self.space.n_dofs {
            return Ok((r, None));
        }
        let (forms, space) = (self.forms(), &self.space);
        let ne = self.mesh.edges.len();
        let u = self.displacement(&r.u, r.t)?;
        let p = match &self.data {
            Some(d) => d.values(r.t)?,
            None => DataValues::default(),
        };
        let au = forms.apply(&self.mesh, &u);
        let bp = forms.data_vector(&p, ne);
        let stored = 0.5 * dot2(&au, &u) - dot2(&bp, &u) + 0.5 * forms.data_data(&p, &p);
        if self.data.is_some() {
            r.energy = 2.0 * stored;
        }
        let mut audit = Audit { stored_energy: stored, ..Audit::default() };
        if let Some(prev) = prev.filter(|s| s.n + 1 == r.n) {
            let du: Vec<[f64; 2]> = u.iter().zip(&prev.u).map(|(a, b)| [a[0] - b[0], a[1] - b[1]]).collect();
            let dp = p.minus(&prev.p);
            let bdp = forms.data_vector(&dp, ne);
            let adu: Vec<[f64; 2]> = au.iter().zip(&prev.au).map(|(a, b)| [a[0] - b[0], a[1] - b[1]]).collect();
            let a_u_du = dot2(&au, &du) - dot2(&bp, &du) - dot2(&bdp, &u) + forms.data_data(&p, &dp);
            audit.euler_dissipation = 0.5 * dot2(&adu, &du) - dot2(&bdp, &du) + 0.5 * forms.data_data(&dp, &dp);
            audit.friction_dissipation = space
                .contact
                .iter()
                .enumerate()
                .zip(r.slip.iter().zip(&prev.slip))
                .map(|((j, c), (s, s0))| match c.coulomb {
                    Some(f) => f * r.normal.force[j].abs() * (s - s0).abs(),
                    None => c.length * c.g_mean * (s - s0).abs(),
                })
                .sum();
            // lⁿ on the unknowns: without data the solver's own load (from the superposition's
            // patterns when superposed, within its span tolerance 1e-13 of the load); with data the
            // loads f, g alone (the solver's right-hand side then holds the lifting's part too)
            let mut l = Vec::new();
            match self.data {
                None => self.free.load_at(r.n, r.t, &mut l)?,
                Some(_) => self.free.loads().assemble_loads(r.t, &mut l)?,
            }
            let mut external: f64 = l.iter().zip(r.u.iter().zip(&prev.w)).map(|(l, (a, b))| l * (a - b)).sum();
            let mut reactions = 0.0;
            if let Some(data) = &self.data {
                let lc = self.free.loads().constrained(r.t)?;
                for ((e, a), lc) in data.constrained(&space.contact).into_iter().zip(lc) {
                    let d = du[e][0] * a[0] + du[e][1] * a[1];
                    let force = (au[e][0] - bp[e][0]) * a[0] + (au[e][1] - bp[e][1]) * a[1] - lc;
                    external += lc * d;
                    reactions += force * d;
                }
            }
            for (c, p) in space.contact.iter().zip(&r.normal.force) {
                reactions -= p * (du[c.edge][0] * c.normal[0] + du[c.edge][1] * c.normal[1]);
            }
            audit.external_work = external;
            audit.boundary_work = reactions + forms.data_data(&p, &dp) - dot2(&bdp, &u);
            audit.balance_residual = a_u_du + audit.friction_dissipation - audit.external_work - audit.boundary_work;
        }
        r.audit = Some(audit);
        let state = AuditState { n: r.n, w: r.u.clone(), u, au, p, slip: r.slip.clone() };
        Ok((r, Some(state)))
    }

    /// The audit state of a step that is not handed out again (the first step of a resumed run).
    pub fn audit_state(&self, r: &StepResult) -> Result<Option<AuditState>> {
        Ok(self.audited(None, r)?.1)
    }
}
