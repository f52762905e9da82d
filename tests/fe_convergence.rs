//! Manufactured elastodynamics on Gmsh-made meshes (issue 22, "done when" 1): the L2 error of
//! every element kind converges at its order — P1 and Q1 at 2, P2 and Q2 at 3 — on refinement
//! families of the unit square (triangles, quadrilaterals) and the unit cube (tetrahedra,
//! hexahedra) generated once by sweeps/meshes/generate.sh (sweeps/meshes/conv/); the P1
//! tetrahedra's finer cubes, which reach the asymptotic regime, are made by Gmsh at test time.
//!
//! The solution u(x, t) = cos(ωt) φ(x), φ = s(x)(1, …, 1), s = Π_k sin(π x_k), vanishes on ∂Ω
//! (all of it clamped) and solves ρ ü − div σ(u) = cos(ωt) g with
//! g = −ρω²φ − (λ + μ)∇(div φ) − μΔφ. Why this form: the semi-discrete problem
//! M ü_h + K u_h = cos(ωt) G (G_i = ∫ g·N_i) started from u_h(0) = w_h = (K − ω²M)⁻¹G,
//! v_h(0) = 0 is solved *exactly* by u_h(t) = cos(ωt) w_h (substitute it), so
//! max_t ‖u_h(t) − u(t)‖_L2 = ‖w_h − φ‖_L2 with no time-discretisation error at all: the fitted
//! rate is the space discretisation's alone (ω = 1 lies below the lowest eigenfrequency, ≈ π√2·
//! √(μ/ρ) ≈ 3.1 in 2D, so K − ω²M is positive definite). Assembly is the engine's
//! (`assemble` on a `GmshMesh`); the load and the error are integrated here with rules exact
//! beyond the element's order (the simplices' degree-4/5 rules, 4 Gauss points per direction
//! on the tensor cells).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use contact_sweep::space::fe::element::for_each_point_with;
use contact_sweep::space::fe::simplex::simplex_for_each_point;
use contact_sweep::space::fe::sparse::element_coords;
use contact_sweep::space::fe::{
    DofMap, ElementOp, GmshMesh, Mesh, SymMatrix, assemble, fe_pattern,
};
use contact_sweep::space::linalg::{Cholesky, SymbolicCholesky};
use contact_sweep::summary::convergence::lsq_slope;

const RHO: f64 = 1.0;
const LAMBDA: f64 = 1.25;
const MU: f64 = 0.5;
const OMEGA: f64 = 1.0;

/// φ(x) and g(x) (module header), in D dimensions.
fn exact<const D: usize>(x: [f64; D]) -> ([f64; D], [f64; D]) {
    let sn: Vec<f64> = x.iter().map(|v| (PI * v).sin()).collect();
    let cs: Vec<f64> = x.iter().map(|v| (PI * v).cos()).collect();
    let s: f64 = sn.iter().product();
    // ∂_i ∂_j s for i ≠ j: π² cos cos Π_{k ≠ i, j} sin; ∂_i² s = −π² s.
    let mixed = |i: usize, j: usize| {
        PI * PI
            * cs[i]
            * cs[j]
            * (0..D)
                .filter(|&k| k != i && k != j)
                .map(|k| sn[k])
                .product::<f64>()
    };
    let phi = [s; D];
    let mut g = [0.0; D];
    for i in 0..D {
        // (∇ div φ)_i = Σ_j ∂_i ∂_j s; Δφ_i = −D π² s.
        let grad_div: f64 = (0..D)
            .map(|j| if j == i { -PI * PI * s } else { mixed(i, j) })
            .sum();
        let lap = -(D as f64) * PI * PI * s;
        g[i] = -RHO * OMEGA * OMEGA * phi[i] - (LAMBDA + MU) * grad_div - MU * lap;
    }
    (phi, g)
}

/// The points of a rule exact beyond the element's order: f(N, w·det J).
type Points<const D: usize, const NN: usize> = fn(&[[f64; D]; NN], &mut dyn FnMut(&[f64; NN], f64));

fn simplex_points<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    f: &mut dyn FnMut(&[f64; NN], f64),
) {
    simplex_for_each_point(x, |n, _, dv| f(n, dv));
}

fn tensor_points<const D: usize, const NN: usize>(
    x: &[[f64; D]; NN],
    f: &mut dyn FnMut(&[f64; NN], f64),
) {
    for_each_point_with(x, 4, |n, _, dv| f(n, dv));
}

fn point<const D: usize, const NN: usize>(x: &[[f64; D]; NN], n: &[f64; NN]) -> [f64; D] {
    let mut p = [0.0; D];
    for (xa, na) in x.iter().zip(n) {
        for k in 0..D {
            p[k] += na * xa[k];
        }
    }
    p
}

/// (h, ‖w_h − φ‖_L2) on one mesh.
fn solve<const D: usize, const NN: usize>(m: &GmshMesh, points: Points<D, NN>) -> (f64, f64) {
    let n = m.num_nodes();
    // The whole boundary ∂Ω is clamped: Gmsh puts its nodes on x_k ∈ {0, 1} to ~1e-13.
    let on_boundary = |v: usize| {
        m.coord(v)[..D]
            .iter()
            .any(|c| c.abs() < 1e-9 || (c - 1.0).abs() < 1e-9)
    };
    let dofs = DofMap::for_nodes(n, D, |v, _| on_boundary(v));
    let p = fe_pattern(m, &dofs);
    let k = assemble(
        m,
        &dofs,
        &p,
        ElementOp::Stiffness {
            lambda: LAMBDA,
            mu: MU,
        },
        &|_| 1.0,
    );
    let mass = assemble(m, &dofs, &p, ElementOp::Mass { rho: RHO }, &|_| 1.0);
    let a = SymMatrix::lin_comb(1.0, &k, -OMEGA * OMEGA, &mass);
    let mut rhs = vec![0.0; dofs.n_free()];
    for e in 0..m.num_elements() {
        let x = element_coords::<GmshMesh, D, NN>(m, e);
        let nodes = m.element_nodes(e);
        points(&x, &mut |nn, dv| {
            let (_, g) = exact(point(&x, nn));
            for (a, &node) in nodes.iter().enumerate() {
                for (c, gc) in g.iter().enumerate() {
                    if let Some(r) = dofs.free_index(node * D + c) {
                        rhs[r] += gc * nn[a] * dv;
                    }
                }
            }
        });
    }
    let chol = Cholesky::new(&SymbolicCholesky::new(&p).unwrap(), &a).unwrap();
    chol.solve_in_place(&mut rhs, &mut chol.work());
    let mut w = vec![0.0; n * D];
    dofs.scatter(&rhs, &mut w);
    let mut err2 = 0.0;
    for e in 0..m.num_elements() {
        let x = element_coords::<GmshMesh, D, NN>(m, e);
        let nodes = m.element_nodes(e);
        points(&x, &mut |nn, dv| {
            let (phi, _) = exact(point(&x, nn));
            for c in 0..D {
                let wh: f64 = nodes
                    .iter()
                    .zip(nn)
                    .map(|(&node, na)| w[node * D + c] * na)
                    .sum();
                err2 += (wh - phi[c]).powi(2) * dv;
            }
        });
    }
    (m.h, err2.sqrt())
}

/// The fitted rate of a family, with its (h, error) points.
fn rate(family: &str, sizes: &[usize]) -> (f64, Vec<(f64, f64)>) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("sweeps/meshes/conv");
    let files: Vec<PathBuf> = sizes
        .iter()
        .map(|n| dir.join(format!("{family}_n{n}.msh")))
        .collect();
    rate_of(&files)
}

/// The fitted rate over mesh files, with the (h, error) points.
fn rate_of(files: &[PathBuf]) -> (f64, Vec<(f64, f64)>) {
    let pts: Vec<(f64, f64)> = files
        .iter()
        .map(|file| {
            let m = GmshMesh::read(file).unwrap_or_else(|e| panic!("{e}"));
            match (m.dim, m.nodes_per_element()) {
                (2, 3) => solve::<2, 3>(&m, simplex_points::<2, 3>),
                (2, 6) => solve::<2, 6>(&m, simplex_points::<2, 6>),
                (2, 4) => solve::<2, 4>(&m, tensor_points::<2, 4>),
                (2, 9) => solve::<2, 9>(&m, tensor_points::<2, 9>),
                (3, 4) => solve::<3, 4>(&m, simplex_points::<3, 4>),
                (3, 10) => solve::<3, 10>(&m, simplex_points::<3, 10>),
                (3, 8) => solve::<3, 8>(&m, tensor_points::<3, 8>),
                (3, 27) => solve::<3, 27>(&m, tensor_points::<3, 27>),
                other => panic!("no element {other:?}"),
            }
        })
        .collect();
    let (h, e): (Vec<f64>, Vec<f64>) = pts.iter().copied().unzip();
    (lsq_slope(&h, &e).unwrap(), pts)
}

fn check(family: &str, sizes: &[usize], order: f64, tol: f64) -> Option<String> {
    let (p, pts) = rate(family, sizes);
    println!("{family}: rate {p:.3} from {pts:?}");
    ((p - order).abs() > tol)
        .then(|| format!("{family}: L2 rate {p:.3}, expected {order} ± {tol} ({pts:?})"))
}

/// Tolerance on the fitted rate. The error of a smooth solution is C h^p (1 + O(h)), so the
/// least-squares slope over levels h_0 > … > h_k deviates from p by O(h_0): the measured local
/// rates approach p from below (P1) or above (P2) level by level. The bound is the coarsest
/// level's share: 2D from h_0 = √2/8 ≈ 0.18 (P1, measured 1.937) or √2/4 ≈ 0.35 (the others:
/// Q1 1.976, P2 3.130, Q2 3.021), ±0.15; 3D from h_0 = √3/2 ≈ 0.87, ±0.3 (measured Q1 1.962,
/// P2 2.946, Q2 2.987).
#[test]
fn square_triangles_and_quadrilaterals() {
    let mut bad = Vec::new();
    for (family, sizes, order) in [
        ("square_tri_p1", &[8, 16, 32][..], 2.0),
        ("square_tri_p2", &[4, 8, 16], 3.0),
        ("square_quad_q1", &[4, 8, 16], 2.0),
        ("square_quad_q2", &[4, 8, 16], 3.0),
    ] {
        bad.extend(check(family, sizes, order, 0.15));
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

#[test]
fn cube_tetrahedra_and_hexahedra() {
    let mut bad = Vec::new();
    for (family, order) in [
        ("cube_tet_p2", 3.0),
        ("cube_hex_q1", 2.0),
        ("cube_hex_q2", 3.0),
    ] {
        bad.extend(check(family, &[2, 3, 4, 6], order, 0.3));
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

/// The unit cube of P1 tetrahedra at n × n × n cube cells (`cube_tet.geo` with N = n), made by
/// Gmsh into `dir` (installed by tests/install_gmsh.sh, as the tests install their tools).
fn gmsh_cube_tets(dir: &Path, n: usize) -> PathBuf {
    static GMSH: OnceLock<()> = OnceLock::new();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    GMSH.get_or_init(|| {
        let o = Command::new("bash")
            .arg(root.join("tests/install_gmsh.sh"))
            .output()
            .expect("bash starts");
        assert!(
            o.status.success(),
            "gmsh is missing and tests/install_gmsh.sh failed:\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
    });
    let geo = std::fs::read_to_string(root.join("sweeps/meshes/cube_tet.geo")).unwrap();
    assert!(geo.contains("\nN = 2;\n"));
    let src = dir.join(format!("cube_tet_n{n}.geo"));
    std::fs::write(&src, geo.replace("\nN = 2;\n", &format!("\nN = {n};\n"))).unwrap();
    let out = dir.join(format!("cube_tet_p1_n{n}.msh"));
    let o = Command::new("gmsh")
        .args(["-v", "1", "-format", "msh41", "-bin", "-3", "-order", "1"])
        .arg(&src)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("gmsh starts");
    assert!(
        o.status.success(),
        "gmsh failed on {}:\n{}",
        src.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    out
}

/// P1 tetrahedra (issue 22 done-when 1: rate 2 in L2 on Gmsh meshes of a cube). The committed
/// cubes (6 tetrahedra per cube cell, n ≤ 8) are pre-asymptotic: local rates 1.16, 1.40, 1.57,
/// 1.70 from n = 2 to 8. Finer levels are made by Gmsh at test time (n = 12, 16, 24: up to
/// 15 625 nodes and 3.9 MB, not committed; the whole test takes ≈ 5 s in release). Measured
/// local rates 1.81 (8 → 12), 1.88 (12 → 16), 1.93 (16 → 24): the gap to 2 shrinks with h.
///
/// The rate is fitted as an error C h^p (1 + a h + O(h²)) asks: ln e = ln C + p ln h + a h
/// (the first-order term of ln(1 + a h)) by least squares over the four finest levels
/// (h ≤ √3/8 = 0.22). Measured p = 2.061 (2.028 … 2.062 from any first level); the neglected
/// O(h²) term moves p by O(h_0²) ≈ 0.05 over these levels, hence ±0.1. The plain two-parameter
/// slope of the same levels is 1.87 — the pre-asymptotic bias the a h term removes. Asserted
/// besides: the local rates rise monotonically and stay below 2 (an error converging from the
/// pre-asymptotic side), and the finest reaches 1.9.
#[test]
fn cube_p1_tetrahedra_converge_at_order_two() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("sweeps/meshes/conv");
    let mut files: Vec<PathBuf> = [2, 3, 4, 6, 8]
        .iter()
        .map(|n| dir.join(format!("cube_tet_p1_n{n}.msh")))
        .collect();
    files.extend([12, 16, 24].map(|n| gmsh_cube_tets(tmp.path(), n)));
    let (_, pts) = rate_of(&files);
    let local: Vec<f64> = pts
        .windows(2)
        .map(|w| (w[1].1 / w[0].1).ln() / (w[1].0 / w[0].0).ln())
        .collect();
    // ln e = c + p ln h + a h: the normal equations of the least-squares fit.
    let finest = &pts[pts.len() - 4..];
    let mut ata = [[0.0; 3]; 3];
    let mut aty = [0.0; 3];
    for &(h, e) in finest {
        let row = [1.0, h.ln(), h];
        for i in 0..3 {
            aty[i] += row[i] * e.ln();
            for j in 0..3 {
                ata[i][j] += row[i] * row[j];
            }
        }
    }
    let p = solve3(ata, aty)[1];
    println!("cube_tet_p1: local rates {local:?} from {pts:?}; fitted p = {p:.4}");
    assert!(local.windows(2).all(|w| w[1] > w[0]), "{local:?}");
    assert!(local.iter().all(|&r| r < 2.0), "{local:?}");
    assert!(*local.last().unwrap() >= 1.9, "{local:?}");
    assert!((p - 2.0).abs() <= 0.1, "fitted p = {p}");
}

/// Cramer's rule for a 3 × 3 system.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        *xk = det(m) / d;
    }
    x
}
