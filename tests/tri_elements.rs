//! Verification of the P1/P2 triangles on their own (issue 22, "done when" 1, first part), as
//! tests/fe_elements.rs does for Q1/Q2: the hand-computed P1 mass, total mass ρ|Ω_h| on the Gmsh
//! squares, rigid motions with zero strain energy, and the exact energy of a linear field.

use std::path::PathBuf;

use contact_sweep::space::fe::simplex::{tri_mass, tri_stiffness};
use contact_sweep::space::fe::{ElementKind, GmshMesh, Mesh, P1Mat2, P2Mat2};
use nalgebra::SMatrix;

const RHO: f64 = 2.5;
const LAMBDA: f64 = 1.7;
const MU: f64 = 0.9;

fn mesh(name: &str) -> GmshMesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("sweeps/meshes")
        .join(name);
    GmshMesh::read(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn cell<const NN: usize>(m: &GmshMesh, e: usize) -> [[f64; 2]; NN] {
    let mut x = [[0.0; 2]; NN];
    for (xa, &n) in x.iter_mut().zip(m.element_nodes(e)) {
        let c = m.coord(n);
        *xa = [c[0], c[1]];
    }
    x
}

/// Per cell: (1ᵀ M_e 1 for component x, max |K_e r| over the rigid motions r, max |K_e|,
/// u_eᵀ K_e u_e for the linear field u(x) = A x).
fn per_cell<const NN: usize, const ND: usize>(
    m: &GmshMesh,
    a: [[f64; 2]; 2],
) -> Vec<(f64, f64, f64, f64)> {
    (0..m.num_elements())
        .map(|e| {
            let x = cell::<NN>(m, e);
            let mm: SMatrix<f64, ND, ND> = tri_mass(&x, RHO);
            let k: SMatrix<f64, ND, ND> = tri_stiffness(&x, LAMBDA, MU);
            let mut ones = SMatrix::<f64, ND, 1>::zeros();
            for i in 0..NN {
                ones[2 * i] = 1.0;
            }
            let mass = (ones.transpose() * mm * ones)[0];
            let rigid = |f: &dyn Fn([f64; 2]) -> [f64; 2]| {
                let mut u = SMatrix::<f64, ND, 1>::zeros();
                for (i, xa) in x.iter().enumerate() {
                    let v = f(*xa);
                    u[2 * i] = v[0];
                    u[2 * i + 1] = v[1];
                }
                u
            };
            let res = [
                rigid(&|_| [1.0, 0.0]),
                rigid(&|_| [0.0, 1.0]),
                rigid(&|p| [-p[1], p[0]]),
            ]
            .iter()
            .map(|u| (k * u).amax())
            .fold(0.0, f64::max);
            let lin = rigid(&|p| {
                [
                    a[0][0] * p[0] + a[0][1] * p[1],
                    a[1][0] * p[0] + a[1][1] * p[1],
                ]
            });
            (mass, res, k.amax(), (lin.transpose() * k * lin)[0])
        })
        .collect()
}

/// ∫_Ω λ (tr ε)² + 2μ ε:ε for u = A x on |Ω| = 1.
fn linear_energy(a: [[f64; 2]; 2]) -> f64 {
    let e = [
        [a[0][0], 0.5 * (a[0][1] + a[1][0])],
        [0.5 * (a[0][1] + a[1][0]), a[1][1]],
    ];
    let tr = e[0][0] + e[1][1];
    let ee: f64 = e.iter().flatten().map(|v| v * v).sum();
    LAMBDA * tr * tr + 2.0 * MU * ee
}

fn check<const NN: usize, const ND: usize>(m: &GmshMesh) {
    let a = [[0.3, -0.7], [0.4, 1.1]];
    let cells = per_cell::<NN, ND>(m, a);
    // Total mass = ρ |Ω_h| = ρ (the unit square, exact for affine cells): 32 cell masses, each
    // exact up to a few ulps of the degree-4 rule, sum to ~1e-15.
    let total: f64 = cells.iter().map(|c| c.0).sum();
    assert!((total - RHO * m.measure()).abs() < 1e-13, "{total}");
    assert!((total - RHO).abs() < 1e-13, "{total}");
    for (e, c) in cells.iter().enumerate() {
        // Rigid motions: K_e r = 0 up to round-off of a sum of ~ND terms of size max|K_e|
        // (times |r| ≤ 1.5 for the rotation on the unit square).
        assert!(
            c.1 <= 1e-13 * c.2,
            "cell {e}: |K r| = {} vs |K| = {}",
            c.1,
            c.2
        );
    }
    // A linear field is represented exactly, so Σ u_eᵀ K_e u_e is the exact ∫ λ (tr ε)² + 2μ ε:ε
    // (5.753 here): 32 cell energies, each a sum of ~ND² products of size ~|K_e|·|u|², agree to
    // ~1e-15 relative; 1e-13 relative leaves room for the ND = 12 of P2.
    let energy: f64 = cells.iter().map(|c| c.3).sum();
    let want = linear_energy(a);
    assert!((energy - want).abs() < 1e-13 * want, "{energy} vs {want}");
}

#[test]
fn p1_mass_by_hand() {
    // The P1 mass on a triangle of area |K|: ρ|K|/12 [[2,1,1],[1,2,1],[1,1,2]] per component.
    let x = [[0.0, 0.0], [2.0, 0.0], [0.5, 1.5]];
    let area = 1.5;
    let m: P1Mat2 = tri_mass(&x, RHO);
    for a in 0..3 {
        for b in 0..3 {
            let want = RHO * area / 12.0 * if a == b { 2.0 } else { 1.0 };
            // Degree-4 rule on a degree-2 integrand: exact to round-off (~1e-16 relative).
            assert!((m[(2 * a, 2 * b)] - want).abs() < 1e-14, "{a} {b}");
            assert!((m[(2 * a + 1, 2 * b + 1)] - want).abs() < 1e-14);
            assert_eq!(m[(2 * a, 2 * b + 1)], 0.0);
        }
    }
}

#[test]
fn p2_mass_vertex_and_edge_sums() {
    // P2: ∫ N_vertex = 0 and ∫ N_edge = |K|/3, so the row sums of M (one component) are ρ·0 and
    // ρ|K|/3 — a check of the degree-4 rule and of the shape functions together.
    let x = [
        [0.0, 0.0],
        [2.0, 0.0],
        [0.5, 1.5],
        [1.0, 0.0],
        [1.25, 0.75],
        [0.25, 0.75],
    ];
    let m: P2Mat2 = tri_mass(&x, RHO);
    for a in 0..6 {
        let row: f64 = (0..6).map(|b| m[(2 * a, 2 * b)]).sum();
        let want = if a < 3 { 0.0 } else { RHO * 1.5 / 3.0 };
        // Exact to round-off: integrands of degree ≤ 4.
        assert!((row - want).abs() < 1e-14, "node {a}: {row}");
    }
}

#[test]
fn p1_on_the_gmsh_square() {
    let m = mesh("square_tri_p1.msh");
    assert_eq!(m.kind, ElementKind::Tri3);
    check::<3, 6>(&m);
}

#[test]
fn p2_on_the_gmsh_square() {
    let m = mesh("square_tri_p2.msh");
    assert_eq!(m.kind, ElementKind::Tri6);
    check::<6, 12>(&m);
}

#[test]
fn curved_p2_triangle_mass_and_rigid_motions() {
    // Corners (0,0), (1,0), (0,1); the midpoint node of edge 12 moved out to (0.6, 0.6): that
    // edge is the parabola through (1,0), (0.6,0.6), (0,1), which bulges by 0.1·√2 over the
    // chord of length √2, so |K| = 1/2 + (2/3)·√2·0.1√2 = 1/2 + 0.4/3. det J is of degree 1
    // here (degree ≤ 2 in general), the degree-4 rule integrates ρ det J exactly.
    let x = [
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.5, 0.0],
        [0.6, 0.6],
        [0.0, 0.5],
    ];
    let m: P2Mat2 = tri_mass(&x, RHO);
    let total: f64 = (0..6)
        .flat_map(|a| (0..6).map(move |b| (a, b)))
        .map(|(a, b)| m[(2 * a, 2 * b)])
        .sum();
    let area = 0.5 + 0.4 / 3.0;
    // Exact quadrature: round-off of 36 entries of size ~0.1.
    assert!(
        (total - RHO * area).abs() < 1e-13,
        "{total} vs {}",
        RHO * area
    );
    // Isoparametric: x ↦ (1, 0), (0, 1), (−y, x) are in the P2 span of the curved cell, their
    // strain vanishes at every quadrature point, K r = 0 to round-off.
    let k: P2Mat2 = tri_stiffness(&x, LAMBDA, MU);
    for f in [
        |_: [f64; 2]| [1.0, 0.0],
        |_: [f64; 2]| [0.0, 1.0],
        |p: [f64; 2]| [-p[1], p[0]],
    ] {
        let mut u = SMatrix::<f64, 12, 1>::zeros();
        for (a, xa) in x.iter().enumerate() {
            let v = f(*xa);
            u[2 * a] = v[0];
            u[2 * a + 1] = v[1];
        }
        let r = (k * u).amax();
        assert!(r <= 1e-13 * k.amax(), "|K r| = {r} vs |K| = {}", k.amax());
    }
}
