//! A sparse LU with partial pivoting (faer's) of a matrix whose values fill a symmetric FE
//! [`Pattern`] but are not symmetric themselves.
//!
//! Why: the frictional Nitsche/penalty Newton (`run::fe::nitsche`) solves its condensed
//! Jacobian I − cτ² W D through the full-space matrix A − cτ² Σ_q C_q D_q P_qᵀ, which lives in
//! the FE pattern (each contact point's rows sit on one element's dofs) and is non-symmetric
//! (Coulomb's slip couples f_t to f_n; Nitsche's C ≠ P). A dense LU of the condensed Jacobian
//! costs the cube of the active contact unknowns (d per point); this one costs what the body's
//! sparse factor costs. The symbolic analysis (COLAMD, the supernodal structure) is made once
//! per run; each [`SparseLu::factor`] refills the numeric factor in buffers sized by the first
//! one, and the scratch is allocated at construction, so a time loop allocates nothing.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{LuRef, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

use super::fe::sparse::Pattern;

/// The LU of one matrix on `pattern` at a time, refactored in place.
pub struct SparseLu {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    mem: MemBuffer,
    factored: bool,
}

impl std::fmt::Debug for SparseLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseLu")
            .field("n", &self.n)
            .finish_non_exhaustive()
    }
}

impl SparseLu {
    /// The symbolic analysis of `pattern` (its column ordering and supernodes) and the scratch
    /// of the numeric factorisation and of one-column solves.
    pub fn new(pattern: &Pattern) -> Result<SparseLu, String> {
        let view = SymbolicSparseColMatRef::new_checked(
            pattern.n,
            pattern.n,
            &pattern.col_ptr,
            None,
            &pattern.row_idx,
        );
        let symbolic =
            faer::sparse::linalg::lu::factorize_symbolic_lu(view, LuSymbolicParams::default())
                .map_err(|e| format!("sparse LU symbolic analysis: {e:?}"))?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        let mem = MemBuffer::try_new(req).map_err(|_| "sparse LU scratch: out of memory")?;
        Ok(SparseLu {
            n: pattern.n,
            col_ptr: pattern.col_ptr.clone(),
            row_idx: pattern.row_idx.clone(),
            symbolic,
            numeric: NumericLu::new(),
            mem,
            factored: false,
        })
    }

    /// Factor the matrix with `values` on the pattern (CSC, the pattern's order of entries).
    pub fn factor(&mut self, values: &[f64]) -> Result<(), String> {
        self.factored = false;
        let sym = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        let a = SparseColMatRef::new(sym, values);
        let stack = MemStack::new(&mut self.mem);
        self.symbolic
            .factorize_numeric_lu(&mut self.numeric, a, Par::Seq, stack, Default::default())
            .map_err(|e| format!("sparse LU: {e:?}"))?;
        self.factored = true;
        Ok(())
    }

    /// Overwrite `rhs` with the solution of A x = rhs for the last factored A.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(
            self.factored,
            "SparseLu::solve_in_place before a factorisation"
        );
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let stack = MemStack::new(&mut self.mem);
        let x = MatMut::from_column_major_slice_mut(rhs, self.n, 1);
        lu.solve_in_place_with_conj(Conj::No, x, Par::Seq, stack);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3 × 3 non-symmetric matrix on a full pattern whose first pivot is 0 (partial pivoting
    /// needed): [[0, 1, 0], [2, 0, 1], [0, 4, 1]] x = [1, 3, 5] has x = (1, 1, 1); entries and
    /// solution are small binary numbers, exact up to the pivots' rounding (1e-15 relative).
    #[test]
    fn solves_a_non_symmetric_system() {
        let p = Pattern::new(3, vec![0, 3, 6, 9], vec![0, 1, 2, 0, 1, 2, 0, 1, 2]).unwrap();
        // Columns: (0, 2, 0), (1, 0, 4), (0, 1, 1).
        let values = [0.0, 2.0, 0.0, 1.0, 0.0, 4.0, 0.0, 1.0, 1.0];
        let mut lu = SparseLu::new(&p).unwrap();
        lu.factor(&values).unwrap();
        let mut b = [1.0, 3.0, 5.0];
        lu.solve_in_place(&mut b);
        for x in b {
            assert!((x - 1.0).abs() < 1e-15, "{b:?}");
        }
    }
}
