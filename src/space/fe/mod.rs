//! The finite-element layer of the 2D/3D scenes (contract §1.2, §2): meshes, vector Q1 element
//! matrices, and global sparse assembly with the pattern built once and refilled many times.
//!
//! - [`mesh`]: the structured box of Q1 squares/cubes (`bar2d`, `bar3d`) behind the [`Mesh`]
//!   trait (elements = node ids + node coordinates);
//! - [`ball`]: the block-structured mapped disc (five-block O-grid) and ball (seven-block cubed
//!   sphere) of `disc2d`/`sphere3d`, Q1 or Q2, with the boundary faces of Γ_C and their
//!   quadrature;
//! - [`nitsche`]: the Γ_C quadrature points of the disc/ball with the linear functionals u_n and
//!   σ_n(u) of Nitsche's method and the dofs the contact problem condenses onto;
//! - [`gmsh`]: Gmsh MSH 4.1 meshes (ASCII or binary, parsed by [`msh`], the engine's own parser
//!   that cannot panic) of the `mesh2d`/`mesh3d` scenes: P1/P2 triangles and tetrahedra, Q1/Q2
//!   quadrilaterals and hexahedra, physical groups by name, validated (typed [`GmshError`]s,
//!   in `gmsh_error`; the whole-mesh checks — conformity, coincident nodes, boundary groups,
//!   certified det J — in `check`; the geometric one, cells overlapping, in `overlap`), with `h` and the file's content hash; the facts of the
//!   reference cells both stand on ([`ElementKind`]: node orders, shape gradients, det J) in
//!   `element_kind`, below both;
//! - [`element`]: isoparametric Q1/Q2 mass, elasticity stiffness, grad-grad and load with nalgebra
//!   fixed-size matrices, one dimension-generic kernel for 2D and 3D;
//! - [`simplex`]: vector P1/P2 triangle and tetrahedron mass, elasticity stiffness, grad-grad
//!   and load (isoparametric; degree-4 rule on triangles, degree-5 on tetrahedra), the simplices
//!   of Gmsh meshes, assembled by [`sparse`] like the Q1/Q2 cells;
//! - [`interface`]: the geometry of a non-matching two-body interface (contract §2.6, issue 45):
//!   the projection Π on Γ^b through a bin grid, the segmentation of Γ^a by Γ^b's projected
//!   faces, and the mortar matrices D, M with the `standard` and `dual` bases — a library the
//!   engine does not use yet;
//! - [`sparse`]: the CSC pattern of the full symmetric matrix on the free dofs, assembly with
//!   element weights (the layer-weighted masses of contract §2.2) and the matrix operations of a
//!   time loop (`matvec_into` allocates nothing).
//!
//! Degrees of freedom are node-major interleaved: dof = node·d + component. Constrained dofs
//! (Dirichlet: clamped face, rollers) are dropped from the assembled matrices by [`DofMap`];
//! the factorisation of the assembled matrices is the sparse Cholesky of `space/linalg.rs` (which
//! builds on this folder, not the other way round).

pub mod ball;
pub mod bodies;
mod check;
pub mod element;
mod element_kind;
pub mod gmsh;
mod gmsh_bodies;
mod gmsh_error;
mod gmsh_interface;
pub mod interface;
pub mod locate;
pub mod mesh;
pub mod msh;
pub mod nitsche;
mod overlap;
pub mod quadrature;
pub mod simplex;
pub mod sparse;

pub use ball::{BallMesh, BoundaryFace, FacePoint};
pub use bodies::BodiesMesh;
pub use element::{ElementOp, Q1Mat2, Q1Mat3, Q2Mat2, Q2Mat3};
pub use gmsh::{ElementKind, GmshError, GmshMesh, PhysicalGroup};
pub use gmsh_bodies::GmshBodies;
pub use gmsh_interface::{FileInterface, FileSide, file_interface};
pub use mesh::{BoxMesh, Mesh};
pub use simplex::{P1Mat2, P1Mat3, P2Mat2, P2Mat3};
pub use sparse::{Pattern, SymMatrix, assemble, assemble_into, assemble_load, fe_pattern};

/// Errors of the finite-element layer (bad shapes, bad user-given matrices).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FeError {
    #[error("invalid mesh: {0}")]
    BadMesh(String),
    #[error("invalid matrix: {0}")]
    BadMatrix(String),
}

/// Which global dofs are unknowns: `free[r]` is the global dof of reduced index r (increasing),
/// `free_of[g]` the reduced index of global dof g or `u32::MAX` if g is constrained.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    pub n_total: usize,
    pub free_of: Vec<u32>,
    pub free: Vec<usize>,
}

impl DofMap {
    /// Marker of a constrained dof in `free_of`.
    pub const CONSTRAINED: u32 = u32::MAX;

    /// Keep the dofs for which `constrained(g)` is false, in increasing order.
    ///
    /// # Panics
    /// If `n_total` ≥ 2³² − 1 (reduced indices are stored as u32: 4·10⁹ dofs is far beyond what
    /// a direct solver handles).
    pub fn new(n_total: usize, constrained: impl Fn(usize) -> bool) -> DofMap {
        assert!(
            n_total < u32::MAX as usize,
            "DofMap: {n_total} dofs exceed the u32 index range"
        );
        let mut free_of = vec![Self::CONSTRAINED; n_total];
        let mut free = Vec::with_capacity(n_total);
        for (g, slot) in free_of.iter_mut().enumerate() {
            if !constrained(g) {
                *slot = free.len() as u32;
                free.push(g);
            }
        }
        DofMap {
            n_total,
            free_of,
            free,
        }
    }

    /// Dofs of a mesh with `dim` components per node, constrained per (node, component).
    pub fn for_nodes(
        num_nodes: usize,
        dim: usize,
        constrained: impl Fn(usize, usize) -> bool,
    ) -> DofMap {
        DofMap::new(num_nodes * dim, |g| constrained(g / dim, g % dim))
    }

    /// Nothing constrained (the full dof set: total mass, rigid motions, error norms).
    pub fn all(n_total: usize) -> DofMap {
        DofMap::new(n_total, |_| false)
    }

    pub fn n_free(&self) -> usize {
        self.free.len()
    }

    /// Reduced index of global dof `g`, `None` if constrained.
    pub fn free_index(&self, g: usize) -> Option<usize> {
        match self.free_of[g] {
            Self::CONSTRAINED => None,
            r => Some(r as usize),
        }
    }

    /// The free dofs (reduced indices) in the order of `node_order`, components of a node
    /// together: turns a node ordering (e.g. [`BoxMesh::nested_dissection`]) into an elimination
    /// order for `SymbolicCholesky::with_ordering` (`space/linalg.rs`).
    pub fn order_by_nodes(&self, node_order: &[usize], dim: usize) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.n_free());
        for &n in node_order {
            for c in 0..dim {
                if let Some(r) = self.free_index(n * dim + c) {
                    out.push(r);
                }
            }
        }
        out
    }

    /// `reduced[r] = full[free[r]]`.
    pub fn gather(&self, full: &[f64], reduced: &mut [f64]) {
        for (r, &g) in reduced.iter_mut().zip(&self.free) {
            *r = full[g];
        }
    }

    /// `full[free[r]] = reduced[r]`; constrained entries of `full` are left as they are.
    pub fn scatter(&self, reduced: &[f64], full: &mut [f64]) {
        for (&r, &g) in reduced.iter().zip(&self.free) {
            full[g] = r;
        }
    }
}

/// Test fixtures shared by the solver modules' unit tests.
#[cfg(test)]
pub(crate) mod test_bars {
    use super::{BoxMesh, DofMap, ElementOp, SymMatrix, assemble, fe_pattern};

    /// M + c K of the Q1 bar `mesh` clamped on its top face (ρ = 1, λ = 1/4, μ = 1/2: an SPD
    /// step matrix of the engine's kind), and its dof map.
    pub fn clamped_step_matrix(mesh: &BoxMesh, c: f64) -> (DofMap, SymMatrix) {
        let d = mesh.dim;
        let top = mesh.cells[d - 1];
        let dofs = DofMap::for_nodes(mesh.num_nodes(), d, |n, _| mesh.node_index(n)[d - 1] == top);
        let p = fe_pattern(mesh, &dofs);
        let m = assemble(mesh, &dofs, &p, ElementOp::Mass { rho: 1.0 }, &|_| 1.0);
        let k = assemble(
            mesh,
            &dofs,
            &p,
            ElementOp::Stiffness {
                lambda: 0.25,
                mu: 0.5,
            },
            &|_| 1.0,
        );
        (dofs, SymMatrix::lin_comb(1.0, &m, c, &k))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dofmap_round_trip() {
        // 3 nodes × 2 components, node 1 clamped, x of node 2 on a roller.
        let d = DofMap::for_nodes(3, 2, |n, c| n == 1 || (n == 2 && c == 0));
        assert_eq!(d.free, vec![0, 1, 5]);
        assert_eq!(d.free_index(5), Some(2));
        assert_eq!(d.free_index(2), None);
        let full = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let mut red = [0.0; 3];
        d.gather(&full, &mut red);
        assert_eq!(red, [1.0, 2.0, 6.0]);
        let mut back = [0.0; 6];
        d.scatter(&red, &mut back);
        assert_eq!(back, [1.0, 2.0, 0.0, 0.0, 0.0, 6.0]);
    }
}
