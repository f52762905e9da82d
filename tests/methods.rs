//! Behaviour of the method family beyond the papers' figures: every mass variant, the two
//! starts of a massless contact node, penalty, Paoli–Schatzman, explicit central difference
//! with its CFL limit.

mod common;

use common::*;
use contact_sweep::run::Grid1d;
use contact_sweep::scene::BarParams;
use contact_sweep::space::{ContactInit, ContactMethod, MassVariant};
use contact_sweep::time::{NewmarkParams, PaoliSchatzmanParams, Scheme};

const CN: Scheme = Scheme::Newmark(NewmarkParams {
    beta: 0.25,
    gamma: 0.5,
});

#[test]
fn massless_contact_variants_start_quasi_static_and_conserve_energy_with_cn() {
    // Every variant whose contact row is zero starts from u₀(0) = u₁(0)⁺ = ½ − h/2, so
    // E⁰ = ½ (u₁)²/(L − h)·E … for the default bar: E⁰ = (½ − h/2)²/(2(1 − h)) = (1 − h)/8.
    let h = 0.01;
    for mass in [
        MassVariant::Mod1,
        MassVariant::Mod2,
        MassVariant::Mod3,
        MassVariant::ZeroContact,
        MassVariant::SingularDynamic,
        MassVariant::NodeNeighbour,
        MassVariant::Weights(vec![1.5, 1.0]),
    ] {
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(100, 0.015, 12.0, ContactMethod::Mixed, mass.clone(), CN),
            1,
        ));
        let e0 = o.metrics.energy_initial.unwrap();
        // closed form of the discrete initial energy: round-off only.
        assert!((e0 - (1.0 - h) / 8.0).abs() < 1e-14, "{mass:?}: E0 = {e0}");
        assert!((o.series.row(0).u_contact - (0.5 - h / 2.0)).abs() < 1e-15);
        // Well-posed semi-discretisation + CN: no energy blow-up; the measured drifts are
        // −0.4 … −0.9 %, so 1.5 % bounds them all while catching the ill-posed +100 % growth.
        let r = energy_ratio(&o);
        assert!((r - 1.0).abs() < 0.015, "{mass:?}: E(T)/E0 = {r}");
    }
}

#[test]
fn penalty_penetration_scales_with_the_inverse_stiffness() {
    // In contact the penalty force −κ[s]₊ balances the contact stress |σ| = aE/L = ½, so the
    // static penetration is |σ|/κ = ½ h/(E γ0): 5e-3/γ0 at h = 0.01. The discrete impact adds
    // an overshoot (measured ≤ 3.5× at τ = h), so: at least the static value, at most 5× it,
    // and two decades of κ buy more than one decade of penetration.
    let penetration = |g: f64| {
        let o = ok(bar1d(
            BarParams::default(),
            Grid1d::new(
                100,
                0.01,
                3.0,
                ContactMethod::Penalty { gamma0: g },
                MassVariant::Consistent,
                Scheme::Hybrid,
            ),
            1,
        ));
        o.series.rows().map(|r| -r.u_contact).fold(0.0, f64::max)
    };
    let (a, b, c) = (penetration(10.0), penetration(100.0), penetration(1000.0));
    for (p, g) in [(a, 10.0), (b, 100.0), (c, 1000.0)] {
        let est = 0.5 * 0.01 / g;
        assert!(
            p > 0.9 * est && p < 5.0 * est,
            "γ0 = {g}: penetration {p:e}, static {est:e}"
        );
    }
    assert!(a > b && b > c && a / c > 10.0, "{a:e} {b:e} {c:e}");
}

#[test]
fn paoli_schatzman_restitution_controls_the_impact_energy() {
    let run = |mass: MassVariant, e: f64| {
        ok(bar1d(
            BarParams::default(),
            Grid1d::new(
                6,
                0.01,
                12.0,
                ContactMethod::Mixed,
                mass,
                Scheme::PaoliSchatzman(PaoliSchatzmanParams {
                    beta: 0.25,
                    restitution: e,
                }),
            ),
            0,
        ))
    };
    // With a contact node that has mass the impact law acts: the inelastic law (e = 0) loses
    // more energy over four impacts than the elastic one (e = 1); both lose some (measured at
    // the 000 setting: 24 % and 11 %).
    let (e0, e1) = (
        energy_ratio(&run(MassVariant::Consistent, 0.0)),
        energy_ratio(&run(MassVariant::Consistent, 1.0)),
    );
    assert!(e0 < e1 && e1 < 1.0, "e=0: {e0}, e=1: {e1}");
    // With a massless contact node (000's setting) the node is quasi-static and every e keeps
    // the energy within 1 %.
    for e in [0.0, 0.5, 1.0] {
        let r = energy_ratio(&run(MassVariant::Mod3, e));
        assert!((r - 1.0).abs() < 0.01, "mod3, e = {e}: {r}");
    }
}

#[test]
fn central_difference_below_its_cfl_limit_is_stable() {
    // mod3 (a consistent-type mass) has the CFL limit ν ≤ 1/√3 ≈ 0.577 (checked by the
    // planner); at ν = 0.5 central difference keeps the energy within 0.1 % (symplectic).
    let o = ok(bar1d(
        BarParams::default(),
        Grid1d::new(
            100,
            0.005,
            12.0,
            ContactMethod::Mixed,
            MassVariant::Mod3,
            Scheme::Newmark(NewmarkParams::central_difference()),
        ),
        0,
    ));
    assert!((energy_ratio(&o) - 1.0).abs() < 1e-3);
    // Lumped mass with the penalty: ν = 0.8 below the lumped limit of 1.
    let o = ok(bar1d(
        BarParams::default(),
        Grid1d::new(
            100,
            0.008,
            12.0,
            ContactMethod::Penalty { gamma0: 1.0 },
            MassVariant::Lumped,
            Scheme::Newmark(NewmarkParams::central_difference()),
        ),
        0,
    ));
    assert!((energy_ratio(&o) - 1.0).abs() < 1e-3);
}

/// The first impact of the default bar is at t = 1: steps before it are contact-free.
const BEFORE_CONTACT: usize = 60; // 60 · 0.015 = 0.9

#[test]
fn interpolant_start_costs_energy_once_where_the_node_row_holds_at_the_new_time() {
    let h = 0.01;
    for mass in [MassVariant::ZeroContact, MassVariant::Mod3] {
        let o = ok(bar1d_start(
            ContactInit::Interpolant,
            BarParams::default(),
            Grid1d::new(100, 0.015, 12.0, ContactMethod::Mixed, mass.clone(), CN),
            1,
        ));
        // u₀(0) = a and E⁰ = 1/8, the exact energy (round-off only).
        assert_eq!(o.series.row(0).u_contact, 0.5);
        assert!((o.metrics.energy_initial.unwrap() - 0.125).abs() < 1e-14);
        // σ_C⁰ is the multiplier of a node not in contact (u₀ = a > 0): zero, as the exact
        // contact stress — not the contact element's stress −aE of the non-equilibrium start.
        assert_eq!(o.series.row(0).sigma_contact, 0.0);
        // The first step loses at least the contact element's excess strain energy h/8
        // (u₀ drops from a to about u₁); contact-free CN then conserves E^h to round-off
        // (linear system, ~1e-15 per step over 60 steps).
        let e = |n: usize| o.series.row(n).energy;
        assert!(e(0) - e(1) > h / 8.0, "{mass:?}: E0 − E1 = {}", e(0) - e(1));
        for n in 2..BEFORE_CONTACT {
            assert!((e(n) - e(1)).abs() < 1e-13, "{mass:?}: step {n}");
        }
    }
}

#[test]
fn interpolant_start_persists_where_the_node_row_holds_at_the_midpoint() {
    // Nitsche-Hybrid with a massless contact node enforces the node's row at t^{n+½}. The
    // difference δ between the interpolant and the consistent runs solves the homogeneous
    // contact-free scheme with δ⁰ = (a − u₀^qs) e₀ = a h e₀, and δⁿ = (−1)ⁿ a h e₀ does: its
    // midpoint average vanishes, so node 1 never feels it. Hence u₀ alternates by ±0.005 about
    // the consistent run until the first contact (round-off only: values of size 0.5).
    let run = |init| {
        ok(bar1d_start(
            init,
            BarParams::default(),
            Grid1d::new(
                100,
                0.015,
                12.0,
                nitsche(1.0, 1e-6),
                MassVariant::ZeroContact,
                Scheme::Hybrid,
            ),
            1,
        ))
    };
    let c = run(ContactInit::Consistent);
    let i = run(ContactInit::Interpolant);
    let ah = 0.5 * 0.01;
    for n in 0..BEFORE_CONTACT {
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        let d = i.series.row(n).u_contact - c.series.row(n).u_contact;
        assert!((d - sign * ah).abs() < 1e-12, "step {n}: δ = {d}");
        // The excess energy stays (no loss at the first step, unlike CN).
        assert!((i.series.row(n).energy - 0.125).abs() < 1e-13, "step {n}");
    }
    // Still energy-stable (003 Cor 3.8): E_Θ never increases beyond round-off.
    assert!(i.metrics.energy_theta_max_increase.unwrap() < 1e-12);
}

/// Issue 20: the method-class table of `sweeps/comparison_bar1d.toml` is computed from the runs
/// (summary/methods.md) and the README prints that table, row for row. The classes themselves
/// follow from the methods' properties (contract §3.2), asserted here with the reason for each.
#[test]
fn comparison_bar1d_method_classes_are_the_readmes() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = concat!(env!("CARGO_MANIFEST_DIR"), "/sweeps/comparison_bar1d.toml");
    let o = cli(tmp.path(), &["run", sweep, "--out", "cmp"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let md = std::fs::read_to_string(tmp.path().join("cmp/summary/methods.md")).unwrap();
    let table = &md[md.find("| method |").expect("the table")..];
    // The README prints it as its one table, docs/methods.md beside the methods' figures.
    for doc in ["README.md", "docs/methods.md"] {
        let text =
            std::fs::read_to_string(format!("{}/{doc}", env!("CARGO_MANIFEST_DIR"))).unwrap();
        assert!(
            text.contains(table.trim_end()),
            "{doc}'s method-class table is stale; the sweep gives:\n{table}"
        );
    }
    let row = |label: &str| -> Vec<String> {
        let line = table
            .lines()
            .find(|l| l.starts_with(&format!("| {label} |")))
            .unwrap_or_else(|| panic!("no row {label} in\n{table}"));
        line.split('|').map(|c| c.trim().to_string()).collect()
    };
    // Kane's step never increases E^h (contract §3.2) and puts the node on the obstacle exactly.
    let kane = row("mixed · consistent · kane");
    assert_eq!(
        (kane[2].as_str(), kane[4].as_str()),
        ("dissipative", "none")
    );
    // Moreau–Jean with e = 1 and θ = ½ conserves E^h to round-off, at the price of an O(τ)
    // penetration (a velocity-level constraint).
    let mj = row("mixed · consistent · moreau-jean(θ=0.5,e=1)");
    assert_eq!((mj[2].as_str(), mj[4].as_str()), ("conserving", "O(τ)"));
    // The discrete gradient conserves E^h + Φ: never growing, a penalty penetrates.
    let dg = row("penalty(γ0=1e2) · consistent · discrete-gradient");
    assert_eq!((dg[2].as_str(), dg[4].as_str()), ("conserving", "O(τ)"));
    // Crank–Nicolson with the consistent mass gains energy at impacts (000 §3, contract §6).
    assert_eq!(row("mixed · consistent · crank-nicolson")[2], "growing");
    // The report draws the same table.
    let r = cli(tmp.path(), &["report", "cmp"]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let html = std::fs::read_to_string(tmp.path().join("cmp/report.html")).unwrap();
    assert!(html.contains("id=\"classes\"") && html.contains("moreau-jean(θ=0.5,e=1)"));
}
