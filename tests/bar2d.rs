//! The 2D and 3D bars dropped on an obstacle (SPEC §1.2, §6; paper 000 Table 1, paper 002).
//!
//! The target figures come from a GetFEM implementation of the same discretisation (Q1,
//! exact element integration, nodal contact on every bottom node, the same mass layers), so
//! they are matched to 1 %: the only differences left are the reference run's own round-off
//! and the LCP tolerance (1e-12), both far below 1 %.

mod common;

use common::run_sweep_text;
use contact_sweep::run::RunRecord;

fn find<'a>(rows: &'a [RunRecord], mass: &str, scheme: &str, h: f64) -> &'a RunRecord {
    rows.iter()
        .find(|r| r.mass == mass && r.scheme_label == scheme && (r.h - h).abs() < 1e-12)
        .unwrap_or_else(|| panic!("no run {mass} {scheme} h = {h}"))
}

fn ratio(r: &RunRecord) -> f64 {
    r.energy_final.unwrap() / r.energy_initial.unwrap()
}

fn close(x: f64, target: f64, rel: f64, what: &str) {
    assert!(
        ((x - target) / target).abs() <= rel,
        "{what}: {x:.5e}, expected {target:.5e} ± {:.1} %",
        rel * 100.0
    );
}

/// SPEC §6: L∞(0,T;L2) at h = 0.05, τ = h/2 with CN against the mod3 + CN reference at h/32,
/// τ/32 (82 k dofs, 2560 steps): consistent 9.18e-3, mod1 3.70e-3, mod2 3.69e-3, mod3 1.50e-3.
/// Printed to three digits, so 1 % (the issue's tolerance) also covers the rounding.
#[test]
fn table1_linf_l2_against_the_h_over_32_reference() {
    let rows = run_sweep_text(
        r#"
name = "t1"
scene = "bar2d"
reference = { h = 0.0015625, dt = 0.00078125, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
T = 2.0
h = 0.05
dt = 0.025
[grid]
mass = ["consistent", "mod1", "mod2", "mod3"]
"#,
    );
    for (mass, target) in [
        ("consistent", 9.18e-3),
        ("mod1", 3.70e-3),
        ("mod2", 3.69e-3),
        ("mod3", 1.50e-3),
    ] {
        let r = find(&rows, mass, "crank-nicolson", 0.05);
        assert_eq!(r.status, "ok", "{:?}", r.message);
        close(r.err_u_linfl2.unwrap(), target, 0.01, mass);
    }
}

/// SPEC §6 / 002 Figs 1–3: CN with the consistent mass gains energy and chatters — E(T)/E⁰ =
/// 2.75 at h = 0.05, 3.48 at h/2, 4.58 at h/4 (printed to three digits: ±0.5 % covers the
/// rounding) with a contact force switching on and off ≥ 10 times, more under refinement —
/// while the modified masses keep E(T)/E⁰ within 1e-3 of 1 with one clean contact interval
/// (force on once, off once) and backward Euler dissipates to E(T)/E⁰ ≈ 0.57–0.61.
#[test]
fn consistent_mass_with_cn_chatters_and_gains_energy_the_modified_masses_do_not() {
    let rows = run_sweep_text(
        r#"
name = "f13"
scene = "bar2d"
[zip]
h = [0.05, 0.025, 0.0125]
dt = [0.025, 0.0125, 0.00625]
[fixed]
T = 2.0
[grid]
mass = ["consistent", "mod1", "mod2", "mod3"]
scheme = ["crank-nicolson", "backward-euler"]
"#,
    );
    assert!(rows.iter().all(|r| r.status == "ok"));
    let mut toggles = Vec::new();
    for (h, target) in [(0.05, 2.75), (0.025, 3.48), (0.0125, 4.58)] {
        let r = find(&rows, "consistent", "crank-nicolson", h);
        close(
            ratio(r),
            target,
            0.005,
            &format!("consistent + CN E(T)/E0 at h = {h}"),
        );
        toggles.push(r.contact_toggles.unwrap());
        for mass in ["mod1", "mod2", "mod3"] {
            let r = find(&rows, mass, "crank-nicolson", h);
            assert!(
                (ratio(r) - 1.0).abs() < 1e-3,
                "{mass} h = {h}: {}",
                ratio(r)
            );
            assert_eq!(
                r.contact_toggles,
                Some(2),
                "{mass} h = {h}: one contact interval"
            );
        }
    }
    assert!(toggles[0] >= 10, "{toggles:?}");
    assert!(
        toggles.windows(2).all(|w| w[1] > w[0]),
        "chatter grows: {toggles:?}"
    );
    for mass in ["consistent", "mod1", "mod2", "mod3"] {
        let r = find(&rows, mass, "backward-euler", 0.05);
        let e = ratio(r);
        assert!((0.565..=0.615).contains(&e), "{mass} + BE: E(T)/E0 = {e}");
    }
    // Total mass 1ᵀM1 = ρ·0.1 except mod1, which drops layer 0 (0.1 − 0.1·h).
    for h in [0.05, 0.025, 0.0125] {
        let m = find(&rows, "mod1", "crank-nicolson", h).mass_total.unwrap();
        assert!((m - (0.1 - 0.1 * h)).abs() < 1e-13, "mod1 mass {m}");
        for mass in ["consistent", "mod2", "mod3"] {
            let m = find(&rows, mass, "crank-nicolson", h).mass_total.unwrap();
            assert!((m - 0.1).abs() < 1e-13, "{mass} mass {m}");
        }
    }
}

/// SPEC §6, 3D at h = 0.05 (τ = h/2), against a mod3 + CN reference at h/4, τ/4 (the setting
/// whose figures SPEC quotes): mod3 7.7e-4 < mod2 1.47e-3 < mod1 1.56e-3 in L∞(0,T;L2),
/// consistent + CN E(T)/E⁰ = 2.65. Two or three printed digits: 1 % tolerance.
#[test]
fn bar3d_orders_the_masses_like_2d() {
    let rows = run_sweep_text(
        r#"
name = "b3"
scene = "bar3d"
reference = { h = 0.0125, dt = 0.00625, mass = "mod3", scheme = "crank-nicolson" }
[fixed]
T = 2.0
h = 0.05
dt = 0.025
[grid]
mass = ["consistent", "mod1", "mod2", "mod3"]
"#,
    );
    let e = |m| find(&rows, m, "crank-nicolson", 0.05).err_u_linfl2.unwrap();
    close(e("mod3"), 7.7e-4, 0.01, "mod3");
    close(e("mod2"), 1.47e-3, 0.01, "mod2");
    close(e("mod1"), 1.56e-3, 0.01, "mod1");
    assert!(e("mod3") < e("mod2") && e("mod2") < e("mod1"));
    close(
        ratio(find(&rows, "consistent", "crank-nicolson", 0.05)),
        2.65,
        0.005,
        "3D consistent + CN E(T)/E0",
    );
    let r = find(&rows, "mod3", "crank-nicolson", 0.05);
    // 3 × 3 nodes on Γ_C, 3 × 3 × 20 free nodes × 3 components.
    assert_eq!((r.contact_dofs, r.dofs), (Some(9), 540));
}
