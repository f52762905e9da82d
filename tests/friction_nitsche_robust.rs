//! The frictional Nitsche/penalty solve does not give up (issue 43): the cases a random campaign
//! found `solver-failed`, each a regression test named after it, run to `ok`.
//!
//! The condensed frictional Newton (run/fe/nitsche.rs, `newton_friction`) tries the damped
//! semismooth Newton from the previous step's forces, then from rest, then a continuation in
//! the friction bound (μ_f or s scaled from 0 to 1) with, for Tresca, the bound ramped over a
//! shrinking width of the penetration — the closure of contract §2.5 where the literal law has
//! no solution. Every stage accepts only a residual within contract §4's tolerance (its unit
//! tests check the closure's residual by hand).
//!
//! The block is the Gmsh rectangle of sweeps/sliding_block.toml (1 × 0.5, 8 × 4 Q1, ρ = 1,
//! λ = μ = 10, gravity 0.1, resting on the plane at gap 0): its weight per unit length of Γ_C
//! is ρ·g·H = 0.05, Tresca's thresholds below are 0.2–1 × that.

use std::path::{Path, PathBuf};

use contact_sweep::run::{Outcome, RunOptions};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every run of the sweep `text` (as if it were the file `path`: meshes relative to it), each
/// asserted `ok`, with its label.
fn runs(path: &Path, text: &str) -> Vec<(String, Outcome)> {
    let plan = contact_sweep::sweep::expand(
        &contact_sweep::sweep::SweepFile::parse(path, text).expect("valid sweep"),
    )
    .expect("plan");
    assert!(!plan.runs.is_empty());
    plan.runs
        .iter()
        .map(|spec| {
            let o = contact_sweep::run::simulate_with(
                &spec.config,
                &RunOptions {
                    series_every: 0,
                    ..RunOptions::default()
                },
                &Default::default(),
            );
            assert_eq!(o.status.as_str(), "ok", "{}: {:?}", spec.label, o.message);
            (spec.label.clone(), o)
        })
        .collect()
}

/// The block's sweep with the [fixed] lines `fixed` and the grid `grid`.
fn block(fixed: &str, grid: &str) -> String {
    format!(
        r#"
name = "block"
scene = "mesh2d"
[fixed]
mesh = "meshes/block2d.msh"
density = 1.0
lame_lambda = 10.0
lame_mu = 10.0
gravity = 0.1
gap = 0.0
{fixed}
[grid]
{grid}
"#
    )
}

fn sweeps() -> PathBuf {
    root().join("sweeps/robust.toml")
}

/// sweeps/sliding_block.toml with `friction = "tresca"` (V = 0.5, T = 50, τ = 0.05, flat and
/// 5°): Nitsche and the penalty failed at every threshold; all 20 runs end ok, the block
/// still moving forward at T, never reversed: 0 < v_t(T) < 2V (measured 0.105 … 0.779; flat
/// below V, on the incline up to 1.56 V).
#[test]
fn sliding_block_tresca_every_threshold_runs_ok() {
    let text = block(
        "velocity_tangential = 0.5\nfriction = \"tresca\"\nT = 50.0\ndt = 0.05",
        r#"incline = [0.0, 5.0]
tresca_threshold = [0.01, 0.02, 0.03, 0.04, 0.05]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "crank-nicolson" },
]"#,
    );
    let out = runs(&sweeps(), &text);
    assert_eq!(out.len(), 20);
    for (label, o) in &out {
        let vt = o.metrics.tangential_velocity_final.unwrap();
        assert!(vt > 0.0 && vt < 1.0, "{label}: v_t(T) = {vt}");
    }
}

/// The block thrown slowly (V = 0.01) with μ_f = 1 and 2: Nitsche at γ0 = 1e-3 and 1e-4 (Θ = 1,
/// 0, and −1 with backward Euler) and the penalty (γ0 = 100 with CN, 1000 with backward Euler)
/// all run ok to T = 5. The friction stops the block within the first step (V/(μ_f g) ≤ 0.1);
/// with backward Euler, whose damping ends the elastic sway, the mean tangential velocity at T
/// is the slow creep of the contact's tangential compliance: |v_t| ≤ 2e-4·V (measured
/// 1.39e-4·V … 1.48e-4·V, the same for Nitsche and the penalty).
#[test]
fn block_mu_1_and_2_at_low_speed_runs_ok() {
    let text = block(
        "velocity_tangential = 0.01\nfriction = \"coulomb\"\nT = 5.0\ndt = 0.05",
        r#"friction_coefficient = [1.0, 2.0]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3, scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-4, scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 1e-4, scheme = "crank-nicolson" },
  { space = "nitsche", nitsche_theta = -1.0, nitsche_gamma0 = 1e-4, scheme = "backward-euler" },
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "crank-nicolson" },
  { space = "penalty", penalty_gamma0 = 1000.0, scheme = "backward-euler" },
]"#,
    );
    for (label, o) in runs(&sweeps(), &text) {
        if label.contains("backward-euler") {
            let vt = o.metrics.tangential_velocity_final.unwrap();
            assert!(vt.abs() <= 2e-4 * 0.01, "{label}: v_t(T) = {vt:e}");
        }
    }
}

/// μ_f = 5 on the slow block with backward Euler (Nitsche Θ = −1, γ0 = 1e-4; penalty γ0 =
/// 1000): ok, and stuck as at μ_f = 1, 2 (measured |v_t(T)| = 1.47e-4·V, 1.49e-4·V).
#[test]
fn block_mu_5_backward_euler_runs_ok() {
    let text = block(
        "velocity_tangential = 0.01\nfriction = \"coulomb\"\nfriction_coefficient = 5.0\nT = 5.0\ndt = 0.05\nscheme = \"backward-euler\"",
        r#"method = [
  { space = "nitsche", nitsche_theta = -1.0, nitsche_gamma0 = 1e-4 },
  { space = "penalty", penalty_gamma0 = 1000.0 },
]"#,
    );
    for (label, o) in runs(&sweeps(), &text) {
        let vt = o.metrics.tangential_velocity_final.unwrap();
        assert!(vt.abs() <= 2e-4 * 0.01, "{label}: v_t(T) = {vt:e}");
    }
}

/// The P2 disc (sweeps/meshes/disc_p2.msh, λ = μ = 20, gap 5, τ = 0.1) dropped (V = 0) and
/// thrown (V = 0.5) onto a 26° incline with Nitsche (Θ = 1 and 0, γ0 = 1e-3), μ_f = 0.86 >
/// tan 26° = 0.49: through the impact at t ≈ 10 to T = 15, ok.
#[test]
fn disc_thrown_on_26_degree_incline_nitsche_mu_0_86_runs_ok() {
    let text = format!(
        r#"
name = "disc-incline"
scene = "mesh2d"
[fixed]
mesh = "{}"
density = 1.0
lame_lambda = 20.0
lame_mu = 20.0
gravity = 0.1
gap = 5.0
T = 15.0
dt = 0.1
incline = 26.0
friction = "coulomb"
friction_coefficient = 0.86
scheme = "crank-nicolson"
[grid]
velocity_tangential = [0.0, 0.5]
method = [
  {{ space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3 }},
  {{ space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 1e-3 }},
]
"#,
        root().join("sweeps/meshes/disc_p2.msh").display()
    );
    assert_eq!(runs(&sweeps(), &text).len(), 4);
}

/// The slow block (V = 0.01, 0.05) on an 18° incline, penalty (γ0 = 100, 1000) + HHT (α = 0.1,
/// 0.3), μ_f = 0.61 > tan 18° = 0.32: ok to T = 5.
#[test]
fn slow_block_on_18_degree_incline_penalty_hht_mu_0_61_runs_ok() {
    let text = block(
        "incline = 18.0\nfriction = \"coulomb\"\nfriction_coefficient = 0.61\nT = 5.0\ndt = 0.05",
        r#"velocity_tangential = [0.01, 0.05]
method = [
  { space = "penalty", penalty_gamma0 = 100.0, scheme = "hht", hht_alpha = 0.1 },
  { space = "penalty", penalty_gamma0 = 1000.0, scheme = "hht", hht_alpha = 0.3 },
]"#,
    );
    assert_eq!(runs(&sweeps(), &text).len(), 4);
}

/// The sliding block of sweeps/sliding_block.toml (V = 0.5) with Nitsche (Θ = 1, 0), the mod3
/// mass and backward Euler, μ_f = 0.917: the block stops at the rigid time V/(μ_f g) = 5.45
/// (flat) — the step the frictional Newton failed at — and the runs go on to T = 10, ok, the
/// block at rest: |v_t(T)| ≤ 1e-4·V (measured 9.7e-6·V flat, 3.7e-5·V on the 5° incline).
#[test]
fn sliding_block_nitsche_mod3_backward_euler_stops_ok() {
    let text = block(
        "velocity_tangential = 0.5\nfriction = \"coulomb\"\nfriction_coefficient = 0.917\nT = 10.0\ndt = 0.05\nmass = \"mod3\"\nscheme = \"backward-euler\"",
        r#"incline = [0.0, 5.0]
method = [
  { space = "nitsche", nitsche_theta = 1.0, nitsche_gamma0 = 1e-3 },
  { space = "nitsche", nitsche_theta = 0.0, nitsche_gamma0 = 1e-3 },
]"#,
    );
    for (label, o) in runs(&sweeps(), &text) {
        let vt = o.metrics.tangential_velocity_final.unwrap();
        assert!(vt.abs() <= 1e-4 * 0.5, "{label}: v_t(T) = {vt:e}");
    }
}
