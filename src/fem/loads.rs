//! The load functional t ↦ lⁿ on the unknowns of V_h:
//!   (lⁿ, v) = ∫_Ω f(tₙ)·v (Dunavant degree 4) + Σ_{Neumann e} ∫_e g(tₙ)·v (3-point Gauss).
//! Quadrature points and the weights w·φ feeding each unknown are stored once, so each step evaluates the
//! (compiled) load expressions at all points of a term in one batch, then scatters sequentially.
//!
//! **Separated loads.** A term whose components are sums of time factors times space parts,
//! f = Σ_j τ_j(t) s_j(x) (`Expr::separate`: the loads of 10 of the 13 scenes of `verification/cases/`
//! and of the polynomial benchmark; not the moving fronts of mms_front, mms_rotated and
//! mms_stick_to_slip), is assembled once per distinct τ_j into a pattern P_j at set-up, and a
//! time node costs l = Σ_j τ_j(tₙ) P_j: [`MAX_FACTORS`] multiply-adds per unknown of the support instead
//! of the expressions at every quadrature point. The two routes compute the same integrals with the
//! products reassociated (a test bounds the difference at 1e-14 of the load's size).
//!
//! Storage is what a time node streams through memory, so it is compact: the points of one triangle
//! (or one Neumann edge) feed the same three edges, stored once per such group; per point only its three
//! weights w·φᵢ; the unknowns and vector coefficients of an edge come from one table shared by all terms.
//! The sums are those of a plain point-by-point scatter, in the same order (the same bits).
//!
//! **Boundary data.** With nonzero u_D or g_n (`fem::lifting`) the load of the unknowns also carries
//! the lifting's right-hand side b_D(tₙ; ·) − a_h(u_Lⁿ, ·) ([`LiftRhs`], evaluated at every node: such
//! loads are not separated), and [`Loads::constrained`] gives (lⁿ, ·) on the constrained components
//! (for the reactions of the energy audit). Without data neither exists and nothing changes.

use super::elasticity::Elasticity;
use super::lifting::{BoundaryData, LiftRhs};
use super::space::CrSpace;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::expr::program::Program;
use crate::scene::expr::sym::Sym;
use crate::scene::expr::{factor_slot, BoundSet, Expr, ExprSet, Vec2Expr};
use crate::scene::Scene;
use constrained::constrained_terms;
use points::load_points;

mod constrained;
mod points;

/// Per point of a load term feeding constrained components: (component, weight w·φ, vector coefficient).
pub(super) type PointWeights = Vec<(usize, f64, [f64; 2])>;

/// A quadrature point of a load term: position, and the (edge, weight · φ) pairs it feeds.
#[derive(Clone, Debug)]
pub(super) struct LoadPoint {
    x: [f64; 2],
    edges: [(usize, f64); 3],
}

/// Largest number of distinct time factors assembled as patterns (a node then costs at most this many
/// multiply-adds per unknown of the support); terms beyond it are evaluated at every node.
pub const MAX_FACTORS: usize = 8;

/// The quadrature of one vector load (body force or one Neumann part) in scatter form.
#[derive(Clone, Debug)]
struct Quad {
    /// Consecutive points feeding the same three edges: the edges and the number of points.
    groups: Vec<([u32; 3], u32)>,
    /// Per point: the weight w·φᵢ of each of its group's edges.
    weights: Vec<[f64; 3]>,
}

/// A load term evaluated at every time node.
#[derive(Clone, Debug)]
struct LoadTerm {
    /// Both components, compiled together and bound to the quadrature points.
    expr: BoundSet,
    quad: Quad,
}

/// The separated terms: l_sep(t) = Σ_j τ_j(t) P_j.
#[derive(Clone, Debug)]
struct Patterns {
    /// The time factors τ_j, compiled together (output j).
    factors: Program,
    /// An expression each factor came from (for messages).
    names: Vec<Expr>,
    /// P_j on the support.
    vectors: Vec<Vec<f64>>,
}

thread_local! {
    /// The expression values of a term, kept from one time node to the next (megabytes on fine meshes).
    static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The load functional t ↦ l(t) on the unknowns.
#[derive(Clone, Debug)]
pub struct Loads {
    /// Terms evaluated at every node.
    terms: Vec<LoadTerm>,
    patterns: Patterns,
    /// The (support slot, vector coefficient) pairs of edge e: `edge_terms[edge_first[e]..edge_first[e + 1]]`.
    edge_first: Vec<u32>,
    edge_terms: Vec<(u32, [f64; 2])>,
    n_dofs: usize,
    /// The unknowns any load can touch, increasing (all of them with a body force, only boundary ones
    /// with tractions alone).
    support: Vec<usize>,
    /// The boundary data and their right-hand side (`None` without data).
    lift: Option<Lift>,
}

/// What boundary data add to the loads.
#[derive(Clone, Debug)]
struct Lift {
    data: BoundaryData,
    rhs: LiftRhs,
    /// The support slot of every unknown (usize::MAX off the support).
    slot: Vec<usize>,
    /// The load terms at the points that feed a constrained component: per term its expression bound
    /// to those points and per point (component, weight w·φ, vector coefficient).
    constrained: Vec<(BoundSet, Vec<PointWeights>)>,
    n_constrained: usize,
}

impl Loads {
    /// Quadrature points of the body force (if any) and of every Neumann part with a traction; the
    /// terms that separate are assembled into patterns now (an error if a space part is not finite).
    /// With `data`, the lifting's part of the right-hand side too.
    pub fn new(scene: &Scene, mesh: &Mesh, space: &CrSpace, data: Option<&BoundaryData>) -> Result<Loads> {
        Self::with_separation(scene, mesh, space, data, true)
    }

    /// As [`Loads::new`]; with `separate = false` every term is evaluated at every node (the reference
    /// route the patterns are tested against).
    pub fn with_separation(
        scene: &Scene,
        mesh: &Mesh,
        space: &CrSpace,
        data: Option<&BoundaryData>,
        separate: bool,
    ) -> Result<Loads> {
        let raw = load_points(scene, mesh, space);
        let mut loads = Loads::on_support(scene, mesh, (space, data), &raw);
        loads.add_terms(raw, separate)?;
        Ok(loads)
    }

    /// The loads of the quadrature points `raw` with no term yet: their support (the unknowns they and
    /// the lifting of `data` touch) and the lifting's part.
    fn on_support(
        scene: &Scene,
        mesh: &Mesh,
        (space, data): (&CrSpace, Option<&BoundaryData>),
        raw: &[(&Vec2Expr, Vec<LoadPoint>)],
    ) -> Loads {
        let mut touched = vec![false; space.n_dofs];
        for p in raw.iter().flat_map(|t| &t.1) {
            for &(e, _) in &p.edges {
                for (k, _) in space.edge_dof[e].terms() {
                    touched[k] = true;
                }
            }
        }
        let lift_parts = data.map(|data| {
            let law = Elasticity::new(&scene.material);
            let rhs = LiftRhs::new(mesh, &space.edge_dof, &space.contact, data, &law, scene.rho);
            rhs.unknowns().for_each(|k| touched[k] = true);
            (data.clone(), rhs, constrained_terms(raw, data, space))
        });
        let support: Vec<usize> = (0..space.n_dofs).filter(|&k| touched[k]).collect();
        let mut slot = vec![usize::MAX; space.n_dofs];
        for (i, &k) in support.iter().enumerate() {
            slot[k] = i;
        }
        let mut edge_first = vec![0u32];
        let mut edge_terms = Vec::new();
        for dof in &space.edge_dof {
            edge_terms.extend(dof.terms().map(|(k, c)| (slot[k] as u32, c)));
            edge_first.push(edge_terms.len() as u32);
        }
        Loads {
            terms: Vec::new(),
            patterns: Patterns { factors: Program::new(&[]), names: Vec::new(), vectors: Vec::new() },
            edge_first,
            edge_terms,
            n_dofs: space.n_dofs,
            lift: lift_parts.map(|(data, rhs, (constrained, n_constrained))| Lift {
                data,
                rhs,
                slot: slot.clone(),
                constrained,
                n_constrained,
            }),
            support,
        }
    }

    /// Add the terms of the quadrature points `raw`: those that separate (unless `separate` is false)
    /// to the patterns, the others as terms evaluated at every node.
    fn add_terms(&mut self, raw: Vec<(&Vec2Expr, Vec<LoadPoint>)>, separate: bool) -> Result<()> {
        let loads = self;
        let mut factors: Vec<(String, Sym)> = Vec::new();
        let mut values = Vec::new();
        for (e, pts) in raw {
            let quad = Quad::new(&pts);
            let points: Vec<[f64; 2]> = pts.iter().map(|p| p.x).collect();
            let Some(parts) = separated(e, &mut factors, separate) else {
                loads.terms.push(LoadTerm { expr: ExprSet::new(&[&e.0[0], &e.0[1]]).bind(points), quad });
                continue;
            };
            for &(j, _) in &parts {
                if j == loads.patterns.vectors.len() {
                    loads.patterns.vectors.push(vec![0.0; loads.support.len()]);
                    loads.patterns.names.push(e.0[0].clone());
                }
            }
            // all parts of the term in one program (their common subexpressions, such as cos(x), computed
            // once a point) and one pass over the points
            let names: Vec<&Expr> = parts.iter().flat_map(|_| [&e.0[0], &e.0[1]]).collect();
            let trees: Vec<&Sym> = parts.iter().flat_map(|(_, [sx, sy])| [sx, sy]).collect();
            ExprSet::derived(&names, &trees).eval(&points, 0.0, &mut values)?;
            let mut outs: Vec<Vec<f64>> =
                parts.iter().map(|&(j, _)| std::mem::take(&mut loads.patterns.vectors[j])).collect();
            loads.scatter(&quad, &values, &mut outs.iter_mut().map(|p| &mut p[..]).collect::<Vec<_>>());
            for (&(j, _), p) in parts.iter().zip(outs) {
                loads.patterns.vectors[j] = p;
            }
        }
        loads.patterns.factors = Program::new(&factors.iter().map(|(_, tau)| tau).collect::<Vec<_>>());
        Ok(())
    }

    /// Number of load patterns (distinct time factors of the separated terms).
    pub fn n_patterns(&self) -> usize {
        self.patterns.vectors.len()
    }

    /// The patterns P_j on the support when every term is separated (l(t) = Σ_j τ_j(t) P_j exactly);
    /// `None` when a term is evaluated at every node.
    pub fn separated(&self) -> Option<&[Vec<f64>]> {
        (self.terms.is_empty() && self.lift.is_none()).then_some(&self.patterns.vectors[..])
    }

    /// The time factors τ_j(t) of the patterns; a non-finite one is an error naming its expression.
    pub fn time_factors(&self, t: f64) -> Result<Vec<f64>> {
        let p = &self.patterns;
        let mut tau = vec![0.0; p.vectors.len()];
        if !tau.is_empty() {
            p.factors.eval_point(0.0, 0.0, t, &mut tau);
        }
        match tau.iter().zip(&p.names).find(|(c, _)| !c.is_finite()) {
            Some((c, name)) => Err(name.error(format!("value {c} at t = {t} (of a time factor, at every point)"))),
            None => Ok(tau),
        }
    }

    /// The unknowns a load can be nonzero on (increasing).
    pub fn support(&self) -> &[usize] {
        &self.support
    }

    /// l(t) restricted to [`Loads::support`], into `out`: the right-hand side of a step, so with
    /// boundary data the lifting's part included (`fem::lifting`).
    pub fn assemble_on_support(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        self.assemble_loads_on_support(t, out)?;
        if let Some(lift) = &self.lift {
            let v = lift.data.values(t)?.flat();
            lift.rhs.add(&v, &lift.slot, out);
        }
        Ok(())
    }

    /// (lⁿ, ψ_k) of the loads f and g alone on every unknown (with boundary data, l(t) without the
    /// lifting's part; otherwise [`Loads::assemble`]).
    pub fn assemble_loads(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        let mut s = Vec::new();
        self.assemble_loads_on_support(t, &mut s)?;
        self.expand(&s, out);
        Ok(())
    }

    /// The loads f and g alone on the support.
    fn assemble_loads_on_support(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        out.clear();
        out.resize(self.support.len(), 0.0);
        for (c, v) in self.time_factors(t)?.into_iter().zip(&self.patterns.vectors) {
            out.iter_mut().zip(v).for_each(|(o, x)| *o += c * x);
        }
        SCRATCH.with(|cell| {
            // a nested call on this thread (none today) would get a buffer of its own
            let mut own = Vec::new();
            let mut borrowed = cell.try_borrow_mut();
            let values = borrowed.as_deref_mut().unwrap_or(&mut own);
            for term in &self.terms {
                // the expression values in parallel batches, the sums sequentially: bit-identical results
                term.expr.eval(t, values)?;
                self.scatter(&term.quad, values, &mut [&mut out[..]]);
            }
            Ok(())
        })
    }

    /// outs[j] += the quadrature sums of the j-th pair of `values` (2 · outs.len() per point,
    /// point-major) over the points of `quad`; each sum in the order of a scatter of that pair alone.
    fn scatter(&self, quad: &Quad, values: &[f64], outs: &mut [&mut [f64]]) {
        let mut points = values.chunks_exact(2 * outs.len()).zip(&quad.weights);
        for &(edges, n) in &quad.groups {
            let terms = edges.map(|e| {
                &self.edge_terms[self.edge_first[e as usize] as usize..self.edge_first[e as usize + 1] as usize]
            });
            for (v, w) in points.by_ref().take(n as usize) {
                for (terms, w) in terms.iter().zip(w) {
                    for &(slot, c) in *terms {
                        for (out, v) in outs.iter_mut().zip(v.chunks_exact(2)) {
                            out[slot as usize] += w * (c[0] * v[0] + c[1] * v[1]);
                        }
                    }
                }
            }
        }
    }

    /// Scatter values on the support into a full vector of unknowns.
    pub fn expand(&self, on_support: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.resize(self.n_dofs, 0.0);
        for (&k, &v) in self.support.iter().zip(on_support) {
            out[k] = v;
        }
    }

    /// l(t) into `out` (length = number of unknowns).
    pub fn assemble(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        let mut s = Vec::new();
        self.assemble_on_support(t, &mut s)?;
        self.expand(&s, out);
        Ok(())
    }
}

impl Quad {
    fn new(pts: &[LoadPoint]) -> Quad {
        let mut groups: Vec<([u32; 3], u32)> = Vec::new();
        for p in pts {
            let edges = p.edges.map(|(e, _)| e as u32);
            match groups.last_mut() {
                Some((g, n)) if *g == edges => *n += 1,
                _ => groups.push((edges, 1)),
            }
        }
        Quad { groups, weights: pts.iter().map(|p| p.edges.map(|(_, w)| w)).collect() }
    }
}

/// The parts of `e` by time factor, (index into `factors`, [x part, y part]), when both components
/// separate and the factors (new ones appended to `factors`, keyed by their tree) stay within
/// [`MAX_FACTORS`]; `None` (and `factors` unchanged) otherwise.
fn separated(e: &Vec2Expr, factors: &mut Vec<(String, Sym)>, separate: bool) -> Option<Vec<(usize, [Sym; 2])>> {
    if !separate {
        return None;
    }
    let comps = [e.0[0].separate()?, e.0[1].separate()?];
    let mut known = factors.clone();
    let mut out: Vec<(usize, [Sym; 2])> = Vec::new();
    for (c, parts) in comps.into_iter().enumerate() {
        for (tau, space) in parts {
            let j = factor_slot(&mut known, tau);
            let at = out.iter().position(|(i, _)| *i == j).unwrap_or_else(|| {
                out.push((j, [Sym::Num(0.0), Sym::Num(0.0)]));
                out.len() - 1
            });
            out[at].1[c] = space;
        }
    }
    if known.len() > MAX_FACTORS {
        return None;
    }
    *factors = known;
    out.sort_by_key(|(j, _)| *j);
    Some(out)
}
