//! Nitsche and the penalty on the bars and the Gmsh meshes (issue 20 "every contact method on
//! every scene", issue 22 "boundary faces of Γ_C with their quadrature"; contract §1.2, §2.3, §2.4,
//! §3.2):
//!
//! - the face quadrature of Γ_C ([`face_contact_points`]) integrates the contact area exactly
//!   on the bars' bottom face and on the `contact` groups of Gmsh meshes of every element kind,
//!   and its σ_n rows are exact on linear fields;
//! - on bar2d, Nitsche (Θ = 1) with the hybrid scheme never increases E_Θ, and the discrete
//!   gradient conserves E_Θ (Nitsche, Θ = 1) and E^h + Φ (penalty) per step;
//! - the papers' question on the same 2D bar: mass redistribution (mixed, mod3) against
//!   Nitsche (Θ = 1, small γ0), both measured against one common reference run.
//!
//! The Gmsh copies of the bars run Nitsche and the penalty as bar2d and bar3d do:
//! `tests/mesh_scenes.rs` (with every other method).
//!
//! Meshes are small (bar2d h = 0.05: 42 nodes) so each test stays well under 10 s in release.

mod common;
use common::outcomes;

use std::path::PathBuf;

use contact_sweep::run::RunRecord;
use contact_sweep::space::fe::nitsche::{
    ContactPoint, box_contact_faces, face_contact_points, gmsh_contact_faces,
};
use contact_sweep::space::fe::{BoxMesh, GmshMesh};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn apply(row: &[f64], dofs: &[usize], u: &[f64]) -> f64 {
    row.iter().zip(dofs).map(|(c, &g)| c * u[g]).sum()
}

/// For u = A x (in every element space here), σ_n(u) = λ tr A + 2μ A_dd at every point; and
/// u = x_d e_d has u_n = −x_d(q) = −(gap + plane). Values ≤ 10·|A|·(λ + 2μ): rounding 1e-12.
fn check_linear_fields(pts: &[ContactPoint], coords: &[[f64; 3]], dim: usize, plane: f64) {
    let a = [[0.3, -0.2, 0.1], [0.15, 0.25, -0.05], [-0.1, 0.2, 0.35]];
    let (lam, mu) = (0.25, 0.5);
    let mut u = vec![0.0; coords.len() * dim];
    let mut ud = vec![0.0; coords.len() * dim];
    for (n, x) in coords.iter().enumerate() {
        for i in 0..dim {
            u[n * dim + i] = (0..dim).map(|j| a[i][j] * x[j]).sum::<f64>();
        }
        ud[n * dim + dim - 1] = x[dim - 1];
    }
    let tr: f64 = (0..dim).map(|i| a[i][i]).sum();
    let want = lam * tr + 2.0 * mu * a[dim - 1][dim - 1];
    for p in pts {
        let sn = apply(&p.sn, &p.dofs, &u);
        assert!((sn - want).abs() < 1e-12, "σ_n {sn} vs {want}");
        let un = apply(&p.un, &p.dofs, &ud);
        assert!(
            (un + p.gap + plane).abs() < 1e-12,
            "u_n {un} vs gap {}",
            p.gap
        );
    }
}

/// Σ_q w_q = |Γ_C|: the bars' bottom face (0.1 in 2D, 0.01 in 3D) and the `contact` groups of
/// the Gmsh meshes (bar2d's box as Q1 quads: 0.1; the unit square and cube: 1) — P1/P2
/// triangles, Q1 quads, P1/P2 tetrahedra, Q1/Q2 hexahedra. The faces are flat, so the measure
/// is integrated exactly by any rule; what remains is rounding of ≤ 100 terms: 1e-13 (the
/// brief's bound), a factor ~10² above the measured ≤ 4.4e-16 (cube_tet.msh). Each point's gap is its
/// height above the plane (0 here: the faces lie at x_d = 0) and its γ (γ0 = 1) the element
/// diameter.
#[test]
fn face_quadrature_integrates_the_contact_area() {
    for (extent, cells, area, diameter) in [
        (vec![0.1, 1.0], vec![2, 20], 0.1, 0.05 * 2f64.sqrt()),
        (
            vec![0.1, 0.1, 1.0],
            vec![2, 2, 20],
            0.01,
            0.05 * 3f64.sqrt(),
        ),
    ] {
        let d = extent.len();
        let mesh = BoxMesh::new(&extent, &cells);
        let faces = box_contact_faces(&mesh);
        assert_eq!(faces.len(), cells[..d - 1].iter().product::<usize>());
        let pts = face_contact_points(&mesh, &faces, 0.25, 0.5, 1.0, 0.0);
        assert_eq!(pts.len(), faces.len() * 3usize.pow(d as u32 - 1));
        let sum: f64 = pts.iter().map(|p| p.weight).sum();
        println!(
            "box {d}D: Σw = {sum:.17} (|Γ_C| = {area}), {} points",
            pts.len()
        );
        assert!((sum - area).abs() < 1e-13, "{d}D: Σw = {sum}");
        for p in &pts {
            // Diameters from coordinates i·0.05 (rounded): within a few ulps of h√d.
            assert!(
                p.gap.abs() < 1e-15 && (p.gamma - diameter).abs() < 1e-14 * diameter,
                "gap {} γ {} vs {diameter}",
                p.gap,
                p.gamma
            );
        }
        check_linear_fields(&pts, &mesh.coords, d, 0.0);
    }
    for (file, area) in [
        ("bar2d_quad.msh", 0.1),
        ("square_tri_p1.msh", 1.0),
        ("square_tri_p2.msh", 1.0),
        ("square_quad_q2.msh", 1.0),
        ("cube_tet.msh", 1.0),
        ("cube_tet_p2.msh", 1.0),
        ("cube_hex_q1.msh", 1.0),
        ("cube_hex_q2.msh", 1.0),
    ] {
        let mesh = GmshMesh::read(&root().join("sweeps/meshes").join(file)).unwrap();
        let group = mesh.group("contact").unwrap();
        let faces = gmsh_contact_faces(&mesh, group).unwrap();
        assert_eq!(faces.len(), group.elements.len());
        let pts = face_contact_points(&mesh, &faces, 0.25, 0.5, 1.0, 0.0);
        let sum: f64 = pts.iter().map(|p| p.weight).sum();
        println!(
            "{file}: Σw = {sum:.17} (|Γ_C| = {area}), {} points",
            pts.len()
        );
        assert!((sum - area).abs() < 1e-13, "{file}: Σw = {sum}");
        check_linear_fields(&pts, &mesh.coords, mesh.dim, 0.0);
        // The points lie on the face x_d = 0 (within the mesh's coordinates' rounding).
        assert!(pts.iter().all(|p| p.gap.abs() < 1e-12), "{file}");
    }
    // A group of cells is not a boundary: refused with the reason.
    let mesh = GmshMesh::read(&root().join("sweeps/meshes/square_tri_p1.msh")).unwrap();
    let e = gmsh_contact_faces(&mesh, mesh.group("body").unwrap()).unwrap_err();
    assert!(e.contains("dimension 2"), "{e}");
}

/// max_n (x^{n+1} − x^n)/scale and max_n |x^{n+1} − x^n|/scale.
fn increase_and_change(x: &[f64], scale: f64) -> (f64, f64) {
    x.windows(2).fold((f64::NEG_INFINITY, 0.0f64), |(i, c), w| {
        let d = (w[1] - w[0]) / scale;
        (i.max(d), c.max(d.abs()))
    })
}

/// bar2d at h = 0.05 over seeded τ and γ0, T = 1.5 (the impact at t = 0.4, the release, the
/// flight back up): Nitsche Θ = 1 with the hybrid scheme never increases E_Θ (003 Cor 3.8) and
/// the discrete gradient conserves E_Θ (Nitsche, Θ = 1) and E^h + Φ (penalty, κ = Eγ0/h_K).
/// Both hold in exact arithmetic; the rounding of energies of size energy_scale (= E⁰) summed
/// over 84 dofs, and the Newton's residual at the round-off of its terms, leave ~1e-14
/// (measured: hybrid's largest rise of E_Θ 1.8e-14, the discrete gradient's largest change
/// 1.3e-14): 1e-12·energy_scale per step is the contract's bound with room, while CN with Nitsche,
/// which does work during contact (003 §4.2), moves E_Θ by 2.3e-2 … 0.85 of it in one step
/// (the counter-check asserts > 1e-8). γ0 ∈ [1e-3, 1e-2] keeps K_Θ coercive on this mesh.
#[test]
fn bar2d_hybrid_and_discrete_gradient_keep_the_energy() {
    let mut rng = fastrand::Rng::with_seed(20);
    for _ in 0..2 {
        let dt = 0.005 + 0.045 * rng.f64();
        let g_nit = 10f64.powf(-3.0 + rng.f64());
        let g_pen = 10f64.powf(1.0 + 2.0 * rng.f64());
        let text = format!(
            r#"
name = "nb"
scene = "bar2d"
[fixed]
T = 1.5
h = 0.05
dt = {dt}
[grid]
method = [
  {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = {g_nit}, scheme = "hybrid" }},
  {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = {g_nit}, scheme = "discrete-gradient" }},
  {{ space = "penalty", penalty_gamma0 = {g_pen}, scheme = "discrete-gradient" }},
  {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = {g_nit}, scheme = "crank-nicolson" }},
]
"#
        );
        let runs = outcomes(&text);
        assert_eq!(runs.len(), 4);
        for (k, (label, o)) in runs.iter().enumerate() {
            let scale = o.metrics.energy_scale.unwrap();
            let conserved = common::kept_energy(label, o);
            let (inc, change) = increase_and_change(&conserved, scale);
            let phases = o.metrics.contact_phases.unwrap();
            println!(
                "bar2d dt = {dt:.5} {label}: max ΔE/scale = {inc:.3e}, max |ΔE|/scale = {change:.3e}, contact phases {phases}, penetration {:?}",
                o.metrics.max_penetration
            );
            assert!(phases >= 1, "{label}: the bar must hit the obstacle");
            match k {
                0 => assert!(inc <= 1e-12, "{label}: E_Θ rose by {inc:e}·scale"),
                1 | 2 => assert!(change <= 1e-12, "{label}: moved by {change:e}·scale"),
                _ => assert!(change > 1e-8, "{label}: CN moved E_Θ by only {change:e}"),
            }
        }
    }
}

/// The papers' question "mass redistribution against Nitsche on the same 2D bar": bar2d at
/// h = 0.05, τ = 0.0125, T = 2, mixed with mod3 and Nitsche (Θ = 1, γ0 = 1e-3) with the
/// energy-conserving hybrid scheme and Crank–Nicolson, all against one reference: mixed mod3
/// Crank–Nicolson on the nested mesh h = 0.025 with τ = 0.003125 (contract §1.2). Measured:
///   mixed mod3 CN      err_u_l2l2 1.040e-3, err_u_l2h1 3.052e-2, energy drift  5.7e-4;
///   Nitsche hybrid     err_u_l2l2 1.436e-3, err_u_l2h1 3.650e-2, energy drift −1.9e-2;
///   Nitsche CN         err_u_l2l2 8.059e-3, err_u_l2h1 1.509e-1, energy drift  1.25.
/// So the energy-stable Nitsche scheme (hybrid) and mass redistribution are of the same order
/// (ratios 1.38 and 1.20): asserted within [½, 2], the same-order claim with the measured
/// ratios well inside. Nitsche with plain CN gains energy at the impact (003 §4.2) and is 7.7
/// and 4.9 times worse: asserted as behaviour, more than 3 times mod3's error in both norms.
#[test]
fn bar2d_mass_redistribution_against_nitsche() {
    let text = r#"
name = "mr-nitsche"
scene = "bar2d"
reference = { h = 0.025, dt = 0.003125, space = "mixed", mass = "mod3", scheme = "crank-nicolson" }
[fixed]
T = 2.0
h = 0.05
dt = 0.0125
[grid]
method = [
  { space = "mixed", mass = "mod3", scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "hybrid" },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "crank-nicolson" },
]
"#;
    let rows: Vec<RunRecord> = common::run_sweep_text(text);
    assert_eq!(rows.len(), 3);
    for r in &rows {
        assert_eq!(r.status, "ok", "{:?}", r.message);
        println!(
            "{} {} {}: err_u_l2l2 {:.4e}, err_u_l2h1 {:.4e}, err_u_contact_max {:.4e}, energy drift {:.3e}, max penetration {:.3e}",
            r.space,
            r.mass,
            r.scheme_label,
            r.err_u_l2l2.unwrap(),
            r.err_u_l2h1.unwrap(),
            r.err_u_contact_max.unwrap(),
            r.energy_drift.unwrap(),
            r.max_penetration.unwrap()
        );
    }
    let ratios = |r: &RunRecord| {
        [
            r.err_u_l2l2.unwrap() / rows[0].err_u_l2l2.unwrap(),
            r.err_u_l2h1.unwrap() / rows[0].err_u_l2h1.unwrap(),
        ]
    };
    for ratio in ratios(&rows[1]) {
        assert!((0.5..2.0).contains(&ratio), "hybrid / mod3: {ratio}");
    }
    for ratio in ratios(&rows[2]) {
        assert!(ratio > 3.0, "Nitsche CN / mod3: {ratio}");
    }
}
