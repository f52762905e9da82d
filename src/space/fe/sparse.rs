//! Symmetric sparse matrices on the free dofs: one pattern per (mesh, constraints), built once
//! and shared (`Arc`) by every matrix of a run and by the symbolic Cholesky analysis; values are
//! refilled by assembly.
//!
//! Storage: CSC of the *full* symmetric matrix (both triangles), rows sorted in each column, the
//! diagonal always present. Full storage makes `A x` a row-oriented gather (column j of a
//! symmetric matrix is its row j), and lets the Cholesky read either triangle as a view without
//! copying. The pattern is the FE graph: free dofs i and j couple when their nodes share an
//! element — structurally, whatever the element weights (a weight 0 keeps its entries, zero).
//!
//! Assembly: A = Σ_e w(e) A_e restricted to the free dofs (rows and columns of constrained dofs
//! dropped: the Dirichlet values are zero, or are lifted by the caller on the full dof set).

use std::sync::Arc;

use nalgebra::{SMatrix, SVector};

pub use super::element::ElementOp;
use super::element::{element_matrix, q1_load};
use super::mesh::Mesh;
use super::simplex::{simplex_element_matrix, simplex_load};
use super::{DofMap, FeError};

/// The CSC structure of a full symmetric n×n matrix (sorted rows, diagonal present).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pattern {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
}

impl Pattern {
    /// Check the invariants: `col_ptr` of length n+1 from 0 to nnz and increasing, rows in range
    /// and strictly increasing in each column, the diagonal present, and the structure symmetric.
    pub fn new(n: usize, col_ptr: Vec<usize>, row_idx: Vec<usize>) -> Result<Pattern, FeError> {
        let bad = |m: String| Err(FeError::BadMatrix(m));
        if col_ptr.len() != n + 1 || col_ptr[0] != 0 || col_ptr[n] != row_idx.len() {
            return bad(format!(
                "col_ptr has {} entries from {:?} to {:?}, expected {} from 0 to nnz = {}",
                col_ptr.len(),
                col_ptr.first(),
                col_ptr.last(),
                n + 1,
                row_idx.len()
            ));
        }
        let p = Pattern {
            n,
            col_ptr,
            row_idx,
        };
        for j in 0..n {
            if p.col_ptr[j] > p.col_ptr[j + 1] {
                return bad(format!("col_ptr decreases at column {j}"));
            }
            let rows = p.col(j);
            if rows.windows(2).any(|w| w[0] >= w[1]) || rows.last().is_some_and(|&r| r >= n) {
                return bad(format!("rows of column {j} are not increasing and < {n}"));
            }
            if rows.binary_search(&j).is_err() {
                return bad(format!("diagonal entry ({j}, {j}) missing"));
            }
            if let Some(&i) = rows.iter().find(|&&i| p.position(j, i).is_none()) {
                return bad(format!("entry ({i}, {j}) present but ({j}, {i}) missing"));
            }
        }
        Ok(p)
    }

    /// Row indices of column j.
    pub fn col(&self, j: usize) -> &[usize] {
        &self.row_idx[self.col_ptr[j]..self.col_ptr[j + 1]]
    }

    /// Index into the values of entry (i, j), if structurally present.
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        self.col(j)
            .binary_search(&i)
            .ok()
            .map(|k| self.col_ptr[j] + k)
    }

    /// Stored entries (both triangles).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
}

/// A symmetric matrix with values in a shared pattern.
#[derive(Debug, Clone, PartialEq)]
pub struct SymMatrix {
    pub pattern: Arc<Pattern>,
    pub values: Vec<f64>,
}

impl SymMatrix {
    /// All stored entries zero.
    pub fn zeros(pattern: &Arc<Pattern>) -> SymMatrix {
        SymMatrix {
            pattern: Arc::clone(pattern),
            values: vec![0.0; pattern.nnz()],
        }
    }

    /// The matrix of a dense symmetric row-major n×n array: the pattern holds its nonzeros and
    /// the diagonal. Asymmetry beyond 1e-14 relative to the largest entry is an error.
    pub fn from_dense(n: usize, a: &[f64]) -> Result<SymMatrix, FeError> {
        if a.len() != n * n {
            return Err(FeError::BadMatrix(format!(
                "dense array has {} entries, expected {n}² = {}",
                a.len(),
                n * n
            )));
        }
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        let mut values = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (aij, aji) = (a[i * n + j], a[j * n + i]);
                if (aij - aji).abs() > 1e-14 * scale {
                    return Err(FeError::BadMatrix(format!(
                        "dense array not symmetric: ({i}, {j}) = {aij}, ({j}, {i}) = {aji}"
                    )));
                }
                if aij != 0.0 || i == j {
                    row_idx.push(i);
                    values.push(aij);
                }
            }
            col_ptr.push(row_idx.len());
        }
        Ok(SymMatrix {
            pattern: Arc::new(Pattern::new(n, col_ptr, row_idx)?),
            values,
        })
    }

    /// A diagonal matrix (e.g. a lumped mass) stored in `pattern`, so that it combines with the
    /// other matrices of the run by [`SymMatrix::lin_comb`].
    pub fn diagonal_from(pattern: &Arc<Pattern>, diag: &[f64]) -> SymMatrix {
        assert_eq!(diag.len(), pattern.n, "diagonal length vs matrix size");
        let mut m = SymMatrix::zeros(pattern);
        for (j, &d) in diag.iter().enumerate() {
            let p = pattern.position(j, j).expect("diagonal always present");
            m.values[p] = d;
        }
        m
    }

    pub fn n(&self) -> usize {
        self.pattern.n
    }

    /// Entry (i, j), 0 outside the pattern.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.pattern.position(i, j).map_or(0.0, |p| self.values[p])
    }

    /// The diagonal.
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.n()).map(|j| self.get(j, j)).collect()
    }

    /// y = A x, allocating nothing (column j of A is row j by symmetry).
    pub fn matvec_into(&self, x: &[f64], y: &mut [f64]) {
        let p = &*self.pattern;
        assert!(x.len() == p.n && y.len() == p.n, "matvec_into: length vs n");
        for (j, yj) in y.iter_mut().enumerate() {
            let (s, e) = (p.col_ptr[j], p.col_ptr[j + 1]);
            *yj = p.row_idx[s..e]
                .iter()
                .zip(&self.values[s..e])
                .map(|(&i, &v)| v * x[i])
                .sum();
        }
    }

    /// The same matrix without its stored zeros off the diagonal, on a pattern of its own: for
    /// products only (a vector mass matrix on the stiffness's pattern stores the zero coupling
    /// of different components, half its entries in 2D). A product with it equals one with
    /// `self` for finite vectors: the dropped terms are 0·x. `self` when the structure would
    /// not be symmetric (it always is for an assembled symmetric matrix).
    pub fn without_zeros(&self) -> SymMatrix {
        let p = &*self.pattern;
        let mut col_ptr = Vec::with_capacity(p.n + 1);
        let (mut rows, mut values) = (Vec::new(), Vec::new());
        col_ptr.push(0);
        for j in 0..p.n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[k];
                if i == j || self.values[k] != 0.0 {
                    rows.push(i);
                    values.push(self.values[k]);
                }
            }
            col_ptr.push(rows.len());
        }
        match Pattern::new(p.n, col_ptr, rows) {
            Ok(pattern) => SymMatrix {
                pattern: Arc::new(pattern),
                values,
            },
            Err(_) => self.clone(),
        }
    }

    /// y_m = A x_m for several vectors at once (at most 8), the matrix read once for all: the
    /// products of a lockstep group. Each y_m gets exactly [`Self::matvec_into`]'s arithmetic
    /// (the same order of summation), so a run's numbers do not depend on its group.
    ///
    /// # Panics
    /// If more than 8 vectors are given, or a length is not n.
    pub fn matvec_many_into(&self, xs: &[&[f64]], ys: &mut [&mut [f64]]) {
        let p = &*self.pattern;
        let k = xs.len();
        assert!(k == ys.len() && k <= 8, "matvec_many_into: 1–8 pairs");
        assert!(
            xs.iter().all(|x| x.len() == p.n) && ys.iter().all(|y| y.len() == p.n),
            "matvec_many_into: length vs n"
        );
        // One kernel per count: the k accumulators of a row can then live in registers.
        match k {
            0 => {}
            1 => self.matvec_into(xs[0], ys[0]),
            2 => self.matvec_fixed::<2>(xs, ys),
            3 => self.matvec_fixed::<3>(xs, ys),
            4 => self.matvec_fixed::<4>(xs, ys),
            5 => self.matvec_fixed::<5>(xs, ys),
            6 => self.matvec_fixed::<6>(xs, ys),
            7 => self.matvec_fixed::<7>(xs, ys),
            _ => self.matvec_fixed::<8>(xs, ys),
        }
    }

    /// [`Self::matvec_many_into`] for exactly `K` vectors.
    fn matvec_fixed<const K: usize>(&self, xs: &[&[f64]], ys: &mut [&mut [f64]]) {
        let p = &*self.pattern;
        let xs: [&[f64]; K] = std::array::from_fn(|m| &xs[m][..p.n]);
        for j in 0..p.n {
            let (s, e) = (p.col_ptr[j], p.col_ptr[j + 1]);
            // Accumulate from −0.0 as the iterator sum does (the additive identity of f64).
            let mut acc = [-0.0f64; K];
            for (&i, &v) in p.row_idx[s..e].iter().zip(&self.values[s..e]) {
                for m in 0..K {
                    acc[m] += v * xs[m][i];
                }
            }
            for m in 0..K {
                ys[m][j] = acc[m];
            }
        }
    }

    /// xᵀ A x.
    pub fn quad_form(&self, x: &[f64]) -> f64 {
        let p = &*self.pattern;
        assert_eq!(x.len(), p.n, "quad_form: length vs n");
        (0..p.n)
            .map(|j| {
                let (s, e) = (p.col_ptr[j], p.col_ptr[j + 1]);
                let r: f64 = p.row_idx[s..e]
                    .iter()
                    .zip(&self.values[s..e])
                    .map(|(&i, &v)| v * x[i])
                    .sum();
                x[j] * r
            })
            .sum()
    }

    /// a·X + b·Y (same pattern required: the same `Arc` or an equal structure).
    ///
    /// # Panics
    /// If the patterns differ.
    pub fn lin_comb(a: f64, x: &SymMatrix, b: f64, y: &SymMatrix) -> SymMatrix {
        assert!(
            Arc::ptr_eq(&x.pattern, &y.pattern) || x.pattern == y.pattern,
            "lin_comb: the two matrices have different patterns"
        );
        SymMatrix {
            pattern: Arc::clone(&x.pattern),
            values: x
                .values
                .iter()
                .zip(&y.values)
                .map(|(u, v)| a * u + b * v)
                .collect(),
        }
    }

    /// Σ_j A_ij for every row i (the row-sum lumping; by symmetry the column sums).
    pub fn row_sums(&self) -> Vec<f64> {
        let p = &*self.pattern;
        (0..p.n)
            .map(|j| self.values[p.col_ptr[j]..p.col_ptr[j + 1]].iter().sum())
            .collect()
    }

    /// Row-major dense copy (tests and small problems).
    pub fn to_dense(&self) -> Vec<f64> {
        let n = self.n();
        let mut d = vec![0.0; n * n];
        for j in 0..n {
            for (k, &i) in self.pattern.col(j).iter().enumerate() {
                d[i * n + j] = self.values[self.pattern.col_ptr[j] + k];
            }
        }
        d
    }
}

/// The pattern of the FE matrices on the free dofs of `dofs` (which numbers `mesh.dim()`
/// components per node, node-major).
pub fn fe_pattern<M: Mesh + ?Sized>(mesh: &M, dofs: &DofMap) -> Arc<Pattern> {
    let d = mesh.dim();
    assert_eq!(
        dofs.n_total,
        mesh.num_nodes() * d,
        "fe_pattern: DofMap size vs nodes × dim"
    );
    // Node graph: each node with itself and every node it shares an element with, sorted.
    let mut nbrs: Vec<Vec<usize>> = (0..mesh.num_nodes()).map(|n| vec![n]).collect();
    for e in 0..mesh.num_elements() {
        let nodes = mesh.element_nodes(e);
        for &a in nodes {
            nbrs[a].extend_from_slice(nodes);
        }
    }
    for l in &mut nbrs {
        l.sort_unstable();
        l.dedup();
    }
    // Column of free dof r = the free dofs of its node's neighbours; the reduced numbering is
    // increasing in the global one, which is increasing in (node, component): already sorted.
    let mut col_ptr = Vec::with_capacity(dofs.n_free() + 1);
    col_ptr.push(0);
    let mut row_idx = Vec::new();
    for &g in &dofs.free {
        for &nb in &nbrs[g / d] {
            for c in 0..d {
                if let Some(r) = dofs.free_index(nb * d + c) {
                    row_idx.push(r);
                }
            }
        }
        col_ptr.push(row_idx.len());
    }
    Arc::new(Pattern {
        n: dofs.n_free(),
        col_ptr,
        row_idx,
    })
}

/// Σ_e w(e) · (element matrix of `op`) on the free dofs, in `pattern` (from [`fe_pattern`] for
/// the same mesh and dofs). Elements with w(e) = 0 are skipped.
pub fn assemble<M: Mesh + ?Sized>(
    mesh: &M,
    dofs: &DofMap,
    pattern: &Arc<Pattern>,
    op: ElementOp,
    weight: &dyn Fn(usize) -> f64,
) -> SymMatrix {
    let mut a = SymMatrix::zeros(pattern);
    assemble_into(&mut a, mesh, dofs, op, weight);
    a
}

/// [`assemble`] into an existing matrix (values overwritten, pattern reused).
///
/// # Panics
/// If the pattern does not fit the mesh and dofs (an entry of an element is missing), or the
/// mesh is not made of Q1 or Q2 quadrilaterals / hexahedra (4, 9 / 8, 27 nodes) or P1/P2
/// triangles / tetrahedra (3, 6 / 4, 10 nodes).
pub fn assemble_into<M: Mesh + ?Sized>(
    a: &mut SymMatrix,
    mesh: &M,
    dofs: &DofMap,
    op: ElementOp,
    weight: &dyn Fn(usize) -> f64,
) {
    assert_eq!(
        a.pattern.n,
        dofs.n_free(),
        "assemble: pattern size vs free dofs"
    );
    a.values.fill(0.0);
    match (mesh.dim(), mesh.nodes_per_element()) {
        (2, 4) => assemble_generic::<M, 2, 4, 8>(a, mesh, dofs, op, weight, element_matrix),
        (3, 8) => assemble_generic::<M, 3, 8, 24>(a, mesh, dofs, op, weight, element_matrix),
        (2, 9) => assemble_generic::<M, 2, 9, 18>(a, mesh, dofs, op, weight, element_matrix),
        (3, 27) => assemble_generic::<M, 3, 27, 81>(a, mesh, dofs, op, weight, element_matrix),
        // The simplices of Gmsh meshes: no node count collides with a tensor element's.
        (2, 3) => assemble_generic::<M, 2, 3, 6>(a, mesh, dofs, op, weight, simplex_element_matrix),
        (2, 6) => {
            assemble_generic::<M, 2, 6, 12>(a, mesh, dofs, op, weight, simplex_element_matrix)
        }
        (3, 4) => {
            assemble_generic::<M, 3, 4, 12>(a, mesh, dofs, op, weight, simplex_element_matrix)
        }
        (3, 10) => {
            assemble_generic::<M, 3, 10, 30>(a, mesh, dofs, op, weight, simplex_element_matrix)
        }
        (d, k) => panic!("assemble: no element for dimension {d} with {k} nodes"),
    }
}

/// Coordinates of element `e` as the fixed-size array the element kernels take.
pub fn element_coords<M: Mesh + ?Sized, const D: usize, const NN: usize>(
    mesh: &M,
    e: usize,
) -> [[f64; D]; NN] {
    let nodes = mesh.element_nodes(e);
    let mut x = [[0.0; D]; NN];
    for (xa, &n) in x.iter_mut().zip(nodes) {
        let c = mesh.coord(n);
        xa.copy_from_slice(&c[..D]);
    }
    x
}

fn assemble_generic<M: Mesh + ?Sized, const D: usize, const NN: usize, const ND: usize>(
    a: &mut SymMatrix,
    mesh: &M,
    dofs: &DofMap,
    op: ElementOp,
    weight: &dyn Fn(usize) -> f64,
    kernel: fn(ElementOp, &[[f64; D]; NN]) -> SMatrix<f64, ND, ND>,
) {
    let p = Arc::clone(&a.pattern);
    let mut red = [u32::MAX; ND];
    for e in 0..mesh.num_elements() {
        let w = weight(e);
        if w == 0.0 {
            continue;
        }
        let nodes = mesh.element_nodes(e);
        for (k, r) in red.iter_mut().enumerate() {
            *r = dofs.free_of[nodes[k / D] * D + k % D];
        }
        let ke = kernel(op, &element_coords::<M, D, NN>(mesh, e));
        for (q, &cq) in red.iter().enumerate() {
            if cq == DofMap::CONSTRAINED {
                continue;
            }
            let col = cq as usize;
            let (s, end) = (p.col_ptr[col], p.col_ptr[col + 1]);
            let rows = &p.row_idx[s..end];
            for (pp, &rp) in red.iter().enumerate() {
                if rp == DofMap::CONSTRAINED {
                    continue;
                }
                let k = rows.binary_search(&(rp as usize)).unwrap_or_else(|_| {
                    panic!("assemble: entry ({rp}, {col}) not in the pattern (pattern of another mesh?)")
                });
                a.values[s + k] += w * ke[(pp, q)];
            }
        }
    }
}

/// Load vector on the free dofs: Σ_e w(e) ∫_e ρ f·v (f constant, e.g. gravity).
pub fn assemble_load<M: Mesh + ?Sized>(
    mesh: &M,
    dofs: &DofMap,
    rho: f64,
    f: [f64; 3],
    weight: &dyn Fn(usize) -> f64,
) -> Vec<f64> {
    let mut r = vec![0.0; dofs.n_free()];
    match (mesh.dim(), mesh.nodes_per_element()) {
        (2, 4) => load_generic::<M, 2, 4, 8>(&mut r, mesh, dofs, rho, f, weight, q1_load),
        (3, 8) => load_generic::<M, 3, 8, 24>(&mut r, mesh, dofs, rho, f, weight, q1_load),
        (2, 9) => load_generic::<M, 2, 9, 18>(&mut r, mesh, dofs, rho, f, weight, q1_load),
        (3, 27) => load_generic::<M, 3, 27, 81>(&mut r, mesh, dofs, rho, f, weight, q1_load),
        (2, 3) => load_generic::<M, 2, 3, 6>(&mut r, mesh, dofs, rho, f, weight, simplex_load),
        (2, 6) => load_generic::<M, 2, 6, 12>(&mut r, mesh, dofs, rho, f, weight, simplex_load),
        (3, 4) => load_generic::<M, 3, 4, 12>(&mut r, mesh, dofs, rho, f, weight, simplex_load),
        (3, 10) => load_generic::<M, 3, 10, 30>(&mut r, mesh, dofs, rho, f, weight, simplex_load),
        (d, k) => panic!("assemble_load: no element for dimension {d} with {k} nodes"),
    }
    r
}

/// An element load kernel: (node coordinates, ρ, f) ↦ ∫ ρ f·N_a (Q1/Q2 or simplex).
type LoadKernel<const D: usize, const NN: usize, const ND: usize> =
    fn(&[[f64; D]; NN], f64, [f64; 3]) -> SVector<f64, ND>;

fn load_generic<M: Mesh + ?Sized, const D: usize, const NN: usize, const ND: usize>(
    r: &mut [f64],
    mesh: &M,
    dofs: &DofMap,
    rho: f64,
    f: [f64; 3],
    weight: &dyn Fn(usize) -> f64,
    kernel: LoadKernel<D, NN, ND>,
) {
    for e in 0..mesh.num_elements() {
        let w = weight(e);
        if w == 0.0 {
            continue;
        }
        let fe = kernel(&element_coords::<M, D, NN>(mesh, e), rho, f);
        let nodes = mesh.element_nodes(e);
        for k in 0..ND {
            if let Some(i) = dofs.free_index(nodes[k / D] * D + k % D) {
                r[i] += w * fe[k];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::BoxMesh;
    use super::*;

    #[test]
    fn pattern_of_a_small_mesh() {
        // 2×1 squares, 6 nodes, 12 dofs: the middle nodes (1, 4) couple with all 6 nodes, the
        // end nodes with 4; 4·2·8 + 2·2·12 = 112 entries, symmetric, diagonal present.
        let m = BoxMesh::new(&[2.0, 1.0], &[2, 1]);
        let d = DofMap::all(12);
        let p = fe_pattern(&m, &d);
        assert_eq!(p.nnz(), 4 * 2 * 8 + 2 * 2 * 12);
        Pattern::new(p.n, p.col_ptr.clone(), p.row_idx.clone()).unwrap();
        // Constraining node 0 removes its two columns and rows.
        let d0 = DofMap::for_nodes(6, 2, |n, _| n == 0);
        let p0 = fe_pattern(&m, &d0);
        assert_eq!(p0.n, 10);
        assert_eq!(p0.nnz(), 112 - 2 * 8 - 2 * 8 + 4);
    }

    #[test]
    fn bad_patterns_are_errors() {
        // Missing diagonal, asymmetric structure, unsorted rows.
        assert!(Pattern::new(2, vec![0, 1, 2], vec![1, 0]).is_err());
        assert!(Pattern::new(2, vec![0, 2, 3], vec![0, 1, 1]).is_err());
        assert!(Pattern::new(2, vec![0, 2, 4], vec![1, 0, 0, 1]).is_err());
        assert!(Pattern::new(2, vec![0, 2, 4], vec![0, 1, 0, 1]).is_ok());
        assert!(SymMatrix::from_dense(2, &[1.0, 2.0, 3.0, 1.0]).is_err());
    }

    #[test]
    fn matrix_operations() {
        // A small dense SPD matrix: every operation against its dense definition; integers and
        // halves are exact in binary, so equality is exact.
        let a = [4.0, 1.0, 0.0, 1.0, 3.0, 0.5, 0.0, 0.5, 2.0];
        let m = SymMatrix::from_dense(3, &a).unwrap();
        assert_eq!(m.pattern.nnz(), 7);
        assert_eq!(m.to_dense(), a.to_vec());
        let x = [1.0, -2.0, 4.0];
        let mut y = [0.0; 3];
        m.matvec_into(&x, &mut y);
        assert_eq!(y, [2.0, -3.0, 7.0]);
        assert_eq!(m.quad_form(&x), 2.0 + 6.0 + 28.0);
        assert_eq!(m.row_sums(), vec![5.0, 4.5, 2.5]);
        assert_eq!(m.get(0, 2), 0.0);
        let dgl = SymMatrix::diagonal_from(&m.pattern, &[1.0, 1.0, 1.0]);
        let c = SymMatrix::lin_comb(2.0, &m, -1.0, &dgl);
        assert_eq!(c.get(1, 1), 5.0);
        assert_eq!(c.get(2, 1), 1.0);
        assert_eq!(m.diagonal(), vec![4.0, 3.0, 2.0]);
    }
}
