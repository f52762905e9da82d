//! Element matrices of the vector P1 (3-node) and P2 (6-node) triangles of Gmsh meshes
//! ([`super::gmsh`], issue 22), the simplicial counterpart of [`super::element`]'s Q1/Q2 kernels.
//!
//! Reference triangle {ξ, η ≥ 0, ξ + η ≤ 1}, barycentric λ_0 = 1 − ξ − η, λ_1 = ξ, λ_2 = η; nodes
//! in Gmsh's order (vertices, then the midpoints of edges 01, 12, 20); shape functions λ_a (P1),
//! λ_a (2λ_a − 1) and 4 λ_i λ_j (P2). Isoparametric: J = Σ_a x_a ⊗ ∇_ξ N_a, ∇N_a = J⁻ᵀ ∇_ξ N_a,
//! dx = det J dξ, so curved P2 edges are kept. The forms and the dof layout (node-major, local dof
//! a·2 + i) are those of [`super::element`]: mass ρ ∫ N_a N_b δ_ij, plane-strain elasticity
//! ∫ λ div u div v + 2μ ε(u):ε(v).
//!
//! Quadrature: the 6-point Dunavant rule of degree 4, exact for the P2 mass (degree 4) and the
//! P2 stiffness (degree 2) on affine triangles — as the Q1/Q2 rules, never a reduced
//! integration.

use nalgebra::SMatrix;

use super::element::ElementOp;

/// The P1 triangle matrix (3 nodes × 2 components).
pub type P1Mat2 = SMatrix<f64, 6, 6>;
/// The P2 triangle matrix (6 nodes × 2 components).
pub type P2Mat2 = SMatrix<f64, 12, 12>;

/// Dunavant's degree-4 rule: (ξ, η) and weights on the reference triangle (weights sum to 1/2).
const RULE4: [([f64; 2], f64); 6] = {
    const A1: f64 = 0.445_948_490_915_964_9;
    const B1: f64 = 1.0 - 2.0 * A1;
    const W1: f64 = 0.5 * 0.223_381_589_678_011_47;
    const A2: f64 = 0.091_576_213_509_770_74;
    const B2: f64 = 1.0 - 2.0 * A2;
    const W2: f64 = 0.5 * 0.109_951_743_655_321_87;
    [
        ([A1, A1], W1),
        ([B1, A1], W1),
        ([A1, B1], W1),
        ([A2, A2], W2),
        ([B2, A2], W2),
        ([A2, B2], W2),
    ]
};

/// Edges of the P2 triangle, Gmsh's order: node 3 + k is the midpoint of edge k.
const EDGES: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];

/// Shape functions (P1 if NN = 3, P2 if NN = 6) and their reference gradients at ξ.
pub fn tri_shape<const NN: usize>(xi: [f64; 2]) -> ([f64; NN], [[f64; 2]; NN]) {
    const { assert!(NN == 3 || NN == 6, "triangles have 3 or 6 nodes") };
    let lam = [1.0 - xi[0] - xi[1], xi[0], xi[1]];
    let dlam = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
    let mut n = [0.0; NN];
    let mut dn = [[0.0; 2]; NN];
    if NN == 3 {
        n[..3].copy_from_slice(&lam);
        dn[..3].copy_from_slice(&dlam);
        return (n, dn);
    }
    for a in 0..3 {
        n[a] = lam[a] * (2.0 * lam[a] - 1.0);
        for k in 0..2 {
            dn[a][k] = (4.0 * lam[a] - 1.0) * dlam[a][k];
        }
    }
    for (e, &(i, j)) in EDGES.iter().enumerate() {
        n[3 + e] = 4.0 * lam[i] * lam[j];
        for k in 0..2 {
            dn[3 + e][k] = 4.0 * (lam[j] * dlam[i][k] + lam[i] * dlam[j][k]);
        }
    }
    (n, dn)
}

/// Shape functions, physical gradients and det J at ξ of the triangle with node coordinates `x`.
///
/// # Panics
/// If det J ≤ 0 (inverted or degenerate: [`super::GmshMesh`] refuses such meshes on reading).
pub fn tri_map_at<const NN: usize>(
    x: &[[f64; 2]; NN],
    xi: [f64; 2],
) -> ([f64; NN], [[f64; 2]; NN], f64) {
    let (n, dn) = tri_shape::<NN>(xi);
    let mut j = [[0.0; 2]; 2];
    for a in 0..NN {
        for i in 0..2 {
            for k in 0..2 {
                j[i][k] += x[a][i] * dn[a][k];
            }
        }
    }
    let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    assert!(
        det > 0.0,
        "triangle with det J = {det} ≤ 0 (inverted or degenerate)"
    );
    let inv = [
        [j[1][1] / det, -j[0][1] / det],
        [-j[1][0] / det, j[0][0] / det],
    ];
    let mut g = [[0.0; 2]; NN];
    for a in 0..NN {
        for i in 0..2 {
            g[a][i] = inv[0][i] * dn[a][0] + inv[1][i] * dn[a][1];
        }
    }
    (n, g, det)
}

/// Calls `f(N, ∇N, w·det J)` at each point of the degree-4 rule.
fn for_each_point<const NN: usize>(
    x: &[[f64; 2]; NN],
    mut f: impl FnMut(&[f64; NN], &[[f64; 2]; NN], f64),
) {
    for &(xi, w) in &RULE4 {
        let (n, g, det) = tri_map_at(x, xi);
        f(&n, &g, w * det);
    }
}

/// The element matrix of `op` for the triangle with node coordinates `x`.
pub fn tri_element_matrix<const NN: usize, const ND: usize>(
    op: ElementOp,
    x: &[[f64; 2]; NN],
) -> SMatrix<f64, ND, ND> {
    const { assert!(ND == 2 * NN) };
    let mut m = SMatrix::<f64, ND, ND>::zeros();
    for_each_point(x, |n, g, dv| {
        for a in 0..NN {
            for b in 0..NN {
                let gab = g[a][0] * g[b][0] + g[a][1] * g[b][1];
                for i in 0..2 {
                    for j in 0..2 {
                        let v = match op {
                            ElementOp::Mass { rho } => {
                                if i == j {
                                    rho * n[a] * n[b]
                                } else {
                                    0.0
                                }
                            }
                            ElementOp::Stiffness { lambda, mu } => {
                                lambda * g[a][i] * g[b][j]
                                    + mu * g[a][j] * g[b][i]
                                    + if i == j { mu * gab } else { 0.0 }
                            }
                            ElementOp::GradGrad => {
                                if i == j {
                                    gab
                                } else {
                                    0.0
                                }
                            }
                        };
                        m[(a * 2 + i, b * 2 + j)] += v * dv;
                    }
                }
            }
        }
    });
    m
}

/// Vector mass matrix ρ ∫ N_a N_b δ_ij.
pub fn tri_mass<const NN: usize, const ND: usize>(
    x: &[[f64; 2]; NN],
    rho: f64,
) -> SMatrix<f64, ND, ND> {
    tri_element_matrix(ElementOp::Mass { rho }, x)
}

/// Plane-strain elasticity stiffness ∫ λ div u div v + 2μ ε(u):ε(v).
pub fn tri_stiffness<const NN: usize, const ND: usize>(
    x: &[[f64; 2]; NN],
    lambda: f64,
    mu: f64,
) -> SMatrix<f64, ND, ND> {
    tri_element_matrix(ElementOp::Stiffness { lambda, mu }, x)
}
