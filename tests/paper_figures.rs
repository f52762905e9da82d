//! The acceptance figures of contract §6 for the 1D bar, each a test of the engine.
//!
//! Deterministic figures are asserted to the digits contract §6 prints ([`common::assert_printed`]:
//! two independent implementations agree to 1e-11, so the printed rounding is the tolerance).
//! The ill-posed cases (mixed or Nitsche with Crank–Nicolson at ν = 1.5) are asserted as
//! behaviour — energy grows — never as digits: round-off moves them anywhere in 1.07–3.9.

mod common;

use common::*;
use contact_sweep::run::{Grid1d, Status};
use contact_sweep::scene::BarParams;
use contact_sweep::space::{ContactInit, ContactMethod, MassVariant};
use contact_sweep::time::{NewmarkParams, PaoliSchatzmanParams, Scheme, ThetaParams};

const CN: Scheme = Scheme::Newmark(NewmarkParams {
    beta: 0.25,
    gamma: 0.5,
});

/// 003 §4.1.2a–b setting: h = 0.01, τ = 0.015 (ν = 1.5), T = 12.
fn fig(method: ContactMethod, mass: MassVariant, scheme: Scheme) -> contact_sweep::run::Outcome {
    bar1d(
        BarParams::default(),
        Grid1d::new(100, 0.015, 12.0, method, mass, scheme),
        1,
    )
}

#[test]
fn fig2_fig3_table_of_spec_6() {
    let n = nitsche(1.0, 1e-6);
    let cases = [
        (
            "backward Euler",
            n,
            MassVariant::Consistent,
            Scheme::Theta(ThetaParams::backward_euler()),
            ["0.1823", "0.2375", "0.6282"],
        ),
        (
            "Newmark γ=1, β=½",
            n,
            MassVariant::Consistent,
            Scheme::Newmark(NewmarkParams::dissipative()),
            ["0.3792", "0.1625", "0.5009"],
        ),
        (
            "Newmark γ=β=½",
            n,
            MassVariant::Consistent,
            Scheme::Newmark(NewmarkParams {
                beta: 0.5,
                gamma: 0.5,
            }),
            ["0.9994", "0.03820", "0.4628"],
        ),
        (
            "Nitsche-Hybrid",
            n,
            MassVariant::Consistent,
            Scheme::Hybrid,
            ["0.9890", "0.02791", "0.3915"],
        ),
        (
            "mixed + mod3 + CN",
            ContactMethod::Mixed,
            MassVariant::Mod3,
            CN,
            ["0.9957", "0.02608", "0.3748"],
        ),
    ];
    for (what, method, mass, scheme, [e, l2, h1]) in cases {
        let o = ok(fig(method, mass, scheme));
        assert_printed(&format!("{what} E(T)/E0"), energy_ratio(&o), e);
        assert_printed(
            &format!("{what} l2(τ;L2)"),
            o.metrics.err_u_l2l2.unwrap(),
            l2,
        );
        assert_printed(
            &format!("{what} l2(τ;H1)"),
            o.metrics.err_u_l2h1.unwrap(),
            h1,
        );
    }
}

#[test]
fn crank_nicolson_with_consistent_mass_is_ill_posed_energy_grows() {
    for method in [ContactMethod::Mixed, nitsche(1.0, 1e-6)] {
        let o = ok(fig(method, MassVariant::Consistent, CN));
        // Behaviour only (contract §6): growth by more than 5 % and at least one increasing step.
        assert!(
            energy_ratio(&o) > 1.05,
            "{method:?}: E(T)/E0 = {}",
            energy_ratio(&o)
        );
        assert!(o.metrics.energy_max_increase.unwrap() > 0.0);
    }
}

#[test]
fn gamma0_tenth_theta_variants() {
    let cn = [(1.0, "1.028"), (0.0, "1.013"), (-1.0, "1.013")];
    for (theta, e) in cn {
        let o = ok(fig(nitsche(theta, 0.1), MassVariant::Consistent, CN));
        assert_printed(&format!("CN Θ={theta}"), energy_ratio(&o), e);
    }
    let hy = [(1.0, "0.9855"), (0.0, "0.9876"), (-1.0, "0.9896")];
    for (theta, e) in hy {
        let o = ok(fig(
            nitsche(theta, 0.1),
            MassVariant::Consistent,
            Scheme::Hybrid,
        ));
        assert_printed(&format!("hybrid Θ={theta}"), energy_ratio(&o), e);
    }
}

#[test]
fn gamma0_one_symmetric_is_unphysical_but_augmented_energy_holds() {
    for scheme in [CN, Scheme::Hybrid] {
        let o = ok(fig(nitsche(1.0, 1.0), MassVariant::Consistent, scheme));
        // E^h peaks about 231·E0 in each contact phase (contract §6): max |E − E0|/E0 ≈ 230.
        let peak = 1.0 + o.metrics.energy_max_dev.unwrap();
        assert!(
            (200.0..260.0).contains(&peak),
            "{scheme:?}: peak E/E0 = {peak}"
        );
        // …while E_Θ stays within 1 %.
        let et0 = o.series.row(0).energy_theta.unwrap();
        let dev = o
            .series
            .rows()
            .map(|r| (r.energy_theta.unwrap() - et0).abs() / et0)
            .fold(0.0, f64::max);
        assert!(dev < 0.01, "{scheme:?}: E_Θ deviates by {dev}");
    }
    for theta in [0.0, -1.0] {
        let o = ok(fig(nitsche(theta, 1.0), MassVariant::Consistent, CN));
        let r = energy_ratio(&o);
        // contract §6: +2.6 … 2.8 %.
        assert!((1.026..=1.028).contains(&r), "Θ={theta}: E(T)/E0 = {r}");
    }
}

#[test]
fn gamma0_three_symmetric_diverges_before_any_contact() {
    let o = fig(nitsche(1.0, 3.0), MassVariant::Consistent, CN);
    assert_eq!(o.status, Status::Diverged);
    let msg = o.message.unwrap();
    assert!(msg.contains("exceeded 1e6"), "{msg}");
    // The first impact is at t = 1 (contract §1.1): A_Θγ is indefinite, growth starts at once.
    assert!(
        (o.metrics.steps as f64) * 0.015 < 1.0,
        "diverged at step {}",
        o.metrics.steps
    );
}

#[test]
fn large_gamma0_non_symmetric_stays_finite() {
    for (theta, gamma0, printed) in [
        (0.0, 10.0, "1.203"),
        (0.0, 100.0, "1.066"),
        (0.0, 1e4, "0.961"),
        (-1.0, 10.0, "4.97"),
        (-1.0, 100.0, "6.02"),
    ] {
        let o = ok(fig(nitsche(theta, gamma0), MassVariant::Consistent, CN));
        assert_printed(
            &format!("CN Θ={theta} γ0={gamma0}"),
            energy_ratio(&o),
            printed,
        );
    }
    // Nitsche-Hybrid with Θ = −1 blows up after the first impact for γ0 ≥ 3.
    let o = fig(nitsche(-1.0, 3.0), MassVariant::Consistent, Scheme::Hybrid);
    assert_eq!(o.status, Status::Diverged);
    assert!((o.metrics.steps as f64) * 0.015 > 1.0);
}

#[test]
fn zero_contact_mass_removes_oscillations() {
    let o = ok(fig(ContactMethod::Mixed, MassVariant::ZeroContact, CN));
    let r = energy_ratio(&o);
    // Dissipative (the digits, for both starts of the contact node, are asserted in
    // zero_contact_cn_energy_depends_on_the_start_of_the_contact_node).
    assert!(r < 1.0, "E(T)/E0 = {r}");
    // One clean contact interval per impact: 4 impacts → 8 switches (on and off).
    assert_eq!(o.metrics.contact_switches, 8);
    // versus the consistent mass, whose pressure switches on and off repeatedly
    let c = ok(fig(ContactMethod::Mixed, MassVariant::Consistent, CN));
    assert!(c.metrics.contact_switches > 8);
}

#[test]
fn zero_contact_cn_energy_depends_on_the_start_of_the_contact_node() {
    // contract §6 (003 §4.1.2d, Fig 9): E(T)/E0 = 0.99511 with the quasi-static start, 0.97845 with
    // the interpolant start (E0 = 1/8) — the paper's "1–2 %" is the latter. Both figures come
    // from the independent numpy implementation, so the printed rounding is the tolerance. The
    // Nitsche variant (Θ = 1, γ0 = 1e-6) is the mixed method up to O(γ0) = 1e-6 relative in the
    // contact law, measured 2e-9 apart here: it rounds to the same digits.
    for method in [ContactMethod::Mixed, nitsche(1.0, 1e-6)] {
        for (init, printed, e0) in [
            (ContactInit::Consistent, "0.99511", 0.12375),
            (ContactInit::Interpolant, "0.97845", 0.125),
        ] {
            let o = ok(bar1d_start(
                init,
                BarParams::default(),
                Grid1d::new(100, 0.015, 12.0, method, MassVariant::ZeroContact, CN),
                0,
            ));
            let what = format!("{method:?} zero-contact CN, {init:?} start: E(T)/E0");
            assert_printed(&what, energy_ratio(&o), printed);
            // E0 in closed form, (1 − h)/8 and 1/8 (the interpolant of an affine u0 is exact):
            // sums of m = 100 squared strains, round-off ~1e-16 each.
            let got = o.metrics.energy_initial.unwrap();
            assert!((got - e0).abs() < 1e-14, "{what}: E0 = {got}");
        }
    }
}

/// 000 §4.2: Δx = 1/6, Δt = 1/100.
fn p000(mass: MassVariant, scheme: Scheme, t: f64) -> contact_sweep::run::Outcome {
    p000_start(ContactInit::Consistent, mass, scheme, t)
}

/// [`p000`] with the contact node started by `init`.
fn p000_start(
    init: ContactInit,
    mass: MassVariant,
    scheme: Scheme,
    t: f64,
) -> contact_sweep::run::Outcome {
    ok(bar1d_start(
        init,
        BarParams::default(),
        Grid1d::new(6, 0.01, t, ContactMethod::Mixed, mass, scheme),
        0,
    ))
}

#[test]
fn paper000_mass_redistribution_errors() {
    for (mass, printed) in [
        (MassVariant::Mod1, "0.1123"),
        (MassVariant::Mod2, "0.05567"),
        (MassVariant::Mod3, "0.04349"),
    ] {
        let o = p000(mass.clone(), CN, 3.0);
        assert_printed(
            &format!("{mass:?} CN l2(τ;L2) at T=3"),
            o.metrics.err_u_l2l2.unwrap(),
            printed,
        );
        assert_printed("E0", o.metrics.energy_initial.unwrap(), "0.10417");
    }
    // mod3 < mod2 < mod1 for backward Euler and the hybrid at T = 3, 6, 12: asserted for both
    // starts in paper000_mass_redistribution_errors_with_the_interpolant_start.
}

#[test]
fn paper000_mass_redistribution_errors_with_the_interpolant_start() {
    // The interpolant start (u₀(0) = a, E0 = 1/8) at 000 §4.2's setting. No independent
    // implementation printed these: they are this engine's figures (docs/methods.md, "Methods against
    // the papers"), asserted to the digits printed there, i.e. ±½ unit in the last place of a
    // deterministic computation (round-off is ~1e-13 of it). They differ from the consistent
    // start's 0.1123 / 0.05567 / 0.04349 by −2.5, −3.2 and +0.5 %.
    let i = ContactInit::Interpolant;
    for (mass, printed) in [
        (MassVariant::Mod1, "0.1095"),
        (MassVariant::Mod2, "0.05389"),
        (MassVariant::Mod3, "0.04373"),
    ] {
        let o = p000_start(i, mass.clone(), CN, 3.0);
        assert_printed(
            &format!("{mass:?} CN, interpolant start: l2(τ;L2) at T=3"),
            o.metrics.err_u_l2l2.unwrap(),
            printed,
        );
        // E0 = 1/8 exactly: the interpolant of the affine u0 carries the exact energy (six
        // squared strains, round-off ~1e-17).
        assert!((o.metrics.energy_initial.unwrap() - 0.125).abs() < 1e-15);
    }
    // 000's ordering mod3 < mod2 < mod1 holds for either start, for CN, backward Euler and the
    // hybrid, at T = 3, 6, 12.
    for init in [ContactInit::Consistent, ContactInit::Interpolant] {
        for scheme in [
            CN,
            Scheme::Theta(ThetaParams::backward_euler()),
            Scheme::Hybrid,
        ] {
            for t in [3.0, 6.0, 12.0] {
                let e: Vec<f64> = [MassVariant::Mod3, MassVariant::Mod2, MassVariant::Mod1]
                    .into_iter()
                    .map(|m| p000_start(init, m, scheme, t).metrics.err_u_l2l2.unwrap())
                    .collect();
                assert!(
                    e[0] < e[1] && e[1] < e[2],
                    "{init:?} {scheme:?} T={t}: {e:?}"
                );
            }
        }
    }
}

#[test]
fn paper000_paoli_schatzman_runs_with_every_redistribution() {
    for mass in [MassVariant::Mod1, MassVariant::Mod2, MassVariant::Mod3] {
        let o = p000(
            mass.clone(),
            Scheme::PaoliSchatzman(PaoliSchatzmanParams::paper()),
            12.0,
        );
        // (β, e) = (¼, 1) conserves energy up to the O(τ) velocity reconstruction: within 1 %.
        let r = energy_ratio(&o);
        assert!((r - 1.0).abs() < 0.01, "{mass:?}: E(T)/E0 = {r}");
    }
}

#[test]
fn fig10_ladder_h_equals_tau() {
    let levels = [4usize, 16, 64, 256];
    let cases: [(&str, ContactMethod, MassVariant, Scheme, [&str; 4]); 4] = [
        (
            "mixed+CN",
            ContactMethod::Mixed,
            MassVariant::Consistent,
            CN,
            ["2.373", "1.470", "3.166", "4.610"],
        ),
        (
            "Nitsche-Hybrid",
            nitsche(1.0, 1e-6),
            MassVariant::Consistent,
            Scheme::Hybrid,
            ["0.7243", "0.5428", "0.3664", "0.2347"],
        ),
        (
            "mod3+CN",
            ContactMethod::Mixed,
            MassVariant::Mod3,
            CN,
            ["0.7641", "0.5186", "0.3337", "0.2224"],
        ),
        (
            "zero-contact+CN",
            ContactMethod::Mixed,
            MassVariant::ZeroContact,
            CN,
            ["1.534", "0.7234", "0.3667", "0.2155"],
        ),
    ];
    for (what, method, mass, scheme, printed) in cases {
        for (m, p) in levels.iter().zip(printed) {
            let h = 1.0 / *m as f64;
            let o = ok(bar1d(
                BarParams::default(),
                Grid1d::new(*m, h, 12.0, method, mass.clone(), scheme),
                0,
            ));
            // One unit in the last place: the contract's 2.373 for mixed+CN at h = 1/4 is the double
            // rounding of 2.37249 (→ 2.3725 → 2.373); every other figure matches to ±½ unit.
            assert_printed_within(
                &format!("{what} h=1/{m}"),
                o.metrics.err_u_l2h1.unwrap(),
                p,
                1.0,
            );
        }
    }
    // Nitsche + CN (γ0 = 1e-6) is "nearly the same" as mixed + CN: within 1 % at every level.
    for m in levels {
        let h = 1.0 / m as f64;
        let a = ok(bar1d(
            BarParams::default(),
            Grid1d::new(
                m,
                h,
                12.0,
                ContactMethod::Mixed,
                MassVariant::Consistent,
                CN,
            ),
            0,
        ));
        let b = ok(bar1d(
            BarParams::default(),
            Grid1d::new(m, h, 12.0, nitsche(1.0, 1e-6), MassVariant::Consistent, CN),
            0,
        ));
        let (x, y) = (a.metrics.err_u_l2h1.unwrap(), b.metrics.err_u_l2h1.unwrap());
        assert!((x - y).abs() < 0.01 * x, "h=1/{m}: mixed {x}, Nitsche {y}");
    }
}

/// Assert `x` against a figure printed with a given number of significant digits ("6.31e-3",
/// "11.3", "0.92489"): the tolerance is half a unit of the last printed digit, as
/// [`assert_printed`]; a printed "0" means zero to round-off (1e-15: an exact Signorini
/// enforcement puts the node at −g, or above it, to the last bit).
fn assert_significant(what: &str, x: f64, printed: &str) {
    let target: f64 = printed.parse().unwrap();
    if target == 0.0 {
        assert!(
            x.abs() <= 1e-15,
            "{what}: computed {x:e}, contract §6 prints 0"
        );
        return;
    }
    let (mantissa, exp) = match printed.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap()),
        None => (printed, 0),
    };
    let decimals = mantissa.split('.').nth(1).map_or(0, |d| d.len()) as i32;
    let half_unit = 0.5 * 10f64.powi(exp - decimals);
    assert!(
        (x - target).abs() <= half_unit * (1.0 + 1e-9),
        "{what}: computed {x:.6e}, contract §6 prints {printed} (tolerance ±{half_unit:e})"
    );
}

/// contract §6 "Methods of §3.2 on the default bar, h = 0.01, τ = 0.015, T = 12" (mixed + consistent
/// mass unless stated): E(T)/E⁰, l2(τ;L2), l2(τ;H1), max_penetration, pressure_oscillation for
/// every row, to the printed digits (an independent numpy implementation; round-off moves none
/// of them by more than 1e-9, so the printed rounding is the tolerance).
#[test]
fn methods_of_spec_3_2_table() {
    use contact_sweep::time::{GeneralizedAlphaParams, MoreauJeanParams};
    let mj = |restitution| {
        Scheme::MoreauJean(MoreauJeanParams {
            theta: 0.5,
            restitution,
        })
    };
    let mixed = ContactMethod::Mixed;
    #[rustfmt::skip]
    let rows: [(&str, ContactMethod, Scheme, [&str; 5]); 8] = [
        ("kane", mixed, Scheme::Kane,
            ["0.98899", "0.02791", "0.3915", "0", "11.3"]),
        ("contact-stabilized-newmark", mixed, Scheme::ContactStabilizedNewmark,
            ["0.97776", "0.03153", "0.3989", "0", "3.14"]),
        ("generalized-alpha ρ∞ = 0.5", mixed,
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::from_rho_inf(0.5)),
            ["0.92489", "0.03415", "0.3510", "0", "3.03"]),
        ("hht α = 0.1", mixed,
            Scheme::GeneralizedAlpha(GeneralizedAlphaParams::hht(0.1)),
            ["0.93481", "0.03093", "0.3421", "0", "5.85"]),
        ("moreau-jean e = 0", mixed, mj(0.0),
            ["0.98856", "0.03868", "0.4368", "6.31e-3", "3.10"]),
        ("moreau-jean e = 1", mixed, mj(1.0),
            ["1.00000", "0.04438", "0.4304", "1.27e-2", "1.00"]),
        ("discrete-gradient penalty γ0 = 1", ContactMethod::Penalty { gamma0: 1.0 },
            Scheme::DiscreteGradient,
            ["1.00000", "0.03867", "0.4246", "7.87e-3", "3.58"]),
        ("discrete-gradient penalty γ0 = 100", ContactMethod::Penalty { gamma0: 100.0 },
            Scheme::DiscreteGradient,
            ["1.00000", "0.02674", "0.4004", "4.36e-4", "2.82"]),
    ];
    let mut failures = Vec::new();
    for (what, method, scheme, printed) in rows {
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(100, 0.015, 12.0, method, MassVariant::Consistent, scheme),
            0,
        ));
        let m = &o.metrics;
        let got = [
            energy_ratio(&o),
            m.err_u_l2l2.unwrap(),
            m.err_u_l2h1.unwrap(),
            m.max_penetration.unwrap(),
            m.pressure_oscillation.unwrap(),
        ];
        eprintln!(
            "{what:40} {:.5} {:.5} {:.4} {:.3e} {:.3}",
            got[0], got[1], got[2], got[3], got[4]
        );
        for (k, (x, p)) in got.iter().zip(printed).enumerate() {
            let col = [
                "E(T)/E0",
                "l2(τ;L2)",
                "l2(τ;H1)",
                "max_penetration",
                "pressure_oscillation",
            ][k];
            if std::panic::catch_unwind(|| assert_significant(&format!("{what} {col}"), *x, p))
                .is_err()
            {
                failures.push(format!("{what} {col}: {x:.6e} vs {p}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// contract §6's last row, `central-difference` + `lumped` (kinematic contact), τ = 0.009: printed
/// E(T)/E⁰ 0.98785, l2(τ;L2) 0.01049, l2(τ;H1) 0.2384, max_penetration 0, pressure_oscillation
/// 3.87. This engine — and an independent 40-line numpy transcription of contract §3.2's formulas
/// (v^{n+½} = vⁿ + τ/2 aⁿ, u^{n+1} = uⁿ + τv^{n+½}, the node put on the obstacle by Δv on
/// v^{n+½}, a^{n+1} = M⁻¹(−Ku^{n+1}), v^{n+1} = v^{n+½} + τ/2 a^{n+1}) — both give
/// E(T)/E⁰ = 0.990591 (and l2(τ;L2) 0.01107, l2(τ;H1) 0.2459, pressure_oscillation 4.10); the
/// variants tried (contact force in a^{n+1}, v₀ zeroed in contact, half the impulse in vⁿ,
/// E with v^{n+½}) give 0.9906–0.9947, none 0.98785. The printed row is therefore not asserted
/// digit for digit (reported in the branch's notes); what the method guarantees is: no
/// penetration ever, and a loss of energy at impacts only, bounded by the contact node's kinetic
/// energy each time (≪ 2 % over four impacts at h = 0.01).
#[test]
fn kinematic_central_difference_row_of_spec_3_2_table() {
    let o = ok(bar1d(
        BarParams::default(),
        Grid1d::new(
            100,
            0.009,
            12.0,
            ContactMethod::Mixed,
            MassVariant::Lumped,
            Scheme::Newmark(NewmarkParams::central_difference()),
        ),
        0,
    ));
    let m = &o.metrics;
    assert_eq!(m.max_penetration, Some(0.0));
    let r = energy_ratio(&o);
    assert!(r > 0.98 && r < 1.0, "E(T)/E0 = {r}");
    // Measured 0.990591 (numpy agrees to the printed digits): a regression guard at 1e-6.
    assert!((r - 0.990591).abs() < 1e-6, "E(T)/E0 = {r}");
    assert!(m.err_u_l2l2.unwrap() < 0.012 && m.err_u_l2h1.unwrap() < 0.25);
    let osc = m.pressure_oscillation.unwrap();
    assert!((1.0..5.0).contains(&osc), "pressure_oscillation = {osc}");
}
