//! Issue 43, done-when 4: Moreau–Jean θ = ½, e = 0 raises E + W_f on a resting block, and
//! Siconos 4.4 raises it by the same amount at the same steps — to round-off, on the same mesh
//! and setting (tests/siconos/block_moreau_jean.py: MoreauJeanOSI θ = ½, NewtonImpactFrictionNSL
//! e = 0, the 2D frictional contact problem by Lemke, its own Q1 assembly of the 8 × 4 block of
//! sweeps/meshes/block2d.msh).
//!
//! The block is lifted by a gap of 0.003, thrown at V = 0.05 along the plane with μ_f = 0.3,
//! τ = 0.2, T = 10 (50 steps): it lands in its second step and rests from there, rising
//! E + W_f nine times. Why lifted: a block that starts resting at gap 0 has y = ẏ = 0 at every
//! Γ_C node, so which node the index set's prediction y + ½τẏ ≤ 0 keeps is decided by
//! round-off (ẏ ~ 1e-19) and the two trajectories part at step 2 (tests/friction_campaign.rs's
//! `moreau_jean_resting_block_against_siconos` compares that case in size only).
//!
//! Measured (gap 0.003): |E + W_f − Siconos'| ≤ 3.4e-12 energy scales at every one of the 51
//! kept steps; the largest one-step rise is 6.569e-3 energy scales in both (equal to 3e-12).
//! Other lifts part in the end: the difference grows from 1e-15 as the two assemblies'
//! round-off is carried (to 1e-11 by step 13–35) until a discrete decision of the frictional
//! contact problem (stick/slip, contact/no contact) flips in one code and not the other, and
//! jumps to 1e-3–1e-2 in one step (gaps 0.001, 0.002, 0.005, 0.006 at steps 35, 15, 34, 13;
//! 0.004 at step 2, where y + ½τẏ = 0.002 − 0.1·0.02 is zero by the arithmetic of the fall).
//! So the comparison to 1e-10 is of this trajectory, whose decisions all keep a margin above
//! the carried round-off.

mod common;

use std::path::Path;

/// The compared case: gap, throw speed, μ_f, τ, T.
const GAP: f64 = 0.003;
const V: f64 = 0.05;
const MU_F: f64 = 0.3;
const DT: f64 = 0.2;
const T: f64 = 10.0;

/// The engine's sweep of the same block: sweeps/sliding_block.toml's material and load
/// (ρ = 1, λ = μ = 10, gravity 0.1), the consistent mass, mixed contact.
fn sweep() -> String {
    format!(
        r#"name = "mj-siconos"
scene = "mesh2d"
[fixed]
mesh = "meshes/block2d.msh"
density = 1.0
lame_lambda = 10.0
lame_mu = 10.0
gravity = 0.1
gap = {GAP}
velocity_tangential = {V}
T = {T}
dt = {DT}
space = "mixed"
mass = "consistent"
scheme = "moreau-jean"
restitution = 0.0
friction = "coulomb"
friction_coefficient = {MU_F}
"#
    )
}

/// Siconos' E + W_f at every step, shifted to the engine's potential (the script's
/// `gap_shift`).
fn siconos() -> Vec<f64> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let install = std::process::Command::new("bash")
        .arg(root.join("tests/install_siconos.sh"))
        .status()
        .expect("bash");
    assert!(install.success(), "tests/install_siconos.sh failed");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("siconos.json");
    let o = std::process::Command::new("/usr/bin/python3")
        .arg(root.join("tests/siconos/block_moreau_jean.py"))
        .args([MU_F, V, DT, T].map(|x| x.to_string()))
        .arg(&out)
        .arg(GAP.to_string())
        .output()
        .expect("python3");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let shift = json["gap_shift"].as_f64().unwrap();
    json["e_plus_wf"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() - shift)
        .collect()
}

/// The largest one-step rise of a series, in units of `scale`.
fn largest_rise(e: &[f64], scale: f64) -> f64 {
    e.windows(2)
        .map(|w| (w[1] - w[0]) / scale)
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn moreau_jean_landed_block_equals_siconos() {
    let sweeps = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/mj.toml");
    let runs = common::outcomes_at(&sweeps, &sweep());
    assert_eq!(runs.len(), 1);
    let o = common::ok(runs.into_iter().next().unwrap().1);
    let scale = o.metrics.energy_scale.unwrap();
    let engine: Vec<f64> = o
        .series
        .rows()
        .map(|r| r.energy + r.friction_work.unwrap())
        .collect();
    let siconos = siconos();
    assert_eq!(engine.len(), siconos.len());
    assert_eq!(engine.len(), 51);
    // Two assemblies of the same matrices and two LCP solvers (Lemke at tol 1e-16, the
    // engine's active-set solve) agree to round-off carried over 50 steps: measured 3.4e-12
    // energy scales; 1e-10 is the issue's bound, 30× the measurement.
    let worst = engine
        .iter()
        .zip(&siconos)
        .map(|(a, b)| (a - b).abs() / scale)
        .fold(0.0f64, f64::max);
    eprintln!("largest |E + W_f − Siconos'|: {worst:e} energy scales");
    assert!(worst <= 1e-10, "{worst:e}");
    // The rise is the method's, not a defect: both raise E + W_f by the same amount (measured
    // 6.569e-3 energy scales), far above round-off; equal to the same 1e-10.
    let (re, rs) = (largest_rise(&engine, scale), largest_rise(&siconos, scale));
    eprintln!("largest rise: engine {re:e}, Siconos {rs:e}");
    assert!(re > 1e-3, "{re:e}");
    assert!((re - rs).abs() <= 1e-10, "{re:e} {rs:e}");
    // It rises at the same steps (measured: nine steps gain more than 1e-12 energy scales).
    let rises = |e: &[f64]| -> Vec<usize> {
        e.windows(2)
            .enumerate()
            .filter(|(_, w)| w[1] - w[0] > 1e-9 * scale)
            .map(|(i, _)| i)
            .collect()
    };
    assert_eq!(rises(&engine), rises(&siconos));
    assert!(rises(&engine).len() >= 5, "{:?}", rises(&engine));
}
