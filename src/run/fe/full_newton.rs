//! The step's Newton matrix on the full system for Nitsche's points and the penalty's rows
//! between two bodies (contract §2.6, §4, §1.10; issue 45): the solve that holds a body held by
//! contact alone.
//!
//! The step reads R(u) = b − A u + cτ² Σ_q φ_q(p_q·u) c_q = 0 with A = M + cτ²(K − Θ Σ_q w_q γ_q
//! s_q s_qᵀ) and φ_q(s) = (w_q/γ_q)[s − g_q]_+ (`run::fe::nitsche`'s header; the penalty: Θ = 0,
//! c_q = −p_q, 1/γ_q = κ_q). Its generalised Jacobian on the active points I (s_q > g_q) is
//!   J = A − cτ² Σ_I (w_q/γ_q) c_q p_qᵀ,
//! sparse: each point adds a k × k block on its own dofs. Why not the condensed form: at a step
//! τ far above the periods of a body held by contact alone (the patch test: one backward-Euler
//! step of τ = 1e6), A's rigid modes carry only M/τ² ≈ 1e-12 of K, so Z = A⁻¹C and W = P Z
//! lose about 12 digits, and the condensed Newton on W either stalls (Nitsche at γ0 = 1e-3:
//! residual 1e9–1e15 against 1e10 after 100 iterations) or empties its active set (the penalty
//! at γ0 ≥ 30). J itself is well conditioned there — the contact blocks hold exactly the rigid
//! modes A lacks — so its LU gives the step to round-off.
//!
//! J's pattern is A's (M's and K's) joined with every point's dof block, fixed when the solver
//! is first needed; its fill-reducing ordering and symbolic LU (faer, COLAMD) are made then,
//! once per run, and each Newton iteration refactors the values only, into the same buffers:
//! after the first factorisation nothing is allocated. Non-symmetric (Nitsche's c_q ≠ −p_q for
//! Θ ≠ 1), hence LU with partial pivoting rather than the step's Cholesky.
//!
//! Where it runs: a step the condensed Newton and its refinement (`run::fe::refine`) leave above
//! the refinement's tolerance — and every step of a run with at least [`FULL_MIN_POINTS`]
//! points ([`full_only`]), which then makes neither Z (n × Q) nor W (Q × Q): on a general
//! interface W is dense over all points (blocks3d, 6 against 8 cubes across: Q ≈ 3·10³,
//! minutes per run; 12 against 16: Q ≈ 1.3·10⁴, 1.4 GB for W alone), while J's LU costs what
//! the step's own factor does.

use std::collections::HashSet;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

use super::config::FeConfig;
use super::nitsche::NitscheOps;
use crate::space::fe::SymMatrix;
use crate::time::Scheme;

/// From this many points on, a two-body run's Nitsche/penalty steps are solved on the full
/// system only (module header): W's Q² entries (8 MB at 1024) and Z's n·Q outgrow J's LU.
pub(super) const FULL_MIN_POINTS: usize = 1024;

/// Whether a run's contact steps take the full-system Newton at all (`two_bodies`,
/// frictionless, a Newmark/θ scheme: the runs the refinement finishes, `run::fe::refine`).
pub(super) fn full_capable(two_bodies: bool, cfg: &FeConfig, ops: &NitscheOps) -> bool {
    two_bodies && ops.friction.is_none() && !matches!(cfg.scheme, Scheme::Hybrid)
}

/// Whether a run solves its contact steps on the full system only, without Z and W (module
/// header).
pub(super) fn full_only(two_bodies: bool, cfg: &FeConfig, ops: &NitscheOps) -> bool {
    full_capable(two_bodies, cfg, ops) && ops.len() >= FULL_MIN_POINTS
}

/// J's structure and factor over one run (module header).
pub(super) struct FullNewton {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// A's values on J's pattern (M + cτ²K − cτ²Θ Σ w γ s sᵀ: constant over the run), and the
    /// values of the iteration's J.
    base: Vec<f64>,
    values: Vec<f64>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    mem: MemBuffer,
    /// Factorisations over the run.
    pub(super) factorizations: usize,
}

impl std::fmt::Debug for FullNewton {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FullNewton")
            .field("n", &self.n)
            .field("nnz", &self.row_idx.len())
            .field("factorizations", &self.factorizations)
            .finish_non_exhaustive()
    }
}

impl FullNewton {
    /// J's pattern over n dofs from A's parts `m`, `k` (M, K) and the points of `ops`, A's
    /// values at the step's cτ², and the symbolic LU.
    pub(super) fn new(
        m: &SymMatrix,
        k: &SymMatrix,
        ops: &NitscheOps,
        c_tau2: f64,
    ) -> Result<FullNewton, String> {
        let n = m.n();
        let mut cols: Vec<Vec<usize>> = (0..n)
            .map(|j| {
                let mut c = m.pattern.col(j).to_vec();
                c.extend_from_slice(k.pattern.col(j));
                c
            })
            .collect();
        // Points on the same pair of elements share their dof list: one block each.
        let kk = ops.k;
        let lists: HashSet<&[usize]> = (0..ops.len())
            .map(|q| &ops.dofs[q * kk..(q + 1) * kk])
            .collect();
        for dofs in lists {
            for &b in dofs {
                cols[b].extend_from_slice(dofs);
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        drop(cols);
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_lu(sym, Default::default())
            .map_err(|e| format!("full-system Newton: symbolic LU: {e:?}"))?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        let mem = MemBuffer::try_new(req).map_err(|_| "full-system Newton: out of memory")?;
        let nnz = row_idx.len();
        let mut full = FullNewton {
            n,
            col_ptr,
            row_idx,
            base: vec![0.0; nnz],
            values: vec![0.0; nnz],
            symbolic,
            numeric: NumericLu::new(),
            mem,
            factorizations: 0,
        };
        for (mat, f) in [(m, 1.0), (k, c_tau2)] {
            let p = &*mat.pattern;
            for j in 0..n {
                for (e, &i) in (p.col_ptr[j]..p.col_ptr[j + 1]).zip(p.col(j)) {
                    let at = full.position(i, j);
                    full.base[at] += f * mat.values[e];
                }
            }
        }
        if ops.theta != 0.0 {
            let mut base = std::mem::take(&mut full.base);
            for q in 0..ops.len() {
                let f = -c_tau2 * ops.theta * ops.w[q] * ops.gamma[q];
                full.add_block(&mut base, ops, q, f, &ops.s, &ops.s);
            }
            full.base = base;
        }
        Ok(full)
    }

    /// The index of entry (i, j) in J's values (always present: the pattern holds it).
    fn position(&self, i: usize, j: usize) -> usize {
        let (s, e) = (self.col_ptr[j], self.col_ptr[j + 1]);
        s + self.row_idx[s..e]
            .binary_search(&i)
            .expect("the entry is in J's pattern")
    }

    /// values += f · left_q right_qᵀ over point q's dofs (rows `left`, columns `right`).
    fn add_block(
        &self,
        values: &mut [f64],
        ops: &NitscheOps,
        q: usize,
        f: f64,
        left: &[f64],
        right: &[f64],
    ) {
        let k = ops.k;
        let dofs = &ops.dofs[q * k..(q + 1) * k];
        let (l, r) = (&left[q * k..(q + 1) * k], &right[q * k..(q + 1) * k]);
        for (b, &j) in dofs.iter().enumerate() {
            if r[b] == 0.0 {
                continue;
            }
            for (a, &i) in dofs.iter().enumerate() {
                values[self.position(i, j)] += f * l[a] * r[b];
            }
        }
    }

    /// J on the points `active` (module header), factored; then `r` ← J⁻¹ r.
    pub(super) fn solve(
        &mut self,
        ops: &NitscheOps,
        c_tau2: f64,
        active: &[usize],
        r: &mut [f64],
    ) -> Result<(), String> {
        let mut values = std::mem::take(&mut self.values);
        values.copy_from_slice(&self.base);
        for &q in active {
            let f = -c_tau2 * ops.w[q] / ops.gamma[q];
            self.add_block(&mut values, ops, q, f, &ops.c, &ops.p);
        }
        self.values = values;
        let n = self.n;
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let a = SparseColMatRef::new(sym, &self.values);
        let stack = MemStack::new(&mut self.mem);
        let lu = self
            .symbolic
            .factorize_numeric_lu(&mut self.numeric, a, Par::Seq, stack, Default::default())
            .map_err(|e| format!("full-system Newton: LU: {e:?}"))?;
        self.factorizations += 1;
        let stack = MemStack::new(&mut self.mem);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(r, n, 1),
            Par::Seq,
            stack,
        );
        if r.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err("full-system Newton: the Newton matrix is singular".into())
        }
    }
}
