//! The engine against GetFEM on a NON-matching two-body interface (issue 45, done-when 4).
//!
//! (a) The nodal brick: `blocks2d` with `mesh_ratio` = 4/3 (A 4 squares across, B
//! round(4/3·4) = 5 rectangles across: no node of A's bottom above a node of B's top but the
//! two ends), `pairing = "node-to-segment"`, `mixed`, Crank–Nicolson, against
//! tests/getfem/blocks.py meshing the same two Q1 blocks (B's nodes at the engine's
//! x = kW/5, y = jH_b/round(H_b/h)) around GetFEM 5.4's
//! `add_nodal_contact_between_nonmatching_meshes_brick` — whose row for a slave node of A's
//! bottom is (u_b(proj) − u_a)·n_B, proj the node's projection on the master face below
//! (interpolated linearly between that face's two nodes): the engine's one-pass
//! node-to-segment row δ_i = (u^a_i − u^b(Π(x_i)))·(−e_y), A the slave, the same number.
//! Everything else as tests/getfem_blocks.rs (the machinery of tests/common/getfem_blocks.rs):
//! the same two settings, both masses (`zero-contact` with `mass_side = "both"` over the whole
//! run; `consistent` through its first contact phase), and the same measured quantities and
//! scales. Conventions: the matching test's header; one more here — the engine's
//! `u_contact_b` on node-to-segment rows is B's u_y at Π(x_i) averaged with Γ^a's trapezoidal
//! weights, so GetFEM's is B's field interpolated at the points below A's face nodes with
//! those weights. The tolerance 1e-8, as there: each step solves the same linear
//! complementarity problem exactly on both sides (GetFEM's Newton to 1e-11 relative residual,
//! its Signorini conditions checked to 1e-13), so the runs differ by round-off grown over
//! 200 stable steps.

mod common;

use common::getfem::run_script_on;
use common::getfem_blocks::{FaceB, Setting, compare, engine_equals_getfem};
use contact_sweep::run::RunContext;

/// B's elements across per A's: round(4/3·4) = 5 against A's 4.
const NODE_TO_SEGMENT: &str = r#"pairing = "node-to-segment"
mesh_ratio = 1.3333333333333333"#;

/// tests/getfem_blocks.rs's two settings on the non-matching blocks.
const SETTINGS: [Setting; 2] = [
    Setting {
        name: "free-ratio-4-3",
        height_b: 1.0,
        gap: 0.1,
        velocity_tangential: 0.3,
        velocity_b: 0.5,
        density_b: 2.0,
        lame_lambda_b: 0.5,
        lame_mu_b: 1.5,
        far_end: "free",
        t_final: 4.0,
        mesh_ratio: 1.3333333333333333,
        contact: NODE_TO_SEGMENT,
    },
    Setting {
        name: "clamped-ratio-4-3",
        height_b: 0.75,
        gap: 0.05,
        velocity_tangential: 0.0,
        velocity_b: 0.0,
        density_b: 1.5,
        lame_lambda_b: 2.0,
        lame_mu_b: 0.5,
        far_end: "clamped",
        t_final: 4.0,
        mesh_ratio: 1.3333333333333333,
        contact: NODE_TO_SEGMENT,
    },
];

#[test]
fn engine_node_to_segment_equals_getfem_nodal_brick_on_nonmatching_blocks2d() {
    engine_equals_getfem(&SETTINGS);
}

/// Nitsche's γ0 (contract §6's patch-test value, at which the blocks' Newton converges) and
/// the variants: `nitsche_sides` × Θ.
const GAMMA0: f64 = 0.05;
const NITSCHE: [(&str, f64); 6] = [
    ("unbiased", 1.0),
    ("unbiased", 0.0),
    ("unbiased", -1.0),
    ("a", 1.0),
    ("a", 0.0),
    ("a", -1.0),
];

#[test]
fn engine_nitsche_element_quadrature_equals_getfem_gwfl_nitsche_on_nonmatching_blocks2d() {
    let ctx = RunContext {
        reference: None,
        record_reference: Some((1, 1)),
    };
    for base in &SETTINGS {
        // 50 steps (T = 1): the first contact phase and the flight after it.
        let s = Setting {
            t_final: 1.0,
            ..*base
        };
        let variants: Vec<String> = NITSCHE.iter().map(|(w, t)| format!("{w}:{t}")).collect();
        let gf = run_script_on(
            "nitsche_blocks.py",
            None,
            &[
                s.params(serde_json::json!({"gamma0": GAMMA0, "mass": "consistent"})),
                variants.join(","),
            ],
        );
        for ((sides, theta), variant) in NITSCHE.iter().zip(&variants) {
            let method = format!(
                "space = \"nitsche\"\nnitsche_gamma0 = {GAMMA0}\nnitsche_sides = \"{sides}\"\ninterface_quadrature = \"element\"\nmesh_ratio = {}\nmass = \"consistent\"",
                s.mesh_ratio
            );
            let sweep = s.sweep(&method, &format!("nitsche_theta = [{theta:?}]"));
            let runs = common::outcomes_edited(
                &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("t.toml"),
                &sweep,
                |_| {},
                &ctx,
            );
            assert_eq!(runs.len(), 1);
            let what = format!("{} · nitsche {variant}", s.name);
            let (g, o) = (&gf["variants"][variant], &runs[0].1);
            compare(&s, &gf["nodes"], g, &what, o, true, FaceB::Nearest);
        }
    }
}
