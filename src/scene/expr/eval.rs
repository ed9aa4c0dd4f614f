//! Evaluation of a compiled [`Program`] over many points.
//!
//! Points go in batches of [`LANES`]: every instruction is one loop over the lanes of its register slots
//! (`dst[l] ← op(a[l], b[l])`), which the compiler vectorises for + − × ÷, min, max, abs. The loops are
//! compiled twice, for the baseline x86-64 target and with AVX2 (chosen at run time): the same IEEE
//! operations on wider registers, so the same bits (no fused multiply-add: Rust never contracts).
//!
//! Three ways through a batch, each with its own instruction list (no per-instruction tests):
//! * no cache: every varying instruction;
//! * filling a cache ([`Program::fill_cache`]): the spatial instructions, then the cached slots are
//!   copied out (once per run);
//! * from a cache (each time node): the timed instructions only. Their operands are read through a table
//!   of row pointers in which the cached slots point straight into the cache, so the spatial values are
//!   read in place, never copied into registers (copying them was ~15 % of an MMS run).
//!
//! The outputs are copied out of the registers point-major and checked for finiteness on the way
//! (the caller looks for the offending point only when a value is not finite). Each point's values come
//! from the same sequence of operations whatever the batching, the path or the thread count, so results
//! are bit-reproducible and the three paths agree bit for bit.

use super::program::{Instr, Op, Program, LANES, SLOT_X, SLOT_Y};
use super::sym::{Bin, Un};
use std::sync::atomic::{AtomicBool, Ordering};

/// Points per chunk of parallel work (a whole number of batches).
const CHUNK: usize = 16 * LANES;

type Row = [f64; LANES];

/// What a batch run computes.
#[derive(Clone, Copy)]
enum Path<'a> {
    All,
    Fill,
    /// This chunk's part of the cache.
    Cached(&'a [f64]),
}

impl Program {
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

    /// All outputs at every point at time t, point-major: `out[i * n_outputs + k]` (every entry is
    /// written; `out` is only resized). Points are split into chunks evaluated in parallel (pointwise, so
    /// the values do not depend on the split). With `cache` (from [`Program::fill_cache`] on the same
    /// points) the spatial part is read, not computed: the same operations were done there, so the
    /// values are the same. Returns whether every value is finite.
    pub fn eval(&self, points: &[[f64; 2]], t: f64, cache: Option<&[f64]>, out: &mut Vec<f64>) -> bool {
        let m = self.outputs.len();
        out.resize(points.len() * m, 0.0);
        if m == 0 || points.is_empty() {
            return true;
        }
        let uniform = self.uniform(t);
        let per_chunk = CHUNK * self.cached.len();
        let finite = AtomicBool::new(true);
        crate::parallel::for_chunks(out, CHUNK * m, 1, |c, chunk| {
            let pts = &points[c * CHUNK..(c * CHUNK + chunk.len() / m)];
            let path = match cache {
                Some(cc) => Path::Cached(&cc[c * per_chunk..(c * per_chunk + per_chunk).min(cc.len())]),
                None => Path::All,
            };
            if !run(self, pts, &uniform, path, chunk) {
                finite.store(false, Ordering::Relaxed);
            }
        });
        finite.into_inner()
    }

    /// As [`Program::eval`] on `points[start..start + n]` with the cache of all `points`, on this thread
    /// (for callers that split the points themselves). `start` is a multiple of [`LANES`].
    pub fn eval_range(
        &self,
        points: &[[f64; 2]],
        start: usize,
        n: usize,
        t: f64,
        cache: &[f64],
        out: &mut Vec<f64>,
    ) -> bool {
        assert_eq!(start % LANES, 0, "a range starts at a batch");
        let m = self.outputs.len();
        out.resize(n * m, 0.0);
        if m == 0 || n == 0 {
            return true;
        }
        let at = start / LANES * LANES * self.cached.len();
        run(self, &points[start..start + n], &self.uniform(t), Path::Cached(&cache[at.min(cache.len())..]), out)
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
        crate::parallel::for_chunks(&mut cache, CHUNK * self.cached.len(), 1, |c, chunk| {
            let pts = &points[c * CHUNK..(c * CHUNK + CHUNK).min(points.len())];
            run(self, pts, &uniform, Path::Fill, chunk);
        });
        cache
    }
}

/// [`run_batches`], with AVX2 where the processor has it.
fn run(p: &Program, points: &[[f64; 2]], uniform: &[f64], path: Path, sink: &mut [f64]) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports AVX2.
        return unsafe { run_avx2(p, points, uniform, path, sink) };
    }
    run_batches(p, points, uniform, path, sink)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_avx2(p: &Program, points: &[[f64; 2]], uniform: &[f64], path: Path, sink: &mut [f64]) -> bool {
    run_batches(p, points, uniform, path, sink)
}

/// Evaluate the batches of `points` along `path` into `sink`: the outputs (point-major) or, filling, the
/// cached slots (batch by batch). Returns whether every output value is finite.
#[inline(always)]
fn run_batches(p: &Program, points: &[[f64; 2]], uniform: &[f64], path: Path, sink: &mut [f64]) -> bool {
    let (m, nc) = (p.outputs.len(), p.cached.len());
    let mut regs: Vec<Row> = vec![[0.0; LANES]; p.n_slots];
    for &(s, n) in &p.broadcast {
        regs[s as usize] = [uniform[n as usize]; LANES];
    }
    let instrs = match path {
        Path::All => &p.all,
        Path::Fill => &p.spatial,
        Path::Cached(_) => &p.timed,
    };
    // every access to the registers below goes through `r` and the row pointers derived from it
    let r = regs.as_mut_ptr();
    let mut rows: Vec<*const Row> = (0..p.n_slots).map(|i| r.wrapping_add(i) as *const Row).collect();
    let mut finite = true;
    for (b, pts) in points.chunks(LANES).enumerate() {
        // SAFETY: slots 0 and 1 exist (x, y); a partial batch repeats its first point in the unused lanes
        // (never read back).
        unsafe {
            for l in 0..LANES {
                let q = pts.get(l).unwrap_or(&pts[0]);
                (*r.add(SLOT_X as usize))[l] = q[0];
                (*r.add(SLOT_Y as usize))[l] = q[1];
            }
        }
        if let Path::Cached(cache) = path {
            for (k, &s) in p.cached.iter().enumerate() {
                let at = (b * nc + k) * LANES;
                rows[s as usize] = cache[at..at + LANES].as_ptr() as *const Row;
            }
        }
        for ins in instrs {
            // SAFETY: every slot index is < n_slots (assigned in `Program::new`); an instruction's
            // destination is a register slot taken while its operands still hold theirs, so it differs
            // from both, and it is never a cached slot (those are only written filling, through `r`). The
            // operand rows point into `regs` or into the cache, which outlives this call.
            unsafe {
                match *ins {
                    Instr::Un(f, d, a) => un_lanes(f, &*rows[a as usize], &mut *r.add(d as usize)),
                    Instr::Bin(f, d, a, c) => {
                        bin_lanes(f, &*rows[a as usize], &*rows[c as usize], &mut *r.add(d as usize))
                    }
                }
            }
        }
        if let Path::Fill = path {
            for (k, &s) in p.cached.iter().enumerate() {
                let at = (b * nc + k) * LANES;
                // SAFETY: as above.
                sink[at..at + LANES].copy_from_slice(unsafe { &*rows[s as usize] });
            }
            continue;
        }
        let base = b * LANES * m;
        let n = pts.len();
        for (k, &(node, s)) in p.outputs.iter().enumerate() {
            match s {
                Some(s) => {
                    // SAFETY: as above.
                    let row = unsafe { &*rows[s as usize] };
                    for (l, &v) in row[..n].iter().enumerate() {
                        sink[base + l * m + k] = v;
                        finite &= v.is_finite();
                    }
                }
                None => {
                    let v = uniform[node as usize];
                    finite &= v.is_finite();
                    for l in 0..n {
                        sink[base + l * m + k] = v;
                    }
                }
            }
        }
    }
    finite
}

/// d ← f(a) lane by lane; a separate loop per operation so each is vectorised where it can be.
#[inline(always)]
fn un_lanes(f: Un, a: &Row, d: &mut Row) {
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
fn bin_lanes(f: Bin, a: &Row, c: &Row, d: &mut Row) {
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
