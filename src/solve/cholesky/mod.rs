//! Sparse Cholesky factorisation K = P L Lᵀ Pᵀ of a symmetric positive definite matrix, made once and
//! solved with many times. It knows nothing of contact or of the finite elements; its one public face is
//! this module's re-exports. As in `faer::sparse::linalg::cholesky`, the work is split in layers:
//!
//! * the fill-reducing ordering P on the graph of the unknowns or of groups of them ([`Graph`]:
//!   AMD, METIS nested dissection, or a coordinate bisection when points are given; [`fill_order`],
//!   [`fill_order_at`]);
//! * the **symbolic** factorisation ([`Symbolic`]: the ordering with chosen unknowns moved last, the
//!   elimination tree, the column counts and the supernodes), which needs only the pattern;
//! * the **numeric** factorisation and the solves ([`Factor`]: faer's supernodal kernel, the trailing
//!   block of L, the forward and backward halves).
//!
//! ```
//! use tresca_cr::solve::cholesky::{fill_order, Factor, Graph, Symbolic};
//! use tresca_cr::sparse::{csc_from_triplets, matvec};
//!
//! // the 1D Laplacian tridiag(−1, 2, −1) on 6 unknowns, both triangles stored
//! let n = 6;
//! let mut trip = Vec::new();
//! for i in 0..n {
//!     trip.push((i, i, 2.0));
//!     if i + 1 < n {
//!         trip.extend([(i + 1, i, -1.0), (i, i + 1, -1.0)]);
//!     }
//! }
//! let k = csc_from_triplets(n, &trip);
//! // symbolic: an ordering of the graph of the unknowns (one per group), unknown 0 moved last
//! let groups: Vec<usize> = (0..=n).collect();
//! let order = fill_order(&Graph::of_matrix(&k, &groups), false)?;
//! let symbolic = Symbolic::new(k.symbolic(), &[0], order)?;
//! // numeric, then solve K x = K·1
//! let factor = Factor::numeric(symbolic, &k)?;
//! assert_eq!(factor.last(), &[0]);
//! let mut x = vec![0.0; n];
//! matvec(&k, &[1.0; 6], &mut x);
//! factor.solve_in_place(&mut x);
//! assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-12));
//! // the trailing block of L gives (K⁻¹)₀₀ = n/(n + 1) without a solve: L_ll² = 1/(K⁻¹)₀₀
//! let l = factor.last_block()?[(0, 0)];
//! assert!((l * l - 7.0 / 6.0).abs() < 1e-12);
//! # Ok::<(), tresca_cr::Error>(())
//! ```
//!
//! Its modules: [`ordering`] (the graph, AMD and METIS) and [`dissect`] (coordinate bisection) with [`direction`] (the direction of each cut) and [`cover`] (its separators); [`etree`]
//! (elimination tree, postorder, column counts), [`grouped`] (the same on the groups' graph) and [`symbolic`] (the symbolic factorisation); [`factor`]
//! (numeric factorisation and solves), [`subtrees`], [`schedule`] and [`queue`] (the numeric factorisation on
//! several threads) and [`pages`] (the factor's memory, mapped in huge pages).

pub(crate) mod cover;
pub(crate) mod direction;
pub(crate) mod dissect;
pub(crate) mod etree;
pub(crate) mod factor;
pub(crate) mod grouped;
pub(crate) mod ordering;
pub(crate) mod pages;
pub(crate) mod queue;
pub(crate) mod schedule;
pub(crate) mod subtrees;
pub(crate) mod symbolic;

pub use factor::Factor;
pub use ordering::{Graph, ND_MIN_SIZE};
pub use symbolic::{fill_order, fill_order_at, Symbolic};
