//! Momentum of two free blocks, a property test (contract §2.6, §5; issue 44 done-when 3):
//! `momentum_drift` ≤ 1e-12 on `blocks2d` and `blocks3d` with a free base over random h, τ,
//! per-body materials, velocities, gaps and penalty parameters, for every scheme and contract
//! §3.2 method the blocks take × `mixed`/`penalty` × every mass variant × `mass_side`, with and
//! without gravity, runs of 100 to 130 steps in 2D.
//!
//! The invariant. Every row acts equally and oppositely on the two bodies (1_dᵀB_iᵀ = 0), a
//! rigid translation has no strain (1_dᵀK = 0), and 1_dᵀM aⁿ = F (the total weight) from a⁰ on,
//! so every scheme's momentum balance gives P^{n+1} = Pⁿ + τF exactly: `momentum_drift` =
//! max_n |Pⁿ − P⁰ − tⁿF| / (Σ_i m_i|V_i| + T|F|) is round-off. The tolerance 1e-12: the
//! two-body runs step in increments (`run::fe::newmark`'s header; the §3.2 methods solve for
//! Δu or Δv), so each step's solve and products add round-off relative to the increment's
//! scale, O(10 ε) of the momentum scale per step, which over ≤ 130 steps is ~1e-13 as a sum
//! of independent errors (measured worst below, printed); in totals the same runs reached
//! 6.5e-11 over 300 steps, the round-off of |u| that grows with the distance travelled.

mod common;

use std::path::Path;

use contact_sweep::run::{Outcome, Status};

/// The implicit schemes and §3.2 methods of `mixed` (the planner leaves out what it refuses:
/// CSN, generalized-α, HHT and Moreau–Jean need inertia on the contact dofs).
const MIXED: &str = r#"method = [
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
"#;

/// The schemes of `penalty` on two bodies (the hybrid midpoint rule and the discrete gradient
/// among them; the planner leaves out the mixed-only methods).
const PENALTY: &str = r#"method = [
  { scheme = "newmark", newmark_beta = 0.3, newmark_gamma = 0.6 },
  { scheme = "crank-nicolson" },
  { scheme = "newmark-dissipative" },
  { scheme = "backward-euler" },
  { scheme = "hybrid" },
  { scheme = "generalized-alpha", rho_inf = 0.8 },
  { scheme = "discrete-gradient" },
]
"#;

const MASSES: &str = r#"mass = ["consistent", "lumped", "mod1", "mod2", "mod3", { mass = "weights", mass_weights = [0.5, 1.5] }, "zero-contact"]
mass_side = ["both", "a", "b"]
"#;

/// One random case: its scene, the [fixed] table and a description.
struct Case {
    scene: &'static str,
    fixed: String,
}

fn case(rng: &mut fastrand::Rng, dim: usize, gravity: bool, steps: usize) -> Case {
    // At least two element layers per body (mod1's layers).
    let h = if dim == 2 {
        1.0 / rng.usize(4..=6) as f64
    } else {
        1.0 / rng.usize(2..=3) as f64
    };
    let heights: &[f64] = if dim == 2 { &[0.5, 1.0] } else { &[1.0] };
    let dt = 0.01 + 0.03 * rng.f64();
    let gravity = if gravity { 0.5 + 2.0 * rng.f64() } else { 0.0 };
    let fixed = format!(
        "T = {t}\nh = {h}\ndt = {dt}\nvelocity = {va}\nvelocity_b = {vb}\nvelocity_tangential = {vt}\ngap = {gap}\nheight = {ha}\nheight_b = {hb}\ndensity = {ra}\ndensity_b = {rb}\nlame_lambda = {la}\nlame_mu = {ma}\nlame_lambda_b = {lb}\nlame_mu_b = {mb}\ngravity = {gravity}\npenalty_gamma0 = {g0}\n",
        t = steps as f64 * dt,
        va = -0.5 - rng.f64(),
        vb = 0.5 * rng.f64() - 0.25,
        vt = 0.5 * rng.f64(),
        gap = 0.02 + 0.08 * rng.f64(),
        ha = heights[rng.usize(0..heights.len())],
        hb = heights[rng.usize(0..heights.len())],
        ra = 0.5 + rng.f64(),
        rb = 0.5 + rng.f64(),
        la = 2.0 * rng.f64(),
        ma = 0.5 + 1.5 * rng.f64(),
        lb = 2.0 * rng.f64(),
        mb = 0.5 + 1.5 * rng.f64(),
        g0 = 1.0 + 19.0 * rng.f64(),
    );
    Case {
        scene: if dim == 2 { "blocks2d" } else { "blocks3d" },
        fixed,
    }
}

/// The runs of one case's grid; asserts each ended ok, touched, and returns the worst drift.
fn worst_drift(c: &Case, space: &str, grid: &str) -> (usize, f64) {
    let text = format!(
        "name = \"pm\"\nscene = \"{}\"\n[fixed]\n{}space = \"{space}\"\n[grid]\n{grid}",
        c.scene, c.fixed
    );
    let runs = common::outcomes_at(Path::new("blocks.toml"), &text);
    let mut worst = 0.0f64;
    for (label, o) in &runs {
        check(label, o);
        worst = worst.max(o.metrics.momentum_drift.unwrap());
    }
    (runs.len(), worst)
}

/// Bound 1e-12 (module header); the run ended ok and the blocks met.
fn check(label: &str, o: &Outcome) {
    assert_eq!(o.status, Status::Ok, "{label}: {:?}", o.message);
    assert!(
        o.metrics.contact_phases.unwrap_or(0) >= 1,
        "{label}: the blocks never touched"
    );
    let drift = o.metrics.momentum_drift.expect("free blocks have a drift");
    assert!(drift <= 1e-12, "{label}: momentum_drift {drift:e}");
}

/// Every scheme × treatment × mass × side on four random cases: blocks2d and blocks3d, each
/// with and without gravity (a fixed seed: the suite is reproducible).
#[test]
fn momentum_holds_for_every_method_on_random_blocks() {
    let mut rng = fastrand::Rng::with_seed(4444);
    let mut total = 0;
    let mut worst = 0.0f64;
    for (dim, gravity, steps) in [
        (2, false, 130),
        (2, true, 100),
        (3, false, 50),
        (3, true, 40),
    ] {
        let c = case(&mut rng, dim, gravity, steps);
        for (space, methods) in [("mixed", MIXED), ("penalty", PENALTY)] {
            let (n, w) = worst_drift(&c, space, &format!("{methods}{MASSES}"));
            eprintln!(
                "{} {space} gravity {gravity}: {n} runs of {steps} steps, worst momentum_drift {w:e}",
                c.scene
            );
            total += n;
            worst = worst.max(w);
        }
    }
    assert!(total > 600, "{total} runs");
    eprintln!("{total} runs, worst momentum_drift {worst:e}");
}

/// Kinematic central difference on two bodies (contract §3.2, lumped mass, `mixed`): each node
/// pair that would interpenetrate is put in contact by one impulse on both nodes, action =
/// reaction, so the momentum holds as for the implicit schemes; no penetration remains
/// (each row is put exactly on its constraint, up to the round-off of B(u + Δ) + g, bound
/// 1e-12 of the gap); at Courant 0.3, below the certified CFL limit.
#[test]
fn central_difference_keeps_the_momentum_of_two_blocks() {
    let mut rng = fastrand::Rng::with_seed(4445);
    for (dim, gravity) in [(2, false), (2, true), (3, false), (3, true)] {
        let c = case(&mut rng, dim, gravity, 100);
        // The case's dt gives way to the Courant number (dt = 0.3 h/c0).
        let fixed: String = c
            .fixed
            .lines()
            .filter(|l| !l.starts_with("dt =") && !l.starts_with("T ="))
            .map(|l| format!("{l}\n"))
            .collect();
        let text = format!(
            "name = \"cd\"\nscene = \"{}\"\n[fixed]\n{fixed}T = 8.0\ncourant = 0.3\nscheme = \"central-difference\"\nmass = \"lumped\"\n",
            c.scene
        );
        for (label, o) in common::outcomes_at(Path::new("blocks.toml"), &text) {
            check(&label, &o);
            let steps = o.metrics.steps;
            let pen = o.metrics.max_penetration.unwrap_or(0.0);
            assert!(pen <= 1e-12, "{label}: penetration {pen:e}");
            eprintln!(
                "{} central difference gravity {gravity}: {steps} steps, momentum_drift {:e}, penetration {pen:e}",
                c.scene,
                o.metrics.momentum_drift.unwrap()
            );
            assert!(steps >= 100, "{label}: {steps} steps");
        }
    }
}

/// With gravity the invariant is P⁰ + tF, not P⁰: a pair thrown together with no contact
/// falls freely, its momentum at T is P⁰ + T·F to round-off, and the series' Pⁿ shows it
/// (the total weight F = −g Σ_i ρ_i|Ω_i| along e_d: ρ_a = 1, ρ_b = 2, |Ω_a| = |Ω_b| = 1,
/// g = 2, so F = −6; the consistent mass keeps 1ᵀM1 = ∫ρ). Bound 1e-12 relative, as above.
#[test]
fn gravity_moves_the_momentum_by_the_weight() {
    let text = "name = \"g\"\nscene = \"blocks2d\"\n[fixed]\nT = 1.0\nh = 0.25\ndt = 0.02\nvelocity = -0.5\nvelocity_b = -0.5\ngap = 0.1\ndensity = 1.0\ndensity_b = 2.0\ngravity = 2.0\nscheme = \"crank-nicolson\"\nmass = \"consistent\"\n";
    for (label, o) in common::outcomes_at(Path::new("blocks.toml"), text) {
        assert_eq!(o.status, Status::Ok, "{label}: {:?}", o.message);
        // The series' `momentum` column (the last of the optional series).
        let p = &o.series.optional[11];
        assert_eq!(p.len(), 51, "{label}: one Pⁿ per step");
        let (p0, pn) = (p[0], p[p.len() - 1]);
        // P⁰ = −0.5·(1 + 2) = −1.5; P(T) = −1.5 − 6·1.
        assert!((p0 + 1.5).abs() <= 1e-12, "{label}: P⁰ {p0}");
        assert!((pn + 7.5).abs() <= 1e-12 * 7.5, "{label}: P(T) {pn}");
        let drift = o.metrics.momentum_drift.unwrap();
        assert!(drift <= 1e-12, "{label}: {drift:e}");
        // The blocks fall together: never in contact, the mean velocities −0.5 − g T.
        assert_eq!(o.metrics.contact_phases, Some(0), "{label}");
        for v in [o.metrics.velocity_a_final, o.metrics.velocity_b_final] {
            assert!((v.unwrap() + 2.5).abs() <= 1e-12, "{label}: {v:?}");
        }
    }
}

/// The same invariant on non-matching blocks (issue 45 done-when 2): B with round(4/3·W/h)
/// elements across, every projecting pairing (node-to-segment; mortar with both bases, on the
/// segmentation and on the element rule) × `mixed`/`penalty` × every scheme × every mass
/// variant and side, 2D and 3D, without gravity. Each row's coefficients sum to zero up
/// to round-off (Σ_j N_j = 1; Σ_i D_ki = Σ_j M_kj), so the bound is the matching blocks' 1e-12
/// (module header).
#[test]
fn momentum_holds_on_non_matching_blocks() {
    let mut rng = fastrand::Rng::with_seed(4545);
    let pairings = "pairing = [\"node-to-segment\", \"mortar\"]\nmortar_basis = [\"standard\", \"dual\"]\ninterface_quadrature = [\"segment\", \"element\"]\n";
    let mut worst = 0.0f64;
    for (dim, gravity, steps) in [(2, false, 40), (3, false, 15)] {
        let mut c = case(&mut rng, dim, gravity, steps);
        c.fixed.push_str("mesh_ratio = 1.3333333333333333\n");
        for (space, methods) in [("mixed", MIXED), ("penalty", PENALTY)] {
            let (n, w) = worst_drift(&c, space, &format!("{methods}{MASSES}{pairings}"));
            eprintln!(
                "{} non-matching {space} gravity {gravity}: {n} runs of {steps} steps, worst momentum_drift {w:e}",
                c.scene
            );
            worst = worst.max(w);
        }
    }
    eprintln!("non-matching: worst momentum_drift {worst:e}");
}
