//! Compiled expressions: one or more [`Sym`] trees lowered once to a straight-line program, evaluated
//! over many points at a time.
//!
//! Lowering (hash-consing of the tree into a DAG):
//! * common subexpressions are shared: structurally equal nodes — across all outputs of a program,
//!   e.g. the six components of an exact solution and its gradient — are computed once;
//! * integer powers a^n, |n| ≤ [`MAX_INT_POWER`], become products by binary powering (a^{-n} = 1/a^n)
//!   instead of `powf`; within a few ulps of `powf` (each product rounds once);
//! * operations on constants are computed at compile time (exmex's own folding already did most);
//! * nodes that depend on neither x nor y ("uniform": constants, t and what is computed from them) are
//!   evaluated once per call, as scalars, and broadcast;
//! * nodes that depend on x, y but not t ("spatial") can be evaluated once for a fixed set of points
//!   ([`Program::fill_cache`]); the evaluations at each time then read the spatial values that the rest
//!   of the program uses from that cache and run only the instructions that involve both.
//!
//! The remaining instructions run over batches of [`LANES`] points: each instruction is one simple loop
//! over the lanes (vectorised by the compiler for + − × ÷, min, max, abs). Values are register slots of
//! `LANES` numbers, reused once their last reader has run. Every point's value comes from the same
//! sequence of operations whatever the batching or the thread count, so results are bit-reproducible.

use super::sym::{Bin, Sym, Un};
use std::collections::HashMap;

/// Points per batch.
pub const LANES: usize = 32;
/// Points per chunk of parallel work (a whole number of batches).
const CHUNK: usize = 16 * LANES;
/// Largest |n| of an integer power a^n compiled into products (beyond, `powf`).
pub const MAX_INT_POWER: f64 = 64.0;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
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
enum Instr {
    Un(Un, u32, u32),
    Bin(Bin, u32, u32, u32),
}

/// A compiled program with one or more outputs.
#[derive(Clone, Debug)]
pub struct Program {
    nodes: Vec<Op>,
    /// Per node: depends on x or y.
    varying: Vec<bool>,
    /// The varying instructions in order, each with whether it is spatial (no t).
    instrs: Vec<(Instr, bool)>,
    /// Slots of the cached spatial nodes (read by a node that depends on t, or outputs), each its own.
    cached: Vec<u32>,
    /// (slot, node) of every uniform node a varying instruction reads.
    broadcast: Vec<(u32, u32)>,
    n_slots: usize,
    /// Per output: its node and, if varying, its slot.
    outputs: Vec<(u32, Option<u32>)>,
}

const SLOT_X: u32 = 0;
const SLOT_Y: u32 = 1;

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
                let (a, b) = (self.lower(a), self.lower(b));
                self.intern(Op::Bin(*f, a, b))
            }
        }
    }

    /// a^n by binary powering (a^0 = 1 like `powf`, even for a NaN).
    fn power(&mut self, a: u32, n: u32) -> u32 {
        match n {
            0 => self.intern(Op::Const(1.0)),
            1 => a,
            _ if n % 2 == 0 => {
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
        // spatial nodes (not x, y themselves) read by a node that also depends on t, or outputs: cached
        let mut cache_it = vec![false; nodes.len()];
        for (i, op) in nodes.iter().enumerate() {
            if varying[i] && timed[i] {
                let reads: &[u32] = match op {
                    Op::Un(_, a) => &[*a][..],
                    Op::Bin(_, a, c) => &[*a, *c][..],
                    _ => &[],
                };
                reads.iter().for_each(|&r| cache_it[r as usize] = varying[r as usize] && !timed[r as usize]);
            }
        }
        for &o in &out_nodes {
            cache_it[o as usize] = varying[o as usize] && !timed[o as usize];
        }
        cache_it[0] = false;
        cache_it[1] = false;
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
        let mut instrs = Vec::new();
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
            let spatial = !timed[i];
            let release = |r: u32, free: &mut Vec<u32>| {
                if varying[r as usize] && !cache_it[r as usize] && last[r as usize] == i && r > 1 {
                    free.push(slot[r as usize]);
                }
            };
            match *op {
                Op::Un(f, a) => {
                    instrs.push((Instr::Un(f, dst, slot[a as usize]), spatial));
                    release(a, &mut free);
                }
                Op::Bin(f, a, c) => {
                    instrs.push((Instr::Bin(f, dst, slot[a as usize], slot[c as usize]), spatial));
                    release(a, &mut free);
                    if c != a {
                        release(c, &mut free);
                    }
                }
                _ => {}
            }
        }
        let outputs = out_nodes.iter().map(|&o| (o, Some(slot[o as usize]).filter(|_| varying[o as usize]))).collect();
        Program { nodes, varying, instrs, cached, broadcast, n_slots, outputs }
    }

    /// Number of outputs.
    pub fn n_outputs(&self) -> usize {
        self.outputs.len()
    }

    /// Number of varying instructions (work per point).
    pub fn n_instructions(&self) -> usize {
        self.instrs.len()
    }

    /// Values of the uniform nodes at time t (NaN for varying nodes, which are never read here).
    fn uniform(&self, t: f64) -> Vec<f64> {
        let mut v = vec![f64::NAN; self.nodes.len()];
        for (i, op) in self.nodes.iter().enumerate() {
            if self.varying[i] {
                continue;
            }
            v[i] = match *op {
                Op::Const(c) => c,
                Op::T => t,
                Op::Un(f, a) => f.apply(v[a as usize]),
                Op::Bin(f, a, b) => f.apply(v[a as usize], v[b as usize]),
                Op::X | Op::Y => f64::NAN,
            };
        }
        v
    }

    /// All outputs at one point, evaluating node by node (for single evaluations).
    pub fn eval_point(&self, x: f64, y: f64, t: f64, out: &mut [f64]) {
        let mut v = vec![0.0; self.nodes.len()];
        for (i, op) in self.nodes.iter().enumerate() {
            v[i] = match *op {
                Op::Const(c) => c,
                Op::X => x,
                Op::Y => y,
                Op::T => t,
                Op::Un(f, a) => f.apply(v[a as usize]),
                Op::Bin(f, a, b) => f.apply(v[a as usize], v[b as usize]),
            };
        }
        for (o, &(node, _)) in out.iter_mut().zip(&self.outputs) {
            *o = v[node as usize];
        }
    }

    /// All outputs at every point at time t, point-major: `out[i * n_outputs + k]`. Points are split
    /// into chunks evaluated in parallel (pointwise, so the values do not depend on the split). With
    /// `cache` (from [`Program::fill_cache`] on the same points) the spatial part is read, not computed:
    /// the same operations were done there, so the values are the same.
    pub fn eval(&self, points: &[[f64; 2]], t: f64, cache: Option<&[f64]>, out: &mut Vec<f64>) {
        let m = self.outputs.len();
        out.clear();
        out.resize(points.len() * m, 0.0);
        if m == 0 || points.is_empty() {
            return;
        }
        let uniform = self.uniform(t);
        let per_chunk = CHUNK / LANES * self.cached.len() * LANES;
        crate::parallel::for_chunks(out, CHUNK * m, |c, chunk| {
            let pts = &points[c * CHUNK..(c * CHUNK + chunk.len() / m)];
            let cache = cache.map(|cc| &cc[c * per_chunk..(c * per_chunk + per_chunk).min(cc.len())]);
            self.eval_chunk(pts, &uniform, Some(chunk), cache, None);
        });
    }

    /// The cached spatial values at `points` (batch by batch, slot by slot), for [`Program::eval`].
    pub fn fill_cache(&self, points: &[[f64; 2]]) -> Vec<f64> {
        let n_batches = points.len().div_ceil(LANES);
        let mut cache = vec![0.0; n_batches * self.cached.len() * LANES];
        if self.cached.is_empty() {
            return cache;
        }
        // spatial nodes do not depend on t: any t gives their values
        let uniform = self.uniform(0.0);
        let per_chunk = CHUNK / LANES * self.cached.len() * LANES;
        crate::parallel::for_chunks(&mut cache, per_chunk, |c, chunk| {
            let pts = &points[c * CHUNK..(c * CHUNK + CHUNK).min(points.len())];
            self.eval_chunk(pts, &uniform, None, None, Some(chunk));
        });
        cache
    }

    /// Evaluate batches of points: everything into `out` (no cache), the time-dependent part into `out`
    /// from `cache`, or only the spatial part into `fill`.
    fn eval_chunk(
        &self,
        points: &[[f64; 2]],
        uniform: &[f64],
        out: Option<&mut [f64]>,
        cache: Option<&[f64]>,
        mut fill: Option<&mut [f64]>,
    ) {
        let m = self.outputs.len();
        let nc = self.cached.len();
        let mut out = out;
        let mut regs = vec![[0.0f64; LANES]; self.n_slots];
        for &(s, n) in &self.broadcast {
            regs[s as usize] = [uniform[n as usize]; LANES];
        }
        for (b, pts) in points.chunks(LANES).enumerate() {
            // a partial batch repeats its first point in the unused lanes (never read back)
            for l in 0..LANES {
                let p = pts.get(l).unwrap_or(&pts[0]);
                regs[SLOT_X as usize][l] = p[0];
                regs[SLOT_Y as usize][l] = p[1];
            }
            if let Some(cache) = cache {
                for (k, &s) in self.cached.iter().enumerate() {
                    let at = (b * nc + k) * LANES;
                    regs[s as usize].copy_from_slice(&cache[at..at + LANES]);
                }
            }
            let r = regs.as_mut_ptr();
            for &(ref ins, spatial) in &self.instrs {
                // with a cache the spatial instructions were done when it was filled; filling, the others wait
                if (cache.is_some() && spatial) || (fill.is_some() && !spatial) {
                    continue;
                }
                // SAFETY: every slot index is < n_slots = regs.len() (assigned in `Program::new`), and an
                // instruction's destination slot is taken while its operands still hold theirs, so it
                // differs from both: the mutable and the shared references never overlap.
                unsafe {
                    match *ins {
                        Instr::Un(f, d, a) => un_lanes(f, &*r.add(a as usize), &mut *r.add(d as usize)),
                        Instr::Bin(f, d, a, c) => {
                            bin_lanes(f, &*r.add(a as usize), &*r.add(c as usize), &mut *r.add(d as usize))
                        }
                    }
                }
            }
            if let Some(fill) = fill.as_deref_mut() {
                for (k, &s) in self.cached.iter().enumerate() {
                    let at = (b * nc + k) * LANES;
                    fill[at..at + LANES].copy_from_slice(&regs[s as usize]);
                }
                continue;
            }
            let Some(out) = out.as_deref_mut() else { continue };
            let base = b * LANES * m;
            for (k, &(node, s)) in self.outputs.iter().enumerate() {
                for l in 0..pts.len() {
                    out[base + l * m + k] = match s {
                        Some(s) => regs[s as usize][l],
                        None => uniform[node as usize],
                    };
                }
            }
        }
    }
}

/// d ← f(a) lane by lane; a separate loop per operation so each is vectorised where it can be.
#[inline(always)]
fn un_lanes(f: Un, a: &[f64; LANES], d: &mut [f64; LANES]) {
    macro_rules! each {
        ($e:expr) => {
            for l in 0..LANES {
                d[l] = $e(a[l]);
            }
        };
    }
    match f {
        Un::Neg => each!(|v: f64| -v),
        Un::Abs => each!(|v: f64| v.abs()),
        _ => each!(|v| f.apply(v)),
    }
}

/// d ← f(a, c) lane by lane.
#[inline(always)]
fn bin_lanes(f: Bin, a: &[f64; LANES], c: &[f64; LANES], d: &mut [f64; LANES]) {
    macro_rules! each {
        ($e:expr) => {
            for l in 0..LANES {
                d[l] = $e(a[l], c[l]);
            }
        };
    }
    match f {
        Bin::Add => each!(|u: f64, v: f64| u + v),
        Bin::Sub => each!(|u: f64, v: f64| u - v),
        Bin::Mul => each!(|u: f64, v: f64| u * v),
        Bin::Div => each!(|u: f64, v: f64| u / v),
        Bin::Min => each!(|u: f64, v: f64| u.min(v)),
        Bin::Max => each!(|u: f64, v: f64| u.max(v)),
        _ => each!(|u, v| f.apply(u, v)),
    }
}
