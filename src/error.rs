//! The crate's one error type. Every variant carries the data a user needs to find the problem.

use std::path::PathBuf;

/// Everything that can go wrong between reading a scene and writing its results.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scene value is missing, malformed or out of range.
    #[error("scene {file}: `{key}`: {msg}")]
    Scene { file: String, key: String, msg: String },

    /// An expression failed to parse, uses unknown variables, or evaluated to a non-finite value.
    #[error("expression `{key}` = \"{expr}\": {msg}")]
    Expr { key: String, expr: String, msg: String },

    /// The mesh is unusable (malformed file, degenerate cells, boundary edges without a part, ...).
    #[error("mesh {source_name}: {msg}")]
    Mesh { source_name: String, msg: String },

    /// A linear system is singular or not positive definite (for example rigid motions not fixed).
    #[error("linear algebra: {0}")]
    Linear(String),

    /// The per-step friction solver did not converge.
    #[error(
        "step {step} (t = {time}): {solver} did not converge in {iterations} iterations \
         (residual {residual:.3e}, tolerance {tol:.1e})"
    )]
    NotConverged { step: usize, time: f64, solver: &'static str, iterations: usize, residual: f64, tol: f64 },

    /// A floating body's loads that no contact force within its bounds balances (`friction::floating`).
    #[error(
        "step {step} (t = {time}): the loads have a net force ({:.3e}, {:.3e}) and moment {moment:.3e} about \
         ({:.4e}, {:.4e}) along {motion}, a rigid motion of the body that contact and friction cannot balance \
         (it would fly away or turn freely; add a dirichlet part or change the loads)",
        force[0], force[1], centre[0], centre[1]
    )]
    Unbalanced { step: usize, time: f64, motion: String, force: [f64; 2], moment: f64, centre: [f64; 2] },

    /// A floating body's rigid motion that no contact force resists (the solution is not unique).
    #[error(
        "step {step} (t = {time}): {motion} of the body is not held: no contact edge in contact, sticking or \
         bilateral resists it, so the solution is not unique; add a dirichlet part, a symmetry part or friction \
         that holds it"
    )]
    Unheld { step: usize, time: f64, motion: String },

    /// Reading or writing a file failed.
    #[error("{path}: {msg}")]
    Io { path: PathBuf, msg: String },

    /// Another run owns the results file (see `output::lock`).
    #[error(
        "{path}: {holder} is already writing this results file (lock {path}.lock); wait for it to end or choose \
         another output path"
    )]
    Busy { path: PathBuf, holder: String },

    /// The run would need more memory or disk than there is (or than the limit given).
    #[error(
        "the run needs about {} of {what} but {} {limit}; {hint}",
        human(*need),
        human(*have)
    )]
    TooLarge { what: &'static str, need: u64, have: u64, limit: &'static str, hint: String },

    /// The thread count (`--threads`, `TRESCA_THREADS`) is not a whole number ≥ 1.
    #[error("the thread count (--threads, TRESCA_THREADS) must be a whole number ≥ 1, not {0:?}")]
    Threads(String),

    /// A thread count beyond the threads a run starts (`threads::MAX`, or the cores if more).
    #[error(
        "the thread count (--threads, TRESCA_THREADS) {asked} is more than a run starts: at most {max} (more \
         threads than cores only share them; the results do not depend on the count)"
    )]
    TooManyThreads { asked: usize, max: usize },

    /// The system refused to start a thread the run needs (`threads::scoped`, `threads::set`).
    #[error(
        "cannot start a thread for {what}: {msg}; the process is at a limit of threads or of memory for their \
         stacks (ulimit -u, a cgroup's pids.max, ulimit -v, RUST_MIN_STACK): raise it"
    )]
    Thread { what: &'static str, msg: String },
}

/// Bytes in a readable unit (decimal: kB, MB, GB, TB).
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    match b {
        _ if b >= 1e12 => format!("{:.1} TB", b / 1e12),
        _ if b >= 1e9 => format!("{:.1} GB", b / 1e9),
        _ if b >= 1e6 => format!("{:.1} MB", b / 1e6),
        _ if b >= 1e3 => format!("{:.1} kB", b / 1e3),
        _ => format!("{bytes} B"),
    }
}

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    pub(crate) fn scene(file: &str, key: impl Into<String>, msg: impl Into<String>) -> Self {
        Error::Scene { file: file.to_string(), key: key.into(), msg: msg.into() }
    }
    pub(crate) fn mesh(source_name: &str, msg: impl Into<String>) -> Self {
        Error::Mesh { source_name: source_name.to_string(), msg: msg.into() }
    }
}
