//! Element matrices of the vector P1/P2 simplices of Gmsh meshes ([`super::gmsh`], issue 22):
//! 3- and 6-node triangles (2D, plane strain) and 4- and 10-node tetrahedra (3D), the simplicial
//! counterpart of [`super::element`]'s Q1/Q2 kernels.
//!
//! Reference simplex {ξ_k ≥ 0, Σ ξ_k ≤ 1}, barycentric λ_0 = 1 − Σ ξ_k, λ_k = ξ_k; nodes in
//! Gmsh's order (vertices, then the midpoints of the edges: triangle 01, 12, 20; tetrahedron 01,
//! 12, 20, 30, 32, 31); shape functions λ_a (P1), λ_a (2λ_a − 1) and 4 λ_i λ_j (P2).
//! Isoparametric: J = Σ_a x_a ⊗ ∇_ξ N_a, ∇N_a = J⁻ᵀ ∇_ξ N_a, dx = det J dξ, so curved P2 edges are
//! kept. The forms and the dof layout (node-major, local dof a·d + i) are those of
//! [`super::element`]: mass ρ ∫ N_a N_b δ_ij, elasticity ∫ λ div u div v + 2μ ε(u):ε(v) (plane
//! strain in 2D), grad-grad ∫ ∇u:∇v, load ∫ ρ f·v.
//!
//! Quadrature, never a reduced integration: on an affine cell the P2 mass has degree 4, the P2
//! stiffness degree 2, so the rules are exact to degree 4 —
//! - triangles: Dunavant's 6-point rule of degree 4;
//! - tetrahedra: Walkington's 14-point rule of degree 5 (positive weights, unlike Keast's
//!   11-point degree-4 rule whose negative weight would make a lumped or layer-weighted mass
//!   indefinite at a point).
//!
//! A curved P2 cell (midside nodes off the straight edges, e.g. on a Gmsh disc's arc) has det J
//! of degree 2 (triangle) or 3 (tetrahedron), and a mass integrand of degree 6 or 7: it takes
//! the conical-product rule of degree 7 of [`super::quadrature`] (16 or 64 positive weights), so
//! its mass and load are exact on its own geometry (contract §1.6) — a degree-4 rule left a curved
//! boundary triangle's mass entries off by up to 2e-4 (issue 34).

use nalgebra::{SMatrix, SVector};

use super::element::{
    ElementOp, add_point_load, add_point_matrix, det_inv, jacobian, physical_gradients,
};
// Edges of the P2 simplices in Gmsh's order: node d + 1 + k is the midpoint of edge k.
use super::element_kind::{TET_EDGES, TRI_EDGES};
use super::quadrature::{curved_simplex_rule, is_affine};

/// The P1 triangle matrix (3 nodes × 2 components).
pub type P1Mat2 = SMatrix<f64, 6, 6>;
/// The P2 triangle matrix (6 nodes × 2 components).
pub type P2Mat2 = SMatrix<f64, 12, 12>;
/// The P1 tetrahedron matrix (4 nodes × 3 components).
pub type P1Mat3 = SMatrix<f64, 12, 12>;
/// The P2 tetrahedron matrix (10 nodes × 3 components).
pub type P2Mat3 = SMatrix<f64, 30, 30>;

/// Dunavant's degree-4 rule: (ξ, η) and weights on the reference triangle (weights sum to 1/2).
const TRI_RULE: [([f64; 3], f64); 6] = {
    const A1: f64 = 0.445_948_490_915_964_9;
    const B1: f64 = 1.0 - 2.0 * A1;
    const W1: f64 = 0.5 * 0.223_381_589_678_011_47;
    const A2: f64 = 0.091_576_213_509_770_74;
    const B2: f64 = 1.0 - 2.0 * A2;
    const W2: f64 = 0.5 * 0.109_951_743_655_321_87;
    [
        ([A1, A1, 0.0], W1),
        ([B1, A1, 0.0], W1),
        ([A1, B1, 0.0], W1),
        ([A2, A2, 0.0], W2),
        ([B2, A2, 0.0], W2),
        ([A2, B2, 0.0], W2),
    ]
};

/// Walkington's 14-point degree-5 rule on the reference tetrahedron (weights sum to 1/6): two
/// orbits of 4 points (λ = (a, a, a, 1 − 3a)) and one of 6 (λ = (a, a, ½ − a, ½ − a)).
const TET_RULE: [([f64; 3], f64); 14] = {
    const A1: f64 = 0.310_885_919_263_300_6;
    const B1: f64 = 1.0 - 3.0 * A1;
    const W1: f64 = 0.018_781_320_953_002_643;
    const A2: f64 = 0.092_735_250_310_891_22;
    const B2: f64 = 1.0 - 3.0 * A2;
    const W2: f64 = 0.012_248_840_519_393_659;
    const A3: f64 = 0.045_503_704_125_649_65;
    const B3: f64 = 0.5 - A3;
    const W3: f64 = 0.007_091_003_462_846_911;
    [
        ([A1, A1, A1], W1),
        ([B1, A1, A1], W1),
        ([A1, B1, A1], W1),
        ([A1, A1, B1], W1),
        ([A2, A2, A2], W2),
        ([B2, A2, A2], W2),
        ([A2, B2, A2], W2),
        ([A2, A2, B2], W2),
        // (λ_0, λ_1, λ_2, λ_3) with two coordinates A3 and two B3: ξ = (λ_1, λ_2, λ_3).
        ([A3, A3, B3], W3),
        ([A3, B3, A3], W3),
        ([B3, A3, A3], W3),
        ([B3, B3, A3], W3),
        ([B3, A3, B3], W3),
        ([A3, B3, B3], W3),
    ]
};

/// The quadrature rule of the reference simplex of dimension `d` (points padded to 3
/// coordinates): degree 4 on triangles, degree 5 on tetrahedra.
pub fn simplex_rule(d: usize) -> &'static [([f64; 3], f64)] {
    match d {
        2 => &TRI_RULE,
        3 => &TET_RULE,
        _ => unreachable!("simplices exist in 2D and 3D only"),
    }
}

/// Shape functions (P1 if NN = D + 1, P2 if NN = (D + 1)(D + 2)/2) and their reference
/// gradients at ξ.
pub fn simplex_shape<const D: usize, const NN: usize>(xi: [f64; D]) -> ([f64; NN], [[f64; D]; NN]) {
    const {
        assert!(D == 2 || D == 3, "simplices exist in 2D and 3D");
        assert!(
            NN == D + 1 || NN == (D + 1) * (D + 2) / 2,
            "P1 or P2 simplices"
        );
    };
    let mut lam = [0.0; 4];
    let mut dlam = [[0.0; D]; 4];
    lam[0] = 1.0 - xi.iter().sum::<f64>();
    for k in 0..D {
        lam[k + 1] = xi[k];
        dlam[0][k] = -1.0;
        dlam[k + 1][k] = 1.0;
    }
    let mut n = [0.0; NN];
    let mut dn = [[0.0; D]; NN];
    if NN == D + 1 {
        n.copy_from_slice(&lam[..NN]);
        dn.copy_from_slice(&dlam[..NN]);
        return (n, dn);
    }
    for a in 0..=D {
        n[a] = lam[a] * (2.0 * lam[a] - 1.0);
        for k in 0..D {
            dn[a][k] = (4.0 * lam[a] - 1.0) * dlam[a][k];
        }
    }
    let edges: &[(usize, usize)] = if D == 2 { &TRI_EDGES } else { &TET_EDGES };
    for (e, &(i, j)) in edges.iter().enumerate() {
        n[D + 1 + e] = 4.0 * lam[i] * lam[j];
        for k in 0..D {
            dn[D + 1 + e][k] = 4.0 * (lam[j] * dlam[i][k] + lam[i] * dlam[j][k]);
        }
    }
    (n, dn)
}

/// Shape functions, physical gradients and det J at ξ of the simplex with node coordinates `x`.
///
/// # Panics
/// If det J ≤ 0 (inverted or degenerate: [`super::GmshMesh`] refuses such meshes on reading).
pub fn simplex_map_at<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    xi: [f64; D],
) -> ([f64; NN], [[f64; D]; NN], f64) {
    let (n, dn) = simplex_shape::<D, NN>(xi);
    let (det, inv) = det_inv(&jacobian(x, &dn));
    assert!(
        det > 0.0,
        "simplex with det J = {det} ≤ 0 (inverted or degenerate)"
    );
    (n, physical_gradients(&inv, &dn), det)
}

/// Calls `f(N, ∇N, w·det J)` at each point of the simplex's rule ([`simplex_rule`]).
pub fn simplex_for_each_point<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    mut f: impl FnMut(&[f64; NN], &[[f64; D]; NN], f64),
) {
    // Curved P2 cells take the rule exact for their mass (det J quadratic/cubic); affine ones
    // keep the cheaper rule, exact there ([`super::quadrature`]).
    let rule = if NN > D + 1 && !is_affine(vertex_jacobians(x)) {
        curved_simplex_rule(D)
    } else {
        simplex_rule(D)
    };
    for &(p, w) in rule {
        let mut xi = [0.0; D];
        xi.copy_from_slice(&p[..D]);
        let (n, g, det) = simplex_map_at(x, xi);
        f(&n, &g, w * det);
    }
}

/// The Jacobian of the simplex's map at its vertices: a P2 map's Jacobian is linear, so these
/// determine it ([`is_affine`]).
fn vertex_jacobians<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
) -> impl Iterator<Item = [[f64; D]; D]> + '_ {
    (0..=D).map(move |v| {
        let mut xi = [0.0; D];
        if v > 0 {
            xi[v - 1] = 1.0;
        }
        let (_, dn) = simplex_shape::<D, NN>(xi);
        jacobian(x, &dn)
    })
}

/// The element matrix of `op` for the simplex with node coordinates `x`.
pub fn simplex_element_matrix<const D: usize, const NN: usize, const ND: usize>(
    op: ElementOp,
    x: &[[f64; D]; NN],
) -> SMatrix<f64, ND, ND> {
    const { assert!(ND == D * NN) };
    let mut m = SMatrix::<f64, ND, ND>::zeros();
    simplex_for_each_point(x, |n, g, dv| add_point_matrix(op, &mut m, n, g, dv));
    m
}

/// Volume load ∫ ρ f·v for a constant body force density f (first D components used).
pub fn simplex_load<const D: usize, const NN: usize, const ND: usize>(
    x: &[[f64; D]; NN],
    rho: f64,
    f: [f64; 3],
) -> SVector<f64, ND> {
    const { assert!(ND == D * NN) };
    let mut r = SVector::<f64, ND>::zeros();
    simplex_for_each_point(x, |n, _, dv| {
        add_point_load::<D, NN, ND>(&mut r, rho, f, n, dv)
    });
    r
}

/// Shape functions and reference gradients of the triangle (P1: NN = 3, P2: NN = 6).
pub fn tri_shape<const NN: usize>(xi: [f64; 2]) -> ([f64; NN], [[f64; 2]; NN]) {
    simplex_shape::<2, NN>(xi)
}

/// [`simplex_map_at`] of a triangle.
pub fn tri_map_at<const NN: usize>(
    x: &[[f64; 2]; NN],
    xi: [f64; 2],
) -> ([f64; NN], [[f64; 2]; NN], f64) {
    simplex_map_at(x, xi)
}

/// The element matrix of `op` for the triangle with node coordinates `x`.
pub fn tri_element_matrix<const NN: usize, const ND: usize>(
    op: ElementOp,
    x: &[[f64; 2]; NN],
) -> SMatrix<f64, ND, ND> {
    simplex_element_matrix(op, x)
}

/// Vector mass matrix ρ ∫ N_a N_b δ_ij of a triangle.
pub fn tri_mass<const NN: usize, const ND: usize>(
    x: &[[f64; 2]; NN],
    rho: f64,
) -> SMatrix<f64, ND, ND> {
    simplex_element_matrix(ElementOp::Mass { rho }, x)
}

/// Plane-strain elasticity stiffness ∫ λ div u div v + 2μ ε(u):ε(v) of a triangle.
pub fn tri_stiffness<const NN: usize, const ND: usize>(
    x: &[[f64; 2]; NN],
    lambda: f64,
    mu: f64,
) -> SMatrix<f64, ND, ND> {
    simplex_element_matrix(ElementOp::Stiffness { lambda, mu }, x)
}

/// Vector mass matrix ρ ∫ N_a N_b δ_ij of a tetrahedron (P1: NN = 4, P2: NN = 10).
pub fn tet_mass<const NN: usize, const ND: usize>(
    x: &[[f64; 3]; NN],
    rho: f64,
) -> SMatrix<f64, ND, ND> {
    simplex_element_matrix(ElementOp::Mass { rho }, x)
}

/// Elasticity stiffness ∫ λ div u div v + 2μ ε(u):ε(v) of a tetrahedron.
pub fn tet_stiffness<const NN: usize, const ND: usize>(
    x: &[[f64; 3]; NN],
    lambda: f64,
    mu: f64,
) -> SMatrix<f64, ND, ND> {
    simplex_element_matrix(ElementOp::Stiffness { lambda, mu }, x)
}

/// ∫ ∇u : ∇v of a tetrahedron (δ_ij ∫ ∇N_a·∇N_b).
pub fn tet_grad_grad<const NN: usize, const ND: usize>(x: &[[f64; 3]; NN]) -> SMatrix<f64, ND, ND> {
    simplex_element_matrix(ElementOp::GradGrad, x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ ξ^a η^b ζ^c over the reference simplex = a! b! c! / (a + b + c + d)!.
    fn exact_monomial(d: usize, e: [u32; 3]) -> f64 {
        let f = |n: u32| (1..=n).map(f64::from).product::<f64>();
        f(e[0]) * f(e[1]) * f(e[2]) / f(e[0] + e[1] + e[2] + d as u32)
    }

    #[test]
    fn rules_are_exact_to_their_degree() {
        // Every monomial of degree ≤ 4 (triangle) / ≤ 5 (tetrahedron): the sum of ≤ 14 products
        // of size ≤ 1/6 agrees to round-off (~1e-17); 1e-15 leaves room for the rule's
        // 20-digit constants, a wrong digit would show at ~1e-10 or worse.
        for (d, deg) in [(2usize, 4u32), (3, 5)] {
            for a in 0..=deg {
                for b in 0..=deg - a {
                    for c in 0..=if d == 3 { deg - a - b } else { 0 } {
                        let q: f64 = simplex_rule(d)
                            .iter()
                            .map(|(p, w)| {
                                w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32)
                            })
                            .sum();
                        let want = exact_monomial(d, [a, b, c]);
                        assert!(
                            (q - want).abs() < 1e-15,
                            "d {d} ({a},{b},{c}): {q} vs {want}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn p2_tet_shape_functions_are_nodal_and_sum_to_one() {
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let mut nodes = v.to_vec();
        for (i, j) in TET_EDGES {
            nodes.push([0, 1, 2].map(|k| 0.5 * (v[i][k] + v[j][k])));
        }
        for (a, xi) in nodes.iter().enumerate() {
            let (n, dn) = simplex_shape::<3, 10>(*xi);
            for (b, nb) in n.iter().enumerate() {
                let want = if a == b { 1.0 } else { 0.0 };
                // Products of exact binary fractions: exact.
                assert_eq!(*nb, want, "N_{b} at node {a}");
            }
            for k in 0..3 {
                let s: f64 = dn.iter().map(|g| g[k]).sum();
                assert!(s.abs() < 1e-15, "Σ ∂N/∂ξ_{k} = {s}");
            }
        }
    }
}
