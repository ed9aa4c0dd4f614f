//! [`Block`]: the columns of a block of consecutive steps that share their triangular solves
//! (`super::free`: B steps' forward halves in one solve with B right-hand sides, and after their friction
//! problems their backward halves in another).

/// The forward halves of a block of consecutive steps (see `super::free`'s module documentation).
pub struct Block {
    /// Step of column 0 (0: none computed yet).
    pub(super) first: usize,
    /// Steps per block, B.
    pub(super) cols: usize,
    /// Columns solved: B, fewer for the run's last block if it has fewer steps (`super::free`'s module doc).
    pub(super) width: usize,
    pub(super) n: usize,
    /// lⁿ, column by column, in the unknowns' order.
    pub(super) loads: Vec<f64>,
    /// yⁿ = L⁻¹Pᵀlⁿ, then (after [`super::free::FreeResponse::finish_block`]) yⁿ − [0; Wμⁿ] solved backward;
    /// with superposed loads [0; Wμⁿ] solved backward.
    pub(super) y: Vec<f64>,
    /// Superposed loads: the last μ solved for in a block and its K⁻¹Eμ, reused while μ repeats
    /// (bit-equal; the columns are computed independently of their position, so reuse changes no bit).
    pub(super) friction: (Vec<f64>, Vec<f64>),
}

impl Block {
    /// True if step n has a column in the block.
    pub(super) fn holds(&self, n: usize) -> bool {
        self.first > 0 && (self.first..self.first + self.cols).contains(&n)
    }

    /// Positions of step n's column.
    pub(super) fn col(&self, n: usize) -> std::ops::Range<usize> {
        let j = n - self.first;
        j * self.n..(j + 1) * self.n
    }

    /// lⁿ of a step in the block.
    pub fn load(&self, n: usize) -> &[f64] {
        &self.loads[self.col(n)]
    }
}
