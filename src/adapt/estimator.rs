//! A residual a posteriori error indicator per triangle for the stabilised CR discretisation of a
//! Tresca step, accumulated over the time nodes.
//!
//! **Derivation.** At a time node tₙ the discrete solution u_h = uⁿ_h is P1 on each triangle, so σ_T =
//! σ(u_h)|_T is constant and div σ_T = 0. Let e = u − u_h and |||e|||² = Σ_T ∫_T σ(e):ε(e) +
//! Σ_{e ∈ E⁰} (2ρμ/h_e)‖[u_h]‖²_e (the norm of `fem::norms`: u has no jumps). Following the residual
//! analysis of nonconforming elasticity (Carstensen–Hu 2007, "A unifying theory of a posteriori error
//! control for nonconforming finite element methods"; Dari–Durán–Padra–Vampa 1996 for CR), split the
//! broken gradient of e into a conforming part, controlled by the residual tested with a
//! quasi-interpolant v − I_h v of the error (local H¹ stability, ‖v − I_h v‖_T ≲ h_T|v|_{1,ω_T},
//! ‖v − I_h v‖_e ≲ h_e^{1/2}|v|_{1,ω_e}), and a nonconforming part, the distance of u_h to H¹, bounded by
//! the jumps of u_h (for CR they have zero mean, so ‖[u_h]‖_e ≍ h_e^{3/2}|[∂_s u_h]|: the tangential
//! derivative jumps of Carstensen–Hu and the h_e^{-1/2}‖[u_h]‖_e used here are the same term up to √12).
//! Integrating the residual by parts on each triangle, with the friction force of the step as the
//! boundary load on Γ_C (as for a Neumann part: the discrete tangential traction of edge e is
//! λ_e = −μ_e/|e|, `friction`), gives, with the energy scaled by 2μ (σ:ε ≈ 2μ|ε|²),
//!
//!   η_T² = h_T²/(2μ) ‖f‖²_T                                       element residual
//!        + Σ_{e ⊂ ∂T interior} ½ h_e/(2μ) ‖[σ(u_h)n]‖²_e           normal-stress jumps
//!        + Σ_{e ⊂ ∂T ∩ Γ_N} h_e/(2μ) ‖g − σ_T n‖²_e                 Neumann residual
//!        + Σ_{e ⊂ ∂T ∩ Γ_C} h_e/(2μ) ‖σ_T n·τ − λ_e‖²_e             friction-force mismatch
//!        + Σ_{e ⊂ ∂T, interior (½) or Γ_D} (1 + ρ) (2μ/h_e) ‖[u_h]‖²_e   nonconformity + stabilisation
//!
//! The last term's ρ part is exactly the jump part of |||e|||²; its 1 part bounds the nonconformity of
//! the broken energy. With boundary data (`fem::lifting`) u_h is the full displacement w + u_L and the
//! jump on a Dirichlet edge is u_h − u_D, as in the norm. The contact term is the Tresca mismatch of Hild–Nicaise 2007 ("Residual a
//! posteriori error estimators for contact problems in elasticity", the σ_τ(u_h) − λ_h term) and of
//! Walloth 2019 (Tresca friction); on bilateral contact the normal stress σ_n is the free reaction of
//! the constraint u_n = 0, so it has no residual. The friction law itself holds exactly at the discrete
//! level (|λ_e| ≤ ḡ_e and λ_e ∥ the slip increment, `friction`'s KKT), so the only complementarity term
//! left is the data oscillation h_e‖g_a − ḡ_e‖², zero for the piecewise constant bounds of the scenes
//! here and not computed. Constants: every term has weight 1 (reliability and efficiency hold up to
//! unknown constants); the effectivity |η/|||e|||| measured in `reference/adaptive.md` shows their size.
//!
//! **Time.** The quasi-static problem's error is measured, as in `study`, by its max over the time
//! nodes. Accordingly η = max_n (Σ_T (η_Tⁿ)²)^{1/2}, and the triangle's indicator for marking is
//! η_T² = max_n (η_Tⁿ)² (the mesh serves every step, so a triangle is refined where any step needs it).
//! The time discretisation error is not estimated (the steps are the scene's; `study` measures it).

use crate::error::Result;
use crate::fem::quadrature::{edge_point, tri_point, GAUSS2, GAUSS3, TRI4};
use crate::fem::space::{jump_terms, Element};
use crate::scene::expr::{BoundSet, ExprSet};
use crate::scene::PartKind;
use crate::stepping::{Problem, StepResult};

/// Names of the indicator's terms, in the order of [`Indicator::terms`].
pub const TERMS: [&str; 5] = ["element", "stress_jump", "neumann", "friction", "jump"];

/// A vector load bound to quadrature points (its two components in one batch).
struct Bound {
    /// `None`: traction free.
    expr: Option<BoundSet>,
    /// Per point: the triangle it charges and its weight (area or length times the rule's weight).
    at: Vec<(usize, f64)>,
    /// Per point on an edge: the edge (Neumann terms) — `usize::MAX` for body points.
    edge: Vec<usize>,
}

/// A stabilised edge and, per 2-point Gauss point, the (edge, signed basis value) terms of [u_h].
type EdgeJumps = (usize, [Vec<(usize, f64)>; 2]);

/// What the indicator of a mesh needs once: elements, edge data and bound loads.
pub struct Estimator {
    elements: Vec<Element>,
    /// h_T: longest side.
    h_tri: Vec<f64>,
    body: Option<Bound>,
    neumann: Vec<Bound>,
    /// Per stabilised edge (interior or Dirichlet), per Gauss point: the jump terms.
    jumps: Vec<EdgeJumps>,
    /// Contact edges: (edge, index in the friction force vector).
    contact: Vec<(usize, usize)>,
    /// u_D on the Dirichlet parts with data ([`dirichlet_data`]).
    dirichlet: Option<DirichletData>,
    two_mu: f64,
    rho: f64,
}

/// The indicator of one time node, per triangle (squared), with the global sum of each term.
#[derive(Clone, Debug)]
pub struct Indicator {
    pub eta2: Vec<f64>,
    /// Σ_T of each term of [`TERMS`] (squared).
    pub terms: [f64; 5],
}

impl Indicator {
    /// (Σ_T η_T²)^{1/2}.
    pub fn global(&self) -> f64 {
        self.eta2.iter().sum::<f64>().sqrt()
    }
}

impl Estimator {
    pub fn new(p: &Problem) -> Result<Estimator> {
        let mesh = &p.mesh;
        let elements: Vec<Element> = (0..mesh.tris.len()).map(|t| Element::new(mesh, t)).collect();
        let h_tri = (0..mesh.tris.len())
            .map(|t| mesh.tri_edges[t].iter().map(|&e| mesh.edge_length(e)).fold(0.0, f64::max))
            .collect();
        let body = match &p.scene.f {
            Some(f) if !f.is_zero() => {
                let (mut pts, mut at) = (Vec::new(), Vec::new());
                for (t, el) in elements.iter().enumerate() {
                    for (l, w) in TRI4 {
                        pts.push(tri_point(el.pts, l));
                        at.push((t, w * el.area));
                    }
                }
                let edge = vec![usize::MAX; pts.len()];
                Some(Bound { expr: Some(ExprSet::new(&[&f.0[0], &f.0[1]]).bind(pts)), at, edge })
            }
            _ => None,
        };
        let mut neumann = Vec::new();
        for (k, part) in p.scene.parts.iter().enumerate() {
            let PartKind::Neumann(g) = &part.kind else { continue };
            let (mut pts, mut at, mut edge) = (Vec::new(), Vec::new(), Vec::new());
            for e in (0..mesh.edges.len()).filter(|&e| p.space.edge_part[e] == Some(k)) {
                let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
                for (s, w) in GAUSS3 {
                    pts.push(edge_point(a, b, s));
                    at.push((mesh.edge_tris[e].0, w * mesh.edge_length(e)));
                    edge.push(e);
                }
            }
            let expr = g.as_ref().map(|g| ExprSet::new(&[&g.0[0], &g.0[1]]).bind(pts));
            neumann.push(Bound { expr, at, edge });
        }
        let jumps = (0..mesh.edges.len())
            .filter(|&e| p.space.is_stabilised(mesh, e))
            .map(|e| (e, GAUSS2.map(|(s, _)| jump_terms(mesh, e, s))))
            .collect();
        let contact = p.space.contact.iter().enumerate().map(|(i, c)| (c.edge, i)).collect();
        let dirichlet = dirichlet_data(p);
        let (two_mu, rho) = (2.0 * p.law.mu, p.scene.rho);
        Ok(Estimator { elements, h_tri, body, neumann, jumps, contact, dirichlet, two_mu, rho })
    }

    /// σ_T as [[σxx, σxy], [σxy, σyy]] for the midpoint values `mid`.
    fn stress(&self, p: &Problem, t: usize, mid: &[[f64; 2]]) -> [[f64; 2]; 2] {
        let g = self.elements[t].gradient(p.mesh.tri_edges[t].map(|e| mid[e]));
        let s = p.law.strain_stress(g).stress;
        [[s[0], s[3]], [s[3], s[1]]]
    }

    /// The indicator of step `r` (module doc).
    pub fn at(&self, p: &Problem, r: &StepResult) -> Result<Indicator> {
        let mesh = &p.mesh;
        let mid = p.displacement(&r.u, r.t)?;
        let sigma: Vec<[[f64; 2]; 2]> = (0..mesh.tris.len()).map(|t| self.stress(p, t, &mid)).collect();
        let sn = |t: usize, n: [f64; 2]| {
            let s = sigma[t];
            [s[0][0] * n[0] + s[0][1] * n[1], s[1][0] * n[0] + s[1][1] * n[1]]
        };
        let mut eta2 = vec![0.0; mesh.tris.len()];
        let mut terms = [0.0; 5];
        let mut add = |t: usize, k: usize, v: f64, eta2: &mut Vec<f64>| {
            eta2[t] += v;
            terms[k] += v;
        };
        let mut vals = Vec::new();
        if let Some(b) = &self.body {
            b.expr.as_ref().expect("a body force").eval(r.t, &mut vals)?;
            for (i, &(t, w)) in b.at.iter().enumerate() {
                let (fx, fy) = (vals[2 * i], vals[2 * i + 1]);
                add(t, 0, self.h_tri[t].powi(2) / self.two_mu * w * (fx * fx + fy * fy), &mut eta2);
            }
        }
        for e in 0..mesh.edges.len() {
            if let (t1, Some(t2)) = mesh.edge_tris[e] {
                let n = normal_from(mesh, e, t1);
                let (a, b) = (sn(t1, n), sn(t2, n));
                let h = mesh.edge_length(e);
                let v = h * h / self.two_mu * ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2));
                add(t1, 1, 0.5 * v, &mut eta2);
                add(t2, 1, 0.5 * v, &mut eta2);
            }
        }
        for b in &self.neumann {
            vals.clear();
            if let Some(x) = &b.expr {
                x.eval(r.t, &mut vals)?;
            }
            let two = !vals.is_empty();
            for (i, (&(t, w), &e)) in b.at.iter().zip(&b.edge).enumerate() {
                let g = if two { [vals[2 * i], vals[2 * i + 1]] } else { [0.0; 2] };
                let s = sn(t, mesh.outward_normal(e));
                let v = mesh.edge_length(e) / self.two_mu * w * ((g[0] - s[0]).powi(2) + (g[1] - s[1]).powi(2));
                add(t, 2, v, &mut eta2);
            }
        }
        for &(e, i) in &self.contact {
            let c = &p.space.contact[i];
            let t = mesh.edge_tris[e].0;
            let s = sn(t, c.normal);
            let lambda = -r.mu.get(i).copied().unwrap_or(0.0) / c.length;
            let d = s[0] * c.tangent[0] + s[1] * c.tangent[1] - lambda;
            add(t, 3, c.length * c.length / self.two_mu * d * d, &mut eta2);
        }
        let mut u_d = Vec::new();
        if let Some((sets, _)) = &self.dirichlet {
            for set in sets {
                let mut v = Vec::new();
                set.eval(r.t, &mut v)?;
                u_d.push(v);
            }
        }
        for (e, terms_q) in &self.jumps {
            let h = mesh.edge_length(*e);
            let slot = self.dirichlet.as_ref().and_then(|(_, s)| s[*e]);
            let mut v = 0.0;
            for (qi, (q, (_, w))) in terms_q.iter().zip(GAUSS2).enumerate() {
                let mut j = q.iter().fold([0.0; 2], |j, &(k, c)| [j[0] + c * mid[k][0], j[1] + c * mid[k][1]]);
                if let Some((set, pos)) = slot {
                    let at = 4 * pos + 2 * qi;
                    j = [j[0] - u_d[set][at], j[1] - u_d[set][at + 1]];
                }
                v += w * h * (j[0] * j[0] + j[1] * j[1]);
            }
            let v = (1.0 + self.rho) * self.two_mu / h * v;
            match mesh.edge_tris[*e] {
                (t1, Some(t2)) => {
                    add(t1, 4, 0.5 * v, &mut eta2);
                    add(t2, 4, 0.5 * v, &mut eta2);
                }
                (t, None) => add(t, 4, v, &mut eta2),
            }
        }
        Ok(Indicator { eta2, terms })
    }
}

/// u_D of each Dirichlet part with data bound to the 2-point Gauss points of its edges (two points per
/// edge, edge by edge), and per mesh edge its (part set, position) (`None`: no data).
type DirichletData = (Vec<BoundSet>, Vec<Option<(usize, usize)>>);

fn dirichlet_data(p: &Problem) -> Option<DirichletData> {
    let mesh = &p.mesh;
    let (mut sets, mut slot) = (Vec::new(), vec![None; mesh.edges.len()]);
    for (k, part) in p.scene.parts.iter().enumerate() {
        let PartKind::Dirichlet(Some(u)) = &part.kind else { continue };
        let mut points = Vec::new();
        for e in (0..mesh.edges.len()).filter(|&e| p.space.edge_part[e] == Some(k)) {
            slot[e] = Some((sets.len(), points.len() / 2));
            let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
            points.extend(GAUSS2.map(|(s, _)| edge_point(a, b, s)));
        }
        sets.push(ExprSet::new(&[&u.0[0], &u.0[1]]).bind(points));
    }
    (!sets.is_empty()).then_some((sets, slot))
}

/// The unit normal of edge e pointing out of triangle t.
fn normal_from(mesh: &crate::mesh::Mesh, e: usize, t: usize) -> [f64; 2] {
    let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
    let len = mesh.edge_length(e);
    let n = [(b[1] - a[1]) / len, -(b[0] - a[0]) / len];
    let opp = mesh.tris[t].iter().copied().find(|v| !mesh.edges[e].contains(v)).expect("third vertex");
    let c = mesh.points[opp];
    if n[0] * (c[0] - a[0]) + n[1] * (c[1] - a[1]) > 0.0 {
        [-n[0], -n[1]]
    } else {
        n
    }
}

/// The indicator over the time nodes: per triangle the max over n of (η_Tⁿ)², and the max over n of
/// the global ηⁿ with its terms and node.
#[derive(Clone, Debug, Default)]
pub struct Accumulated {
    pub eta2: Vec<f64>,
    pub global: f64,
    pub terms: [f64; 5],
    pub step: usize,
}

impl Accumulated {
    pub fn push(&mut self, n: usize, ind: &Indicator) {
        if self.eta2.is_empty() {
            self.eta2 = vec![0.0; ind.eta2.len()];
        }
        for (a, b) in self.eta2.iter_mut().zip(&ind.eta2) {
            *a = a.max(*b);
        }
        let g = ind.global();
        if g > self.global || n == 0 {
            self.global = self.global.max(g);
            self.terms = ind.terms;
            self.step = n;
        }
    }
}
