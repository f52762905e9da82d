//! The energy unit of the scenes with gravity (contract §1.3, issue 42): `energy_scale` =
//! m·|f|·d + ½m|v⁰|², m = ∫ρ the body's mass, v⁰ both components of the initial velocity, d the
//! gap — or the body's height H when it starts on the plane. It is continuous in v⁰: a block
//! resting on the plane had m·|f|·H at V_t = 0 but ½mV_t² for any V_t > 0 (a unit that vanished
//! as V_t → 0 and turned V_t = 1e-6 into a `diverged` run), and a normal `velocity` did not
//! enter at all.
//!
//! And every step in the balance: a frictional Nitsche/penalty run handed E⁰ to its E + W_f
//! tally only after its first step, so the tally started from E⁰ + W_f¹ and
//! `energy_balance_max_increase` left step 1 out (+0.35 energy scales reported as −4.2e-4);
//! its series had no W_f at step 0.

use std::path::Path;

use contact_sweep::run::{Outcome, RunContext, RunOptions, simulate_with};
use contact_sweep::sweep::{SweepFile, expand};

/// Plan `text` (one run; a sweep file in sweeps/, where the mesh paths are relative to) and run
/// it with every step in the series.
fn run(text: &str) -> Outcome {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("sweeps/energy_scale_test.toml");
    let plan = expand(&SweepFile::parse(&path, text).expect("a valid sweep")).expect("a plan");
    assert_eq!(plan.runs.len(), 1, "{text}");
    simulate_with(
        &plan.runs[0].config,
        &RunOptions {
            series_every: 1,
            ..RunOptions::default()
        },
        &RunContext::default(),
    )
}

const G: f64 = 0.1;

/// The disc of contract §1.3 (P1, h = 8, ten steps) thrown with (V_t, V_d) = (0.3, −0.4): its
/// scale is m·|f|·5 + ½m(V_t² + V_d²), both components of the throw. m is the mass of the disc
/// at rest (its scale over |f|·5, the same mesh), checked against the consistent mass's 1ᵀM1
/// (mass_total, another sum of the same integrals: 1e-12). Sums of a few products of the same
/// m: 1e-14 relative (the done-when's figure).
#[test]
fn the_disc_thrown_with_both_components_is_measured_in_weight_and_throw() {
    let disc = |extra: &str| {
        run(&format!(
            "name = \"d\"\nscene = \"disc2d\"\n[fixed]\ndegree = 1\nh = 8.0\ndt = 0.1\nT = 1.0\n{extra}"
        ))
    };
    let rest = disc("");
    assert_eq!(rest.status.as_str(), "ok", "{:?}", rest.message);
    let m = rest.metrics.energy_scale.unwrap() / (G * 5.0);
    let mass_total = rest.metrics.mass_total.unwrap();
    assert!(
        (m - mass_total).abs() < 1e-12 * m,
        "m = {m}, mass_total = {mass_total}"
    );
    let (vt, vd) = (0.3, -0.4);
    let thrown = disc(&format!(
        "velocity_tangential = {vt:?}\nvelocity = {vd:?}\n"
    ));
    assert_eq!(thrown.status.as_str(), "ok", "{:?}", thrown.message);
    let want = m * G * 5.0 + 0.5 * m * (vt * vt + vd * vd);
    let got = thrown.metrics.energy_scale.unwrap();
    assert!(
        (got - want).abs() < 1e-14 * want,
        "energy_scale {got} vs m·|f|·5 + ½m|v⁰|² = {want}"
    );
    // The engine's E⁰ is the throw's kinetic energy with the consistent mass (u⁰ = 0): the
    // same ½m|v⁰|² (1e-12: mass_total against m above).
    let e0 = thrown.metrics.energy_initial.unwrap();
    assert!(
        (e0 - 0.5 * m * 0.25).abs() < 1e-12 * e0,
        "E⁰ = {e0} vs ½m|v⁰|² = {}",
        0.5 * m * 0.25
    );
}

/// The block of contract §1.8 (sweeps/meshes/block2d.msh, [0,1]×[0,0.5], ρ = 1: m = 0.5,
/// H = 0.5) resting on the plane under gravity, with friction, thrown along it at V_t = 0,
/// 1e-9 and 1: one unit m·|f|·H + ½mV_t² for the three (1e-14 relative: m = 0.5 is the sum of
/// the Q1 cells' exact areas to a few ulps), continuous at V_t → 0, and the three runs end
/// alike.
#[test]
fn a_resting_block_has_one_unit_whatever_its_throw() {
    let (m, h) = (0.5, 0.5);
    let mut statuses = Vec::new();
    for vt in [0.0, 1e-9, 1.0] {
        let o = run(&format!(
            "name = \"b\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"meshes/block2d.msh\"\nlame_lambda = 10.0\nlame_mu = 10.0\ngravity = {G:?}\ngap = 0.0\nvelocity_tangential = {vt:?}\nfriction = \"coulomb\"\nfriction_coefficient = 0.2\nT = 1.0\ndt = 0.05\n"
        ));
        let want = m * G * h + 0.5 * m * vt * vt;
        let got = o.metrics.energy_scale.unwrap();
        assert!(
            (got - want).abs() < 1e-14 * want,
            "V_t = {vt}: energy_scale {got} vs m·|f|·H + ½mV_t² = {want}"
        );
        statuses.push((vt, o.status.as_str().to_string(), o.message.clone()));
    }
    assert!(
        statuses.iter().all(|s| s.1 == "ok"),
        "the three throws end alike: {statuses:?}"
    );
}

/// The largest one-step rise of E + W_f over the series of a run that keeps every step: the
/// series holds E and W_f (both in joules, W_f⁰ = 0), the row divides by `energy_scale`.
/// Returns (the rise of step 1, the largest rise), over the scale.
fn series_rises(o: &Outcome) -> (f64, f64) {
    let s = &o.series;
    let scale = o.metrics.energy_scale.unwrap();
    assert_eq!(s.step[0], 0);
    assert!(s.has(9), "a friction_work column");
    let balance: Vec<f64> = (0..s.len())
        .map(|k| {
            assert!(s.valid[9][k], "W_f at step {k}");
            s.energy[k] + s.optional[9][k]
        })
        .collect();
    let rises: Vec<f64> = balance.windows(2).map(|w| (w[1] - w[0]) / scale).collect();
    (
        rises[0],
        rises.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )
}

/// The bug (issue 42): Nitsche and penalty handed E⁰ to their E + W_f tally after the first
/// step, so it started from E⁰ + W_f¹ and step 1's rise was left out of
/// `energy_balance_max_increase` (it read E¹ − E⁰, short of the friction's first work); their
/// series had no W_f at step 0. A run whose first step
/// gains: the sliding block (V_t = 0.5, Coulomb 0.2) under Newmark β = ¼, γ = 0.4 — γ < ½ is
/// negative numerical damping, E + W_f grows from the first step (measured +3.6e-6 Nitsche,
/// +4.1e-6 penalty). Over one step the row's largest rise is step 1's; over ten it is the
/// series' largest over every step from the first (the same sums of the same doubles in
/// another order: 1e-12 of the rise). W_f⁰ = 0 exactly.
#[test]
fn energy_balance_max_increase_counts_the_first_step_of_nitsche_and_penalty() {
    for space in [
        "space = \"nitsche\"\nnitsche_theta = 1.0\nnitsche_gamma0 = 1e-3",
        "space = \"penalty\"\npenalty_gamma0 = 100.0",
    ] {
        for t in [0.05, 0.5] {
            let o = run(&format!(
                "name = \"b\"\nscene = \"mesh2d\"\n[fixed]\nmesh = \"meshes/block2d.msh\"\nlame_lambda = 10.0\nlame_mu = 10.0\ngravity = {G:?}\ngap = 0.0\nvelocity_tangential = 0.5\nfriction = \"coulomb\"\nfriction_coefficient = 0.2\nscheme = \"newmark\"\nnewmark_beta = 0.25\nnewmark_gamma = 0.4\nT = {t:?}\ndt = 0.05\n{space}\n"
            ));
            let what = format!("{space} T = {t}");
            assert_eq!(o.status.as_str(), "ok", "{what}: {:?}", o.message);
            assert_eq!(o.series.optional[9][0], 0.0, "{what}: W_f⁰");
            let (first, max) = series_rises(&o);
            let row = o.metrics.energy_balance_max_increase.unwrap();
            assert!(first > 0.0, "{what}: the first step gains ({first:e})");
            assert!(
                (row - max).abs() <= 1e-12 * max.abs(),
                "{what}: energy_balance_max_increase {row:e} vs the series' {max:e}"
            );
            assert!(row >= first, "{what}: {row:e} < step 1's {first:e}");
        }
    }
}
