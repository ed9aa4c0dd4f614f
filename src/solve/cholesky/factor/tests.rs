use super::super::ordering::nested_dissection;
use super::*;
use crate::sparse::{csc_from_triplets, matvec};

/// Plane-elasticity-like test matrix: a 2D grid (m × m nodes) Laplacian, two coupled unknowns per node
/// (numbered consecutively), shifted to be SPD.
fn grid(m: usize) -> SparseColMat<usize, f64> {
    let node = |i: usize, j: usize| i * m + j;
    let mut t = Vec::new();
    for i in 0..m {
        for j in 0..m {
            let a = node(i, j);
            for c in 0..2 {
                t.push((2 * a + c, 2 * a + c, 4.5));
            }
            t.push((2 * a, 2 * a + 1, 0.25));
            t.push((2 * a + 1, 2 * a, 0.25));
            for (di, dj) in [(0, 1), (1, 0)] {
                if i + di < m && j + dj < m {
                    let b = node(i + di, j + dj);
                    for c in 0..2 {
                        t.push((2 * a + c, 2 * b + c, -1.0));
                        t.push((2 * b + c, 2 * a + c, -1.0));
                    }
                }
            }
        }
    }
    csc_from_triplets(2 * m * m, &t)
}

fn residual(k: &SparseColMat<usize, f64>, f: &Factor) -> f64 {
    let n = k.nrows();
    let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
    let mut x = b.clone();
    f.solve_in_place(&mut x);
    let mut r = vec![0.0; n];
    matvec(k, &x, &mut r);
    r.iter().zip(&b).map(|(r, b)| (r - b).abs()).fold(0.0, f64::max)
}

/// The blocked steps (`solve::free::Block`) rely on this: in a solve with B columns each column's
/// result depends neither on the other columns nor on its position.
#[test]
fn block_columns_are_independent_of_neighbours_and_position() {
    let k = grid(70);
    let n = k.nrows();
    let f = Factor::with_last(&k, &[0, 2, 4, 6]).unwrap();
    let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
    let cols = 16;
    let mut y: Vec<f64> =
        (0..n * cols).map(|i| if (i / n).is_multiple_of(2) { b[i % n] } else { ((i * 13) % 7) as f64 }).collect();
    f.forward_block(&mut y, cols).unwrap();
    f.backward_block(&mut y, cols).unwrap();
    let bits = |c: usize| y[c * n..(c + 1) * n].iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    for c in (2..cols).step_by(2) {
        assert_eq!(bits(0), bits(c), "column {c}");
    }
}

/// The factor with the ordering of `fill_order` on the groups `first`.
fn ordered(k: &SparseColMat<usize, f64>, nested: bool, first: &[usize]) -> Result<Factor> {
    Factor::with_order(k, &[], fill_order(&Graph::of_matrix(k, first), nested)?)
}

/// Groups of the two unknowns of a grid node.
fn pairs(n: usize) -> Vec<usize> {
    (0..=n).step_by(2).collect()
}

fn singles(n: usize) -> Vec<usize> {
    (0..=n).collect()
}

#[test]
fn nested_dissection_orders_and_solves() {
    let k = grid(40);
    let (fwd, inv) = nested_dissection(&Graph::of_matrix(&k, &pairs(k.nrows()))).expect("METIS ordering");
    assert!(fwd.iter().enumerate().all(|(new, &old)| inv[old] == new));
    let nd = ordered(&k, true, &pairs(k.nrows())).unwrap();
    let amd = ordered(&k, false, &pairs(k.nrows())).unwrap();
    assert!(residual(&k, &nd) < 1e-12 && residual(&k, &amd) < 1e-12);
}

#[test]
fn nested_dissection_is_deterministic_across_threads() {
    let k = grid(30);
    let reference = nested_dissection(&Graph::of_matrix(&k, &pairs(k.nrows()))).unwrap();
    let runs: Vec<_> = std::thread::scope(|s| {
        let h: Vec<_> =
            (0..4).map(|_| s.spawn(|| nested_dissection(&Graph::of_matrix(&k, &pairs(k.nrows()))).unwrap())).collect();
        h.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(runs.iter().all(|r| *r == reference));
}

#[test]
fn degenerate_graphs_fall_back_to_amd() {
    let diag = |n: usize| csc_from_triplets(n, &(0..n).map(|i| (i, i, 2.0)).collect::<Vec<_>>());
    for n in [0, 1, 2, 5] {
        assert!(nested_dissection(&Graph::of_matrix(&diag(n), &singles(n))).is_none());
        let f = ordered(&diag(n), true, &singles(n)).unwrap();
        assert!(residual(&diag(n), &f) < 1e-15);
    }
    // One coupled pair: a single METIS vertex, no edges.
    let pair = csc_from_triplets(2, &[(0, 0, 2.0), (1, 1, 2.0), (0, 1, 1.0), (1, 0, 1.0)]);
    assert!(nested_dissection(&Graph::of_matrix(&pair, &[0, 2])).is_none());
    assert!(residual(&pair, &ordered(&pair, true, &[0, 2]).unwrap()) < 1e-15);
    // Three unknowns: METIS on a 2-vertex graph.
    let three = csc_from_triplets(
        3,
        &[(0, 0, 4.0), (1, 1, 4.0), (2, 2, 4.0), (1, 2, 1.0), (2, 1, 1.0), (0, 2, 1.0), (2, 0, 1.0)],
    );
    assert!(residual(&three, &ordered(&three, true, &[0, 1, 3]).unwrap()) < 1e-14);
}

/// The system shall give the same factor, bit for bit, from K's lower triangle alone as from both
/// triangles (a run keeps only the lower one, `stepping::setup`): the factorisation reads that triangle
/// only, so upper entries that differ from their mirror by rounding (as K's element blocks do) change
/// nothing, and the symbolic factorisation of the lower pattern has the same structure.
#[test]
fn the_lower_triangle_gives_the_factor_of_both() {
    let k = grid(30);
    let n = k.nrows();
    // both triangles, the upper entries off their mirror by a few ulps
    let (cp, ri) = (k.symbolic().col_ptr(), k.symbolic().row_idx());
    let mut val = k.val().to_vec();
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            if ri[p] < j {
                val[p] *= 1.0 + 4.0 * f64::EPSILON;
            }
        }
    }
    let full = SparseColMat::new(k.symbolic().to_owned().unwrap(), val);
    let lower = SparseColMat::new(
        crate::sparse::lower_pattern(full.symbolic()),
        crate::sparse::lower_values(full.symbolic(), full.val().to_vec()),
    );
    assert!(lower.compute_nnz() < full.compute_nnz());
    let last = [0, 2, 4, 6];
    let base = fill_order(&Graph::of_matrix(&full, &pairs(n)), false).unwrap();
    let a = Factor::with_order(&full, &last, base.clone()).unwrap();
    let b = Factor::with_order(&lower, &last, base).unwrap();
    assert_eq!(a.len_val(), b.len_val());
    let bits = |m: DMatrix<f64>| m.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(a.last_block().unwrap()), bits(b.last_block().unwrap()));
    let rhs: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
    let (mut x, mut y) = (rhs.clone(), rhs);
    a.solve_in_place(&mut x);
    b.solve_in_place(&mut y);
    assert!(x.iter().zip(&y).all(|(p, q)| p.to_bits() == q.to_bits()));
    // a run's path: the symbolic factorisation from the full pattern, the values from the lower triangle
    let base = fill_order(&Graph::of_matrix(&full, &pairs(n)), false).unwrap();
    let c = Factor::numeric(Symbolic::from_symmetric(full.symbolic(), &last, base).unwrap(), &lower).unwrap();
    assert_eq!(bits(b.last_block().unwrap()), bits(c.last_block().unwrap()));
    let bits_l = |f: &Factor| f.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits_l(&b), bits_l(&c), "L from the full pattern's analysis");
    // a matrix of another pattern is refused
    assert!(Factor::numeric(Symbolic::from_symmetric(full.symbolic(), &last, (0..n).collect()).unwrap(), &grid(29))
        .is_err());
}

/// The system shall compute, from its own elimination tree and column counts (`solve::cholesky::etree`), the
/// same supernodal factor as faer's complete analysis (`factorize_symbolic_cholesky`), bit for bit,
/// with unknowns ordered last, under AMD and nested dissection.
#[test]
fn the_factor_is_faers_own_bit_for_bit() {
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering,
    };
    use faer::sparse::linalg::SupernodalThreshold;
    let k = grid(45);
    let n = k.nrows();
    for nested in [false, true] {
        let base = fill_order(&Graph::of_matrix(&k, &pairs(n)), nested).unwrap();
        let f = Factor::with_order(&k, &[3, 1, 40], base).unwrap();
        let inv: Vec<usize> = {
            let mut inv = vec![0; n];
            f.fwd.iter().enumerate().for_each(|(new, &old)| inv[old] = new);
            inv
        };
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let ord = SymmetricOrdering::Custom(PermRef::new_checked(&f.fwd, &inv, n));
        let theirs = factorize_symbolic_cholesky(k.symbolic(), Side::Lower, ord, params).unwrap();
        let mut values = vec![0.0; theirs.len_val()];
        let mut mem = MemBuffer::new(theirs.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
        let stack = MemStack::new(&mut mem);
        theirs
            .factorize_numeric_llt(
                &mut values,
                k.as_ref(),
                Side::Lower,
                Default::default(),
                Par::Seq,
                stack,
                Default::default(),
            )
            .unwrap();
        let SymbolicCholeskyRaw::Supernodal(s) = theirs.raw() else { panic!("faer chose the simplicial kernel") };
        assert_eq!(s.n_supernodes(), f.symbolic.n_supernodes(), "supernodes (nested {nested})");
        for j in 0..s.n_supernodes() {
            assert_eq!(s.supernode(j).start(), f.symbolic.supernode(j).start());
            assert_eq!(s.supernode(j).pattern(), f.symbolic.supernode(j).pattern());
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&values), bits(&f.values), "L's values (nested {nested})");
    }
}

/// L's values, bit for bit.
fn value_bits(f: &Factor) -> Vec<u64> {
    f.values.iter().map(|v| v.to_bits()).collect()
}

/// The system shall factorise bit-identically run after run with 2 threads, and as faer's sequential
/// kernel does with 1 (`solve::cholesky::subtrees`: subtrees on threads of their own, each supernode computed as
/// faer computes it; the rule of docs/model.md, "Threads"), under AMD and nested dissection, with
/// unknowns ordered last; and report a matrix that is not positive definite at the same column.
#[test]
fn two_threads_factorise_bit_identically_run_after_run() {
    let k = grid(160);
    let n = k.nrows();
    for nested in [false, true] {
        let base = fill_order(&Graph::of_matrix(&k, &pairs(n)), nested).unwrap();
        let factor = |par| Factor::numeric_with(Symbolic::new(k.symbolic(), &[0, 2], base.clone()).unwrap(), &k, par);
        let first = factor(Par::rayon(2)).unwrap();
        let second = factor(Par::rayon(2)).unwrap();
        assert_eq!(value_bits(&first), value_bits(&second), "2 threads, run after run (nested {nested})");
        let seq = factor(Par::Seq).unwrap();
        assert_eq!(value_bits(&first), value_bits(&seq), "2 threads against 1 (nested {nested})");
        assert_eq!(value_bits(&factor(Par::rayon(3)).unwrap()), value_bits(&seq), "3 threads (nested {nested})");
    }
    // indefinite: a negative diagonal entry deep in the ordering
    let mut bad = k.clone();
    let (cp, ri) = (bad.symbolic().col_ptr().to_vec(), bad.symbolic().row_idx().to_vec());
    let j = 2 * 80 * 160 + 7;
    let p = (cp[j]..cp[j + 1]).find(|&p| ri[p] == j).unwrap();
    bad.val_mut()[p] = -10.0;
    let base = fill_order(&Graph::of_matrix(&bad, &pairs(n)), true).unwrap();
    let err = |par| {
        Factor::numeric_with(Symbolic::new(bad.symbolic(), &[], base.clone()).unwrap(), &bad, par)
            .err()
            .map(|e| e.to_string())
    };
    let seq = err(Par::Seq);
    assert!(seq.is_some());
    assert_eq!(err(Par::rayon(2)), seq);
}

/// The system shall solve with several right-hand sides bit-identically with 2 threads and with 1 (the
/// blocked steps, superposition and condensation solve so: `solve_par`).
#[test]
fn block_solves_are_the_same_with_two_threads() {
    let k = grid(160);
    let n = k.nrows();
    let f = Factor::with_last(&k, &[0, 2, 4, 6]).unwrap();
    let cols = 16;
    let rhs: Vec<f64> = (0..n * cols).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
    let solve = |par| {
        let mut y = rhs.clone();
        let llt = f.supernodal().unwrap();
        let mut mem = MemBuffer::new(f.symbolic.solve_in_place_scratch::<f64>(cols, par));
        let ym = MatMut::from_column_major_slice_mut(&mut y, n, cols);
        llt.solve_in_place_with_conj(Conj::No, ym, par, MemStack::new(&mut mem));
        y.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    };
    let seq = solve(Par::Seq);
    assert_eq!(solve(Par::rayon(2)), seq);
    assert_eq!(solve(Par::rayon(2)), seq);
}

/// The system shall factorise on one thread, giving the factor of two bit for bit, when the memory
/// available holds the factor and one thread's scratch but not that of two (`Symbolic::par_that_fits`), and
/// refuse with a typed error naming the bytes needed and those available when not even one thread's fits.
#[test]
fn without_the_memory_for_two_threads_one_factorises_and_without_that_it_is_refused() {
    let k = grid(160);
    let n = k.nrows();
    let base = fill_order(&Graph::of_matrix(&k, &pairs(n)), true).unwrap();
    let symbolic = || Symbolic::new(k.symbolic(), &[0, 2], base.clone()).unwrap();
    let two_threads = super::super::subtrees::threads_of(Par::rayon(2), n);
    assert!(two_threads.is_some() || !cfg!(target_arch = "x86_64") || !std::arch::is_x86_feature_detected!("avx2"));
    let ((two, schedule), (one, none)) = (symbolic().need(Par::rayon(2)), symbolic().need(Par::Seq));
    assert!(none.is_none());
    if two_threads.is_none() {
        return; // no factorisation by subtrees on this machine: nothing to fall back from
    }
    assert!(schedule.is_some_and(|b| b > 0) && two > one, "two threads need {two} B, one {one} B");
    let factor = |have: Option<u64>| Factor::numeric_par(Par::rayon(2), symbolic(), &k, || (), have).0;
    let reference = factor(None).unwrap();
    assert_eq!(reference.threads(), 2);
    assert_eq!(factor(Some(two)).unwrap().threads(), 2, "exactly the bytes of two threads");
    for have in [two - 1, one] {
        let fallback = factor(Some(have)).unwrap();
        assert_eq!(fallback.threads(), 1, "{have} B available");
        assert_eq!(value_bits(&fallback), value_bits(&reference), "{have} B available");
    }
    match factor(Some(one - 1)) {
        Err(e @ Error::TooLarge { need, have, .. }) => {
            assert_eq!((need, have), (one, one - 1));
            let text = e.to_string();
            assert!(text.contains("memory for the Cholesky factor") && text.contains("is available"), "{text}");
        }
        other => panic!("expected TooLarge, got {:?}", other.map(|f| f.threads())),
    }
}
