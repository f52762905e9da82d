//! Sparse Cholesky factorisation P A Pᵀ = L Lᵀ of the symmetric positive definite step matrices of
//! the 2D/3D scenes (M + βτ²K, M + τ²/4 K, …; contract §4), by faer.
//!
//! Two stages, because their lifetimes differ:
//! - [`SymbolicCholesky`]: the fill-reducing ordering (AMD) and the symbolic factor (elimination
//!   tree, supernodes) of a [`Pattern`] — once per mesh and set of constraints, shared by every
//!   matrix with that pattern (`Arc`, `Send + Sync`);
//! - [`Cholesky`]: the numeric factor L of one matrix — once per run (or per distinct matrix of a
//!   sweep, shared between runs by `Arc`), then only triangular solves.
//!
//! faer reads one triangle of the symmetric matrix; the full-storage CSC of [`SymMatrix`] is
//! handed to it as an upper-triangle view (same `col_ptr` and `row_idx`, with per-column counts
//! stopping at the diagonal), so no copy of the matrix is made. faer chooses a simplicial or a
//! supernodal (dense-block) factorisation from the flop count of the symbolic analysis.
//!
//! Solves run in place with caller-owned scratch ([`SolveWork`]): a time step allocates nothing.
//! Several right-hand sides are solved two ways: [`Cholesky::solve_many_in_place`], faer's
//! blocked solve (setup: the condensation's columns), and
//! [`Cholesky::solve_columns_in_place`], which gives every column the arithmetic of its solve
//! alone (time loops: a lockstep member must write its run alone's numbers). A single solve is
//! the latter with one column.
//! A matrix that is not numerically positive definite is a [`LinalgError`], never a panic.

use std::hash::{Hash, Hasher};
use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{LltError, LltRegularization};
use faer::linalg::matmul::matmul_with_conj;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place_with_conj, solve_upper_triangular_in_place_with_conj,
};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky as FaerSymbolic, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, Conj, MatMut, MatRef, Par, Side};

/// Column stride of [`Cholesky::solve_columns_in_place`]'s block: n rounded up to a whole
/// number of 64-byte lines, so every column starts on one.
fn padded(n: usize) -> usize {
    n.next_multiple_of(8)
}

use super::fe::{Pattern, SymMatrix};

/// Failures of the factorisation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinalgError {
    /// A pivot was ≤ 0 (or NaN): the matrix is not positive definite (numerically).
    #[error("matrix is not positive definite: non-positive pivot at unknown {dof}")]
    NotPositiveDefinite { dof: usize },
    /// A stored value is NaN or infinite.
    #[error("matrix entry ({row}, {col}) is not finite")]
    NonFinite { row: usize, col: usize },
    /// The matrix does not have the pattern the symbolic factorisation was computed for.
    #[error(
        "matrix pattern (n = {n}, nnz = {nnz}) differs from the analysed one (n = {n_sym}, nnz = {nnz_sym})"
    )]
    PatternMismatch {
        n: usize,
        nnz: usize,
        n_sym: usize,
        nnz_sym: usize,
    },
    /// A custom elimination order that is not a permutation of the unknowns.
    #[error("invalid elimination order: {0}")]
    BadOrdering(String),
    /// faer's symbolic analysis failed (out of memory or index overflow).
    #[error("symbolic Cholesky analysis failed: {0}")]
    Symbolic(String),
}

/// Fill-reducing elimination order of the symbolic analysis.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum Ordering {
    /// faer's approximate minimum degree.
    #[default]
    Amd,
    /// `order[k]` is the unknown eliminated k-th, e.g. a nested dissection of a structured mesh
    /// ([`crate::space::fe::BoxMesh::nested_dissection`] with
    /// [`crate::space::fe::DofMap::order_by_nodes`]).
    Custom(Vec<usize>),
}

/// Storage and kernels of the numeric factor.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum FactorKind {
    /// faer decides from the flop count of the symbolic analysis.
    #[default]
    Auto,
    /// Column by column (exact nonzeros, one row index per entry).
    Simplicial,
    /// Dense blocks of columns with a common structure (explicit zeros allowed by relaxation).
    Supernodal,
}

/// Choices of the symbolic analysis. Measured on the bars (README "Performance",
/// `tests/fe_elements.rs::cholesky_timings`): a triangular solve costs ≈ 1.5–2.6 ns per stored
/// entry of L, so the smallest factor wins — AMD + simplicial for the 2D bar, nested dissection
/// + supernodal for the 3D bar.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CholeskyOptions {
    pub ordering: Ordering,
    pub kind: FactorKind,
}

/// Identity of a pattern: size, entry count and a hash of the structure (checked before each
/// numeric factorisation so that a matrix of another mesh cannot be factored with this analysis).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Fingerprint {
    n: usize,
    nnz: usize,
    hash: u64,
}

impl Fingerprint {
    fn of(p: &Pattern) -> Fingerprint {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        p.col_ptr.hash(&mut h);
        p.row_idx.hash(&mut h);
        Fingerprint {
            n: p.n,
            nnz: p.nnz(),
            hash: h.finish(),
        }
    }
}

/// The ordering and symbolic factor of one pattern.
#[derive(Debug)]
pub struct SymbolicCholesky {
    inner: FaerSymbolic<usize>,
    /// Entries of column j on or above the diagonal: the upper-triangle view of the full storage.
    upper_len: Vec<usize>,
    fingerprint: Fingerprint,
}

impl SymbolicCholesky {
    /// AMD ordering and symbolic factorisation of `p` (the full symmetric pattern), faer
    /// choosing simplicial or supernodal.
    pub fn new(p: &Pattern) -> Result<Arc<SymbolicCholesky>, LinalgError> {
        Self::with_options(p, &CholeskyOptions::default())
    }

    /// Symbolic factorisation with a chosen ordering and factor kind (see [`CholeskyOptions`]).
    pub fn with_options(
        p: &Pattern,
        opts: &CholeskyOptions,
    ) -> Result<Arc<SymbolicCholesky>, LinalgError> {
        let upper_len: Vec<usize> = (0..p.n)
            .map(|j| p.col(j).partition_point(|&i| i <= j))
            .collect();
        let view = SymbolicSparseColMatRef::new_checked(
            p.n,
            p.n,
            &p.col_ptr,
            Some(&upper_len),
            &p.row_idx,
        );
        let inv: Vec<usize>;
        let ordering = match &opts.ordering {
            Ordering::Amd => SymmetricOrdering::Amd,
            Ordering::Custom(fwd) => {
                let mut seen = vec![usize::MAX; p.n];
                if fwd.len() != p.n {
                    return Err(LinalgError::BadOrdering(format!(
                        "{} entries for {} unknowns",
                        fwd.len(),
                        p.n
                    )));
                }
                for (k, &i) in fwd.iter().enumerate() {
                    if i >= p.n || seen[i] != usize::MAX {
                        return Err(LinalgError::BadOrdering(format!(
                            "not a permutation: entry {k} = {i}"
                        )));
                    }
                    seen[i] = k;
                }
                inv = seen;
                SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(fwd, &inv, p.n))
            }
        };
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: match opts.kind {
                FactorKind::Auto => SupernodalThreshold::AUTO,
                FactorKind::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
                FactorKind::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
            },
            ..Default::default()
        };
        let inner = factorize_symbolic_cholesky(view, Side::Upper, ordering, params)
            .map_err(|e| LinalgError::Symbolic(format!("{e:?}")))?;
        Ok(Arc::new(SymbolicCholesky {
            inner,
            upper_len,
            fingerprint: Fingerprint::of(p),
        }))
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        self.fingerprint.n
    }

    /// Stored values of the factor L (its nonzeros, including the explicit zeros of supernodes).
    pub fn factor_nnz(&self) -> usize {
        self.inner.len_val()
    }

    /// Number of supernodes (0 if simplicial).
    pub fn supernodes(&self) -> usize {
        match self.inner.raw() {
            faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(s) => s.n_supernodes(),
            _ => 0,
        }
    }

    /// Whether faer chose the supernodal (dense-block) factorisation.
    pub fn is_supernodal(&self) -> bool {
        matches!(
            self.inner.raw(),
            faer::sparse::linalg::cholesky::SymbolicCholeskyRaw::Supernodal(_)
        )
    }
}

/// Scratch memory of a solve (reused across steps: a solve allocates nothing).
pub struct SolveWork {
    buf: MemBuffer,
    ncols: usize,
    /// [`Cholesky::solve_columns_in_place`]'s permuted columns and supernode products, on
    /// 64-byte boundaries (see there); empty for a simplicial factor.
    cols: AlignedBuf,
    tmp: AlignedBuf,
}

/// `len` f64s whose first one sits on a 64-byte boundary, so that a kernel that peels to an
/// alignment boundary treats every copy of a vector the same way.
#[derive(Default)]
struct AlignedBuf {
    data: Vec<f64>,
    offset: usize,
    len: usize,
}

impl AlignedBuf {
    fn new(len: usize) -> AlignedBuf {
        if len == 0 {
            return AlignedBuf::default();
        }
        // 8 f64s of slack: a Vec<f64> starts on an 8-byte boundary, at most 56 bytes short.
        let data = vec![0.0; len + 8];
        let offset = data.as_ptr().align_offset(64);
        AlignedBuf { data, offset, len }
    }

    /// The first `len` values (the buffer's own length at most).
    fn get(&mut self, len: usize) -> &mut [f64] {
        assert!(
            len <= self.len,
            "aligned scratch of {} values, {len} asked",
            self.len
        );
        &mut self.data[self.offset..self.offset + len]
    }
}

impl std::fmt::Debug for SolveWork {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolveWork")
            .field("ncols", &self.ncols)
            .finish_non_exhaustive()
    }
}

/// The numeric factor of one SPD matrix.
#[derive(Debug)]
pub struct Cholesky {
    symbolic: Arc<SymbolicCholesky>,
    values: Vec<f64>,
}

impl Cholesky {
    /// Factor `a`, whose pattern must be the one `sym` was computed from.
    pub fn new(sym: &Arc<SymbolicCholesky>, a: &SymMatrix) -> Result<Cholesky, LinalgError> {
        let p = &*a.pattern;
        let fp = Fingerprint::of(p);
        if fp != sym.fingerprint {
            return Err(LinalgError::PatternMismatch {
                n: fp.n,
                nnz: fp.nnz,
                n_sym: sym.fingerprint.n,
                nnz_sym: sym.fingerprint.nnz,
            });
        }
        if let Some(k) = a.values.iter().position(|v| !v.is_finite()) {
            let col = p.col_ptr.partition_point(|&c| c <= k) - 1;
            return Err(LinalgError::NonFinite {
                row: p.row_idx[k],
                col,
            });
        }
        let n = p.n;
        let view = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(
                n,
                n,
                &p.col_ptr,
                Some(&sym.upper_len),
                &p.row_idx,
            ),
            &a.values,
        );
        let mut values = vec![0.0; sym.inner.len_val()];
        let mut mem = MemBuffer::new(
            sym.inner
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        );
        let res = sym.inner.factorize_numeric_llt(
            &mut values,
            view,
            Side::Upper,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut mem),
            Default::default(),
        );
        match res {
            Ok(_) => Ok(Cholesky {
                symbolic: Arc::clone(sym),
                values,
            }),
            Err(LltError::NonPositivePivot { index }) => {
                // faer's index is in the permuted (AMD) order, 1-based in its simplicial
                // kernel and 0-based in the supernodal one (faer 0.24); report the caller's
                // unknown, 0-based.
                let k = if sym.is_supernodal() {
                    index
                } else {
                    index.saturating_sub(1)
                }
                .min(n - 1);
                let dof = sym.inner.perm().map_or(k, |perm| perm.arrays().0[k]);
                Err(LinalgError::NotPositiveDefinite { dof })
            }
        }
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        self.symbolic.n()
    }

    pub fn symbolic(&self) -> &Arc<SymbolicCholesky> {
        &self.symbolic
    }

    /// Scratch for solves with one right-hand side.
    pub fn work(&self) -> SolveWork {
        self.work_for(1)
    }

    /// Scratch for solves with up to `ncols` right-hand sides at once.
    pub fn work_for(&self, ncols: usize) -> SolveWork {
        let ncols = ncols.max(1);
        let (cols, tmp) = match self.symbolic.inner.raw() {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                let llt = SupernodalLltRef::new(sn, &self.values);
                let widest = (0..sn.n_supernodes())
                    .map(|s| llt.supernode(s).pattern().len())
                    .max()
                    .unwrap_or(0);
                (
                    AlignedBuf::new(padded(self.n()) * ncols),
                    AlignedBuf::new(widest.max(1)),
                )
            }
            SymbolicCholeskyRaw::Simplicial(_) => (AlignedBuf::default(), AlignedBuf::default()),
        };
        SolveWork {
            buf: MemBuffer::new(
                self.symbolic
                    .inner
                    .solve_in_place_scratch::<f64>(ncols, Par::Seq),
            ),
            ncols,
            cols,
            tmp,
        }
    }

    /// Solve for `ncols` right-hand sides (column-major n × ncols) in place, each column with
    /// exactly the arithmetic of a solve of that column alone — whatever `ncols` is.
    ///
    /// faer's blocked solve ([`Self::solve_many_in_place`]) hands each supernode's dense
    /// products to a kernel chosen by the number of columns (matrix–vector for one, small or
    /// packed GEMM for more), so column j of a k-column solve rounds differently from the same
    /// column solved alone. Time loops whose runs may advance in lockstep (issue 24) need the
    /// same numbers either way: a chattering contact magnifies a 1e-16 difference to 1e-10 in
    /// the energy. Here the supernodal sweep visits each supernode once for all columns and
    /// calls faer's dense kernels (triangular solve, matrix–vector product) on one column at a
    /// time, so the factor still streams from memory once per step for the whole block while
    /// every column sees the single-column kernels. The columns are copied (permuted) into
    /// 64-byte-aligned storage so that alignment-dependent kernels treat them alike. A
    /// simplicial factor's solve is already column by column: faer's own is used.
    ///
    /// # Panics
    /// If `rhs.len() != n · ncols` or `work` was made for fewer columns.
    pub fn solve_columns_in_place(&self, rhs: &mut [f64], ncols: usize, work: &mut SolveWork) {
        let SymbolicCholeskyRaw::Supernodal(sn) = self.symbolic.inner.raw() else {
            return self.solve_many_in_place(rhs, ncols, work);
        };
        let n = self.n();
        assert_eq!(rhs.len(), n * ncols, "solve: rhs length vs n × ncols");
        assert!(
            ncols <= work.ncols,
            "solve: scratch made for {} columns, {ncols} given",
            work.ncols
        );
        let ld = padded(n);
        let x = work.cols.get(ld * ncols);
        let perm = self.symbolic.inner.perm();
        // P b, column by column into the aligned block.
        for (j, col) in x.chunks_exact_mut(ld).enumerate() {
            let b = &rhs[j * n..(j + 1) * n];
            match perm {
                Some(p) => {
                    for (xi, &f) in col.iter_mut().zip(p.arrays().0) {
                        *xi = b[f];
                    }
                }
                None => col[..n].copy_from_slice(b),
            }
        }
        let llt = SupernodalLltRef::new(sn, &self.values);
        let widest = work.tmp.len;
        let tmp = work.tmp.get(widest);
        // Forward, L y = P b in faer's supernode order: the diagonal block's triangular solve,
        // then the rows below it (`pattern`) updated through the product with the block under
        // the diagonal. Each supernode is read once; the columns take turns on it.
        for s in 0..sn.n_supernodes() {
            let node = llt.supernode(s);
            let ls = node.val();
            let size = ls.ncols();
            let (top, bot) = ls.split_at_row(size);
            let (start, pattern) = (node.start(), node.pattern());
            let t = &mut tmp[..pattern.len()];
            for col in x.chunks_exact_mut(ld) {
                let mut x_top =
                    MatMut::from_column_major_slice_mut(&mut col[start..start + size], size, 1);
                solve_lower_triangular_in_place_with_conj(top, Conj::No, x_top.rb_mut(), Par::Seq);
                matmul_with_conj(
                    MatMut::from_column_major_slice_mut(t, pattern.len(), 1),
                    Accum::Replace,
                    bot,
                    Conj::No,
                    x_top.rb(),
                    Conj::No,
                    1.0,
                    Par::Seq,
                );
                for (&i, &v) in pattern.iter().zip(t.iter()) {
                    col[i] -= v;
                }
            }
        }
        // Backward, Lᵀ z = y in reverse order: the rows below the block gathered, their
        // contribution subtracted, then the diagonal block's transposed triangular solve.
        for s in (0..sn.n_supernodes()).rev() {
            let node = llt.supernode(s);
            let ls = node.val();
            let size = ls.ncols();
            let (top, bot) = ls.split_at_row(size);
            let (start, pattern) = (node.start(), node.pattern());
            let t = &mut tmp[..pattern.len()];
            for col in x.chunks_exact_mut(ld) {
                for (v, &i) in t.iter_mut().zip(pattern) {
                    *v = col[i];
                }
                let mut x_top =
                    MatMut::from_column_major_slice_mut(&mut col[start..start + size], size, 1);
                matmul_with_conj(
                    x_top.rb_mut(),
                    Accum::Add,
                    bot.transpose(),
                    Conj::Yes,
                    MatRef::from_column_major_slice(t, pattern.len(), 1),
                    Conj::No,
                    -1.0,
                    Par::Seq,
                );
                solve_upper_triangular_in_place_with_conj(
                    top.transpose(),
                    Conj::Yes,
                    x_top,
                    Par::Seq,
                );
            }
        }
        // x = Pᵀ z.
        for (j, col) in x.chunks_exact(ld).enumerate() {
            let b = &mut rhs[j * n..(j + 1) * n];
            match perm {
                Some(p) => {
                    for (bi, &v) in b.iter_mut().zip(p.arrays().1) {
                        *bi = col[v];
                    }
                }
                None => b.copy_from_slice(&col[..n]),
            }
        }
    }

    /// rhs ← A⁻¹ rhs, allocating nothing.
    ///
    /// # Panics
    /// If `rhs.len() != n`.
    pub fn solve_in_place(&self, rhs: &mut [f64], work: &mut SolveWork) {
        // One column: faer's blocked solve would do the same arithmetic; going through the
        // column-by-column sweep makes a run alone and a lockstep member (issue 24) the same
        // code, not just the same numbers today.
        self.solve_columns_in_place(rhs, 1, work);
    }

    /// Solve for `ncols` right-hand sides stored column-major in `rhs` (n × ncols), in place
    /// (blocked: faster than `ncols` single solves, e.g. for Z = A⁻¹Bᵀ on the contact set).
    ///
    /// # Panics
    /// If `rhs.len() != n · ncols` or `work` was made for fewer columns.
    pub fn solve_many_in_place(&self, rhs: &mut [f64], ncols: usize, work: &mut SolveWork) {
        let n = self.n();
        assert_eq!(rhs.len(), n * ncols, "solve: rhs length vs n × ncols");
        assert!(
            ncols <= work.ncols,
            "solve: scratch made for {} columns, {ncols} given",
            work.ncols
        );
        if ncols == 0 {
            return;
        }
        let x = MatMut::from_column_major_slice_mut(rhs, n, ncols);
        LltRef::new(&self.symbolic.inner, &self.values).solve_in_place_with_conj(
            Conj::No,
            x,
            Par::Seq,
            MemStack::new(&mut work.buf),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dense SPD matrix A = BᵀB + n I with a fixed pseudo-random B (entries in [−1, 1]), mostly
    /// sparse (≈ 30 % kept) so that the pattern is irregular. cond(A) ≲ 10.
    fn spd(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = fastrand::Rng::with_seed(seed);
        let b: Vec<f64> = (0..n * n)
            .map(|_| {
                if rng.f64() < 0.3 {
                    2.0 * rng.f64() - 1.0
                } else {
                    0.0
                }
            })
            .collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| b[k * n + i] * b[k * n + j]).sum::<f64>()
                    + if i == j { n as f64 } else { 0.0 };
            }
        }
        // Symmetrise exactly (the sums above are evaluated in the same order, but be explicit).
        for i in 0..n {
            for j in 0..i {
                a[i * n + j] = a[j * n + i];
            }
        }
        a
    }

    #[test]
    fn solve_matches_dense_reference() {
        let n = 12;
        let a = spd(n, 7);
        let m = SymMatrix::from_dense(n, &a).unwrap();
        let sym = SymbolicCholesky::new(&m.pattern).unwrap();
        let ch = Cholesky::new(&sym, &m).unwrap();
        let mut work = ch.work();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let mut x = b.clone();
        ch.solve_in_place(&mut x, &mut work);
        // Dense reference: nalgebra's Cholesky of the same matrix. Both are backward stable, so
        // they agree to ~cond(A)·n·ε ≈ 10·12·1.1e-16 ≈ 1.3e-14 relative; 1e-13 leaves margin.
        let ad = nalgebra::DMatrix::from_row_slice(n, n, &a);
        let xr = ad
            .clone()
            .cholesky()
            .unwrap()
            .solve(&nalgebra::DVector::from_column_slice(&b));
        let err = (0..n).map(|i| (x[i] - xr[i]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-13 * xr.amax(), "err {err}");
    }

    #[test]
    fn factor_reused_for_many_rhs_and_blocked_solve() {
        let n = 20;
        let a = spd(n, 3);
        let m = SymMatrix::from_dense(n, &a).unwrap();
        let sym = SymbolicCholesky::new(&m.pattern).unwrap();
        let ch = Cholesky::new(&sym, &m).unwrap();
        let mut work = ch.work_for(5);
        let mut rng = fastrand::Rng::with_seed(11);
        let mut y = vec![0.0; n];
        let mut block = vec![0.0; n * 5];
        let mut singles = vec![0.0; n * 5];
        for k in 0..50 {
            let b: Vec<f64> = (0..n).map(|_| rng.f64() - 0.5).collect();
            let mut x = b.clone();
            ch.solve_in_place(&mut x, &mut work);
            m.matvec_into(&x, &mut y);
            // Backward stability: residual ≲ n·ε·‖A‖‖x‖ ≈ 20·1.1e-16·40·1 ≈ 1e-13.
            let res = (0..n).map(|i| (y[i] - b[i]).abs()).fold(0.0, f64::max);
            assert!(res < 1e-12, "rhs {k}: residual {res}");
            if k < 5 {
                block[k * n..(k + 1) * n].copy_from_slice(&b);
                singles[k * n..(k + 1) * n].copy_from_slice(&x);
            }
        }
        // The blocked solve does the same arithmetic per column up to blocking order.
        ch.solve_many_in_place(&mut block, 5, &mut work);
        let d = block
            .iter()
            .zip(&singles)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max);
        assert!(d < 1e-14, "blocked vs single: {d}");
    }

    /// The lockstep groups' contract (issue 24): column j of a k-column
    /// `solve_columns_in_place` is, bit for bit, the solve of that column alone, for both factor
    /// kinds and every k (faer's blocked `solve_many_in_place` is not: its supernodal products
    /// pick GEMM kernels by the number of columns).
    #[test]
    fn column_solves_equal_single_solves_bit_for_bit() {
        use crate::space::fe::BoxMesh;
        use crate::space::fe::test_bars::clamped_step_matrix;
        // A 3D bar big enough for supernodes of several columns (nested dissection).
        let mesh = BoxMesh::new(&[0.5, 0.5, 1.0], &[4, 4, 12]);
        let d = mesh.dim;
        let (dofs, a) = clamped_step_matrix(&mesh, 0.01);
        let p = &a.pattern;
        let n = p.n;
        let mut rng = fastrand::Rng::with_seed(24);
        let b: Vec<f64> = (0..n * 8).map(|_| rng.f64() - 0.5).collect();
        for kind in [FactorKind::Simplicial, FactorKind::Supernodal] {
            let opts = CholeskyOptions {
                ordering: Ordering::Custom(dofs.order_by_nodes(&mesh.nested_dissection(), d)),
                kind,
            };
            let sym = SymbolicCholesky::with_options(p, &opts).unwrap();
            assert_eq!(sym.is_supernodal(), kind == FactorKind::Supernodal);
            let ch = Cholesky::new(&sym, &a).unwrap();
            let mut work = ch.work_for(8);
            let mut singles = b.clone();
            for col in singles.chunks_exact_mut(n) {
                ch.solve_in_place(col, &mut ch.work());
            }
            for cols in [2, 3, 5, 8] {
                let mut x = b[..n * cols].to_vec();
                ch.solve_columns_in_place(&mut x, cols, &mut work);
                let same = x
                    .iter()
                    .zip(&singles)
                    .all(|(u, v)| u.to_bits() == v.to_bits());
                assert!(
                    same,
                    "{kind:?}, {cols} columns differ from the single solves"
                );
            }
            // And the single solve is faer's: the blocked solve of one column agrees to
            // round-off of a backward-stable solve (cond(A) ≲ 10², |x| ≲ 10: 1e-12).
            let mut faer_one = b[..n].to_vec();
            ch.solve_many_in_place(&mut faer_one, 1, &mut work);
            let d = faer_one.iter().zip(&singles).map(|(u, v)| (u - v).abs());
            assert!(d.fold(0.0, f64::max) < 1e-12);
        }
    }

    #[test]
    fn shared_between_threads() {
        fn send_sync<T: Send + Sync>() {}
        send_sync::<SymbolicCholesky>();
        send_sync::<Cholesky>();
        fn send<T: Send>() {}
        send::<SolveWork>();
        let n = 10;
        let m = SymMatrix::from_dense(n, &spd(n, 5)).unwrap();
        let sym = SymbolicCholesky::new(&m.pattern).unwrap();
        let ch = Arc::new(Cholesky::new(&sym, &m).unwrap());
        let res: Vec<f64> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..4)
                .map(|t| {
                    let (ch, m) = (Arc::clone(&ch), &m);
                    s.spawn(move || {
                        let mut w = ch.work();
                        let b: Vec<f64> = (0..n).map(|i| (i + t) as f64).collect();
                        let mut x = b.clone();
                        ch.solve_in_place(&mut x, &mut w);
                        let mut y = vec![0.0; n];
                        m.matvec_into(&x, &mut y);
                        (0..n).map(|i| (y[i] - b[i]).abs()).fold(0.0, f64::max)
                    })
                })
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        // Residual of a backward-stable solve with ‖b‖ ≤ 13, ‖A‖ ≲ 20: ≲ 1e-12.
        assert!(res.iter().all(|&r| r < 1e-12), "{res:?}");
    }

    #[test]
    fn orderings_and_kinds_agree() {
        use crate::space::fe::BoxMesh;
        use crate::space::fe::test_bars::clamped_step_matrix;
        // M + K of a clamped 2D and 3D bar: every (ordering, kind) pair solves the same system.
        for mesh in [
            BoxMesh::new(&[0.5, 1.0], &[5, 9]),
            BoxMesh::new(&[0.5, 0.5, 1.0], &[3, 3, 6]),
        ] {
            let d = mesh.dim;
            let (dofs, a) = clamped_step_matrix(&mesh, 0.01);
            let p = &a.pattern;
            let b: Vec<f64> = (0..p.n).map(|i| ((i * 7 % 13) as f64) - 6.0).collect();
            let nd = dofs.order_by_nodes(&mesh.nested_dissection(), d);
            let mut reference: Option<Vec<f64>> = None;
            for ordering in [Ordering::Amd, Ordering::Custom(nd.clone())] {
                for kind in [
                    FactorKind::Auto,
                    FactorKind::Simplicial,
                    FactorKind::Supernodal,
                ] {
                    let opts = CholeskyOptions {
                        ordering: ordering.clone(),
                        kind,
                    };
                    let sym = SymbolicCholesky::with_options(p, &opts).unwrap();
                    if kind != FactorKind::Auto {
                        assert_eq!(sym.is_supernodal(), kind == FactorKind::Supernodal);
                    }
                    let ch = Cholesky::new(&sym, &a).unwrap();
                    let mut x = b.clone();
                    ch.solve_in_place(&mut x, &mut ch.work());
                    match &reference {
                        None => reference = Some(x),
                        // cond(M + 0.01 K) ≲ 10²: different elimination orders agree to
                        // ≈ cond·ε·|x| ≈ 1e-13 relative; |x| ≈ 10².
                        Some(r) => {
                            let diff = r.iter().zip(&x).map(|(u, v)| (u - v).abs());
                            let scale = r.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                            let err = diff.fold(0.0, f64::max);
                            assert!(err < 1e-12 * scale, "{opts:?}: {err}");
                        }
                    }
                }
            }
        }
        // A custom order that is not a permutation is refused.
        let m = SymMatrix::from_dense(2, &[2.0, 0.0, 0.0, 2.0]).unwrap();
        let bad = CholeskyOptions {
            ordering: Ordering::Custom(vec![0, 0]),
            kind: FactorKind::Auto,
        };
        assert!(matches!(
            SymbolicCholesky::with_options(&m.pattern, &bad),
            Err(LinalgError::BadOrdering(_))
        ));
    }

    #[test]
    fn indefinite_matrix_is_an_error() {
        // Eigenvalues 3 and −1.
        let m = SymMatrix::from_dense(2, &[1.0, 2.0, 2.0, 1.0]).unwrap();
        let sym = SymbolicCholesky::new(&m.pattern).unwrap();
        let e = Cholesky::new(&sym, &m).unwrap_err();
        assert!(matches!(e, LinalgError::NotPositiveDefinite { .. }), "{e}");
        // The reported unknown is the caller's (not the permuted) index: only dof 2 of this
        // diagonal matrix is negative, whatever order AMD picks.
        let dg = SymMatrix::from_dense(
            4,
            &[
                1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, -3.0, 0.0, 0.0, 0.0, 0.0, 4.0,
            ],
        )
        .unwrap();
        assert_eq!(
            Cholesky::new(&SymbolicCholesky::new(&dg.pattern).unwrap(), &dg).unwrap_err(),
            LinalgError::NotPositiveDefinite { dof: 2 }
        );
        // Singular (positive semi-definite) is not positive definite either.
        let z = SymMatrix::from_dense(2, &[1.0, 1.0, 1.0, 1.0]).unwrap();
        assert!(matches!(
            Cholesky::new(&SymbolicCholesky::new(&z.pattern).unwrap(), &z),
            Err(LinalgError::NotPositiveDefinite { .. })
        ));
        // NaN entries are reported with their position.
        let mut nan = SymMatrix::from_dense(2, &[2.0, 0.0, 0.0, 2.0]).unwrap();
        nan.values[1] = f64::NAN;
        let sym = SymbolicCholesky::new(&nan.pattern).unwrap();
        assert_eq!(
            Cholesky::new(&sym, &nan).unwrap_err(),
            LinalgError::NonFinite { row: 1, col: 1 }
        );
        // A matrix of another pattern.
        let other = SymMatrix::from_dense(2, &[2.0, 1.0, 1.0, 2.0]).unwrap();
        assert!(matches!(
            Cholesky::new(&sym, &other),
            Err(LinalgError::PatternMismatch { .. })
        ));
    }
}
