//! Compiled expressions: one or more [`Sym`] trees lowered once to a straight-line program, evaluated
//! over many points at a time.
//!
//! Lowering (hash-consing of the tree into a DAG):
//! * common subexpressions are shared: structurally equal nodes — across all outputs of a program,
//!   e.g. the six components of an exact solution and its gradient — are computed once;
//! * integer powers a^n, |n| ≤ [`MAX_INT_POWER`], become products by binary powering (a^{-n} = 1/a^n)
//!   instead of `powf`; within a few ulps of `powf` (each product rounds once);
//! * operations on constants are computed at compile time (exmex's own folding already did most);
//! * products are regrouped with their time-dependent factors last ([`super::regroup`]);
//! * nodes that depend on neither x nor y ("uniform": constants, t and what is computed from them) are
//!   evaluated once per call, as scalars, and broadcast;
//! * nodes that depend on x, y but not t ("spatial") can be evaluated once for a fixed set of points
//!   ([`Program::fill_cache`]); the evaluations at each time then read some spatial values from that
//!   cache and run the other instructions. Which ones is a cost model ([`plan_cache`]): a cached value is
//!   read from main memory at every time (the cache of a fine mesh is far larger than the processor's
//!   caches), about as dear as [`LOAD_COST`] vectorised products, so a spatial value is cached only if
//!   recomputing it costs more — sin, cos, exp, `powf` and long chains of products and divisions are
//!   cached, polynomial factors such as `(1-y)^2*(2*y+1)` or `x/5` are recomputed. Either way a value comes from the same
//!   operations, so the choice changes no bit.
//!
//! Evaluation (batches of points, the cache read in place, the finiteness check on the way out) is in
//! [`super::eval`]; this module only lowers and schedules.

use super::regroup;
use super::sym::{Bin, Sym, Un};
use std::collections::HashMap;

/// Points per batch (see [`super::eval`]).
pub const LANES: usize = 64;
/// Largest |n| of an integer power a^n compiled into products (beyond, `powf`).
pub const MAX_INT_POWER: f64 = 64.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Op {
    Const(f64),
    X,
    Y,
    T,
    Un(Un, u32),
    Bin(Bin, u32, u32),
}

/// Cost of reading a cached value at a time, in vectorised products (read in order: 4, not 16; mms_stop's
/// error norms per node −10–40 %, mms_front's loads at r5 +11 %: the right value depends on cache size).
const LOAD_COST: u32 = 4;

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
fn plan_cache(nodes: &[Op], varying: &[bool], timed: &[bool], outputs: &[u32]) -> (Vec<bool>, Vec<bool>) {
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

/// Hash key of a node: the operation with the constant's bits.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    Const(u64),
    Var(u8),
    Un(Un, u32),
    Bin(Bin, u32, u32),
}

/// One varying instruction: `dst ← op(a, b)` on slots.
#[derive(Clone, Copy, Debug)]
pub(super) enum Instr {
    Un(Un, u32, u32),
    Bin(Bin, u32, u32, u32),
}

/// A compiled program with one or more outputs.
#[derive(Clone, Debug)]
pub struct Program {
    pub(super) nodes: Vec<Op>,
    /// Per node: depends on x or y.
    pub(super) varying: Vec<bool>,
    /// Every varying instruction, in order (evaluation without a cache).
    pub(super) all: Vec<Instr>,
    /// The spatial ones (no t: filling a cache) and the others (evaluating from a cache), in order.
    pub(super) spatial: Vec<Instr>,
    pub(super) timed: Vec<Instr>,
    /// Slots of the cached spatial nodes (read by a node that depends on t, or outputs), each its own
    /// and never written by a timed instruction.
    pub(super) cached: Vec<u32>,
    /// (slot, node) of every uniform node a varying instruction reads.
    pub(super) broadcast: Vec<(u32, u32)>,
    pub(super) n_slots: usize,
    /// Per output: its node and, if varying, its slot.
    pub(super) outputs: Vec<(u32, Option<u32>)>,
}

pub(super) const SLOT_X: u32 = 0;
pub(super) const SLOT_Y: u32 = 1;

struct Builder {
    nodes: Vec<Op>,
    index: HashMap<Key, u32>,
}

impl Builder {
    fn intern(&mut self, op: Op) -> u32 {
        // compile-time evaluation of operations on constants
        let op = match op {
            Op::Un(f, a) => match self.nodes[a as usize] {
                Op::Const(v) => Op::Const(f.apply(v)),
                _ => op,
            },
            Op::Bin(f, a, b) => match (self.nodes[a as usize], self.nodes[b as usize]) {
                (Op::Const(u), Op::Const(v)) => Op::Const(f.apply(u, v)),
                _ => op,
            },
            _ => op,
        };
        let key = match op {
            Op::Const(v) => Key::Const(v.to_bits()),
            Op::X => Key::Var(0),
            Op::Y => Key::Var(1),
            Op::T => Key::Var(2),
            Op::Un(f, a) => Key::Un(f, a),
            Op::Bin(f, a, b) => Key::Bin(f, a, b),
        };
        if let Some(&id) = self.index.get(&key) {
            return id;
        }
        let id = self.nodes.len() as u32;
        self.nodes.push(op);
        self.index.insert(key, id);
        id
    }

    fn lower(&mut self, s: &Sym) -> u32 {
        match s {
            Sym::Num(v) => self.intern(Op::Const(*v)),
            Sym::Var(0) => self.intern(Op::X),
            Sym::Var(1) => self.intern(Op::Y),
            Sym::Var(_) => self.intern(Op::T),
            Sym::Un(f, a) => {
                let a = self.lower(a);
                self.intern(Op::Un(*f, a))
            }
            Sym::Bin(Bin::Pow, a, b) => match **b {
                Sym::Num(n) if n.fract() == 0.0 && n.abs() <= MAX_INT_POWER => {
                    let a = self.lower(a);
                    let p = self.power(a, n.abs() as u32);
                    if n < 0.0 {
                        let one = self.intern(Op::Const(1.0));
                        self.intern(Op::Bin(Bin::Div, one, p))
                    } else {
                        p
                    }
                }
                _ => {
                    let (a, b) = (self.lower(a), self.lower(b));
                    self.intern(Op::Bin(Bin::Pow, a, b))
                }
            },
            Sym::Bin(f, a, b) => {
                if matches!(f, Bin::Mul | Bin::Div) {
                    if let Some(v) = self.product(s) {
                        return v;
                    }
                }
                let (a, b) = (self.lower(a), self.lower(b));
                self.intern(Op::Bin(*f, a, b))
            }
        }
    }

    /// A product a₁ ∘ a₂ ∘ … (∘ = × or ÷, divisors independent of t) with factors of both kinds, lowered
    /// as (the t-independent factors, in their order) × (the t-dependent ones, in their order); `None`
    /// when all factors are of one kind (then the product is lowered as written).
    fn product(&mut self, s: &Sym) -> Option<u32> {
        let (factors, timed) = regroup::factors(s)?;
        let mut acc: Option<u32> = None;
        for pass_timed in [false, true] {
            for ((f, divide), _) in factors.iter().zip(&timed).filter(|(_, &tm)| tm == pass_timed) {
                let v = self.lower(f);
                acc = Some(match (acc, divide) {
                    (None, false) => v,
                    (None, true) => {
                        let one = self.intern(Op::Const(1.0));
                        self.intern(Op::Bin(Bin::Div, one, v))
                    }
                    (Some(a), false) => self.intern(Op::Bin(Bin::Mul, a, v)),
                    (Some(a), true) => self.intern(Op::Bin(Bin::Div, a, v)),
                });
            }
        }
        acc
    }

    /// a^n by binary powering (a^0 = 1 like `powf`, even for a NaN).
    fn power(&mut self, a: u32, n: u32) -> u32 {
        match n {
            0 => self.intern(Op::Const(1.0)),
            1 => a,
            _ if n.is_multiple_of(2) => {
                let h = self.power(a, n / 2);
                self.intern(Op::Bin(Bin::Mul, h, h))
            }
            _ => {
                let h = self.power(a, n - 1);
                self.intern(Op::Bin(Bin::Mul, h, a))
            }
        }
    }
}

impl Program {
    /// Compile the trees `outputs` into one program.
    pub fn new(outputs: &[&Sym]) -> Program {
        let mut b = Builder { nodes: Vec::new(), index: HashMap::new() };
        // x and y first so their slots are fixed
        b.intern(Op::X);
        b.intern(Op::Y);
        let out_nodes: Vec<u32> = outputs.iter().map(|s| b.lower(s)).collect();
        let nodes = b.nodes;
        let varying: Vec<bool> = {
            let mut v = vec![false; nodes.len()];
            for (i, op) in nodes.iter().enumerate() {
                v[i] = match *op {
                    Op::X | Op::Y => true,
                    Op::Const(_) | Op::T => false,
                    Op::Un(_, a) => v[a as usize],
                    Op::Bin(_, a, c) => v[a as usize] || v[c as usize],
                };
            }
            v
        };
        let timed: Vec<bool> = {
            let mut v = vec![false; nodes.len()];
            for (i, op) in nodes.iter().enumerate() {
                v[i] = match *op {
                    Op::T => true,
                    Op::Const(_) | Op::X | Op::Y => false,
                    Op::Un(_, a) => v[a as usize],
                    Op::Bin(_, a, c) => v[a as usize] || v[c as usize],
                };
            }
            v
        };
        let (cache_it, at_time) = plan_cache(&nodes, &varying, &timed, &out_nodes);
        // last varying reader of each node (outputs are read at the end)
        let mut last = vec![0usize; nodes.len()];
        for (i, op) in nodes.iter().enumerate() {
            if varying[i] {
                match *op {
                    Op::Un(_, a) => last[a as usize] = i,
                    Op::Bin(_, a, c) => {
                        last[a as usize] = i;
                        last[c as usize] = i;
                    }
                    _ => {}
                }
            }
        }
        for &o in &out_nodes {
            last[o as usize] = usize::MAX;
        }
        let mut slot = vec![u32::MAX; nodes.len()];
        slot[0] = SLOT_X;
        slot[1] = SLOT_Y;
        let mut n_slots = 2usize;
        let mut free: Vec<u32> = Vec::new();
        let mut broadcast = Vec::new();
        let mut take = |free: &mut Vec<u32>| {
            free.pop().unwrap_or_else(|| {
                n_slots += 1;
                (n_slots - 1) as u32
            })
        };
        // uniform nodes read by varying ones (or outputs) get a broadcast slot for the whole call
        for (i, op) in nodes.iter().enumerate() {
            let reads: &[u32] = match op {
                Op::Un(_, a) if varying[i] => &[*a][..],
                Op::Bin(_, a, c) if varying[i] => &[*a, *c][..],
                _ => &[],
            };
            for &r in reads {
                if !varying[r as usize] && slot[r as usize] == u32::MAX {
                    slot[r as usize] = take(&mut free);
                    broadcast.push((slot[r as usize], r));
                }
            }
        }
        let (mut all, mut spatial, mut timed_instrs) = (Vec::new(), Vec::new(), Vec::new());
        let mut cached = Vec::new();
        for (i, op) in nodes.iter().enumerate() {
            if !varying[i] || matches!(op, Op::X | Op::Y) {
                continue;
            }
            // a cached node keeps a slot of its own: the cache is loaded before any instruction runs
            let dst = if cache_it[i] { take(&mut Vec::new()) } else { take(&mut free) };
            if cache_it[i] {
                cached.push(dst);
            }
            slot[i] = dst;
            let release = |r: u32, free: &mut Vec<u32>| {
                if varying[r as usize] && !cache_it[r as usize] && last[r as usize] == i && r > 1 {
                    free.push(slot[r as usize]);
                }
            };
            let ins = match *op {
                Op::Un(f, a) => {
                    let ins = Instr::Un(f, dst, slot[a as usize]);
                    release(a, &mut free);
                    ins
                }
                Op::Bin(f, a, c) => {
                    let ins = Instr::Bin(f, dst, slot[a as usize], slot[c as usize]);
                    release(a, &mut free);
                    if c != a {
                        release(c, &mut free);
                    }
                    ins
                }
                _ => continue,
            };
            all.push(ins);
            if !timed[i] {
                spatial.push(ins);
            }
            if at_time[i] {
                timed_instrs.push(ins);
            }
        }
        let outputs = out_nodes.iter().map(|&o| (o, Some(slot[o as usize]).filter(|_| varying[o as usize]))).collect();
        Program { nodes, varying, all, spatial, timed: timed_instrs, cached, broadcast, n_slots, outputs }
    }

    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Number of varying instructions (work per point).
    pub fn n_instructions(&self) -> usize {
        self.all.len()
    }

    /// Instructions per point at each time once the spatial part is cached.
    pub fn n_timed_instructions(&self) -> usize {
        self.timed.len()
    }

    /// Cached values per point (the spatial nodes the timed part reads).
    pub fn n_cached(&self) -> usize {
        self.cached.len()
    }
}
