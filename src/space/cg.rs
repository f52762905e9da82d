//! Jacobi-preconditioned conjugate gradient for the step matrices of the 2D/3D scenes
//! (`solver = "cg"`, contract §4): A = M + cτ²K (and the Nitsche variant M + cτ²(K − Θ·γ-term)),
//! solved without a factor — the memory of a run is the matrices and a few vectors, never the
//! fill of a Cholesky factor (nnz(L) ≈ 12.5·n^{4/3} in 3D: 4 GiB at n = 3·10⁵).
//!
//! Why CG converges fast here. With D = diag(A), CG on A with the preconditioner D⁻¹ converges
//! like CG on the scaled matrix Â = D^{-½} A D^{-½}: after k iterations the A-norm error is at
//! most 2((√κ − 1)/(√κ + 1))^k of the initial one, κ = κ(Â). The step matrix is a mass matrix
//! plus a *small* multiple of the stiffness: cτ²‖K‖/‖M‖ ~ c(c0 τ/h)² = cν², so at a fixed
//! Courant number ν the spectrum of Â does not depend on h — the mass alone gives κ ≤ 3, 9, 27
//! for Q1 in 1D, 2D, 3D (eigenvalues of D_M⁻¹M in [½, 3/2]^d), and the stiffness term fills in the
//! low end. Measured on the bars at ν ≈ 1.1 (issue 24): κ(Â) ≈ 2.6 in 2D, 5.5 in 3D, so the
//! contraction per iteration is ≈ 0.23 and 0.40, and a relative residual of 1e-12 takes about
//! 20 and 30 iterations on every mesh — each one sparse matrix–vector product, streaming A once.
//! (A direct solve streams the factor twice: 4× the entries of A on the 3D bar at 19 440 dofs,
//! ≈ 10× at 3·10⁵ by the n^{4/3} fill — which is why a factor still wins in time where it fits,
//! docs/performance.md.) Larger Courant numbers
//! raise κ like cν² (iterations like √c·ν).
//!
//! Stopping test: ‖r‖_{D⁻¹} ≤ tol·‖b‖_{D⁻¹}, with ‖r‖²_{D⁻¹} = rᵀD⁻¹r (computed anyway, it is
//! rᵀz). This norm is invariant under the diagonal scaling, so the rows of a massless contact
//! layer (rows of cτ²K, whose size differs from the mass rows') weigh like every other row. In
//! the scaled variables it is the relative residual of Âx̂ = b̂, so the relative error of x̂ is
//! at most κ·tol: with tol = 1e-12 the solution agrees with a direct solve to ≈ 1e-11. The
//! residual tested is the recursively updated one, which keeps shrinking below round-off while
//! the true residual b − Ax stagnates near ε·‖A‖‖x‖: tolerances below ≈ 1e-15 cost iterations
//! without adding accuracy (and are never reported as unreachable).
//!
//! Warm start: the caller passes an initial guess in `x` (the time loop, the previous step's
//! solution, which differs from the new one by O(τ)); only the initial residual b − Ax₀ costs a
//! product more. A zero right-hand side gives x = 0 without iterating.
//!
//! Several right-hand sides (the condensation columns Z = A⁻¹Bᵀ of the setup) are solved
//! [`BLOCK`] at a time, interleaved (row i of the block holds the [`BLOCK`] columns' entries
//! side by side): one pass over A serves all of them — each stored entry is read once and
//! applied to [`BLOCK`] contiguous values — with each column's own α, β and stopping test.
//!
//! Everything is allocation-free after the workspace ([`CgWork`], [`CgBlockWork`]) is made: the
//! `*_into` kernels only write into caller-owned slices. A curvature pᵀAp ≤ 0 (the matrix is not
//! positive definite — the direct solver's failed factorisation) and a residual that does not
//! reach the tolerance in `max_iter` iterations are [`CgError`]s, never a panic.

use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Accum, MatMut, MatRef, Par};

use super::fe::SymMatrix;

/// Right-hand sides solved together by [`pcg_many_into`] (8 doubles: one 64-byte cache line
/// per row of the block).
pub const BLOCK: usize = 8;

/// Failures of the iteration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CgError {
    /// A diagonal entry ≤ 0 or not finite: A is not positive definite, Jacobi is undefined.
    #[error("conjugate gradient: diagonal entry {dof} of the step matrix is {value:e}, not > 0")]
    BadDiagonal { dof: usize, value: f64 },
    /// pᵀAp ≤ 0 (or NaN): A is not positive definite along the search direction.
    #[error(
        "conjugate gradient: curvature pᵀAp = {curvature:e} ≤ 0 at iteration {iteration}: the step matrix is not positive definite"
    )]
    NotPositiveDefinite { iteration: usize, curvature: f64 },
    /// The relative residual stayed above the tolerance.
    #[error(
        "conjugate gradient: relative residual {residual:e} after {iterations} iterations, above cg_tol = {tol:e}"
    )]
    NotConverged {
        iterations: usize,
        residual: f64,
        tol: f64,
    },
    /// The right-hand side or the initial guess holds a NaN or an infinity.
    #[error("conjugate gradient: the right-hand side or the initial guess is not finite")]
    NonFinite,
}

/// Tolerance and iteration cap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CgOptions {
    /// Relative residual in the D⁻¹ norm (module header).
    pub tol: f64,
    pub max_iter: usize,
}

/// The default iteration cap: 100 times what κ ≈ 5.5 needs for 1e-12 (≈ 30), so it is reached
/// only by a matrix far outside the step matrices' range (a Courant number in the hundreds).
pub const MAX_ITER: usize = 3000;

impl CgOptions {
    pub fn new(tol: f64) -> CgOptions {
        CgOptions {
            tol,
            max_iter: MAX_ITER,
        }
    }
}

/// The Jacobi preconditioner: 1/diag(A).
pub fn jacobi(a: &SymMatrix) -> Result<Vec<f64>, CgError> {
    a.diagonal()
        .into_iter()
        .enumerate()
        .map(|(dof, d)| {
            if d.is_finite() && d > 0.0 {
                Ok(1.0 / d)
            } else {
                Err(CgError::BadDiagonal { dof, value: d })
            }
        })
        .collect()
}

/// Scratch of one right-hand side: residual r, preconditioned residual z, direction p, Ap.
#[derive(Debug, Clone)]
pub struct CgWork {
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
}

impl CgWork {
    pub fn new(n: usize) -> CgWork {
        CgWork {
            r: vec![0.0; n],
            z: vec![0.0; n],
            p: vec![0.0; n],
            q: vec![0.0; n],
        }
    }
}

/// y = A x by faer's sparse × dense product over the full symmetric storage. Measured against
/// [`SymMatrix::matvec_into`] (a row gather, `cargo bench --bench fe -- matvec`): 1.26 against
/// 1.56 ms on the 3D bar at h = 0.0125 (19 440 dofs), 2.06 against 2.42 ms on the 2D bar at
/// h = 0.05/32 (83 200 dofs). The view is made (and its structure checked, one pass over the
/// indices) once per solve, not per product.
fn product(view: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64]) {
    let n = x.len();
    sparse_dense_matmul(
        MatMut::from_column_major_slice_mut(y, n, 1),
        Accum::Replace,
        view,
        MatRef::from_column_major_slice(x, n, 1),
        1.0,
        Par::Seq,
    );
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solve A x = b by Jacobi-preconditioned CG from the initial guess in `x`; returns the number
/// of iterations (matrix–vector products after the initial residual). Allocates nothing.
///
/// # Panics
/// If a length differs from A's order.
pub fn pcg_into(
    a: &SymMatrix,
    inv_diag: &[f64],
    b: &[f64],
    x: &mut [f64],
    opts: CgOptions,
    work: &mut CgWork,
) -> Result<usize, CgError> {
    let n = a.pattern.n;
    assert!(
        b.len() == n && x.len() == n && inv_diag.len() == n && work.r.len() == n,
        "pcg_into: lengths vs n = {n}"
    );
    let CgWork { r, z, p, q } = work;
    // ‖b‖²_{D⁻¹}: the scale of the stopping test.
    let bb: f64 = b.iter().zip(inv_diag).map(|(v, d)| v * v * d).sum();
    if !bb.is_finite() || x.iter().any(|v| !v.is_finite()) {
        return Err(CgError::NonFinite);
    }
    if bb == 0.0 {
        x.fill(0.0);
        return Ok(0);
    }
    let target = opts.tol * opts.tol * bb;
    let pat = &*a.pattern;
    let view = SparseColMatRef::new(
        SymbolicSparseColMatRef::new_checked(n, n, &pat.col_ptr, None, &pat.row_idx),
        &a.values,
    );
    product(view, x, q);
    for i in 0..n {
        r[i] = b[i] - q[i];
        z[i] = inv_diag[i] * r[i];
    }
    p.copy_from_slice(z);
    let mut rz = dot(r, z);
    let mut it = 0;
    while rz > target {
        if it == opts.max_iter {
            return Err(CgError::NotConverged {
                iterations: it,
                residual: (rz / bb).sqrt(),
                tol: opts.tol,
            });
        }
        product(view, p, q);
        let pq = dot(p, q);
        // Not `pq > 0` (NaN included).
        if pq.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(CgError::NotPositiveDefinite {
                iteration: it,
                curvature: pq,
            });
        }
        let alpha = rz / pq;
        let mut rz_new = 0.0;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            z[i] = inv_diag[i] * r[i];
            rz_new += r[i] * z[i];
        }
        let beta = rz_new / rz;
        for (pi, zi) in p.iter_mut().zip(z.iter()) {
            *pi = zi + beta * *pi;
        }
        rz = rz_new;
        it += 1;
    }
    Ok(it)
}

/// Scratch of [`BLOCK`] right-hand sides, interleaved (n × [`BLOCK`], row-major).
#[derive(Debug, Clone)]
pub struct CgBlockWork {
    x: Vec<f64>,
    r: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
}

impl CgBlockWork {
    pub fn new(n: usize) -> CgBlockWork {
        let v = || vec![0.0; n * BLOCK];
        CgBlockWork {
            x: v(),
            r: v(),
            p: v(),
            q: v(),
        }
    }
}

/// Q = A P for [`BLOCK`] interleaved columns: each stored entry of A read once.
fn matvec_block(a: &SymMatrix, p: &[f64], q: &mut [f64]) {
    let pat = &*a.pattern;
    for (j, qj) in q.chunks_exact_mut(BLOCK).enumerate() {
        let mut acc = [0.0; BLOCK];
        let (s, e) = (pat.col_ptr[j], pat.col_ptr[j + 1]);
        for (&i, &v) in pat.row_idx[s..e].iter().zip(&a.values[s..e]) {
            let pi = &p[i * BLOCK..(i + 1) * BLOCK];
            for c in 0..BLOCK {
                acc[c] += v * pi[c];
            }
        }
        qj.copy_from_slice(&acc);
    }
}

/// Solve A X = B for `ncols` right-hand sides stored column-major in `bx` (n × ncols), in
/// place, from a zero initial guess; [`BLOCK`] columns share each pass over A. Returns the
/// largest iteration count of a column. Allocates nothing.
///
/// # Panics
/// If `bx.len() != n · ncols` or the workspace was made for another n.
pub fn pcg_many_into(
    a: &SymMatrix,
    inv_diag: &[f64],
    bx: &mut [f64],
    ncols: usize,
    opts: CgOptions,
    work: &mut CgBlockWork,
) -> Result<usize, CgError> {
    let n = a.pattern.n;
    assert!(
        bx.len() == n * ncols && work.x.len() == n * BLOCK && inv_diag.len() == n,
        "pcg_many_into: lengths vs n = {n}, {ncols} columns"
    );
    let CgBlockWork { x, r, p, q } = work;
    let mut most = 0;
    for first in (0..ncols).step_by(BLOCK) {
        let cols = BLOCK.min(ncols - first);
        // Load the block: x = 0, r = b (unused lanes: b = 0, done from the start).
        x.fill(0.0);
        r.fill(0.0);
        for c in 0..cols {
            let col = &bx[(first + c) * n..(first + c + 1) * n];
            for (i, &v) in col.iter().enumerate() {
                r[i * BLOCK + c] = v;
            }
        }
        let mut bb = [0.0; BLOCK];
        let mut rz = [0.0; BLOCK];
        for i in 0..n {
            let d = inv_diag[i];
            for c in 0..BLOCK {
                let v = r[i * BLOCK + c];
                p[i * BLOCK + c] = d * v;
                rz[c] += v * d * v;
            }
        }
        bb.copy_from_slice(&rz);
        if bb.iter().any(|v| !v.is_finite()) {
            return Err(CgError::NonFinite);
        }
        let target: [f64; BLOCK] = std::array::from_fn(|c| opts.tol * opts.tol * bb[c]);
        let mut active: [bool; BLOCK] = std::array::from_fn(|c| rz[c] > target[c]);
        let mut it = 0;
        while active.iter().any(|&a| a) {
            if it == opts.max_iter {
                let c = (0..BLOCK).find(|&c| active[c]).unwrap_or(0);
                return Err(CgError::NotConverged {
                    iterations: it,
                    residual: (rz[c] / bb[c]).sqrt(),
                    tol: opts.tol,
                });
            }
            matvec_block(a, p, q);
            let mut pq = [0.0; BLOCK];
            for (pi, qi) in p.chunks_exact(BLOCK).zip(q.chunks_exact(BLOCK)) {
                for c in 0..BLOCK {
                    pq[c] += pi[c] * qi[c];
                }
            }
            // A converged (or unused) lane takes α = 0 and β = 0 and stays where it is.
            let mut alpha = [0.0; BLOCK];
            for c in 0..BLOCK {
                if active[c] {
                    if pq[c].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                        return Err(CgError::NotPositiveDefinite {
                            iteration: it,
                            curvature: pq[c],
                        });
                    }
                    alpha[c] = rz[c] / pq[c];
                }
            }
            let mut rz_new = [0.0; BLOCK];
            for i in 0..n {
                let d = inv_diag[i];
                let k = i * BLOCK;
                for c in 0..BLOCK {
                    x[k + c] += alpha[c] * p[k + c];
                    r[k + c] -= alpha[c] * q[k + c];
                    rz_new[c] += r[k + c] * d * r[k + c];
                }
            }
            let beta: [f64; BLOCK] =
                std::array::from_fn(|c| if active[c] { rz_new[c] / rz[c] } else { 0.0 });
            for i in 0..n {
                let d = inv_diag[i];
                let k = i * BLOCK;
                for c in 0..BLOCK {
                    if active[c] {
                        p[k + c] = d * r[k + c] + beta[c] * p[k + c];
                    }
                }
            }
            for c in 0..BLOCK {
                if active[c] {
                    rz[c] = rz_new[c];
                    active[c] = rz[c] > target[c];
                }
            }
            it += 1;
        }
        most = most.max(it);
        for c in 0..cols {
            let col = &mut bx[(first + c) * n..(first + c + 1) * n];
            for (i, v) in col.iter_mut().enumerate() {
                *v = x[i * BLOCK + c];
            }
        }
    }
    Ok(most)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::fe::BoxMesh;
    use crate::space::fe::test_bars::clamped_step_matrix;
    use crate::space::linalg::{Cholesky, SymbolicCholesky};

    /// M + cτ²K of a clamped Q1 bar (the engine's step matrix at Courant `nu`, c = ¼).
    fn step_matrix(cells: &[usize], nu: f64) -> SymMatrix {
        let mesh = BoxMesh::new(
            &cells.iter().map(|&c| c as f64 * 0.1).collect::<Vec<_>>(),
            cells,
        );
        // h = 0.1, c0 = √1.25: τ = ν h / c0.
        let tau = nu * 0.1 / 1.25f64.sqrt();
        clamped_step_matrix(&mesh, 0.25 * tau * tau).1
    }

    fn direct(a: &SymMatrix, b: &[f64]) -> Vec<f64> {
        let ch = Cholesky::new(&SymbolicCholesky::new(&a.pattern).unwrap(), a).unwrap();
        let mut x = b.to_vec();
        ch.solve_in_place(&mut x, &mut ch.work());
        x
    }

    fn rel_diff(x: &[f64], y: &[f64]) -> f64 {
        let d = x.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum::<f64>();
        (d / y.iter().map(|b| b * b).sum::<f64>()).sqrt()
    }

    #[test]
    fn agrees_with_cholesky_in_few_iterations() {
        for (cells, most) in [(vec![4, 30], 30), (vec![3, 3, 20], 45)] {
            let a = step_matrix(&cells, 1.1);
            let n = a.pattern.n;
            let b: Vec<f64> = (0..n).map(|i| ((i * 7 % 13) as f64) - 6.0).collect();
            let inv = jacobi(&a).unwrap();
            let mut x = vec![0.0; n];
            let it = pcg_into(
                &a,
                &inv,
                &b,
                &mut x,
                CgOptions::new(1e-12),
                &mut CgWork::new(n),
            )
            .unwrap();
            // κ(Â) ≤ 6 at ν = 1.1 (module header): ≤ 31 iterations to 1e-12 in 3D, 19 in
            // 2D by the bound; the caps leave room for the bound's factor 2 and round-off.
            assert!(it > 3 && it <= most, "{cells:?}: {it} iterations");
            // Relative error ≤ κ·tol ≈ 6e-12; Cholesky's own ≈ 1e-15.
            let e = rel_diff(&x, &direct(&a, &b));
            assert!(e < 1e-10, "{cells:?}: {e}");
            // Warm start from the solution: the residual test passes at once.
            let it2 = pcg_into(
                &a,
                &inv,
                &b,
                &mut x,
                CgOptions::new(1e-10),
                &mut CgWork::new(n),
            )
            .unwrap();
            assert_eq!(it2, 0);
        }
    }

    #[test]
    fn blocked_columns_equal_single_solves() {
        let a = step_matrix(&[3, 3, 12], 1.1);
        let n = a.pattern.n;
        let inv = jacobi(&a).unwrap();
        // 11 columns: one full block and a partial one (unused lanes must stay inert).
        let ncols = 11;
        let mut bx = vec![0.0; n * ncols];
        for c in 0..ncols {
            bx[c * n + (c * 37) % n] = 1.0;
        }
        let mut singles = bx.clone();
        let opts = CgOptions::new(1e-12);
        let most = pcg_many_into(&a, &inv, &mut bx, ncols, opts, &mut CgBlockWork::new(n)).unwrap();
        assert!(most > 3, "{most}");
        let mut w = CgWork::new(n);
        for c in 0..ncols {
            let b = singles[c * n..(c + 1) * n].to_vec();
            let x = &mut singles[c * n..(c + 1) * n];
            x.fill(0.0);
            pcg_into(&a, &inv, &b, x, opts, &mut w).unwrap();
            // Same iteration per column, other summation order: both within κ·tol of A⁻¹b.
            let e = rel_diff(&bx[c * n..(c + 1) * n], x);
            assert!(e < 1e-10, "column {c}: {e}");
            let e = rel_diff(x, &direct(&a, &b));
            assert!(e < 1e-10, "column {c} vs Cholesky: {e}");
        }
    }

    #[test]
    fn indefinite_and_unconverged_are_errors() {
        let m = SymMatrix::from_dense(2, &[1.0, 2.0, 2.0, 1.0]).unwrap();
        let inv = jacobi(&m).unwrap();
        let mut x = vec![0.0; 2];
        // b along the eigenvector (1, −1) of eigenvalue −1: pᵀAp < 0 at once.
        let e = pcg_into(
            &m,
            &inv,
            &[1.0, -1.0],
            &mut x,
            CgOptions::new(1e-12),
            &mut CgWork::new(2),
        )
        .unwrap_err();
        assert!(matches!(e, CgError::NotPositiveDefinite { .. }), "{e}");
        let neg = SymMatrix::from_dense(2, &[-1.0, 0.0, 0.0, 1.0]).unwrap();
        assert_eq!(
            jacobi(&neg).unwrap_err(),
            CgError::BadDiagonal {
                dof: 0,
                value: -1.0
            }
        );
        let a = step_matrix(&[4, 30], 1.1);
        let n = a.pattern.n;
        let inv = jacobi(&a).unwrap();
        let b = vec![1.0; n];
        let mut x = vec![0.0; n];
        let opts = CgOptions {
            tol: 1e-12,
            max_iter: 2,
        };
        let e = pcg_into(&a, &inv, &b, &mut x, opts, &mut CgWork::new(n)).unwrap_err();
        assert!(
            matches!(e, CgError::NotConverged { iterations: 2, .. }),
            "{e}"
        );
        let mut bad = vec![0.0; n];
        bad[3] = f64::NAN;
        let e = pcg_into(&a, &inv, &bad, &mut x, opts, &mut CgWork::new(n)).unwrap_err();
        assert_eq!(e, CgError::NonFinite);
        // A zero right-hand side: x = 0 without iterating, whatever the guess.
        x.fill(3.0);
        let z = vec![0.0; n];
        assert_eq!(
            pcg_into(&a, &inv, &z, &mut x, opts, &mut CgWork::new(n)),
            Ok(0)
        );
        assert!(x.iter().all(|&v| v == 0.0));
    }
}
