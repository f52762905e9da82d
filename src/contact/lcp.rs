//! The condensed nodal Signorini problem of the finite-element scenes: a linear
//! complementarity problem on the contact dofs,
//!
//!   find λ ≥ 0 with w = H λ + q ≥ 0 and λᵀw = 0,
//!
//! H = c τ² B A⁻¹ Bᵀ symmetric positive definite (the step matrix condensed onto the contact
//! dofs), q = B y + g the gap after the contact-free step. It is the KKT system of the convex
//! bound-constrained QP min ½λᵀHλ + qᵀλ, λ ≥ 0, solved *exactly* by an active-set method of
//! Lawson–Hanson type: on the passive set P the equations H_PP λ_P = −q_P hold to round-off
//! (dense Cholesky, |P| ≤ a few hundred); an index whose multiplier would turn negative leaves P
//! by a step back to the feasible boundary; the most violated constraint enters P. Every
//! iterate is feasible and the objective decreases strictly, so the method terminates finitely
//! (no cycling, unlike a plain primal–dual active set on a matrix that is not an M-matrix). It is
//! warm-started from the previous step's contact set, so a step whose contact set does not change
//! costs one dense solve.
//!
//! All buffers are allocated once ([`Lcp::new`]); [`Lcp::solve`] does not allocate.

/// Why the contact problem was not solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LcpError {
    #[error("contact active set did not converge in {0} iterations")]
    NoConvergence(usize),
    #[error("condensed contact matrix is not positive definite on the active set")]
    NotPositiveDefinite,
    #[error("non-finite contact data")]
    NonFinite,
}

/// A dense SPD LCP of fixed size with its workspace.
#[derive(Debug, Clone)]
pub struct Lcp {
    n: usize,
    /// H, row-major.
    h: Vec<f64>,
    passive: Vec<bool>,
    idx: Vec<usize>,
    chol: Vec<f64>,
    z: Vec<f64>,
    w: Vec<f64>,
}

impl Lcp {
    /// The problem with matrix `h` if given, else with the zero matrix: the idle workspace of a
    /// run whose contact is not a multiplier LCP (Nitsche, penalty), sized alike.
    pub fn new_or_idle(n: usize, h: Option<&[f64]>) -> Lcp {
        Lcp::new(n, h.map_or_else(|| vec![0.0; n * n], <[f64]>::to_vec))
    }

    /// The problem with matrix `h` (n × n, row-major, symmetric positive definite).
    pub fn new(n: usize, h: Vec<f64>) -> Lcp {
        assert_eq!(h.len(), n * n, "H must be n × n");
        Lcp {
            n,
            h,
            passive: vec![false; n],
            idx: Vec::with_capacity(n),
            chol: vec![0.0; n * n],
            z: vec![0.0; n],
            w: vec![0.0; n],
        }
    }

    pub fn n(&self) -> usize {
        self.n
    }

    /// Solve for `q`. On entry `lambda` holds the warm start (its support is the initial
    /// passive set); on exit the solution. Returns the number of dense solves. `tol` is relative
    /// to max|q|. The cap is `max_iter` iterations beyond the n that a cold start may need:
    /// each index entering the passive set costs one iteration, so a fixed cap below the
    /// number of rows coming into contact at once would refuse a large interface's impact
    /// (169 rows of a 12 × 12 blocks3d face did) rather than bound a cycle.
    pub fn solve(
        &mut self,
        q: &[f64],
        lambda: &mut [f64],
        max_iter: usize,
        tol: f64,
    ) -> Result<usize, LcpError> {
        self.solve_impl(q, lambda, None, max_iter, tol)
    }

    /// [`Lcp::solve`] on the rows with `rows[i]` only: the others keep λ_i = 0 whatever their
    /// w_i (Moreau–Jean's complementarity holds on the rows whose predicted gap closes). The
    /// problem on the kept rows is the principal sub-LCP, SPD as well; `q` of the other rows is
    /// not read (nor counted in the tolerance's scale).
    pub fn solve_on(
        &mut self,
        q: &[f64],
        lambda: &mut [f64],
        rows: &[bool],
        max_iter: usize,
        tol: f64,
    ) -> Result<usize, LcpError> {
        assert_eq!(rows.len(), self.n, "one flag per row");
        self.solve_impl(q, lambda, Some(rows), max_iter, tol)
    }

    fn solve_impl(
        &mut self,
        q: &[f64],
        lambda: &mut [f64],
        rows: Option<&[bool]>,
        max_iter: usize,
        tol: f64,
    ) -> Result<usize, LcpError> {
        let n = self.n;
        let kept = |i: usize| rows.is_none_or(|r| r[i]);
        if (0..n).any(|i| kept(i) && !q[i].is_finite()) {
            return Err(LcpError::NonFinite);
        }
        let scale = (0..n)
            .filter(|&i| kept(i))
            .fold(0.0f64, |m, i| m.max(q[i].abs()))
            .max(f64::MIN_POSITIVE);
        let eps = tol * scale;
        let max_iter = max_iter + n;
        for i in 0..n {
            self.passive[i] = kept(i) && lambda[i] > 0.0;
        }
        let mut iters = 0usize;
        // A feasible start: the warm set without the indices whose multiplier comes out
        // negative (each pass drops at least one, so at most n passes).
        loop {
            iters += 1;
            self.solve_passive(q)?;
            let mut dropped = false;
            for i in 0..n {
                if self.passive[i] && self.z[i] <= 0.0 {
                    self.passive[i] = false;
                    dropped = true;
                }
            }
            if !dropped {
                break;
            }
        }
        for i in 0..n {
            lambda[i] = if self.passive[i] { self.z[i] } else { 0.0 };
        }
        loop {
            // w = Hλ + q; the most violated complementarity condition enters.
            let mut worst = -eps;
            let mut enter = None;
            for i in 0..n {
                let row = &self.h[i * n..(i + 1) * n];
                let wi = q[i]
                    + row
                        .iter()
                        .zip(lambda.iter())
                        .map(|(a, b)| a * b)
                        .sum::<f64>();
                self.w[i] = wi;
                if !self.passive[i] && kept(i) && wi < worst {
                    worst = wi;
                    enter = Some(i);
                }
            }
            let Some(j) = enter else {
                return Ok(iters);
            };
            self.passive[j] = true;
            // Inner loop: move towards the passive-set solution, stepping back to the boundary
            // when a multiplier would become negative.
            loop {
                if iters >= max_iter {
                    return Err(LcpError::NoConvergence(iters));
                }
                iters += 1;
                self.solve_passive(q)?;
                let mut alpha = f64::INFINITY;
                let mut block = None;
                for i in 0..n {
                    if self.passive[i] && self.z[i] <= 0.0 {
                        let a = lambda[i] / (lambda[i] - self.z[i]);
                        if a < alpha {
                            alpha = a;
                            block = Some(i);
                        }
                    }
                }
                let Some(b) = block else {
                    for i in 0..n {
                        lambda[i] = if self.passive[i] { self.z[i] } else { 0.0 };
                    }
                    break;
                };
                // Step back to the boundary; the blocking index leaves exactly at zero (others
                // reaching zero by rounding leave too).
                for i in 0..n {
                    if self.passive[i] {
                        lambda[i] += alpha * (self.z[i] - lambda[i]);
                        if i == b || lambda[i] <= 0.0 {
                            lambda[i] = 0.0;
                            self.passive[i] = false;
                        }
                    }
                }
            }
        }
    }

    /// z_P = −H_PP⁻¹ q_P (dense Cholesky on the passive set), z = 0 elsewhere.
    fn solve_passive(&mut self, q: &[f64]) -> Result<(), LcpError> {
        let n = self.n;
        self.idx.clear();
        self.idx.extend((0..n).filter(|&i| self.passive[i]));
        let p = self.idx.len();
        self.z.iter_mut().for_each(|x| *x = 0.0);
        if p == 0 {
            return Ok(());
        }
        let c = &mut self.chol;
        for (a, &i) in self.idx.iter().enumerate() {
            for (b, &j) in self.idx.iter().enumerate().take(a + 1) {
                c[a * p + b] = self.h[i * n + j];
            }
        }
        // In-place lower Cholesky of the p × p block.
        for k in 0..p {
            let mut d = c[k * p + k];
            for s in 0..k {
                d -= c[k * p + s] * c[k * p + s];
            }
            // NaN fails this test too.
            if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return Err(LcpError::NotPositiveDefinite);
            }
            let d = d.sqrt();
            c[k * p + k] = d;
            for i in k + 1..p {
                let mut v = c[i * p + k];
                for s in 0..k {
                    v -= c[i * p + s] * c[k * p + s];
                }
                c[i * p + k] = v / d;
            }
        }
        // Forward and back substitution into w (scratch), result scattered into z.
        for a in 0..p {
            let mut v = -q[self.idx[a]];
            for s in 0..a {
                v -= c[a * p + s] * self.w[s];
            }
            self.w[a] = v / c[a * p + a];
        }
        for a in (0..p).rev() {
            let mut v = self.w[a];
            for s in a + 1..p {
                v -= c[s * p + a] * self.w[s];
            }
            self.w[a] = v / c[a * p + a];
        }
        for a in 0..p {
            self.z[self.idx[a]] = self.w[a];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Check the KKT conditions of a solution to round-off.
    fn check(h: &[f64], q: &[f64], lambda: &[f64]) {
        let n = q.len();
        for i in 0..n {
            let w: f64 = q[i] + (0..n).map(|j| h[i * n + j] * lambda[j]).sum::<f64>();
            assert!(lambda[i] >= 0.0);
            assert!(w >= -1e-12, "w[{i}] = {w}");
            assert!((lambda[i] * w).abs() < 1e-12, "complementarity {i}");
        }
    }

    #[test]
    fn solves_a_non_m_matrix_lcp_from_any_warm_start() {
        // H has positive off-diagonal entries (not an M-matrix): a plain primal–dual active set
        // can cycle on it; the feasible active-set method cannot.
        let h = vec![4.0, 1.5, 0.5, 1.5, 3.0, 1.2, 0.5, 1.2, 2.0];
        for q in [
            [-1.0, 2.0, -0.5],
            [-1.0, -1.0, -1.0],
            [1.0, 1.0, 1.0],
            [-3.0, 0.1, 2.0],
        ] {
            for warm in [[0.0; 3], [1.0; 3], [1.0, 0.0, 1.0]] {
                let mut lcp = Lcp::new(3, h.clone());
                let mut lambda = warm;
                lcp.solve(&q, &mut lambda, 100, 1e-12).unwrap();
                check(&h, &q, &lambda);
            }
        }
    }

    #[test]
    fn inactive_problem_costs_one_solve_and_returns_zero() {
        let mut lcp = Lcp::new(2, vec![2.0, 0.0, 0.0, 2.0]);
        let mut lambda = [0.0; 2];
        let it = lcp.solve(&[1.0, 0.5], &mut lambda, 100, 1e-12).unwrap();
        assert_eq!(lambda, [0.0, 0.0]);
        assert_eq!(it, 1);
        // Warm start on the true active set: one solve.
        let mut lambda = [1.0, 0.0];
        let it = lcp.solve(&[-1.0, 0.5], &mut lambda, 100, 1e-12).unwrap();
        assert_eq!(it, 1);
        assert!((lambda[0] - 0.5).abs() < 1e-15);
    }

    /// A cold start on a problem whose 150 rows all come into contact needs at least one
    /// iteration per row: a cap of 10 beyond them suffices, where a fixed cap of 10 (or the
    /// engine's 100 below 169 rows of a blocks3d face) would refuse it. H = 2I plus a 0.1
    /// coupling of neighbours (SPD, diagonally dominant), q = −1: every λ_i > 0, and the KKT
    /// check holds to 1e-12 (entries O(1), a 150 × 150 Cholesky's round-off ~1e-14).
    #[test]
    fn a_cold_start_with_every_row_active_is_not_capped_below_the_rows() {
        let n = 150;
        let mut h = vec![0.0; n * n];
        for i in 0..n {
            h[i * n + i] = 2.0;
            if i + 1 < n {
                h[i * n + i + 1] = 0.1;
                h[(i + 1) * n + i] = 0.1;
            }
        }
        let q = vec![-1.0; n];
        let mut lcp = Lcp::new(n, h.clone());
        let mut lambda = vec![0.0; n];
        let it = lcp.solve(&q, &mut lambda, 10, 1e-12).unwrap();
        assert!(it > n, "{it} iterations: one per entering row at least");
        assert!(lambda.iter().all(|&l| l > 0.0));
        check(&h, &q, &lambda);
    }

    #[test]
    fn indefinite_matrix_is_an_error_not_a_panic() {
        // Warm-started on both indices, the 2 × 2 block [[1, 3], [3, 1]] has a negative pivot.
        let mut lcp = Lcp::new(2, vec![1.0, 3.0, 3.0, 1.0]);
        let mut lambda = [1.0; 2];
        assert_eq!(
            lcp.solve(&[-1.0, -1.0], &mut lambda, 100, 1e-12),
            Err(LcpError::NotPositiveDefinite)
        );
    }
}
