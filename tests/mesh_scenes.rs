//! The `mesh2d`/`mesh3d` scenes (SPEC §1.6, issue 22): the user's body from a Gmsh file.
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
    ]
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
    let bar = run(&format!(
        "name = \"b\"\nscene = \"bar2d\"\nreference = {{ dt = 0.00625, mass = \"mod3\", scheme = \"crank-nicolson\" }}\n{methods}h = [0.05]\n"
    ));
    let mesh = run(&format!(
        "name = \"m\"\nscene = \"mesh2d\"\nreference = {{ dt = 0.00625, mass = \"mod3\", scheme = \"crank-nicolson\" }}\n{methods}mesh = [\"meshes/bar2d_quad.msh\"]\nvelocity = [-0.5]\n"
    ));
    assert_eq!(bar.len(), 12);
    assert_eq!(mesh.len(), bar.len());
    let mut worst = (0.0f64, String::new());
    for (b, m) in bar.iter().zip(&mesh) {
        assert_eq!(b.status, "ok", "{:?}", b.message);
        assert_eq!(m.status, "ok", "{:?}", m.message);
        assert_eq!((&b.mass, &b.scheme_label), (&m.mass, &m.scheme_label));
        assert_eq!(b.dofs, m.dofs);
        assert_eq!(b.contact_dofs, m.contact_dofs);
        assert_eq!(
            b.contact_toggles, m.contact_toggles,
            "{} {}",
            b.mass, b.scheme_label
        );
        for ((name, x), (_, y)) in columns(b).into_iter().zip(columns(m)) {
            match (x, y) {
                (Some(x), Some(y)) => {
                    let d = (x - y).abs();
                    if d > worst.0 {
                        worst = (
                            d,
                            format!("{} {} {name}: {x:e} vs {y:e}", b.mass, b.scheme_label),
                        );
                    }
                    println!(
                        "{} {} {name}: {x:e} vs {y:e} diff {d:e}",
                        b.mass, b.scheme_label
                    );
                }
                (None, None) => {}
                _ => panic!("{} {} {name}: {x:?} vs {y:?}", b.mass, b.scheme_label),
            }
        }
    }
    // The two runs solve the same equations with the dofs numbered differently, so their
    // factorisations round differently (~1e-16 relative) and their LCPs stop at different
    // iterates within the tolerance 1e-12·gap = 2e-13 m; the impacts carry that through the
    // steps. Measured: at most 7.6e-11 (the chattering lumped CN's energy_drift, which is
    // relative to E⁰), every error column within 2e-11 m·(unit); 1e-10 is the issue's bound.
    // (The differences are absolute, in each column's unit: an error column is a difference of
    // nearly equal solutions, so its relative round-off is that of u times ‖u‖/‖e‖ ~ 100.)
    println!("worst: {worst:?}");
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
