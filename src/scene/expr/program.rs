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
//!   cache and run the other instructions. Which ones is a cost model (`cache`): a cached value is
//!   read from main memory at every time (the cache of a fine mesh is far larger than the processor's
//!   caches), about as dear as a few vectorised products, so a spatial value is cached only if
//!   recomputing it costs more — sin, cos, exp, `powf` and long chains of products and divisions are
//!   cached, polynomial factors such as `(1-y)^2*(2*y+1)` or `x/5` are recomputed. Either way a value comes from the same
//!   operations, so the choice changes no bit.
//!
//! Evaluation (batches of points, the cache read in place, the finiteness check on the way out) is in
//! [`super::eval`]; this module only lowers and schedules.

mod cache;

use super::regroup;
use super::sym::{Bin, Sym, Un};
use cache::plan_cache;
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

/// Per node: whether it depends on a leaf for which `leaf` holds (x or y: varying; t: timed).
fn depends_on(nodes: &[Op], leaf: impl Fn(&Op) -> bool) -> Vec<bool> {
    let mut v = vec![false; nodes.len()];
    for (i, op) in nodes.iter().enumerate() {
        v[i] = match *op {
            Op::Un(_, a) => v[a as usize],
            Op::Bin(_, a, c) => v[a as usize] || v[c as usize],
            _ => leaf(op),
        };
    }
    v
}

/// Per node: its last varying reader (`usize::MAX` for the outputs, read at the end).
fn last_readers(nodes: &[Op], varying: &[bool], outputs: &[u32]) -> Vec<usize> {
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
    for &o in outputs {
        last[o as usize] = usize::MAX;
    }
    last
}

/// What the scheduler knows of every node.
struct Plan<'a> {
    varying: &'a [bool],
    timed: &'a [bool],
    cache_it: &'a [bool],
    at_time: &'a [bool],
    last: &'a [usize],
}

/// The instruction lists of a program ([`Program`]'s fields of the same names).
struct Code {
    all: Vec<Instr>,
    spatial: Vec<Instr>,
    timed: Vec<Instr>,
    cached: Vec<u32>,
}

/// The slot of every node, the slots in use and those free for reuse.
struct Slots {
    slot: Vec<u32>,
    n_slots: usize,
    free: Vec<u32>,
}

impl Slots {
    fn new(n: usize) -> Slots {
        let mut slot = vec![u32::MAX; n];
        slot[0] = SLOT_X;
        slot[1] = SLOT_Y;
        Slots { slot, n_slots: 2, free: Vec::new() }
    }

    /// A slot never used before.
    fn fresh(&mut self) -> u32 {
        self.n_slots += 1;
        (self.n_slots - 1) as u32
    }

    /// A free slot, else a fresh one.
    fn take(&mut self) -> u32 {
        match self.free.pop() {
            Some(s) => s,
            None => self.fresh(),
        }
    }

    /// Uniform nodes read by varying ones (or outputs) get a broadcast slot for the whole call:
    /// (slot, node) of each.
    fn broadcast(&mut self, nodes: &[Op], varying: &[bool]) -> Vec<(u32, u32)> {
        let mut broadcast = Vec::new();
        for (i, op) in nodes.iter().enumerate() {
            let reads: &[u32] = match op {
                Op::Un(_, a) if varying[i] => &[*a][..],
                Op::Bin(_, a, c) if varying[i] => &[*a, *c][..],
                _ => &[],
            };
            for &r in reads {
                if !varying[r as usize] && self.slot[r as usize] == u32::MAX {
                    self.slot[r as usize] = self.take();
                    broadcast.push((self.slot[r as usize], r));
                }
            }
        }
        broadcast
    }

    /// The varying instructions in order, a slot freed after its node's last reader.
    fn schedule(&mut self, nodes: &[Op], p: &Plan) -> Code {
        let mut code = Code { all: Vec::new(), spatial: Vec::new(), timed: Vec::new(), cached: Vec::new() };
        for (i, op) in nodes.iter().enumerate() {
            if !p.varying[i] || matches!(op, Op::X | Op::Y) {
                continue;
            }
            // a cached node keeps a slot of its own: the cache is loaded before any instruction runs
            let dst = if p.cache_it[i] { self.fresh() } else { self.take() };
            if p.cache_it[i] {
                code.cached.push(dst);
            }
            self.slot[i] = dst;
            let ins = match *op {
                Op::Un(f, a) => {
                    let ins = Instr::Un(f, dst, self.slot[a as usize]);
                    self.release(p, i, a);
                    ins
                }
                Op::Bin(f, a, c) => {
                    let ins = Instr::Bin(f, dst, self.slot[a as usize], self.slot[c as usize]);
                    self.release(p, i, a);
                    if c != a {
                        self.release(p, i, c);
                    }
                    ins
                }
                _ => continue,
            };
            code.all.push(ins);
            if !p.timed[i] {
                code.spatial.push(ins);
            }
            if p.at_time[i] {
                code.timed.push(ins);
            }
        }
        code
    }

    /// Free the slot of node r if node i is its last reader (never x's, y's or a cached node's).
    fn release(&mut self, p: &Plan, i: usize, r: u32) {
        let r = r as usize;
        if p.varying[r] && !p.cache_it[r] && p.last[r] == i && r > 1 {
            self.free.push(self.slot[r]);
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
        let varying = depends_on(&nodes, |op| matches!(op, Op::X | Op::Y));
        let timed = depends_on(&nodes, |op| matches!(op, Op::T));
        let (cache_it, at_time) = plan_cache(&nodes, &varying, &timed, &out_nodes);
        let last = last_readers(&nodes, &varying, &out_nodes);
        let mut slots = Slots::new(nodes.len());
        let broadcast = slots.broadcast(&nodes, &varying);
        let plan = Plan { varying: &varying, timed: &timed, cache_it: &cache_it, at_time: &at_time, last: &last };
        let code = slots.schedule(&nodes, &plan);
        let Slots { slot, n_slots, .. } = slots;
        let outputs = out_nodes.iter().map(|&o| (o, Some(slot[o as usize]).filter(|_| varying[o as usize]))).collect();
        let Code { all, spatial, timed, cached } = code;
        Program { nodes, varying, all, spatial, timed, cached, broadcast, n_slots, outputs }
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
