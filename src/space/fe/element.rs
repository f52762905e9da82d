//! Element matrices of the vector tensor Lagrange elements, isoparametric: Q1 (bilinear squares,
//! trilinear cubes) and Q2 (9-node quadrilaterals, 27-node hexahedra — the degree-2 elements of
//! the disc and ball, contract §1.3).
//!
//! Reference element [−1, 1]^d with (p+1)^d nodes in tensor order (local node a has index
//! i_k = ⌊a/(p+1)^k⌋ mod (p+1) along axis k, at ξ_k = −1 + 2 i_k/p; for Q1 this is bit k of a) and
//! shape functions N_a(ξ) = Π_k L_{i_k}(ξ_k), the 1D Lagrange polynomials of degree p.
//! At each quadrature point the Jacobian J = Σ_a x_a ⊗ ∇_ξ N_a maps the reference gradients to
//! physical ones, ∇N_a = J⁻ᵀ ∇_ξ N_a, and dx = det J dξ — nothing assumes the box's constant
//! Jacobian, so distorted (mapped) elements use the same code.
//!
//! Element dofs are node-major like the global ones: local dof a·d + i is component i of node a.
//! With isotropic elasticity (2D = plane strain) the forms are
//! - mass        M_{ai,bj} = δ_ij ∫ ρ N_a N_b,
//! - stiffness   K_{ai,bj} = ∫ λ ∂_i N_a ∂_j N_b + μ (δ_ij ∇N_a·∇N_b + ∂_j N_a ∂_i N_b)
//!   (the bilinear form ∫ λ div u div v + 2μ ε(u):ε(v)),
//! - grad-grad   G_{ai,bj} = δ_ij ∫ ∇N_a·∇N_b (full vector gradient, for H1 error norms),
//! - load        F_{ai} = ∫ ρ f_i N_a.
//!
//! Quadrature: Gauss–Legendre with p + 1 points per direction (2 for Q1, 3 for Q2) on affine
//! cells (parallelograms, parallelepipeds), where it is exact for the mass, stiffness and load —
//! the matrices of contract §1.2, never a reduced integration. On a mapped (curved or distorted)
//! cell det J is a polynomial too and the mass integrand N_a N_b det J has degree 7 per variable
//! (Q2, 2D), 9 (Q2, 3D), 4 (Q1, 3D) or 3 (Q1, 2D): such cells take 4, 5, 3 or 2 points per
//! direction, exact for their mass and load ([`super::quadrature`], contract §1.6). The stiffness
//! integrand of a mapped cell is rational; the same rule still integrates ∫ ∇N_a exactly (the
//! cofactor of J is polynomial), which is what the patch test needs.
//!
//! The kernels are generic over the dimension `D`, the node count `NN` and the dof count
//! `ND = D·NN` (checked at compile time), so the 2D and 3D paths share one code; the concrete
//! sizes are [`Q1Mat2`] (8×8), [`Q1Mat3`] (24×24), [`Q2Mat2`] (18×18) and [`Q2Mat3`] (81×81).
//! The `q1_*` names are historical: every kernel takes Q1 or Q2 by its node count NN.

use nalgebra::{SMatrix, SVector};

use super::quadrature::{curved_tensor_points, is_affine};

/// The 2D Q1 element matrix (4 nodes × 2 components).
pub type Q1Mat2 = SMatrix<f64, 8, 8>;
/// The 3D Q1 element matrix (8 nodes × 3 components).
pub type Q1Mat3 = SMatrix<f64, 24, 24>;
/// The 2D Q2 element matrix (9 nodes × 2 components).
pub type Q2Mat2 = SMatrix<f64, 18, 18>;
/// The 3D Q2 element matrix (27 nodes × 3 components).
pub type Q2Mat3 = SMatrix<f64, 81, 81>;

/// Which element bilinear form to compute (see the module header).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ElementOp {
    /// Vector mass ρ ∫ N_a N_b δ_ij.
    Mass { rho: f64 },
    /// Isotropic linear elasticity (plane strain in 2D).
    Stiffness { lambda: f64, mu: f64 },
    /// ∫ ∇u : ∇v (full vector gradient).
    GradGrad,
}

/// Gauss–Legendre points and weights on [−1, 1] (2 points: exact to degree 3).
const GAUSS2: [(f64, f64); 2] = [
    (-0.577_350_269_189_625_8, 1.0),
    (0.577_350_269_189_625_8, 1.0),
];

/// Gauss–Legendre rule with `n` points on [−1, 1] (exact to degree 2n − 1), n = 1 … 6: 2 points
/// for Q1, 3 for Q2 element matrices, 3 (order 5 ≥ 4, contract §1.3) on the faces of Γ_C, more for
/// error norms and the tests' exact measures.
///
/// # Panics
/// If n is 0 or > 6.
pub fn gauss_legendre(n: usize) -> &'static [(f64, f64)] {
    const G1: [(f64, f64); 1] = [(0.0, 2.0)];
    const G3: [(f64, f64); 3] = [
        (-0.774_596_669_241_483_4, 5.0 / 9.0),
        (0.0, 8.0 / 9.0),
        (0.774_596_669_241_483_4, 5.0 / 9.0),
    ];
    const G4: [(f64, f64); 4] = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    const G5: [(f64, f64); 5] = [
        (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
        (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.0, 0.568_888_888_888_888_9),
        (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.906_179_845_938_664, 0.236_926_885_056_189_1),
    ];
    const G6: [(f64, f64); 6] = [
        (-0.932_469_514_203_152, 0.171_324_492_379_170_3),
        (-0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
        (-0.238_619_186_083_196_9, 0.467_913_934_572_691_1),
        (0.238_619_186_083_196_9, 0.467_913_934_572_691_1),
        (0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
        (0.932_469_514_203_152, 0.171_324_492_379_170_3),
    ];
    match n {
        1 => &G1,
        2 => &GAUSS2,
        3 => &G3,
        4 => &G4,
        5 => &G5,
        6 => &G6,
        _ => panic!("gauss_legendre: {n} points is not tabulated (1 … 6)"),
    }
}

/// Nodes per axis of a tensor Lagrange element with NN nodes in dimension D: 2 (Q1) or 3 (Q2).
pub const fn nodes_per_axis(d: usize, nn: usize) -> usize {
    if nn == 1 << d {
        2
    } else if nn == 3usize.pow(d as u32) {
        3
    } else {
        panic!("tensor Lagrange elements have 2^d (Q1) or 3^d (Q2) nodes")
    }
}

/// One-dimensional Lagrange basis of degree n1 − 1 on the equispaced nodes of [−1, 1] and its
/// derivative: (1 ∓ ξ)/2 for Q1; ξ(ξ−1)/2, 1 − ξ², ξ(ξ+1)/2 for Q2 (nodes −1, 0, 1).
pub fn lagrange_1d(n1: usize, i: usize, xi: f64) -> (f64, f64) {
    match (n1, i) {
        (2, 0) => (0.5 * (1.0 - xi), -0.5),
        (2, 1) => (0.5 * (1.0 + xi), 0.5),
        (3, 0) => (0.5 * xi * (xi - 1.0), xi - 0.5),
        (3, 1) => (1.0 - xi * xi, -2.0 * xi),
        (3, 2) => (0.5 * xi * (xi + 1.0), xi + 0.5),
        _ => panic!("lagrange_1d: node {i} of a {n1}-node basis"),
    }
}

/// Tensor Lagrange shape functions (Q1 or Q2, by NN) and their reference gradients at ξ. Local
/// node a has index i_k = ⌊a / n1^k⌋ mod n1 along axis k (x fastest); for Q1 that is bit k of a.
pub fn shape<const D: usize, const NN: usize>(xi: [f64; D]) -> ([f64; NN], [[f64; D]; NN]) {
    let n1 = const { nodes_per_axis(D, NN) };
    let mut n = [0.0; NN];
    let mut dn = [[0.0; D]; NN];
    for a in 0..NN {
        let mut f = [0.0; D];
        let mut df = [0.0; D];
        let mut r = a;
        for k in 0..D {
            (f[k], df[k]) = lagrange_1d(n1, r % n1, xi[k]);
            r /= n1;
        }
        n[a] = f.iter().product();
        for j in 0..D {
            dn[a][j] = (0..D).map(|k| if k == j { df[k] } else { f[k] }).product();
        }
    }
    (n, dn)
}

/// Determinant and inverse of a 2×2 or 3×3 matrix (cofactor formulas).
pub(crate) fn det_inv<const D: usize>(j: &[[f64; D]; D]) -> (f64, [[f64; D]; D]) {
    let mut inv = [[0.0; D]; D];
    let det = match D {
        2 => {
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            inv[0][0] = j[1][1] / det;
            inv[0][1] = -j[0][1] / det;
            inv[1][0] = -j[1][0] / det;
            inv[1][1] = j[0][0] / det;
            det
        }
        3 => {
            // inv = adj(J)/det, adj_ik = cofactor_ki.
            let c = |r: usize, s: usize| {
                let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
                let (s1, s2) = ((s + 1) % 3, (s + 2) % 3);
                j[r1][s1] * j[r2][s2] - j[r1][s2] * j[r2][s1]
            };
            let det = j[0][0] * c(0, 0) + j[0][1] * c(0, 1) + j[0][2] * c(0, 2);
            for i in 0..3 {
                for k in 0..3 {
                    inv[i][k] = c(k, i) / det;
                }
            }
            det
        }
        _ => unreachable!("elements exist in 2D and 3D only"),
    };
    (det, inv)
}

/// Shape functions, physical gradients and det J at reference point ξ of the element with node
/// coordinates `x`.
///
/// # Panics
/// If det J ≤ 0 (inverted or degenerate element: a mesh construction bug; the structured meshes
/// never produce one).
pub fn map_at<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    xi: [f64; D],
) -> ([f64; NN], [[f64; D]; NN], f64) {
    let (n, dn) = shape::<D, NN>(xi);
    let (det, jinv) = det_inv(&jacobian(x, &dn));
    assert!(
        det > 0.0,
        "element with det J = {det} ≤ 0 (inverted or degenerate element)"
    );
    (n, physical_gradients(&jinv, &dn), det)
}

/// Σ_a x_a ⊗ g_a (`[i][j]` = Σ_a x_a,i g_a,j): with the reference gradients ∇_ξ N_a, the
/// Jacobian ∂x/∂ξ of the map of the cell with node coordinates `x`; with the physical
/// gradients and nodal displacements, the displacement gradient ∇u. Every isoparametric kernel
/// (boxes and simplices) forms it this way.
pub(crate) fn jacobian<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    g: &[[f64; D]; NN],
) -> [[f64; D]; D] {
    let mut jac = [[0.0; D]; D];
    for a in 0..NN {
        for i in 0..D {
            for j in 0..D {
                jac[i][j] += x[a][i] * g[a][j];
            }
        }
    }
    jac
}

/// The physical gradients ∇N_a = J⁻ᵀ ∇_ξ N_a, i.e. g_i = Σ_j (J⁻¹)_ji ∂_ξj N_a, from J⁻¹ and
/// the reference gradients `dn`.
pub(crate) fn physical_gradients<const D: usize, const NN: usize>(
    jinv: &[[f64; D]; D],
    dn: &[[f64; D]; NN],
) -> [[f64; D]; NN] {
    let mut g = [[0.0; D]; NN];
    for a in 0..NN {
        for i in 0..D {
            g[a][i] = (0..D).map(|j| jinv[j][i] * dn[a][j]).sum();
        }
    }
    g
}

/// Calls `f(N, ∇N, w·det J)` at each Gauss point of the element with node coordinates `x`: the
/// element's own rule, n1 points per direction on an affine cell (2 for Q1 — exact on boxes,
/// contract §1.2 — and 3 for Q2), more on a mapped one so that its mass is exact (module header).
fn for_each_point<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    f: impl FnMut(&[f64; NN], &[[f64; D]; NN], f64),
) {
    let n1 = const { nodes_per_axis(D, NN) };
    let points = if is_affine(tensor_node_jacobians(x)) {
        n1
    } else {
        curved_tensor_points(D, n1)
    };
    for_each_point_with(x, points, f)
}

/// The Jacobian of the cell's map at each of its reference nodes (tensor order), which
/// determine it ([`is_affine`]).
fn tensor_node_jacobians<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
) -> impl Iterator<Item = [[f64; D]; D]> + '_ {
    let n1 = const { nodes_per_axis(D, NN) };
    (0..NN).map(move |b| {
        let mut xi = [0.0; D];
        let mut r = b;
        for xk in xi.iter_mut() {
            *xk = -1.0 + 2.0 * (r % n1) as f64 / (n1 - 1) as f64;
            r /= n1;
        }
        let (_, dn) = shape::<D, NN>(xi);
        jacobian(x, &dn)
    })
}

/// Calls `f(N, ∇N, w·det J)` at each point of the tensor Gauss rule with `points` points per
/// direction (error norms and exact measures use more points than the element matrices).
pub fn for_each_point_with<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    points: usize,
    mut f: impl FnMut(&[f64; NN], &[[f64; D]; NN], f64),
) {
    let rule = gauss_legendre(points);
    let total = points.pow(D as u32);
    for q in 0..total {
        let mut xi = [0.0; D];
        let mut w = 1.0;
        let mut r = q;
        for xk in xi.iter_mut() {
            let (p, wk) = rule[r % points];
            *xk = p;
            w *= wk;
            r /= points;
        }
        let (n, g, det) = map_at(x, xi);
        f(&n, &g, w * det);
    }
}

/// The displacement gradient ∇u (`[i][j]` = ∂u_i/∂x_j) at reference point ξ ∈ [−1, 1]^D of the
/// element with node coordinates `x` and nodal displacements `u` (strains and stresses).
pub fn q1_gradient_at<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    u: &[[f64; D]; NN],
    xi: [f64; D],
) -> [[f64; D]; D] {
    let (_, g, _) = map_at(x, xi);
    jacobian(u, &g)
}

/// The element matrix of `op` for the element with node coordinates `x`.
pub fn element_matrix<const D: usize, const NN: usize, const ND: usize>(
    op: ElementOp,
    x: &[[f64; D]; NN],
) -> SMatrix<f64, ND, ND> {
    const { assert!(ND == D * NN) };
    let mut m = SMatrix::<f64, ND, ND>::zeros();
    for_each_point(x, |n, g, dv| add_point_matrix(op, &mut m, n, g, dv));
    m
}

/// Adds one quadrature point's share of `op` (shape values N, physical gradients ∇N and
/// w·det J there) to the element matrix `m`: the one integrand of the box and simplex kernels.
pub(crate) fn add_point_matrix<const D: usize, const NN: usize, const ND: usize>(
    op: ElementOp,
    m: &mut SMatrix<f64, ND, ND>,
    n: &[f64; NN],
    g: &[[f64; D]; NN],
    dv: f64,
) {
    match op {
        ElementOp::Mass { rho } => {
            for a in 0..NN {
                for b in 0..NN {
                    let v = rho * n[a] * n[b] * dv;
                    for i in 0..D {
                        m[(a * D + i, b * D + i)] += v;
                    }
                }
            }
        }
        ElementOp::Stiffness { lambda, mu } => {
            for a in 0..NN {
                for b in 0..NN {
                    let gab: f64 = (0..D).map(|l| g[a][l] * g[b][l]).sum();
                    for i in 0..D {
                        for j in 0..D {
                            let mut v = lambda * g[a][i] * g[b][j] + mu * g[a][j] * g[b][i];
                            if i == j {
                                v += mu * gab;
                            }
                            m[(a * D + i, b * D + j)] += v * dv;
                        }
                    }
                }
            }
        }
        ElementOp::GradGrad => {
            for a in 0..NN {
                for b in 0..NN {
                    let gab: f64 = (0..D).map(|l| g[a][l] * g[b][l]).sum();
                    for i in 0..D {
                        m[(a * D + i, b * D + i)] += gab * dv;
                    }
                }
            }
        }
    }
}

/// Vector mass matrix ρ ∫ N_a N_b δ_ij.
pub fn q1_mass<const D: usize, const NN: usize, const ND: usize>(
    x: &[[f64; D]; NN],
    rho: f64,
) -> SMatrix<f64, ND, ND> {
    element_matrix(ElementOp::Mass { rho }, x)
}

/// Isotropic elasticity stiffness ∫ λ div u div v + 2μ ε(u):ε(v) (plane strain in 2D).
pub fn q1_stiffness<const D: usize, const NN: usize, const ND: usize>(
    x: &[[f64; D]; NN],
    lambda: f64,
    mu: f64,
) -> SMatrix<f64, ND, ND> {
    element_matrix(ElementOp::Stiffness { lambda, mu }, x)
}

/// ∫ ∇u : ∇v, the full vector gradient (δ_ij ∫ ∇N_a·∇N_b).
pub fn q1_grad_grad<const D: usize, const NN: usize, const ND: usize>(
    x: &[[f64; D]; NN],
) -> SMatrix<f64, ND, ND> {
    element_matrix(ElementOp::GradGrad, x)
}

/// Volume load ∫ ρ f·v for a constant body force density f (only the first D components used).
pub fn q1_load<const D: usize, const NN: usize, const ND: usize>(
    x: &[[f64; D]; NN],
    rho: f64,
    f: [f64; 3],
) -> SVector<f64, ND> {
    const { assert!(ND == D * NN) };
    let mut r = SVector::<f64, ND>::zeros();
    for_each_point(x, |n, _, dv| {
        add_point_load::<D, NN, ND>(&mut r, rho, f, n, dv)
    });
    r
}

/// Adds one quadrature point's share of the load ∫ ρ f·v (shape values N and w·det J there)
/// to `r`: the one integrand of the box and simplex loads.
pub(crate) fn add_point_load<const D: usize, const NN: usize, const ND: usize>(
    r: &mut SVector<f64, ND>,
    rho: f64,
    f: [f64; 3],
    n: &[f64; NN],
    dv: f64,
) {
    for a in 0..NN {
        for i in 0..D {
            r[a * D + i] += rho * f[i] * n[a] * dv;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(h: f64) -> [[f64; 2]; 4] {
        [[0.0, 0.0], [h, 0.0], [0.0, h], [h, h]]
    }

    #[test]
    fn shape_functions_partition_unity() {
        // Σ N_a = 1 and Σ ∇_ξ N_a = 0 at an arbitrary point: exact polynomial identities, so only
        // rounding (a few ulps) remains.
        let (n, dn) = shape::<3, 8>([0.3, -0.7, 0.1]);
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        for j in 0..3 {
            assert!(dn.iter().map(|d| d[j]).sum::<f64>().abs() < 1e-15);
        }
    }

    #[test]
    fn element_matrices_are_symmetric() {
        // A distorted quadrilateral: symmetry is structural (same sums in both orders up to
        // rounding of a few terms of size ≤ λ+2μ), so 1e-14 absolute.
        let x = [[0.0, 0.0], [1.1, 0.1], [-0.1, 0.9], [1.2, 1.3]];
        let k: Q1Mat2 = q1_stiffness(&x, 0.25, 0.5);
        let m: Q1Mat2 = q1_mass(&x, 1.0);
        assert!((k - k.transpose()).amax() < 1e-14);
        assert!((m - m.transpose()).amax() < 1e-14);
    }

    #[test]
    fn gauss_rules_are_exact_to_their_degree() {
        // ∫_{−1}^{1} ξ^k = 2/(k+1) for even k, 0 for odd: exact for k ≤ 2n − 1 up to the rounding
        // of the tabulated 16-digit nodes and weights (≤ 1e-15).
        for n in 1..=6 {
            for k in 0..2 * n {
                let q: f64 = gauss_legendre(n)
                    .iter()
                    .map(|(x, w)| w * x.powi(k as i32))
                    .sum();
                let exact = if k % 2 == 0 {
                    2.0 / (k as f64 + 1.0)
                } else {
                    0.0
                };
                assert!(
                    (q - exact).abs() < 1e-15,
                    "n = {n}, k = {k}: {q} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn q2_shape_functions_are_nodal() {
        // N_a(ξ_b) = δ_ab at the 27 nodes, Σ N_a = 1 and Σ ∇N_a = 0 anywhere: polynomial
        // identities with small integers and halves, exact up to a few ulps.
        for b in 0..27 {
            let xi = [
                (b % 3) as f64 - 1.0,
                ((b / 3) % 3) as f64 - 1.0,
                (b / 9) as f64 - 1.0,
            ];
            let (n, _) = shape::<3, 27>(xi);
            for (a, na) in n.iter().enumerate() {
                assert_eq!(*na, if a == b { 1.0 } else { 0.0 });
            }
        }
        let (n, dn) = shape::<2, 9>([0.3, -0.7]);
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        for j in 0..2 {
            assert!(dn.iter().map(|d| d[j]).sum::<f64>().abs() < 1e-15);
        }
    }

    #[test]
    fn load_sums_to_force_times_volume() {
        // Σ_a F_ai = ρ f_i |e| since Σ N_a = 1; exact quadrature of a linear det J → 1e-15.
        let x = square(0.5);
        let f: SVector<f64, 8> = q1_load(&x, 2.0, [1.0, -3.0, 0.0]);
        let fx: f64 = (0..4).map(|a| f[2 * a]).sum();
        let fy: f64 = (0..4).map(|a| f[2 * a + 1]).sum();
        assert!((fx - 2.0 * 0.25).abs() < 1e-15);
        assert!((fy + 2.0 * 3.0 * 0.25).abs() < 1e-15);
    }
}
