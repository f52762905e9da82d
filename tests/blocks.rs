//! Two blocks with a matching interface (contract §1.10, §2.6; issue 44): `blocks2d` and
//! `blocks3d` with `mixed` node-to-node rows.
//!
//! The invariant. With nothing clamped and no load, every row acts equally and oppositely
//! (B_i = e_{a,i,d} − e_{b,π(i),d}: 1_dᵀB_iᵀ = 0) and a rigid translation has no strain
//! (K 1_d = 0, K symmetric), so every scheme's momentum balance M(v^{n+1} − v^n) = τ(…Bᵀλ − Ku…)
//! gives 1_dᵀM v^{n+1} = 1_dᵀM v^n: P is constant up to the round-off of the step's solve and of
//! the carried products, whatever the mass variant and the side it acts on.

mod common;

use std::path::Path;

use common::assert_momentum;

use contact_sweep::run::{Outcome, RunOptions, Status, simulate};
use contact_sweep::sweep::{SweepFile, expand};

/// Every run of a sweep text, with its label (the run's parameters as the planner lists them).
fn run_all(text: &str) -> Vec<(String, Outcome)> {
    let plan = expand(&SweepFile::parse(Path::new("blocks.toml"), text).expect("valid sweep"))
        .expect("plan");
    assert!(!plan.runs.is_empty(), "{text}");
    plan.runs
        .iter()
        .map(|spec| {
            let label = format!("{:?}", spec.params);
            (label, simulate(&spec.config, &RunOptions::default()))
        })
        .collect()
}

/// The sweep's planning error (the message of a refused sweep).
fn plan_error(text: &str) -> String {
    match SweepFile::parse(Path::new("blocks.toml"), text).map(|s| expand(&s)) {
        Err(e) => e.to_string(),
        Ok(Err(e)) => e.to_string(),
        Ok(Ok(_)) => panic!("the sweep was accepted:\n{text}"),
    }
}

/// The implicit schemes and §3.2 methods `mixed` takes on the FE scenes (the planner leaves out
/// the combinations it refuses: CSN, generalized-α, HHT and Moreau–Jean need inertia on the
/// contact dofs).
const METHODS: &str = r#"method = [
  { scheme = "newmark", newmark_beta = 0.3, newmark_gamma = 0.6 },
  { scheme = "crank-nicolson" },
  { scheme = "newmark-dissipative" },
  { scheme = "theta", theta_scheme = 0.6 },
  { scheme = "backward-euler" },
  { scheme = "kane" },
  { scheme = "contact-stabilized-newmark" },
  { scheme = "generalized-alpha", rho_inf = 0.5 },
  { scheme = "hht", hht_alpha = 0.1 },
  { scheme = "moreau-jean", restitution = 0.0 },
]
mass = ["consistent", "lumped", "mod1", "mod2", "mod3", { mass = "weights", mass_weights = [0.5, 1.5] }, "zero-contact"]
mass_side = ["both", "a", "b"]
"#;

/// contract §2.6's invariant on blocks2d: every scheme × mass variant × mass_side, A thrown down
/// at 1 onto B thrown up at ½, 4 × 4 squares per block. Tolerance 1e-12 (issue 44 done-when
/// 3): P's terms are O(m|V|) = O(1) and each step adds the solve's and the products'
/// round-off, O(10 ε) per step over 40 steps.
#[test]
fn momentum_is_an_invariant_of_blocks2d() {
    let text = format!(
        "name = \"m2\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.8\nh = 0.25\ndt = 0.02\nvelocity = -1.0\nvelocity_b = 0.5\ngap = 0.1\n[grid]\n{METHODS}"
    );
    let runs = run_all(&text);
    // 10 schemes × 7 masses × 3 sides less the refused combinations.
    assert!(runs.len() > 100, "{} runs", runs.len());
    let worst = assert_momentum(&runs, 1e-12);
    eprintln!(
        "blocks2d: {} runs, worst momentum_drift {worst:e}",
        runs.len()
    );
}

/// The same on blocks3d (2 × 2 × 2 cubes per block), with fewer masses to keep the suite fast.
#[test]
fn momentum_is_an_invariant_of_blocks3d() {
    let methods = METHODS.replace(
        "mass = [\"consistent\", \"lumped\", \"mod1\", \"mod2\", \"mod3\", { mass = \"weights\", mass_weights = [0.5, 1.5] }, \"zero-contact\"]",
        "mass = [\"consistent\", \"lumped\", \"mod3\", \"zero-contact\"]",
    );
    let text = format!(
        "name = \"m3\"\nscene = \"blocks3d\"\n[fixed]\nT = 0.6\nh = 0.5\ndt = 0.05\nvelocity = -1.0\nvelocity_b = 0.25\nvelocity_tangential = 0.3\ngap = 0.1\n[grid]\n{methods}"
    );
    let runs = run_all(&text);
    let worst = assert_momentum(&runs, 1e-12);
    eprintln!(
        "blocks3d: {} runs, worst momentum_drift {worst:e}",
        runs.len()
    );
}

/// A property test over random meshes, steps, materials and velocities (a fixed seed: the
/// suite is reproducible): 8 blocks2d runs of CN, kane and backward Euler with random masses.
#[test]
fn momentum_holds_for_random_blocks() {
    let mut rng = fastrand::Rng::with_seed(44);
    let schemes = ["crank-nicolson", "kane", "backward-euler", "moreau-jean"];
    let masses = ["consistent", "lumped", "mod3", "zero-contact"];
    for k in 0..8 {
        let h = 1.0 / rng.usize(2..=4) as f64;
        let dt = 0.01 + 0.04 * rng.f64();
        let scheme = schemes[k % schemes.len()];
        // Moreau–Jean needs inertia at the contact.
        let mass = if scheme == "moreau-jean" {
            "consistent"
        } else {
            masses[rng.usize(0..masses.len())]
        };
        let text = format!(
            "name = \"p\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.6\nh = {h}\ndt = {dt}\nvelocity = {va}\nvelocity_b = {vb}\ngap = 0.05\nheight_b = {hb}\ndensity = {ra}\ndensity_b = {rb}\nlame_lambda = {la}\nlame_mu = {ma}\nlame_lambda_b = {lb}\nlame_mu_b = {mb}\nscheme = \"{scheme}\"\nmass = \"{mass}\"\n",
            va = -0.5 - rng.f64(),
            vb = 0.5 * rng.f64(),
            hb = [0.5, 1.0][rng.usize(0..2)],
            ra = 0.5 + rng.f64(),
            rb = 0.5 + rng.f64(),
            la = 2.0 * rng.f64(),
            ma = 0.5 + 1.5 * rng.f64(),
            lb = 2.0 * rng.f64(),
            mb = 0.5 + 1.5 * rng.f64(),
        );
        let runs = run_all(&text);
        assert_momentum(&runs, 1e-12);
    }
}

/// Rigid motion: both blocks in contact (gap 0) moving together at −1 stay a rigid translation —
/// no contact force beyond round-off, no strain energy (E constant), each body's mean velocity
/// −1. The rows' gaps are B y = y_a − y_b of two equal rigid predictions, ±1e-17 after the
/// solve, which the exact LCP may take as touching: the force it then finds is that round-off
/// over W, so the bound is on its size, 1e-12 of the momentum flux m|V|/τ = 50, not on its
/// support. E, the velocities and P: the same 1e-12 as the momentum invariant, relative to
/// O(1) quantities (measured: the mean velocities within 1.2e-13 of −1).
#[test]
fn blocks_moving_together_stay_rigid() {
    let text = "name = \"r\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.4\nh = 0.25\ndt = 0.02\nvelocity = -1.0\nvelocity_b = -1.0\ngap = 0.0\n[grid]\nscheme = [\"crank-nicolson\", \"backward-euler\", \"kane\"]\nmass = [\"consistent\", \"mod3\"]\n";
    for (label, o) in run_all(text) {
        assert_eq!(o.status, Status::Ok, "{label}: {:?}", o.message);
        let m = &o.metrics;
        let force = o
            .series
            .sigma_contact
            .iter()
            .fold(0.0f64, |a, f| a.max(f.abs()));
        assert!(!o.series.sigma_contact.is_empty(), "{label}: no series");
        assert!(force <= 1e-12 * 50.0, "{label}: contact force {force:e}");
        let e0 = m.energy_initial.unwrap();
        assert!(
            (m.energy_final.unwrap() - e0).abs() <= 1e-12 * e0,
            "{label}: E {e0} → {:?}",
            m.energy_final
        );
        for v in [m.velocity_a_final, m.velocity_b_final] {
            assert!((v.unwrap() + 1.0).abs() <= 1e-12, "{label}: {v:?}");
        }
        assert!(m.momentum_drift.unwrap() <= 1e-12, "{label}");
        eprintln!("rigid {}: force {force:e}", o.metrics.steps);
    }
}

/// `penalty` node-to-node (contract §2.6: the row force w_i κ[δ_i − g_i]_+) keeps the momentum
/// too, through the same Nitsche/penalty operators as the one-body scenes: every scheme they
/// take, the hybrid and the discrete gradient included. Same bound as `mixed`.
#[test]
fn penalty_rows_keep_the_momentum() {
    let text = "name = \"pm\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.8\nh = 0.25\ndt = 0.02\nvelocity = -1.0\nvelocity_b = 0.5\nspace = \"penalty\"\npenalty_gamma0 = 10.0\n[grid]\nscheme = [\"crank-nicolson\", \"backward-euler\", \"hybrid\", \"kane\", \"generalized-alpha\", \"discrete-gradient\", \"moreau-jean\"]\nmass = [\"consistent\", \"lumped\", \"mod3\", \"zero-contact\"]\nmass_side = [\"both\", \"b\"]\n";
    let runs = run_all(text);
    let worst = assert_momentum(&runs, 1e-12);
    eprintln!(
        "penalty: {} runs, worst momentum_drift {worst:e}",
        runs.len()
    );
}

/// The contact patch test (contract §1.10): B's base clamped, gap 0, at rest, λ = λ_b = 0,
/// μ = 1, μ_b = 2, p = 1e-2, one backward-Euler step of τ = 1e6. The static solution is
/// uniform (σ = −p e_d⊗e_d, contact pressure p) and Q1 represents it; one step is it up to
/// O(ρH²/(μτ²)) = 1e-12, and the refined condensed solve ([`contact_sweep::run`]'s iterative
/// refinement) resolves it to round-off: the bound 1e-8 of issue 44 done-when 5 (measured
/// 5e-13 to 7e-13 for mixed and penalty, 2D and 3D; without the refinement 0.9 for mixed, whose
/// LCP picks a wrong active set, and 2.6e-2 for penalty).
#[test]
fn patch_test_on_matching_blocks() {
    for (scene, h, space) in [
        ("blocks2d", 0.25, "space = \"mixed\""),
        ("blocks3d", 0.5, "space = \"mixed\""),
        (
            "blocks2d",
            0.25,
            "space = \"penalty\"\npenalty_gamma0 = 10.0",
        ),
        (
            "blocks3d",
            0.5,
            "space = \"penalty\"\npenalty_gamma0 = 10.0",
        ),
    ] {
        let runs = run_all(&common::patch_sweep(scene, h, space));
        common::assert_patch(&format!("{scene} {space}"), &runs);
    }
}

/// The column limit of contract §1.10 (W = h: one element across, λ = λ_b = 0) runs — the
/// geometry issue 44's done-when 4 compares with `bars1d` (E = 2μ) — and keeps its momentum
/// (bound as above). The comparison with `bars1d` itself is the lead's (after merging it).
#[test]
fn the_column_runs_with_one_element_across() {
    let text = "name = \"c\"\nscene = \"blocks2d\"\n[fixed]\nT = 2.0\nwidth = 0.125\nh = 0.125\ndt = 0.0625\nlame_lambda = 0.0\nlame_lambda_b = 0.0\n[grid]\nscheme = [\"crank-nicolson\", \"kane\"]\nmass = [\"consistent\", \"zero-contact\"]\n";
    let runs = run_all(text);
    for (label, o) in &runs {
        assert_eq!(
            o.metrics.dofs,
            2 * 2 * 18,
            "{label}: two columns of 9 + 9 nodes"
        );
    }
    let worst = assert_momentum(&runs, 1e-12);
    eprintln!(
        "column: {} runs, worst momentum_drift {worst:e}",
        runs.len()
    );
}

/// Bad input is refused at plan time naming the key: a non-matching interface (issue 45), a
/// clamped base that moves, a two-body key on a one-body scene.
#[test]
fn two_body_input_is_checked_at_plan_time() {
    let base = "name = \"b\"\nscene = \"blocks2d\"\n[fixed]\nT = 0.1\nh = 0.25\ndt = 0.05\n";
    let e = plan_error(&format!("{base}mesh_ratio = 1.3333\n"));
    assert!(e.contains("mesh_ratio") && e.contains("issue 45"), "{e}");
    let e = plan_error(&format!("{base}far_end = \"clamped\"\nvelocity_b = 1.0\n"));
    assert!(e.contains("velocity_b") && e.contains("clamped"), "{e}");
    let e = plan_error(&format!("{base}far_end = \"glued\"\n"));
    assert!(e.contains("far_end"), "{e}");
    let e = plan_error(
        "name = \"b\"\nscene = \"bar2d\"\n[fixed]\nT = 0.1\nh = 0.1\ndt = 0.05\nheight_b = 1.0\n",
    );
    assert!(e.contains("height_b"), "{e}");
}
