//! Curved degree-2 cells are integrated exactly on their own geometry (contract §1.6, issue 34):
//! every element mass matrix of a curved P2 triangle, P2 tetrahedron, Q2 quadrilateral and Q2
//! hexahedron (and a distorted Q1 hexahedron) equals the one a much higher-order rule gives —
//! degree 14+ in 2D, 10+ in 3D — to 1e-13 relative, and so does the load ∫ρ f·φ.
//!
//! Why 1e-13: the engine's rules are exact for these integrands (polynomials of degree 6, 7, 7
//! per variable, 9 per variable, 4 per variable), as are the reference rules; what remains is
//! round-off of sums of ≤ 125 products of O(1) terms (~1e-15) — 1e-13 leaves a factor 100. The
//! rule of before (degree 4 on triangles) misses by ~1e-4 on the same cells: each test checks
//! that a too-low rule is visibly off, so it could fail.

use contact_sweep::space::fe::element::{ElementOp, element_matrix, gauss_legendre, map_at};
use contact_sweep::space::fe::quadrature::{collapsed_simplex_rule, gauss_legendre_any};
use contact_sweep::space::fe::simplex::{
    simplex_element_matrix, simplex_load, simplex_map_at, simplex_rule,
};
use nalgebra::SMatrix;

const RHO: f64 = 1.7;

/// Mass matrix by an explicit simplex rule (reference or too-low).
fn simplex_mass_with<const D: usize, const NN: usize, const ND: usize>(
    x: &[[f64; D]; NN],
    rule: &[([f64; 3], f64)],
) -> SMatrix<f64, ND, ND> {
    let mut m = SMatrix::<f64, ND, ND>::zeros();
    for &(p, w) in rule {
        let mut xi = [0.0; D];
        xi.copy_from_slice(&p[..D]);
        let (n, _, det) = simplex_map_at::<D, NN>(x, xi);
        let dv = w * det;
        for a in 0..NN {
            for b in 0..NN {
                for i in 0..D {
                    m[(a * D + i, b * D + i)] += RHO * n[a] * n[b] * dv;
                }
            }
        }
    }
    m
}

/// Mass matrix by an explicit tensor Gauss rule with `rule` points per direction.
fn tensor_mass_with<const D: usize, const NN: usize, const ND: usize>(
    x: &[[f64; D]; NN],
    rule: &[(f64, f64)],
) -> SMatrix<f64, ND, ND> {
    let mut m = SMatrix::<f64, ND, ND>::zeros();
    let n1 = rule.len();
    for q in 0..n1.pow(D as u32) {
        let mut xi = [0.0; D];
        let mut w = 1.0;
        let mut r = q;
        for xk in xi.iter_mut() {
            *xk = rule[r % n1].0;
            w *= rule[r % n1].1;
            r /= n1;
        }
        let (n, _, det) = map_at::<D, NN>(x, xi);
        for a in 0..NN {
            for b in 0..NN {
                for i in 0..D {
                    m[(a * D + i, b * D + i)] += RHO * n[a] * n[b] * w * det;
                }
            }
        }
    }
    m
}

fn rel_diff<const N: usize>(a: &SMatrix<f64, N, N>, b: &SMatrix<f64, N, N>) -> f64 {
    (a - b).abs().max() / b.abs().max()
}

/// A P2 triangle with its edge 0–1 bent into an arc-like curve (midside node pushed outwards
/// by 15 % of the edge) and its other midside nodes slightly off: det J quadratic, positive.
fn curved_tri() -> [[f64; 2]; 6] {
    let v = [[0.0, 0.0], [2.0, 0.3], [0.4, 1.8]];
    let mid = |i: usize, j: usize| [(v[i][0] + v[j][0]) / 2.0, (v[i][1] + v[j][1]) / 2.0];
    let m01 = mid(0, 1);
    let m12 = mid(1, 2);
    let m20 = mid(2, 0);
    [
        v[0],
        v[1],
        v[2],
        [m01[0] + 0.045, m01[1] - 0.3],
        [m12[0] + 0.05, m12[1] + 0.04],
        [m20[0] - 0.03, m20[1] + 0.02],
    ]
}

fn curved_tet() -> [[f64; 3]; 10] {
    let v = [
        [0.0, 0.0, 0.0],
        [1.5, 0.1, 0.0],
        [0.2, 1.4, 0.1],
        [0.1, 0.2, 1.3],
    ];
    let edges = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)];
    let bumps = [
        [0.0, -0.12, -0.05],
        [0.08, 0.06, 0.0],
        [-0.07, 0.0, 0.03],
        [0.0, -0.05, 0.04],
        [0.05, 0.05, 0.05],
        [0.06, -0.03, 0.05],
    ];
    let mut x = [[0.0; 3]; 10];
    x[..4].copy_from_slice(&v);
    for (k, &(i, j)) in edges.iter().enumerate() {
        for c in 0..3 {
            x[4 + k][c] = 0.5 * (v[i][c] + v[j][c]) + bumps[k][c];
        }
    }
    x
}

/// A mapped Q2 quadrilateral as in the disc's O-grid: the unit square's top edge bent into an
/// arc (tensor node order, x fastest), plus a skew.
fn curved_quad9() -> [[f64; 2]; 9] {
    let mut x = [[0.0; 2]; 9];
    for j in 0..3 {
        for i in 0..3 {
            let (s, t) = (i as f64 / 2.0, j as f64 / 2.0);
            let bulge = 0.25 * t * (1.0 - (2.0 * s - 1.0).powi(2));
            x[3 * j + i] = [s + 0.2 * t + 0.05 * s * t, t + bulge];
        }
    }
    x
}

fn curved_hex<const NN: usize>() -> [[f64; 3]; NN] {
    let n1 = if NN == 8 { 2 } else { 3 };
    let mut x = [[0.0; 3]; NN];
    for (a, xa) in x.iter_mut().enumerate() {
        let (i, j, k) = (a % n1, (a / n1) % n1, a / (n1 * n1));
        let h = (n1 - 1) as f64;
        let (s, t, r) = (i as f64 / h, j as f64 / h, k as f64 / h);
        *xa = [
            s + 0.15 * t * r + 0.1 * s * r,
            t + 0.2 * s * r - 0.05 * s * t,
            r + 0.2 * r * s * (1.0 - s) + 0.1 * t * s + 0.05 * s * t * r,
        ];
    }
    x
}

#[test]
fn curved_p2_triangle_mass_equals_a_degree_15_rule() {
    let x = curved_tri();
    let engine: SMatrix<f64, 12, 12> = simplex_element_matrix(ElementOp::Mass { rho: RHO }, &x);
    let reference = simplex_mass_with::<2, 6, 12>(&x, &collapsed_simplex_rule(2, 8));
    let d = rel_diff(&engine, &reference);
    eprintln!("curved P2 triangle mass: engine against the reference rule {d:.2e}");
    assert!(d <= 1e-13, "curved P2 triangle mass: {d:.2e}");
    // The degree-4 rule of affine cells is visibly off on this cell.
    let low = simplex_mass_with::<2, 6, 12>(&x, simplex_rule(2));
    assert!(rel_diff(&low, &reference) > 1e-5);
    // Load ∫ρ f·φ: the reference load is the mass times f on every node (Σφ = 1).
    let f = [0.3, -1.1, 0.0];
    let load: nalgebra::SVector<f64, 12> = simplex_load(&x, RHO, f);
    for a in 0..6 {
        for i in 0..2 {
            let r: f64 = (0..6)
                .map(|b| reference[(2 * a + i, 2 * b + i)] * f[i])
                .sum();
            assert!((load[2 * a + i] - r).abs() <= 1e-13 * reference.abs().max());
        }
    }
}

#[test]
fn curved_p2_tetrahedron_mass_equals_a_degree_11_rule() {
    let x = curved_tet();
    let engine: SMatrix<f64, 30, 30> = simplex_element_matrix(ElementOp::Mass { rho: RHO }, &x);
    let reference = simplex_mass_with::<3, 10, 30>(&x, &collapsed_simplex_rule(3, 6));
    let d = rel_diff(&engine, &reference);
    eprintln!("curved P2 tetrahedron mass: engine against the reference rule {d:.2e}");
    assert!(d <= 1e-13, "curved P2 tetrahedron mass: {d:.2e}");
    let low = simplex_mass_with::<3, 10, 30>(&x, simplex_rule(3));
    assert!(rel_diff(&low, &reference) > 1e-6);
}

#[test]
fn curved_q2_quadrilateral_mass_equals_a_degree_15_rule() {
    let x = curved_quad9();
    let engine: SMatrix<f64, 18, 18> = element_matrix(ElementOp::Mass { rho: RHO }, &x);
    let reference = tensor_mass_with::<2, 9, 18>(&x, &gauss_legendre_any(8));
    let d = rel_diff(&engine, &reference);
    eprintln!("curved Q2 quadrilateral mass: engine against the reference rule {d:.2e}");
    assert!(d <= 1e-13, "curved Q2 quadrilateral mass: {d:.2e}");
    let low = tensor_mass_with::<2, 9, 18>(&x, gauss_legendre(3));
    assert!(rel_diff(&low, &reference) > 1e-6);
}

#[test]
fn curved_q2_hexahedron_mass_equals_a_degree_11_rule() {
    let x = curved_hex::<27>();
    let engine: SMatrix<f64, 81, 81> = element_matrix(ElementOp::Mass { rho: RHO }, &x);
    let reference = tensor_mass_with::<3, 27, 81>(&x, &gauss_legendre_any(6));
    let d = rel_diff(&engine, &reference);
    eprintln!("curved Q2 hexahedron mass: engine against the reference rule {d:.2e}");
    assert!(d <= 1e-13, "curved Q2 hexahedron mass: {d:.2e}");
    let low = tensor_mass_with::<3, 27, 81>(&x, gauss_legendre(3));
    assert!(rel_diff(&low, &reference) > 1e-7);
}

#[test]
fn distorted_q1_hexahedron_mass_equals_a_degree_11_rule() {
    let x = curved_hex::<8>();
    let engine: SMatrix<f64, 24, 24> = element_matrix(ElementOp::Mass { rho: RHO }, &x);
    let reference = tensor_mass_with::<3, 8, 24>(&x, &gauss_legendre_any(6));
    let d = rel_diff(&engine, &reference);
    eprintln!("distorted Q1 hexahedron mass: engine against the reference rule {d:.2e}");
    assert!(d <= 1e-13, "distorted Q1 hexahedron mass: {d:.2e}");
    let low = tensor_mass_with::<3, 8, 24>(&x, gauss_legendre(2));
    assert!(rel_diff(&low, &reference) > 1e-7);
}

#[test]
fn affine_cells_keep_their_rule_bit_for_bit() {
    // A straight-sided P2 triangle (midside nodes at the midpoints): the affine rule, exact
    // there, is kept — the same matrix to the last bit as the degree-4 rule gives.
    let v = [[0.0, 0.0], [2.0, 0.3], [0.4, 1.8]];
    let mid = |i: usize, j: usize| [(v[i][0] + v[j][0]) / 2.0, (v[i][1] + v[j][1]) / 2.0];
    let x = [v[0], v[1], v[2], mid(0, 1), mid(1, 2), mid(2, 0)];
    let engine: SMatrix<f64, 12, 12> = simplex_element_matrix(ElementOp::Mass { rho: RHO }, &x);
    let low = simplex_mass_with::<2, 6, 12>(&x, simplex_rule(2));
    let reference = simplex_mass_with::<2, 6, 12>(&x, &collapsed_simplex_rule(2, 8));
    assert_eq!(engine, low);
    assert!(rel_diff(&engine, &reference) <= 1e-14);
}
