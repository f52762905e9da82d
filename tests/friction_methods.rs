//! Friction in contract §3.2's methods with the nodal multiplier (issue 33, "done when" 2):
//! property tests over seeded random (h, τ, μ_f) on bar2d, bar3d, disc2d and sphere3d.
//!
//! - `kane` and `moreau-jean` (θ = ½) never raise E^h + W_f by more than 1e-12 energy scales in
//!   a step (`energy_balance_max_increase`), and `moreau-jean` with e = 1 conserves it;
//! - μ_f = 0 and s = 0 give the frictionless rows bit for bit, every method;
//! - friction does work on the bars (`friction_work` > 0: the Poisson expansion of the struck
//!   face slides its nodes outwards) and on the disc thrown along e_1;
//! - kinematic `central-difference` (lumped): the tangential force is the local projection of
//!   the force that stops the slip increment onto the disc of radius μ_f·λ — its work is never
//!   negative, |Σf_t| ≤ μ_f Σf_n, and no dof penetrates;
//! - every frictional run keeps |Σf_t| ≤ μ_f Σf_n (`friction_ratio_max`).
//!
//! The meshes are the coarse ones of tests/fe_methods.rs (bar2d h = 0.1/0.05, bar3d h = 0.1,
//! disc/ball h = 8, degree 1) so each test stays well under 30 s in release.

mod common;
use common::{outcomes, run_sweep_text};

use contact_sweep::run::Outcome;

/// Seeded draws (h, τ, μ_f): h from the meshes the tests afford, τ between a tenth and a whole
/// Courant number on the bars (c0 = √(λ + 2μ) = 1.118), μ_f ∈ [0.05, 1].
fn draws(seed: u64, hs: &[f64], count: usize) -> Vec<(f64, f64, f64)> {
    let mut rng = fastrand::Rng::with_seed(seed);
    (0..count)
        .map(|_| {
            let h = hs[rng.usize(..hs.len())];
            let dt = h * (0.1 + 0.9 * rng.f64());
            let mu = 0.05 + 0.95 * rng.f64();
            (h, dt, mu)
        })
        .collect()
}

/// The friction columns every frictional run reports, and the checks common to all: the run
/// hit the obstacle and |Σf_t| ≤ μ_f Σf_n (the law holds per node, so for the sums). The
/// semismooth Newton stops at a natural residual of 1e-12 of the problem's force scale — the
/// largest |f| or r|q| over the nodes, the force that would stop one node's free motion alone,
/// up to ~100 times a step's mean node force at an impact on these meshes — so a node's
/// |f_t| may exceed μ_f f_n by 1e-12 of that: 1e-10 relative (measured up to 6.5e-12 on the
/// tetrahedra cube, where every node slides the same way and the sums sit on the cone).
fn check_common(place: &str, label: &str, o: &Outcome, mu: Option<f64>) -> (f64, f64) {
    let m = &o.metrics;
    let work = m
        .friction_work
        .expect("a frictional run reports friction_work");
    let rise = m
        .energy_balance_max_increase
        .expect("a frictional run reports energy_balance_max_increase");
    let ratio = m.friction_ratio_max;
    eprintln!(
        "{place} {label}: min tangential work {:.2e}, W_f/scale {work:.4e}, max rise of E + W_f {rise:.3e}, drift {:.3e}, stick {:?} slip {:?}, |Σf_t|/Σf_n ≤ {ratio:?}, its {} (max {:?})",
        m.tangential_work_min.unwrap(),
        m.energy_balance_drift.unwrap(),
        m.stick_steps,
        m.slip_steps,
        m.iterations,
        m.iterations_max_step
    );
    assert!(
        m.contact_phases.unwrap() >= 1,
        "{place} {label}: the body must hit the obstacle"
    );
    // Every position-level method's step does the tangential work −Σf_t^{n+1}·Δu_t ≥ 0 (contract
    // §2.5: the law's own sign, per node); a stuck node's Δu_t is the solver's residual, whose
    // work is ~1e-12 of a force times 1e-12 of a displacement: nothing at 1e-15 scales.
    // (Moreau–Jean's slip is v_t^{n+1}, not Δu_t/τ: no sign.)
    let own = m.tangential_work_min.expect("a frictional run reports it");
    if !label.contains("moreau-jean") {
        assert!(
            own >= -1e-15,
            "{place} {label}: a step's tangential work {own:.3e}"
        );
    }
    if let (Some(mu), Some(r)) = (mu, ratio) {
        assert!(
            r <= mu * (1.0 + 1e-10),
            "{place} {label}: |Σf_t|/Σf_n = {r} above μ_f = {mu}"
        );
    }
    (work, rise)
}

/// Kinematic friction on the bars: no penetration (as without friction: ≤ 1e-14 length
/// scales, measured 0), the tangential work −f_t·Δu_t of every step is ≥ 0 (the projection
/// onto the disc: τ²/m (b|s| − b²) with |s| > b, so W_f never decreases; 1e-15 energy scales
/// for the rounding of the series' sums), friction does work (W_f > 0), and the sums obey
/// the law. Coulomb and Tresca, seeded μ_f, τ below the certified CFL step (0.89 h on bar2d
/// h = 0.05, 0.81 h on bar3d h = 0.1).
#[test]
fn kinematic_friction_is_a_local_projection() {
    let mut rng = fastrand::Rng::with_seed(33);
    for scene in ["bar2d", "bar3d"] {
        let h = if scene == "bar2d" { 0.05 } else { 0.1 };
        let dt = h * (0.05 + 0.25 * rng.f64());
        let mu = 0.05 + 0.45 * rng.f64();
        let text = format!(
            r#"
name = "cd"
scene = "{scene}"
[fixed]
T = 1.5
h = {h}
dt = {dt}
mass = "lumped"
scheme = "central-difference"
[grid]
law = [
  {{ friction = "coulomb", friction_coefficient = {mu} }},
  {{ friction = "tresca", tresca_threshold = 0.02 }},
]
"#
        );
        for (label, o) in outcomes(&text) {
            let place = format!("{scene} dt = {dt:.5} μ_f = {mu:.3}");
            let coulomb = label.contains("coulomb");
            let (work, _) = check_common(&place, &label, &o, coulomb.then_some(mu));
            let pen = o.metrics.max_penetration.unwrap();
            let len = o.metrics.length_scale.unwrap();
            assert!(pen <= 1e-14 * len, "{place} {label}: penetration {pen:.3e}");
            let scale = o.metrics.energy_scale.unwrap();
            let wf: Vec<f64> = o
                .series
                .rows()
                .map(|r| r.friction_work.expect("the series has W_f"))
                .collect();
            let worst = wf
                .windows(2)
                .map(|w| (w[1] - w[0]) / scale)
                .fold(f64::INFINITY, f64::min);
            assert!(
                worst >= -1e-15,
                "{place} {label}: W_f fell by {worst:.3e}·scale in a step"
            );
            assert!(work > 0.0, "{place} {label}: friction did no work");
            assert_eq!(wf.last().copied().unwrap() / scale, work);
        }
    }
}

/// μ_f = 0 and s = 0 are the frictionless problem: every method's rows equal `friction =
/// "none"`'s bit for bit (contract §2.5) — energies, contact force, displacement and velocity at
/// every step, and the run's energy columns; the run ids differ. Seeded h, τ on bar2d (the
/// kinematic run below its CFL step, 0.89 h at h = 0.05).
#[test]
fn zero_friction_is_frictionless_bit_for_bit() {
    for (h, dt, _) in draws(34, &[0.1, 0.05], 2) {
        let cd_dt = 0.3 * dt.min(0.8 * h);
        let text = |law: &str| {
            format!(
                r#"
name = "mu0"
scene = "bar2d"
[fixed]
T = 1.0
h = {h}
dt = {dt}
{law}
[grid]
method = [
  {{ mass = "consistent", scheme = "kane" }},
  {{ mass = "mod3", scheme = "kane" }},
  {{ mass = "consistent", scheme = "contact-stabilized-newmark" }},
  {{ mass = "consistent", scheme = "generalized-alpha", rho_inf = 0.5 }},
  {{ mass = "lumped", scheme = "hht", hht_alpha = 0.1 }},
  {{ mass = "consistent", scheme = "moreau-jean", theta_scheme = 0.5, restitution = 0.0 }},
  {{ mass = "lumped", scheme = "central-difference", dt = {cd_dt} }},
]
"#
            )
        };
        let base = outcomes(&text(""));
        let per = base.len();
        assert_eq!(per, 7);
        for law in [
            "friction = \"coulomb\"\nfriction_coefficient = 0.0",
            "friction = \"tresca\"\ntresca_threshold = 0.0",
        ] {
            let runs = outcomes(&text(law));
            for ((base_label, b), (label, o)) in base.iter().zip(&runs) {
                assert!(o.metrics.contact_phases.unwrap() >= 1, "{label}");
                let (s, bs) = (&o.series, &b.series);
                assert_eq!(s.energy, bs.energy, "{label} against {base_label}");
                assert_eq!(s.sigma_contact, bs.sigma_contact, "{label}");
                assert_eq!(s.u_contact, bs.u_contact, "{label}");
                assert_eq!(s.v_contact, bs.v_contact, "{label}");
                assert_eq!(o.metrics.energy_final, b.metrics.energy_final, "{label}");
                assert_eq!(o.metrics.energy_max_increase, b.metrics.energy_max_increase);
            }
        }
        eprintln!("h = {h} dt = {dt:.5}: {per} methods × 3 laws equal bit for bit");
    }
}

/// max_n |b^{n+1} − b^n|/scale and |b^N − b^0|/scale of E + W_f over a run's series.
fn balance_changes(o: &Outcome) -> (f64, f64) {
    let scale = o.metrics.energy_scale.unwrap();
    let b: Vec<f64> = o
        .series
        .rows()
        .map(|r| r.energy + r.friction_work.expect("the series has W_f"))
        .collect();
    let step = b
        .windows(2)
        .map(|w| ((w[1] - w[0]) / scale).abs())
        .fold(0.0, f64::max);
    (step, ((b[b.len() - 1] - b[0]) / scale).abs())
}

/// The sweep of one draw: the methods with friction on `scene`.
fn frictional_sweep(scene: &str, fixed: &str, law: &str, methods: &str) -> Vec<(String, Outcome)> {
    outcomes(&format!(
        "name = \"f\"\nscene = \"{scene}\"\n[fixed]\n{fixed}\n{law}\n[grid]\nmethod = [\n{methods}]\n"
    ))
}

/// `kane` and `moreau-jean` (θ = ½) never raise E + W_f by more than 1e-12 energy scales in a
/// step (contract §2.5, module header of run::fe's methods: kane's step changes it by
/// −λ·(Buⁿ + g) ≤ 0, Moreau–Jean's by ½(1 − e)p_n·Bvⁿ). Moreau–Jean with e = 1 conserves
/// E + W_f: its step change is ½p_n·(Bv^{n+1} + Bvⁿ), zero up to the solver's residual.
///
/// Tolerances. E + W_f is re-evaluated each step from the state: ½vᵀMv + ½uᵀKu − Fᵀu + W_f,
/// sums of n ≤ 300 products; each rounds at ε·n·c relative to the scale, c the ratio of the
/// terms' magnitudes to the energy scale (≤ ~10: on the disc the gravity potential and the
/// kinetic energy are a few scales each and cancel), so ≈ 2.2e-16·300·10 ≈ 7e-13 per step
/// in the worst case; the contact solve stops at a natural residual of 1e-12 of the forces,
/// whose work over a step, ~1e-12·|p|·|Bv|, is ≤ 1e-12 scales as well. So 1e-12 per step
/// (measured: ≤ 9e-14 for kane and Moreau–Jean on the four scenes, against 1e-3…1 for a
/// generalized-α/HHT step), and for e = 1 a drift ≤ N·1e-12 over the N ≤ 300 steps of a draw,
/// the per-step errors' worst-case sum (measured ≤ 4e-14: they do not accumulate
/// coherently). The other methods run the same draws: ok, |Σf_t| ≤ μ_f Σf_n. Kane's and CSN's
/// step's tangential work −f_t^{n+1}·Δu_t is ≥ 0 (the law's sign): W_f never falls, and it
/// grows where a node slid.
fn balance_never_rises(scene: &str, draws: &[(f64, f64, f64)], extra: &str, bars: bool) {
    for (k, &(h, dt, mu)) in draws.iter().enumerate() {
        let e = if k % 2 == 0 { 1.0 } else { 0.0 };
        let fixed = format!("h = {h}\ndt = {dt}\n{extra}");
        let law = format!("friction = \"coulomb\"\nfriction_coefficient = {mu}");
        let kane_masses = if bars {
            "  { mass = \"consistent\", scheme = \"kane\" },\n  { mass = \"lumped\", scheme = \"kane\" },\n  { mass = \"mod3\", scheme = \"kane\" },\n"
        } else {
            "  { mass = \"consistent\", scheme = \"kane\" },\n  { mass = \"lumped\", scheme = \"kane\" },\n"
        };
        let methods = format!(
            "{kane_masses}  {{ mass = \"consistent\", scheme = \"moreau-jean\", theta_scheme = 0.5, restitution = {e} }},\n  {{ mass = \"lumped\", scheme = \"moreau-jean\", theta_scheme = 0.5, restitution = 0.0 }},\n  {{ mass = \"consistent\", scheme = \"contact-stabilized-newmark\" }},\n  {{ mass = \"consistent\", scheme = \"generalized-alpha\", rho_inf = 0.5 }},\n  {{ mass = \"lumped\", scheme = \"hht\", hht_alpha = 0.1 }},\n"
        );
        let place = format!("{scene} h = {h} dt = {dt:.5} μ_f = {mu:.3}");
        for (label, o) in frictional_sweep(scene, &fixed, &law, &methods) {
            let (work, rise) = check_common(&place, &label, &o, Some(mu));
            let (step, drift) = balance_changes(&o);
            eprintln!("    max |Δ(E + W_f)| {step:.3e}, |drift| {drift:.3e}");
            if label.contains("kane") || label.contains("moreau-jean") {
                assert!(
                    rise <= 1e-12,
                    "{place} {label}: E + W_f rose by {rise:.3e}·scale in a step"
                );
            }
            if label.contains("moreau-jean") && label.contains("e=1)") {
                let n = o.metrics.steps as f64;
                assert!(
                    step <= 1e-12,
                    "{place} {label}: E + W_f moved by {step:.3e}"
                );
                assert!(drift <= 1e-12 * n, "{place} {label}: drift {drift:.3e}");
            }
            // Kane's and CSN's steps do the tangential work −f_t^{n+1}·Δu_t ≥ 0 (the law's
            // sign): W_f never decreases beyond the rounding of its sum (1e-15 scales).
            if label.contains("kane") || label.contains("contact-stabilized") {
                let scale = o.metrics.energy_scale.unwrap();
                let wf: Vec<f64> = o.series.rows().map(|r| r.friction_work.unwrap()).collect();
                let fall = wf
                    .windows(2)
                    .map(|w| (w[1] - w[0]) / scale)
                    .fold(0.0f64, f64::min);
                assert!(fall >= -1e-15, "{place} {label}: W_f fell by {fall:.3e}");
                assert!(work >= -1e-15, "{place} {label}: W_f = {work:.3e}");
            }
            // Where nodes slid, those steps' work is positive: W_f > 0. (Generalized-α's and
            // HHT's f̄_t mixes two steps' forces and Moreau–Jean's slip is v_t^{n+1}, not
            // Δu_t/τ: their W_f has no sign per step — measured −6e-4 for HHT at μ_f = 0.335.)
            let signed = label.contains("kane") || label.contains("contact-stabilized");
            if signed && o.metrics.slip_steps.unwrap() > 0 {
                assert!(work > 0.0, "{place} {label}: friction did no work");
            }
        }
    }
}

#[test]
fn bar2d_energy_plus_friction_work_never_rises() {
    balance_never_rises("bar2d", &draws(35, &[0.1, 0.05], 3), "T = 1.5", true);
}

#[test]
fn bar3d_energy_plus_friction_work_never_rises() {
    balance_never_rises("bar3d", &draws(36, &[0.1], 2), "T = 1.5", true);
}

/// Friction does work on the bars: the impact's Poisson expansion slides the struck face's
/// nodes outwards (at μ_f = 0.05 and Tresca s = 0.02 they slip; at μ_f ≳ 0.3 the coarse bars
/// stick and W_f is round-off, measured ±1e-16). Every method, both bars, W_f > 0 — for
/// generalized-α/HHT and Moreau–Jean too at this μ_f, though their steps' work has no sign.
#[test]
fn friction_does_work_on_the_bars() {
    let methods = "  { mass = \"consistent\", scheme = \"kane\" },\n  { mass = \"mod3\", scheme = \"kane\" },\n  { mass = \"consistent\", scheme = \"contact-stabilized-newmark\" },\n  { mass = \"consistent\", scheme = \"generalized-alpha\", rho_inf = 0.5 },\n  { mass = \"lumped\", scheme = \"hht\", hht_alpha = 0.1 },\n  { mass = \"consistent\", scheme = \"moreau-jean\", theta_scheme = 0.5, restitution = 0.0 },\n  { mass = \"lumped\", scheme = \"central-difference\", dt = 0.01 },\n";
    for (scene, h) in [("bar2d", 0.05), ("bar3d", 0.1)] {
        for (law, mu) in [
            (
                "friction = \"coulomb\"\nfriction_coefficient = 0.05",
                Some(0.05),
            ),
            ("friction = \"tresca\"\ntresca_threshold = 0.02", None),
        ] {
            let fixed = format!("T = 1.5\nh = {h}\ndt = 0.02");
            for (label, o) in frictional_sweep(scene, &fixed, law, methods) {
                let (work, _) = check_common(scene, &label, &o, mu);
                assert!(work > 0.0, "{scene} {label}: friction did no work");
                assert!(
                    o.metrics.slip_steps.unwrap() > 0,
                    "{scene} {label}: no slip"
                );
            }
        }
    }
}

/// The disc and the ball under gravity (gap 0.05: the impact at t ≈ 1, then they stay in
/// contact, bouncing; the contact patch spreads and slides outwards): seeded τ ∈ [0.05, 0.2]
/// and μ_f, the mesh of tests/fe_methods.rs (h = 8, degree 1).
fn ball_draws(seed: u64) -> Vec<(f64, f64, f64)> {
    let mut rng = fastrand::Rng::with_seed(seed);
    (0..2)
        .map(|_| (8.0, 0.05 + 0.15 * rng.f64(), 0.05 + 0.95 * rng.f64()))
        .collect()
}

#[test]
fn disc2d_energy_plus_friction_work_never_rises() {
    balance_never_rises(
        "disc2d",
        &ball_draws(37),
        "T = 4.0\ngap = 0.05\ndegree = 1",
        false,
    );
}

#[test]
fn sphere3d_energy_plus_friction_work_never_rises() {
    balance_never_rises(
        "sphere3d",
        &ball_draws(38),
        "T = 4.0\ngap = 0.05\ndegree = 1",
        false,
    );
}

/// The disc thrown along e_1 (v⁰ = (V, 0) on every node; set on the planned run, the sweep key
/// being the mesh scenes'): while every contact node slides forward, f_t = −μ_f f_n at each of
/// them, and the free body's momentum P = 1ᵀMv per direction obeys contract §1.8's balance
/// P_1 + μ_f P_d − (ΣF_1 + μ_f ΣF_d)·t = const (1ᵀK = 0 for the unclamped disc; every
/// method's momentum equation is linear in the forces of its time levels). With the body load
/// ΣF = −g·m e_d and 1ᵀM1 = m per direction (consistent and lumped masses), in mean velocities:
/// v̄_1(T) + μ_f (v̄_d(T) + gT) = V. V = 1 is ten times the impact velocity √(2g·0.05) = 0.1,
/// so no node sticks before T = 3 (asserted: stick_steps = 0, the balance's premise). Exact in
/// exact arithmetic: the momentum sums of ~100 dofs over ≤ 60 steps round at ~1e-14·V, and the
/// solver's residual (1e-12 of the forces) enters τΣf ≈ 1e-13·V; 1e-11·V bounds both.
/// This checks the sign and the size of every method's tangential force.
#[test]
fn disc2d_sliding_keeps_the_coulomb_momentum_balance() {
    use contact_sweep::run::{RunConfig, RunOptions, simulate};
    let (v_t, mu, t_final) = (1.0, 0.3, 3.0);
    let text = format!(
        r#"
name = "slide"
scene = "disc2d"
[fixed]
T = {t_final}
h = 8.0
dt = 0.05
gap = 0.05
degree = 1
friction = "coulomb"
friction_coefficient = {mu}
[grid]
method = [
  {{ mass = "consistent", scheme = "kane" }},
  {{ mass = "lumped", scheme = "kane" }},
  {{ mass = "consistent", scheme = "contact-stabilized-newmark" }},
  {{ mass = "consistent", scheme = "generalized-alpha", rho_inf = 0.5 }},
  {{ mass = "lumped", scheme = "hht", hht_alpha = 0.1 }},
  {{ mass = "consistent", scheme = "moreau-jean", theta_scheme = 0.5, restitution = 0.0 }},
  {{ mass = "lumped", scheme = "moreau-jean", theta_scheme = 0.5, restitution = 1.0 }},
  {{ mass = "lumped", scheme = "central-difference", dt = 0.01 }},
]
"#
    );
    let plan = contact_sweep::sweep::expand(
        &contact_sweep::sweep::SweepFile::parse(std::path::Path::new("t.toml"), &text).unwrap(),
    )
    .unwrap();
    assert_eq!(plan.runs.len(), 8);
    for spec in &plan.runs {
        let mut config = spec.config.clone();
        let RunConfig::Fe(cfg) = &mut config else {
            unreachable!("disc2d is an FE scene")
        };
        cfg.setup.v0_tangential = v_t;
        let (g, dt) = (cfg.setup.gravity, cfg.dt);
        let o = simulate(&config, &RunOptions::default());
        assert_eq!(o.status.as_str(), "ok", "{}: {:?}", spec.label, o.message);
        let m = &o.metrics;
        let (v1, vd) = (
            m.tangential_velocity_final.unwrap(),
            m.normal_velocity_final.unwrap(),
        );
        let t = m.steps as f64 * dt;
        let balance = v1 + mu * (vd + g * t) - v_t;
        eprintln!(
            "{}: v̄_1 {v1:.6}, v̄_d {vd:.3e}, balance {balance:.3e}, W_f/scale {:.4e}, stick {:?} slip {:?}, phases {:?}",
            spec.label,
            m.friction_work.unwrap(),
            m.stick_steps,
            m.slip_steps,
            m.contact_phases
        );
        assert!(m.contact_phases.unwrap() >= 1, "{}: no contact", spec.label);
        assert!(m.slip_steps.unwrap() > 0, "{}: no slip", spec.label);
        assert_eq!(m.stick_steps, Some(0), "{}: a node stuck", spec.label);
        assert!(
            balance.abs() <= 1e-11 * v_t,
            "{}: the momentum balance is off by {balance:.3e}",
            spec.label
        );
        // Friction took energy: v̄_1 fell below V.
        assert!(v1 < v_t && m.friction_work.unwrap() > 0.0, "{}", spec.label);
    }
}

/// The Gmsh path (mesh3d, issue 22's clamped cube of P1 tetrahedra, 125 nodes, dropped as
/// bar3d is): its Γ_C nodes' tangential dofs and Tresca's weights from the mesh's faces. Kane
/// and Moreau–Jean (e = 0, 1) keep the bounds of [`balance_never_rises`], Moreau–Jean e = 1
/// conserves E + W_f, kinematic central difference never penetrates, and friction does work
/// (μ_f = 0.05 and s = 0.02: the struck face slides outwards, as the bars').
#[test]
fn mesh3d_tetrahedra_friction() {
    const TET_CUBE: &str = "sweeps/meshes/conv/cube_tet_p1_n4.msh";
    for law in [
        "friction = \"coulomb\"\nfriction_coefficient = 0.05",
        "friction = \"tresca\"\ntresca_threshold = 0.02",
    ] {
        let fixed = format!("T = 1.5\nmesh = \"{TET_CUBE}\"\nvelocity = -0.5\ndt = 0.03");
        let methods = "  { mass = \"consistent\", scheme = \"kane\" },\n  { mass = \"mod3\", scheme = \"kane\" },\n  { mass = \"consistent\", scheme = \"moreau-jean\", theta_scheme = 0.5, restitution = 0.0 },\n  { mass = \"lumped\", scheme = \"moreau-jean\", theta_scheme = 0.5, restitution = 1.0 },\n  { mass = \"lumped\", scheme = \"central-difference\", dt = 0.01 },\n";
        let mu = law.contains("coulomb").then_some(0.05);
        for (label, o) in frictional_sweep("mesh3d", &fixed, law, methods) {
            let (work, rise) = check_common("mesh3d cube", &label, &o, mu);
            let (step, drift) = balance_changes(&o);
            eprintln!("    max |Δ(E + W_f)| {step:.3e}, |drift| {drift:.3e}");
            assert!(work > 0.0, "{label}: friction did no work");
            if label.contains("central-difference") {
                let pen = o.metrics.max_penetration.unwrap();
                assert!(
                    pen <= 1e-14 * o.metrics.length_scale.unwrap(),
                    "{label}: {pen:.3e}"
                );
            } else {
                assert!(rise <= 1e-12, "{label}: E + W_f rose by {rise:.3e}·scale");
            }
            if label.contains("e=1)") {
                let n = o.metrics.steps as f64;
                assert!(
                    step <= 1e-12 && drift <= 1e-12 * n,
                    "{label}: {step:.3e} {drift:.3e}"
                );
            }
        }
    }
}

/// The step factor's cache key holds the solver for `kane`/CSN/generalized-α/Moreau–Jean too
/// (it did not: a frictional kane run with `solver = "cg"` took the direct run's Cholesky from
/// the cache — factorizations 0, one cache hit, no CG iteration, the direct numbers bit for
/// bit — or the other way round, whichever ran second). Two runs differing only in `solver`:
/// each builds its own (cg: no factor, its iterations counted), and they agree to CG's
/// tolerance (cg_tol 1e-12 relative per solve, carried through 40 steps and the contact
/// solves: measured 4.1e-13 on energy_drift and 4.3e-15 on friction_work, in energy scales;
/// bound 1e-10, ~250 times that).
#[test]
fn frictional_kane_runs_do_not_share_a_factor_across_solvers() {
    let rows = run_sweep_text(
        r#"
name = "cgk"
scene = "bar2d"
[fixed]
T = 1.0
h = 0.05
dt = 0.025
mass = "consistent"
scheme = "kane"
friction = "coulomb"
friction_coefficient = 0.3
[grid]
solver = ["direct", "cg"]
"#,
    );
    assert_eq!(rows.len(), 2);
    let by = |s: &str| {
        rows.iter()
            .find(|r| r.solver.as_deref() == Some(s))
            .unwrap_or_else(|| panic!("no {s} run"))
    };
    let (direct, cg) = (by("direct"), by("cg"));
    for r in [direct, cg] {
        assert_eq!(r.status, "ok", "{}: {:?}", r.label, r.message);
    }
    assert_eq!((cg.factorizations, cg.factor_cache_hits), (0, None));
    assert!(cg.solver_iterations.unwrap() > 0, "cg iterates");
    assert_eq!(direct.factorizations + direct.factor_cache_hits.unwrap(), 1);
    assert_eq!(direct.solver_iterations, None);
    let de = (direct.energy_drift.unwrap() - cg.energy_drift.unwrap()).abs();
    let dw = (direct.friction_work.unwrap() - cg.friction_work.unwrap()).abs();
    eprintln!("direct against cg: energy_drift {de:e}, friction_work {dw:e}");
    assert!(de <= 1e-10 && dw <= 1e-10, "{de:e} {dw:e}");
}
