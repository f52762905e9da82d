//! The Hertz half-disc example (issue 22: `sweeps/hertz_halfdisc.toml` on the Gmsh mesh
//! `sweeps/meshes/hertz_halfdisc.msh`, P2 triangles, R = 1, nothing clamped).
//!
//! - the sweep file plans as committed: the seeds' methods and contract §3.2's (17 runs) on one
//!   mesh whose `h` and cell count come from the file;
//! - a short version of it (T = 2: the impact at t = 0.2 and most of the contact, which lasts
//!   until t ≈ 2.7) runs in well under a second in release and shows what docs/methods.md reports:
//!   the total mass is ρ|Ω_h| with |Ω_h| below πR²/2 by no more than the P2 arcs' geometric
//!   error, the consistent mass with Crank–Nicolson gains energy, the massless-Γ_C masses
//!   conserve it, backward Euler dissipates it, and row-sum lumping (massless P2 vertices,
//!   which made Crank–Nicolson blow up during the contact) is refused with its reason; and the
//!   properties of the comparison methods on this P2 mesh: kane, contact-stabilized Newmark and
//!   the penalty's hybrid never raise E^h (E^h + Φ) beyond round-off, Nitsche-Hybrid never
//!   raises E_Θ, the discrete gradient conserves E^h + Φ and E_Θ, generalized-α and HHT
//!   dissipate, Moreau–Jean sinks by O(τ).

mod common;

use std::path::PathBuf;

use common::run_sweep_text_at;
use contact_sweep::run::RunRecord;

fn sweep_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("sweeps/hertz_halfdisc.toml")
}

fn sweep_text() -> String {
    std::fs::read_to_string(sweep_path()).unwrap()
}

#[test]
fn the_sweep_file_plans() {
    use contact_sweep::sweep::{Key, Value};
    let sweep = contact_sweep::sweep::SweepFile::parse(&sweep_path(), &sweep_text())
        .unwrap_or_else(|e| panic!("{e}"));
    let plan = contact_sweep::sweep::expand(&sweep).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(plan.runs.len(), 17);
    for r in &plan.runs {
        // 765 P2 triangles; h = the largest element diameter (hertz_halfdisc.geo's h = 0.12
        // is Gmsh's target edge length, its largest triangle's longest side is 0.1337).
        assert_eq!(r.params[&Key::Elements], Value::Int(765));
        let h = r.params[&Key::H].as_f64().unwrap();
        assert!((h - 0.1337).abs() < 1e-4, "h = {h}");
    }
}

/// The half-disc's area |Ω_h| under its P2 map: each boundary arc edge spanning the angle 2α
/// is replaced by the parabola through its end points and its mid-angle point (where Gmsh puts
/// the mid-edge node), which encloses (2/3)·chord·sagitta = (4/3)R² sin α (1 − cos α) of the
/// circular segment's R²(α − sin α cos α). The difference f(α) = α − sin α cos α −
/// (4/3) sin α (1 − cos α) = α⁵/30 − α⁷/252 + O(α⁹) is positive and below α⁵/30 for the α
/// here (the series; checked in floating point on [amax/4, amax], where the α⁷ term is above
/// f's round-off), and Σ α = π/2 over the arc; the chord 2R sin α is at most the largest element
/// diameter h. So 0 < πR²/2 − |Ω_h| ≤ (π/60)·asin(h/2)⁴ = 1.05e-6 for h = 0.1337 (measured:
/// 1.086e-7 — most arc edges are shorter than h).
fn area_deficit_bound(h: f64) -> f64 {
    let f = |a: f64| a - a.sin() * a.cos() - 4.0 / 3.0 * a.sin() * (1.0 - a.cos());
    let amax = (h / 2.0).asin();
    for k in 25..=100 {
        let a = amax * k as f64 / 100.0;
        assert!(f(a) > 0.0 && f(a) <= a.powi(5) / 30.0, "f({a}) = {}", f(a));
    }
    std::f64::consts::PI / 60.0 * amax.powi(4)
}

#[test]
fn short_impact_energies() {
    let text = sweep_text();
    assert!(text.contains("\nT = 6.0\n"));
    let rows = run_sweep_text_at(&sweep_path(), &text.replace("\nT = 6.0\n", "\nT = 2.0\n"));
    assert_eq!(rows.len(), 17);
    let find = |space: &str, mass: &str, scheme: &str| -> &RunRecord {
        rows.iter()
            .find(|r| r.space == space && r.mass == mass && r.scheme_label.starts_with(scheme))
            .unwrap_or_else(|| panic!("{space} {mass} {scheme}"))
    };
    let by = |mass: &str, scheme: &str| find("mixed", mass, scheme);
    let cn = "crank-nicolson";
    let be = "backward-euler";
    let half_disc = std::f64::consts::PI / 2.0;
    for r in &rows {
        if r.mass == "lumped" {
            continue;
        }
        assert_eq!(
            r.status, "ok",
            "{} {} {}: {:?}",
            r.space, r.mass, r.scheme_label, r.message
        );
        // 1604 nodes, nothing clamped; Γ_C = 69 nodes (Nitsche and the penalty condense onto
        // the 34 faces' 3 quadrature points each instead: 102).
        assert_eq!(r.dofs, 2 * 1604);
        let points = if r.space == "mixed" { 69 } else { 102 };
        assert_eq!(r.contact_dofs, Some(points), "{}", r.label);
        if r.space != "mixed" || r.scheme_label.starts_with("moreau-jean") {
            continue;
        }
        // The plane is 0.02 below, reached at 0.02 / 0.1 = 0.2 (the step ending at 0.21 is the
        // first with contact). The position-level nodal multiplier keeps every Γ_C node above
        // the plane (to the LCP's tolerance).
        let t = r.first_contact_time.unwrap();
        assert!((t - 0.21).abs() < 1e-12, "{}: first contact {t}", r.mass);
        assert!(r.max_penetration.unwrap() < 1e-12);
    }
    // Total mass ρ|Ω_h| (ρ = 1) for the masses that keep it (mod3 moves layer 0's mass to
    // layer 1): exact integration of the P2 map's Jacobian, so |Ω_h| to round-off, and
    // |Ω_h| is πR²/2 to the arcs' geometric error.
    let bound = area_deficit_bound(by("consistent", cn).h);
    for m in ["consistent", "mod3"] {
        let deficit = half_disc - by(m, cn).mass_total.unwrap();
        assert!(
            deficit > 0.0 && deficit <= bound,
            "{m}: {deficit:e} > {bound:e}"
        );
    }
    // zero-contact removes the Γ_C nodes' rows: less mass, not redistributed.
    assert!(by("zero-contact", cn).mass_total.unwrap() < half_disc - 1e-3);
    // No gravity: E⁰ = ½ m v² (u⁰ = 0), and it is the energy scale.
    let consistent = by("consistent", cn);
    let e0 = consistent.energy_initial.unwrap();
    assert!((e0 - 0.5 * consistent.mass_total.unwrap() * 0.01).abs() < 1e-15);
    // Consistent mass + CN: the spurious gain of the mixed method (measured E(2)/E⁰ = 1.592,
    // 2.131 at T = 6); the gain starts near t = 1 and is past 1.05 by t = 1.5.
    let gain = consistent.energy_final.unwrap() / e0;
    assert!(gain > 1.2, "consistent + CN: E(T)/E⁰ = {gain}");
    // Massless Γ_C: CN conserves E but for the step that starts the contact (measured
    // max |E − E⁰| = 2.0e-4 E⁰ for mod3, 4.3e-4 for zero-contact over the whole T = 6).
    for m in ["mod3", "zero-contact"] {
        let dev = by(m, cn).energy_max_dev.unwrap();
        assert!(dev < 1e-3, "{m} + CN: max |E − E⁰|/E⁰ = {dev}");
    }
    // Backward Euler: never gains (≤ round-off per step), loses elastic energy once in contact
    // (measured E(2)/E⁰ ≈ 0.93).
    for m in ["consistent", "mod3"] {
        let r = by(m, be);
        assert!(r.energy_max_increase.unwrap() < 1e-12, "{m} + BE");
        let ratio = r.energy_final.unwrap() / r.energy_initial.unwrap();
        assert!(ratio < 0.97 && ratio > 0.85, "{m} + BE: E(T)/E⁰ = {ratio}");
    }
    // Row-sum lumping: the P2 triangle's vertex rows sum to zero, so every vertex would be
    // massless (Crank–Nicolson then diverged at t = 1.96, E/E⁰ = 4.8 at t = 1.5): the run is
    // refused, a row with the reason.
    let lumped = by("lumped", cn);
    assert_eq!(lumped.status, "invalid");
    let msg = lumped.message.as_deref().unwrap_or_default();
    assert!(msg.contains("row-sum lumping"), "{msg}");

    // contract §3.2's properties on this P2 mesh (per step, in units of E⁰ = energy_scale; the
    // bound is round-off of energies of size E⁰ over 3 208 dofs, ~1e-14 of it, as in
    // tests/fe_methods.rs — measured over T = 6: ≤ 2.8e-13 for kane, CSN and the penalty's
    // hybrid, 4.1e-13 for Nitsche-Hybrid's E_Θ).
    let increase = |r: &RunRecord| r.energy_max_increase.unwrap();
    for r in [
        by("consistent", "kane"),
        by("mod3", "kane"),
        by("consistent", "contact-stabilized-newmark"),
        find("penalty", "consistent", "hybrid"),
    ] {
        assert!(increase(r) <= 1e-12, "{}: {:e}", r.label, increase(r));
    }
    let nitsche_hybrid = find("nitsche", "consistent", "hybrid");
    let rise = nitsche_hybrid.energy_theta_max_increase.unwrap();
    assert!(rise <= 1e-12, "Nitsche-Hybrid: E_Θ rose by {rise:e}");
    // The discrete gradient conserves E^h + Φ (penalty) and E_Θ (Nitsche, Θ = 1) per step to
    // round-off, so over 200 steps to ≤ 200 × 1e-14 (measured over T = 6: 1.7e-13, 3.3e-14).
    let dg_pen = find("penalty", "consistent", "discrete-gradient");
    let dg_nit = find("nitsche", "consistent", "discrete-gradient");
    assert!(
        dg_pen.energy_max_dev.unwrap() <= 1e-11,
        "{:?}",
        dg_pen.energy_max_dev
    );
    assert!(dg_nit.energy_theta_drift.unwrap().abs() <= 1e-11);
    // Generalized-α (ρ∞ = ½) and HHT (α = 0.1) damp the high frequencies the impact excites:
    // E(T) below E⁰ (measured 0.9952, 0.9959 at T = 6), one contact phase where CN chatters.
    for r in [
        by("consistent", "generalized-alpha"),
        by("consistent", "hht"),
    ] {
        let ratio = r.energy_final.unwrap() / r.energy_initial.unwrap();
        assert!(
            ratio < 1.0 && ratio > 0.98,
            "{}: E(T)/E⁰ = {ratio}",
            r.label
        );
        assert_eq!(r.contact_phases, Some(1), "{}", r.label);
    }
    // Moreau–Jean is velocity-level: Γ_C sinks below the plane while its impulse acts (O(τ);
    // measured 8.3e-4 = 0.04 of the gap over T = 6), where the position-level methods hold it.
    let mj = by("consistent", "moreau-jean");
    let sink = mj.max_penetration.unwrap();
    assert!(sink > 1e-6 && sink < 0.02, "Moreau–Jean: {sink:e}");
}

/// The 3D counterpart, `sweeps/meshes/ball_tet.msh` (R = 1, 420 P2 tetrahedra, 821 nodes,
/// Γ_C = the lower hemisphere, 257 nodes; nothing clamped) under the half-disc's material and
/// impact (v = −0.1, gap 0.02), T = 1: the same split as in 2D. Measured over T = 3 (docs/methods.md):
/// consistent + CN E(T)/E⁰ = 66 with 50 contact phases, mod3 + CN within 1.1e-5 of E⁰.
#[test]
fn ball_of_tetrahedra_short_impact() {
    let text = sweep_text()
        .replace("scene = \"mesh2d\"", "scene = \"mesh3d\"")
        .replace("meshes/hertz_halfdisc.msh", "meshes/ball_tet.msh")
        .replace("\nT = 6.0\n", "\nT = 1.0\n");
    let start = text.find("method = [").unwrap();
    let text = format!(
        "{}method = [\n  {{ space = \"mixed\", mass = \"consistent\", scheme = \"crank-nicolson\" }},\n  {{ space = \"mixed\", mass = \"mod3\", scheme = \"crank-nicolson\" }},\n]\n",
        &text[..start]
    );
    let rows = run_sweep_text_at(&sweep_path(), &text);
    assert_eq!(rows.len(), 2);
    let ball = 4.0 / 3.0 * std::f64::consts::PI;
    for r in &rows {
        assert_eq!(r.status, "ok", "{}: {:?}", r.mass, r.message);
        assert_eq!(r.dofs, 3 * 821);
        assert_eq!(r.contact_dofs, Some(257));
        assert!((r.first_contact_time.unwrap() - 0.21).abs() < 1e-12);
        assert!(r.max_penetration.unwrap() < 1e-12);
        // ρ|Ω_h| below 4π/3 by the P2 surface's geometric error (measured 1.25e-3, 3.0e-4 of
        // the ball; the straight-sided tetrahedra on the same vertices miss 4.7 %).
        let deficit = (ball - r.mass_total.unwrap()) / ball;
        assert!(deficit > 0.0 && deficit < 1e-3, "{}: {deficit:e}", r.mass);
    }
    let by = |m: &str| rows.iter().find(|r| r.mass == m).unwrap();
    let consistent = by("consistent");
    let gain = consistent.energy_final.unwrap() / consistent.energy_initial.unwrap();
    assert!(
        gain > 1.3,
        "consistent + CN: E(1)/E⁰ = {gain} (measured 1.707)"
    );
    let dev = by("mod3").energy_max_dev.unwrap();
    assert!(
        dev < 1e-4,
        "mod3 + CN: max |E − E⁰|/E⁰ = {dev} (measured 1.05e-5)"
    );
}
