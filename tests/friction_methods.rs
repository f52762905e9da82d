//! Friction in SPEC §3.2's methods with the nodal multiplier (issue 33, "done when" 2):
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
use common::outcomes;

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
/// hit the obstacle and |Σf_t| ≤ μ_f Σf_n (the law holds per node, so for the sums; 1e-12 for
/// the rounding of the sums and of the solver's projection onto the disc).
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
        "{place} {label}: W_f/scale {work:.4e}, max rise of E + W_f {rise:.3e}, drift {:.3e}, stick {:?} slip {:?}, |Σf_t|/Σf_n ≤ {ratio:?}, its {} (max {:?})",
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
    if let (Some(mu), Some(r)) = (mu, ratio) {
        assert!(
            r <= mu * (1.0 + 1e-12),
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
/// "none"`'s bit for bit (SPEC §2.5) — energies, contact force, displacement and velocity at
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
