//! What a run will need, estimated from the scene before anything large is allocated: memory (mesh, K and
//! its factor, the condensed operator, per-step series) and disk (the results file). `check` prints the
//! estimates; `check` and `run` refuse a run whose estimate exceeds what the machine has (MemAvailable of
//! `/proc/meminfo`, free space of the output's file system) or the limits the user gives.
//!
//! Calibration (Example 5.1 `--steps 4 -o`, peak RSS by `/usr/bin/time` in KiB, with K kept
//! as its lower triangle; figures in `reference/performance.md` §8): six meshes from 24,640 to 4,817,792
//! unknowns (refine 5–8 of `cells = [2, 2]`, refine 8 of `[3, 3]`, refine 7 of `[7, 7]`; refitted in the
//! eighth session, when refine 7 passed to the nested dissection and its peak fell 10 %). The
//! factor's fill grows like n log n, so the estimate is γ + n (α + β log₂ n) plus the two buffers of a
//! block of steps (`solve::free`, 16 bytes a value, at most 16 columns and 2²⁴ values) and the dense contact
//! parts: γ, α, β fitted by least squares of the relative misfit to the six, which it then gives within
//! 5.1 % (AMD's fill below the dissection's threshold and the dissection's above follow one curve only
//! approximately).
//! An estimate, not a bound: the fill also depends on the ordering (AMD below 200,000 unknowns, nested dissection
//! above). The factorisation checks its exact size once the symbolic factorisation is known
//! (`solve::cholesky::symbolic::Symbolic::fits`) and refuses a factor that would not fit, or first tries
//! METIS's ordering, which fills a little less. The estimate gives that fallback's peak beside
//! ([`Estimate::memory_metis`]): the coordinate nested dissection's factor has about `FILL_ND` · n log₂ n
//! entries (13.9 at 1.57 M unknowns, 14.2–14.5 at 3.5–6.3 M) and METIS's `METIS_FILL` of them (0.972 at
//! 6,292,480 unknowns: 2.007e9 against 2.064e9 entries), 8 bytes an entry; refine 9 of Example 5.1 ran with
//! METIS at a 21.87 GB peak against 21.1 GB so estimated.
//!
//! Beside the fit, what the calibration scene does not hold: the results writer's queue of steps, full
//! (how full it gets depends on the speed of the solve), and the expressions evaluated at every volume
//! quadrature point at every time node (a body force, an exact solution), whose cached values are
//! counted from their compiled programs.

use super::expr::program::Program;
use super::expr::Expr;
use super::{MeshSpec, PartKind, Scene};
use crate::error::{human, Error, Result};
use std::path::Path;

pub use crate::machine::{available_disk, available_memory};

/// Sizes and needs of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub triangles: u64,
    pub edges: u64,
    pub unknowns: u64,
    pub contact: u64,
    pub steps: u64,
    /// Peak memory, bytes.
    pub memory: u64,
    /// Peak memory with METIS's ordering, which the set-up falls back to from `FALLBACK_MIN_UNKNOWNS`
    /// unknowns when the coordinate ordering's factor does not fit (module doc); `None` below.
    pub memory_metis: Option<u64>,
    /// Results file, bytes (0 when no file is written).
    pub disk: u64,
}

/// Peak bytes of the set-up (mesh, space, K, factor) are BYTES_FIXED + unknowns · (BYTES_PER_UNKNOWN +
/// BYTES_PER_UNKNOWN_LOG2 · log₂(unknowns)) (fitted, see the module doc).
const BYTES_FIXED: f64 = 9.439e6;
const BYTES_PER_UNKNOWN: f64 = 623.05;
const BYTES_PER_UNKNOWN_LOG2: f64 = 120.12;
/// Factor entries of the coordinate nested dissection per n log₂ n, and METIS's share of them (module doc).
const FILL_ND: f64 = 14.5;
const METIS_FILL: f64 = 0.972;
/// From this many unknowns K is ordered by nested dissection and the set-up can fall back to METIS
/// (`solve::cholesky::ND_MIN_SIZE`, which `tests/budget.rs` checks it equals).
pub const FALLBACK_MIN_UNKNOWNS: u64 = 200_000;
/// The values of the block of steps' buffers (`solve::free`): at most 16 columns and 2²⁴ values each.
const BLOCK_COLUMNS: u64 = 16;
const BLOCK_VALUES: u64 = 1 << 24;
/// Bytes per time step kept in memory (time node, load coefficients, contact state at hand).
const BYTES_PER_STEP: u64 = 64;
/// Frames of the visualisation views by default (`output::AUTO_FRAMES`).
const FRAMES: u64 = 51;
/// Steps queued for the results writer at most (`output::background::QUEUE`), each holding u at the edge
/// midpoints (16 bytes an edge), and the bytes of rows buffered for one commit (`output::rows::BUDGET`):
/// whether the queue fills depends on how fast the steps are solved, so the estimate counts it full.
const WRITER_QUEUE: u64 = 32;
const WRITER_ROWS: u64 = 4 << 20;
/// Quadrature points a triangle has for the body force and the error norms (Dunavant degree 4,
/// `fem::quadrature::TRI4`).
const VOLUME_POINTS: u64 = 6;
/// Bytes a volume point holds beside the cached values of its expressions, measured (peak RSS with and
/// without the expression, mms_data_front refine 5: 85 and 31 bytes a point): for the body force the
/// point (16), its weights w·φ (24), its values at a node (16) and what the allocator keeps of the
/// set-up's points; for the exact solution the point and its share of the elements' geometry.
const FORCE_POINT: u64 = 88;
const EXACT_POINT: u64 = 32;

impl Estimate {
    /// The estimate of `scene` run with `steps` time steps; `results`: a results file is written.
    pub fn of(scene: &Scene, steps: usize, results: bool) -> Result<Estimate> {
        let (triangles, edges, contact) = sizes(scene)?;
        // with normal unknowns C has two rows per Γ_C edge (4× the bytes), and a step's rows the normal
        // series (17 bytes an edge, within the doubled count's 33)
        let contact = if scene.has_normal_unknowns() { 2 * contact } else { contact };
        let mut e = Estimate::of_sizes((triangles, edges, contact), steps, results);
        let volume = triangles.saturating_mul(expression_bytes(scene));
        e.memory = e.memory.saturating_add(volume);
        e.memory_metis = e.memory_metis.map(|m| m.saturating_add(volume));
        Ok(e)
    }

    /// The estimate of a run on a mesh of (triangles, edges, contact edges) with `steps` time steps (an
    /// adapted mesh, whose sizes are known once built).
    pub fn of_sizes((triangles, edges, boundary_contact): (u64, u64, u64), steps: usize, results: bool) -> Estimate {
        let unknowns = 2 * edges;
        let contact = boundary_contact;
        let steps = steps as u64;
        let per_unknown = BYTES_PER_UNKNOWN + BYTES_PER_UNKNOWN_LOG2 * (unknowns.max(2) as f64).log2();
        let blocks = 16 * unknowns.saturating_mul(BLOCK_COLUMNS).min(BLOCK_VALUES);
        let memory = ((BYTES_FIXED + per_unknown * unknowns as f64).min(u64::MAX as f64 / 2.0) as u64)
            .saturating_add(blocks)
            .saturating_add(contact.saturating_mul(contact).saturating_mul(16))
            .saturating_add(steps.saturating_mul(BYTES_PER_STEP))
            .saturating_add(if results { writer_bytes(edges, steps) } else { 0 });
        let memory_metis = (unknowns >= FALLBACK_MIN_UNKNOWNS).then(|| {
            let n = unknowns as f64;
            memory.saturating_sub((8.0 * (1.0 - METIS_FILL) * FILL_ND * n * n.log2()) as u64)
        });
        let disk = if results { results_file((triangles, edges, contact), steps, (steps + 1).min(FRAMES)) } else { 0 };
        Estimate { triangles, edges, unknowns, contact, steps, memory, memory_metis, disk }
    }

    /// Refuse the run when memory or disk exceed what there is: the limits given (bytes), else what the
    /// machine has (`dir`: where the results file goes).
    pub fn check(&self, max_memory: Option<u64>, max_disk: Option<u64>, dir: Option<&Path>) -> Result<()> {
        let sizes = format!(
            "{} triangles, {} unknowns, {} contact edges, {} steps",
            self.triangles, self.unknowns, self.contact, self.steps
        );
        // a limit given is checked against the hard bounds too (address space, cgroup: `machine`), which
        // no allocation can pass
        let (mem, mem_limit) = match (max_memory, crate::machine::hard_memory_left()) {
            (Some(m), Some((h, why))) if h < m => (Some(h), why),
            (Some(m), _) => (Some(m), "is the limit given (--max-memory)"),
            (None, _) => crate::machine::memory_left().map_or((None, ""), |(b, why)| (Some(b), why)),
        };
        let least = self.memory_metis.unwrap_or(self.memory);
        if let Some(have) = mem.filter(|&h| least > h) {
            return Err(Error::TooLarge {
                what: "memory",
                need: least,
                have,
                limit: mem_limit,
                hint: format!("{sizes}: use a coarser mesh (--refine) or fewer steps (--steps)"),
            });
        }
        if self.disk > 0 {
            let (disk, disk_limit) = match max_disk {
                Some(d) => (Some(d), "is the limit given (--max-disk)"),
                None => (dir.and_then(available_disk), "is free on the results file's disk"),
            };
            if let Some(have) = disk.filter(|&h| self.disk > h) {
                return Err(Error::TooLarge {
                    what: "disk for the results file",
                    need: self.disk,
                    have,
                    limit: disk_limit,
                    hint: format!("{sizes}: use fewer steps (--steps), a coarser mesh (--refine) or another disk"),
                });
            }
        }
        Ok(())
    }

    /// One line for `check`.
    pub fn describe(&self) -> String {
        let mem = available_memory().map(|m| format!(" of {} available", human(m))).unwrap_or_default();
        let metis = self.memory_metis.map(|m| format!(" (~{} with METIS's ordering, the fallback)", human(m)));
        format!("memory ~{}{}{mem}; results file ~{}", human(self.memory), metis.unwrap_or_default(), human(self.disk))
    }
}

/// Bytes of the results writer's queue and buffered rows (a run that writes a file, `output::background`).
fn writer_bytes(edges: u64, steps: u64) -> u64 {
    (steps + 1).min(WRITER_QUEUE).saturating_mul(16).saturating_mul(edges).saturating_add(WRITER_ROWS)
}

/// Bytes a triangle holds for the expressions evaluated at its volume points at every time node, kept
/// for the run: the body force and the exact solution of the error norms, each bound to the points with
/// its spatial subexpressions cached (`scene::expr::BoundSet`, 8 bytes a cached value). A separated exact
/// solution keeps its space parts instead (`fem::exact`): the larger of the two counts. A separated body
/// force keeps at most `fem::loads::MAX_FACTORS` vectors of the unknowns (at most 8 · 8 bytes an unknown,
/// below the 6 · 56 bytes its points would hold bound), so the bound route bounds it.
fn expression_bytes(scene: &Scene) -> u64 {
    let cached = |es: &[&Expr]| Program::new(&es.iter().map(|e| e.tree()).collect::<Vec<_>>()).n_cached() as u64;
    let force = scene.f.as_ref().map_or(0, |f| 8 * cached(&[&f.0[0], &f.0[1]]) + FORCE_POINT);
    let exact = scene.exact.as_ref().map_or(0, |x| {
        let six = [&x.u.0[0], &x.u.0[1], &x.grad[0][0], &x.grad[0][1], &x.grad[1][0], &x.grad[1][1]];
        let parts: Option<usize> = six.iter().map(|e| e.separate().map(|p| p.len())).sum();
        8 * cached(&six).max(parts.unwrap_or(0) as u64) + EXACT_POINT
    });
    VOLUME_POINTS * (force + exact)
}

/// Bytes of a results file of a mesh of (triangles, edges, contact edges) with `steps` time steps and
/// `frames` visualisation frames (an estimate, as [`Estimate::disk`]).
pub fn results_file((triangles, edges, contact): (u64, u64, u64), steps: u64, frames: u64) -> u64 {
    // per step: u (edges × 2 f64), 8 scalars, 5 contact series (4 f64 + 1 byte), 3 errors
    let row = 16 * edges + 64 + 33 * contact + 24;
    let per_frame = 100 * triangles + 40 * contact;
    let fixed = 250 * triangles + 64 * edges + (1 << 20);
    (steps + 1).saturating_mul(row).saturating_add(frames.saturating_mul(per_frame)).saturating_add(fixed)
}

/// The most triangles a mesh may count (2⁴⁸ = 2.8e14, beyond any machine's memory by a factor of a
/// thousand): below it every size and byte count of [`Estimate::of_sizes`] is exact in 64-bit integers
/// (the largest, the frames' 51 × 100 bytes a triangle, stays below 2⁶¹), so none wraps around.
const MAX_TRIANGLES: f64 = (1u64 << 48) as f64;

/// (triangles, edges, contact edges) of the scene's mesh, without building it; refused when the
/// triangles exceed [`MAX_TRIANGLES`], with their number computed in floating point.
fn sizes(scene: &Scene) -> Result<(u64, u64, u64)> {
    let (what, triangles) = match &scene.mesh {
        MeshSpec::Structured { cells, refine, .. } => {
            let f = f64::from(1u32 << refine);
            (
                format!("cells = [{}, {}] at refine {refine}", cells[0], cells[1]),
                2.0 * cells[0] as f64 * cells[1] as f64 * f * f,
            )
        }
        MeshSpec::Gmsh { .. } => (String::new(), 0.0),
    };
    if triangles > MAX_TRIANGLES {
        return Err(Error::scene(
            &scene.file,
            "mesh.cells",
            format!(
                "{what} makes {triangles:.3e} triangles, far beyond any machine's memory (at most {MAX_TRIANGLES:.1e} \
                 are counted)"
            ),
        ));
    }
    counts(scene)
}

/// [`sizes`] once the triangles are known to be countable.
fn counts(scene: &Scene) -> Result<(u64, u64, u64)> {
    let contact_parts: Vec<&str> =
        scene.parts.iter().filter(|p| matches!(p.kind, PartKind::Contact(..))).map(|p| p.name.as_str()).collect();
    match &scene.mesh {
        MeshSpec::Structured { cells, refine, .. } => {
            let f = 1u64 << refine;
            let (n, m) = ((cells[0] as u64).saturating_mul(f), (cells[1] as u64).saturating_mul(f));
            let tris = n.saturating_mul(m).saturating_mul(2);
            let edges = n.saturating_mul(m).saturating_mul(3).saturating_add(n + m);
            let side = |s: &str| match s {
                "bottom" | "top" => n,
                "left" | "right" => m,
                _ => 0,
            };
            Ok((tris, edges, contact_parts.iter().map(|s| side(s)).sum()))
        }
        MeshSpec::Gmsh { path, refine } => {
            let text = crate::input::read_text(path, "mesh")?;
            let raw = crate::mesh::parse_gmsh(&text, &path.display().to_string())?;
            let f = 1u64 << (2 * refine);
            let tris = (raw.tris.len() as u64).saturating_mul(f);
            if tris as f64 > MAX_TRIANGLES {
                return Err(Error::scene(
                    &scene.file,
                    "mesh.refine",
                    format!("{} triangles at refine {refine} are far beyond any machine's memory", tris as f64),
                ));
            }
            let contact = raw
                .tagged
                .iter()
                .filter(|(_, tag)| raw.tag_names.get(*tag).is_some_and(|n| contact_parts.contains(&n.as_str())))
                .count() as u64;
            Ok((tris, tris.saturating_mul(3) / 2 + tris.isqrt(), contact << refine))
        }
    }
}

/// A size such as `800M`, `16G`, `1.5T` or a number of bytes (decimal units; `k`, `M`, `G`, `T`).
pub fn parse_size(text: &str) -> std::result::Result<u64, String> {
    let t = text.trim();
    let (num, mult) = match t.chars().last() {
        Some('k' | 'K') => (&t[..t.len() - 1], 1e3),
        Some('m' | 'M') => (&t[..t.len() - 1], 1e6),
        Some('g' | 'G') => (&t[..t.len() - 1], 1e9),
        Some('t' | 'T') => (&t[..t.len() - 1], 1e12),
        _ => (t, 1.0),
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 && v * mult < 1.8e19 => Ok((v * mult) as u64),
        _ => Err(format!("`{text}`: expected a size such as 800M, 16G, 1.5T or a number of bytes")),
    }
}
