//! Nested iteration for the active sets (coarse to fine, as full multigrid starts each level from the
//! coarser one's solution): the predictor of `hik` and `coulomb`.
//!
//! A primal–dual active-set iteration moves a contact or stick/slip front by about one Γ_C edge per
//! Newton step where the sets are wrong near it (the forces of a too-large stick or contact zone exceed
//! their bounds only next to its end), so a start whose front is m edges off costs about m steps, and m
//! grows with 1/h (the first step from λ = 0; a front that moves a fixed distance per step). Here the Γ_C
//! edges are ordered along their chains and grouped 2^ℓ consecutive ones at level ℓ; level ℓ's problem
//! is the Galerkin restriction of the fine one to forces constant on each group, λ = R_ℓΛ with
//! λ_e = (|e|/|J|) Λ_J on the edges e of group J:
//!   C_ℓ = R_ℓᵀ C R_ℓ,   d_ℓ = R_ℓᵀ d,   bound of Λ_J: Σ_{e∈J} w_e,   F̄_J = Σ_{e∈J} (|e|/|J|) F̄_e.
//! The coarsest level (≤ [`COARSEST`] groups) is solved from λ = 0; each finer level starts from the
//! sets of the coarser level's solution, copied to the edges of each group, where its fronts are within
//! a group or two of its own; the fine problem starts from the sets of level 1. The prediction is only a
//! start: the fine problem is solved to its tolerance from it, and a level that fails to converge ends the
//! prediction (the fine iteration then starts as without it). A level costs 8^-ℓ of a fine Newton step.

use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use nalgebra::DMatrix;
use std::collections::HashMap;

/// The coarsest level has at most this many groups.
pub const COARSEST: usize = 8;

/// Newton steps allowed on a coarse level.
pub const COARSE_ITER: usize = 50;

/// The groups of the Γ_C edges at each coarse level.
pub struct Levels {
    /// Per level ℓ = 1, 2, … the group of each Γ_C edge, and the number of groups.
    groups: Vec<(Vec<usize>, usize)>,
    /// |e| of each Γ_C edge.
    length: Vec<f64>,
}

/// A coarse level's problem: C_ℓ, d_ℓ, the bounds (tangential first, then normal), the Tresca bounds
/// and the Coulomb coefficients of its groups.
pub struct Coarse {
    pub c: DMatrix<f64>,
    pub d: Vec<f64>,
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    pub w: Vec<f64>,
    pub coulomb: Vec<Option<f64>>,
}

impl Levels {
    /// The levels of the Γ_C edges of `space`: chains of edges that share a vertex and have the same part,
    /// law and friction kind, grouped 2, 4, … consecutive edges until at most [`COARSEST`] groups remain.
    pub fn new(mesh: &Mesh, space: &CrSpace) -> Levels {
        let (chain, pos) = chains(mesh, space);
        Levels::of_chains(&chain, &pos, space.contact.iter().map(|c| c.length).collect())
    }

    /// The levels of edges with lengths `length` on chains `chain` at positions `pos` in them.
    pub fn of_chains(chain: &[usize], pos: &[usize], length: Vec<f64>) -> Levels {
        let mut groups = Vec::new();
        let mut last = chain.len();
        for l in 1..usize::BITS {
            if last <= COARSEST {
                break;
            }
            let mut ids: HashMap<(usize, usize), usize> = HashMap::new();
            let g: Vec<usize> = (0..chain.len())
                .map(|e| {
                    let n = ids.len();
                    *ids.entry((chain[e], pos[e] >> l)).or_insert(n)
                })
                .collect();
            if ids.len() == last {
                break;
            }
            last = ids.len();
            groups.push((g, last));
        }
        Levels { groups, length }
    }

    /// Number of coarse levels.
    pub fn len(&self) -> usize {
        self.groups.len()
    }

    /// True without coarse levels (few Γ_C edges).
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// The group of edge e at level l (l = 0: the edge itself) and the number of groups.
    fn group(&self, l: usize, e: usize) -> usize {
        if l == 0 {
            e
        } else {
            self.groups[l - 1].0[e]
        }
    }

    fn count(&self, l: usize) -> usize {
        if l == 0 {
            self.length.len()
        } else {
            self.groups[l - 1].1
        }
    }

    /// Level l's problem from the fine one (C, d, the normal lower bounds `lo_n`, the Tresca bounds `w`
    /// and the Coulomb coefficients `coulomb`; 2 n_c unknowns, tangential first).
    pub fn coarse(
        &self,
        l: usize,
        c: &DMatrix<f64>,
        d: &[f64],
        lo_n: &[f64],
        w: &[f64],
        coulomb: &[Option<f64>],
    ) -> Coarse {
        let nc = self.length.len();
        let m = self.count(l);
        let mut glen = vec![0.0; m];
        for e in 0..nc {
            glen[self.group(l, e)] += self.length[e];
        }
        // unknown k of the fine problem → (its coarse unknown, its weight |e|/|J|)
        let map = |k: usize| -> (usize, f64) {
            let e = k % nc;
            let g = self.group(l, e);
            (g + if k < nc { 0 } else { m }, self.length[e] / glen[g])
        };
        let n = 2 * nc;
        let mut cr = DMatrix::<f64>::zeros(n, 2 * m);
        for k in 0..n {
            let (a, r) = map(k);
            for i in 0..n {
                cr[(i, a)] += r * c[(i, k)];
            }
        }
        let mut cc = DMatrix::<f64>::zeros(2 * m, 2 * m);
        let mut dc = vec![0.0; 2 * m];
        for k in 0..n {
            let (a, r) = map(k);
            for b in 0..2 * m {
                cc[(a, b)] += r * cr[(k, b)];
            }
            dc[a] += r * d[k];
        }
        let (mut wc, mut lo, mut fc) = (vec![0.0; m], vec![0.0; m], vec![None; m]);
        for e in 0..nc {
            let (g, r) = map(e);
            wc[g] += w[e];
            lo[g] = lo_n[e];
            let sum: Option<f64> = fc[g];
            fc[g] = coulomb[e].map(|f| sum.unwrap_or(0.0) + r * f);
        }
        let lo_all = wc.iter().map(|w| -w).chain(lo.iter().copied()).collect();
        let hi_all = wc.iter().copied().chain(std::iter::repeat_n(f64::INFINITY, m)).collect();
        Coarse { c: cc, d: dc, lo: lo_all, hi: hi_all, w: wc, coulomb: fc }
    }

    /// Sets of level `from` (one per unknown, tangential then normal) copied to the unknowns of level `to`
    /// (< `from`): each takes its group's.
    pub fn prolong<T: Copy>(&self, from: usize, to: usize, set: &[T]) -> Vec<T> {
        let (mf, mt) = (self.count(from), self.count(to));
        let mut up = vec![usize::MAX; mt];
        for e in 0..self.length.len() {
            up[self.group(to, e)] = self.group(from, e);
        }
        let tail = set.len() / mf;
        (0..tail).flat_map(|t| up.iter().map(move |&g| set[t * mf + g])).collect()
    }
}

/// Per Γ_C edge its chain and its position in it: edges of one part, law and friction kind that share
/// vertices, walked from an end (a closed loop from any edge).
fn chains(mesh: &Mesh, space: &CrSpace) -> (Vec<usize>, Vec<usize>) {
    let nc = space.contact.len();
    let key = |i: usize| {
        let c = &space.contact[i];
        (space.edge_part[c.edge], c.unilateral, c.coulomb.is_some())
    };
    let mut at: HashMap<usize, Vec<usize>> = HashMap::new();
    for (i, c) in space.contact.iter().enumerate() {
        for v in mesh.edges[c.edge] {
            at.entry(v).or_default().push(i);
        }
    }
    let next = |i: usize, v: usize| at[&v].iter().copied().find(|&j| j != i && key(j) == key(i));
    let (mut chain, mut pos) = (vec![usize::MAX; nc], vec![0; nc]);
    let mut n_chains = 0;
    let ends: Vec<usize> =
        (0..nc).filter(|&i| mesh.edges[space.contact[i].edge].iter().any(|&v| next(i, v).is_none())).collect();
    for start in ends.into_iter().chain(0..nc) {
        if chain[start] != usize::MAX {
            continue;
        }
        let (mut i, mut p) = (start, 0);
        let mut from = mesh.edges[space.contact[i].edge].into_iter().find(|&v| next(i, v).is_none());
        loop {
            chain[i] = n_chains;
            pos[i] = p;
            p += 1;
            let [a, b] = mesh.edges[space.contact[i].edge];
            let v = if from == Some(a) { b } else { a };
            match at[&v].iter().copied().find(|&j| j != i && key(j) == key(i) && chain[j] == usize::MAX) {
                Some(j) => (i, from) = (j, Some(v)),
                None => break,
            }
        }
        n_chains += 1;
    }
    (chain, pos)
}
