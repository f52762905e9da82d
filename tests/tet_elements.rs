//! Verification of the P1/P2 tetrahedra on their own (issue 22, "done when" 1), as
//! tests/fe_elements.rs does for Q1/Q2 and tests/tri_elements.rs for the triangles: the
//! hand-computed P1 mass and P2 row sums, total mass ρ|Ω_h| on the Gmsh cubes, rigid motions with
//! zero strain energy (straight and curved cells), the exact energy of a linear field, and the
//! patch test (boundary values of a linear field reproduce it inside).

use std::path::PathBuf;

use contact_sweep::space::fe::simplex::{tet_grad_grad, tet_mass, tet_stiffness};
use contact_sweep::space::fe::sparse::element_coords;
use contact_sweep::space::fe::{
    DofMap, ElementKind, ElementOp, GmshMesh, Mesh, P1Mat3, P2Mat3, assemble, fe_pattern,
};
use contact_sweep::space::linalg::{Cholesky, SymbolicCholesky};
use nalgebra::SMatrix;

const RHO: f64 = 2.5;
const LAMBDA: f64 = 1.7;
const MU: f64 = 0.9;
/// A linear field u(x) = A x + b used by the energy and patch tests.
const A: [[f64; 3]; 3] = [[0.3, -0.7, 0.2], [0.4, 1.1, -0.5], [-0.6, 0.25, 0.8]];
const B: [f64; 3] = [0.1, -0.2, 0.3];

fn mesh(name: &str) -> GmshMesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("sweeps/meshes")
        .join(name);
    GmshMesh::read(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn linear(p: [f64; 3]) -> [f64; 3] {
    let mut u = B;
    for i in 0..3 {
        for j in 0..3 {
            u[i] += A[i][j] * p[j];
        }
    }
    u
}

/// The energy density λ (tr ε)² + 2μ ε:ε of the linear field (its ∫ over a body of volume V is
/// V times this).
fn linear_energy_density() -> f64 {
    let e = |i: usize, j: usize| 0.5 * (A[i][j] + A[j][i]);
    let tr = e(0, 0) + e(1, 1) + e(2, 2);
    let ee: f64 = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| e(i, j) * e(i, j))
        .sum();
    LAMBDA * tr * tr + 2.0 * MU * ee
}

fn nodal<const NN: usize, const ND: usize>(
    x: &[[f64; 3]; NN],
    f: impl Fn([f64; 3]) -> [f64; 3],
) -> SMatrix<f64, ND, 1> {
    let mut u = SMatrix::<f64, ND, 1>::zeros();
    for (a, xa) in x.iter().enumerate() {
        let v = f(*xa);
        for i in 0..3 {
            u[3 * a + i] = v[i];
        }
    }
    u
}

/// The six rigid motions: three translations, three infinitesimal rotations.
fn rigid_motions() -> [fn([f64; 3]) -> [f64; 3]; 6] {
    [
        |_| [1.0, 0.0, 0.0],
        |_| [0.0, 1.0, 0.0],
        |_| [0.0, 0.0, 1.0],
        |p| [-p[1], p[0], 0.0],
        |p| [0.0, -p[2], p[1]],
        |p| [p[2], 0.0, -p[0]],
    ]
}

/// Per cell: (1ᵀM_e1 of component x, max |K_e r| over the rigid motions, max |K_e|, u_eᵀK_eu_e of
/// the linear field, max |G_e r| over the translations).
fn check_cell<const NN: usize, const ND: usize>(x: &[[f64; 3]; NN]) -> (f64, f64, f64, f64, f64) {
    let m: SMatrix<f64, ND, ND> = tet_mass(x, RHO);
    let k: SMatrix<f64, ND, ND> = tet_stiffness(x, LAMBDA, MU);
    let g: SMatrix<f64, ND, ND> = tet_grad_grad(x);
    let ones = nodal::<NN, ND>(x, |_| [1.0, 0.0, 0.0]);
    let mass = (ones.transpose() * m * ones)[0];
    let rigid = rigid_motions()
        .iter()
        .map(|f| (k * nodal::<NN, ND>(x, f)).amax())
        .fold(0.0, f64::max);
    let grad_const = rigid_motions()[..3]
        .iter()
        .map(|f| (g * nodal::<NN, ND>(x, f)).amax())
        .fold(0.0, f64::max);
    let lin = nodal::<NN, ND>(x, linear);
    (
        mass,
        rigid,
        k.amax(),
        (lin.transpose() * k * lin)[0],
        grad_const,
    )
}

fn check_mesh<const NN: usize, const ND: usize>(m: &GmshMesh) {
    let cells: Vec<_> = (0..m.num_elements())
        .map(|e| check_cell::<NN, ND>(&element_coords::<GmshMesh, 3, NN>(m, e)))
        .collect();
    // Total mass = ρ|Ω_h| = ρ (the unit cube, affine cells): 48 cell masses, each exact up to a
    // few ulps of the degree-5 rule, sum to ~1e-15.
    let total: f64 = cells.iter().map(|c| c.0).sum();
    assert!((total - RHO * m.measure()).abs() < 1e-13, "{total}");
    assert!((total - RHO).abs() < 1e-13, "{total}");
    for (e, c) in cells.iter().enumerate() {
        // K_e r = 0 up to round-off of a sum of ND terms of size max|K_e| (|r| ≤ 1.5 on the unit
        // cube): 1e-13 relative is ~100 ε·ND.
        assert!(
            c.1 <= 1e-13 * c.2,
            "cell {e}: |K r| = {} vs |K| = {}",
            c.1,
            c.2
        );
        // ∫∇u:∇v vanishes on constants, the same round-off bound.
        assert!(
            c.4 <= 1e-13 * c.2 / MU.min(LAMBDA),
            "cell {e}: |G 1| = {}",
            c.4
        );
    }
    // A linear field lies in the P1/P2 span: the sum of the cell energies is the exact
    // ∫ λ(tr ε)² + 2μ ε:ε over the unit cube (5.1 here), to round-off of 48 sums of ~ND²
    // products (~1e-15 relative); 1e-13 relative is the same margin as the triangles.
    let energy: f64 = cells.iter().map(|c| c.3).sum();
    let want = linear_energy_density();
    assert!((energy - want).abs() < 1e-13 * want, "{energy} vs {want}");
}

/// The patch test on a Gmsh cube: the nodes on ∂Ω take the linear field's values, the interior
/// nodes are solved for with the assembled stiffness; they must reproduce the field.
fn patch_test(m: &GmshMesh) {
    let d = 3;
    let on_boundary = |n: usize| {
        let c = m.coord(n);
        // Gmsh writes the faces' coordinates as 0 and 1 exactly or within ~1e-13 (its
        // transfinite interpolation); interior nodes are ≥ 1/4 away.
        c.iter().any(|&v| v.abs() < 1e-9 || (v - 1.0).abs() < 1e-9)
    };
    let n = m.num_nodes();
    let mut exact = vec![0.0; n * d];
    for node in 0..n {
        exact[node * d..(node + 1) * d].copy_from_slice(&linear(m.coord(node)));
    }
    let stiff = ElementOp::Stiffness {
        lambda: LAMBDA,
        mu: MU,
    };
    let all = DofMap::all(n * d);
    let k_full = assemble(m, &all, &fe_pattern(m, &all), stiff, &|_| 1.0);
    let mut lift = exact.clone();
    for node in (0..n).filter(|&v| !on_boundary(v)) {
        lift[node * d..(node + 1) * d].fill(0.0);
    }
    let mut r = vec![0.0; lift.len()];
    k_full.matvec_into(&lift, &mut r);
    let inner = DofMap::for_nodes(n, d, |v, _| on_boundary(v));
    assert!(inner.n_free() > 0, "no interior node");
    let p = fe_pattern(m, &inner);
    let k = assemble(m, &inner, &p, stiff, &|_| 1.0);
    let mut u_in = vec![0.0; inner.n_free()];
    inner.gather(&r, &mut u_in);
    u_in.iter_mut().for_each(|v| *v = -*v);
    let chol = Cholesky::new(&SymbolicCholesky::new(&p).unwrap(), &k).unwrap();
    chol.solve_in_place(&mut u_in, &mut chol.work());
    let mut u = lift;
    inner.scatter(&u_in, &mut u);
    // cond(K_II) ~ (nodes across)² ~ 25 and λ/μ ~ 2: a backward-stable solve leaves ~1e-14;
    // 1e-12 relative to max |u| as for the Q1/Q2 patch tests.
    let umax = exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let err = u
        .iter()
        .zip(&exact)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(
        err <= 1e-12 * umax,
        "interior error {err} (max |u| {umax}, {} interior dofs)",
        inner.n_free()
    );
}

#[test]
fn p1_mass_by_hand() {
    // The P1 mass on a tetrahedron of volume |K|: ρ|K|/20 (2 on the diagonal, 1 off it) per
    // component. Vertices (0,0,0), (2,0,0), (0.5,1.5,0), (0.3,0.2,1.2): |K| = 2·1.5·1.2/6 = 0.6.
    let x = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.5, 1.5, 0.0],
        [0.3, 0.2, 1.2],
    ];
    let vol = 0.6;
    let m: P1Mat3 = tet_mass(&x, RHO);
    for a in 0..4 {
        for b in 0..4 {
            let want = RHO * vol / 20.0 * if a == b { 2.0 } else { 1.0 };
            for i in 0..3 {
                // A degree-2 integrand under a degree-5 rule: exact to round-off (~1e-16).
                assert!(
                    (m[(3 * a + i, 3 * b + i)] - want).abs() < 1e-14,
                    "{a} {b} {i}: {} vs {want}",
                    m[(3 * a + i, 3 * b + i)]
                );
                assert_eq!(m[(3 * a + i, 3 * b + (i + 1) % 3)], 0.0);
            }
        }
    }
}

#[test]
fn p2_mass_vertex_and_edge_sums() {
    // P2 tetrahedron: ∫ N_vertex = −|K|/20, ∫ N_edge = |K|/5, so the row sums of M (one
    // component) are −ρ|K|/20 and ρ|K|/5 — the shape functions and the rule checked together.
    let v = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.5, 1.5, 0.0],
        [0.3, 0.2, 1.2],
    ];
    let mut x = [[0.0; 3]; 10];
    x[..4].copy_from_slice(&v);
    for (k, (i, j)) in [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)]
        .into_iter()
        .enumerate()
    {
        x[4 + k] = [0, 1, 2].map(|c| 0.5 * (v[i][c] + v[j][c]));
    }
    let vol = 0.6;
    let m: P2Mat3 = tet_mass(&x, RHO);
    for a in 0..10 {
        let row: f64 = (0..10).map(|b| m[(3 * a, 3 * b)]).sum();
        let want = RHO * vol * if a < 4 { -1.0 / 20.0 } else { 1.0 / 5.0 };
        // Degree-4 integrands under the degree-5 rule: exact to round-off.
        assert!((row - want).abs() < 1e-14, "node {a}: {row} vs {want}");
    }
}

#[test]
fn p1_on_the_gmsh_cube() {
    let m = mesh("cube_tet.msh");
    assert_eq!(m.kind, ElementKind::Tet4);
    check_mesh::<4, 12>(&m);
    patch_test(&m);
}

#[test]
fn p2_on_the_gmsh_cube() {
    let m = mesh("cube_tet_p2.msh");
    assert_eq!(m.kind, ElementKind::Tet10);
    assert_eq!(m.num_nodes(), 125, "5³ nodes of the 2×2×2 cube at degree 2");
    check_mesh::<10, 30>(&m);
    patch_test(&m);
}

#[test]
fn curved_p2_tetrahedron() {
    // The unit tetrahedron with the midpoint node of edge 12 moved from (½, ½, 0) to
    // (0.6, 0.6, 0): edge 12 becomes a parabola, faces 0-1-2 and 1-2-3 are curved. The P2
    // isoparametric span holds every rigid motion and every linear field.
    let mut x = [[0.0; 3]; 10];
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    x[..4].copy_from_slice(&v);
    for (k, (i, j)) in [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)]
        .into_iter()
        .enumerate()
    {
        x[4 + k] = [0, 1, 2].map(|c| 0.5 * (v[i][c] + v[j][c]));
    }
    x[5] = [0.6, 0.6, 0.0];
    let (mass, rigid, kmax, energy, _) = check_cell::<10, 30>(&x);
    // The map is x = ξ + δ N_5(ξ) with δ = (0.1, 0.1, 0) and N_5 = 4 λ_1 λ_2 = 4 ξ_1 ξ_2, so
    // J = I + δ ⊗ ∇N_5 and det J = 1 + ∇N_5·δ = 1 + 0.4 (ξ_1 + ξ_2); with ∫ ξ_k = 1/24 on the
    // reference tetrahedron, |K| = 1/6 + 0.4·2/24 = 1/6 + 1/30.
    let vol = 1.0 / 6.0 + 1.0 / 30.0;
    // det J has degree 1 here (≤ 3 in general): the degree-5 rule integrates ρ det J exactly;
    // 1e-14 is round-off of 100 entries of size ~0.02.
    assert!((mass - RHO * vol).abs() < 1e-14, "{mass} vs {}", RHO * vol);
    assert!(rigid <= 1e-13 * kmax, "|K r| = {rigid} vs |K| = {kmax}");
    // The linear field's strain is constant, so its energy is the density times the curved
    // volume: ∫ W det J dξ, exact under the rule.
    let want = linear_energy_density() * vol;
    assert!((energy - want).abs() < 1e-13 * want, "{energy} vs {want}");
}
