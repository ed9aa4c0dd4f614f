//! The friction problem of one time step, condensed onto the Γ_C unknowns.
//!
//! With K the stiffness on V_h (factored once), E the injection of the contact unknowns s (one tangential
//! displacement per Γ_C edge), l the load and s_old the previous step's s, a step solves
//!   K u = l − E μ,   μ_e ∈ w_e ∂|·|(s_e − s_old,e),   w_e = |e| ḡ_e,
//! (μ is the friction force on edge e; the tangential traction is σ_τ·τ_e = −μ_e/|e|). Writing
//! u_f = K⁻¹l, C = Eᵀ K⁻¹ E (dense, SPD, n_c × n_c) and d = Eᵀu_f − s_old, the slip increment is
//! Δs = d − Cμ and μ solves the box-constrained dual QP
//!   min_μ q(μ) = ½ μᵀCμ − dᵀμ   subject to |μ_e| ≤ w_e,
//! whose KKT conditions are exactly Tresca's law on every edge. The natural residual
//!   r(μ) = max_e |μ_e − P_e(μ_e + Δs_e / C_ee)| / F,   F = max_e min(w_e, |d_e|/C_ee),
//! vanishes exactly at the solution and is what every solver reports.

use crate::cr::CrSpace;
use crate::error::Error;
use crate::factor::Factor;
use faer::Mat;
use nalgebra::DMatrix;
use std::cell::RefCell;

/// Condensed operator of the contact unknowns.
pub struct Condensed {
    /// Unknown index of each contact edge.
    pub dofs: Vec<usize>,
    /// Friction weights w_e = |e| ḡ_e.
    pub w: Vec<f64>,
    /// ḡ_e.
    pub g: Vec<f64>,
    /// C = Eᵀ K⁻¹ E.
    pub c: DMatrix<f64>,
    /// Z = K⁻¹ E (column-major, n × n_c) when it fits in memory; otherwise u is recovered by a second solve.
    pub z: Option<Vec<f64>>,
    /// The last μ given to [`Condensed::apply_friction`] and its K⁻¹Eμ: once Γ_C slips (or sticks)
    /// everywhere μ stays the same from step to step, and K⁻¹Eμ is reused instead of recomputed
    /// (keyed on bit-equal μ, so the result does not depend on the cache).
    friction_cache: RefCell<(Vec<f64>, Vec<f64>)>,
}

/// Largest Z kept in memory (entries); beyond it a second triangular solve per step is cheaper in memory.
const Z_MAX_ENTRIES: usize = 50_000_000;

impl Condensed {
    /// Build C (and Z) with blocked multi-right-hand-side solves.
    pub fn new(space: &CrSpace, llt: &Factor) -> Condensed {
        let n = space.n_dofs;
        let dofs: Vec<usize> = space.contact.iter().map(|c| c.dof).collect();
        let nc = dofs.len();
        let keep_z = n.saturating_mul(nc) <= Z_MAX_ENTRIES;
        let mut z = if keep_z { Some(vec![0.0; n * nc]) } else { None };
        let mut c = DMatrix::zeros(nc, nc);
        const BLOCK: usize = 64;
        for start in (0..nc).step_by(BLOCK) {
            let end = (start + BLOCK).min(nc);
            let mut rhs = Mat::<f64>::zeros(n, end - start);
            for j in start..end {
                rhs[(dofs[j], j - start)] = 1.0;
            }
            llt.solve_many(rhs.as_mut());
            for j in start..end {
                for i in 0..nc {
                    c[(i, j)] = rhs[(dofs[i], j - start)];
                }
                if let Some(z) = z.as_mut() {
                    for r in 0..n {
                        z[j * n + r] = rhs[(r, j - start)];
                    }
                }
            }
        }
        let c = 0.5 * (&c + c.transpose());
        let w = space.contact.iter().map(|e| e.length * e.g_mean).collect();
        let g = space.contact.iter().map(|e| e.g_mean).collect();
        Condensed { dofs, w, g, c, z, friction_cache: RefCell::new((vec![], vec![])) }
    }

    /// Eᵀ K⁻¹ l = Zᵀ l (requires Z).
    pub fn trace_of_solution(&self, l: &[f64]) -> Vec<f64> {
        let z = self.z.as_ref().expect("Z is kept");
        let n = l.len();
        (0..self.dofs.len()).map(|j| z[j * n..(j + 1) * n].iter().zip(l).map(|(a, b)| a * b).sum()).collect()
    }

    /// u ← u_f − K⁻¹ E μ, with K⁻¹Eμ = Σ_e μ_e z_e from Z, or one pair of triangular solves without it.
    pub fn apply_friction(&self, llt: &Factor, u: &mut [f64], mu: &[f64]) {
        let n = u.len();
        let mut cache = self.friction_cache.borrow_mut();
        let (last_mu, zmu) = &mut *cache;
        let same = last_mu.len() == mu.len()
            && zmu.len() == n
            && last_mu.iter().zip(mu).all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            zmu.clear();
            zmu.resize(n, 0.0);
            match &self.z {
                Some(z) => {
                    for (j, &m) in mu.iter().enumerate() {
                        if m != 0.0 {
                            let col = &z[j * n..(j + 1) * n];
                            zmu.iter_mut().zip(col).for_each(|(a, zi)| *a += m * zi);
                        }
                    }
                }
                None => {
                    for (j, &m) in mu.iter().enumerate() {
                        zmu[self.dofs[j]] = m;
                    }
                    llt.solve_in_place(zmu);
                }
            }
            last_mu.clear();
            last_mu.extend_from_slice(mu);
        }
        u.iter_mut().zip(zmu.iter()).for_each(|(ui, a)| *ui -= a);
    }
}

/// One step's dual QP: min ½μᵀCμ − dᵀμ, |μ_e| ≤ w_e.
pub struct Qp<'a> {
    pub c: &'a DMatrix<f64>,
    pub d: &'a [f64],
    pub w: &'a [f64],
}

impl Qp<'_> {
    /// Slip increment Δs = d − Cμ.
    pub fn slip_increment(&self, mu: &[f64]) -> Vec<f64> {
        let n = self.d.len();
        let mut ds = self.d.to_vec();
        for j in 0..n {
            let m = mu[j];
            if m != 0.0 {
                let col = self.c.column(j);
                for i in 0..n {
                    ds[i] -= col[i] * m;
                }
            }
        }
        ds
    }

    /// Projection onto [−w_e, w_e].
    pub fn project(&self, e: usize, v: f64) -> f64 {
        v.clamp(-self.w[e], self.w[e])
    }

    /// Force scale F = max_e min(w_e, |d_e|/C_ee): the size of the friction forces of this step (all-stick
    /// forces are about |d|/C_ee, all-slip forces are w). Residuals are relative to it, so a huge bound
    /// (g_a → ∞) does not make every iterate look converged.
    pub fn force_scale(&self) -> f64 {
        (0..self.d.len()).map(|e| self.w[e].min(self.d[e].abs() / self.c[(e, e)])).fold(0.0, f64::max)
    }

    /// Natural residual r(μ) = max_e |μ_e − P_e(μ_e + Δs_e/C_ee)| / F, given Δs (see module doc).
    pub fn residual(&self, mu: &[f64], ds: &[f64]) -> f64 {
        let mut r: f64 = 0.0;
        for e in 0..mu.len() {
            r = r.max((mu[e] - self.project(e, mu[e] + ds[e] / self.c[(e, e)])).abs());
        }
        if r == 0.0 {
            0.0
        } else {
            r / self.force_scale().max(f64::MIN_POSITIVE)
        }
    }
}

/// Stick (0) or slip (1) per edge: slip when the bound is reached and the increment is nonzero.
pub fn classify(qp: &Qp, mu: &[f64], ds: &[f64]) -> Vec<u8> {
    let scale = ds.iter().chain(qp.d).fold(0.0f64, |a, v| a.max(v.abs()));
    mu.iter()
        .zip(ds)
        .zip(qp.w)
        .map(|((m, s), w)| {
            u8::from(
                *w > 0.0 && m.abs() >= w * (1.0 - 1e-9) && s.abs() > 1e-9 * scale
                    || *w == 0.0 && s.abs() > 1e-9 * scale,
            )
        })
        .collect()
}

/// Outcome of a per-step friction solve.
#[derive(Clone, Debug)]
pub struct FrictionSolution {
    pub mu: Vec<f64>,
    pub iterations: usize,
    pub residual: f64,
}

/// Failure of a per-step solver before its iteration limit (e.g. detected cycling).
pub fn not_converged(solver: &'static str, iterations: usize, residual: f64, tol: f64) -> Error {
    Error::NotConverged { step: 0, time: f64::NAN, solver, iterations, residual, tol }
}
