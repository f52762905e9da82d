//! The `mesh2d`/`mesh3d` scenes (contract §1.6, issue 22): the user's body from a Gmsh file.
//!
//! - issue 22 "done when" 2: the 002 bar meshed by Gmsh as transfinite quadrilaterals
//!   (sweeps/meshes/bar2d_quad.msh: the nodes and Q1 elements of bar2d's box at h = 0.05, in
//!   Gmsh's numbering) reproduces bar2d's runs in every error and energy column;
//! - the plan: h = the mesh's largest element diameter, the id holds the file's content hash
//!   (a copy of the file elsewhere gives the same id; an edited file another), a list of files is
//!   an axis.

mod common;

use std::path::{Path, PathBuf};

use common::run_sweep_text_at;
use contact_sweep::run::RunRecord;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The sweep as if it were `sweeps/NAME.toml` (mesh paths relative to `sweeps/`).
fn run(text: &str) -> Vec<RunRecord> {
    run_sweep_text_at(&root().join("sweeps/test_mesh_scenes.toml"), text)
}

/// Every error and energy column of a run, by name.
fn columns(r: &RunRecord) -> Vec<(&'static str, Option<f64>)> {
    vec![
        ("err_u_l2l2", r.err_u_l2l2),
        ("err_u_l2h1", r.err_u_l2h1),
        ("err_u_linfl2", r.err_u_linfl2),
        ("err_energy_l2", r.err_energy_l2),
        ("err_u_contact_max", r.err_u_contact_max),
        ("err_force_l2", r.err_force_l2),
        ("energy_initial", r.energy_initial),
        ("energy_final", r.energy_final),
        ("energy_drift", r.energy_drift),
        ("energy_max_dev", r.energy_max_dev),
        ("energy_max_increase", r.energy_max_increase),
        ("mass_total", r.mass_total),
        ("max_penetration", r.max_penetration),
        ("first_contact_time", r.first_contact_time),
        ("pressure_oscillation", r.pressure_oscillation),
        ("energy_theta_max_increase", r.energy_theta_max_increase),
        ("energy_theta_drift", r.energy_theta_drift),
    ]
}

/// Runs the sweep body `methods` on the built-in bar `scene` at h = 0.05 and on its Gmsh copy
/// `mesh` (scene `mesh_scene`, velocity −½ as the bars'), with `reference` (a top-level line,
/// or empty), and returns the largest absolute difference over [`columns`] with where it is;
/// the rows must pair up method by method, end ok, and have the same dofs, contact dofs and
/// contact toggles.
fn gmsh_copy_difference(
    scene: &str,
    mesh_scene: &str,
    mesh: &str,
    reference: &str,
    methods: &str,
    count: usize,
) -> (f64, String) {
    let bar = run(&format!(
        "name = \"b\"\nscene = \"{scene}\"\n{reference}\n{methods}h = [0.05]\n"
    ));
    let gmsh = run(&format!(
        "name = \"m\"\nscene = \"{mesh_scene}\"\n{reference}\n{methods}mesh = [\"{mesh}\"]\nvelocity = [-0.5]\n"
    ));
    assert_eq!(bar.len(), count);
    assert_eq!(gmsh.len(), bar.len());
    let mut worst = (0.0f64, String::new());
    for (b, m) in bar.iter().zip(&gmsh) {
        let what = format!("{} {} {}", b.space, b.mass, b.scheme_label);
        assert_eq!(b.status, "ok", "{what}: {:?}", b.message);
        assert_eq!(m.status, "ok", "{what}: {:?}", m.message);
        assert_eq!(
            (&b.space, &b.mass, &b.scheme_label),
            (&m.space, &m.mass, &m.scheme_label)
        );
        assert_eq!(b.dofs, m.dofs);
        assert_eq!(b.contact_dofs, m.contact_dofs);
        assert_eq!(b.contact_toggles, m.contact_toggles, "{what}");
        for ((name, x), (_, y)) in columns(b).into_iter().zip(columns(m)) {
            match (x, y) {
                (Some(x), Some(y)) => {
                    let d = (x - y).abs();
                    if d > worst.0 {
                        worst = (d, format!("{what} {name}: {x:e} vs {y:e}"));
                    }
                    println!("{what} {name}: {x:e} vs {y:e} diff {d:e}");
                }
                (None, None) => {}
                _ => panic!("{what} {name}: {x:?} vs {y:?}"),
            }
        }
    }
    println!("worst: {worst:?}");
    worst
}

#[test]
fn gmsh_bar_reproduces_bar2d() {
    let methods = r#"
[fixed]
T = 2.0
dt = 0.025
[grid]
mass = ["consistent", "lumped", "mod1", "mod2", "mod3", "zero-contact"]
scheme = ["crank-nicolson", "backward-euler"]
"#;
    let worst = gmsh_copy_difference(
        "bar2d",
        "mesh2d",
        "meshes/bar2d_quad.msh",
        "reference = { dt = 0.00625, mass = \"mod3\", scheme = \"crank-nicolson\" }",
        methods,
        12,
    );
    // The two runs solve the same equations with the dofs numbered differently, so their
    // factorisations round differently (~1e-16 relative) and their LCPs stop at different
    // iterates within the tolerance 1e-12·gap = 2e-13 m; the impacts carry that through the
    // steps. Measured: at most 7.6e-11 (the chattering lumped CN's energy_drift, which is
    // relative to E⁰), every error column within 2e-11 m·(unit); 1e-10 is the issue's bound.
    // (The differences are absolute, in each column's unit: an error column is a difference of
    // nearly equal solutions, so its relative round-off is that of u times ‖u‖/‖e‖ ~ 100.)
    assert!(worst.0 < 1e-10, "{worst:?}");
}

/// contract §3.2's methods on the mesh scenes (issue 22: "every contact method and scheme that
/// applies"): the Gmsh copy of the 002 bar gives bar2d's rows for Nitsche (Θ = 1 hybrid,
/// Θ = −1 CN) and the penalty (backward Euler) — the same face quadrature points from the other
/// path (`gmsh_contact_faces`: faces matched to their cells, heights above the lowest contact
/// node, the run's gap added; the Newton iterates round differently as the factors do) — and
/// for kane (every mass kind),
/// contact-stabilized Newmark, generalized-α and HHT (mixed, and generalized-α with Nitsche
/// and the penalty), Moreau–Jean (e = 0 and 1), the discrete gradient (penalty, Nitsche Θ = 1)
/// and kinematic central difference (lumped, τ = 0.025 below its CFL step 0.89 h = 0.044),
/// against the same mod3 + CN reference. The bound is `gmsh_bar_reproduces_bar2d`'s, for the
/// same reason (two dof numberings, round-off carried through the impacts). Measured: at most
/// 1.7e-11 (the penalty backward Euler's err_u_contact_max).
#[test]
fn gmsh_bar_reproduces_bar2d_with_the_comparison_methods() {
    let methods = r#"
[fixed]
T = 2.0
dt = 0.025
[grid]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "hybrid" },
  { space = "nitsche", nitsche_theta = -1.0, nitsche_gamma0 = 0.01, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "backward-euler" },
  { mass = "consistent", scheme = "kane" },
  { mass = "lumped", scheme = "kane" },
  { mass = "mod3", scheme = "kane" },
  { mass = "zero-contact", scheme = "kane" },
  { mass = "consistent", scheme = "contact-stabilized-newmark" },
  { mass = "lumped", scheme = "contact-stabilized-newmark" },
  { mass = "consistent", scheme = "generalized-alpha", rho_inf = 0.5 },
  { mass = "consistent", scheme = "hht", hht_alpha = 0.1 },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "generalized-alpha", rho_inf = 0.8 },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "hht", hht_alpha = 0.2 },
  { mass = "consistent", scheme = "moreau-jean", restitution = 0.0 },
  { mass = "lumped", scheme = "moreau-jean", restitution = 1.0 },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "discrete-gradient" },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "discrete-gradient" },
  { mass = "lumped", scheme = "central-difference" },
]
"#;
    let worst = gmsh_copy_difference(
        "bar2d",
        "mesh2d",
        "meshes/bar2d_quad.msh",
        "reference = { dt = 0.00625, space = \"mixed\", mass = \"mod3\", scheme = \"crank-nicolson\" }",
        methods,
        18,
    );
    assert!(worst.0 < 1e-10, "{worst:?}");
}

/// Issue 22's 3D counterpart: the Gmsh copy of bar3d's box at h = 0.05
/// (`sweeps/meshes/bar3d_hex.msh`, 2 × 2 × 20 hexahedra extruded in layers, bottom = `contact`)
/// gives bar3d's rows for Nitsche (Θ = 1 hybrid, Θ = −1 CN), the penalty (backward Euler,
/// hybrid), the discrete gradient with both, the mixed method's seeds (CN with the consistent
/// mass and mod3) and contract §3.2's mixed methods, against one mod3 + CN reference (τ/4). Same
/// bound and reason as in 2D; 3D factors are supernodal, which rounds differently again.
/// Measured: at most 4.8e-12 (HHT's pressure_oscillation).
#[test]
fn gmsh_bar_reproduces_bar3d() {
    let methods = r#"
[fixed]
T = 1.5
dt = 0.025
[grid]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "hybrid" },
  { space = "nitsche", nitsche_theta = -1.0, nitsche_gamma0 = 0.01, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "backward-euler" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "hybrid" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "discrete-gradient" },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 0.001, scheme = "discrete-gradient" },
  { mass = "consistent", scheme = "crank-nicolson" },
  { mass = "mod3", scheme = "crank-nicolson" },
  { mass = "mod3", scheme = "kane" },
  { mass = "consistent", scheme = "contact-stabilized-newmark" },
  { mass = "consistent", scheme = "hht", hht_alpha = 0.1 },
  { mass = "consistent", scheme = "moreau-jean" },
  { mass = "lumped", scheme = "central-difference" },
]
"#;
    let worst = gmsh_copy_difference(
        "bar3d",
        "mesh3d",
        "meshes/bar3d_hex.msh",
        "reference = { dt = 0.00625, space = \"mixed\", mass = \"mod3\", scheme = \"crank-nicolson\" }",
        methods,
        13,
    );
    assert!(worst.0 < 1e-10, "{worst:?}");
}

fn plan(path: &Path, text: &str) -> contact_sweep::sweep::Plan {
    let sweep =
        contact_sweep::sweep::SweepFile::parse(path, text).unwrap_or_else(|e| panic!("{e}"));
    contact_sweep::sweep::expand(&sweep).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_mesh_file_gives_h_and_the_run_id() {
    use contact_sweep::sweep::{Key, Value};
    let text = |mesh: &str| {
        format!("name = \"m\"\nscene = \"mesh2d\"\n[fixed]\ndt = 0.025\nmesh = \"{mesh}\"\n")
    };
    let here = plan(
        &root().join("sweeps/x.toml"),
        &text("meshes/bar2d_quad.msh"),
    );
    assert_eq!(here.runs.len(), 1);
    let r = &here.runs[0];
    // h = the largest element diameter: the 0.05 × 0.05 squares' diagonal (coordinates
    // k·0.05 to ~1e-17, so 1e-15).
    let h = r.params[&Key::H].as_f64().unwrap();
    assert!((h - 0.05 * 2f64.sqrt()).abs() < 1e-15, "h = {h}");
    assert_eq!(r.params[&Key::Elements], Value::Int(40));
    assert_eq!(
        r.params[&Key::Mesh],
        Value::Str("meshes/bar2d_quad.msh".into())
    );
    // The same bytes under another name in another folder: the same run.
    let tmp = tempfile::tempdir().unwrap();
    let bytes = std::fs::read(root().join("sweeps/meshes/bar2d_quad.msh")).unwrap();
    std::fs::write(tmp.path().join("copy.msh"), &bytes).unwrap();
    let there = plan(&tmp.path().join("y.toml"), &text("copy.msh"));
    assert_eq!(there.runs[0].run_id, r.run_id);
    // Other bytes (one node moved inside the body, still a valid mesh): another run.
    let edited = String::from_utf8(bytes)
        .unwrap()
        .replacen("\n0.05 0.5 0\n", "\n0.05 0.51 0\n", 1);
    assert!(
        edited.len()
            == std::fs::metadata(tmp.path().join("copy.msh"))
                .unwrap()
                .len() as usize
                + 1
    );
    std::fs::write(tmp.path().join("edited.msh"), edited).unwrap();
    let other = plan(&tmp.path().join("y.toml"), &text("edited.msh"));
    assert_ne!(other.runs[0].run_id, r.run_id);
    // A list of files is an axis, ordered as written.
    let axis = plan(
        &root().join("sweeps/x.toml"),
        "name = \"m\"\nscene = \"mesh2d\"\n[fixed]\ndt = 0.025\n[grid]\nmesh = [\"meshes/square_tri_p1.msh\", \"meshes/square_tri_p2.msh\", \"meshes/square_quad_q1.msh\"]\n",
    );
    assert_eq!(axis.runs.len(), 3);
    let ids: std::collections::BTreeSet<_> = axis.runs.iter().map(|r| &r.run_id).collect();
    assert_eq!(ids.len(), 3);
}

/// mesh3d end to end on the Gmsh cube of P2 tetrahedra (clamped top z = 1, Γ_C the bottom
/// z = 0, dropped at ½ onto a plane 0.2 below): every run ends ok, the consistent and mod3
/// masses hold ρ|Ω| = 1, mod1 drops layer 0 (by topology: the cells with a node on Γ_C), the
/// body reaches the plane, and the energy of the modified mass stays within 1e-3 of E⁰ as in
/// bar3d; the errors against the reference (the same mesh, τ/2) are reported.
#[test]
fn mesh3d_tetrahedra_run() {
    let rows = run(
        "name = \"c\"\nscene = \"mesh3d\"\nreference = { dt = 0.0125, mass = \"mod3\" }\n[fixed]\nT = 1.0\ndt = 0.025\nvelocity = -0.5\nmesh = \"meshes/cube_tet_p2.msh\"\n[grid]\nmass = [\"consistent\", \"mod1\", \"mod3\"]\n",
    );
    assert_eq!(rows.len(), 3);
    for r in &rows {
        assert_eq!(r.status, "ok", "{}: {:?}", r.mass, r.message);
        // 5³ nodes, the top 25 clamped: 100 free nodes × 3; Γ_C = the 25 bottom nodes.
        assert_eq!(r.dofs, 300);
        assert_eq!(r.contact_dofs, Some(25));
        assert!(
            r.err_u_l2l2.is_some(),
            "{}: no error against the reference",
            r.mass
        );
    }
    let by = |m: &str| rows.iter().find(|r| r.mass == m).unwrap();
    // 1ᵀM1 = ρ|Ω| = 1: a sum of 48 exact cell masses (round-off ~1e-15).
    for m in ["consistent", "mod3"] {
        let total = by(m).mass_total.unwrap();
        assert!((total - 1.0).abs() < 1e-13, "{m}: {total}");
    }
    // mod1 removes the cells with a node on z = 0: on this mesh those of the bottom cube
    // layer z ∈ [0, ½] (every tetrahedron of it has a vertex on z = 0) — half the mass.
    let m1 = by("mod1").mass_total.unwrap();
    assert!((m1 - 0.5).abs() < 1e-13, "mod1: {m1}");
    // Γ_C with inertia reaches the plane within T (0.2 at ½ until the clamped top's wave
    // arrives); mod1's massless Γ_C follows the quasi-static state of the half body above it.
    for m in ["consistent", "mod3"] {
        let t = by(m).first_contact_time;
        assert!(
            t.is_some_and(|t| t > 0.0 && t < 1.0),
            "{m}: first contact {t:?}"
        );
    }
    let drift = by("mod3").energy_max_dev.unwrap();
    assert!(drift < 1e-3, "mod3 energy deviation {drift}");
}

/// The plan's memory check covers mesh scenes and points to the cure: a coarser file.
#[test]
fn a_mesh_run_above_the_memory_budget_is_refused_towards_a_coarser_file() {
    use contact_sweep::sweep::{PlanLimits, SweepFile, expand_with};
    let sweep = SweepFile::parse(
        &root().join("sweeps/x.toml"),
        "name = \"m\"\nscene = \"mesh3d\"\n[fixed]\ndt = 0.025\nmesh = \"meshes/cube_tet_p2.msh\"\n",
    )
    .unwrap();
    let limits = PlanLimits {
        max_run_bytes: Some(1e5),
        ..PlanLimits::default()
    };
    let e = expand_with(&sweep, &limits)
        .expect_err("above 100 kB")
        .to_string();
    assert!(
        e.contains("`fixed.mesh`") && e.contains("use a coarser mesh file"),
        "{e}"
    );
    // Within a generous budget the same sweep plans.
    let ok = PlanLimits {
        max_run_bytes: Some(1e9),
        ..PlanLimits::default()
    };
    assert_eq!(expand_with(&sweep, &ok).unwrap().runs.len(), 1);
}

/// References on another mesh (contract §1.6, issue 22 done-when 3's second half on the mesh
/// scenes): the Gmsh bar `bar2d_quad.msh` (h = 0.05) measured against a finer mesh *file*
/// (`bar2d_quad_n4.msh`, h = 0.025: a mesh2d reference, located node by node) and against a
/// `bar2d` reference (`reference = { scene = "bar2d", … }`: the box stored whole, located)
/// gives the errors bar2d's own runs get from the same reference node for node (nested
/// lattice, stride 2). Every coarse node is a node of the finer mesh, so the interpolation is
/// exact there and only round-off separates the paths.
#[test]
fn references_on_another_mesh_file_or_on_bar2d_equal_the_nested_path() {
    let methods = "[fixed]\nT = 2.0\ndt = 0.025\n[grid]\nmass = [\"consistent\", \"mod3\"]\nscheme = [\"crank-nicolson\"]\n";
    let bar = run(&format!(
        "name = \"b\"\nscene = \"bar2d\"\nreference = {{ h = 0.025, dt = 0.0125, mass = \"mod3\", scheme = \"crank-nicolson\" }}\n{methods}h = [0.05]\n"
    ));
    let file = run(&format!(
        "name = \"f\"\nscene = \"mesh2d\"\nreference = {{ mesh = \"meshes/bar2d_quad_n4.msh\", dt = 0.0125, mass = \"mod3\", scheme = \"crank-nicolson\" }}\n{methods}mesh = [\"meshes/bar2d_quad.msh\"]\nvelocity = [-0.5]\n"
    ));
    let scene = run(&format!(
        "name = \"s\"\nscene = \"mesh2d\"\nreference = {{ scene = \"bar2d\", h = 0.025, dt = 0.0125, mass = \"mod3\", scheme = \"crank-nicolson\" }}\n{methods}mesh = [\"meshes/bar2d_quad.msh\"]\nvelocity = [-0.5]\n"
    ));
    assert_eq!(bar.len(), 2);
    let mut worst = (0.0f64, String::new());
    for (what, rows) in [("mesh file", &file), ("bar2d scene", &scene)] {
        assert_eq!(rows.len(), bar.len(), "{what}");
        for (b, m) in bar.iter().zip(rows) {
            assert_eq!(b.status, "ok", "{:?}", b.message);
            assert_eq!(m.status, "ok", "{what}: {:?}", m.message);
            assert_eq!(b.mass, m.mass);
            for ((name, x), (_, y)) in columns(b).into_iter().zip(columns(m)) {
                let (Some(x), Some(y)) = (x, y) else {
                    assert_eq!(x.is_some(), y.is_some(), "{what} {} {name}", b.mass);
                    continue;
                };
                let d = (x - y).abs();
                println!("{what} {} {name}: {x:e} vs {y:e} diff {d:e}", b.mass);
                if d > worst.0 {
                    worst = (d, format!("{what} {} {name}: {x:e} vs {y:e}", b.mass));
                }
            }
            // The errors exist (the reference was found and read), and are not zero.
            assert!(m.err_u_l2l2.is_some_and(|e| e > 1e-6), "{what} {}", m.mass);
        }
    }
    // As `gmsh_bar_reproduces_bar2d`: the same equations with other dof numberings round
    // differently and the impacts carry it; the located weights are 1 at a coincident node to
    // ~1e-16 (Newton on the inverse map of a square). 1e-10 is the issue's bound for the
    // node-for-node comparison.
    println!("worst: {worst:?}");
    assert!(worst.0 < 1e-10, "{worst:?}");
}

/// A reference of another scene must be the run's problem: bar2d's initial velocity is −½,
/// a mesh run left at `velocity = 0` is refused, naming the difference; a 3D scene cannot be
/// the reference of a 2D mesh, nor can a built-in scene take a reference of another scene.
#[test]
fn a_reference_of_another_scene_is_checked() {
    use contact_sweep::sweep::{SweepFile, expand};
    let path = root().join("sweeps/x.toml");
    let text = |scene: &str, reference: &str, extra: &str| {
        format!(
            "name = \"m\"\nscene = \"{scene}\"\nreference = {{ {reference} }}\n[fixed]\ndt = 0.025\n{extra}"
        )
    };
    let mesh = "mesh = \"meshes/bar2d_tri_n2.msh\"\n";
    let sweep = SweepFile::parse(
        &path,
        &text("mesh2d", "scene = \"bar2d\", h = 0.025, dt = 0.0125", mesh),
    )
    .unwrap();
    let e = expand(&sweep)
        .expect_err("velocity 0 against −½")
        .to_string();
    assert!(
        e.contains("reference.scene")
            && e.contains("velocity = 0 in the run, -0.5 in the reference"),
        "{e}"
    );
    let ok = SweepFile::parse(
        &path,
        &text(
            "mesh2d",
            "scene = \"bar2d\", h = 0.025, dt = 0.0125",
            &format!("{mesh}velocity = -0.5\n"),
        ),
    )
    .unwrap();
    let plan = expand(&ok).unwrap();
    assert_eq!(plan.references.len(), 1);
    assert!(plan.references[0].spec.label.contains("bar2d"));
    assert_eq!(plan.references[0].space_stride, 1);
    // Another dimension, and a built-in scene's sweep: refused when the file is read.
    let e = SweepFile::parse(&path, &text("mesh2d", "scene = \"bar3d\", h = 0.025", mesh))
        .expect_err("3D reference of a 2D mesh")
        .to_string();
    assert!(
        e.contains("reference.scene") && e.contains("same dimension"),
        "{e}"
    );
    let e = SweepFile::parse(
        &path,
        &text("bar2d", "scene = \"mesh2d\", dt = 0.0125", "h = 0.05\n"),
    )
    .expect_err("bar2d against a mesh scene")
    .to_string();
    assert!(
        e.contains("reference.scene") && e.contains("is for runs on a mesh file"),
        "{e}"
    );
}

/// Issue 22 done-when 2, second half: the 002 bar meshed with P1 triangles at three sizes
/// (`sweeps/bar2d_triangles.toml`: N × 10N squares cut in two, N = 2, 4, 8, τ = 0.05/N) against
/// the bar2d reference of `bar2d_convergence.toml` (Q1 at h = 0.05/32, τ/32, mod3 + CN, a run
/// of scene bar2d located node by node). Measured (docs/methods.md "The 002 bar in triangles"), LSQ
/// slopes in h over the three levels, with bar2d's own on the same ladder in brackets:
/// l2(τ;L2) mod1 0.85 [0.83], mod2 0.80 [0.82], mod3 0.71 [0.91]; l2(τ;H1) stagnates for both
/// element kinds (|slope| ≤ 0.06 here, ≤ 0.15 for bar2d) — the impact's velocity jump.
#[test]
fn triangles_converge_to_the_bar2d_reference() {
    let path = root().join("sweeps/bar2d_triangles.toml");
    let rows = run_sweep_text_at(&path, &std::fs::read_to_string(&path).unwrap());
    assert_eq!(rows.len(), 12);
    let slope = |mass: &str, err: fn(&RunRecord) -> Option<f64>| {
        let mut pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.mass == mass)
            .map(|r| {
                assert_eq!(r.status, "ok", "{mass}: {:?}", r.message);
                (
                    r.h.ln(),
                    err(r).expect("an error against the reference").ln(),
                )
            })
            .collect();
        assert_eq!(pts.len(), 3, "{mass}");
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let n = pts.len() as f64;
        let (mx, my) = (
            pts.iter().map(|p| p.0).sum::<f64>() / n,
            pts.iter().map(|p| p.1).sum::<f64>() / n,
        );
        pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
            / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>()
    };
    // The massless-Γ_C masses are well-posed: their runs reproduce to round-off (the two
    // numberings of `gmsh_bar_reproduces_bar2d` differ by 1e-10 in an error of ~1e-3), which
    // moves a slope by ~1e-7; 0.02 leaves room for another faer or compiler and still
    // separates the triangles' mod3 (0.71) from bar2d's (0.91).
    for (mass, l2) in [("mod1", 0.847), ("mod2", 0.796), ("mod3", 0.709)] {
        let s = slope(mass, |r| r.err_u_l2l2);
        println!("{mass}: l2(τ;L2) slope {s:.4}");
        assert!((s - l2).abs() < 0.02, "{mass}: L2 slope {s}, measured {l2}");
        // H1 does not converge at these sizes, as for bar2d (docs/methods.md): measured −0.04 … 0.05.
        let s1 = slope(mass, |r| r.err_u_l2h1);
        println!("{mass}: l2(τ;H1) slope {s1:.4}");
        assert!(s1.abs() < 0.1, "{mass}: H1 slope {s1}");
    }
    // The finest level's L2 error against bar2d's at h = 0.0125 (docs/methods.md): the triangles' is
    // larger by 6 % (mod1), 9 % (mod2), 54 % (mod3) — one order, the same reference.
    let finest = |mass: &str| {
        rows.iter()
            .filter(|r| r.mass == mass)
            .map(|r| r.err_u_l2l2.unwrap())
            .fold(f64::INFINITY, f64::min)
    };
    for (mass, bar2d) in [
        ("mod1", 9.9305e-4),
        ("mod2", 8.9475e-4),
        ("mod3", 3.7831e-4),
    ] {
        let ratio = finest(mass) / bar2d;
        println!(
            "{mass}: finest L2 {:.4e}, {ratio:.3} × bar2d's",
            finest(mass)
        );
        assert!((1.0..1.6).contains(&ratio), "{mass}: {ratio}");
    }
    // The consistent mass with CN is ill-posed (contract §2.1): no convergence in L2 (measured
    // slope −0.01; bar2d's 0.25), energy growing (E(T)/E⁰ 1.98 → 4.93).
    let s = slope("consistent", |r| r.err_u_l2l2);
    assert!(s < 0.3, "consistent: L2 slope {s}");
}

/// contract §1.6's `obstacle`: the absolute plane x_d = obstacle is the gap under another name
/// (gap = lowest contact node's x_d − obstacle), so the run it gives is the `gap` run — the same
/// id, the same configuration — and a list of obstacles is an axis like any key. The Gmsh bar's
/// bottom is at y = 0 (to ~1e-17), so obstacle = −g is gap = g; the default gap 0.2 is the
/// plane −0.2. The hexahedral ball-free cube of mesh3d (bottom z = 0) likewise. A built-in
/// scene has no `obstacle` (its plane is its `gap`).
#[test]
fn obstacle_is_the_gap_under_another_name() {
    use contact_sweep::sweep::{Key, SweepFile, expand};
    let at = root().join("sweeps/x.toml");
    let ids = |scene: &str, mesh: &str, plane: &str| {
        let p = plan(
            &at,
            &format!(
                "name = \"o\"\nscene = \"{scene}\"\n[fixed]\ndt = 0.025\nvelocity = -0.5\nmesh = \"{mesh}\"\n[grid]\n{plane}\n"
            ),
        );
        p.runs
            .iter()
            .map(|r| {
                let obstacle = r.params[&Key::Obstacle].as_f64().unwrap();
                let gap = r.params[&Key::Gap].as_f64().unwrap();
                (r.run_id.clone(), obstacle, gap, r.config.clone())
            })
            .collect::<Vec<_>>()
    };
    for (scene, mesh) in [
        ("mesh2d", "meshes/bar2d_quad.msh"),
        ("mesh3d", "meshes/cube_hex_q1.msh"),
    ] {
        let by_gap = ids(scene, mesh, "gap = [0.2, 0.1, 0.05]");
        let by_obstacle = ids(scene, mesh, "obstacle = [-0.2, -0.1, -0.05]");
        assert_eq!(by_gap.len(), 3);
        assert_eq!(by_obstacle.len(), 3, "a list of obstacles is an axis");
        for (g, o) in by_gap.iter().zip(&by_obstacle) {
            assert_eq!(g.0, o.0, "{scene}: same plane, same run id");
            assert_eq!(g.3, o.3, "{scene}: same run configuration");
            // The derived columns: the plane's height and the gap (floor 0 to ~1e-17).
            assert!((g.1 - o.1).abs() < 1e-15 && (g.2 - o.2).abs() < 1e-15);
            assert!(
                (g.1 + g.2).abs() < 1e-15,
                "{scene}: obstacle {} gap {}",
                g.1,
                g.2
            );
        }
        // The default plane (gap 0.2) is obstacle = −0.2: the run without either key.
        let default = ids(scene, mesh, "T = [2.0]");
        assert_eq!(default[0].0, by_obstacle[0].0);
    }
    // Not a key of the built-in scenes.
    let e = SweepFile::parse(
        &at,
        "name = \"o\"\nscene = \"bar2d\"\n[fixed]\nh = 0.05\ndt = 0.025\nobstacle = -0.2\n",
    )
    .expect_err("bar2d has no obstacle key")
    .to_string();
    assert!(
        e.contains("`obstacle` is not a parameter of scene bar2d"),
        "{e}"
    );
    // With another scene's reference, `obstacle` is the run's gap in the physics check: the
    // Gmsh bar with obstacle = −0.2 against bar2d (gap 0.2) plans, with −0.1 it is refused.
    let text = |obstacle: f64| {
        format!(
            "name = \"o\"\nscene = \"mesh2d\"\nreference = {{ scene = \"bar2d\", h = 0.025, dt = 0.0125 }}\n[fixed]\ndt = 0.025\nvelocity = -0.5\nmesh = \"meshes/bar2d_quad.msh\"\nobstacle = {obstacle}\n"
        )
    };
    assert_eq!(
        expand(&SweepFile::parse(&at, &text(-0.2)).unwrap())
            .unwrap()
            .references
            .len(),
        1
    );
    let e = expand(&SweepFile::parse(&at, &text(-0.1)).unwrap())
        .expect_err("gap 0.1 against bar2d's 0.2")
        .to_string();
    assert!(
        e.contains("gap = 0.1 in the run, 0.2 in the reference"),
        "{e}"
    );
}
