//! The frictional Nitsche/penalty Newton on large active sets, in the space of the contact
//! dofs (contract §2.5, §4; `run::fe::nitsche`'s header has the condensed problem).
//!
//! Why: the condensed frictional problem has d unknowns per contact point (1 944 on the 3D
//! block of 5 187 dofs with its 648 points), and a dense LU of its Newton matrix costs their
//! cube, a sparse LU of the full-space Newton matrix A − cτ² Σ_q C_q D_q P_qᵀ what a
//! non-symmetric factor of the body costs — either, refactored at every Newton iteration, made
//! a frictional step 8–25× the frictionless one. But the points see the body only through
//! W = P A⁻¹ C, and P's and C's rows live on the dofs of the points' elements: the set R of the
//! m contact dofs (m = 546 on that block). So W = P_R S C_R with S = R A⁻¹ Rᵀ (m × m), made
//! once per run from A's factor ([`ContactSchur`], m solves). With D the points' d × d
//! derivative blocks, J = I − cτ² W D = I − U V (U = cτ² P_R S, V = C_R D), and by
//! Woodbury's identity the Newton step J δ = r is
//!   K y = C_R D r,   K = I_m − cτ² B S,   B = Σ_q C_q D_q P_qᵀ,   δ = r + cτ² P_R S y
//! — an m × m system (B: each active point's rank-d block on its element's dofs; an inactive
//! point has D = 0). A product with K costs m² + O(Q d k), not (Q d)². K changes with D at every
//! iteration, but little where the active and slip sets do not change: each step's system is
//! solved by GMRES right-preconditioned with the LU of the last K factored, and K is
//! refactored (its dense LU, (2/3)m³) only where GMRES does not reach [`KRYLOV_TOL`] in
//! [`KRYLOV_MAX`] iterations — then the step is the direct solve with the new factor. The
//! Newton's convergence test is on its own residual, so the solution meets the same tolerance
//! whatever the inner solve's accuracy; an inexact step only costs iterations (measured on the
//! 3D block, benches/fe.rs `block3d-friction`: the same 57 (Nitsche) and 75 (penalty) Newton
//! iterations over its 10 steps as the exact solves, 20 factorisations of K and 574 GMRES
//! iterations for Nitsche's 57; a frictional step 0.96× (Nitsche) and 1.25× (penalty) the
//! frictionless one, from 8–25× with a full-space sparse LU per iteration). All buffers are
//! made at set-up: nothing is allocated per step.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{MatMut, MatRef, Par};

/// GMRES's relative residual ‖K y − b‖ ≤ tol·‖b‖: the Newton step's relative error, well
/// below the Newton's own contraction at its last iterations (≥ 1e4 per iteration measured on
/// the 3D block), so the step counts are the exact solve's.
pub(crate) const KRYLOV_TOL: f64 = 1e-10;
/// GMRES iterations (no restart) before K is refactored.
pub(crate) const KRYLOV_MAX: usize = 16;

/// S = R A⁻¹ Rᵀ over the contact dofs R of one run's points (module header).
#[derive(Debug, Clone)]
pub(crate) struct ContactSchur {
    m: usize,
    /// Per entry of the points' dof lists (point-major, k per point), its index in R.
    loc: Vec<usize>,
    /// S, m × m row-major, and |S| entrywise (the residual's bounds, [`SchurNewton::apply_w`]).
    s: Vec<f64>,
    s_abs: Vec<f64>,
}

impl ContactSchur {
    /// From the points' dof lists `point_dofs` (reduced indices < n) and `solve`, which
    /// overwrites `ncols` columns of length n (column-major) with A⁻¹ of them.
    pub(crate) fn new(
        n: usize,
        point_dofs: &[usize],
        solve: impl FnOnce(&mut [f64], usize) -> Result<(), String>,
    ) -> Result<ContactSchur, String> {
        let mut dofs = point_dofs.to_vec();
        dofs.sort_unstable();
        dofs.dedup();
        let m = dofs.len();
        let loc = point_dofs
            .iter()
            .map(|g| dofs.binary_search(g).expect("every dof is in the set"))
            .collect();
        let mut z = vec![0.0; n * m];
        for (j, &g) in dofs.iter().enumerate() {
            z[j * n + g] = 1.0;
        }
        solve(&mut z, m)?;
        let mut s = vec![0.0; m * m];
        for (i, &gi) in dofs.iter().enumerate() {
            for j in 0..m {
                s[i * m + j] = z[j * n + gi];
            }
        }
        let s_abs = s.iter().map(|x: &f64| x.abs()).collect();
        Ok(ContactSchur { m, loc, s, s_abs })
    }
}

/// One run's Newton steps through K (module header): S, the points' rows of P and C over
/// their dofs, K's last LU and the GMRES scratch.
#[derive(Debug)]
pub(crate) struct SchurNewton {
    schur: ContactSchur,
    /// Dofs per point k and unknowns per point d.
    k: usize,
    d: usize,
    /// Unknown j's row of P and column of C over its point's k dofs (j = q·d + a).
    prow: Vec<f64>,
    crow: Vec<f64>,
    /// K's LU (row-major, m × m) and its row permutation.
    lu: Vec<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    factored: bool,
    mem: FaerScratch,
    /// GMRES: the Krylov basis ((KRYLOV_MAX + 1) × m), the Hessenberg matrix (column-major,
    /// (KRYLOV_MAX + 1) per column), the Givens rotations and the reduced right-hand side.
    basis: Vec<f64>,
    hess: Vec<f64>,
    cs: Vec<f64>,
    sn: Vec<f64>,
    gv: Vec<f64>,
    /// m-vectors: the right-hand side b, y, and two products' scratch; a k × k block of B.
    b: Vec<f64>,
    y: Vec<f64>,
    t1: Vec<f64>,
    t2: Vec<f64>,
    block: Vec<f64>,
    /// One element's rows of S and of B_e S (k × m, [`Self::refactor`]).
    rows: Vec<f64>,
    prod: Vec<f64>,
    /// (W λ)_j and the bound of Σ_r |W_jr λ_r| per unknown ([`Self::apply_w`]).
    pub wl: Vec<f64>,
    pub wabs: Vec<f64>,
    /// Over the run: K's factorisations and the GMRES iterations.
    pub refactors: usize,
    pub krylov: usize,
}

/// faer's scratch for the dense LU and its solves (not `Debug`).
struct FaerScratch(MemBuffer);

impl std::fmt::Debug for FaerScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("FaerScratch")
    }
}

impl SchurNewton {
    /// For `schur`, k dofs and d unknowns per point, and the rows `prow`, `crow` (unknown
    /// j's at j·k..(j + 1)·k).
    pub(crate) fn new(
        schur: ContactSchur,
        k: usize,
        d: usize,
        prow: Vec<f64>,
        crow: Vec<f64>,
    ) -> Result<SchurNewton, String> {
        let m = schur.m;
        let req = StackReq::any_of(&[
            factor::lu_in_place_scratch::<usize, f64>(m, m, Par::Seq, Default::default()),
            solve::solve_in_place_scratch::<usize, f64>(m, 1, Par::Seq),
        ]);
        let mem = MemBuffer::try_new(req).map_err(|_| "contact Newton scratch: out of memory")?;
        let kr = KRYLOV_MAX;
        let nu = prow.len() / k.max(1);
        assert!(d <= 3, "at most 3 unknowns per point");
        Ok(SchurNewton {
            schur,
            k,
            d,
            prow,
            crow,
            lu: vec![0.0; m * m],
            perm: vec![0; m],
            perm_inv: vec![0; m],
            factored: false,
            mem: FaerScratch(mem),
            basis: vec![0.0; (kr + 1) * m],
            hess: vec![0.0; (kr + 1) * kr],
            cs: vec![0.0; kr],
            sn: vec![0.0; kr],
            gv: vec![0.0; kr + 1],
            b: vec![0.0; m],
            y: vec![0.0; m],
            t1: vec![0.0; m],
            t2: vec![0.0; m],
            block: vec![0.0; k * k],
            rows: vec![0.0; k * m],
            prod: vec![0.0; k * m],
            wl: vec![0.0; nu],
            wabs: vec![0.0; nu],
            refactors: 0,
            krylov: 0,
        })
    }

    /// (W λ)_j = p_j · S (Σ_r c_r λ_r) into `wl` over the unknowns `nonzero` of λ (the others
    /// are 0), and into `wabs` the bound |p_j| · |S| (Σ_r |c_r λ_r|) ≥ Σ_r |W_jr λ_r|: the sizes
    /// of the terms W Λ's sum cancels, which the Newton's tolerance allows for (its
    /// `evaluate`), from above. Costs 2m² + O(Q d k), not (Q d)².
    pub(crate) fn apply_w(&mut self, lambda: &[f64], nonzero: &[usize]) {
        let (k, d) = (self.k, self.d);
        self.t1.fill(0.0);
        self.t2.fill(0.0);
        for &r in nonzero {
            let q = r / d;
            let loc = &self.schur.loc[q * k..(q + 1) * k];
            for (&l, &c) in loc.iter().zip(&self.crow[r * k..(r + 1) * k]) {
                let t = c * lambda[r];
                self.t1[l] += t;
                self.t2[l] += t.abs();
            }
        }
        mul_sym(&self.schur.s, &self.t1, &mut self.y);
        mul_sym(&self.schur.s_abs, &self.t2, &mut self.b);
        for (j, (wl, wabs)) in self.wl.iter_mut().zip(&mut self.wabs).enumerate() {
            let q = j / d;
            let loc = &self.schur.loc[q * k..(q + 1) * k];
            let p = &self.prow[j * k..(j + 1) * k];
            (*wl, *wabs) = loc.iter().zip(p).fold((0.0, 0.0), |(a, b), (&l, &pi)| {
                (a + pi * self.y[l], b + pi.abs() * self.b[l])
            });
        }
    }

    /// The Newton step δ = J⁻¹ r into `step` (module header) for the points' `active` flags
    /// and d × d `blocks` (D[b][a] = ∂λ_b/∂x_a at b·d + a) and r = `rhs`.
    pub(crate) fn step(
        &mut self,
        active: &[bool],
        blocks: &[f64],
        rhs: &[f64],
        c_tau2: f64,
        step: &mut [f64],
    ) -> Result<(), String> {
        // b = C_R D r.
        self.b.fill(0.0);
        let (k, d) = (self.k, self.d);
        for q in (0..active.len()).filter(|&q| active[q]) {
            let blk = &blocks[q * d * d..(q + 1) * d * d];
            let loc = &self.schur.loc[q * k..(q + 1) * k];
            for bb in 0..d {
                let e: f64 = (0..d).map(|a| blk[bb * d + a] * rhs[q * d + a]).sum();
                let c = &self.crow[(q * d + bb) * k..(q * d + bb + 1) * k];
                for (&l, &ci) in loc.iter().zip(c) {
                    self.b[l] += ci * e;
                }
            }
        }
        if !(self.factored && self.gmres(active, blocks, c_tau2)) {
            self.refactor(active, blocks, c_tau2)?;
            self.y.copy_from_slice(&self.b);
            self.lu_solve_y();
        }
        // δ = r + cτ² P_R S y.
        mul_sym(&self.schur.s, &self.y, &mut self.t1);
        for (j, out) in step.iter_mut().enumerate() {
            let q = j / d;
            let loc = &self.schur.loc[q * k..(q + 1) * k];
            let p = &self.prow[j * k..(j + 1) * k];
            let ps: f64 = loc.iter().zip(p).map(|(&l, &pi)| pi * self.t1[l]).sum();
            *out = rhs[j] + c_tau2 * ps;
        }
        Ok(())
    }

    /// Basis vector `v` ← K_old⁻¹ of it in place (K_old the last factored).
    fn precond(&mut self, v: usize) {
        let m = self.schur.m;
        let lu = MatRef::from_row_major_slice(&self.lu, m, m);
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, m);
        let rhs = MatMut::from_column_major_slice_mut(&mut self.basis[v * m..(v + 1) * m], m, 1);
        solve::solve_in_place(lu, lu, perm, rhs, Par::Seq, MemStack::new(&mut self.mem.0));
    }

    /// y ← K⁻¹ y with the last factor.
    fn lu_solve_y(&mut self) {
        let m = self.schur.m;
        let lu = MatRef::from_row_major_slice(&self.lu, m, m);
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, m);
        let rhs = MatMut::from_column_major_slice_mut(&mut self.y, m, 1);
        solve::solve_in_place(lu, lu, perm, rhs, Par::Seq, MemStack::new(&mut self.mem.0));
    }

    /// Right-preconditioned GMRES for K y = b from y = 0; whether it reached [`KRYLOV_TOL`].
    fn gmres(&mut self, active: &[bool], blocks: &[f64], c_tau2: f64) -> bool {
        let m = self.schur.m;
        let kr = KRYLOV_MAX;
        let beta = norm(&self.b);
        if beta == 0.0 {
            self.y.fill(0.0);
            return true;
        }
        for (v, b) in self.basis[..m].iter_mut().zip(&self.b) {
            *v = b / beta;
        }
        self.gv.fill(0.0);
        self.gv[0] = beta;
        for j in 0..kr {
            self.krylov += 1;
            // w = K K_old⁻¹ v_j, made in slot j + 1.
            let (head, tail) = self.basis.split_at_mut((j + 1) * m);
            tail[..m].copy_from_slice(&head[j * m..]);
            self.precond(j + 1);
            self.k_mul_in_place(active, blocks, c_tau2, j + 1);
            // Modified Gram–Schmidt.
            let h = &mut self.hess[j * (kr + 1)..(j + 1) * (kr + 1)];
            let (head, tail) = self.basis.split_at_mut((j + 1) * m);
            let w = &mut tail[..m];
            for (i, hi) in h.iter_mut().enumerate().take(j + 1) {
                let vi = &head[i * m..(i + 1) * m];
                let h = dot(vi, w);
                *hi = h;
                for (wx, vx) in w.iter_mut().zip(vi) {
                    *wx -= h * vx;
                }
            }
            let hn = norm(w);
            h[j + 1] = hn;
            if hn > 0.0 {
                w.iter_mut().for_each(|x| *x /= hn);
            }
            // The previous rotations, then the one zeroing h[j + 1].
            for (i, (&c, &sn)) in self.cs.iter().zip(&self.sn).enumerate().take(j) {
                let (a, b) = (h[i], h[i + 1]);
                h[i] = c * a + sn * b;
                h[i + 1] = -sn * a + c * b;
            }
            let r = h[j].hypot(h[j + 1]);
            if r == 0.0 {
                return false;
            }
            (self.cs[j], self.sn[j]) = (h[j] / r, h[j + 1] / r);
            h[j] = r;
            h[j + 1] = 0.0;
            self.gv[j + 1] = -self.sn[j] * self.gv[j];
            self.gv[j] *= self.cs[j];
            if self.gv[j + 1].abs() <= KRYLOV_TOL * beta || hn == 0.0 {
                self.finish(j + 1);
                return true;
            }
        }
        false
    }

    /// Basis slot `v` ← K of it: v − cτ² B S v (S v in the scratch t2).
    fn k_mul_in_place(&mut self, active: &[bool], blocks: &[f64], c_tau2: f64, v: usize) {
        let m = self.schur.m;
        // K v = v − cτ² B S v, written back into slot v.
        mul_sym(&self.schur.s, &self.basis[v * m..(v + 1) * m], &mut self.t2);
        let (k, d) = (self.k, self.d);
        let dst = &mut self.basis[v * m..(v + 1) * m];
        for q in (0..active.len()).filter(|&q| active[q]) {
            let blk = &blocks[q * d * d..(q + 1) * d * d];
            let loc = &self.schur.loc[q * k..(q + 1) * k];
            let mut t = [0.0; 3];
            for (a, ta) in t.iter_mut().enumerate().take(d) {
                let p = &self.prow[(q * d + a) * k..(q * d + a + 1) * k];
                *ta = loc.iter().zip(p).map(|(&l, &pi)| pi * self.t2[l]).sum();
            }
            for bb in 0..d {
                let e: f64 = (0..d).map(|a| blk[bb * d + a] * t[a]).sum::<f64>() * c_tau2;
                let c = &self.crow[(q * d + bb) * k..(q * d + bb + 1) * k];
                for (&l, &ci) in loc.iter().zip(c) {
                    dst[l] -= ci * e;
                }
            }
        }
    }

    /// y = K_old⁻¹ Σ_{i<n} v_i t_i with H t = g (the first n rows, upper triangular).
    fn finish(&mut self, n: usize) {
        let (m, kr) = (self.schur.m, KRYLOV_MAX);
        for i in (0..n).rev() {
            let acc: f64 = (i + 1..n)
                .map(|j| self.hess[j * (kr + 1) + i] * self.gv[j])
                .sum();
            self.gv[i] = (self.gv[i] - acc) / self.hess[i * (kr + 1) + i];
        }
        self.y.fill(0.0);
        for (&t, v) in self.gv[..n].iter().zip(self.basis.chunks_exact(m)) {
            for (y, vx) in self.y.iter_mut().zip(v) {
                *y += t * vx;
            }
        }
        self.lu_solve_y();
    }

    /// K = I − cτ² B S at the current D, factored (module header). Points with the same dof
    /// list (one element's) add their blocks into one k × k block of B first.
    fn refactor(&mut self, active: &[bool], blocks: &[f64], c_tau2: f64) -> Result<(), String> {
        self.factored = false;
        self.refactors += 1;
        let (m, k, d) = (self.schur.m, self.k, self.d);
        self.lu.fill(0.0);
        for i in 0..m {
            self.lu[i * m + i] = 1.0;
        }
        let nq = active.len();
        let mut q = 0;
        while q < nq {
            let loc = &self.schur.loc[q * k..(q + 1) * k];
            let mut end = q + 1;
            while end < nq && self.schur.loc[end * k..(end + 1) * k] == *loc {
                end += 1;
            }
            // B_e = Σ_{q ∈ e} C_q D_q P_qᵀ over the element's k dofs.
            self.block.fill(0.0);
            for p in (q..end).filter(|&p| active[p]) {
                let blk = &blocks[p * d * d..(p + 1) * d * d];
                for bb in 0..d {
                    let c = &self.crow[(p * d + bb) * k..(p * d + bb + 1) * k];
                    for a in 0..d {
                        let dba = blk[bb * d + a];
                        if dba == 0.0 {
                            continue;
                        }
                        let pr = &self.prow[(p * d + a) * k..(p * d + a + 1) * k];
                        for (i, &ci) in c.iter().enumerate() {
                            let f = ci * dba;
                            for (bl, &pl) in self.block[i * k..(i + 1) * k].iter_mut().zip(pr) {
                                *bl += f * pl;
                            }
                        }
                    }
                }
            }
            // K[loc_i, :] −= cτ² Σ_l B_e[i][l] S[loc_l, :]: the element's rows of S gathered,
            // one product (k × k)(k × m), scattered.
            for (l, &ll) in loc.iter().enumerate() {
                self.rows[l * m..(l + 1) * m].copy_from_slice(&self.schur.s[ll * m..(ll + 1) * m]);
            }
            faer::linalg::matmul::matmul(
                MatMut::from_row_major_slice_mut(&mut self.prod, k, m),
                faer::Accum::Replace,
                MatRef::from_row_major_slice(&self.block, k, k),
                MatRef::from_row_major_slice(&self.rows, k, m),
                c_tau2,
                Par::Seq,
            );
            for (i, &li) in loc.iter().enumerate() {
                let krow = &mut self.lu[li * m..(li + 1) * m];
                for (kx, px) in krow.iter_mut().zip(&self.prod[i * m..(i + 1) * m]) {
                    *kx -= px;
                }
            }
            q = end;
        }
        let lu = MatMut::from_row_major_slice_mut(&mut self.lu, m, m);
        factor::lu_in_place(
            lu,
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem.0),
            Default::default(),
        );
        for i in 0..m {
            let u = self.lu[i * m + i];
            if !(u != 0.0 && u.is_finite()) {
                return Err(format!("singular Jacobian at contact dof {i}"));
            }
        }
        self.factored = true;
        Ok(())
    }
}

/// out = S v for the m × m row-major S (faer's product: SIMD, where a plain loop's sum is a
/// chain of dependent additions).
fn mul_sym(s: &[f64], v: &[f64], out: &mut [f64]) {
    let m = v.len();
    faer::linalg::matmul::matmul(
        MatMut::from_column_major_slice_mut(out, m, 1),
        faer::Accum::Replace,
        MatRef::from_row_major_slice(s, m, m),
        MatRef::from_column_major_slice(v, m, 1),
        1.0,
        Par::Seq,
    );
}

/// Σ a_i b_i over four partial sums (vectorised).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for ((a, xi), yi) in acc.iter_mut().zip(x).zip(y) {
            *a += xi * yi;
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

fn norm(v: &[f64]) -> f64 {
    dot(v, v).sqrt()
}
