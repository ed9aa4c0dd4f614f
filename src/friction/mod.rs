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
//!
//! With normal unknowns (a unilateral or a Coulomb part, [`normal`]) the condensed problem has one more
//! unknown per Γ_C edge, the normal force P_e, with its own bounds; the QP's bounds are then per unknown,
//! [lo_e, hi_e] with hi_e = +∞ allowed (module [`normal`] states the problem).
//!
//! A floating body (no Dirichlet part) adds the equilibrium of its rigid motions, Gᵀλ = e, with
//! multiplier α ([`floating`]).

pub mod balance;
pub mod coulomb;
pub mod floating;
pub mod hik;
pub mod nested;
pub mod normal;
pub mod pdas;
pub mod ssn;
pub mod uzawa;

use crate::error::{Error, Result};
use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use crate::scene::{Method, Scene, SolverSettings};
use nalgebra::DMatrix;
use normal::Normal;

/// The friction problem of a run: C, the weights and the per-step solver.
pub struct Friction {
    /// C = Eᵀ K⁻¹ E.
    c: DMatrix<f64>,
    /// Friction weights w_e = |e| ḡ_e.
    w: Vec<f64>,
    /// ḡ_e, the mean of g_a over edge e (Uzawa's c_τ).
    g_mean: Vec<f64>,
    settings: SolverSettings,
    /// Steps at which the bound was treated as zero (below the rounding of the load).
    zeroed: std::sync::atomic::AtomicUsize,
    /// The normal unknowns (`None`: the bilateral Tresca problem, tangential unknowns only).
    normal: Option<Normal>,
    /// The rigid motions of a floating body (`None`: a Dirichlet part fixes them).
    floating: Option<floating::Floating>,
}

/// What a step's friction solve produced.
#[derive(Clone, Debug)]
pub struct FrictionSolution {
    /// Friction force per contact edge.
    pub mu: Vec<f64>,
    /// Δs = d − Cμ.
    pub slip_increment: Vec<f64>,
    pub state: Vec<EdgeState>,
    pub iterations: usize,
    pub residual: f64,
    /// Normal force P_e per normal unknown (empty without normal unknowns).
    pub normal: Vec<f64>,
    /// u_n(m_e) − ḡ_e per normal unknown (empty without).
    pub gap: Vec<f64>,
    /// Separated (no pressure, open gap) per normal unknown (empty without).
    pub separated: Vec<bool>,
    /// α, the rigid motion of a floating body (u = K⁺(l − Eλ) + Rα; empty otherwise).
    pub rigid: Vec<f64>,
}

/// Stick or slip of one contact edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum EdgeState {
    Stick = 0,
    Slip = 1,
}

/// A per-step solver that stopped short of the tolerance: which (and why), after how many iterations,
/// at what residual. [`Friction::solve`] turns it into [`Error::NotConverged`] with the step and time.
#[derive(Clone, Debug)]
pub struct Stalled {
    pub solver: &'static str,
    pub iterations: usize,
    pub residual: f64,
}

impl Friction {
    /// The problem of `scene` on the contact edges of `space` with operator `c` (see `solve::condense`);
    /// with normal unknowns, `uzawa` is refused (it iterates on multipliers scaled by a finite bound).
    pub fn new(scene: &Scene, mesh: &Mesh, space: &CrSpace, c: DMatrix<f64>) -> Result<Friction> {
        let w = space.contact.iter().map(|e| e.length * e.g_mean).collect();
        let g_mean = space.contact.iter().map(|e| e.g_mean).collect();
        let mut f = Friction::from_parts(c, w, g_mean, scene.solver);
        f.normal = Normal::new(scene, mesh, space);
        if f.normal.is_some() && scene.solver.method == Method::Uzawa {
            return Err(Error::scene(
                &scene.file,
                "solver.method",
                "uzawa solves the bilateral Tresca problem only: with a unilateral or Coulomb part use ssn",
            ));
        }
        Ok(f)
    }

    /// The problem of operator C, weights w and mean bounds ḡ (Uzawa's c_τ).
    pub(crate) fn from_parts(c: DMatrix<f64>, w: Vec<f64>, g_mean: Vec<f64>, settings: SolverSettings) -> Friction {
        Friction { c, w, g_mean, settings, zeroed: Default::default(), normal: None, floating: None }
    }

    /// The problem of a floating body whose rigid motions have the trace `g` on the contact unknowns
    /// (G = EᵀR, orthonormal columns; [`floating`]).
    pub fn with_floating(mut self, g: DMatrix<f64>, motions: crate::solve::kernel::Motions) -> Friction {
        self.floating = Some(floating::Floating::new(&self.c, g, motions));
        self
    }

    /// True for a floating body (its steps need the net load e = Rᵀlⁿ: [`Friction::solve_rigid`]).
    pub fn is_floating(&self) -> bool {
        self.floating.is_some()
    }

    /// [`Friction::solve`] for a floating body: `alpha0` warm-starts α, `e` = Rᵀlⁿ; without rigid
    /// motions it is [`Friction::solve`].
    pub fn solve_rigid(
        &self,
        d: &[f64],
        (lam0, alpha0): (&[f64], &[f64]),
        e: &[f64],
        n: usize,
        t: f64,
    ) -> Result<FrictionSolution> {
        match &self.floating {
            Some(fl) => fl.solve(self, (d, lam0, alpha0), e, n, t),
            None => self.solve(d, lam0, n, t),
        }
    }

    /// The normal unknowns, if any.
    pub fn normal(&self) -> Option<&Normal> {
        self.normal.as_ref()
    }

    /// Solve step n (time t) with d = s_f − s_old from the warm start μ₀ with the scene's method, to
    /// natural residual ≤ tol. With normal unknowns d and μ₀ hold the normal entries after the
    /// tangential ones (d_n = s_f,n − ḡ, `normal`).
    pub fn solve(&self, d: &[f64], mu0: &[f64], n: usize, t: f64) -> Result<FrictionSolution> {
        self.solve_on(&self.c, d, mu0, n, t)
    }

    /// [`Friction::solve`] with the operator `c` in place of C (`floating`: C + ρGGᵀ).
    fn solve_on(&self, c: &DMatrix<f64>, d: &[f64], mu0: &[f64], n: usize, t: f64) -> Result<FrictionSolution> {
        if let Some(nm) = &self.normal {
            return nm.solve(self, c, d, mu0, n, t);
        }
        let (k, zeroed, w, d, mu0) = scaled(c, &self.w, d, mu0);
        if zeroed {
            self.zeroed.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        let g_mean: Vec<f64> = if k != 0 || zeroed {
            self.g_mean.iter().zip(&w).map(|(g, w)| if *w == 0.0 { 0.0 } else { pow2_scale(*g, -k) }).collect()
        } else {
            self.g_mean.clone()
        };
        let lo: Vec<f64> = w.iter().map(|w| -w).collect();
        let qp = Qp { c, d: &d, lo: &lo, hi: &w };
        let s = &self.settings;
        let sol = match s.method {
            Method::Ssn => ssn::solve(&qp, &mu0, s.tol, s.max_iter()),
            Method::Pdas => pdas::solve(&qp, &mu0, s.tol, s.max_iter()),
            Method::Uzawa => {
                let rho = if s.uzawa_step > 0.0 { s.uzawa_step } else { uzawa::auto_step(&qp, &g_mean) };
                uzawa::solve(&qp, &g_mean, &mu0, rho, s.tol, s.max_iter())
            }
        };
        let (mu, iterations, residual) = sol.map_err(|e| not_converged(e, n, t, s.tol))?;
        let slip_increment = qp.slip_increment(&mu);
        let state = classify(&qp, &mu, &slip_increment);
        let back = |v: Vec<f64>| if k == 0 { v } else { v.into_iter().map(|x| pow2_scale(x, k)).collect() };
        Ok(FrictionSolution {
            mu: back(mu),
            slip_increment: back(slip_increment),
            state,
            iterations,
            residual,
            normal: vec![],
            gap: vec![],
            separated: vec![],
            rigid: vec![],
        })
    }

    /// The diagonal C_ee of the condensed operator (the slip of edge e per unit friction force on it).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.w.len()).map(|e| self.c[(e, e)]).collect()
    }

    /// Number of steps whose friction bound was below the rounding of the load and treated as zero.
    pub fn zeroed_steps(&self) -> usize {
        self.zeroed.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// Largest and smallest force scale (2^±450, about 1e±135) solved as given: q(μ) = ½μᵀCμ − dᵀμ and the
/// solvers' products stay far from overflow and underflow. Beyond, the step is solved for 2^-k (d, μ₀, w)
/// and the result scaled back, exactly (powers of two; the problem is positively homogeneous).
const SAFE_EXP: i32 = 450;

/// A friction bound whose effect on the slip, C_ee·w_e, is below this fraction of the free slip |d_e|
/// is below the rounding of the load: it is treated as zero for the step (frictionless).
const NEGLIGIBLE: f64 = 1e-17;

fn pow2(k: i32) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// v · 2^k (two factors, so |k| may reach 2046).
fn pow2_scale(v: f64, k: i32) -> f64 {
    let h = k / 2;
    v * pow2(h) * pow2(k - h)
}

/// The error of a step whose solver stalled.
fn not_converged(e: Stalled, n: usize, t: f64, tol: f64) -> Error {
    Error::NotConverged { step: n, time: t, solver: e.solver, iterations: e.iterations, residual: e.residual, tol }
}

/// (k, zeroed, w, d, μ₀) of the step to solve: scaled by 2^-k where the forces are beyond 2^±SAFE_EXP,
/// and w = 0 where the friction is below the rounding of the load (see [`NEGLIGIBLE`]).
fn scaled(c: &DMatrix<f64>, w: &[f64], d: &[f64], mu0: &[f64]) -> (i32, bool, Vec<f64>, Vec<f64>, Vec<f64>) {
    let stick = (0..d.len()).map(|e| d[e].abs() / c[(e, e)]).fold(0.0f64, f64::max);
    let w_max = w.iter().fold(0.0f64, |a, v| a.max(*v));
    let zeroed = w_max > 0.0 && w_max < NEGLIGIBLE * stick;
    let w: Vec<f64> = if zeroed { vec![0.0; w.len()] } else { w.to_vec() };
    let mu0: Vec<f64> = if zeroed { vec![0.0; mu0.len()] } else { mu0.to_vec() };
    let m = mu0.iter().fold(stick.max(w_max), |a, v| a.max(v.abs()));
    if m == 0.0 || !m.is_finite() || (m >= pow2(-SAFE_EXP) && m <= pow2(SAFE_EXP)) {
        return (0, zeroed, w, d.to_vec(), mu0);
    }
    let k = m.log2().floor() as i32;
    let s = |v: &[f64]| v.iter().map(|x| pow2_scale(*x, -k)).collect::<Vec<f64>>();
    (k, zeroed, s(&w), s(d), s(&mu0))
}

/// A solver's result: (μ, iterations, residual).
pub type Solved = std::result::Result<(Vec<f64>, usize, f64), Stalled>;

/// One step's dual QP: min ½μᵀCμ − dᵀμ, lo_e ≤ μ_e ≤ hi_e (Tresca's box: lo = −w, hi = w; a normal
/// force: [0, +∞) unilateral, (−∞, +∞) bilateral).
pub struct Qp<'a> {
    pub c: &'a DMatrix<f64>,
    pub d: &'a [f64],
    pub lo: &'a [f64],
    pub hi: &'a [f64],
}

impl Qp<'_> {
    /// Slip increment Δs = d − Cμ.
    pub fn slip_increment(&self, mu: &[f64]) -> Vec<f64> {
        let n = self.d.len();
        let mut ds = self.d.to_vec();
        for (j, &m) in mu.iter().enumerate().take(n) {
            if m != 0.0 {
                let col = self.c.column(j);
                for (d, c) in ds.iter_mut().zip(col.iter()) {
                    *d -= c * m;
                }
            }
        }
        ds
    }

    /// Projection onto [lo_e, hi_e].
    pub fn project(&self, e: usize, v: f64) -> f64 {
        v.clamp(self.lo[e], self.hi[e])
    }

    /// Force scale F = max_e min(max(|lo_e|, hi_e), |d_e|/C_ee): the size of the forces of this step
    /// (all-stick forces are about |d|/C_ee, all-slip forces are w; an unbounded normal force counts
    /// with |d_e|/C_ee, the force that closes or holds its free gap alone). Residuals are relative to it,
    /// so a huge bound (g_a → ∞) does not make every iterate look converged.
    pub fn force_scale(&self) -> f64 {
        let bound = |e: usize| self.hi[e].max(-self.lo[e]);
        (0..self.d.len()).map(|e| bound(e).min(self.d[e].abs() / self.c[(e, e)])).fold(0.0, f64::max)
    }

    /// The half width w_e of a symmetric box [−w_e, w_e] (Uzawa's scaling; Tresca's problem only).
    pub fn half_width(&self, e: usize) -> f64 {
        self.hi[e]
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

/// Stick or slip per edge: slip when the bound is reached and the increment is nonzero.
pub fn classify(qp: &Qp, mu: &[f64], ds: &[f64]) -> Vec<EdgeState> {
    classify_with(qp.hi, qp.d, mu, ds)
}

/// [`classify`] with the bounds w of the first `mu.len()` unknowns (the tangential ones).
pub fn classify_with(w: &[f64], d: &[f64], mu: &[f64], ds: &[f64]) -> Vec<EdgeState> {
    let scale = ds.iter().chain(d).fold(0.0f64, |a, v| a.max(v.abs()));
    mu.iter()
        .zip(ds)
        .zip(w)
        .map(|((m, s), w)| {
            if *w > 0.0 && m.abs() >= w * (1.0 - 1e-9) && s.abs() > 1e-9 * scale || *w == 0.0 && s.abs() > 1e-9 * scale
            {
                EdgeState::Slip
            } else {
                EdgeState::Stick
            }
        })
        .collect()
}

/// A solver stopped at `iterations` with `residual`.
pub fn stalled(solver: &'static str, iterations: usize, residual: f64) -> Stalled {
    Stalled { solver, iterations, residual }
}

#[cfg(test)]
mod tests;
