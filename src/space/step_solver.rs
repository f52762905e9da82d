//! The per-step linear solve of the 2D/3D engines, direct or iterative (`solver` key, contract §4):
//! one type with the calls the time loops make (`work()`, `work_for(k)`, `solve_in_place`,
//! `solve_many_in_place`), dispatching to the sparse Cholesky factor ([`super::linalg`]) or to
//! Jacobi-preconditioned conjugate gradient on the step matrix itself ([`super::cg`]).
//!
//! The direct solver keeps only the factor; CG keeps the matrix A and 1/diag(A) (no factor is
//! ever made: a run's `factorizations` is 0). CG's single-vector solves are warm-started from the
//! previous solution made with the same [`StepWork`] (the previous time step's), and count their
//! iterations there ([`StepWork::iterations_total`], [`StepWork::iterations_max`]).
//!
//! `solve_in_place` returns nothing, as the Cholesky solve always did; a CG failure (matrix not
//! positive definite, tolerance not reached) is kept in the work and returned by
//! [`StepWork::check`], which a time loop calls after each solve (the right-hand side then holds
//! the last iterate). [`StepSolver::try_solve_many_in_place`] returns it directly (the setup).

use std::sync::Arc;

use super::cg::{self, CgBlockWork, CgError, CgOptions, CgWork};
use super::fe::SymMatrix;
use super::linalg::{Cholesky, LinalgError, SolveWork, SymbolicCholesky};

/// How the step systems are solved (the `solver` and `cg_tol` keys).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Solver {
    /// Sparse Cholesky, factored once per run (shared between runs with the same matrix).
    #[default]
    Direct,
    /// Jacobi-preconditioned CG to a relative residual `tol` (module [`super::cg`]).
    Cg { tol: f64 },
}

impl Solver {
    /// The default `cg_tol`.
    pub const DEFAULT_CG_TOL: f64 = 1e-12;
    /// Values of the `solver` key.
    pub const NAMES: [&'static str; 2] = ["direct", "cg"];

    pub fn name(&self) -> &'static str {
        match self {
            Solver::Direct => "direct",
            Solver::Cg { .. } => "cg",
        }
    }
}

/// Failures of building the solver or of a solve.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepSolveError {
    #[error(transparent)]
    Direct(#[from] LinalgError),
    #[error(transparent)]
    Cg(#[from] CgError),
}

/// The step matrix, ready to solve with.
#[derive(Debug)]
pub enum StepSolver {
    Direct(Cholesky),
    Cg {
        a: SymMatrix,
        inv_diag: Vec<f64>,
        opts: CgOptions,
    },
}

/// The scratch of the solver kind.
#[derive(Debug)]
enum Scratch {
    Direct(SolveWork),
    Cg {
        single: CgWork,
        /// For several right-hand sides at once (made by `work_for(k)` with k > 1).
        block: Option<CgBlockWork>,
        /// The last solution: the next solve's initial guess.
        guess: Vec<f64>,
    },
}

/// Scratch memory and iteration counts of the solves made with it (a solve allocates nothing).
#[derive(Debug)]
pub struct StepWork {
    scratch: Scratch,
    iterations_total: u64,
    iterations_max: usize,
    failure: Option<CgError>,
}

impl StepWork {
    /// The first failure since the last check (CG only; a direct solve cannot fail).
    pub fn check(&mut self) -> Result<(), CgError> {
        self.failure.take().map_or(Ok(()), Err)
    }

    /// CG iterations of every solve made with this work (0 for the direct solver).
    pub fn iterations_total(&self) -> u64 {
        self.iterations_total
    }

    /// Most CG iterations of one solve (a solve of several right-hand sides: of its slowest
    /// column).
    pub fn iterations_max(&self) -> usize {
        self.iterations_max
    }

    fn record(&mut self, r: Result<usize, CgError>) -> Result<(), CgError> {
        match r {
            Ok(it) => {
                self.iterations_total += it as u64;
                self.iterations_max = self.iterations_max.max(it);
                Ok(())
            }
            Err(e) => {
                if let CgError::NotConverged { iterations, .. } = e {
                    self.iterations_total += iterations as u64;
                    self.iterations_max = self.iterations_max.max(iterations);
                }
                Err(e)
            }
        }
    }
}

impl StepSolver {
    /// The solver of `a`: its Cholesky factor (`symbolic` is asked for only then) or, for CG,
    /// the matrix itself with its Jacobi preconditioner.
    pub fn new(
        solver: Solver,
        symbolic: impl FnOnce() -> Result<Arc<SymbolicCholesky>, LinalgError>,
        a: SymMatrix,
    ) -> Result<StepSolver, StepSolveError> {
        match solver {
            Solver::Direct => Ok(StepSolver::Direct(Cholesky::new(&symbolic()?, &a)?)),
            Solver::Cg { tol } => {
                if let Some(k) = a.values.iter().position(|v| !v.is_finite()) {
                    let p = &a.pattern;
                    let col = p.col_ptr.partition_point(|&c| c <= k) - 1;
                    return Err(LinalgError::NonFinite {
                        row: p.row_idx[k],
                        col,
                    }
                    .into());
                }
                let inv_diag = cg::jacobi(&a)?;
                Ok(StepSolver::Cg {
                    a,
                    inv_diag,
                    opts: CgOptions::new(tol),
                })
            }
        }
    }

    /// Order of the matrix.
    pub fn n(&self) -> usize {
        match self {
            StepSolver::Direct(c) => c.n(),
            StepSolver::Cg { a, .. } => a.pattern.n,
        }
    }

    /// Whether a factorisation was made (the `factorizations` metric).
    pub fn is_factored(&self) -> bool {
        matches!(self, StepSolver::Direct(_))
    }

    /// Scratch for solves with one right-hand side.
    pub fn work(&self) -> StepWork {
        self.work_for(1)
    }

    /// Scratch for solves with up to `ncols` right-hand sides at once.
    pub fn work_for(&self, ncols: usize) -> StepWork {
        let scratch = match self {
            StepSolver::Direct(c) => Scratch::Direct(c.work_for(ncols)),
            StepSolver::Cg { a, .. } => {
                let n = a.pattern.n;
                Scratch::Cg {
                    single: CgWork::new(n),
                    block: (ncols > 1).then(|| CgBlockWork::new(n)),
                    guess: vec![0.0; n],
                }
            }
        };
        StepWork {
            scratch,
            iterations_total: 0,
            iterations_max: 0,
            failure: None,
        }
    }

    /// rhs ← A⁻¹ rhs, allocating nothing. CG starts from the previous solution made with
    /// `work`; a failure is kept in `work` ([`StepWork::check`]).
    ///
    /// # Panics
    /// If `rhs.len() != n`.
    pub fn solve_in_place(&self, rhs: &mut [f64], work: &mut StepWork) {
        match (self, &mut work.scratch) {
            (StepSolver::Direct(c), Scratch::Direct(w)) => c.solve_in_place(rhs, w),
            (StepSolver::Cg { a, inv_diag, opts }, Scratch::Cg { single, guess, .. }) => {
                let r = cg::pcg_into(a, inv_diag, rhs, guess, *opts, single);
                rhs.copy_from_slice(guess);
                if let Err(e) = work.record(r) {
                    // The guess may be ruined (NaN): the next solve starts from zero.
                    if let Scratch::Cg { guess, .. } = &mut work.scratch {
                        guess.fill(0.0);
                    }
                    work.failure.get_or_insert(e);
                }
            }
            _ => panic!("solve_in_place: work made by another solver"),
        }
    }

    /// Solve for `ncols` right-hand sides stored column-major in `rhs` (n × ncols), in place
    /// (the direct solver blocks the triangular solves, CG shares each pass over A between
    /// [`cg::BLOCK`] columns; CG starts from zero). A failure is kept in `work`.
    ///
    /// # Panics
    /// If `rhs.len() != n · ncols` or `work` was made for fewer columns.
    pub fn solve_many_in_place(&self, rhs: &mut [f64], ncols: usize, work: &mut StepWork) {
        if let Err(e) = self.try_solve_many_in_place(rhs, ncols, work) {
            work.failure.get_or_insert(e);
        }
    }

    /// [`Self::solve_many_in_place`] with each column's arithmetic that of its solve alone
    /// ([`Cholesky::solve_columns_in_place`]): the lockstep groups' solve, whose members must
    /// write the numbers of their runs alone. CG columns are independent already.
    ///
    /// # Panics
    /// As [`Self::solve_many_in_place`].
    pub fn solve_columns_in_place(&self, rhs: &mut [f64], ncols: usize, work: &mut StepWork) {
        match (self, &mut work.scratch) {
            (StepSolver::Direct(c), Scratch::Direct(w)) => c.solve_columns_in_place(rhs, ncols, w),
            _ => self.solve_many_in_place(rhs, ncols, work),
        }
    }

    /// [`Self::solve_many_in_place`], returning a CG failure.
    pub fn try_solve_many_in_place(
        &self,
        rhs: &mut [f64],
        ncols: usize,
        work: &mut StepWork,
    ) -> Result<(), CgError> {
        match (self, &mut work.scratch) {
            (StepSolver::Direct(c), Scratch::Direct(w)) => {
                c.solve_many_in_place(rhs, ncols, w);
                Ok(())
            }
            (
                StepSolver::Cg { a, inv_diag, opts },
                Scratch::Cg {
                    single,
                    block,
                    guess,
                },
            ) => {
                let n = a.pattern.n;
                assert_eq!(rhs.len(), n * ncols, "solve: rhs length vs n × ncols");
                let r = match (block, ncols) {
                    (Some(b), _) => cg::pcg_many_into(a, inv_diag, rhs, ncols, *opts, b),
                    (None, 0) => Ok(0),
                    // One column with single-column scratch: from zero, through `guess`.
                    (None, 1) => {
                        guess.fill(0.0);
                        let r = cg::pcg_into(a, inv_diag, rhs, guess, *opts, single);
                        rhs.copy_from_slice(guess);
                        r
                    }
                    (None, _) => panic!("solve: scratch made for 1 column, {ncols} given"),
                };
                work.record(r)
            }
            _ => panic!("solve_many_in_place: work made by another solver"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spd() -> SymMatrix {
        // Tridiagonal (−1, 4, −1), n = 6: SPD, κ < 3.
        let n = 6;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            a[i * n + i] = 4.0;
            if i + 1 < n {
                a[i * n + i + 1] = -1.0;
                a[(i + 1) * n + i] = -1.0;
            }
        }
        SymMatrix::from_dense(n, &a).unwrap()
    }

    #[test]
    fn cg_and_direct_agree_and_cg_warm_starts() {
        let a = spd();
        let direct = StepSolver::new(
            Solver::Direct,
            || SymbolicCholesky::new(&a.pattern),
            a.clone(),
        )
        .unwrap();
        let mut asked = false;
        let cg = StepSolver::new(
            Solver::Cg { tol: 1e-13 },
            || {
                asked = true;
                SymbolicCholesky::new(&a.pattern)
            },
            a.clone(),
        )
        .unwrap();
        assert!(!asked, "cg must not make the symbolic analysis");
        assert!(direct.is_factored() && !cg.is_factored());
        let b: Vec<f64> = (0..6).map(|i| i as f64 - 2.0).collect();
        let (mut x, mut y) = (b.clone(), b.clone());
        direct.solve_in_place(&mut x, &mut direct.work());
        let mut w = cg.work();
        cg.solve_in_place(&mut y, &mut w);
        w.check().unwrap();
        // κ < 3: |x − y| ≤ κ·1e-13·|x| ≈ 1e-12 (|x| ≈ 1).
        let d = x
            .iter()
            .zip(&y)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(d < 1e-12, "{d}");
        let first = w.iterations_total();
        assert!(first > 0 && first <= 6, "{first}");
        // The same right-hand side again: the warm start is the solution, no iteration.
        let mut z = b.clone();
        cg.solve_in_place(&mut z, &mut w);
        assert_eq!(w.iterations_total(), first);
        assert_eq!(w.iterations_max(), first as usize);
    }

    #[test]
    fn a_cg_failure_is_kept_for_check() {
        // Positive diagonal (Jacobi is defined), eigenvalues 3 and −1.
        let a = SymMatrix::from_dense(2, &[1.0, 2.0, 2.0, 1.0]).unwrap();
        let cg = StepSolver::new(
            Solver::Cg { tol: 1e-12 },
            || unreachable!("no symbolic analysis for cg"),
            a,
        )
        .unwrap();
        let mut w = cg.work();
        let mut y = vec![1.0, -1.0];
        cg.solve_in_place(&mut y, &mut w);
        assert!(matches!(
            w.check(),
            Err(CgError::NotPositiveDefinite { .. })
        ));
        // Taken: the next check is clean.
        assert_eq!(w.check(), Ok(()));
        // A negative diagonal is refused when the solver is built.
        let neg = SymMatrix::from_dense(2, &[-1.0, 0.0, 0.0, 1.0]).unwrap();
        assert!(matches!(
            StepSolver::new(Solver::Cg { tol: 1e-12 }, || unreachable!(), neg),
            Err(StepSolveError::Cg(CgError::BadDiagonal { dof: 0, .. }))
        ));
    }
}
