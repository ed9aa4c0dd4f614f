//! The cost model of the cache of spatial values ([`plan_cache`]): which nodes a program reads from the
//! cache at each time and which it computes again.

use super::Op;
use crate::scene::expr::sym::{Bin, Un};

/// Cost of reading a cached value at a time, in vectorised products (the cache is read in order, so 4
/// rather than the 16 of a random read; the best value depends on the processor's cache size).
pub(super) const LOAD_COST: u32 = 4;

/// Cost of recomputing an operation (same unit as [`LOAD_COST`]).
fn op_cost(op: &Op) -> u32 {
    match *op {
        Op::Const(_) | Op::X | Op::Y | Op::T => 0,
        Op::Un(Un::Neg | Un::Abs, _) => 1,
        Op::Un(Un::Sqrt | Un::Floor | Un::Ceil | Un::Trunc | Un::Round | Un::Fract | Un::Signum, _) => 4,
        Op::Un(..) => 40,
        Op::Bin(Bin::Add | Bin::Sub | Bin::Mul | Bin::Min | Bin::Max, ..) => 1,
        Op::Bin(Bin::Div, ..) => 4,
        Op::Bin(..) => 60,
    }
}

/// Which spatial nodes to cache, and which nodes to compute at each time when the cache is used.
///
/// Bottom-up, c(n) = cost(n) + Σ over n's spatial inputs i of min(c(i), LOAD_COST) estimates what
/// computing n at a time costs when its dear inputs are cached. Top-down from what the time part needs
/// (the inputs of nodes that depend on t, and the outputs), a needed spatial node is cached if
/// c(n) > LOAD_COST, else computed at each time and its spatial inputs are needed in turn. x and y are
/// never cached (they are the points).
pub(super) fn plan_cache(nodes: &[Op], varying: &[bool], timed: &[bool], outputs: &[u32]) -> (Vec<bool>, Vec<bool>) {
    let n = nodes.len();
    let spatial = |i: usize| varying[i] && !timed[i];
    let reads = |op: &Op| -> ([u32; 2], usize) {
        match *op {
            Op::Un(_, a) => ([a, a], 1),
            Op::Bin(_, a, c) => ([a, c], 2),
            _ => ([0, 0], 0),
        }
    };
    let mut cost = vec![0u32; n];
    for (i, op) in nodes.iter().enumerate() {
        let (r, k) = reads(op);
        let inputs: u32 =
            r[..k].iter().filter(|&&a| spatial(a as usize)).map(|&a| cost[a as usize].min(LOAD_COST)).sum();
        cost[i] = op_cost(op).saturating_add(inputs);
    }
    let mut needed = vec![false; n];
    for &o in outputs {
        needed[o as usize] = true;
    }
    let (mut cache_it, mut at_time) = (vec![false; n], vec![false; n]);
    for i in (0..n).rev() {
        if !varying[i] || !(timed[i] || needed[i]) || matches!(nodes[i], Op::X | Op::Y) {
            continue;
        }
        if !timed[i] && cost[i] > LOAD_COST {
            cache_it[i] = true;
            continue;
        }
        at_time[i] = true;
        let (r, k) = reads(&nodes[i]);
        r[..k].iter().for_each(|&a| needed[a as usize] = true);
    }
    (cache_it, at_time)
}
